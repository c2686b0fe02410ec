//! Contacts between block pairs: the [`Contact`] trait, typed ids, sub-contact state and the
//! per-sub-contact kinematics kernel.

mod kernel;

use serde::{Deserialize, Serialize};

pub(crate) use kernel::{sum_contact, update_pair_geometry, update_subcontact, KernelContext};

use crate::block::BlockId;
use crate::constitutive::{JointForce, JointStatus};
use crate::geometry::{ContactKind, SubKey};
use crate::math::{Real, Vector};

/// Typed index of a contact in the model's current contact list (valid until the next
/// re-detection).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub struct ContactId(pub u32);

/// Whether contact geometry follows the blocks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum DisplacementMode {
    /// Contact planes, points and lever arms follow the blocks; contacts are re-detected as they
    /// move.
    #[default]
    Large,
    /// Contact geometry and lever arms stay as first detected (linearised kinematics); contacts
    /// are detected once.
    Small,
}

/// A block pair's interface: its plane, its sub-contacts and their resultant.
pub trait Contact {
    /// Per-sub-contact data type.
    type SubContact;
    /// The two blocks, `a` < `b`.
    fn blocks(&self) -> (BlockId, BlockId);
    /// Unit normal of the joint plane, from `a` to `b` (world).
    fn normal(&self) -> Vector;
    /// The sub-contacts.
    fn subcontacts(&self) -> &[Self::SubContact];
    /// Resultant force on block `b` (N, world); the force on `a` is its opposite.
    fn resultant(&self) -> Vector;
}

/// One contact between blocks `a < b`, with a contiguous range of sub-contacts.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ContactPair {
    pub(crate) a: u32,
    pub(crate) b: u32,
    pub(crate) kind: ContactKind,
    pub(crate) host_is_a: bool,
    pub(crate) law: u32,
    pub(crate) first: u32,
    pub(crate) count: u32,
    /// Unit normal a → b (world), updated every step in large-displacement mode.
    pub(crate) normal: Vector,
    /// Outward normal of the host face (world).
    pub(crate) host_normal: Vector,
    /// Plane of the other face: `other_normal · x = other_offset` (world).
    pub(crate) other_normal: Vector,
    pub(crate) other_offset: Real,
    /// Centroids at detection (lever arms in small-displacement mode).
    pub(crate) ref_a: Vector,
    pub(crate) ref_b: Vector,
    /// Resultant force on `b` (N).
    pub(crate) force: Vector,
    /// Moments of the sub-contact forces about the centroids of `a` and `b` (N·m).
    pub(crate) moment_a: Vector,
    pub(crate) moment_b: Vector,
    /// Sum of normal forces (N, compression positive).
    pub(crate) normal_force: Real,
    pub(crate) work: Real,
    pub(crate) dashpot_work: Real,
    pub(crate) elastic: Real,
    /// Sum of the sub-contact areas (m²).
    pub(crate) area: Real,
    /// `area` when the critical step was last evaluated (0 for a new contact).
    pub(crate) bound_area: Real,
}

impl ContactPair {
    /// The two blocks.
    pub fn blocks(&self) -> (BlockId, BlockId) {
        (BlockId(self.a), BlockId(self.b))
    }
    /// Contact case.
    pub fn kind(&self) -> ContactKind {
        self.kind
    }
    /// Unit normal a → b (world).
    pub fn normal(&self) -> Vector {
        self.normal
    }
    /// Resultant force on `b` (N, world).
    pub fn resultant(&self) -> Vector {
        self.force
    }
    /// Sum of the sub-contact normal forces (N, compression positive).
    pub fn normal_force(&self) -> Real {
        self.normal_force
    }
    /// Index of the joint law in the model's [`crate::constitutive::JointTable`].
    pub fn law_index(&self) -> usize {
        self.law as usize
    }
    /// Number of sub-contacts.
    pub fn subcontact_count(&self) -> usize {
        self.count as usize
    }
    pub(crate) fn range(&self) -> std::ops::Range<usize> {
        self.first as usize..self.first as usize + self.count as usize
    }
}

/// A sub-contact: a point of a joint with a tributary area, its spring forces and history.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SubContact<S> {
    pub(crate) key: SubKey,
    /// Material point on the host block (body frame).
    pub(crate) anchor: Vector,
    pub(crate) area: Real,
    /// Normal displacement `u_n` (m, positive = open).
    pub(crate) gap: Real,
    /// Added to the geometric gap of a point contact at each re-detection (m): the overlap a
    /// face-face joint left behind when it turned into an edge contact, which the springs do not
    /// carry. Zero otherwise.
    #[serde(default)]
    pub(crate) gap_offset: Real,
    pub(crate) force: JointForce,
    pub(crate) status: JointStatus,
    /// Accumulated slip while sliding (m).
    pub(crate) slip: Real,
    pub(crate) state: S,
    /// World position (fixed in small-displacement mode).
    pub(crate) point: Vector,
    /// Spring force on `b` (world) after the last update.
    pub(crate) spring: Vector,
    /// Spring plus dashpot force on `b` (world).
    pub(crate) total: Vector,
    /// Work done on the joint springs during the last step (J).
    pub(crate) work: Real,
    /// Energy dissipated by the dashpot during the last step (J).
    pub(crate) dashpot_work: Real,
    /// Elastic energy stored (J).
    pub(crate) elastic: Real,
}

impl<S> SubContact<S> {
    /// Stable identity within the pair.
    pub fn key(&self) -> SubKey {
        self.key
    }
    /// Current world position (m).
    pub fn point(&self) -> Vector {
        self.point
    }
    /// Tributary area (m²).
    pub fn area(&self) -> Real {
        self.area
    }
    /// Normal displacement `u_n` (m, positive = open).
    pub fn normal_displacement(&self) -> Real {
        self.gap
    }
    /// Normal force (N, compression positive).
    pub fn normal_force(&self) -> Real {
        self.force.normal
    }
    /// Normal stress (Pa, compression positive).
    pub fn normal_stress(&self) -> Real {
        self.force.normal / self.area
    }
    /// Shear force on block `b` (N, world, in the joint plane).
    pub fn shear_force(&self) -> Vector {
        self.force.shear
    }
    /// Status after the last update.
    pub fn status(&self) -> JointStatus {
        self.status
    }
    /// Accumulated slip (m).
    pub fn slip(&self) -> Real {
        self.slip
    }
    /// The law's own state.
    pub fn law_state(&self) -> &S {
        &self.state
    }
    /// Spring plus dashpot force on block `b` (N, world).
    pub fn total_force(&self) -> Vector {
        self.total
    }
}

/// A borrowed view of one contact and its sub-contacts.
#[derive(Debug, Clone, Copy)]
pub struct ContactView<'a, S> {
    /// The contact.
    pub pair: &'a ContactPair,
    /// Its sub-contacts.
    pub subs: &'a [SubContact<S>],
}

impl<S> Contact for ContactView<'_, S> {
    type SubContact = SubContact<S>;
    fn blocks(&self) -> (BlockId, BlockId) {
        self.pair.blocks()
    }
    fn normal(&self) -> Vector {
        self.pair.normal
    }
    fn subcontacts(&self) -> &[SubContact<S>] {
        self.subs
    }
    fn resultant(&self) -> Vector {
        self.pair.force
    }
}
