//! Node contacts start unbonded (`ConstitutiveLaw::unbonded_state`, `docs/theory.md` §2.2): a
//! bonded law's tension and cohesion act across the faces of a joint, not at a vertex or an
//! edge. Where four blocks of a stack-bonded panel meet on an edge, the diagonal neighbours
//! touch along that edge only; bonded there, their nodes were held by a force that flips
//! between the two faces at the edge, and the panel did not settle.

use crate::common;

use voussoir::geometry::ContactKind;
use voussoir::law::{CoulombSlip, MortarJoint};
use voussoir::prelude::*;

/// Lourenço's bed joints of the J4D wall with the bricks' compliance (N/m³), and its strengths.
fn mortar() -> MortarJoint {
    MortarJoint::builder(6.27e10, 2.75e10, 36.87)
        .tension(2.5e5, 18.0)
        .cohesion(3.5e5, 125.0)
        .build()
        .expect("valid mortar joint")
}

/// Lourenço's potential cracks through the bricks: stiffer and stronger.
fn mortar_unit() -> MortarJoint {
    MortarJoint::builder(1.52e11, 6.6e10, 45.0)
        .tension(2e6, 80.0)
        .cohesion(2.8e6, 1000.0)
        .build()
        .expect("valid mortar joint")
}

fn coulomb_unit() -> CoulombSlip {
    CoulombSlip::new(1.52e11, 6.6e10, 45.0, 45.0, 2.8e6, 2e6).expect("valid Coulomb joint")
}

fn bonded_coulomb() -> CoulombSlip {
    CoulombSlip::new(6.27e10, 2.75e10, 36.87, 30.0, 3.5e5, 2.5e5).expect("valid Coulomb joint")
}

/// Pre-compression on the panel (Pa), as on the J4D wall.
const PRESSURE: Real = 3e5;
/// Units: 0.11 m long (x), 0.1 m thick (y), 0.0625 m high (z): the J4D wall's half bricks,
/// which its potential cracks through the bricks make a stack bond of.
const UNIT: (Real, Real, Real) = (0.11, 0.1, 0.0625);

/// A stack-bonded panel of `n × n` units on a fixed base, under a loaded top plate (free,
/// rotations fixed): `(n − 1)²` edges where four units meet. Every other vertical joint has
/// `unit_law` (the potential cracks through the J4D wall's bricks), the others `law`.
fn panel<L: ConstitutiveLaw>(law: L, unit_law: L, n: usize) -> (Model<L>, BlockId, BlockId) {
    let params = ModelParameters {
        time_step: TimeStep::Auto { safety: 0.8 },
        ..ModelParameters::default()
    };
    let mut model = common::model_with(params, law);
    model.set_damping(Damping::Local { alpha: 0.8 }).expect("damping");
    let (lx, ly, lz) = UNIT;
    let length = n as Real * lx;
    let base = model
        .add_block(
            RigidBlock::cuboid("base", Vector::new(0.0, 0.0, -lz), Vector::new(length, ly, 0.0), 2400.0)
                .expect("base")
                .with_fixity(Fixity::FIXED),
        )
        .expect("base");
    for row in 0..n {
        let mut left = None;
        for col in 0..n {
            let lo = Vector::new(col as Real * lx, 0.0, row as Real * lz);
            let id = model
                .add_block(
                    RigidBlock::cuboid(&format!("unit {row} {col}"), lo, lo + Vector::new(lx, ly, lz), 2000.0)
                        .expect("unit"),
                )
                .expect("unit");
            if (row + col) % 2 == 1 {
                if let Some(left) = left {
                    model.set_interface_law(left, id, unit_law.clone()).expect("unit law");
                }
            }
            left = Some(id);
        }
    }
    let top = n as Real * lz;
    let plate = model
        .add_block(
            RigidBlock::cuboid(
                "plate",
                Vector::new(0.0, 0.0, top),
                Vector::new(length, ly, top + lz),
                2000.0,
            )
            .expect("plate")
            .with_fixity(Fixity {
                translation: [Dof::Free; 3],
                rotation: [Dof::Fixed; 3],
            }),
        )
        .expect("plate");
    model
        .set_load(
            plate,
            Wrench {
                force: Vector::new(0.0, 0.0, -PRESSURE * length * ly),
                moment: Vector::ZERO,
            },
        )
        .expect("load");
    (model, base, plate)
}

/// The panel settles as a panel without four-block edges does, its base carries the load and
/// the weight, and the diagonal neighbours' node contacts carry no tension.
fn settles<L: ConstitutiveLaw>(law: L, unit_law: L, what: &str) {
    let n = 16;
    let (mut model, base, _) = panel(law, unit_law, n);
    // It settles in 1,638 steps (MortarJoint); with the diagonal nodes bonded, its ratio was
    // still 0.087 after 50,000.
    model.run_to_equilibrium(1e-5, 20_000).unwrap_or_else(|e| {
        panic!("{what}: the stack-bonded panel did not settle: {e}");
    });
    let nodes: Vec<_> = model
        .contacts()
        .filter(|c| matches!(c.kind(), ContactKind::Nodes))
        .collect();
    assert!(
        nodes.len() >= 2 * (n - 1) * (n - 1),
        "{what}: {} node contacts",
        nodes.len()
    );
    let (mut node_force, mut most_tension): (Real, Real) = (0.0, 0.0);
    for c in &nodes {
        for s in c.subcontacts() {
            node_force += s.normal_force().abs();
            most_tension = most_tension.max(-s.normal_force());
        }
    }
    assert_eq!(most_tension, 0.0, "{what}: a node contact carries tension");
    let (lx, ly, lz) = UNIT;
    // The units and the plate (n units long), 2000 kg/m³.
    let weight = 9.81 * 2000.0 * (n * n + n) as Real * lx * ly * lz;
    let load = PRESSURE * n as Real * lx * ly + weight;
    // The panel presses the base down.
    let reaction = -model.contact_wrench(base).expect("base").force.z;
    assert!(
        (reaction - load).abs() <= 1e-4 * load,
        "{what}: the base carries {reaction} N of {load} N"
    );
    // What the diagonal nodes press is the overlap of soft joints' corners, which under a
    // vertical load barely move into each other: 0.04 N (MortarJoint) and 0.08 N (CoulombSlip)
    // of the 56 kN the panel carries, measured; the faces carry the load.
    assert!(
        node_force < 1e-4 * load,
        "{what}: the node contacts carry {node_force} N of {load} N"
    );
}

#[test]
fn a_stack_bonded_mortar_panel_settles_and_its_corner_nodes_carry_no_tension() {
    settles(mortar(), mortar_unit(), "MortarJoint");
}

#[test]
fn a_stack_bonded_coulomb_panel_settles_and_its_corner_nodes_carry_no_tension() {
    settles(bonded_coulomb(), coulomb_unit(), "bonded CoulombSlip");
}

/// A cube standing on one edge (turned 45° about y) on a fixed slab, pressed 20 µm into it and
/// pulled 40 µm back at a prescribed velocity: its edge–face node contact carries compression
/// and lets go at zero gap, bonded law or not.
fn edge_contact_lets_go<L: ConstitutiveLaw>(law: L, what: &str) {
    let params = ModelParameters {
        gravity: Vector::ZERO,
        time_step: TimeStep::Fixed(1e-5),
        ..ModelParameters::default()
    };
    let mut model = common::model_with(params, law);
    model
        .add_block(
            RigidBlock::cuboid(
                "slab",
                Vector::new(-0.5, -0.5, -0.1),
                Vector::new(0.5, 0.5, 0.0),
                2400.0,
            )
            .expect("slab")
            .with_fixity(Fixity::FIXED),
        )
        .expect("slab");
    let half = 0.05;
    let turn = Pose::from_rotation(Rotation::from_rotation_y(std::f64::consts::FRAC_PI_4));
    let lift = Pose::from_translation(Vector::new(0.0, 0.0, half * std::f64::consts::SQRT_2));
    let speed = 0.2;
    let cube = model
        .add_block(
            RigidBlock::cuboid("cube", Vector::splat(-half), Vector::splat(half), 2400.0)
                .expect("cube")
                .transformed(turn)
                .transformed(lift)
                .with_fixity(Fixity::velocity(Vector::new(0.0, 0.0, -speed))),
        )
        .expect("cube");
    // Down 20 µm (10 steps of 2 µm), then up 40 µm.
    model.run_steps(10).expect("press");
    let pressed = model.contact_wrench(cube).expect("cube").force.z;
    assert!(pressed > 0.0, "{what}: the pressed edge carries {pressed} N");
    model
        .set_fixity(cube, Fixity::velocity(Vector::new(0.0, 0.0, speed)))
        .expect("reverse");
    let mut most_pull: Real = 0.0;
    for _ in 0..20 {
        model.step().expect("pull");
        most_pull = most_pull.max(-model.contact_wrench(cube).expect("cube").force.z);
    }
    assert_eq!(most_pull, 0.0, "{what}: the edge holds the cube down by {most_pull} N");
    let nodes = model
        .contacts()
        .filter(|c| matches!(c.kind(), ContactKind::Nodes))
        .count();
    assert!(nodes > 0, "{what}: no node contact");
}

#[test]
fn an_edge_on_a_face_carries_no_tension_under_a_bonded_law() {
    edge_contact_lets_go(mortar(), "MortarJoint");
    edge_contact_lets_go(bonded_coulomb(), "bonded CoulombSlip");
}
