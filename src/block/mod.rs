//! Blocks: the [`Block`] trait, typed ids, per-degree-of-freedom fixity and the rigid polyhedral block.

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

use crate::error::{positive, Error, Result};
use crate::geometry::{MassProperties, Polyhedron};
pub use crate::ids::BlockId;
use crate::ids::MaterialId;
use crate::math::{is_finite_vector, Matrix, Pose, Real, Vector};
use std::sync::Arc;

/// What a single degree of freedom does.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub enum Dof {
    /// Moves under the forces.
    #[default]
    Free,
    /// Held at zero velocity.
    Fixed,
    /// Moves at a prescribed velocity (m/s or rad/s).
    Velocity(Real),
}

impl Dof {
    /// The prescribed velocity, if the degree of freedom is constrained.
    #[inline]
    pub fn prescribed(self) -> Option<Real> {
        match self {
            Dof::Free => None,
            Dof::Fixed => Some(0.0),
            Dof::Velocity(v) => Some(v),
        }
    }
}

/// Fixity of the six degrees of freedom of a block, along the world axes.
///
/// ```
/// use voussoir::block::{Dof, Fixity};
/// // A loading plate: pushed down at 10 mm/s, free horizontally, no rotation.
/// let plate = Fixity {
///     translation: [Dof::Free, Dof::Velocity(-0.01), Dof::Free],
///     rotation: [Dof::Fixed; 3],
/// };
/// assert!(!plate.is_free());
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Fixity {
    /// Translations along world x, y, z.
    pub translation: [Dof; 3],
    /// Rotations about world x, y, z.
    pub rotation: [Dof; 3],
}

impl Fixity {
    /// All six degrees of freedom free.
    pub const FREE: Fixity = Fixity {
        translation: [Dof::Free; 3],
        rotation: [Dof::Free; 3],
    };
    /// All six degrees of freedom fixed (a support).
    pub const FIXED: Fixity = Fixity {
        translation: [Dof::Fixed; 3],
        rotation: [Dof::Fixed; 3],
    };

    /// Translation at a prescribed velocity, rotations fixed.
    pub fn velocity(v: Vector) -> Fixity {
        Fixity {
            translation: [Dof::Velocity(v.x), Dof::Velocity(v.y), Dof::Velocity(v.z)],
            rotation: [Dof::Fixed; 3],
        }
    }

    /// `true` when no degree of freedom is constrained.
    #[inline]
    pub fn is_free(&self) -> bool {
        self.translation
            .iter()
            .chain(&self.rotation)
            .all(|d| matches!(d, Dof::Free))
    }

    /// `true` when every degree of freedom is held at zero velocity.
    pub fn is_fixed(&self) -> bool {
        self.translation.iter().chain(&self.rotation).all(|d| *d == Dof::Fixed)
    }

    fn validate(&self, block: &str) -> Result<()> {
        for d in self.translation.iter().chain(&self.rotation) {
            if let Dof::Velocity(v) = d {
                if !v.is_finite() {
                    return Err(Error::NonFinite {
                        what: format!("prescribed velocity of block {block:?}"),
                    });
                }
            }
        }
        Ok(())
    }
}

/// Kinematic state of a block. Velocities are at the last half step of central difference.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct BlockState {
    /// Pose of the principal frame (translation = centroid).
    pub pose: Pose,
    /// Velocity of the centroid (m/s).
    pub velocity: Vector,
    /// Angular velocity, world frame (rad/s).
    pub angular_velocity: Vector,
    /// Angular momentum about the centroid, world frame (kg·m²/s).
    pub angular_momentum: Vector,
}

/// A force and a moment about the block centroid, world frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Wrench {
    /// Force (N).
    pub force: Vector,
    /// Moment about the centroid (N·m).
    pub moment: Vector,
}

impl std::ops::AddAssign for Wrench {
    fn add_assign(&mut self, o: Wrench) {
        self.force += o.force;
        self.moment += o.moment;
    }
}

/// What the integrator and the contact code need from a body.
///
/// [`RigidBlock`] is the implementation voussoir ships; the trait leaves room for other kinds.
pub trait Block {
    /// A name for messages and outputs.
    fn name(&self) -> &str;
    /// The shape in its principal frame.
    fn shape(&self) -> &Polyhedron;
    /// Mass and principal inertia.
    fn mass_properties(&self) -> MassProperties;
    /// Current kinematic state.
    fn state(&self) -> &BlockState;
    /// Fixity of its degrees of freedom.
    fn fixity(&self) -> &Fixity;
    /// Material, which selects the joint law with each neighbour.
    fn material(&self) -> MaterialId;

    /// Current world position of a material point given in the body frame.
    fn world_point(&self, local: Vector) -> Vector {
        self.state().pose.transform_point(local)
    }
    /// Body-frame coordinates of a world point in the current pose.
    fn local_point(&self, world: Vector) -> Vector {
        self.state().pose.inverse_transform_point(world)
    }
}

/// A rigid convex polyhedral block of uniform density.
///
/// ```
/// use voussoir::block::{Block, Fixity, RigidBlock};
/// use voussoir::math::Vector;
/// let base = RigidBlock::cuboid("base", Vector::new(-1.0, -1.0, -0.2), Vector::new(1.0, 1.0, 0.0), 2500.0)?
///     .with_fixity(Fixity::FIXED);
/// assert!((base.mass_properties().mass - 2500.0 * 0.8).abs() < 1e-9);
/// # Ok::<(), voussoir::Error>(())
/// ```
///
/// Layout: what every step reads (state, mass, load, and whether the block is free) comes first
/// and together, in 232 bytes (four cache lines); the fixity (96 bytes, read only for a
/// constrained block) and the rest follow, and the shape sits behind a pointer
/// (`docs/performance.md`).
#[derive(Debug, Clone)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[repr(C)]
pub struct RigidBlock {
    pub(crate) state: BlockState,
    mass: MassProperties,
    pub(crate) load: Wrench,
    /// `shape.radius()`, kept next to the state for the per-step movement and speed checks
    /// (set on construction, by `Model::add_block` and on restore).
    #[cfg_attr(feature = "serde", serde(skip))]
    pub(crate) radius: Real,
    /// `fixity.is_free()`, kept with the state (set with the fixity and on restore).
    #[cfg_attr(feature = "serde", serde(skip))]
    free: bool,
    fixity: Fixity,
    material: MaterialId,
    /// Shared between blocks of the same shape (the builders' bricks): a shape is immutable
    /// once built.
    shape: Arc<Polyhedron>,
    name: String,
    density: Real,
    pub(crate) initial_pose: Pose,
}

impl RigidBlock {
    /// The convex hull of `vertices` (world coordinates) with uniform `density` (kg/m³).
    ///
    /// # Errors
    /// Bad geometry as in [`Polyhedron::from_hull`]; [`Error::InvalidParameter`] for a density
    /// that is not positive and finite.
    pub fn from_vertices(name: &str, vertices: &[Vector], density: Real) -> Result<Self> {
        positive(&format!("density of block {name:?}"), density)?;
        let placed = Polyhedron::from_hull(name, vertices)?;
        Ok(Self::from_shape(name, placed.shape, placed.pose, density))
    }

    /// A polyhedron with explicit faces (vertex loops, counter-clockwise seen from outside).
    ///
    /// # Errors
    /// As [`Polyhedron::from_faces`], and for a bad density.
    pub fn from_faces(name: &str, vertices: &[Vector], faces: &[Vec<usize>], density: Real) -> Result<Self> {
        positive(&format!("density of block {name:?}"), density)?;
        let placed = Polyhedron::from_faces(name, vertices, faces)?;
        Ok(Self::from_shape(name, placed.shape, placed.pose, density))
    }

    /// An axis-aligned box between the corners `min` and `max`.
    ///
    /// # Errors
    /// As [`RigidBlock::from_vertices`].
    pub fn cuboid(name: &str, min: Vector, max: Vector, density: Real) -> Result<Self> {
        Self::from_vertices(name, &cuboid_corners(min, max), density)
    }

    fn from_shape(name: &str, shape: Polyhedron, pose: Pose, density: Real) -> Self {
        let mass = shape.mass_properties(density);
        Self {
            name: name.to_owned(),
            radius: shape.radius(),
            shape: Arc::new(shape),
            density,
            mass,
            material: MaterialId::default(),
            fixity: Fixity::FREE,
            free: true,
            state: BlockState {
                pose,
                velocity: Vector::ZERO,
                angular_velocity: Vector::ZERO,
                angular_momentum: Vector::ZERO,
            },
            initial_pose: pose,
            load: Wrench::default(),
        }
    }

    /// Sets the material.
    pub fn with_material(mut self, material: MaterialId) -> Self {
        self.material = material;
        self
    }

    /// Sets the fixity.
    pub fn with_fixity(mut self, fixity: Fixity) -> Self {
        self.replace_fixity(fixity);
        self
    }

    /// Sets the fixity in place (and the cached `free` flag), without copying the block.
    pub(crate) fn replace_fixity(&mut self, fixity: Fixity) {
        self.fixity = fixity;
        self.free = fixity.is_free();
    }

    /// Whether no degree of freedom is constrained ([`Fixity::is_free`], cached next to the
    /// state).
    #[inline]
    pub fn is_free(&self) -> bool {
        self.free
    }

    /// Sets the initial velocity (m/s) and angular velocity (rad/s, world frame).
    pub fn with_velocity(mut self, velocity: Vector, angular_velocity: Vector) -> Self {
        self.replace_velocity(velocity, angular_velocity);
        self
    }

    /// Sets the velocities in place (and the angular momentum), without copying the block.
    pub(crate) fn replace_velocity(&mut self, velocity: Vector, angular_velocity: Vector) {
        self.state.velocity = velocity;
        self.state.angular_velocity = angular_velocity;
        self.state.angular_momentum = self.world_inertia_times(angular_velocity);
    }

    /// Moves the block rigidly: `pose` is applied on top of its current placement.
    pub fn transformed(mut self, pose: Pose) -> Self {
        self.state.pose = pose * self.state.pose;
        self.initial_pose = self.state.pose;
        self.state.angular_momentum = self.world_inertia_times(self.state.angular_velocity);
        self
    }

    /// Makes this block share `other`'s shape when the two are the same bit for bit.
    #[cfg(feature = "serde")]
    pub(crate) fn share_shape_of(&mut self, other: &RigidBlock) -> bool {
        let same = Arc::ptr_eq(&self.shape, &other.shape) || self.shape.same_as(&other.shape);
        if same {
            self.shape = Arc::clone(&other.shape);
        }
        same
    }

    /// This block under another name (the builders' copies of one brick).
    pub(crate) fn renamed(mut self, name: &str) -> Self {
        name.clone_into(&mut self.name);
        self
    }

    /// Density (kg/m³).
    pub fn density(&self) -> Real {
        self.density
    }

    /// Pose at construction (reference for displacements).
    pub fn initial_pose(&self) -> &Pose {
        &self.initial_pose
    }

    /// Applied external load (force and moment about the centroid), constant in time.
    pub fn load(&self) -> Wrench {
        self.load
    }

    /// Displacement of the material point that was at `initial_world` at construction (m).
    pub fn displacement_of(&self, initial_world: Vector) -> Vector {
        let local = self.initial_pose.inverse_transform_point(initial_world);
        self.state.pose.transform_point(local) - initial_world
    }

    /// Velocity of a material point given in world coordinates (current position).
    pub fn point_velocity(&self, world: Vector) -> Vector {
        self.state.velocity + self.state.angular_velocity.cross(world - self.state.pose.translation)
    }

    /// Kinetic energy at the stored (half-step) velocities (J).
    pub fn kinetic_energy(&self) -> Real {
        0.5 * self.mass.mass * self.state.velocity.length_squared()
            + 0.5 * self.state.angular_velocity.dot(self.state.angular_momentum)
    }

    /// The kinematic state, for an [`Integrator`](crate::Integrator) of one's own to advance
    /// (a model hands its blocks out mutably only to its integrator). Keep
    /// `angular_momentum = I_world·angular_velocity` ([`RigidBlock::world_inertia_times`]).
    pub fn state_mut(&mut self) -> &mut BlockState {
        &mut self.state
    }

    /// `I_world · w` with the current rotation (kg·m²/s for `w` in rad/s).
    pub fn world_inertia_times(&self, w: Vector) -> Vector {
        let r = self.state.pose.rotation;
        r * (self.mass.principal_inertia * (r.inverse() * w))
    }

    pub(crate) fn validate(&self) -> Result<()> {
        self.fixity.validate(&self.name)?;
        let s = &self.state;
        for (what, v) in [
            ("velocity", s.velocity),
            ("angular velocity", s.angular_velocity),
            ("position", s.pose.translation),
            ("angular momentum", s.angular_momentum),
            ("load force", self.load.force),
            ("load moment", self.load.moment),
        ] {
            if !is_finite_vector(v) {
                return Err(Error::NonFinite {
                    what: format!("{what} of block {:?}", self.name),
                });
            }
        }
        if !s.pose.rotation.is_finite() {
            return Err(Error::NonFinite {
                what: format!("rotation of block {:?}", self.name),
            });
        }
        let norm = s.pose.rotation.length();
        if (norm - 1.0).abs() > 1e-9 {
            return Err(Error::InvalidParameter {
                name: format!("rotation quaternion norm of block {:?}", self.name),
                value: norm,
                expected: "must be a unit quaternion (norm 1 within 1e-9)",
            });
        }
        Ok(())
    }
}

// For checkpoints.
#[cfg(feature = "serde")]
impl RigidBlock {
    pub(crate) fn shape_face_count(&self) -> usize {
        self.shape.faces().len()
    }

    pub(crate) fn restore(&mut self) -> Result<()> {
        Arc::make_mut(&mut self.shape).restore()?;
        self.radius = self.shape.radius();
        self.free = self.fixity.is_free();
        self.validate()
    }

    /// Checks the stored derived data (after [`RigidBlock::restore`]): the shape's against its
    /// vertices ([`Polyhedron::check_derived`]) and the mass properties, which must be those
    /// construction computes from the shape and the density (bit for bit). `Err((field,
    /// message))`.
    pub(crate) fn check_derived(&self) -> std::result::Result<(), (String, String)> {
        if !(self.density.is_finite() && self.density > 0.0) {
            return Err(("density".into(), format!("{} is not positive and finite", self.density)));
        }
        self.shape.check_derived()?;
        let expected = self.shape.mass_properties(self.density);
        let same = |a: Real, b: Real| a.to_bits() == b.to_bits();
        let stored = self.mass;
        for (field, ok) in [
            ("mass.mass", same(stored.mass, expected.mass)),
            ("mass.volume", same(stored.volume, expected.volume)),
            (
                "mass.principal_inertia",
                (0..3).all(|i| same(stored.principal_inertia[i], expected.principal_inertia[i])),
            ),
        ] {
            if !ok {
                return Err((
                    field.into(),
                    format!(
                        "disagrees with the shape and the density {} kg/m³: {:?} in the file, {:?} expected",
                        self.density, stored, expected
                    ),
                ));
            }
        }
        Ok(())
    }
}

impl Block for RigidBlock {
    fn name(&self) -> &str {
        &self.name
    }
    fn shape(&self) -> &Polyhedron {
        &self.shape
    }
    fn mass_properties(&self) -> MassProperties {
        self.mass
    }
    fn state(&self) -> &BlockState {
        &self.state
    }
    fn fixity(&self) -> &Fixity {
        &self.fixity
    }
    fn material(&self) -> MaterialId {
        self.material
    }
}

/// What the contact pass reads of a block, copied once per step into a compact list (the
/// pipeline's `motions`, index for index with the blocks): its pose, velocities, rotation
/// matrix and bounding radius, in three cache lines. A contact reads its two blocks at
/// scattered places; from the blocks themselves that would be the lines of their states, radii
/// and a separate list of rotation matrices (issue 45: at 100k blocks those loads stalled the
/// contact pass). The values are the blocks' own, so that the step's bits do not change.
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(C, align(64))]
pub(crate) struct BlockMotion {
    /// The block's pose (translation = centroid).
    pub(crate) pose: Pose,
    /// Velocity of the centroid (m/s).
    pub(crate) velocity: Vector,
    /// Angular velocity, world frame (rad/s).
    pub(crate) angular_velocity: Vector,
    /// `pose.rotation` as a matrix.
    pub(crate) rotation: Matrix,
    /// [`RigidBlock::radius`].
    pub(crate) radius: Real,
}

impl Default for BlockMotion {
    fn default() -> Self {
        Self {
            pose: Pose::IDENTITY,
            velocity: Vector::ZERO,
            angular_velocity: Vector::ZERO,
            rotation: Matrix::IDENTITY,
            radius: 0.0,
        }
    }
}

impl BlockMotion {
    /// Block `b`'s motion as it stands.
    #[inline(always)]
    pub(crate) fn of(b: &RigidBlock) -> Self {
        Self {
            pose: b.state.pose,
            velocity: b.state.velocity,
            angular_velocity: b.state.angular_velocity,
            rotation: Matrix::from_quat(b.state.pose.rotation),
            radius: b.radius,
        }
    }
}

/// Makes blocks whose shapes are the same bit for bit share one (a checkpoint's bricks, each
/// read on its own): memory, not physics.
#[cfg(feature = "serde")]
pub(crate) fn share_shapes(blocks: &mut [RigidBlock]) {
    let mut first: std::collections::HashMap<u64, Vec<usize>> = std::collections::HashMap::new();
    for i in 0..blocks.len() {
        let (earlier, rest) = blocks.split_at_mut(i);
        let block = &mut rest[0];
        let candidates = first.entry(block.shape.vertex_hash()).or_default();
        if !candidates.iter().any(|&j| block.share_shape_of(&earlier[j])) {
            candidates.push(i);
        }
    }
}

/// The eight corners of the axis-aligned box `[min, max]`.
pub fn cuboid_corners(min: Vector, max: Vector) -> [Vector; 8] {
    std::array::from_fn(|i| {
        Vector::new(
            if i & 1 == 0 { min.x } else { max.x },
            if i & 2 == 0 { min.y } else { max.y },
            if i & 4 == 0 { min.z } else { max.z },
        )
    })
}
