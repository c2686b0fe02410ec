//! Sub-contact history through re-detection.
//!
//! A block sits on a base that moves at constant velocity (a conveyor), and a constant lateral
//! load below its friction capacity pushes it across the direction of travel. It sticks: the joint
//! carries the load as elastic shear in its springs. Both blocks travel, so contacts are
//! re-detected every `redetect_fraction × tolerance` = 0.25 mm. If re-detection lost the
//! sub-contacts' shear forces, the joint would drop the load and the block would slip by
//! `P/(ks·A)` each time until the springs reloaded.

use crate::common;

use voussoir::prelude::*;

#[test]
fn a_stuck_joint_keeps_its_shear_force_through_redetection() -> Result<()> {
    let (phi_deg, rho, g) = (30.0_f64, 2500.0, 9.81);
    let mu = phi_deg.to_radians().tan();
    let (kn, ks) = (1e9, 4e8);
    let mut model = common::model(CoulombSlip::dry(kn, ks, phi_deg)?);
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
        worst_force_error = worst_force_error.max((joint.resultant().x + push).abs());
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

/// The same for point (edge–face) contacts: a beam rests on the ridges of two triangular prisms
/// that travel on a conveyor, and a push along the ridges, half its friction capacity, is carried
/// by the edge contacts' shear springs. A point contact's body-frame normal changes between
/// re-detections as soon as its block turns by round-off, and history must still carry by key.
#[test]
fn a_stuck_edge_contact_keeps_its_shear_force_through_redetection() -> Result<()> {
    let (phi_deg, rho, g) = (30.0_f64, 2500.0, 9.81);
    let mu = phi_deg.to_radians().tan();
    let mut model = common::model(CoulombSlip::dry(1e9, 4e8, phi_deg)?);
    let travel = Vector::new(0.0, 0.1, 0.0);
    let prism = |name: &str, y: Real| -> Result<RigidBlock> {
        let v = [
            Vector::new(-0.3, y - 0.05, 0.0),
            Vector::new(0.3, y - 0.05, 0.0),
            Vector::new(-0.3, y + 0.05, 0.0),
            Vector::new(0.3, y + 0.05, 0.0),
            Vector::new(-0.3, y, 0.1),
            Vector::new(0.3, y, 0.1),
        ];
        Ok(RigidBlock::from_vertices(name, &v, rho)?.with_fixity(Fixity::velocity(travel)))
    };
    let left = model.add_block(prism("left ridge", -0.2)?)?;
    let right = model.add_block(prism("right ridge", 0.2)?)?;
    let beam = model.add_block(
        RigidBlock::cuboid("beam", Vector::new(-0.2, -0.3, 0.1), Vector::new(0.2, 0.3, 0.15), rho)?
            .with_velocity(travel, Vector::ZERO),
    )?;
    let m = rho * 0.4 * 0.6 * 0.05;
    let push = 0.5 * mu * m * g;
    model.set_load(
        beam,
        Wrench {
            force: Vector::new(push, 0.0, 0.0),
            moment: Vector::ZERO,
        },
    )?;
    // Settle under the push, then travel 60 mm: hundreds of re-detections.
    model.run_until_time(0.2)?;
    let kinds = |model: &Model| [left, right].map(|r| model.contact_between(r, beam).map(|c| c.kind()));
    assert!(
        kinds(&model)
            .iter()
            .all(|k| matches!(k, Some(voussoir::geometry::ContactKind::Nodes))),
        "edge contacts: {:?}",
        kinds(&model)
    );
    let x0 = model.block(beam)?.state().pose.translation.x;
    let detections = model.detection_count();
    model.run_until_time(0.8)?;
    let redetected = model.detection_count() - detections;
    let slip = model.block(beam)?.state().pose.translation.x - x0;
    assert!(redetected > 100, "{redetected} re-detections");
    // Sticking: the beam creeps by 2e-10 m over 236 re-detections. When a re-detection drops
    // the edge contacts' history (as it did while the body-frame normal was compared), the
    // springs reload from zero each time and the beam slips 6.9 mm.
    assert!(slip.abs() < 1e-5, "slip {slip:.3e} m over {redetected} re-detections");
    Ok(())
}
