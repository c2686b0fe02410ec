//! Joint-level stepping on the reference arch: its static case (settled, then the plate pushed
//! down) and an impact (settled, then the M60 impactor released just above voussoir 5) give the
//! poses and forces of the cell-by-cell step to round-off over 1,000 steps each. Each scene is
//! settled once and copied through a checkpoint (a restart continues bit for bit), so that the
//! copies start from the same state. Round-off is measured as in `tests/joint_stepping.rs`: the
//! cell-by-cell step run again with gravity changed by one ulp; poses must agree within 1e-9 m
//! (or 10 × that floor), forces within 10 × the floor.

use voussoir::block::{BlockId, Dof, Fixity};
use voussoir::model::JointStepping;
use voussoir::prelude::*;
use voussoir_arch::scenarios::arch_impact::{self, ImpactCase};
use voussoir_arch::scenarios::arch_static::{self, StaticCase};
use voussoir_arch::scenarios::impact_case::setups;

/// The largest differences between `a` and `b`: block positions (m), rotations (quaternion
/// components), and contact resultants over the largest resultant.
fn differences(a: &Model, b: &Model) -> [Real; 3] {
    let mut d = [0.0_f64; 3];
    for (x, y) in a.blocks().iter().zip(b.blocks()) {
        let (p, q) = (x.state().pose, y.state().pose);
        d[0] = d[0].max((p.translation - q.translation).length());
        let r = if p.rotation.dot(q.rotation) < 0.0 {
            -q.rotation
        } else {
            q.rotation
        };
        d[1] = d[1].max((p.rotation - r).length());
    }
    let (ca, cb): (Vec<_>, Vec<_>) = (a.contacts().collect(), b.contacts().collect());
    assert_eq!(ca.len(), cb.len(), "the same contacts");
    let scale = cb.iter().map(|c| c.resultant().length()).fold(1e-300, Real::max);
    for (x, y) in ca.iter().zip(&cb) {
        assert_eq!(x.blocks(), y.blocks());
        d[2] = d[2].max((x.wrench().force - y.wrench().force).length() / scale);
    }
    d
}

/// Three copies of the `settled` scene (joints stepped as a whole; cell by cell; cell by cell
/// with gravity one ulp heavier), driven alike by `drive` in `rounds` rounds, compared after
/// each.
fn agree(name: &str, settled: &Model, rounds: usize, mut drive: impl FnMut(&mut Model, usize)) {
    let text = settled.to_checkpoint_string().expect("save");
    let copy = || -> Model { Model::from_checkpoint_str(&text).expect("load") };
    let mut whole = copy();
    let mut cells = copy();
    cells.set_joint_stepping(JointStepping::Cells);
    let mut nudged = copy();
    nudged.set_joint_stepping(JointStepping::Cells);
    let mut params = *nudged.parameters();
    params.gravity.y *= 1.0 + Real::EPSILON;
    params.gravity.z *= 1.0 + Real::EPSILON;
    nudged.set_parameters(params).expect("parameters");
    let (mut worst, mut floor, mut stepped) = ([0.0_f64; 3], [0.0_f64; 3], 0);
    for round in 0..rounds {
        for m in [&mut whole, &mut cells, &mut nudged] {
            drive(m, round);
        }
        stepped = stepped.max(whole.whole_joint_count());
        for (k, (w, f)) in differences(&whole, &cells)
            .iter()
            .zip(differences(&nudged, &cells))
            .enumerate()
        {
            worst[k] = worst[k].max(*w);
            floor[k] = floor[k].max(f);
        }
    }
    println!("{name}: {worst:?} against cells, {floor:?} one ulp changed; up to {stepped} joints stepped whole");
    assert!(stepped > 0, "{name}: some joints are stepped as a whole");
    let close = |a: Real, b: Real| a < 1e-9 || a <= 10.0 * b;
    assert!(
        close(worst[0], floor[0]) && close(worst[1], floor[1]) && worst[2] <= 10.0 * floor[2] + 1e-12,
        "{name}: {worst:?} against cells, {floor:?} one ulp changed"
    );
}

/// The static arch's baseline, settled, and its plate.
fn settled_static_arch() -> (Model, BlockId) {
    let case = StaticCase::baseline();
    let mut built = arch_static::build(&case).expect("build");
    built
        .model
        .run_to_equilibrium(case.settle_ratio, 200_000)
        .expect("settle");
    (built.model, built.plate)
}

/// Pushes the plate down at 10 mm/s, free to roll.
fn push_plate(model: &mut Model, plate: BlockId) {
    let fixity = Fixity {
        translation: [Dof::Free, Dof::Velocity(-0.01), Dof::Fixed],
        rotation: [Dof::Fixed, Dof::Fixed, Dof::Free],
    };
    model.set_fixity(plate, fixity).expect("fixity");
}

#[test]
fn the_static_arch_agrees_with_its_cells() {
    let (model, plate) = settled_static_arch();
    agree("static arch", &model, 20, |m, round| {
        // 500 steps at rest, then 500 with the plate pushed down.
        if round == 10 {
            push_plate(m, plate);
        }
        m.run_steps(50).expect("run");
    });
}

#[test]
fn an_impact_agrees_with_its_cells() {
    let case = ImpactCase::baseline(setups()[0].clone());
    let mut built = arch_impact::build(&case).expect("build");
    built.model.run_to_equilibrium(1e-5, 200_000).expect("settle");
    let impactor = built.impactor;
    agree("impact", &built.model, 20, |m, round| {
        // 500 steps at rest, then the impactor released at 2 m/s with Rayleigh damping.
        if round == 10 {
            let guided = Fixity {
                translation: [Dof::Fixed, Dof::Free, Dof::Fixed],
                rotation: [Dof::Fixed; 3],
            };
            let free = if case.guide == voussoir_arch::scenarios::impact_case::ImpactorGuide::Frame {
                Fixity::FREE
            } else {
                guided
            };
            m.set_fixity(impactor, free).expect("fixity");
            m.set_velocity(impactor, Vector::new(0.0, -2.0, 0.0), Vector::ZERO)
                .expect("velocity");
            m.set_damping(Damping::rayleigh_stiffness(case.damping_ratio, case.damping_frequency).expect("damping"))
                .expect("damping");
        }
        m.run_steps(50).expect("run");
    });
}

/// The static arch pushed down by its plate opens most of its joints in part (hinges): they
/// are stepped as a whole, their closed and their open cells, but for the cells the line
/// `g = 0` crosses. Within
/// 2,000 steps of the push, more joints are stepped as a whole than are closed or open all
/// over, so hinges are among them, and the run agrees with its cells (the test above).
#[test]
fn the_static_arch_steps_its_hinges_as_a_whole() {
    let (mut model, plate) = settled_static_arch();
    push_plate(&mut model, plate);
    let mut hinges_whole = 0;
    for _ in 0..40 {
        model.run_steps(50).expect("run");
        let m = &model;
        let uniform = m
            .contacts()
            .filter(|c| {
                let open = c.subcontacts().filter(|s| s.status() == JointStatus::Open).count();
                open == 0 || open == c.subcontact_count()
            })
            .count();
        let mixed = m.contacts().count() - uniform;
        hinges_whole = m.whole_joint_count().saturating_sub(uniform).min(mixed);
        if hinges_whole > 0 {
            break;
        }
    }
    assert!(hinges_whole > 0, "no joint open in part was stepped as a whole");
    println!("{hinges_whole} joints open in part stepped as a whole");
    // A checkpoint taken while hinges are stepped as a whole stores their records and
    // continues bit for bit.
    let text = model.to_checkpoint_string().expect("save");
    assert!(text.contains("\"hinge\""), "no hinge record in the checkpoint");
    assert!(
        text.contains("\"open_before\"") || text.contains("\"open_after\""),
        "no hinge's open cells stepped as a whole in the checkpoint"
    );
    let mut restored: Model = Model::from_checkpoint_str(&text).expect("load");
    assert_eq!(restored.whole_joint_count(), model.whole_joint_count());
    model.run_steps(300).expect("run");
    restored.run_steps(300).expect("run");
    for (a, b) in model.blocks().iter().zip(restored.blocks()) {
        assert_eq!(a.state().pose, b.state().pose, "a restarted run differs");
    }
}
