//! Detection that follows relative motion (`docs/theory.md` §2.3): a pair keeps its contact while
//! its two blocks move together, whatever distance they travel, and is tested afresh once they
//! move relative to each other.

use crate::common;

use voussoir::prelude::*;

/// A stack of three cubes on a slab, everything moving at `velocity` from the start (the slab's
/// translations prescribed at it), with stiffness-proportional damping (20 % at the cubes'
/// 225 Hz bounce on their joints), which acts on relative velocities only, so that the two
/// frames see the same damping (local damping acts on absolute velocities). Undamped, the
/// stack bounced on its joints' kinks for good and amplified round-off: reordering one sum
/// in the contact kernel moved its forces at 0.25 s by 1.3e-4.
fn stack(velocity: Vector) -> (Model<CoulombSlip>, Vec<BlockId>) {
    let mut model = common::model(CoulombSlip::dry(1e9, 4e8, 30.0).expect("law"));
    model
        .set_damping(Damping::rayleigh_stiffness(0.2, 225.0).expect("damping"))
        .expect("damped");
    let slab = common::fixed_slab("slab").with_fixity(Fixity {
        translation: velocity.to_array().map(Dof::Velocity),
        rotation: [Dof::Fixed; 3],
    });
    let mut ids = vec![model
        .add_block(slab.with_velocity(velocity, Vector::ZERO))
        .expect("slab")];
    for k in 0..3 {
        let at = Vector::new(0.0, 0.0, 0.2 * k as f64);
        let cube = common::cube(&format!("cube {k}"), at).with_velocity(velocity, Vector::ZERO);
        ids.push(model.add_block(cube).expect("cube"));
    }
    (model, ids)
}

/// The joints' normal forces, by pair.
fn normal_forces(model: &Model<CoulombSlip>) -> Vec<(u32, u32, f64)> {
    model
        .contacts()
        .map(|c| {
            let (a, b) = c.blocks();
            (a.0, b.0, c.normal_force())
        })
        .collect()
}

/// A stack carried along at 0.5 m/s travels 100 mm (400 re-detection triggers) without a pair
/// tested again, and its joints carry the forces of the same stack at rest: contact
/// geometry depends on relative poses only (Galilean invariance). Before, every contact of a
/// block that had moved a quarter of the tolerance was clipped afresh.
#[test]
fn a_stack_carried_along_keeps_its_contacts_and_forces() {
    let (mut still, ids) = stack(Vector::ZERO);
    let (mut carried, _) = stack(Vector::new(0.5, 0.0, 0.0));
    // The first detection, then the stack finds its feet (its joints close on their springs).
    still.run_until_time(0.05).expect("run");
    carried.run_until_time(0.05).expect("run");
    let (tests_still, tests_carried) = (still.pair_tests(), carried.pair_tests());
    let detections = carried.detection_count();
    still.run_until_time(0.25).expect("run");
    carried.run_until_time(0.25).expect("run");
    let x = |m: &Model<CoulombSlip>| m.block(ids[3]).expect("top").state().pose.translation.x;
    assert!(x(&carried) - x(&still) > 0.099, "carried {} m", x(&carried) - x(&still));
    assert!(
        carried.detection_count() - detections >= 100,
        "the blocks moved past the trigger"
    );
    assert_eq!(
        carried.pair_tests(),
        tests_carried,
        "no pair tested again while carried"
    );
    assert_eq!(still.pair_tests(), tests_still);
    let (a, b) = (normal_forces(&still), normal_forces(&carried));
    assert_eq!(a.len(), 3);
    assert_eq!(a.len(), b.len());
    for ((i, j, fa), (k, l, fb)) in a.iter().zip(&b) {
        assert_eq!((i, j), (k, l));
        // A difference δ of relative position between the two frames changes a joint force by
        // k·A·δ = 4e7 N/m × δ: 1e-8 of it is δ ≈ 1e-13 m, above the round-off of coordinates
        // 0.1 m from the origin (1e-17 m a step, damped away) and far below a change of contact
        // geometry (a contact clipped afresh moves its anchors by up to the 0.25 mm trigger;
        // dropped or new sub-contacts change the force by percents). Measured: 1e-12.
        assert!(
            (fa - fb).abs() <= 1e-8 * fa.abs(),
            "{i}–{j}: {fa} N at rest, {fb} N carried"
        );
    }
}

/// A cube slid across the slab (relative motion) is tested again every time it moved the
/// trigger relative to the slab, and its contact follows: its sub-contacts stay under it and
/// its normal force equals its weight.
#[test]
fn a_sliding_block_is_tested_again_as_it_slides() {
    let mut model = common::model(CoulombSlip::dry(1e9, 4e8, 0.0).expect("frictionless"));
    model.add_block(common::fixed_slab("slab")).expect("slab");
    let cube = model.add_block(common::cube("cube", Vector::ZERO)).expect("cube");
    // Settled under local damping, then undamped: frictionless sliding keeps its speed.
    model.run_until_time(0.1).expect("settle");
    model.set_damping(Damping::None).expect("undamped");
    model
        .set_velocity(cube, Vector::new(0.2, 0.0, 0.0), Vector::ZERO)
        .expect("push");
    let tests = model.pair_tests();
    model.run_until_time(0.6).expect("slide");
    let travelled = model.block(cube).expect("cube").state().pose.translation.x;
    // The cube moves v·Δt a step and passes the 0.25 mm trigger after k = ⌊0.25 mm / v·Δt⌋ + 1
    // steps, when it is tested again (it moved more than half the trigger relative to the slab).
    let per_step = 0.2 * model.dt();
    let k = (0.25e-3 / per_step).floor() + 1.0;
    let expected = travelled / (k * per_step);
    let retests = model.pair_tests() - tests;
    assert!(travelled > 0.099, "{travelled}");
    assert!(
        (retests as f64 - expected).abs() <= 2.0,
        "{retests} tests over {travelled} m, {expected:.1} expected"
    );
    let contact = model.contacts().next().expect("the joint");
    let weight = model.block(cube).expect("cube").mass_properties().mass * 9.81;
    assert!(
        (contact.normal_force() - weight).abs() < 0.05 * weight,
        "{} N against a weight of {weight} N",
        contact.normal_force()
    );
    for s in contact.subcontacts() {
        let p = s.point();
        assert!(
            (p.x - travelled).abs() <= 0.1 + 1e-3 && p.y.abs() <= 0.1 + 1e-3,
            "sub-contact at {p} under a cube at x = {travelled}"
        );
    }
}

/// The shaking wall, run into its rocking (pairs re-tested, contacts spliced, bounds
/// re-evaluated block by block), ends in the same bits on one thread and on four.
#[test]
fn a_shaking_wall_gives_the_same_bits_on_any_number_of_threads() {
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        pool.install(|| {
            let mut model = voussoir::scenes::shaking_wall(600, voussoir::scenes::BENCHMARK_SPACING).expect("wall");
            let tests = model.pair_tests();
            model.run_steps(900).expect("run");
            assert!(model.pair_tests() > tests, "the courses moved relative to each other");
            let mut bits: Vec<u64> = Vec::new();
            for b in model.blocks() {
                let p = &b.state().pose;
                bits.extend(p.translation.to_array().map(f64::to_bits));
                bits.extend(p.rotation.to_array().map(f64::to_bits));
            }
            for c in model.contacts() {
                bits.push(c.normal_force().to_bits());
                bits.push(c.subcontacts().count() as u64);
            }
            bits.push(model.dt().to_bits());
            bits
        })
    };
    assert!(run(1) == run(4), "one thread and four differ");
}

/// A 0.2 m cube from `x` along x (its base at height `z`), of stone.
fn cube_at(x: f64, z: f64) -> RigidBlock {
    RigidBlock::cuboid(
        "cube",
        Vector::new(x, 0.0, z),
        Vector::new(x + 0.2, 0.2, z + 0.2),
        common::STONE_DENSITY,
    )
    .expect("cube")
}

/// A model without gravity at a fixed step of 0.1 ms, one Coulomb law.
fn weightless_model() -> Model<CoulombSlip> {
    let params = ModelParameters {
        gravity: Vector::ZERO,
        time_step: TimeStep::Fixed(1e-4),
        ..ModelParameters::default()
    };
    common::model_with(params, CoulombSlip::dry(1e9, 4e8, 30.0).expect("law"))
}

/// A checkpoint holds the contact lists packed; the first detection after loading lays them out
/// afresh, with room after every 64 contacts, even when it tests no pair and stages nothing
/// (it used to take its filler from the empty staging lists and panic). The resumed run keeps
/// the bits of the uninterrupted one.
#[test]
fn a_resumed_run_detects_without_retesting_and_keeps_the_bits() {
    let build = || {
        let mut wall = voussoir::scenes::benchmark_wall(100).expect("wall");
        let mut params = *wall.parameters();
        params.gravity = Vector::ZERO;
        wall.set_parameters(params).expect("weightless");
        // Far away and flying: the only block that moves past the trigger.
        let flyer = cube_at(0.0, 10.0).with_velocity(Vector::new(0.0, 0.0, 1.0), Vector::ZERO);
        wall.add_block(flyer).expect("flyer");
        wall
    };
    let mut straight = build();
    straight.run_steps(5).expect("run");
    assert!(straight.contacts().len() > 128, "more than two segments of contacts");
    let text = straight.to_checkpoint_string().expect("save");
    let mut resumed: Model<CoulombSlip> = Model::from_checkpoint_str(&text).expect("load");
    let detections = resumed.detection_count();
    resumed.run_steps(100).expect("resumed run");
    straight.run_steps(100).expect("straight run");
    assert!(
        resumed.detection_count() > detections,
        "the flyer moved past the trigger"
    );
    assert_eq!(common::fingerprint(&resumed), common::fingerprint(&straight));
}

/// A table given a base motion (0.5 m/s along x) runs into a fixed post: their contact is
/// found. The table's fixity turned from fixed to prescribed by the motion, without a full
/// detection; the pair of two fixed blocks it was at the start must not stay skipped. (The
/// motion used to be removed after one step, the table keeping its last velocity; removing a
/// motion now stops the block, so the motion stays on.)
#[test]
fn a_block_released_from_a_base_motion_meets_a_fixed_one() {
    use voussoir::loading::{BaseMotion, MotionKind, TimeHistory};
    let mut model = weightless_model();
    let table = model
        .add_block(cube_at(0.0, 0.0).with_fixity(Fixity::FIXED))
        .expect("table");
    let post = model
        .add_block(cube_at(0.22, 0.0).with_fixity(Fixity::FIXED))
        .expect("post");
    model.add_block(cube_at(5.0, 5.0)).expect("a free block far away");
    model.run_steps(1).expect("first detection");
    let velocity = TimeHistory::new(vec![0.0, 100.0], vec![0.5, 0.5]).expect("history");
    let motion = BaseMotion::new(MotionKind::Velocity, [Some(velocity), None, None]).expect("motion");
    model.set_base_motion(table, Some(motion)).expect("motion on");
    model.step().expect("step");
    // 20 mm at 0.5 m/s, and 0.3 mm into the post (the table's centroid starts at x = 0.1 m).
    while model.block(table).expect("table").state().pose.translation.x < 0.1203 {
        model.step().expect("step");
    }
    let joint = model.contact_between(table, post).expect("the table meets the post");
    assert!(joint.subcontacts().count() > 0);
}

/// A cube tested apart from a fixed one 1.2 mm away (0.2 mm beyond the 1 mm tolerance) drifts
/// 10 mm off, the tolerance is raised to 5 mm, and the cube comes back to 1.2 mm (in steps of
/// at most 2.5 mm, half the tolerance: a step that moves a block further than the tolerance is
/// now an error; it used to come back in one step): the pair is in contact, as in a model
/// built there. The verdict of a pair found apart holds
/// only for the tolerance it was measured against; a change of parameters forgets it.
#[test]
fn raising_the_tolerance_forgets_the_verdicts_of_pairs_found_apart() {
    let contact_subcontacts = |model: &Model<CoulombSlip>| {
        model
            .contact_between(BlockId(0), BlockId(1))
            .map_or(0, |c| c.subcontacts().count())
    };
    let mut model = weightless_model();
    model
        .add_block(cube_at(0.0, 0.0).with_fixity(Fixity::FIXED))
        .expect("fixed");
    let cube = model.add_block(cube_at(0.2012, 0.0)).expect("cube");
    model.run_steps(1).expect("first detection");
    assert_eq!(contact_subcontacts(&model), 0, "1.2 mm apart at a 1 mm tolerance");
    model
        .set_velocity(cube, Vector::new(0.1, 0.0, 0.0), Vector::ZERO)
        .expect("push");
    model.run_steps(1000).expect("10 mm away");
    model.set_velocity(cube, Vector::ZERO, Vector::ZERO).expect("stop");
    let mut params = *model.parameters();
    params.contact.tolerance = 5e-3;
    model.set_parameters(params).expect("5 mm tolerance");
    model.run_steps(2).expect("run");
    // Back, at most 2.5 mm a step.
    let mut steps = 0;
    loop {
        let x = model.block(cube).expect("cube").state().pose.translation.x;
        let back = x - (0.2012 + 0.1);
        if back.abs() < 1e-12 {
            break;
        }
        model
            .set_velocity(
                cube,
                Vector::new(-back.min(2.5e-3) / model.dt(), 0.0, 0.0),
                Vector::ZERO,
            )
            .expect("back");
        model.step().expect("step");
        steps += 1;
        assert!(steps < 10, "back in {steps} steps");
    }
    assert_eq!(steps, 4, "10 mm back in steps of at most 2.5 mm");
    model.set_velocity(cube, Vector::ZERO, Vector::ZERO).expect("stop");
    model.run_steps(3).expect("run");
    let mut fresh = common::model_with(params, CoulombSlip::dry(1e9, 4e8, 30.0).expect("law"));
    fresh
        .add_block(cube_at(0.0, 0.0).with_fixity(Fixity::FIXED))
        .expect("fixed");
    fresh.add_block(cube_at(0.2012, 0.0)).expect("cube");
    fresh.run_steps(1).expect("first detection");
    assert!(contact_subcontacts(&fresh) > 0);
    assert_eq!(contact_subcontacts(&model), contact_subcontacts(&fresh));
}
