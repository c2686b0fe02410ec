//! Quasi-static loading (`loading::Servo`): the answer follows the closed form and does not
//! depend on the loading speed or the threshold, where a plate driven at a constant speed
//! measures inertia.

use crate::common;

use std::ops::ControlFlow;

use voussoir::loading::Servo;
use voussoir::prelude::*;

const KN: f64 = 1e9;
const AREA: f64 = 0.04;

/// A 0.2 m cube on a fixed base, a plate resting on it (prescribed velocity, zero for now).
fn stack() -> (Model, BlockId, BlockId) {
    let mut model = common::model(CoulombSlip::dry(KN, KN, 30.0).expect("law"));
    model.set_damping(Damping::Local { alpha: 0.8 }).expect("damping");
    model.add_block(common::fixed_slab("base")).expect("base");
    let cube = model.add_block(common::cube("cube", Vector::ZERO)).expect("cube");
    let plate = model
        .add_block(
            RigidBlock::cuboid(
                "plate",
                Vector::new(-0.3, -0.3, 0.2),
                Vector::new(0.3, 0.3, 0.25),
                7800.0,
            )
            .expect("plate")
            .with_fixity(Fixity::velocity(Vector::ZERO)),
        )
        .expect("plate");
    (model, cube, plate)
}

/// The plate's force on the cube at travels of 20, 40, …, 100 µm (read once `settled` says so),
/// pushed by `drive`.
fn curve(
    settled: impl Fn(&Model) -> bool,
    drive: impl FnOnce(&mut Model, BlockId, &mut dyn FnMut(&Model) -> Result<ControlFlow<()>>),
) -> Vec<(f64, f64)> {
    let (mut model, cube, plate) = stack();
    let z0 = model.block(plate).expect("plate").state().pose.translation.z;
    let mut samples = Vec::new();
    let mut observe = |m: &Model| -> Result<ControlFlow<()>> {
        let travel = z0 - m.blocks()[plate.index()].state().pose.translation.z;
        if settled(m) && travel >= 2e-5 * (samples.len() + 1) as f64 {
            samples.push((travel, m.contact_between(cube, plate).map_or(0.0, |c| c.normal_force())));
        }
        Ok(if samples.len() == 5 {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        })
    };
    drive(&mut model, plate, &mut observe);
    assert_eq!(samples.len(), 5, "the run reached 100 µm of travel");
    samples
}

fn servo(increment: f64, ratio: f64) -> Vec<(f64, f64)> {
    servo_curve(Servo::new(BlockId(2), Vector::new(0.0, 0.0, -1.0), increment, ratio).expect("servo"))
}

fn servo_curve(servo: Servo) -> Vec<(f64, f64)> {
    curve(
        |m| servo.settled(m),
        |model, _plate, observe| {
            assert!(
                servo.run(model, 10_000_000, &mut |m: &Model| observe(m)).expect("run"),
                "stopped by the observer"
            );
        },
    )
}

/// Largest error of the force increments against `kn·A·Δδ/2` (two joints in series), relative
/// to the force range.
fn slope_error(c: &[(f64, f64)]) -> f64 {
    let (t0, f0) = c[0];
    let range = c[c.len() - 1].1 - f0;
    c.iter()
        .map(|&(t, f)| ((f - f0) - KN * AREA * (t - t0) / 2.0).abs() / range)
        .fold(0.0, f64::max)
}

#[test]
fn servo_loading_follows_the_static_answer_whatever_the_increment_and_threshold() {
    let fine = servo(0.05e-6, 1e-3);
    let coarse = servo(0.2e-6, 1e-3);
    let tight = servo(0.2e-6, 0.25e-3);
    for (name, c) in [("fine", &fine), ("coarse", &coarse), ("tight", &tight)] {
        let e = slope_error(c);
        println!(
            "{name}: slope error {:.3e}, forces {:?}",
            e,
            c.iter().map(|s| s.1).collect::<Vec<_>>()
        );
        // Read at settled states: the out-of-balance force is at most 1e-3 of the mean contact
        // force, and a sample falls up to one increment (0.2 µm of 20) past its travel.
        assert!(e < 0.01, "{name}: {e}");
    }
    // The answer at the same travel does not depend on the increment or the threshold: within
    // 1 %, and the force of one coarse increment (4 N). A sample's forces are those the step
    // computed before it moved the plate, which it may have just advanced by an increment: at
    // the first sample (300 N) that alone is 1.3 % (measured: 301.8 N coarse, 297.9 N tight).
    let increment_force = KN * AREA * 0.2e-6 / 2.0;
    for ((a, b), c) in fine.iter().zip(&coarse).zip(&tight) {
        let f = a.1.max(1.0);
        assert!((a.1 - b.1).abs() < 0.01 * f + increment_force, "{a:?} vs {b:?}");
        assert!((b.1 - c.1).abs() < 0.01 * f + increment_force, "{b:?} vs {c:?}");
    }
}

#[test]
fn a_plate_at_constant_speed_measures_inertia_that_the_servo_does_not() {
    let plain = curve(
        |_| true,
        |model, plate, observe| {
            model
                .set_prescribed_velocity(plate, Vector::new(0.0, 0.0, -1.0))
                .expect("velocity");
            assert!(model
                .run_observed(10_000_000, &mut |m: &Model| observe(m))
                .expect("run"));
        },
    );
    let servoed = servo(0.2e-6, 1e-3);
    let (e_plain, e_servo) = (slope_error(&plain), slope_error(&servoed));
    println!("plate at 1 m/s: slope error {e_plain:.3e}; servo: {e_servo:.3e}");
    assert!(e_servo < 0.01, "{e_servo}");
    assert!(e_plain > 5.0 * e_servo, "{e_plain} vs {e_servo}");
}

/// `Servo::check_convergence` runs the analysis and its refinement: the plate force at 100 µm
/// moves by far less than 1 % (two settled states of a linear problem), and both runs follow
/// the closed form.
#[test]
fn the_convergence_check_runs_the_refined_servo_too() {
    let servo = Servo::new(BlockId(2), Vector::new(0.0, 0.0, -1.0), 0.2e-6, 1e-3).expect("servo");
    let seen = std::sync::Mutex::new(Vec::new());
    let c = servo
        .check_convergence(|s| {
            seen.lock().expect("lock").push(s);
            let c = servo_curve(s);
            assert!(slope_error(&c) < 0.01, "{s:?}: {}", slope_error(&c));
            Ok(c[c.len() - 1].1)
        })
        .expect("check");
    let mut seen = seen.into_inner().expect("lock");
    seen.sort_by(|a, b| a.increment.total_cmp(&b.increment));
    assert_eq!(seen, [servo.refined(), servo]);
    println!("force at 100 µm: {} N, refined {} N", c.value, c.refined);
    assert!(c.converged(0.01), "{c:?}");
}
