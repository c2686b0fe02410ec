//! Stepping a dry-stacked running-bond wall settling under gravity (`settle_step`) or shaken at
//! its base (`shake_step`, `shake_step_full_speed`, `shake_step_100k`), and its broad phase.
//!
//! `cargo bench --bench wall` reports the time per step; the "items" throughput is sub-contact
//! updates per second (with the sub-contact count at the start of the sample).

use divan::counter::ItemsCount;
use voussoir::prelude::*;
use voussoir::scenes::{benchmark_wall, shaking_wall, BENCHMARK_SPACING};

fn main() {
    divan::main();
}

/// A wall of about `blocks` bricks, 1/10 as many courses as bricks per course, settled for a few
/// steps so that the initial contact detection is done.
fn wall(blocks: usize) -> Model {
    let mut model = benchmark_wall(blocks).expect("wall");
    model.run_steps(20).expect("settling");
    model
}

#[divan::bench(args = [1_000, 10_000, 100_000], sample_count = 20, sample_size = 5)]
fn settle_step(bencher: divan::Bencher, blocks: usize) {
    let mut model = wall(blocks);
    let updates = model.subcontact_count();
    bencher
        .counter(ItemsCount::new(updates))
        .bench_local(|| model.step().expect("step"));
}

/// The wall of [`wall`] with its joints of law `law` (same blocks, parameters and damping):
/// what a law costs per sub-contact on a resting wall.
fn wall_with<L: ConstitutiveLaw>(blocks: usize, law: L) -> Model<L> {
    let coulomb = benchmark_wall(blocks).expect("wall");
    let mut model: Model<L> = Model::new(*coulomb.parameters()).expect("model");
    model.set_damping(coulomb.damping()).expect("damping");
    model.set_joint_law(MaterialId(0), MaterialId(0), law).expect("law");
    for b in coulomb.blocks() {
        model.add_block(b.clone()).expect("block");
    }
    model.run_steps(20).expect("settling");
    model
}

/// [`settle_step`] with bonded mortar joints (`MortarJoint`: f_t 0.25 MPa, c 0.35 MPa, G_f^I 18
/// N/m, G_f^II 125 N/m, the wall's kn, ks and φ), all elastic at rest: the softening law's
/// cost per sub-contact against `CoulombSlip`'s (issue 44, item 5: at most 1.3×).
#[divan::bench(args = [10_000, 100_000], sample_count = 10, sample_size = 5)]
fn settle_step_mortar(bencher: divan::Bencher, blocks: usize) {
    let law = MortarJoint::builder(1e9, 4e8, 30.0)
        .tension(2.5e5, 18.0)
        .cohesion(3.5e5, 125.0)
        .build()
        .expect("law");
    let mut model = wall_with(blocks, law);
    let updates = model.subcontact_count();
    bencher
        .counter(ItemsCount::new(updates))
        .bench_local(|| model.step().expect("step"));
}

/// [`settle_step`] with bonded `CoulombSlip` joints of [`settle_step_mortar`]'s strengths
/// (tension cut-off 0.25 MPa, cohesion 0.35 MPa, brittle): what carrying tension costs, apart
/// from what softening costs.
#[divan::bench(args = [10_000, 100_000], sample_count = 10, sample_size = 5)]
fn settle_step_bonded_coulomb(bencher: divan::Bencher, blocks: usize) {
    let law = CoulombSlip::new(1e9, 4e8, 30.0, 30.0, 3.5e5, 2.5e5).expect("law");
    let mut model = wall_with(blocks, law);
    let updates = model.subcontact_count();
    bencher
        .counter(ItemsCount::new(updates))
        .bench_local(|| model.step().expect("step"));
}

/// [`settle_step`] through `AnyLaw` (the Python package's model): the same Coulomb joints, with
/// every sub-contact holding `AnyState` (all laws' states side by side).
#[divan::bench(args = [10_000, 100_000], sample_count = 10, sample_size = 5)]
fn settle_step_any_law(bencher: divan::Bencher, blocks: usize) {
    let mut model = wall_with(blocks, AnyLaw::from(CoulombSlip::dry(1e9, 4e8, 30.0).expect("law")));
    let updates = model.subcontact_count();
    bencher
        .counter(ItemsCount::new(updates))
        .bench_local(|| model.step().expect("step"));
}

/// The wall of [`wall`] undamped, its base shaken across the wall at 0.3 g and 3 Hz from the
/// first step (`scenes::shaking_wall`), after the same 20 steps.
fn shaking(blocks: usize) -> Model {
    let mut model = shaking_wall(blocks, BENCHMARK_SPACING).expect("wall");
    model.run_steps(20).expect("shaking");
    model
}

/// One step of the shaking wall. Re-detections come every few steps (more as the table speeds
/// up: the base alone triggers one every 0.25 mm it moves), so a sample is 10 steps and the mean
/// is the figure to read; the model keeps shaking from sample to sample.
#[divan::bench(args = [1_000, 10_000], sample_count = 20, sample_size = 10)]
fn shake_step(bencher: divan::Bencher, blocks: usize) {
    let mut model = shaking(blocks);
    let updates = model.subcontact_count();
    bencher
        .counter(ItemsCount::new(updates))
        .bench_local(|| model.step().expect("step"));
}

/// [`shake_step`] at full table speed: after 700 steps (0.08 s, the table at 0.156 m/s and the
/// courses rocking across the wall), where the blocks move relative to each other and pairs
/// are tested afresh at every step.
#[divan::bench(args = [1_000, 10_000], sample_count = 20, sample_size = 10)]
fn shake_step_full_speed(bencher: divan::Bencher, blocks: usize) {
    let mut model = shaking_wall(blocks, BENCHMARK_SPACING).expect("wall");
    model.run_steps(700).expect("shaking");
    let updates = model.subcontact_count();
    bencher
        .counter(ItemsCount::new(updates))
        .bench_local(|| model.step().expect("step"));
}

/// [`shake_step`] on the 100,000-block wall, with fewer samples.
#[divan::bench(args = [100_000], sample_count = 5, sample_size = 10)]
fn shake_step_100k(bencher: divan::Bencher, blocks: usize) {
    let mut model = shaking(blocks);
    let updates = model.subcontact_count();
    bencher
        .counter(ItemsCount::new(updates))
        .bench_local(|| model.step().expect("step"));
}

/// Writing one ParaView frame (blocks as polyhedron cells, sub-contacts as points, `.pvd`
/// collections) of a settled wall.
#[divan::bench(args = [10_000], sample_count = 5, sample_size = 1)]
fn write_paraview_frame(bencher: divan::Bencher, blocks: usize) {
    let model = wall(blocks);
    let dir = std::env::temp_dir().join(format!("voussoir-bench-vtu-{}", std::process::id()));
    let mut series = voussoir::io::vtk::Series::new(&dir, "wall");
    bencher.bench_local(|| series.write_frame(&model).expect("write"));
    std::fs::remove_dir_all(&dir).ok();
}

/// Candidate pairs of a settled wall: parry's BVH (what the model uses) against a uniform grid.
#[divan::bench(args = [10_000, 100_000], sample_count = 10, sample_size = 1)]
fn broad_phase_bvh(bencher: divan::Bencher, blocks: usize) {
    let model = wall(blocks);
    let mut bp = voussoir::geometry::BroadPhase::default();
    let mut out = Vec::new();
    bencher.bench_local(|| {
        bp.pairs(
            model.blocks().iter().map(|b| (b.shape(), &b.state().pose)),
            1e-3,
            &mut out,
        )
    });
}

/// As [`broad_phase_bvh`] with the uniform cell grid.
#[divan::bench(args = [10_000, 100_000], sample_count = 10, sample_size = 1)]
fn broad_phase_grid(bencher: divan::Bencher, blocks: usize) {
    let model = wall(blocks);
    let mut bp = voussoir::geometry::BroadPhase::default();
    let mut out = Vec::new();
    bencher.bench_local(|| {
        bp.pairs_grid(
            model.blocks().iter().map(|b| (b.shape(), &b.state().pose)),
            1e-3,
            &mut out,
        )
    });
}

/// Broad-phase margin of the incremental benches: the default contact tolerance, as the `1e-3` above.
const MARGIN: Real = 1e-3;

/// The shapes of a settled wall, its poses, and a broad phase whose incremental BVH is built on
/// them.
fn primed(blocks: usize) -> (Model, Vec<Pose>, voussoir::geometry::BroadPhase) {
    let model = wall(blocks);
    let poses: Vec<Pose> = model.blocks().iter().map(|b| b.state().pose).collect();
    let mut bp = voussoir::geometry::BroadPhase::default();
    let mut out = Vec::new();
    bp.pairs_incremental(model.blocks().iter().map(|b| b.shape()).zip(&poses), MARGIN, &mut out);
    (model, poses, bp)
}

/// One pseudo-random unit vector per block (xorshift, fixed seed).
fn directions(n: usize) -> Vec<Vector> {
    let mut seed = 0x2545_f491_4f6c_dd1d_u64;
    let mut rand = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as Real / (1u64 << 52) as Real - 1.0
    };
    (0..n)
        .map(|_| Vector::new(rand(), rand(), rand()).normalize_or(Vector::Z))
        .collect()
}

/// `poses` with block `k` moved by `step * dirs[k]` where `moved(k)`.
fn displaced(poses: &[Pose], dirs: &[Vector], step: Real, moved: impl Fn(usize) -> bool) -> Vec<Pose> {
    let mut p = poses.to_vec();
    for (k, (p, d)) in p.iter_mut().zip(dirs).enumerate() {
        if moved(k) {
            p.translation += step * *d;
        }
    }
    p
}

/// [`broad_phase_bvh`] with the BVH kept between detections, when no block left its fat leaf
/// (nothing moved): the boxes are recomputed and the kept pairs filtered.
#[divan::bench(args = [10_000, 100_000], sample_count = 10, sample_size = 5)]
fn broad_phase_incremental_static(bencher: divan::Bencher, blocks: usize) {
    let (model, poses, mut bp) = primed(blocks);
    let mut out = Vec::new();
    bencher
        .bench_local(|| bp.pairs_incremental(model.blocks().iter().map(|b| b.shape()).zip(&poses), MARGIN, &mut out));
}

/// As [`broad_phase_incremental_static`] with 1% of the blocks moved by 3 margins (out of their
/// fat leaves) at every detection: they go back and forth between two positions.
#[divan::bench(args = [10_000, 100_000], sample_count = 10, sample_size = 5)]
fn broad_phase_incremental_1pct(bencher: divan::Bencher, blocks: usize) {
    let (model, poses, mut bp) = primed(blocks);
    let moved = displaced(&poses, &directions(poses.len()), 3.0 * MARGIN, |k| k % 100 == 50);
    let mut out = Vec::new();
    let mut flip = false;
    bencher
        .with_inputs(|| {
            flip = !flip;
            if flip {
                moved.clone()
            } else {
                poses.clone()
            }
        })
        .bench_local_refs(|p| {
            bp.pairs_incremental(model.blocks().iter().map(|b| b.shape()).zip(&*p), MARGIN, &mut out)
        });
}

/// As [`broad_phase_incremental_static`] with every block moved by 0.3 margin at every detection,
/// as when the whole wall settles: each block drifts along its own direction, 10 detections one
/// way and 10 back. A leaf leaves its fat box every few detections only: 19% of the leaves are
/// re-inserted per detection on average, in bursts (none at 12 detections out of 20).
#[divan::bench(args = [10_000, 100_000], sample_count = 10, sample_size = 10)]
fn broad_phase_incremental_settle(bencher: divan::Bencher, blocks: usize) {
    let (model, poses, mut bp) = primed(blocks);
    let dirs = directions(poses.len());
    let mut out = Vec::new();
    let mut detection = 0_usize;
    bencher
        .with_inputs(|| {
            detection += 1;
            let phase = detection % 20;
            let steps = if phase <= 10 { phase } else { 20 - phase };
            displaced(&poses, &dirs, 0.3 * MARGIN * steps as Real, |_| true)
        })
        .bench_local_refs(|p| {
            bp.pairs_incremental(model.blocks().iter().map(|b| b.shape()).zip(&*p), MARGIN, &mut out)
        });
}

/// As [`broad_phase_incremental_static`] with every block moved out of its fat leaf at every
/// detection (2 margins back and forth): the worst case, every leaf re-inserted.
#[divan::bench(args = [10_000, 100_000], sample_count = 10, sample_size = 2)]
fn broad_phase_incremental_all(bencher: divan::Bencher, blocks: usize) {
    let (model, poses, mut bp) = primed(blocks);
    let moved = displaced(&poses, &directions(poses.len()), 2.0 * MARGIN, |_| true);
    let mut out = Vec::new();
    let mut flip = false;
    bencher
        .with_inputs(|| {
            flip = !flip;
            if flip {
                moved.clone()
            } else {
                poses.clone()
            }
        })
        .bench_local_refs(|p| {
            bp.pairs_incremental(model.blocks().iter().map(|b| b.shape()).zip(&*p), MARGIN, &mut out)
        });
}
