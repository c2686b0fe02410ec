//! Sub-contact history through re-detection.
//!
//! A block sits on a base that moves at constant velocity (a conveyor), and a constant lateral
//! load below its friction capacity pushes it across the direction of travel. It sticks: the joint
//! carries the load as elastic shear in its springs. Both blocks travel, so contacts are
//! re-detected every `redetect_fraction × tolerance` = 0.25 mm. If re-detection lost the
//! sub-contacts' shear forces, the joint would drop the load and the block would slip by
//! `P/(ks·A)` each time until the springs reloaded.

use voussoir::prelude::*;

#[test]
fn a_stuck_joint_keeps_its_shear_force_through_redetection() -> Result<()> {
    let (phi_deg, rho, g) = (30.0_f64, 2500.0, 9.81);
    let mu = phi_deg.to_radians().tan();
    let mut model: Model = Model::new(ModelParameters::default())?;
    let (kn, ks) = (1e9, 4e8);
    model.set_joint_law(MaterialId(0), MaterialId(0), CoulombSlip::dry(kn, ks, phi_deg)?)?;
    let travel = Vector::new(0.0, 0.1, 0.0);
    let base = model.add_block(
        RigidBlock::cuboid(
            "conveyor",
            Vector::new(-0.5, -0.5, -0.2),
            Vector::new(0.5, 0.5, 0.0),
            rho,
        )?
        .with_fixity(Fixity::velocity(travel)),
    )?;
    let block = model.add_block(
        RigidBlock::cuboid("block", Vector::new(-0.1, -0.1, 0.0), Vector::new(0.1, 0.1, 0.1), rho)?
            .with_velocity(travel, Vector::ZERO),
    )?;
    let m = rho * 0.2 * 0.2 * 0.1;
    let push = 0.5 * mu * m * g;
    model.set_load(
        block,
        Wrench {
            force: Vector::new(push, 0.0, 0.0),
            moment: Vector::ZERO,
        },
    )?;
    // Settle with local damping (the default).
    model.run_until_time(0.05)?;
    let relative_x = |m: &Model| -> Result<f64> {
        Ok(m.block(block)?.state().pose.translation.x - m.block(base)?.state().pose.translation.x)
    };
    let x0 = relative_x(&model)?;
    let detections0 = model.detection_count();
    let mut worst_force_error: f64 = 0.0;
    let mut worst_slip: f64 = 0.0;
    while model.time() < 0.35 {
        model.step()?;
        let joint = model
            .contact_between(base, block)
            .expect("the block stays on the conveyor");
        worst_force_error = worst_force_error.max((joint.pair.resultant().x + push).abs());
        worst_slip = worst_slip.max((relative_x(&model)? - x0).abs());
    }
    let detections = model.detection_count() - detections0;
    // 30 mm of travel at 0.25 mm per detection.
    assert!(detections > 100, "only {detections} re-detections");
    // The joint keeps carrying the load (force on the block = −P). Tolerance: 1e-3 of P covers
    // the residual of the settling (unbalanced ratio at 0.05 s) — a lost history drops it by 100 %.
    assert!(
        worst_force_error < 1e-3 * push,
        "joint force off by {worst_force_error} N (load {push} N)"
    );
    // Elastic shear displacement P/(ks·A) = 2.5e-7 m; losing it once would show a slip of that size.
    let elastic = push / (ks * 0.04);
    assert!(
        worst_slip < 0.1 * elastic,
        "block slipped {worst_slip} m relative to the conveyor (elastic {elastic} m)"
    );
    Ok(())
}
