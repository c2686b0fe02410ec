//! The capacity driver (`loading::PushOver`) against a closed form: a block pushed sideways by
//! a frictionless pusher slides when the push reaches the base joint's friction, `tan φ · W`.

use crate::common;

use std::ops::ControlFlow;

use voussoir::loading::{PushOver, PushOverStop, Servo};
use voussoir::prelude::*;

/// A 0.2 m cube on a fixed base (φ 30°) and a pusher at its mid-height, frictionless against it.
fn pushed_cube() -> (Model, BlockId, Real) {
    let mut model: Model = Model::new(ModelParameters::default()).expect("model");
    model
        .set_joint_law(
            MaterialId(0),
            MaterialId(0),
            CoulombSlip::dry(1e9, 4e8, 30.0).expect("law"),
        )
        .expect("law");
    model
        .set_joint_law(
            MaterialId(0),
            MaterialId(1),
            CoulombSlip::dry(1e9, 4e8, 0.0).expect("law"),
        )
        .expect("law");
    model.set_damping(Damping::Local { alpha: 0.8 }).expect("damping");
    model.add_block(common::fixed_slab("base")).expect("base");
    model
        .add_block(RigidBlock::cuboid("cube", Vector::ZERO, Vector::splat(0.2), 2500.0).expect("cube"))
        .expect("cube");
    let pusher = model
        .add_block(
            RigidBlock::cuboid(
                "pusher",
                Vector::new(-0.1, 0.05, 0.05),
                Vector::new(0.0, 0.15, 0.15),
                2500.0,
            )
            .expect("pusher")
            .with_material(MaterialId(1))
            .with_fixity(Fixity::velocity(Vector::ZERO)),
        )
        .expect("pusher");
    model.run_to_equilibrium(1e-5, 100_000).expect("settles");
    let weight = 2500.0 * 0.008 * 9.81;
    (model, pusher, 30f64.to_radians().tan() * weight)
}

/// The peak is the sliding load: within 1 % (measured −0.6 %). Once the cube slides, each
/// advance slips it and the settled state after the slip holds a shear spring that has relaxed
/// a little: the settled states form a sawtooth just below `tan φ · W` (their average over
/// 0.1 mm of travel: −2 %), whose top is the capacity. Halving the increment and the threshold
/// moves the peak by less than 1 %.
#[test]
fn a_pushed_cube_slides_at_its_friction_load() {
    let run = |servo: Servo| {
        let (mut model, _, _) = pushed_cube();
        let push = PushOver {
            max_travel: 1e-3,
            ..PushOver::new(Servo {
                block: BlockId(2),
                ..servo
            })
        };
        push.run(&mut model, 10_000_000, |_, _| ControlFlow::Continue(()))
    };
    let (_, pusher, sliding) = pushed_cube();
    let servo = Servo::new(pusher, Vector::X, 2e-6, 1e-3).expect("servo");
    let r = run(servo).expect("runs");
    println!(
        "peak {:.2} N at {:.3} mm (raw {:.2}), tan φ W = {sliding:.2} N, {} samples",
        r.peak_load,
        r.travel_at_peak * 1e3,
        r.raw_peak_load,
        r.curve.len()
    );
    assert_eq!(r.stop, PushOverStop::MaxTravel);
    assert!(
        (r.peak_load / sliding - 1.0).abs() < 0.01,
        "{} vs {sliding}",
        r.peak_load
    );
    // The curve rises, then holds the plateau to the end: the mean of the last 100 settled
    // states lies within 3 % below the sliding load (the sawtooth).
    let tail = &r.curve[r.curve.len() - 100..];
    let mean = tail.iter().map(|s| s.load).sum::<Real>() / 100.0;
    println!(
        "mean of the last 100: {mean:.2} N ({:.2} %)",
        100.0 * (mean / sliding - 1.0)
    );
    assert!(r.curve.last().expect("samples").travel >= 1e-3);
    assert!(mean < sliding && mean > 0.97 * sliding, "{mean}");
    let c = servo.check_convergence(|s| run(s).map(|r| r.peak_load)).expect("runs");
    println!("refined {:.2} N: {:.3} %", c.refined, 100.0 * c.relative_change());
    assert!(c.converged(0.01), "{c:?}");
}

/// The sample callback sees each settled state and may stop the run; bad settings are refused
/// before a step.
#[test]
fn the_callback_stops_and_bad_settings_are_refused() {
    let (mut model, pusher, _) = pushed_cube();
    let push = PushOver::new(Servo::new(pusher, Vector::X, 2e-6, 1e-3).expect("servo"));
    let mut seen = 0;
    let r = push
        .run(&mut model, 10_000_000, |_, s| {
            seen += 1;
            assert!(s.travel >= 0.0);
            if seen == 5 {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        })
        .expect("runs");
    assert_eq!((r.stop, r.curve.len()), (PushOverStop::Callback, 5));
    let steps = model.step_count();
    for bad in [
        PushOver {
            max_travel: 0.0,
            ..push
        },
        PushOver {
            stop_fraction: 1.0,
            ..push
        },
        PushOver {
            smoothing_window: Real::NAN,
            ..push
        },
    ] {
        assert!(matches!(
            bad.run(&mut model, 10, |_, _| ControlFlow::Continue(())),
            Err(Error::InvalidParameter { .. })
        ));
    }
    assert_eq!(model.step_count(), steps, "nothing stepped");
}

/// A push-over whose only moving block is the pushed one is refused: the servo advances from
/// states settled by the free blocks' unbalanced-force ratio, and with no free block every
/// state would count as settled (driven along its own joint, such a block's samples caught the
/// joint ringing: 0.79 W against the 0.577 W it slides at).
#[test]
fn a_push_over_without_free_blocks_is_refused() {
    let (mut model, pusher, _) = pushed_cube();
    // The cube fixed: the pusher is the only block that could move.
    model.set_fixity(BlockId(1), Fixity::FIXED).expect("fixity");
    let push = PushOver::new(Servo::new(pusher, Vector::X, 2e-6, 1e-3).expect("servo"));
    let steps = model.step_count();
    let r = push.run(&mut model, 1000, |_, _| ControlFlow::Continue(()));
    assert!(matches!(r, Err(Error::Unsupported { .. })), "{r:?}");
    assert_eq!(model.step_count(), steps, "nothing stepped");
}
