//! Joint-level stepping (`src/contact/joint_level/`): a closed, sticking joint stepped as a
//! whole gives the forces and poses of the cell-by-cell step to round-off, through settling,
//! shaking, landing and sliding, and through a checkpoint.
//!
//! Tolerance. The two ways sum the same forces in another order (the joint's from area
//! moments, the cells' one by one) and keep the shear history as `F⁰ − k_s A U` rather than
//! step by step: they differ by round-off, a few ulps of a force per step. How far round-off
//! carries in a scene is the scene's own property: stiff joints turn a pose that differs by
//! `δ` into forces that differ by `k_n A δ`, and a settling wall amplifies it while its blocks
//! settle. Each test therefore measures it, running the cell-by-cell step a second time with
//! gravity changed by one ulp (`1 + 2⁻⁵²`), and requires
//! - poses to agree within 1e-9 of the scene's length (measured: 1e-10 at most);
//! - forces (resultants, moments and every sub-contact's) to differ by no more than 10 × what
//!   that one ulp makes them differ. Measured on the settling wall: the joints stepped as a
//!   whole differ from the cells by 2.9e-8 of the largest resultant at step 200, 2.6e-5 at
//!   step 300 (the wall's settling peak of sensitivity) and 1.4e-9 at step 1,000, where one
//!   ulp of gravity gives 2.2e-8, 2.7e-5 and 1.7e-9: the same round-off, carried as far.

use crate::common;

use common::{cube, fixed_slab};
use voussoir::model::JointStepping;
use voussoir::prelude::*;

/// The largest differences, relative to the scene's scales, between `whole` and `cells`:
/// block positions (over `length`), rotations, and contact resultants and moments (over the
/// largest resultant of the scene).
fn differences(whole: &Model, cells: &Model, length: Real) -> (Real, Real, Real) {
    let (mut pose, mut turn) = (0.0_f64, 0.0_f64);
    for (a, b) in whole.blocks().iter().zip(cells.blocks()) {
        let (pa, pb) = (a.state().pose, b.state().pose);
        pose = pose.max((pa.translation - pb.translation).length() / length);
        // The quaternions' difference (the same sign), not an angle from `acos`, which cannot
        // resolve below 1e-8.
        let (qa, qb) = (
            pa.rotation,
            if pa.rotation.dot(pb.rotation) < 0.0 {
                -pb.rotation
            } else {
                pb.rotation
            },
        );
        turn = turn.max((qa - qb).length());
    }
    let (ca, cb): (Vec<_>, Vec<_>) = (whole.contacts().collect(), cells.contacts().collect());
    assert_eq!(ca.len(), cb.len(), "the same contacts");
    let scale = ca.iter().map(|c| c.resultant().length()).fold(1e-300, Real::max);
    let mut force = 0.0_f64;
    for (a, b) in ca.iter().zip(&cb) {
        assert_eq!(a.blocks(), b.blocks());
        let (wa, wb) = (a.wrench(), b.wrench());
        force = force.max((wa.force - wb.force).length() / scale);
        force = force.max((wa.moment_a - wb.moment_a).length() / (scale * length));
        force = force.max((wa.moment_b - wb.moment_b).length() / (scale * length));
        for (sa, sb) in a.subcontacts().zip(b.subcontacts()) {
            force = force.max((sa.normal_force() - sb.normal_force()).abs() / scale);
            force = force.max((sa.shear_force() - sb.shear_force()).length() / scale);
        }
    }
    (pose, turn, force)
}

/// Gravity changed by one ulp: how far round-off carries in a scene.
fn one_ulp_heavier(model: &mut Model) {
    heavier_by_ulps(model, 1.0);
}

/// Gravity `ulps` ulps heavier (negative: lighter).
fn heavier_by_ulps(model: &mut Model, ulps: Real) {
    let mut params = *model.parameters();
    params.gravity.z *= 1.0 + ulps * Real::EPSILON;
    model.set_parameters(params).expect("parameters");
}

/// The largest of each difference over a run.
#[derive(Debug, Clone, Copy, Default)]
struct Worst {
    poses: Real,
    rotations: Real,
    forces: Real,
}

impl std::fmt::Display for Worst {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "poses {:.2e}, rotations {:.2e}, forces {:.2e}",
            self.poses, self.rotations, self.forces
        )
    }
}

impl Worst {
    fn add(&mut self, (poses, rotations, forces): (Real, Real, Real)) {
        self.poses = self.poses.max(poses);
        self.rotations = self.rotations.max(rotations);
        self.forces = self.forces.max(forces);
    }

    /// Whether `self` (joint-level against cells) is round-off as `floor` (one ulp against
    /// cells) measures it: poses within 1e-9, or within 10 × the floor where round-off carries
    /// further; forces within 10 × the floor.
    fn within(&self, floor: &Worst) -> bool {
        let close = |a: Real, b: Real| a < 1e-9 || a <= 10.0 * b;
        close(self.poses, floor.poses)
            && close(self.rotations, floor.rotations)
            && self.forces <= 10.0 * floor.forces + 1e-12
    }
}

/// `model`, with gravity one ulp heavier if `nudge`.
fn nudged(mut model: Model, nudge: bool) -> Model {
    if nudge {
        one_ulp_heavier(&mut model);
    }
    model
}

/// Runs `build` both ways for `steps` (comparing every `every` steps) and checks that they
/// agree to round-off (see the module's documentation); `build(true)` builds the scene with
/// one ulp changed (gravity, or a block's height). Returns the largest share of joints stepped
/// as a whole.
fn agree(name: &str, build: impl Fn(bool) -> Model, steps: u64, every: u64, length: Real) -> Real {
    let mut whole = build(false);
    let mut cells = build(false);
    cells.set_joint_stepping(JointStepping::Cells);
    let mut nudged = build(true);
    nudged.set_joint_stepping(JointStepping::Cells);
    let mut share: Real = 0.0;
    let (mut worst, mut floor) = (Worst::default(), Worst::default());
    let mut done = 0;
    while done < steps {
        for m in [&mut whole, &mut cells, &mut nudged] {
            m.run_steps(every).expect("run");
        }
        done += every;
        assert_eq!(cells.whole_joint_count(), 0);
        share = share.max(whole.whole_joint_count() as Real / whole.contacts().len().max(1) as Real);
        worst.add(differences(&whole, &cells, length));
        floor.add(differences(&nudged, &cells, length));
    }
    println!("{name}: {worst} against cells, {floor} one ulp changed; {share:.2} stepped whole");
    assert!(
        worst.within(&floor),
        "{name}: {worst} against cells, {floor} one ulp changed"
    );
    share
}

#[test]
fn a_settling_wall_agrees_with_its_cells() {
    let share = agree(
        "settling wall",
        |nudge| nudged(voussoir::scenes::benchmark_wall(300).expect("wall"), nudge),
        1000,
        100,
        1.0,
    );
    assert!(share > 0.5, "most joints are stepped as a whole ({share})");
}

#[test]
fn a_shaking_wall_agrees_with_its_cells() {
    agree(
        "shaking wall",
        |nudge| {
            let wall = voussoir::scenes::shaking_wall(300, voussoir::scenes::BENCHMARK_SPACING).expect("wall");
            nudged(wall, nudge)
        },
        1000,
        100,
        1.0,
    );
}

/// A cube released 5 mm above the slab (and 3e-17 m more, `nudge`: about two ulps of its
/// centroid's height), turned by `tilt` (rad)
/// about x then about y, with friction and local damping, so that it lands, rocks and comes to
/// rest.
fn cube_drop(tilt: (Real, Real), nudge: bool) -> Model {
    let mut model = common::model(CoulombSlip::dry(1e9, 4e8, 35.0).expect("law"));
    model.add_block(fixed_slab("slab")).expect("slab");
    let height = if nudge { 0.005 + 3e-17 } else { 0.005 };
    model
        .add_block(common::tilted_cube("cube", tilt, height))
        .expect("cube");
    model
}

#[test]
fn cube_drops_agree_with_their_cells() {
    for (name, tilt) in [
        ("flat", (0.0, 0.0)),
        ("on an edge", (0.05, 0.0)),
        ("on a corner", (0.04, 0.03)),
    ] {
        let share = agree(name, |nudge| cube_drop(tilt, nudge), 3000, 100, 0.2);
        assert!(share > 0.0, "{name}: the joint is stepped as a whole once at rest");
    }
}

/// A block on a slab pushed sideways by a load that grows until it slides: the joint is stepped
/// as a whole while its corners pass the stick test (up to the closed-form bound below), is
/// left to its cells beyond, and the block slides as in the cell-by-cell step.
#[test]
fn a_block_pushed_until_it_slides_agrees_with_its_cells() {
    // `ulps`: gravity that many ulps heavier (negative: lighter).
    let build = |stepping: JointStepping, ulps: Real| {
        let mut model = common::model(CoulombSlip::dry(1e9, 4e8, 30.0).expect("law"));
        model.set_joint_stepping(stepping);
        model.add_block(fixed_slab("slab")).expect("slab");
        let id = model.add_block(cube("cube", Vector::ZERO)).expect("cube");
        heavier_by_ulps(&mut model, ulps);
        model.run_steps(1500).expect("settle");
        (model, id)
    };
    let weight = common::STONE_DENSITY * 0.008 * 9.81;
    let mu = (30.0_f64).to_radians().tan();
    let limit = mu * weight;
    // The joint-level step keeps the joint while the largest shear stress its cells hold stays
    // within the friction strength at every corner of the face (`docs/theory.md` §3.1). Pushed
    // at its centroid (a lever arm h = 0.1 m over the 0.2 m face, L), the cube's joint carries
    // the uniform shear stress P/A and the compression W/A (1 ∓ 6 P h/(W L)), least at the heel:
    // it sticks by the corner test while P/A ≤ μ W/A (1 − 6 P h/(W L)), up to
    // P = μ W/(1 + 6 μ h/L), 0.37 of the friction limit.
    let corner_bound = limit / (1.0 + 6.0 * mu * 0.1 / 0.2);
    let (mut whole, id) = build(JointStepping::Whole, 0.0);
    let (mut cells, _) = build(JointStepping::Cells, 0.0);
    // How far round-off carries in a block that slides is itself a matter of round-off (the
    // floor of one perturbation read 7.4e-5 on one build and 1.0e-6 on another whose time step
    // differed in its last bits): the floor is the largest over three perturbations.
    let (mut heavier, _) = build(JointStepping::Cells, 1.0);
    let (mut lighter, _) = build(JointStepping::Cells, -1.0);
    let (mut heavier_2, _) = build(JointStepping::Cells, 2.0);
    let (mut worst, mut floor) = (Worst::default(), Worst::default());
    for k in 0..=60 {
        // Up to 1.2 × the friction limit, tan 30° W, in 60 increments of 50 steps.
        let push = 0.02 * k as Real * limit;
        for m in [&mut whole, &mut cells, &mut heavier, &mut lighter, &mut heavier_2] {
            m.set_load(
                id,
                Wrench {
                    force: Vector::new(push, 0.0, 0.0),
                    moment: Vector::ZERO,
                },
            )
            .expect("load");
            m.run_steps(50).expect("run");
        }
        worst.add(differences(&whole, &cells, 0.2));
        for nudged in [&heavier, &lighter, &heavier_2] {
            floor.add(differences(nudged, &cells, 0.2));
        }
        let stuck = whole.whole_joint_count() == 1;
        if push < 0.95 * corner_bound {
            assert!(stuck, "push {push:.1} N: sticking, stepped as a whole");
        } else if push > 1.05 * corner_bound {
            assert!(
                !stuck,
                "push {push:.1} N: beyond the corner test's bound, {corner_bound:.1} N"
            );
        }
    }
    println!("pushed block: {worst} against cells, {floor} gravity one or two ulps changed");
    let slid = cells.blocks()[id.index()].state().pose.translation.x;
    assert!(slid > 1e-3, "the block slid ({slid} m)");
    assert!(
        worst.within(&floor),
        "{worst} against cells, {floor} gravity one or two ulps changed"
    );
}

/// A checkpoint of a model whose joints are stepped as a whole stores the cells' forces as they
/// stand (a reader sees the cell-by-cell step's values), and the run continues bit for bit.
#[test]
fn a_checkpoint_of_whole_joints_continues_bit_for_bit() {
    let mut model = voussoir::scenes::benchmark_wall(300).expect("wall");
    model.run_steps(400).expect("run");
    assert!(model.whole_joint_count() > 0);
    let text = model.to_checkpoint_string().expect("save");
    let mut restarted: Model = Model::from_checkpoint_str(&text).expect("load");
    assert_eq!(restarted.whole_joint_count(), model.whole_joint_count());
    assert_eq!(common::fingerprint(&model), common::fingerprint(&restarted));
    // The stored forces are the live ones: a model stepped cell by cell agrees to round-off.
    let json: serde_json::Value = serde_json::from_str(&text).expect("json");
    let contacts = json["contacts"].as_array().expect("contacts");
    let (stored, live): (Vec<Real>, Vec<Real>) = contacts
        .iter()
        .flat_map(|c| c["subcontacts"].as_array().expect("subcontacts"))
        .map(|s| s["force"]["normal"].as_f64().expect("a number"))
        .zip(
            model
                .contacts()
                .flat_map(|c| c.subcontacts().map(|s| s.normal_force()).collect::<Vec<_>>()),
        )
        .unzip();
    assert_eq!(stored, live);
    model.run_steps(300).expect("run");
    restarted.run_steps(300).expect("run");
    assert_eq!(common::fingerprint(&model), common::fingerprint(&restarted));
}

/// The elastic energy of a settling wall whose joints are stepped as a whole is summed from
/// the cells as they stand: the same as cell by cell, to round-off (within 10 × what one ulp of
/// gravity changes it).
#[test]
fn the_energy_books_read_the_live_cells() {
    let mut whole = voussoir::scenes::benchmark_wall(300).expect("wall");
    let mut cells = voussoir::scenes::benchmark_wall(300).expect("wall");
    let mut nudged = voussoir::scenes::benchmark_wall(300).expect("wall");
    cells.set_joint_stepping(JointStepping::Cells);
    nudged.set_joint_stepping(JointStepping::Cells);
    one_ulp_heavier(&mut nudged);
    for steps in [200, 300, 500] {
        for m in [&mut whole, &mut cells, &mut nudged] {
            m.run_steps(steps).expect("run");
        }
        assert!(whole.whole_joint_count() > 0);
        let (a, b, c) = (whole.energies(), cells.energies(), nudged.energies());
        let floor = (c.elastic - b.elastic).abs();
        println!(
            "elastic energy: {} whole, {} cells, {} one ulp",
            a.elastic, b.elastic, c.elastic
        );
        assert!(
            (a.elastic - b.elastic).abs() <= 10.0 * floor + 1e-12 * b.elastic.abs(),
            "{} vs {} (one ulp: {})",
            a.elastic,
            b.elastic,
            c.elastic
        );
        assert!(((a.input() - a.accounted()) - (b.input() - b.accounted())).abs() <= 1e-6 * b.input().abs().max(1e-9));
    }
}
