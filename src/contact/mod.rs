//! Contacts between block pairs: the [`Contact`] trait, typed ids, sub-contact state and the
//! per-sub-contact kinematics kernel.

mod closed_lanes;
mod elastic_step;
mod joint_level;
mod kernel;
mod lanes;
mod law_update;
mod moments;
mod node_step;
mod spread;
mod store;
mod view;

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

pub(crate) use closed_lanes::LaneBuild;
pub(crate) use joint_level::{HingeRecord, JointLevel, SpanEnds};
pub(crate) use kernel::{face_gap_coefficients, update_contact, KernelContext};
pub(crate) use moments::ForceMoments;
pub(crate) use node_step::{integrated_stiffness, node_frame, stored_node_frame, update_nodes};
pub(crate) use spread::tension_free;
pub(crate) use store::{ContactLists, ContactSlices, ContactStore, OldContacts};
pub(crate) use view::{CellGeometry, NodeGeometry, TensionFree};
pub use view::{Contact, ContactView, SubContactSample, SubContactView};

pub use crate::ids::ContactId;

use crate::geometry::Polyhedron;
use crate::geometry::{ContactKind, SubKey};
use crate::law::{JointAxes, JointForce, JointStatus};
use crate::math::{Pose, Real, Rotation, Vector, Vector2};

/// Whether contact geometry follows the blocks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub enum DisplacementMode {
    /// Contact planes, points and lever arms follow the blocks; contacts are re-detected as they
    /// move.
    #[default]
    Large,
    /// Contact geometry and lever arms stay as first detected (linearised kinematics); contacts
    /// are detected once.
    Small,
}

/// One contact between blocks `a < b`, with a contiguous range of sub-contacts.
///
/// Layout: what a step reads and writes; the detection bookkeeping and the record of a hinge
/// sit in a parallel internal list, which a large-displacement step reads for hinges only, and
/// the reference geometry of small-displacement mode in another, kept in that mode only.
#[derive(Debug, Clone, PartialEq)]
#[repr(C)]
pub(crate) struct ContactPair {
    pub(crate) a: u32,
    pub(crate) b: u32,
    pub(crate) kind: ContactKind,
    pub(crate) host_is_a: bool,
    pub(crate) law: u32,
    pub(crate) first: u32,
    pub(crate) count: u32,
    /// Unit normal a → b (world), updated every step in large-displacement mode. At the start of
    /// a step it still holds the previous step's normal, in which the stored spring forces were
    /// composed.
    pub(crate) normal: Vector,
    /// First tangent of the joint (world, normal to `normal`); the second is `normal × tangent`.
    /// The sub-contacts' shear forces are components along the two. Turned with the normal
    /// every step in large-displacement mode.
    pub(crate) tangent: Vector,
    /// The plane of the anchors in the host block's body frame (see [`AnchorPlane`]).
    pub(crate) anchors: AnchorPlane,
    /// The plane the sub-contacts' gaps are measured to, fixed in the block that is not the
    /// host: its outward unit normal and offset (`plane_normal·x = plane_offset`) in that
    /// block's body frame — the other face of a face-face contact, the plane of a point
    /// contact. Cached from the shapes (or the kind) at detection and on checkpoint load, so
    /// that the step loop does not visit the polyhedra.
    pub(crate) plane_normal: Vector,
    pub(crate) plane_offset: Real,
    /// Whether the sub-contacts may hold dashpot forces (Rayleigh damping in the last step, or
    /// history carried over at detection); only saves reading them when not. Checkpointed: it
    /// selects the sub-contact loop, and with it the order of the sums.
    pub(crate) dashpots: bool,
    /// Sum of normal forces (N, compression positive).
    pub(crate) normal_force: Real,
    /// Force and first moment of the sub-contacts' spring forces as they stand (composed with
    /// `normal`), for the first half of the next step's joint work. Kept by the step,
    /// recomputed from the sub-contacts at detection, checkpointed (a recomputation could sum
    /// in another order than the step did).
    pub(crate) springs: ForceMoments,
    /// Elastic energy the spread of the gap over the face-face cells stores beyond the laws'
    /// `F_n²/(2 k_n A)` (J, `contact/spread.rs`): kept by the step with `springs`,
    /// checkpointed.
    pub(crate) spread_energy: Real,
    /// What the step needs of the cells as a whole (see [`CellSummary`]): derived from the
    /// sub-contacts whenever they are set (detection, checkpoint load), not stored.
    pub(crate) cells: CellSummary,
    /// The joint stepped as a whole while it is closed and sticking (`contact/joint_level/`);
    /// inactive otherwise. Checkpointed.
    pub(crate) joint: JointLevel,
}

/// A face-face contact's cells as a whole: the box on the anchor plane that they cover, and
/// `Σ A h²/3` per axis (`J = A h²/3`, a rectangle's second moment about its centre) summed in
/// sub-contact order. When the gap is negative over the whole box, every cell is all closed,
/// and the step need not test them one by one (`kernel.rs`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct CellSummary {
    /// Lower corner of the box (plane coordinates, m).
    pub(crate) lo: Vector2,
    /// Upper corner (m).
    pub(crate) hi: Vector2,
    /// `Σ A h_x²/3`, `Σ A h_y²/3` (m⁴).
    pub(crate) closed_moments: Vector2,
    /// The cells' area moments about the plane's origin, taken at their anchors:
    /// `Σ A`, `Σ A x`, `Σ A y`, `Σ A x²`, `Σ A x y`, `Σ A y²` (m², m³, m³, m⁴, m⁴, m⁴), for
    /// joint-level stepping (`contact/joint_level/`).
    pub(crate) area_moments: [Real; 6],
}

impl ContactPair {
    /// The range of the contact's own sub-contacts that its next step reads, as far as the
    /// contact says beforehand: none for a joint stepped as a whole (unless it leaves), the
    /// span of a hinge, all of them otherwise.
    #[inline]
    pub(crate) fn cells_read_by_step(&self) -> std::ops::Range<usize> {
        if !self.joint.active {
            0..self.count as usize
        } else if self.joint.is_partial() {
            self.joint.span_range()
        } else {
            0..0
        }
    }
}

impl CellSummary {
    /// The summary of the cells of `own`, a contact's sub-contacts.
    pub(crate) fn of<S>(own: &[SubContact<S>]) -> Self {
        let mut s = Self {
            lo: Vector2::splat(Real::INFINITY),
            hi: Vector2::splat(Real::NEG_INFINITY),
            closed_moments: Vector2::ZERO,
            area_moments: [0.0; 6],
        };
        for sub in own {
            let half = sub.half();
            s.lo = s.lo.min(sub.plane - half);
            s.hi = s.hi.max(sub.plane + half);
            s.closed_moments += elastic_step::cell_moments(sub.area, half);
            let (a, x, y) = (sub.area, sub.plane.x, sub.plane.y);
            for (m, add) in s
                .area_moments
                .iter_mut()
                .zip([a, a * x, a * y, a * x * x, a * x * y, a * y * y])
            {
                *m += add;
            }
        }
        s
    }

    /// The area moments and `Σ J` of the cells other than `some` (of the same contact): the
    /// summary's less those of `some`, summed in their order. A joint open in part takes those
    /// of its closed cells so when it enters (`contact/joint_level/hinge.rs`).
    #[inline]
    pub(crate) fn without<S>(&self, some: &[SubContact<S>]) -> ([Real; 6], Vector2) {
        let part = Self::of(some);
        let mut moments = self.area_moments;
        for (m, p) in moments.iter_mut().zip(part.area_moments) {
            *m -= p;
        }
        (moments, self.closed_moments - part.closed_moments)
    }
}

/// What a contact keeps besides the fields of [`ContactPair`], in a parallel array (same index):
/// the areas the critical-step bookkeeping compares, and what a contact of one kind keeps on
/// the side (a hinge's record, a node contact's strips), which the step reads for those
/// contacts only. Its geometry at detection, which small-displacement mode alone steps with,
/// is a list of its own ([`SmallReference`]), kept in that mode only.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ContactReference {
    /// Sum of the sub-contact areas (m²).
    pub(crate) area: Real,
    /// `area` when the critical step was last evaluated (0 for a new contact).
    pub(crate) bound_area: Real,
    /// What the contact keeps on the side ([`SideRecord`]). Boxed, so that a contact that
    /// needs none (almost every contact of a wall) pays 8 bytes for it: a node contact's from
    /// its detection on ([`ContactReference::nodes`]), a joint's allocated when it first needs
    /// it after its detection, and reused after.
    pub(crate) side: Option<Box<SideRecord>>,
}

/// What a contact of one kind keeps beside its sub-contacts ([`ContactReference::side`]).
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum SideRecord {
    /// Of a joint open in part ([`JointLevel::span`] not empty): what its cells stepped as a
    /// whole need; stale otherwise.
    Hinge(HingeRecord),
    /// Of a node contact, always (from its detection or its checkpoint's load on): its nodes'
    /// keys and strips ([`NodeRecord`]).
    Nodes(NodeRecord),
}

/// What a node contact keeps beside its sub-contacts: the keys of its nodes, index for index
/// with its sub-contacts (a node's key names its block, vertex, edge or face and its place
/// there, [`crate::geometry::NodeId`]: up to 59 bits, which the padding of a [`SubContact`]
/// cannot hold, where a face-face cell's key is its joint's faces and two grid indices,
/// [`ContactPair::key`]), and, stepped integrated, their strips
/// (`geometry/narrow_phase/strips.rs`), built at its first such step after detection.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct NodeRecord {
    /// The nodes' keys, in sub-contact order (sorted).
    pub(crate) keys: Vec<SubKey>,
    /// Their strips, once built.
    pub(crate) strips: Option<crate::geometry::NodeStrips>,
}

/// A contact's geometry at its detection, which small-displacement mode steps with: in a
/// parallel list of the contacts ([`crate::contact::ContactStore::small_refs`], same index),
/// kept in that mode only. Large-displacement mode steps with the current poses and keeps none
/// (a switch to small displacements detects every contact afresh).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SmallReference {
    /// Centroids at detection (lever arms in small-displacement mode).
    pub(crate) ref_a: Vector,
    pub(crate) ref_b: Vector,
    /// Rotation of the host block at detection (anchors to world in small-displacement mode).
    pub(crate) ref_host_rotation: Rotation,
}

impl SmallReference {
    /// The reference the step's geometry of contact `k` follows in `mode`: its entry of `refs`
    /// (a store's `small_refs`) in small-displacement mode, none (the current poses) in large
    /// mode, or when the list is not kept (contacts found in large mode, read by the detection
    /// that a switch to small displacements makes before any of them steps so).
    #[inline]
    pub(crate) fn of(refs: &[Self], k: usize, mode: DisplacementMode) -> Option<&Self> {
        match mode {
            DisplacementMode::Large => None,
            DisplacementMode::Small => refs.get(k),
        }
    }

    /// The centroids of `a` and `b` the step's lever arms start from: their current positions,
    /// or those at detection (`small`, [`SmallReference::of`]).
    #[inline]
    pub(crate) fn centroids(small: Option<&Self>, pose_a: &Pose, pose_b: &Pose) -> (Vector, Vector) {
        match small {
            None => (pose_a.translation, pose_b.translation),
            Some(r) => (r.ref_a, r.ref_b),
        }
    }

    /// A reference to fill room with until a contact's is written there (never read).
    pub(crate) const DEAD: Self = Self {
        ref_a: Vector::ZERO,
        ref_b: Vector::ZERO,
        ref_host_rotation: Rotation::IDENTITY,
    };
}

impl ContactReference {
    /// The record of a joint open in part, if it holds one.
    #[inline]
    pub(crate) fn hinge(&self) -> Option<&HingeRecord> {
        match self.side.as_deref() {
            Some(SideRecord::Hinge(h)) => Some(h),
            _ => None,
        }
    }

    /// The record of a joint open in part, if it holds one, to change (a checkpoint's reader).
    #[inline]
    #[cfg(feature = "serde")]
    pub(crate) fn hinge_mut(&mut self) -> Option<&mut HingeRecord> {
        match self.side.as_deref_mut() {
            Some(SideRecord::Hinge(h)) => Some(h),
            _ => None,
        }
    }

    /// Keeps `record` as the contact's side record, in the box it has if any (a joint's: a node
    /// contact's side record holds its keys).
    #[inline]
    pub(crate) fn keep(&mut self, record: SideRecord) {
        debug_assert!(!matches!(self.side.as_deref(), Some(SideRecord::Nodes(_))));
        match self.side.as_deref_mut() {
            Some(side) => *side = record,
            None => self.side = Some(Box::new(record)),
        }
    }

    /// The side record of a node contact whose nodes have keys `keys` (in sub-contact order),
    /// without strips.
    pub(crate) fn nodes(keys: Vec<SubKey>) -> Option<Box<SideRecord>> {
        Some(Box::new(SideRecord::Nodes(NodeRecord { keys, strips: None })))
    }

    /// A node contact's keys, index for index with its sub-contacts (none for a face-face
    /// joint, whose cells' keys follow from the contact, [`ContactPair::key`]).
    #[inline]
    pub(crate) fn node_keys(&self) -> &[SubKey] {
        match self.side.as_deref() {
            Some(SideRecord::Nodes(r)) => &r.keys,
            _ => &[],
        }
    }

    /// A node contact's keys and, when `build` is given, its nodes' strips: those kept, or
    /// `build`'s (from the keys), kept for the steps until its next detection (which drops
    /// them). No strips for a contact without a node record.
    #[inline]
    pub(crate) fn node_keys_and_strips(
        &mut self,
        build: Option<impl FnOnce(&[SubKey]) -> crate::geometry::NodeStrips>,
    ) -> (&[SubKey], Option<&crate::geometry::NodeStrips>) {
        let Some(SideRecord::Nodes(record)) = self.side.as_deref_mut() else {
            debug_assert!(false, "a node contact without its node record");
            return (&[], None);
        };
        let Some(build) = build else {
            return (&record.keys, None);
        };
        if !record.strips.as_ref().is_some_and(|s| s.holds(record.keys.len())) {
            record.strips = Some(build(&record.keys));
        }
        (&record.keys, record.strips.as_ref())
    }
}

#[cfg(test)]
mod tests {
    use super::AnchorPlane;
    use crate::math::{Rotation, Vector};

    /// Anchors of every contact case come back from their plane coordinates to round-off: a
    /// grid on a tilted face, a segment, a single point, and nothing.
    #[test]
    fn anchor_plane_reproduces_coplanar_collinear_and_single_anchors() {
        let tilt = Rotation::from_scaled_axis(Vector::new(0.3, -0.7, 0.4));
        let origin = Vector::new(0.8, -0.35, 1.2);
        let grid: Vec<Vector> = (0..9)
            .flat_map(|i| (0..5).map(move |j| (i, j)))
            .map(|(i, j)| origin + tilt * Vector::new(0.025 * i as f64 - 0.1, 0.025 * j as f64, 0.0))
            .collect();
        let segment: Vec<Vector> = (0..7)
            .map(|k| origin + tilt * Vector::new(0.01 * k as f64, 0.0, 0.0))
            .collect();
        for anchors in [grid, segment, vec![origin]] {
            let plane = AnchorPlane::through(anchors.iter().copied());
            assert!((plane.u.length() - 1.0).abs() < 1e-15 && (plane.v.length() - 1.0).abs() < 1e-15);
            assert!(plane.u.dot(plane.v).abs() < 1e-15);
            for a in &anchors {
                let back = plane.point(plane.coordinates(*a));
                assert!((back - *a).length() < 1e-15, "{a} -> {back}");
            }
        }
        assert_eq!(AnchorPlane::through(std::iter::empty()), AnchorPlane::default());
    }

    /// The size the documentation of [`super::SubContact`] states, with `CoulombSlip`'s state:
    /// a cell's grid indices (its key) in the padding of the 74 bytes the step reads.
    #[test]
    fn subcontact_is_80_bytes_with_coulomb_state() {
        use crate::law::CoulombState;
        assert_eq!(std::mem::size_of::<super::SubContact<CoulombState>>(), 80);
    }

    /// The contact record every step streams stays at the size `docs/performance.md` counts:
    /// a hinge's span in the joint record's padding, the rest of its record boxed in the
    /// reference (8 bytes for a contact that is neither a hinge nor a node contact), and the
    /// reference geometry of small-displacement mode in a list of its own, which large
    /// displacements do not keep.
    #[test]
    fn contact_records_keep_their_sizes() {
        assert_eq!(std::mem::size_of::<super::ContactPair>(), 536);
        assert_eq!(std::mem::size_of::<super::ContactReference>(), 24);
        assert_eq!(std::mem::size_of::<super::SmallReference>(), 80);
    }

    /// A cell's key is its joint's faces and its two grid indices, which its sub-contact holds
    /// in the padding it had: whatever the faces (cut to 16 bits each, as the key does) and
    /// the indices, the key comes back to the bit, and a key of other faces is told apart.
    #[test]
    fn cell_keys_come_back_from_their_indices_and_faces() {
        use crate::geometry::SubKey;
        for (fa, fb) in [(0, 0), (3, 5), (0xffff, 0x1_0007), (0x12_3456, 7)] {
            for (i, j) in [(0, 0), (1, 65_534), (65_534, 2), (400, 999), (65_535, 65_535)] {
                let key = SubKey::cell(fa, fb, i, j);
                let [ki, kj] = key.cell_indices();
                assert_eq!((u32::from(ki), u32::from(kj)), (i, j));
                assert!(key.is_cell_of(fa, fb));
                assert!(!key.is_cell_of(fa + 1, fb) && !key.is_cell_of(fa, fb + 1));
            }
        }
    }
}

impl ContactPair {
    /// The joint's normal and tangents (world); sub-contact shear forces are components along
    /// the tangents.
    pub fn axes(&self) -> JointAxes {
        JointAxes {
            normal: self.normal,
            tangent: self.tangent,
        }
    }
    /// Material point of `sub` (one of this contact's sub-contacts) on the host block, in its
    /// body frame (m).
    pub fn anchor<S>(&self, sub: &SubContact<S>) -> Vector {
        self.anchors.point(sub.plane)
    }

    /// The key of this contact's sub-contact `sub`, its `index`-th (`reference`: the
    /// contact's): a face-face cell's from the joint's faces and the grid indices it holds, a
    /// node's as its contact keeps it ([`ContactReference::node_keys`]).
    #[inline]
    pub(crate) fn key<S>(&self, reference: &ContactReference, index: usize, sub: &SubContact<S>) -> SubKey {
        match self.kind {
            ContactKind::FaceFace { face_a, face_b } => {
                SubKey::cell(face_a, face_b, u32::from(sub.cell[0]), u32::from(sub.cell[1]))
            }
            ContactKind::Nodes => reference.node_keys()[index],
        }
    }

    /// The index among `own` (this contact's sub-contacts, in key order) of the one with key
    /// `key`, if any (`reference`: the contact's).
    #[inline]
    pub(crate) fn find_key<S>(
        &self,
        reference: &ContactReference,
        own: &[SubContact<S>],
        key: SubKey,
    ) -> Option<usize> {
        match self.kind {
            // Every cell of the joint has its faces: its grid indices tell it.
            ContactKind::FaceFace { face_a, face_b } => key
                .is_cell_of(face_a, face_b)
                .then(|| own.binary_search_by_key(&key.cell_indices(), |s| s.cell).ok())
                .flatten(),
            ContactKind::Nodes => reference.node_keys().binary_search(&key).ok(),
        }
    }
    /// Fills the body-frame plane the step loop measures gaps to ([`ContactPair::plane_normal`]).
    pub(crate) fn cache_local_faces(&mut self, shape_a: &Polyhedron, shape_b: &Polyhedron) {
        match self.kind {
            ContactKind::FaceFace { face_a, face_b } => {
                let face = if self.host_is_a {
                    &shape_b.faces()[face_b as usize]
                } else {
                    &shape_a.faces()[face_a as usize]
                };
                self.plane_normal = face.normal;
                self.plane_offset = face.offset;
            }
            // Each node finds its own face of the other block (`nodes.rs`).
            ContactKind::Nodes => {
                self.plane_normal = Vector::ZERO;
                self.plane_offset = 0.0;
            }
        }
    }

    /// The pose mapping sub-contact anchors to world points, given the current poses of `a`
    /// and `b`: the host's pose, or its pose at detection (`small`, [`SmallReference::of`]:
    /// in small-displacement mode).
    #[inline]
    pub(crate) fn frame(&self, small: Option<&SmallReference>, pose_a: &Pose, pose_b: &Pose) -> Pose {
        match small {
            None => {
                if self.host_is_a {
                    *pose_a
                } else {
                    *pose_b
                }
            }
            Some(r) => Pose::from_parts(if self.host_is_a { r.ref_a } else { r.ref_b }, r.ref_host_rotation),
        }
    }

    /// Recomputes [`ContactPair::springs`] and [`ContactPair::spread_energy`] from the
    /// contact's own sub-contacts (`own`: those of its range) at the blocks' `poses` (`None` in
    /// small-displacement mode, whose gaps are not geometric).
    /// A face-face contact's sub-contacts get the gaps the step gives their laws
    /// (`kernel::seed_law_gaps`) first.
    pub(crate) fn refresh_springs<L: crate::law::ConstitutiveLaw>(
        &mut self,
        own: &mut [SubContact<L::State>],
        law: &L,
        poses: Option<(&Pose, &Pose)>,
    ) {
        self.cells = CellSummary::of(own);
        if let (ContactKind::FaceFace { .. }, Some(poses)) = (self.kind, poses) {
            kernel::seed_law_gaps(self, own, law, poses);
        }
        (self.springs, self.spread_energy) = self.springs_of(own, law, poses);
    }

    /// The spring moments of `own` (the contact's sub-contacts) on its anchor plane and their
    /// spread energy, as the step sums them (see [`ContactPair::refresh_springs`]); none for a
    /// node contact, whose step books each node's work by itself.
    pub(crate) fn springs_of<L: crate::law::ConstitutiveLaw>(
        &self,
        own: &[SubContact<L::State>],
        law: &L,
        poses: Option<(&Pose, &Pose)>,
    ) -> (ForceMoments, Real) {
        match self.kind {
            ContactKind::Nodes => (ForceMoments::default(), 0.0),
            ContactKind::FaceFace { .. } => kernel::spring_moments(self, own, law, poses),
        }
    }

    pub(crate) fn range(&self) -> std::ops::Range<usize> {
        self.first as usize..self.first as usize + self.count as usize
    }

    /// Whether this contact, loaded, may turn back into a face-face joint, its forces handed to
    /// the joint's cells (`docs/theory.md` §6): a node contact carrying load whose nodes are
    /// integrated (`integrated`: large-displacement mode, `NodeRule::Integrated`, a law with a
    /// linear normal spring) and all in the state a new cell starts from (`S::default()`: a
    /// dry joint's; a node that slid or cracked in a law that remembers it keeps its history as
    /// a node), so that the cells store what the nodes stored and lose no state. Point nodes
    /// store `½ k_n A g²` for shares the cells integrate, and never turn back.
    pub(crate) fn may_turn_back<S: PartialEq + Default>(&self, own: &[SubContact<S>], integrated: bool) -> bool {
        let fresh = S::default();
        integrated
            && matches!(self.kind, ContactKind::Nodes)
            && self.normal_force > 0.0
            && own.iter().all(|s| s.state == fresh)
    }

    /// Whether this contact, re-detected as a contact of kind `next`, hands its forces to the
    /// new contact's cells: one that [may turn back](Self::may_turn_back) turning into a
    /// face-face joint.
    pub(crate) fn hands_forces_to_cells<S: PartialEq + Default>(
        &self,
        own: &[SubContact<S>],
        integrated: bool,
        next: &ContactKind,
    ) -> bool {
        matches!(next, ContactKind::FaceFace { .. }) && self.may_turn_back(own, integrated)
    }
}

/// The plane of a contact's sub-contact anchors, in the host block's body frame: the anchor with
/// plane coordinates `c` is `origin + c.x u + c.y v` (`u`, `v` orthonormal). Face-face anchors lie
/// on the host face, so one plane holds them all, and a sub-contact stores two coordinates
/// instead of a 3-D point. (A node contact does not use it: its nodes' keys name them.)
///
/// ```
/// use voussoir::contact::AnchorPlane;
/// use voussoir::math::Vector;
/// let pts = [Vector::new(0.1, 0.2, 0.3), Vector::new(0.4, 0.2, 0.3), Vector::new(0.1, 0.2, -0.5)];
/// let plane = AnchorPlane::through(pts);
/// for p in pts {
///     assert!((plane.point(plane.coordinates(p)) - p).length() < 1e-15);
/// }
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct AnchorPlane {
    /// A point of the plane (body frame, m).
    pub origin: Vector,
    /// First in-plane unit axis.
    pub u: Vector,
    /// Second in-plane unit axis, normal to `u`.
    pub v: Vector,
}

impl Default for AnchorPlane {
    fn default() -> Self {
        Self {
            origin: Vector::ZERO,
            u: Vector::X,
            v: Vector::Y,
        }
    }
}

impl AnchorPlane {
    /// A plane through `points` when they are coplanar (collinear points and a single point
    /// included): origin at the first point, `u` towards the farthest, `v` towards the point
    /// farthest from that line (any normal to `u` when the points are collinear).
    pub fn through<I>(points: I) -> Self
    where
        I: IntoIterator<Item = Vector>,
        I::IntoIter: Clone,
    {
        let points = points.into_iter();
        let Some(origin) = points.clone().next() else {
            return Self::default();
        };
        let far = points.clone().map(|p| p - origin).fold(Vector::ZERO, |best, d| {
            if d.length_squared() > best.length_squared() {
                d
            } else {
                best
            }
        });
        let size = far.length();
        if size == 0.0 {
            return Self {
                origin,
                ..Self::default()
            };
        }
        let u = far / size;
        let off = points
            .map(|p| {
                let d = p - origin;
                d - u * u.dot(d)
            })
            .fold(Vector::ZERO, |best, w| {
                if w.length_squared() > best.length_squared() {
                    w
                } else {
                    best
                }
            });
        let v = if off.length() > 1e-9 * size {
            // Normal to `u` again: `off` inherits round-off when the points are nearly collinear.
            (off - u * u.dot(off)).normalize()
        } else {
            u.any_orthonormal_vector()
        };
        Self { origin, u, v }
    }
    /// The point with plane coordinates `c` (body frame, m).
    #[inline]
    pub fn point(&self, c: Vector2) -> Vector {
        self.origin + self.u * c.x + self.v * c.y
    }
    /// The plane coordinates of `p` (its projection onto the plane).
    #[inline]
    pub fn coordinates(&self, p: Vector) -> Vector2 {
        let d = p - self.origin;
        Vector2::new(self.u.dot(d), self.v.dot(d))
    }
}

/// A sub-contact: a point of a joint with a tributary area, its spring forces, its accumulated
/// slip and the law's state — what the step reads and writes for every sub-contact — and a
/// face-face cell's grid indices, in what would be padding (80 bytes with
/// [`crate::law::CoulombSlip`]'s state, with or without them). Its position is given by
/// two coordinates on the contact's [`AnchorPlane`], its shear force by two components along the
/// joint's tangents ([`JointAxes`]). Its identity ([`SubKey`]) follows from its contact and its
/// grid indices, or for a node sits in its contact's [`NodeRecord`] ([`ContactPair::key`]); its
/// dashpot force, when the model keeps any, in a parallel list
/// ([`store::ContactStore::sub_dashpots`]), empty in a model without Rayleigh damping: 24 bytes
/// per sub-contact that such a model neither stores nor moves. Its world position and forces
/// follow from the contact, see [`ContactView::point`], [`ContactView::shear_force`] and
/// [`ContactView::total_force`].
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct SubContact<S> {
    /// Coordinates of the material point on the host block, on the contact's anchor plane (m).
    pub(crate) plane: Vector2,
    pub(crate) area: Real,
    /// Normal displacement `u_n` (m, positive = open).
    pub(crate) gap: Real,
    pub(crate) force: JointForce,
    /// Accumulated slip while sliding (m).
    pub(crate) slip: Real,
    /// Half sizes of the rectangle a face-face sub-contact's normal spring is integrated over
    /// (m, along the anchor plane's axes; `contact/spread.rs`), zero for a node.
    pub(crate) half: [f32; 2],
    pub(crate) status: JointStatus,
    /// A face-face cell's grid indices `(i, j)` ([`crate::geometry::SubKey::cell_indices`]),
    /// which with its joint's faces make its key ([`ContactPair::key`]); zero for a node.
    /// Written by detection (and a checkpoint's load) with the sub-contact, never by the step.
    pub(crate) cell: [u16; 2],
    pub(crate) state: S,
}

// A sub-contact with `CoulombSlip`'s state takes the 80 bytes `docs/performance.md` counts:
// its cell's grid indices sit in what was padding (checked at compile time).
const _: () = assert!(std::mem::size_of::<SubContact<crate::law::CoulombState>>() == 80);

impl<S> SubContact<S> {
    /// [`SubContact::half`] as a vector.
    #[inline(always)]
    pub(crate) fn half(&self) -> Vector2 {
        Vector2::new(self.half[0] as Real, self.half[1] as Real)
    }
}

/// What one contact applies to its two blocks: the resultant force on `b` (`−force` on `a`) and
/// the moments about the blocks' centroids (N, N·m, world).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct ContactWrench {
    /// Resultant force on `b` (N).
    pub force: Vector,
    /// Moment of the contact forces on `a` about `a`'s centroid (N·m).
    pub moment_a: Vector,
    /// Moment of the contact forces on `b` about `b`'s centroid (N·m).
    pub moment_b: Vector,
}
