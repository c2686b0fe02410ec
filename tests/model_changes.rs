//! Changing a model mid-run (laws, parameters, fixity) re-evaluates what depends on it
//! (regressions from a review: these changes used to be ignored silently).

use crate::common;

use voussoir::prelude::*;

/// A 0.2 m cube on the fixed slab (1 GPa/m joints, φ = 30°).
fn cube_on_base() -> Result<(Model, BlockId)> {
    let mut model = common::model(CoulombSlip::dry(1e9, 4e8, 30.0)?);
    model.add_block(common::fixed_slab("base"))?;
    let cube = model.add_block(common::cube("cube", Vector::ZERO))?;
    Ok((model, cube))
}

/// A stiffer law mid-run shortens the step (by √1000 for 1000× the stiffness) and the run stays
/// stable: the overlap left by the softer springs kicks the cube up, and it settles back.
#[test]
fn stiffer_law_mid_run_shortens_the_step() -> Result<()> {
    let (mut model, cube) = cube_on_base()?;
    model.run_steps(10)?;
    let before = model.dt();
    model.set_joint_law(MaterialId(0), MaterialId(0), CoulombSlip::dry(1e12, 4e11, 30.0)?)?;
    model.run_steps(200)?;
    model.run_to_equilibrium(1e-5, 200_000)?;
    let after = model.dt();
    assert!(
        (before / after - 1000f64.sqrt()).abs() < 0.05 * 1000f64.sqrt(),
        "dt {before} -> {after}"
    );
    let z = model.block(cube)?.state().pose.translation.z;
    // Settled on the stiff springs: the compression is W/(kn·A) = 1.2e-8 m.
    assert!((z - 0.1).abs() < 1e-6, "the cube must settle back on the base: z = {z}");
    Ok(())
}

/// A fixed step above the limit set mid-run is an error at once, and the parameters stay as
/// they were; set before the first step, at the first step.
#[test]
fn unsafe_fixed_step_set_mid_run_is_an_error() -> Result<()> {
    let (mut model, _) = cube_on_base()?;
    model.run_steps(10)?;
    let before = *model.parameters();
    let unsafe_step = ModelParameters {
        time_step: TimeStep::Fixed(1.0),
        ..before
    };
    assert!(matches!(
        model.set_parameters(unsafe_step),
        Err(Error::TimeStepTooLarge { .. })
    ));
    assert_eq!(*model.parameters(), before);
    model.run_steps(10)?;
    let (mut fresh, _) = cube_on_base()?;
    fresh.set_parameters(unsafe_step)?;
    assert!(matches!(fresh.step(), Err(Error::TimeStepTooLarge { .. })));
    Ok(())
}

/// A block released from a fixed state while touching another fixed block gets its contact at
/// once (contacts between two fixed blocks are not kept).
#[test]
fn released_block_finds_its_contact_at_once() -> Result<()> {
    let (mut model, cube) = cube_on_base()?;
    model.set_fixity(cube, Fixity::FIXED)?;
    model.run_steps(5)?;
    assert_eq!(model.contacts().len(), 0);
    model.set_fixity(cube, Fixity::FREE)?;
    model.step()?;
    assert_eq!(model.contacts().len(), 1);
    Ok(())
}

/// The contact wrench of a block the model has not detected contacts for yet (before the first
/// step, or a block added since) is zero, not an index out of bounds (found by the scene fuzzer).
#[test]
fn contact_wrench_before_detection_is_zero() {
    let mut model = common::model(CoulombSlip::dry(1e9, 1e9, 30.0).expect("law"));
    let base = model.add_block(common::fixed_slab("base")).expect("base");
    let cube = model.add_block(common::cube("cube", Vector::ZERO)).expect("cube");
    assert_eq!(model.contact_wrench(cube).expect("wrench"), Wrench::default());
    // The cube is built exactly touching (zero gap, an open joint): it presses from the
    // second step on, once gravity has moved it.
    model.run_steps(2).expect("steps");
    let added = model
        .add_block(common::cube("second", Vector::new(0.5, 0.0, 0.0)))
        .expect("added");
    assert_eq!(model.contact_wrench(added).expect("wrench"), Wrench::default());
    assert!(model.contact_wrench(base).expect("wrench").force.z < 0.0);
}

/// The block pairs in contact, in order.
fn contact_pairs(model: &Model) -> Vec<(BlockId, BlockId)> {
    model.contacts().map(|c| c.blocks()).collect()
}

/// A change of fixity looks at the block's own pairs, not at every pair of the model (a full
/// detection of a 100k-block wall took seconds per `set_fixity`), and gives the contacts a full
/// detection gives: fixing a brick of the first course drops its contacts with the fixed base,
/// releasing it again finds them at once.
#[test]
fn fixity_change_re_detects_the_blocks_pairs_only() -> Result<()> {
    let mut model = voussoir::scenes::benchmark_wall(300)?;
    model.run_steps(3)?;
    let before = contact_pairs(&model);
    // A brick of the first course (on the base, between two bricks, under two).
    let first_course = |m: &Model| {
        m.blocks()
            .iter()
            .position(|b| !b.fixity().is_fixed() && b.state().pose.translation.z < 0.1)
            .map(|i| BlockId(i as u32))
    };
    let brick = first_course(&model).expect("a brick of the first course");
    // The brick's contacts with fixed blocks.
    let touches_fixed = |m: &Model| {
        m.contacts()
            .filter_map(|c| match c.blocks() {
                (a, other) | (other, a) if a == brick => Some(other),
                _ => None,
            })
            .filter(|other| m.blocks()[other.0 as usize].fixity().is_fixed())
            .count()
    };
    let on_fixed = touches_fixed(&model);
    assert!(on_fixed >= 1, "the brick stands on the base");
    let (tests, detections) = (model.pair_tests(), model.detection_count());
    model.set_fixity(brick, Fixity::FIXED)?;
    model.step()?;
    let tested = model.pair_tests() - tests;
    assert_eq!(
        model.detection_count(),
        detections + 1,
        "one detection follows the change"
    );
    // The brick did not move: its pairs keep their verdicts, and those with fixed blocks are
    // dropped without a test.
    assert!(
        tested <= 8,
        "{tested} pairs tested of {} contacts: only the brick's",
        before.len()
    );
    // The contacts a full detection finds: a wall built with the brick fixed from the start.
    let mut fresh = voussoir::scenes::benchmark_wall(300)?;
    assert_eq!(first_course(&fresh), Some(brick));
    fresh.set_fixity(brick, Fixity::FIXED)?;
    fresh.run_steps(4)?;
    assert_eq!(contact_pairs(&model), contact_pairs(&fresh));
    assert_eq!(touches_fixed(&model), 0, "its contacts with fixed blocks are gone");
    model.set_fixity(brick, Fixity::FREE)?;
    model.step()?;
    assert_eq!(
        touches_fixed(&model),
        on_fixed,
        "the released brick finds the base at once"
    );
    let mut free = voussoir::scenes::benchmark_wall(300)?;
    free.run_steps(5)?;
    assert_eq!(contact_pairs(&model), contact_pairs(&free));
    assert!(contact_pairs(&model).len() >= before.len());
    Ok(())
}

/// Parameters that leave the contacts as they are (the same ones, or new gravity) detect
/// nothing; new contact parameters detect every contact afresh.
#[test]
fn parameters_re_detect_only_when_the_contacts_change() -> Result<()> {
    let mut model = voussoir::scenes::benchmark_wall(300)?;
    model.run_steps(3)?;
    let tests = model.pair_tests();
    let p = *model.parameters();
    model.set_parameters(p)?;
    model.step()?;
    model.set_parameters(ModelParameters {
        gravity: p.gravity * 1.01,
        ..p
    })?;
    model.step()?;
    assert_eq!(model.pair_tests(), tests, "no pair tested afresh");
    model.set_parameters(ModelParameters {
        contact: ContactParameters {
            tolerance: p.contact.tolerance * 1.01,
            ..p.contact
        },
        ..p
    })?;
    model.step()?;
    assert!(
        model.pair_tests() - tests >= model.contacts().len() as u64,
        "a full detection"
    );
    Ok(())
}

/// **A switch to small displacements detects every contact afresh** (`Model::set_parameters`):
/// the geometry small displacements keep is then the switch's for every contact, where before
/// each contact kept that of its own last detection in large displacements (the wall settles
/// for 300 steps first, re-detecting as it sags). In small displacements, new gravity detects
/// nothing, and new contact parameters detect afresh again.
#[test]
fn a_switch_to_small_displacements_detects_afresh() -> Result<()> {
    let mut model = voussoir::scenes::benchmark_wall(300)?;
    model.run_steps(300)?;
    let detections = model.detection_count();
    let p = *model.parameters();
    let small = ModelParameters {
        mode: DisplacementMode::Small,
        ..p
    };
    model.set_parameters(small)?;
    model.step()?;
    assert_eq!(model.detection_count(), detections + 1, "detected at the switch");
    model.run_steps(20)?;
    assert_eq!(model.detection_count(), detections + 1, "and not again");
    let tests = model.pair_tests();
    model.set_parameters(ModelParameters {
        gravity: p.gravity * 1.01,
        ..small
    })?;
    model.step()?;
    assert_eq!(model.pair_tests(), tests, "no pair tested afresh for new gravity");
    model.set_parameters(ModelParameters {
        contact: ContactParameters {
            tolerance: p.contact.tolerance * 1.01,
            ..p.contact
        },
        ..small
    })?;
    model.step()?;
    assert!(
        model.pair_tests() - tests >= model.contacts().len() as u64,
        "a full detection for new contact parameters"
    );
    Ok(())
}

/// An interrupt check that fires stops the step before it changes anything: the model's state
/// (blocks, contacts, energies, clock) is as before, and the run goes on afterwards.
#[test]
fn interrupted_step_leaves_the_model_as_it_was() -> Result<()> {
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::Arc;
    use voussoir::model::InterruptCheck;

    // A wall shaken on its base, so that its steps re-detect contacts.
    let mut model = voussoir::scenes::shaking_wall(300, voussoir::scenes::BENCHMARK_SPACING)?;
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    model.set_interrupt_check(Some(InterruptCheck::new(move || flag.load(Ordering::Relaxed))));
    model.run_steps(300)?;
    stop.store(true, Ordering::Relaxed);
    // Steps until one detects (and is interrupted); the others run as usual.
    let mut interrupted = None;
    for _ in 0..200 {
        let before = common::fingerprint(&model);
        match model.step() {
            Ok(()) => {}
            Err(Error::Interrupted { step }) => {
                assert_eq!(step, model.step_count());
                assert!(
                    common::fingerprint(&model) == before,
                    "the interrupted step changed the model"
                );
                interrupted = Some(step);
                break;
            }
            Err(e) => return Err(e),
        }
    }
    assert!(interrupted.is_some(), "no step detected contacts in 200 steps");
    stop.store(false, Ordering::Relaxed);
    let detections = model.detection_count();
    model.run_steps(50)?;
    assert!(model.detection_count() > detections);
    Ok(())
}

/// A push-over whose servo waits for a balance it never reaches (threshold 1e-300) stops within
/// a few steps of the interrupt check firing, with the model as before the step it was about to
/// take: the check is asked before every step (every 20 ms at most), not only in detections,
/// which a resting model does not run. It ran to `max_steps` (minutes) before.
#[test]
fn a_push_over_waiting_for_its_servo_stops_when_interrupted() -> Result<()> {
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::Arc;
    use std::time::{Duration, Instant};
    use voussoir::loading::{PushOver, Servo};
    use voussoir::model::InterruptCheck;

    // `PushOver`'s example: a cube on a base, pushed by a block whose x translation is
    // prescribed.
    let mut model: Model = Model::new(ModelParameters::default())?;
    model.set_joint_law(MaterialId(0), MaterialId(0), CoulombSlip::dry(1e9, 4e8, 30.0)?)?;
    model.set_joint_law(MaterialId(0), MaterialId(1), CoulombSlip::dry(1e9, 4e8, 0.0)?)?;
    model.add_block(
        RigidBlock::cuboid(
            "base",
            Vector::new(-1.0, -1.0, -0.2),
            Vector::new(1.0, 1.0, 0.0),
            2500.0,
        )?
        .with_fixity(Fixity::FIXED),
    )?;
    model.add_block(RigidBlock::cuboid("cube", Vector::ZERO, Vector::splat(0.2), 2500.0)?)?;
    let pusher = model.add_block(
        RigidBlock::cuboid(
            "pusher",
            Vector::new(-0.1, 0.05, 0.05),
            Vector::new(0.0, 0.15, 0.15),
            2500.0,
        )?
        .with_material(MaterialId(1))
        .with_fixity(Fixity::velocity(Vector::ZERO)),
    )?;
    model.run_steps(200)?;
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    model.set_interrupt_check(Some(InterruptCheck::new(move || flag.load(Ordering::Relaxed))));
    let setter = std::thread::spawn(move || {
        std::thread::sleep(Duration::from_millis(300));
        stop.store(true, Ordering::Relaxed);
        Instant::now()
    });
    let push = PushOver::new(Servo::new(pusher, Vector::X, 1e-6, 1e-300)?);
    let outcome = push.run(&mut model, 50_000_000, |_, _| std::ops::ControlFlow::Continue(()));
    let stopped = Instant::now();
    let sent = setter.join().unwrap();
    let step = model.step_count();
    assert!(
        matches!(outcome, Err(Error::Interrupted { step: s }) if s == step),
        "{outcome:?} at step {step}"
    );
    let late = stopped.duration_since(sent);
    assert!(
        late < Duration::from_millis(500),
        "stopped {late:?} after the check fired"
    );
    // Without the check firing, it goes on.
    model.set_interrupt_check(None);
    model.run_steps(3)?;
    assert_eq!(model.step_count(), step + 3);
    Ok(())
}

/// A block added to a running model 5 mm into another is refused, as the same layout is at the
/// start (it was launched: both blocks thrown up); one added clear of the others is taken.
#[test]
fn a_block_added_into_another_after_the_first_step_is_refused() -> Result<()> {
    let mut model = common::model(CoulombSlip::dry(1e9, 4e8, 30.0)?);
    model.add_block(common::fixed_slab("base"))?;
    model.add_block(common::cube("cube", Vector::ZERO))?;
    model.run_steps(20)?;
    let blocks = model.blocks().len();
    let into = common::cube("into the base", Vector::new(0.5, 0.0, -0.005));
    let err = model.add_block(into.clone()).expect_err("overlapping by 5 mm");
    let Error::AddedBlockOverlap { other, depth, .. } = &err else {
        panic!("expected AddedBlockOverlap, got {err:?}")
    };
    assert_eq!(*other, BlockId(0), "{err}");
    assert!((depth - 0.005).abs() < 1e-9, "{err}");
    assert!(err.to_string().contains("into the base"), "{err}");
    assert_eq!(model.blocks().len(), blocks, "nothing added");
    model.run_steps(5)?;
    // Within the tolerance (1 mm), and clear: taken.
    model.add_block(common::cube("touching", Vector::new(0.5, 0.0, -0.0005)))?;
    model.add_block(common::cube("clear", Vector::new(-0.5, 0.0, 0.001)))?;
    model.run_steps(5)?;
    // Before the first step the same layout is refused by the first step.
    let mut fresh = common::model(CoulombSlip::dry(1e9, 4e8, 30.0)?);
    fresh.add_block(common::fixed_slab("base"))?;
    fresh.add_block(into)?;
    assert!(matches!(fresh.step(), Err(Error::InitialOverlap { .. })));
    Ok(())
}

/// Probe 3, F11: `run_to_equilibrium` on a model with nothing free says so at once (it ran all
/// its steps, then reported "last value inf").
#[test]
fn equilibrium_of_a_model_with_nothing_free_is_refused_at_once() -> Result<()> {
    let mut model = common::model(CoulombSlip::dry(1e9, 4e8, 30.0)?);
    model.add_block(common::fixed_slab("base"))?;
    model.add_block(common::cube("held", Vector::ZERO).with_fixity(Fixity::FIXED))?;
    let err = model.run_to_equilibrium(1e-4, 1_000_000).expect_err("nothing free");
    assert!(
        matches!(err, Error::Unsupported { .. }) && err.to_string().contains("no block has a free"),
        "{err}"
    );
    assert_eq!(model.step_count(), 0);
    model.set_fixity(BlockId(1), Fixity::FREE)?;
    model.run_to_equilibrium(1e-3, 100_000)?;
    Ok(())
}
