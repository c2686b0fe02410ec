//! Stepping a dry-stacked running-bond wall settling under gravity.
//!
//! `cargo bench --bench wall` reports the time per step; the "items" throughput is sub-contact
//! updates per second.

use divan::counter::ItemsCount;
use voussoir::build::benchmark_wall;
use voussoir::prelude::*;

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

#[divan::bench(args = [1_000, 10_000], sample_count = 20, sample_size = 5)]
fn settle_step(bencher: divan::Bencher, blocks: usize) {
    let mut model = wall(blocks);
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
