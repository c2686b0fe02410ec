//! The answer of a limit analysis: the multiplier, the contact forces at collapse and the
//! mechanism (the blocks' virtual velocities), read as hinges and sliding joints; or, with no
//! live load, whether the dead loads are carried.

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

use crate::analysis::{Hinge, HingeSide, JointRef, Mechanism};
use crate::block::{Block, BlockId};
use crate::law::ConstitutiveLaw;
use crate::math::{Pose, Real, Rotation, Vector};
use crate::model::Model;

/// One corner of a contact polygon with its forces and the mechanism's relative motion there.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct LimitVertex {
    /// The corner (m, world).
    pub point: Vector,
    /// Normal force (N, compression positive).
    pub normal_force: Real,
    /// Shear force on block `b` (N, world, in the joint plane).
    pub shear_force: Vector,
    /// Opening rate `n·(v_b − v_a)` in the mechanism (m/s on the mechanism's scale, ≥ 0 up to
    /// the solver's tolerance).
    pub opening: Real,
    /// Sliding rate `|(v_b − v_a)_t|` in the mechanism.
    pub sliding: Real,
}

/// A contact at collapse: its blocks, normal and polygon corners.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct LimitContact {
    /// The two blocks, `a < b`.
    pub blocks: (BlockId, BlockId),
    /// Unit normal from `a` to `b`.
    pub normal: Vector,
    /// The polygon's corners.
    pub vertices: Vec<LimitVertex>,
}

impl LimitContact {
    /// Sum of the corners' forces on block `b` (N).
    pub fn resultant(&self) -> Vector {
        self.vertices
            .iter()
            .map(|v| self.normal * v.normal_force + v.shear_force)
            .sum()
    }
}

/// A block's rigid motion in the collapse mechanism: velocity of its centroid and angular
/// velocity (zero for supports and constrained degrees of freedom).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct BlockMotion {
    /// Centroid (m, world).
    pub centroid: Vector,
    /// Velocity of the centroid.
    pub velocity: Vector,
    /// Angular velocity (rad per unit of the mechanism's time).
    pub angular_velocity: Vector,
}

/// How a joint moves in the mechanism, at its two edge points.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct JointMotion {
    /// Joint label.
    pub joint: usize,
    /// Opening rate at the intrados point (relative normal velocity, positive = opening).
    pub opening_intrados: Real,
    /// Opening rate at the extrados point.
    pub opening_extrados: Real,
    /// Sliding rate at the edge that opens less (where a hinge turns).
    pub sliding: Real,
    /// Hinge, if any.
    pub hinge: Option<HingeSide>,
    /// Whether the joint slides.
    pub is_sliding: bool,
}

/// The answer of [`LimitProblem::solve`](super::LimitProblem::solve).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct LimitResult {
    /// The collapse multiplier `λ`: the live loads at collapse are `λ` times theirs.
    pub multiplier: Real,
    /// The contacts with their corner forces at collapse (a statically admissible set; it is
    /// not unique where the structure is hyperstatic at collapse).
    pub contacts: Vec<LimitContact>,
    /// Per block of the model, in order: its motion in the mechanism, scaled so that the live
    /// loads' power is `Σ |force|` (one live load of unit direction: its point moves at unit
    /// speed along it).
    pub blocks: Vec<BlockMotion>,
    /// Clarabel's status (`Solved` or `AlmostSolved`).
    pub status: String,
    /// Interior-point iterations.
    pub iterations: u32,
}

impl LimitResult {
    /// Velocity and angular velocity of `block` in the mechanism, `None` for an unknown id.
    pub fn block_velocity(&self, block: BlockId) -> Option<(Vector, Vector)> {
        block_velocity(&self.blocks, block)
    }

    /// Velocity of the material point of `block` at `point` (world) in the mechanism.
    pub fn point_velocity(&self, block: BlockId, point: Vector) -> Option<Vector> {
        point_velocity(&self.blocks, block, point)
    }

    /// The rigid motion of `block` after advancing the mechanism by `t`: a turn by `ω t` about
    /// its centroid and a translation by `v t`, to put on top of the block's pose (a frame of
    /// the mechanism for ParaView). The identity for an unknown id.
    pub fn displacement(&self, block: BlockId, t: Real) -> Pose {
        displacement(&self.blocks, block, t)
    }

    /// The contact between `a` and `b` (either order).
    pub fn contact_between(&self, a: BlockId, b: BlockId) -> Option<&LimitContact> {
        contact_between(&self.contacts, a, b)
    }

    /// Names the mechanism's hinges and sliding joints at `joints`, as
    /// [`classify_joints`](crate::analysis::classify_joints) does for the DEM's states, from the relative
    /// velocity `v_rel = v_b − v_a` of the joint's blocks at its intrados and extrados points
    /// (mapped from the blocks' initial poses to where they were analysed, like
    /// `classify_joints`):
    ///
    /// * a joint moves when `|v_rel|` at either point exceeds `tolerance` times the largest
    ///   relative speed at any contact corner;
    /// * it is a **hinge** when the opening rates at its two points differ by more than that
    ///   (a relative rotation about an axis in the joint), about the edge that opens less;
    /// * it **slides** when the tangential relative speed at the edge that opens less exceeds
    ///   it (about a hinge edge the relative velocity vanishes). Sliding is dilatant
    ///   (associative flow): the joint opens at `μ` times the slip rate as well.
    ///
    /// `tolerance` 1e-3 suits a converged interior-point answer (duals to ~1e-8); where the
    /// mechanism is not unique the duals are a blend of the admissible ones.
    pub fn classify<L: ConstitutiveLaw>(
        &self,
        model: &Model<L>,
        joints: &[JointRef],
        tolerance: Real,
    ) -> (Vec<JointMotion>, Mechanism) {
        let scale = self
            .contacts
            .iter()
            .flat_map(|c| c.vertices.iter().map(|v| v.opening.hypot(v.sliding)))
            .fold(0.0, Real::max);
        let tol = tolerance * scale;
        let mut motions = Vec::with_capacity(joints.len());
        let mut mechanism = Mechanism::default();
        for j in joints {
            let (a, b) = j.blocks;
            let normal = match self.contact_between(a, b) {
                Some(c) if c.blocks.0 == a => c.normal,
                Some(c) => -c.normal,
                None => {
                    motions.push(JointMotion {
                        joint: j.index,
                        opening_intrados: 0.0,
                        opening_extrados: 0.0,
                        sliding: 0.0,
                        hinge: None,
                        is_sliding: false,
                    });
                    continue;
                }
            };
            // Edge points move with the first block, as in `classify_joints`.
            let here = |p: Vector| match model.blocks().get(a.index()) {
                Some(block) => block.world_point(block.initial_pose().inverse_transform_point(p)),
                None => p,
            };
            let rel = |p: Vector| {
                let vb = self.point_velocity(b, p).unwrap_or(Vector::ZERO);
                let va = self.point_velocity(a, p).unwrap_or(Vector::ZERO);
                vb - va
            };
            let (pi, pe) = (here(j.intrados), here(j.extrados));
            let (ri, re) = (rel(pi), rel(pe));
            let (oi, oe) = (normal.dot(ri), normal.dot(re));
            let tangential = |r: Vector, o: Real| (r - normal * o).length();
            let (si, se) = (tangential(ri, oi), tangential(re, oe));
            let moving = ri.length().max(re.length()) > tol;
            let hinge = (moving && (oe - oi).abs() > tol).then_some(if oi < oe {
                HingeSide::Intrados
            } else {
                HingeSide::Extrados
            });
            let sliding = if oi <= oe { si } else { se };
            let is_sliding = moving && sliding > tol;
            if let Some(side) = hinge {
                mechanism.hinges.push(Hinge { joint: j.index, side });
            }
            if is_sliding {
                mechanism.sliding_joints.push(j.index);
            }
            motions.push(JointMotion {
                joint: j.index,
                opening_intrados: oi,
                opening_extrados: oe,
                sliding,
                hinge,
                is_sliding,
            });
        }
        (motions, mechanism)
    }
}

/// The answer of [`LimitProblem::dead_load`](super::LimitProblem::dead_load): whether the dead
/// loads alone (gravity and the blocks' constant loads, no live load) are carried, with the
/// contact forces of a statically admissible state when they are, and a collapse mechanism
/// when they are not.
///
/// Nothing in it is NaN: a state that does not exist is zeros (the forces of a structure that
/// falls, the motion of one that stands).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct DeadLoadResult {
    /// Whether contact forces within the joints' strength hold every free block in
    /// equilibrium under the dead loads.
    pub carried: bool,
    /// The contacts. Carried: the corner forces of one statically admissible state (the
    /// interior-point solver's, towards the middle of the admissible set; not unique where the
    /// structure is hyperstatic), with zero opening and sliding rates; they balance the dead
    /// loads to round-off (1e-14 of the weight measured). Not carried: zero forces and the
    /// certificate's opening and sliding rates at the corners.
    pub contacts: Vec<LimitContact>,
    /// Per block of the model, in order. Not carried: its motion in the solver's certificate
    /// that no admissible state exists, a mechanism of the dead loads (kinematically
    /// admissible: at every corner the joint opens by at least `μ` times its slip; the dead
    /// loads do positive work on it, more than the joints' cohesion can dissipate), scaled so
    /// that the dead loads' power is the free blocks' weight (`Σ W`: under gravity alone the
    /// centroids sink at unit speed, weighted by weight). Which blocks fall and which way, but
    /// not a collapse mechanism to read hinges from: where several mechanisms exist (an arch
    /// too thin has many) the interior-point certificate is a blend of them. Carried: zero
    /// motion.
    pub blocks: Vec<BlockMotion>,
    /// Clarabel's status: `Solved` or `AlmostSolved` when carried, `PrimalInfeasible` or
    /// `AlmostPrimalInfeasible` when not.
    pub status: String,
    /// Interior-point iterations.
    pub iterations: u32,
    /// Why the dead loads are not carried (naming the blocks that move most in the
    /// certificate); `None` when they are.
    pub reason: Option<String>,
}

impl DeadLoadResult {
    /// Velocity and angular velocity of `block` in the mechanism (zero when carried), `None`
    /// for an unknown id.
    pub fn block_velocity(&self, block: BlockId) -> Option<(Vector, Vector)> {
        block_velocity(&self.blocks, block)
    }

    /// Velocity of the material point of `block` at `point` (world) in the mechanism.
    pub fn point_velocity(&self, block: BlockId, point: Vector) -> Option<Vector> {
        point_velocity(&self.blocks, block, point)
    }

    /// The rigid motion of `block` after advancing the mechanism by `t`, as
    /// [`LimitResult::displacement`].
    pub fn displacement(&self, block: BlockId, t: Real) -> Pose {
        displacement(&self.blocks, block, t)
    }

    /// The contact between `a` and `b` (either order).
    pub fn contact_between(&self, a: BlockId, b: BlockId) -> Option<&LimitContact> {
        contact_between(&self.contacts, a, b)
    }
}

/// The answer of [`LimitProblem::analyse`](super::LimitProblem::analyse): the collapse
/// multiplier of a live load, or, with no live load (none, or all of zero force), the answer
/// to the dead-load question alone.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub enum LimitAnswer {
    /// The live load's collapse multiplier, forces at collapse and mechanism.
    Collapse(LimitResult),
    /// No live load: whether the dead loads are carried.
    DeadLoad(DeadLoadResult),
}

impl LimitAnswer {
    /// The collapse multiplier; `None` for the dead-load question.
    pub fn multiplier(&self) -> Option<Real> {
        match self {
            Self::Collapse(r) => Some(r.multiplier),
            Self::DeadLoad(_) => None,
        }
    }

    /// The contacts with their corner forces and the mechanism's rates.
    pub fn contacts(&self) -> &[LimitContact] {
        match self {
            Self::Collapse(r) => &r.contacts,
            Self::DeadLoad(r) => &r.contacts,
        }
    }

    /// Per block, its motion in the mechanism.
    pub fn blocks(&self) -> &[BlockMotion] {
        match self {
            Self::Collapse(r) => &r.blocks,
            Self::DeadLoad(r) => &r.blocks,
        }
    }

    /// Clarabel's status.
    pub fn status(&self) -> &str {
        match self {
            Self::Collapse(r) => &r.status,
            Self::DeadLoad(r) => &r.status,
        }
    }

    /// Interior-point iterations.
    pub fn iterations(&self) -> u32 {
        match self {
            Self::Collapse(r) => r.iterations,
            Self::DeadLoad(r) => r.iterations,
        }
    }
}

fn block_velocity(blocks: &[BlockMotion], block: BlockId) -> Option<(Vector, Vector)> {
    blocks.get(block.index()).map(|m| (m.velocity, m.angular_velocity))
}

fn point_velocity(blocks: &[BlockMotion], block: BlockId, point: Vector) -> Option<Vector> {
    blocks
        .get(block.index())
        .map(|m| m.velocity + m.angular_velocity.cross(point - m.centroid))
}

fn displacement(blocks: &[BlockMotion], block: BlockId, t: Real) -> Pose {
    let Some(m) = blocks.get(block.index()) else {
        return Pose::IDENTITY;
    };
    let rotation = Rotation::from_scaled_axis(m.angular_velocity * t);
    // x ↦ c + v t + R (x − c)
    Pose::from_parts(m.centroid + m.velocity * t - rotation * m.centroid, rotation)
}

fn contact_between(contacts: &[LimitContact], a: BlockId, b: BlockId) -> Option<&LimitContact> {
    let key = (a.min(b), a.max(b));
    contacts.iter().find(|c| c.blocks == key)
}
