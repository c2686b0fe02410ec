//! Changing a model mid-run (laws, parameters, fixity) re-evaluates what depends on it
//! (regressions from a review: these changes used to be ignored silently).

mod common;

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

/// A fixed step above the limit set mid-run is an error, not ignored: at `set_parameters`
/// itself (which re-evaluates the step when no contact parameter changed, since 6f4a2b0), the
/// model keeping its parameters and stepping on.
#[test]
fn unsafe_fixed_step_set_mid_run_is_an_error() -> Result<()> {
    let (mut model, _) = cube_on_base()?;
    model.run_steps(10)?;
    let before = *model.parameters();
    let e = model.set_parameters(ModelParameters {
        time_step: TimeStep::Fixed(1.0),
        ..before
    });
    assert!(matches!(e, Err(Error::TimeStepTooLarge { .. })), "{e:?}");
    assert_eq!(*model.parameters(), before);
    model.step()?;
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
    model.step().expect("step");
    let added = model
        .add_block(common::cube("second", Vector::new(0.5, 0.0, 0.0)))
        .expect("added");
    assert_eq!(model.contact_wrench(added).expect("wrench"), Wrench::default());
    assert!(model.contact_wrench(base).expect("wrench").force.z < 0.0);
}
