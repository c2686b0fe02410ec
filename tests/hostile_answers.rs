//! Issue 33, unsafe answers: a step that would move a block further than the contact tolerance
//! is cut (automatic step) or stops the run (fixed step) instead of letting a block pass
//! through another; limit analysis lets only the part of a tilted face that touches carry
//! force; a checkpoint's slack of a tested pair is checked against its shapes.

use crate::common;

use voussoir::prelude::*;

/// A 0.2 m cube whose bottom is `gap` above a fixed 0.2 m slab, falling at `speed`.
fn cube_at_slab(params: ModelParameters, kn: Real, speed: Real, gap: Real) -> (Model, BlockId) {
    let mut model = common::model_with(params, CoulombSlip::dry(kn, 0.4 * kn, 30.0).expect("law"));
    model.add_block(common::fixed_slab("slab")).expect("slab");
    let cube = model
        .add_block(
            common::cube("bullet", Vector::new(0.0, 0.0, gap))
                .with_velocity(Vector::new(0.0, 0.0, -speed), Vector::ZERO),
        )
        .expect("cube");
    (model, cube)
}

/// A 0.2 m cube at 300, 600 and 900 m/s (below `max_speed`) towards a 0.2 m fixed slab, with
/// the automatic step: the step is cut so that the cube moves at most half the contact
/// tolerance a step, the contact is found and the cube bounces back above the slab. On the
/// old code the step was the critical one (the cube moved 3 to 9 cm a step), the cube passed
/// through the slab and the run reported success.
#[test]
fn a_fast_cube_does_not_tunnel_through_a_slab() {
    for speed in [300.0, 600.0, 900.0] {
        let (mut model, cube) = cube_at_slab(ModelParameters::default(), 1e12, speed, 0.3);
        let tolerance = model.parameters().contact.tolerance;
        let mut lowest = Real::INFINITY;
        let mut steps = 0;
        while model.time() < 0.3 / speed + 2e-3 {
            let before = model.block(cube).expect("cube").state().pose.translation;
            model.step().unwrap_or_else(|e| panic!("{speed} m/s: {e}"));
            let after = model.block(cube).expect("cube").state().pose.translation;
            assert!(
                (after - before).length() <= tolerance,
                "{speed} m/s: the cube moved {} m in one step",
                (after - before).length()
            );
            lowest = lowest.min(after.z - 0.1);
            steps += 1;
        }
        let z = model.block(cube).expect("cube").state().pose.translation.z - 0.1;
        println!("{speed} m/s: {steps} steps, lowest bottom {lowest:.4} m, bottom now {z:.4} m");
        assert!(
            lowest > -0.2,
            "{speed} m/s: the cube went through the slab ({lowest} m)"
        );
        assert!(z > -tolerance, "{speed} m/s: the cube ends above the slab ({z} m)");
    }
}

/// With a fixed step the step is not cut: a step that moves a block further than the contact
/// tolerance stops the run with `Error::StepTooLong` naming the step, the block, the distance
/// and the longest step at that speed.
#[test]
fn a_fixed_step_too_long_for_the_speed_is_an_error() {
    let params = ModelParameters {
        time_step: TimeStep::Fixed(1e-5),
        ..ModelParameters::default()
    };
    let (mut model, cube) = cube_at_slab(params, 1e9, 300.0, 0.3);
    let e = model.run_until_time(0.01).unwrap_err();
    match e {
        Error::StepTooLong {
            step,
            block,
            distance,
            tolerance,
            max_dt,
            ..
        } => {
            assert_eq!(block, cube);
            assert_eq!(step, 1);
            assert!((distance - 3e-3).abs() < 1e-6, "{distance}");
            assert_eq!(tolerance, 1e-3);
            assert!((max_dt - 1e-3 / 300.0).abs() < 1e-9, "{max_dt}");
        }
        e => panic!("{e:?}"),
    }
    assert!(e.to_string().contains("contact tolerance"), "{e}");
}

/// A 0.2 m cube of 1e13 kg/m³ on the fixed slab, joints of normal stiffness `kn` (Pa/m, shear
/// 0.4 kn, φ 30°): the model, the slab and the cube.
fn dense_cube_on_slab(kn: f64) -> (Model, BlockId, BlockId) {
    let mut model = common::model(CoulombSlip::dry(kn, 0.4 * kn, 30.0).expect("law"));
    let base = model.add_block(common::fixed_slab("base")).expect("slab");
    let h = 0.5 * common::CUBE_EDGE;
    let cube = RigidBlock::cuboid(
        "lead star",
        Vector::new(-h, -h, 0.0),
        Vector::new(h, h, common::CUBE_EDGE),
        1e13,
    )
    .expect("cube");
    let cube = model.add_block(cube).expect("cube");
    (model, base, cube)
}

/// A block of absurd density has a critical step of seconds (its springs are weak for its
/// mass): the step is cut to what keeps its fall within half the tolerance a step, and it
/// lands on its base instead of falling 1,928 m in one step of 9.45 s.
#[test]
fn an_absurdly_dense_block_gets_a_short_step() {
    let (mut model, _, cube) = dense_cube_on_slab(1e9);
    model.step().expect("step");
    let critical = model.critical_step().expect("critical").dt;
    println!("critical step {critical} s, step taken {} s", model.last_step());
    assert!(critical > 1.0, "the critical step is long: {critical}");
    assert!(model.last_step() < 0.011, "{}", model.last_step());
    let tolerance = model.parameters().contact.tolerance;
    // Every step moves the cube at most half the tolerance, until it has sunk so far into the
    // slab that the run stops (`a_block_sinking_through_its_base_stops_the_run`).
    for _ in 0..200 {
        let before = model.block(cube).expect("cube").state().pose.translation;
        match model.step() {
            Ok(()) => {}
            Err(Error::Overlap { .. }) => break,
            Err(e) => panic!("{e}"),
        }
        let moved = (model.block(cube).expect("cube").state().pose.translation - before).length();
        assert!(moved <= 0.5 * tolerance * 1.01, "moved {moved} m");
    }
}

/// A block the joints cannot carry (1e13 kg/m³ on 1 GPa/m springs) sinks into its base step by
/// short step: the run stops with `Error::Overlap` (naming both blocks) once they overlap by
/// half the cube's size, instead of reporting success with the cube a metre below its base.
#[test]
fn a_block_sinking_through_its_base_stops_the_run() {
    let (mut model, base, cube) = dense_cube_on_slab(1e9);
    match model.run_until_time(1.0) {
        Err(Error::Overlap {
            a,
            b,
            depth,
            limit,
            step,
        }) => {
            assert_eq!((a, b), (base, cube));
            assert!(
                depth > limit && limit > 0.08 && limit < 0.09,
                "depth {depth}, limit {limit}"
            );
            assert_eq!(step, model.step_count());
            let z = model.block(cube).expect("cube").state().pose.translation.z;
            assert!(z > 0.1 - 2.0 * limit, "stopped at z = {z}");
        }
        other => panic!("the sinking cube ran on: {other:?}"),
    }
    // The stiff joints a block of that weight needs hold it: 1e17 Pa/m.
    let (mut model, _, heavy) = dense_cube_on_slab(1e17);
    model.run_steps(300).expect("a carried block runs");
    let z = model.block(heavy).expect("cube").state().pose.translation.z;
    assert!((z - 0.1).abs() < 1e-2, "z = {z}");
}

/// A 0.2 m cube balanced on its edge (turned 45° about y) on a fixed slab, friction 40°,
/// pushed horizontally at its centroid: only the strip of its face within the contact
/// tolerance of the slab can carry force, so its capacity is that of a 1 mm wide base, about
/// W × 0.5 mm / 141 mm. The old limit analysis took the whole tilted face (a "covered faces"
/// contact) as a joint and answered W tan 40° = 0.839 W, where the DEM tips the cube over at
/// 0.05 W.
#[cfg(feature = "limit")]
#[test]
fn a_cube_on_its_edge_has_no_capacity_in_limit_analysis() {
    use voussoir::analysis::limit::{LimitOptions, LimitProblem, LiveLoad};
    let mut model = common::model(CoulombSlip::dry(1e9, 4e8, 40.0).expect("law"));
    model.add_block(common::fixed_slab("slab")).expect("slab");
    let a = common::CUBE_EDGE;
    let r = a / 2f64.sqrt();
    let mut vertices = Vec::new();
    for y in [-0.5 * a, 0.5 * a] {
        for (x, z) in [(0.0, 0.0), (r, r), (0.0, 2.0 * r), (-r, r)] {
            vertices.push(Vector::new(x, y, z));
        }
    }
    let cube = model
        .add_block(RigidBlock::from_vertices("on edge", &vertices, common::STONE_DENSITY).expect("cube"))
        .expect("cube");
    model.step().expect("detected");
    assert_eq!(model.contacts().count(), 1);
    let weight = common::STONE_DENSITY * a * a * a * 9.81;
    let problem = LimitProblem::from_model(&model).expect("problem");
    for (pair, corners) in problem.polygons() {
        println!("contact {pair:?}: corners {corners:?}");
    }
    // Pushed either way: towards the side of the face that the contact was found on (where
    // the old analysis took the whole face and answered sliding, W tan 40°), and away from it.
    for direction in [Vector::NEG_X, Vector::X] {
        let result = problem
            .solve(
                &[LiveLoad {
                    block: cube,
                    point: Vector::new(0.0, 0.0, r),
                    force: direction,
                }],
                &LimitOptions::default(),
            )
            .expect("solved");
        let ratio = result.multiplier / weight;
        println!("cube on its edge pushed along {direction}: λ = {ratio:.4e} W");
        // The strip is 0.7 mm wide in x; the lever arm of the weight about its far edge is
        // at most 0.7 mm against a height of 141 mm: λ ≤ 0.005 W.
        assert!(ratio.abs() < 0.01, "λ = {ratio} W");
    }
    // A cube flat on the slab keeps its capacity: W tan 40° by sliding (its overturning
    // capacity is W/2, above that).
    let mut flat = common::model(CoulombSlip::dry(1e9, 4e8, 40.0).expect("law"));
    flat.add_block(common::fixed_slab("slab")).expect("slab");
    let c = flat.add_block(common::cube("flat", Vector::ZERO)).expect("cube");
    flat.step().expect("detected");
    let result = LimitProblem::from_model(&flat)
        .expect("problem")
        .solve(
            &[LiveLoad {
                block: c,
                point: Vector::new(0.0, 0.0, 0.1),
                force: Vector::X,
            }],
            &LimitOptions::default(),
        )
        .expect("solved");
    let expected = 40f64.to_radians().tan();
    assert!(
        (result.multiplier / weight - expected).abs() < 1e-6,
        "{}",
        result.multiplier / weight
    );
}

/// Limit analysis messages: a model never stepped says no contact was detected yet (not that
/// the structure cannot carry its own weight); live loads of 1e-300 N and 1e300 N are solved
/// (their squares used to underflow to "zero" and overflow to "unbounded"), giving the same
/// capacity in their units; zero friction gives λ = 0, not −1.14e-24.
#[cfg(feature = "limit")]
#[test]
fn limit_analysis_messages_and_extreme_live_loads() {
    use voussoir::analysis::limit::{LimitOptions, LimitProblem, LiveLoad};
    let cube_on_slab = |phi: Real| {
        let mut model = common::model(CoulombSlip::dry(1e9, 4e8, phi).expect("law"));
        model.add_block(common::fixed_slab("slab")).expect("slab");
        let c = model.add_block(common::cube("cube", Vector::ZERO)).expect("cube");
        (model, c)
    };
    let (model, _) = cube_on_slab(30.0);
    let e = LimitProblem::from_model(&model).unwrap_err();
    assert!(
        matches!(e, Error::Unsupported { .. }) && e.to_string().contains("never detected"),
        "{e}"
    );
    let (mut model, cube) = cube_on_slab(30.0);
    model.step().expect("step");
    let problem = LimitProblem::from_model(&model).expect("problem");
    let weight = common::STONE_DENSITY * 0.008 * 9.81;
    let solve = |size: Real| {
        problem.solve(
            &[LiveLoad {
                block: cube,
                point: Vector::new(0.0, 0.0, 0.1),
                force: Vector::X * size,
            }],
            &LimitOptions::default(),
        )
    };
    let expected = 30f64.to_radians().tan() * weight;
    for size in [1e-300, 1.0, 1e300] {
        let r = solve(size).unwrap_or_else(|e| panic!("{size}: {e}"));
        let capacity = r.multiplier * size;
        assert!(
            (capacity - expected).abs() < 1e-6 * weight,
            "{size}: capacity {capacity} N, expected {expected}"
        );
    }
    let e = solve(1e-320).unwrap_err();
    assert!(matches!(e, Error::InvalidParameter { .. }), "{e}");
    let (mut model, cube) = cube_on_slab(0.0);
    model.step().expect("step");
    let r = LimitProblem::from_model(&model)
        .expect("problem")
        .solve(
            &[LiveLoad {
                block: cube,
                point: Vector::new(0.0, 0.0, 0.1),
                force: Vector::X,
            }],
            &LimitOptions::default(),
        )
        .expect("solved");
    // Zero to the solver's round-off on either side; below zero it is reported as 0, never
    // negative (it was −1.14e-24 before the clamp, and is 9.3e-28 with today's geometry).
    assert!(r.multiplier >= 0.0 && r.multiplier < 1e-12 * weight, "{}", r.multiplier);
}

/// A checkpoint whose tested pair's slack was raised and resealed is refused: the slack is
/// re-derived from the two shapes at the stored relative pose (it let a moving cube pass
/// through a fixed one). The honest slack loads.
#[test]
fn a_raised_slack_in_a_checkpoint_is_refused() {
    let params = ModelParameters {
        gravity: Vector::ZERO,
        ..ModelParameters::default()
    };
    let mut model = common::model_with(params, CoulombSlip::dry(1e9, 4e8, 30.0).expect("law"));
    model
        .add_block(common::cube("fixed", Vector::ZERO).with_fixity(Fixity::FIXED))
        .expect("fixed");
    // 1.2 mm apart along x: found apart with a slack of 0.2 mm.
    model
        .add_block(common::cube("free", Vector::new(0.2012, 0.0, 0.0)))
        .expect("free");
    model.step().expect("detected");
    let text = model.to_checkpoint_string().expect("checkpoint");
    Model::<CoulombSlip>::from_checkpoint_str(&text).expect("the honest checkpoint loads");
    let mut doc: serde_json::Value = serde_json::from_str(&text).expect("json");
    let slack = doc["tested"][0]["slack"].as_f64().expect("a slack");
    assert!((slack - 2e-4).abs() < 1e-9, "slack {slack}");
    doc["tested"][0]["slack"] = 1.0.into();
    let edited = voussoir::model::reseal_checkpoint(&doc.to_string()).expect("resealed");
    let e = Model::<CoulombSlip>::from_checkpoint_str(&edited).unwrap_err();
    assert!(
        matches!(&e, Error::Checkpoint { path, .. } if path == "tested[0].slack"),
        "{e}"
    );
    // Lowered (a conservative edit) it loads: the pair is only tested sooner.
    doc["tested"][0]["slack"] = 1e-4.into();
    let lowered = voussoir::model::reseal_checkpoint(&doc.to_string()).expect("resealed");
    Model::<CoulombSlip>::from_checkpoint_str(&lowered).expect("a lower slack loads");
}

/// Servo loading refuses, before its first step, what it used to run silently: a direction
/// along a translation that is not prescribed (20,000 steps without moving the plate), a block
/// with a base motion (which overrode the servo), an increment above half the contact
/// tolerance (1 mm a step drove a cube 66 mm into its base).
#[test]
fn servo_refuses_what_it_cannot_do() {
    use voussoir::loading::{BaseMotion, MotionKind, Servo, TimeHistory};
    let plate_model = |fixity: Fixity| {
        let mut model = common::model(CoulombSlip::dry(1e9, 4e8, 30.0).expect("law"));
        model.add_block(common::fixed_slab("base")).expect("slab");
        model.add_block(common::cube("cube", Vector::ZERO)).expect("cube");
        let plate = model
            .add_block(common::cube("plate", Vector::new(0.0, 0.0, common::CUBE_EDGE)).with_fixity(fixity))
            .expect("plate");
        (model, plate)
    };
    let mut none = |_: &Model| Ok::<_, Error>(std::ops::ControlFlow::Continue(()));
    // Only x prescribed, driven along z.
    let mut only_x = Fixity::FIXED;
    only_x.translation[0] = Dof::Velocity(0.0);
    let (mut model, plate) = plate_model(only_x);
    let servo = Servo::new(plate, Vector::NEG_Z, 1e-6, 1e-3).expect("servo");
    let e = servo.run(&mut model, 20_000, &mut none).unwrap_err();
    assert!(e.to_string().contains("along z"), "{e}");
    assert_eq!(model.step_count(), 0, "refused before stepping");
    // A base motion on the plate.
    let (mut model, plate) = plate_model(Fixity::velocity(Vector::ZERO));
    let shake = TimeHistory::sine(1.0, 2.0, 1.0, 20).expect("history");
    model
        .set_base_motion(
            plate,
            Some(BaseMotion::new(MotionKind::Acceleration, [Some(shake), None, None]).expect("motion")),
        )
        .expect("motion");
    let e = servo.run(&mut model, 10, &mut none).unwrap_err();
    assert!(e.to_string().contains("base motion"), "{e}");
    // An increment of the contact tolerance.
    let (mut model, plate) = plate_model(Fixity::velocity(Vector::ZERO));
    let coarse = Servo::new(plate, Vector::NEG_Z, 1e-3, 1e-3).expect("servo");
    let e = coarse.run(&mut model, 10, &mut none).unwrap_err();
    assert!(e.to_string().contains("half the contact tolerance"), "{e}");
    let fine = Servo::new(plate, Vector::NEG_Z, 5e-4, 1e-3).expect("servo");
    fine.run(&mut model, 10, &mut none)
        .expect("half the tolerance is accepted");
}
