//! Fixtures shared by the integration tests (one crate, `tests/integration.rs`): a test file
//! that uses them says `use crate::common;`.
//!
//! Only what several files build the same way lives here: the fixed 2 m slab that most single-
//! block tests stand on, the 0.2 m stone cube, a model with one joint law for material 0, and
//! the bit fingerprints that the determinism, checkpoint and mixed-law tests compare. A test
//! whose setup differs (another size, density, material or placement) keeps its own.

// Each test file is its own crate and uses only some of the fixtures.
#![allow(dead_code)]

use voussoir::contact::ContactView;
use voussoir::prelude::*;

/// Density of stone (kg/m³), of the slab and the cube.
pub const STONE_DENSITY: Real = 2500.0;

/// Edge of the stone cube (m).
pub const CUBE_EDGE: Real = 0.2;

/// A model with `params` and `law` for the joints between blocks of material 0 (the default
/// material).
pub fn model_with<L: ConstitutiveLaw>(params: ModelParameters, law: L) -> Model<L> {
    let mut model = Model::new(params).expect("valid model parameters");
    model
        .set_joint_law(MaterialId(0), MaterialId(0), law)
        .expect("valid joint law");
    model
}

/// A model with the default parameters and `law` for the joints between blocks of material 0.
pub fn model<L: ConstitutiveLaw>(law: L) -> Model<L> {
    model_with(ModelParameters::default(), law)
}

/// A fixed 2 m × 2 m × 0.2 m stone slab named `name`, centred on the z axis, whose top face is
/// the plane z = 0.
pub fn fixed_slab(name: &str) -> RigidBlock {
    RigidBlock::cuboid(
        name,
        Vector::new(-1.0, -1.0, -0.2),
        Vector::new(1.0, 1.0, 0.0),
        STONE_DENSITY,
    )
    .expect("valid slab")
    .with_fixity(Fixity::FIXED)
}

/// The stone cube [`cube`] at the origin turned by `tilt` (rad) about x then about y (about its
/// centroid), its lowest corner `height` above the plane z = 0: a cube to drop on the slab.
pub fn tilted_cube(name: &str, tilt: (Real, Real), height: Real) -> RigidBlock {
    let turn = Rotation::from_rotation_y(tilt.1) * Rotation::from_rotation_x(tilt.0);
    let block = cube(name, Vector::ZERO);
    let centre = block.state().pose.translation;
    let h = 0.5 * CUBE_EDGE;
    let corners = voussoir::block::cuboid_corners(Vector::splat(-h), Vector::splat(h));
    let lowest = corners.iter().map(|c| (turn * *c).z).fold(Real::INFINITY, Real::min);
    let lift = Vector::new(0.0, 0.0, height - lowest - centre.z);
    let pose = Pose::from_parts(centre + lift, turn) * Pose::from_translation(-centre);
    block.transformed(pose)
}

/// A free, axis-aligned 0.2 m stone cube named `name` whose bottom face is centred on `at`.
pub fn cube(name: &str, at: Vector) -> RigidBlock {
    let h = 0.5 * CUBE_EDGE;
    RigidBlock::cuboid(
        name,
        at - Vector::new(h, h, 0.0),
        at + Vector::new(h, h, CUBE_EDGE),
        STONE_DENSITY,
    )
    .expect("valid cube")
}

/// Every bit of the state that a run produces: the clock (time, step, step count), the
/// detection count, every block's state, every contact (see [`push_contact`]) and every energy
/// term. Two models are in the same state when their fingerprints are equal.
pub fn fingerprint<L: ConstitutiveLaw>(model: &Model<L>) -> Vec<u64> {
    let mut bits = vec![
        model.time().to_bits(),
        model.dt().to_bits(),
        model.step_count(),
        model.detection_count(),
        model.subcontact_count() as u64,
    ];
    for block in model.blocks() {
        push_block(&mut bits, block);
    }
    for contact in model.contacts() {
        push_contact(&mut bits, &contact);
    }
    let e = model.energies();
    bits.extend(
        [
            e.kinetic,
            e.initial_kinetic,
            e.elastic,
            e.gravity_work,
            e.load_work,
            e.boundary_work,
            e.friction,
            e.damping,
            e.joint_work,
        ]
        .map(f64::to_bits),
    );
    bits
}

/// The bits of the states of the blocks `ids` and of the contacts between them (for each pair
/// of `ids` in order, whether it has a contact and, if so, the contact): a part of a model, to
/// compare with the same part built in another model.
pub fn part_fingerprint<L: ConstitutiveLaw>(model: &Model<L>, ids: &[BlockId]) -> Vec<u64> {
    let mut bits = Vec::new();
    for &id in ids {
        push_block(&mut bits, model.block(id).expect("a block of the model"));
    }
    for (k, &a) in ids.iter().enumerate() {
        for &b in &ids[k + 1..] {
            match model.contact_between(a, b) {
                Some(contact) => {
                    bits.push(1);
                    push_contact(&mut bits, &contact);
                }
                None => bits.push(0),
            }
        }
    }
    bits
}

/// Pushes the bits of a block's state: position, rotation, velocity, angular velocity and
/// angular momentum.
pub fn push_block(bits: &mut Vec<u64>, block: &RigidBlock) {
    let s = block.state();
    for v in [s.pose.translation, s.velocity, s.angular_velocity, s.angular_momentum] {
        bits.extend(v.to_array().map(f64::to_bits));
    }
    bits.extend(s.pose.rotation.to_array().map(f64::to_bits));
}

/// Pushes the bits of a contact: its normal force and wrench (resultant and moments), and for
/// each sub-contact its key, area, normal displacement, normal, shear and dashpot forces and
/// slip.
pub fn push_contact<S>(bits: &mut Vec<u64>, contact: &ContactView<'_, S>) {
    let w = contact.wrench();
    bits.push(contact.normal_force().to_bits());
    for v in [w.force, w.moment_a, w.moment_b] {
        bits.extend(v.to_array().map(f64::to_bits));
    }
    bits.push(contact.subcontact_count() as u64);
    for s in contact.subcontacts() {
        bits.push(s.key().0);
        bits.extend([s.area(), s.normal_displacement(), s.normal_force(), s.slip()].map(f64::to_bits));
        for v in [s.shear_force(), s.dashpot_force()] {
            bits.extend(v.to_array().map(f64::to_bits));
        }
    }
}

/// The lowest and highest world `z` of a block's vertices (m).
pub fn z_range(block: &RigidBlock) -> (Real, Real) {
    block
        .shape()
        .vertices()
        .iter()
        .map(|v| block.world_point(*v).z)
        .fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), z| {
            (lo.min(z), hi.max(z))
        })
}

/// A deterministic pseudo-random stream in [0, 1) (64-bit LCG), for reproducible random
/// shapes, placements and orientations.
pub struct Lcg(pub u64);

impl Lcg {
    /// The next number in [0, 1).
    pub fn next(&mut self) -> Real {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as Real) / ((1u64 << 53) as Real)
    }

    /// A rotation by the rotation vector of components uniform in [-3, 3) rad.
    pub fn rotation(&mut self) -> Rotation {
        let axis = Vector::new(self.next() - 0.5, self.next() - 0.5, self.next() - 0.5);
        Rotation::from_scaled_axis(axis * 6.0)
    }

    /// A unit vector in a direction uniform over the sphere (by rejection in a shell).
    pub fn unit(&mut self) -> Vector {
        loop {
            let v = Vector::new(self.next() - 0.5, self.next() - 0.5, self.next() - 0.5);
            if v.length() > 0.05 && v.length() < 0.5 {
                return v.normalize();
            }
        }
    }
}
