//! The read API of contacts: borrowed views over the model's contact storage.
//!
//! The storage itself (the contact list, the sub-contacts and their keys, laid out for the
//! step loop) is private to the crate, so that its layout can change without changing the API
//! or the checkpoint format. Users read a joint through [`ContactView`] and its sub-contacts
//! through [`SubContactView`]; code that does not need the law's own state reads either through
//! the law-free [`Contact`] trait.

use super::lanes::face_gap;
use super::spread::cell_response;
use super::{stored_node_frame, AnchorPlane, ContactPair, ContactReference, ContactWrench, SubContact};
use crate::block::BlockState;
use crate::geometry::{ContactKind, NodeId, Polyhedron, SubKey};
use crate::ids::BlockId;
use crate::law::{JointAxes, JointForce, JointStatus};
use crate::math::{Matrix, Pose, Real, Vector, Vector2};

/// The two blocks of a node contact as its views need them: a node's point and axes follow
/// from its key, the blocks' poses and shapes (`contact/node_step.rs`).
#[derive(Debug, Clone, Copy)]
pub(crate) struct NodeGeometry<'a> {
    pub states: [&'a BlockState; 2],
    pub rotations: [Matrix; 2],
    pub shapes: [&'a Polyhedron; 2],
}

impl NodeGeometry<'_> {
    /// The world point of a node sub-contact and the axes its forces are composed in.
    fn frame<S>(&self, sub: &SubContact<S>, key: SubKey) -> (Vector, JointAxes) {
        stored_node_frame(
            NodeId::from_key(key),
            sub.plane.x as usize,
            (self.states[0], &self.rotations[0], self.shapes[0]),
            (self.states[1], &self.rotations[1], self.shapes[1]),
        )
    }
}

/// What the views of a face-face contact need to place its cells' normal forces where the step
/// put them (`contact/spread.rs`): the gap over the anchor plane at the blocks' poses, and the
/// law, which says which cells carry no tension.
#[derive(Debug)]
pub(crate) struct CellGeometry<'a, S> {
    pub law: &'a dyn TensionFree<S>,
    /// Gap coefficients at the current poses ([`super::face_gap_coefficients`]).
    pub coefficients: (Real, Real, Real),
}

impl<S> Clone for CellGeometry<'_, S> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<S> Copy for CellGeometry<'_, S> {}

/// [`super::tension_free`] for a law whose type the views do not carry.
pub(crate) trait TensionFree<S>: std::fmt::Debug + Sync {
    fn tension_free(&self, state: &S) -> bool;
}

impl<L: crate::law::ConstitutiveLaw> TensionFree<L::State> for L {
    fn tension_free(&self, state: &L::State) -> bool {
        super::tension_free(self, state)
    }
}

/// A law-free read interface of a contact between two blocks: what outputs and analyses need,
/// whatever the joint law.
///
/// [`ContactView`] implements it; [`crate::analysis`] reads the masonry joints of an arch through it.
///
/// ```
/// use voussoir::contact::Contact;
///
/// /// Share of a joint's sub-contacts in compression.
/// fn closed_share(joint: &impl Contact) -> f64 {
///     let n = joint.subcontact_count();
///     (0..n).filter(|&i| joint.subcontact(i).normal_force > 0.0).count() as f64 / n.max(1) as f64
/// }
/// ```
pub trait Contact {
    /// The two blocks, `a` < `b`.
    fn blocks(&self) -> (BlockId, BlockId);
    /// Unit normal of the joint plane, from `a` to `b` (world).
    fn normal(&self) -> Vector;
    /// Resultant force on block `b` (N, world); the force on `a` is its opposite.
    fn resultant(&self) -> Vector;
    /// Sum of the sub-contact normal forces (N, compression positive).
    fn normal_force(&self) -> Real;
    /// Number of sub-contacts.
    fn subcontact_count(&self) -> usize;
    /// The sub-contact at `index` (below [`Contact::subcontact_count`]), law state left out.
    ///
    /// # Panics
    /// If `index` is out of range.
    fn subcontact(&self, index: usize) -> SubContactSample;
}

/// One sub-contact's values, copied out of the model, without the law's own state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SubContactSample {
    /// World position (m).
    pub point: Vector,
    /// Where the normal force acts (m, world): see [`SubContactView::normal_force_point`].
    pub normal_force_point: Vector,
    /// Tributary area (m²).
    pub area: Real,
    /// Normal force (N, compression positive).
    pub normal_force: Real,
    /// Shear spring force on block `b` (N, world, in the joint plane).
    pub shear_force: Vector,
    /// Normal displacement `u_n` (m, positive = open).
    pub normal_displacement: Real,
    /// Slip accumulated while sliding (m).
    pub slip: Real,
    /// Status after the last update.
    pub status: JointStatus,
}

/// A borrowed view of one contact (two blocks that touch) and its sub-contacts, as of the last
/// step.
///
/// ```
/// use voussoir::prelude::*;
///
/// let mut model: Model = Model::new(ModelParameters::default())?;
/// model.set_joint_law(MaterialId(0), MaterialId(0), CoulombSlip::dry(1e9, 4e8, 30.0)?)?;
/// let base = model.add_block(
///     RigidBlock::cuboid("base", Vector::new(-1.0, -1.0, -0.2), Vector::new(1.0, 1.0, 0.0), 2500.0)?
///         .with_fixity(Fixity::FIXED),
/// )?;
/// let cube = model.add_block(RigidBlock::cuboid("cube", Vector::ZERO, Vector::splat(0.2), 2500.0)?)?;
/// model.run_to_equilibrium(1e-4, 20_000)?;
/// let joint = model.contact_between(base, cube).expect("in contact");
/// let weight = 2500.0 * 0.008 * 9.81;
/// assert!((joint.normal_force() - weight).abs() < 1e-3 * weight);
/// // The sub-contacts carry the weight between them, all on the base's top face.
/// let sum: f64 = joint.subcontacts().map(|s| s.normal_force()).sum();
/// assert!((sum - joint.normal_force()).abs() < 1e-9 * weight);
/// assert!(joint.subcontacts().all(|s| s.point().z.abs() < 1e-3 && s.status() == JointStatus::Elastic));
/// # Ok::<(), voussoir::Error>(())
/// ```
#[derive(Debug, Clone, Copy)]
pub struct ContactView<'a, S> {
    pair: &'a ContactPair,
    subs: &'a [SubContact<S>],
    /// The contact's reference: a node contact's keys.
    reference: &'a ContactReference,
    /// The sub-contacts' dashpot forces, or empty when the model keeps none.
    dashpots: &'a [Vector],
    /// Maps anchors to world points: the host block's pose (its pose at detection in
    /// small-displacement mode).
    frame: Pose,
    wrench: ContactWrench,
    nodes: Option<NodeGeometry<'a>>,
    cells: Option<CellGeometry<'a, S>>,
}

impl<'a, S> ContactView<'a, S> {
    pub(crate) fn new(
        pair: &'a ContactPair,
        subs: &'a [SubContact<S>],
        (reference, dashpots): (&'a ContactReference, &'a [Vector]),
        frame: Pose,
        wrench: ContactWrench,
        (nodes, cells): (Option<NodeGeometry<'a>>, Option<CellGeometry<'a, S>>),
    ) -> Self {
        debug_assert!(nodes.is_none() || reference.node_keys().len() == subs.len());
        debug_assert!(dashpots.is_empty() || dashpots.len() == subs.len());
        Self {
            pair,
            subs,
            reference,
            dashpots,
            frame,
            wrench,
            nodes,
            cells,
        }
    }

    /// The two blocks, `a` < `b`.
    pub fn blocks(&self) -> (BlockId, BlockId) {
        (BlockId(self.pair.a), BlockId(self.pair.b))
    }
    /// Contact case (a face-face joint, or a node contact).
    pub fn kind(&self) -> ContactKind {
        self.pair.kind
    }
    /// Whether the sub-contacts are anchored to block `a` (else `b`).
    pub(crate) fn host_is_a(&self) -> bool {
        self.pair.host_is_a
    }
    /// Unit normal a → b (world).
    pub fn normal(&self) -> Vector {
        self.pair.normal
    }
    /// The joint's normal and tangents (world); sub-contact shear forces are components along
    /// the tangents.
    pub fn axes(&self) -> JointAxes {
        self.pair.axes()
    }
    /// The plane of the sub-contact anchors in the host block's body frame.
    pub fn anchor_plane(&self) -> &'a AnchorPlane {
        &self.pair.anchors
    }
    /// Sum of the sub-contact normal forces (N, compression positive).
    pub fn normal_force(&self) -> Real {
        self.pair.normal_force
    }
    /// Index of the joint law in the model's [`crate::law::LawTable`].
    pub fn law_index(&self) -> usize {
        self.pair.law as usize
    }
    /// Resultant force on `b` (N, world), spring and dashpot forces, as of the last step (zero
    /// for a contact that detection has just found).
    pub fn resultant(&self) -> Vector {
        self.wrench.force
    }
    /// The resultant with its moments about the centroids of `a` and `b`.
    pub fn wrench(&self) -> ContactWrench {
        self.wrench
    }
    /// Number of sub-contacts.
    pub fn subcontact_count(&self) -> usize {
        self.subs.len()
    }
    /// The sub-contacts, in order.
    pub fn subcontacts(&self) -> impl ExactSizeIterator<Item = SubContactView<'a, S>> + 'a {
        let (pair, frame, nodes, cells, dashpots) = (self.pair, self.frame, self.nodes, self.cells, self.dashpots);
        let reference = self.reference;
        self.subs.iter().enumerate().map(move |(i, sub)| SubContactView {
            pair,
            frame,
            sub,
            live: pair.joint.live(i, sub),
            key: pair.key(reference, i, sub),
            dashpot: dashpots.get(i).copied().unwrap_or(Vector::ZERO),
            nodes,
            cells,
        })
    }
    /// The sub-contact at `index`, if any.
    pub fn subcontact(&self, index: usize) -> Option<SubContactView<'a, S>> {
        let sub = self.subs.get(index)?;
        Some(SubContactView {
            pair: self.pair,
            frame: self.frame,
            sub,
            live: self.pair.joint.live(index, sub),
            key: self.pair.key(self.reference, index, sub),
            dashpot: self.dashpots.get(index).copied().unwrap_or(Vector::ZERO),
            nodes: self.nodes,
            cells: self.cells,
        })
    }
    /// The centre of the sub-contacts' normal forces (m, world; each force where it acts within
    /// its cell): where the resultant gives the contact's moment about any axis in the joint
    /// plane. `None` for a contact that carries no compression.
    pub fn application_point(&self) -> Option<Vector> {
        let (mut total, mut moment) = (0.0, Vector::ZERO);
        for s in self.subcontacts() {
            let n = s.normal_force();
            if n > 0.0 {
                total += n;
                moment += s.normal_force_point() * n;
            }
        }
        (total > 0.0).then(|| moment / total)
    }
    /// World positions of the sub-contacts, in order (m).
    pub fn points(&self) -> impl ExactSizeIterator<Item = Vector> + 'a {
        self.subcontacts().map(|s| s.point())
    }
}

impl<S> Contact for ContactView<'_, S> {
    fn blocks(&self) -> (BlockId, BlockId) {
        ContactView::blocks(self)
    }
    fn normal(&self) -> Vector {
        ContactView::normal(self)
    }
    fn resultant(&self) -> Vector {
        ContactView::resultant(self)
    }
    fn normal_force(&self) -> Real {
        ContactView::normal_force(self)
    }
    fn subcontact_count(&self) -> usize {
        ContactView::subcontact_count(self)
    }
    fn subcontact(&self, index: usize) -> SubContactSample {
        let s = ContactView::subcontact(self, index).expect("sub-contact index out of range");
        SubContactSample {
            point: s.point(),
            normal_force_point: s.normal_force_point(),
            area: s.area(),
            normal_force: s.normal_force(),
            shear_force: s.shear_force(),
            normal_displacement: s.normal_displacement(),
            slip: s.slip(),
            status: s.status(),
        }
    }
}

/// A borrowed view of one sub-contact: a point of a joint with its tributary area, spring
/// forces, slip and the law's own state, as of the last step.
#[derive(Debug, Clone, Copy)]
pub struct SubContactView<'a, S> {
    pair: &'a ContactPair,
    frame: Pose,
    sub: &'a SubContact<S>,
    /// The sub-contact's force, gap and status as they stand: its own, or those of its joint
    /// while the joint is stepped as a whole (`joint_level/`).
    live: (JointForce, Real, JointStatus),
    /// Its key ([`ContactPair::key`]).
    key: SubKey,
    /// Its dashpot force (zero when the model keeps none).
    dashpot: Vector,
    nodes: Option<NodeGeometry<'a>>,
    cells: Option<CellGeometry<'a, S>>,
}

impl<'a, S> SubContactView<'a, S> {
    /// Stable identity within the block pair (carries history across re-detection).
    pub fn key(&self) -> SubKey {
        self.key
    }
    /// Coordinates of the anchor on the contact's [`AnchorPlane`] (m). For a node of a
    /// [`ContactKind::Nodes`] contact: the index of the other block's face it was last pressed
    /// out of, and 0.
    pub fn plane_coordinates(&self) -> Vector2 {
        self.sub.plane
    }
    /// Material point on the host block, in its body frame (m); for a node, on the block its
    /// key names ([`SubContactView::node_on_b`]).
    pub fn anchor(&self) -> Vector {
        match &self.nodes {
            Some(g) => {
                let id = NodeId::from_key(self.key);
                id.point(g.shapes[id.on_b as usize])
            }
            None => self.pair.anchors.point(self.sub.plane),
        }
    }
    /// For a node of a [`ContactKind::Nodes`] contact, whether it is a point of block `b`
    /// (else of `a`); `None` for a sub-contact of a face–face joint.
    pub fn node_on_b(&self) -> Option<bool> {
        self.nodes.map(|_| NodeId::from_key(self.key).on_b)
    }
    /// The joint axes this sub-contact's forces are composed in: the contact's, or for a node
    /// those of the face it is pressed out of.
    pub fn axes(&self) -> JointAxes {
        match &self.nodes {
            Some(g) => g.frame(self.sub, self.key).1,
            None => self.pair.axes(),
        }
    }
    /// World position (m).
    pub fn point(&self) -> Vector {
        match &self.nodes {
            Some(g) => g.frame(self.sub, self.key).0,
            None => self.frame.transform_point(self.anchor()),
        }
    }
    /// Where the normal force acts (m, world). A face-face cell whose law carries no tension
    /// in its state has its normal spring integrated over the cell (`docs/theory.md` §2.3): its
    /// force acts at the centre of the compression over the cell, which lies within the cell
    /// and moves towards the closed side as the joint opens (at a hinge, towards the hinge's
    /// edge), as of the blocks' current poses. Elsewhere (a node, a bonded cell, small
    /// displacements), [`SubContactView::point`].
    pub fn normal_force_point(&self) -> Vector {
        match &self.cells {
            Some(c) if self.live.0.normal > 0.0 && c.law.tension_free(&self.sub.state) => {
                let plane = self.sub.plane;
                let gap = face_gap(c.coefficients, plane.x, plane.y);
                let slope = Vector2::new(-c.coefficients.1, -c.coefficients.2);
                let cell = cell_response(gap, slope, self.sub.half(), self.sub.area);
                self.frame.transform_point(self.pair.anchors.point(plane + cell.offset))
            }
            _ => self.point(),
        }
    }
    /// Tributary area (m²).
    pub fn area(&self) -> Real {
        self.sub.area
    }
    /// Normal displacement `u_n` (m, positive = open).
    pub fn normal_displacement(&self) -> Real {
        self.live.1
    }
    /// Normal force (N, compression positive).
    pub fn normal_force(&self) -> Real {
        self.live.0.normal
    }
    /// Normal stress (Pa, compression positive).
    pub fn normal_stress(&self) -> Real {
        self.live.0.normal / self.sub.area
    }
    /// Shear spring force on block `b` as components along the joint's tangents
    /// ([`ContactView::axes`]) (N).
    pub fn shear_components(&self) -> Vector2 {
        self.live.0.shear
    }
    /// Shear spring force on block `b` (N, world, in the joint plane).
    pub fn shear_force(&self) -> Vector {
        self.axes().shear(self.live.0.shear)
    }
    /// Stiffness-proportional (Rayleigh) dashpot force on block `b` (N, world); zero without
    /// Rayleigh damping.
    pub fn dashpot_force(&self) -> Vector {
        self.dashpot
    }
    /// Spring plus dashpot force on block `b` (N, world).
    pub fn total_force(&self) -> Vector {
        self.axes().force(&self.live.0) + self.dashpot
    }
    /// Slip accumulated while sliding (m): the sum of the shear displacement increments of the
    /// steps that ended sliding.
    pub fn slip(&self) -> Real {
        self.sub.slip
    }
    /// Status after the last update.
    pub fn status(&self) -> JointStatus {
        self.live.2
    }
    /// The law's own state ([`crate::ConstitutiveLaw::State`]).
    pub fn law_state(&self) -> &'a S {
        &self.sub.state
    }
}
