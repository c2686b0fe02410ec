//! Staging the contacts a detection found: their places in the staging lists, in pair order,
//! and each task of the narrow phase writing its contacts into its part of them.

use rayon::prelude::*;

use super::*;
use crate::block::{Block, RigidBlock};
use crate::contact::{
    node_frame, stored_node_frame, AnchorPlane, ContactLists, ContactPair, ContactReference, ContactStore,
    ContactWrench, ForceMoments, OldContacts, SmallReference, SubContact,
};
use crate::error::Result;
use crate::geometry::{face_frame, ContactKind, DetectedContact, NodeId, SubContactSeed, SubKey, PARALLEL_ANGLE};
use crate::law::{ConstitutiveLaw, JointAxes, JointForce, JointStatus};
use crate::math::{Matrix, Real, Vector, Vector2};
use crate::model::ModelState;

/// A sub-contact to fill dead room with (never read).
pub(super) fn dead_subcontact<S: Default>() -> SubContact<S> {
    SubContact {
        plane: Vector2::ZERO,
        area: 0.0,
        gap: 0.0,
        force: JointForce::default(),
        slip: 0.0,
        half: [0.0; 2],
        status: JointStatus::Open,
        cell: [0; 2],
        state: S::default(),
    }
}

/// A contact and its reference to fill room in the staging lists with until a contact is
/// written there.
pub(super) fn dead_contact() -> (ContactPair, ContactReference) {
    let pair = ContactPair {
        a: 0,
        b: 0,
        kind: crate::geometry::ContactKind::Nodes,
        host_is_a: true,
        law: 0,
        first: 0,
        count: 0,
        normal: Vector::ZERO,
        tangent: Vector::ZERO,
        anchors: AnchorPlane::default(),
        plane_normal: Vector::ZERO,
        plane_offset: 0.0,
        dashpots: true,
        normal_force: 0.0,
        springs: ForceMoments::default(),
        spread_energy: 0.0,
        cells: Default::default(),
        joint: Default::default(),
    };
    let reference = ContactReference {
        area: 0.0,
        bound_area: 0.0,
        side: None,
    };
    (pair, reference)
}

/// Contacts staged by detection: the contact lists' own (owned) form, of the whole detection
/// and of each task of its narrow phase.
#[derive(Debug, Clone)]
pub(super) struct StagedLists<S> {
    /// The lists, as the model's.
    pub(super) store: ContactStore<S>,
    /// The contacts and sub-contacts (dead room included) placed so far.
    pub(super) placed: (usize, usize),
}

impl<S> Default for StagedLists<S> {
    fn default() -> Self {
        Self {
            store: ContactStore::default(),
            placed: (0, 0),
        }
    }
}

impl<S> StagedLists<S> {
    pub(super) fn lists(&mut self) -> ContactLists<'_, S> {
        self.store.lists()
    }
}

impl<S: Clone + Default + Send + Sync> StagedLists<S> {
    /// Extends the lists to the places [`DetectionScratch::place_staged`] gave (`placed`), with
    /// dead entries written in parallel (the first touch of a large list's memory is most of
    /// its cost), and returns the slices of the new entries, for the contacts to be written.
    pub(super) fn grow(&mut self) -> StagingSlices<'_, S> {
        let (pair_base, sub_base) = (self.store.pairs.len(), self.store.subs.len());
        let (contacts, subs) = self.placed;
        let (pair, reference) = dead_contact();
        let sub = dead_subcontact();
        self.store
            .pairs
            .par_extend(rayon::iter::repeat_n(pair, contacts - pair_base));
        self.store
            .references
            .par_extend(rayon::iter::repeat_n(reference, contacts - pair_base));
        self.store
            .wrenches
            .par_extend(rayon::iter::repeat_n(ContactWrench::default(), contacts - pair_base));
        if self.store.small_kept {
            self.store
                .small_refs
                .par_extend(rayon::iter::repeat_n(SmallReference::DEAD, contacts - pair_base));
        }
        self.store.subs.par_extend(rayon::iter::repeat_n(sub, subs - sub_base));
        if self.store.dashpots_kept {
            self.store
                .sub_dashpots
                .par_extend(rayon::iter::repeat_n(Vector::ZERO, subs - sub_base));
        }
        StagingSlices {
            pair_base,
            sub_base,
            pairs: &mut self.store.pairs[pair_base..],
            references: &mut self.store.references[pair_base..],
            wrenches: &mut self.store.wrenches[pair_base..],
            small_refs: if self.store.small_kept {
                &mut self.store.small_refs[pair_base..]
            } else {
                &mut []
            },
            subs: &mut self.store.subs[sub_base..],
            dashpots: if self.store.dashpots_kept {
                &mut self.store.sub_dashpots[sub_base..]
            } else {
                &mut []
            },
        }
    }
}

/// Slices of the staging lists that one task of the narrow phase writes its contacts into:
/// `pairs[0]` is contact `pair_base` of the detection, `subs[0]` its sub-contact `sub_base`.
pub(super) struct StagingSlices<'a, S> {
    pub(super) pair_base: usize,
    pub(super) sub_base: usize,
    pub(super) pairs: &'a mut [ContactPair],
    pub(super) references: &'a mut [ContactReference],
    pub(super) wrenches: &'a mut [ContactWrench],
    /// The contacts' small-displacement references, or empty when the lists keep none.
    pub(super) small_refs: &'a mut [SmallReference],
    pub(super) subs: &'a mut [SubContact<S>],
    /// The sub-contacts' dashpot forces, or empty when the model keeps none.
    pub(super) dashpots: &'a mut [Vector],
}

impl<'a, S> StagingSlices<'a, S> {
    /// The slices from contact `pair` and sub-contact `sub` of the detection on (the second
    /// part), and those before (the first).
    pub(super) fn split_at(self, pair: usize, sub: usize) -> (Self, Self) {
        let (p, s) = (pair - self.pair_base, sub - self.sub_base);
        let (pairs_a, pairs_b) = self.pairs.split_at_mut(p);
        let (references_a, references_b) = self.references.split_at_mut(p);
        let (wrenches_a, wrenches_b) = self.wrenches.split_at_mut(p);
        let (small_refs_a, small_refs_b) = if self.small_refs.is_empty() {
            (self.small_refs, &mut [][..])
        } else {
            self.small_refs.split_at_mut(p)
        };
        let (subs_a, subs_b) = self.subs.split_at_mut(s);
        let (dashpots_a, dashpots_b) = if self.dashpots.is_empty() {
            (self.dashpots, &mut [][..])
        } else {
            self.dashpots.split_at_mut(s)
        };
        (
            Self {
                pair_base: self.pair_base,
                sub_base: self.sub_base,
                pairs: pairs_a,
                references: references_a,
                wrenches: wrenches_a,
                small_refs: small_refs_a,
                subs: subs_a,
                dashpots: dashpots_a,
            },
            Self {
                pair_base: pair,
                sub_base: sub,
                pairs: pairs_b,
                references: references_b,
                wrenches: wrenches_b,
                small_refs: small_refs_b,
                subs: subs_b,
                dashpots: dashpots_b,
            },
        )
    }
}

impl<S: Clone + Default + PartialEq> StagingSlices<'_, S> {
    /// Writes the contact the narrow phase found between blocks `i < j` as contact `staged` of
    /// the detection, its sub-contacts (`seeds`) from `first` on (`law` the index of its joint
    /// law), carrying the history of old contact `k_old` by sub-contact key when it joins the
    /// same features with the same host. `large`: large-displacement mode; `integrated`: whether
    /// the old contact's nodes are integrated (its law's, [`super::law_integrated`]), so that a
    /// loaded node contact turning into a joint hands its forces to the cells.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn write_detected<L>(
        &mut self,
        (staged, first): (u32, u32),
        old: &OldContacts<'_, S>,
        k_old: Option<usize>,
        (i, bi): (u32, &RigidBlock),
        (j, bj): (u32, &RigidBlock),
        dc: &DetectedContact,
        (law, joint_law): (u32, &L),
        (large, integrated): (bool, bool),
        seeds: &[SubContactSeed],
    ) where
        L: ConstitutiveLaw<State = S>,
    {
        let host = if dc.host_is_a { bi } else { bj };
        let bound_area = k_old.map_or(0.0, |k| old.references[k].bound_area);
        let old_subs = k_old.map(|k| {
            let p = &old.pairs[k];
            debug_assert!(!p.joint.active, "a joint stepped as a whole re-detected unwritten");
            (p.kind.same_joint(&dc.kind) && p.host_is_a == dc.host_is_a)
                .then(|| (p, &old.references[k], &old.subs[p.range()], p.first as usize))
        });
        let old_subs = old_subs.flatten();
        // Carried spring forces were composed in the old contact's axes: their shear forces
        // are components along its tangents, and the next step's energy increment needs its
        // normal as the previous one. A new contact starts with any tangents.
        let axes = match (k_old, old_subs) {
            (Some(k), Some(_)) => old.pairs[k].axes(),
            _ => JointAxes::from_normal(dc.normal),
        };
        // The sub-contact of the old contact with a key, if any.
        let old_index = |key| old_subs.and_then(|(p, reference, subs, _)| p.find_key(reference, subs, key));
        let old_first = old_subs.map_or(0, |(.., first)| first);
        let old_subs = old_subs.map_or(&[][..], |(_, _, subs, _)| subs);
        let old_anchors = k_old.map_or(AnchorPlane::default(), |k| old.pairs[k].anchors);
        // A face-face contact's anchors lie on the host face, in its frame: the frame its
        // cells' rectangles are aligned with (`contact/spread.rs`).
        let anchors = match dc.kind {
            ContactKind::FaceFace { face_a, face_b } => {
                let (shape, face) = if dc.host_is_a {
                    (bi.shape(), face_a)
                } else {
                    (bj.shape(), face_b)
                };
                let (origin, u, v) = face_frame(shape, face as usize);
                AnchorPlane { origin, u, v }
            }
            ContactKind::Nodes => AnchorPlane::through(seeds.iter().map(|s| s.anchor)),
        };
        let at = first as usize - self.sub_base;
        let subs = &mut self.subs[at..at + seeds.len()];
        // Empty when the model keeps no dashpot forces.
        let dashpots = self.dashpots.get_mut(at..at + seeds.len()).unwrap_or(&mut []);
        let nodes = matches!(dc.kind, ContactKind::Nodes);
        // The state a new sub-contact starts from: a node contact is unbonded
        // (`ConstitutiveLaw::unbonded_state`), a face joint's cell virgin.
        let fresh = if nodes {
            joint_law.unbonded_state()
        } else {
            S::default()
        };
        // Faces tilted beyond `PARALLEL_ANGLE` meet along the edge that digs in, where the
        // loaded cells are and their gaps vary steeply.
        let tilted = match dc.kind {
            ContactKind::FaceFace { face_a, face_b } => {
                let na = bi.state.pose.rotation * bi.shape().faces()[face_a as usize].normal;
                let nb = bj.state.pose.rotation * bj.shape().faces()[face_b as usize].normal;
                -na.dot(nb) < PARALLEL_ANGLE.cos()
            }
            ContactKind::Nodes => false,
        };
        let rotations = (
            Matrix::from_quat(bi.state.pose.rotation),
            Matrix::from_quat(bj.state.pose.rotation),
        );
        for (n, (seed, sub_slot)) in seeds.iter().zip(subs.iter_mut()).enumerate() {
            let plane = if nodes {
                // A node's plane coordinates hold the face of the other block it lies deepest
                // under (`contact/node_step.rs`).
                let frame = node_frame(
                    NodeId::from_key(seed.key),
                    (&bi.state, &rotations.0, bi.shape()),
                    (&bj.state, &rotations.1, bj.shape()),
                );
                Vector2::new(frame.face as Real, 0.0)
            } else {
                anchors.coordinates(seed.anchor)
            };
            let mut sub = SubContact {
                plane,
                area: seed.area,
                gap: seed.gap,
                force: JointForce::default(),
                slip: 0.0,
                half: [seed.half.x as f32, seed.half.y as f32],
                status: JointStatus::Open,
                cell: match dc.kind {
                    ContactKind::FaceFace { .. } => seed.key.cell_indices(),
                    ContactKind::Nodes => [0; 2],
                },
                state: fresh.clone(),
            };
            debug_assert!(match dc.kind {
                ContactKind::FaceFace { face_a, face_b } => seed.key.is_cell_of(face_a, face_b),
                ContactKind::Nodes => true,
            });
            let mut dashpot = Vector::ZERO;
            if let Some(k) = old_index(seed.key) {
                let o = &old_subs[k];
                if nodes {
                    // Its shear force is stored along the tangents of that face.
                    sub.plane = o.plane;
                } else if tilted && o.force.normal != 0.0 {
                    // A loaded cell of a tilted joint keeps its place and area until it
                    // unloads: its spring energy `½ k A g²` stays a function of the poses,
                    // where a refresh of a partly covered cell under load would make or
                    // destroy `½ k ΔA g²` at the deepest gaps (`docs/theory.md` §2.3). Faces
                    // parallel within `PARALLEL_ANGLE` are refreshed: their gaps are nearly
                    // uniform, and a face sliding over a larger one takes its support along.
                    sub.plane = anchors.coordinates(old_anchors.point(o.plane));
                    sub.area = o.area;
                    sub.half = o.half;
                }
                sub.force = o.force;
                sub.slip = o.slip;
                sub.status = o.status;
                sub.state = o.state.clone();
                dashpot = old.dashpot(old_first + k);
            }
            *sub_slot = sub;
            if let Some(slot) = dashpots.get_mut(n) {
                *slot = dashpot;
            }
        }
        if let Some(k) = k_old.filter(|&k| {
            let p = &old.pairs[k];
            p.hands_forces_to_cells(&old.subs[p.range()], integrated, &dc.kind)
        }) {
            let p = &old.pairs[k];
            hand_node_forces_to_cells(
                (&old.subs[p.range()], old.references[k].node_keys()),
                (bi, &rotations.0),
                (bj, &rotations.1),
                (host, &anchors, &axes),
                joint_law,
                subs,
            );
        }
        let mut pair = ContactPair {
            a: i,
            b: j,
            kind: dc.kind,
            host_is_a: dc.host_is_a,
            law,
            first,
            count: seeds.len() as u32,
            normal: axes.normal,
            tangent: axes.tangent,
            anchors,
            plane_normal: Vector::ZERO,
            plane_offset: 0.0,
            dashpots: true,
            normal_force: 0.0,
            springs: ForceMoments::default(),
            spread_energy: 0.0,
            cells: Default::default(),
            joint: Default::default(),
        };
        pair.cache_local_faces(bi.shape(), bj.shape());
        pair.refresh_springs(subs, joint_law, large.then_some((&bi.state.pose, &bj.state.pose)));
        let k = staged as usize - self.pair_base;
        self.pairs[k] = pair;
        self.wrenches[k] = ContactWrench::default();
        // Kept in small-displacement mode only (empty otherwise).
        if let Some(small) = self.small_refs.get_mut(k) {
            *small = SmallReference {
                ref_a: bi.state.pose.translation,
                ref_b: bj.state.pose.translation,
                ref_host_rotation: host.state.pose.rotation,
            };
        }
        self.references[k] = ContactReference {
            area: seeds.iter().map(|s| s.area).sum(),
            bound_area,
            // A node contact's keys name its nodes (a cell's follows from its contact).
            side: if nodes {
                ContactReference::nodes(seeds.iter().map(|s| s.key).collect())
            } else {
                None
            },
        };
    }
}

/// Hands the forces of a loaded node contact's nodes (`nodes`: its sub-contacts and keys) to
/// the cells of the face-face joint it turns into (`cells`, fresh; `docs/theory.md` §6,
/// "Contact transitions"): each node's force (world, as it stands) goes to the cell whose
/// rectangle on the joint's anchor plane lies nearest its point, composed in the joint's
/// `axes`, so that the contact's resultant is kept and its moment moves by the distance from a
/// node to its cell (less than a cell), and a node's normal force along its load's resultant,
/// within 1° of the joint's normal, leaves up to sin 1° of itself as shear history. The normal
/// forces only start the trapezoidal work of the joint's first step (the cells' own follow from
/// their gaps); the shear forces are the joint's history. A cell takes the largest accumulated
/// slip and the most advanced status of its nodes; its law state stays the fresh one, which the
/// nodes had ([`ContactPair::may_turn_back`]).
///
/// The cells' shear springs must not store more than the nodes' did: the loaded cells cover the
/// loaded part of the joint exactly, where the nodes' shares reach beyond it (an edge node's
/// strip on the side face), so the same forces on less area store more (up to 1.5 times in a
/// closing voussoir joint of `arch_impact`), and the law books what a cell's first step
/// releases of it as friction. The cells' shear forces are then scaled down together until
/// they store what the nodes stored; what they store less stays in the balance (never more).
fn hand_node_forces_to_cells<L: ConstitutiveLaw>(
    (nodes, keys): (&[SubContact<L::State>], &[SubKey]),
    (bi, rotation_a): (&RigidBlock, &Matrix),
    (bj, rotation_b): (&RigidBlock, &Matrix),
    (host, anchors, axes): (&RigidBlock, &AnchorPlane, &JointAxes),
    law: &L,
    cells: &mut [SubContact<L::State>],
) {
    debug_assert_eq!(nodes.len(), keys.len());
    for (node, key) in nodes.iter().zip(keys) {
        if node.force == JointForce::default() && node.slip == 0.0 {
            continue;
        }
        let (point, node_axes) = stored_node_frame(
            NodeId::from_key(*key),
            node.plane.x as usize,
            (&bi.state, rotation_a, bi.shape()),
            (&bj.state, rotation_b, bj.shape()),
        );
        let x = anchors.coordinates(host.state.pose.inverse_transform_point(point));
        let outside = |c: &SubContact<L::State>| ((x - c.plane).abs() - c.half()).max(Vector2::ZERO).length();
        let Some(cell) = cells
            .iter_mut()
            .reduce(|best, c| if outside(c) < outside(best) { c } else { best })
        else {
            return;
        };
        let f = node_axes.force(&node.force);
        cell.force.normal += axes.normal.dot(f);
        cell.force.shear += axes.components(f);
        cell.slip = cell.slip.max(node.slip);
        cell.status = match (cell.status, node.status) {
            (JointStatus::Sliding, _) | (_, JointStatus::Sliding) => JointStatus::Sliding,
            (JointStatus::Elastic, _) | (_, JointStatus::Elastic) => JointStatus::Elastic,
            _ => JointStatus::Open,
        };
    }
    let ks = law.stiffness().shear;
    let shear_energy = |subs: &[SubContact<L::State>]| -> Real {
        subs.iter()
            .filter(|s| s.area > 0.0)
            .map(|s| s.force.shear.length_squared() / (2.0 * ks * s.area))
            .sum()
    };
    if ks > 0.0 {
        let (stored, handed) = (shear_energy(nodes), shear_energy(cells));
        if handed > stored {
            let scale = (stored / handed).sqrt();
            for cell in cells.iter_mut() {
                cell.force.shear *= scale;
            }
        }
    }
}

impl<L: ConstitutiveLaw> ModelState<L> {
    /// Stages the contacts the narrow phase found in the planned pairs of `chunks` (`chunk`
    /// pairs each, the last one possibly fewer) at the places [`DetectionScratch::place_staged`]
    /// gave them, with the history of the old ones: the tasks in parallel, each into its part of
    /// the staging lists. The error is the first in plan order (a missing joint law).
    pub(super) fn stage(
        &self,
        chunks: &mut [ChunkScratch],
        plan: &[Planned],
        outcomes: &mut [Outcome],
        (chunk, integrated_laws): (usize, &[bool]),
        slices: StagingSlices<'_, L::State>,
    ) -> Result<()> {
        if chunks.len() > 1 {
            let mid = chunks.len() / 2;
            let (pair, sub) = chunks[mid].place;
            let (slices_a, slices_b) = slices.split_at(pair as usize, sub as usize);
            let (chunks_a, chunks_b) = chunks.split_at_mut(mid);
            let (plan_a, plan_b) = plan.split_at(mid * chunk);
            let (outcomes_a, outcomes_b) = outcomes.split_at_mut(mid * chunk);
            let (a, b) = rayon::join(
                || self.stage(chunks_a, plan_a, outcomes_a, (chunk, integrated_laws), slices_a),
                || self.stage(chunks_b, plan_b, outcomes_b, (chunk, integrated_laws), slices_b),
            );
            return a.and(b);
        }
        let Some(scratch) = chunks.first() else { return Ok(()) };
        let old = OldContacts {
            pairs: &self.contacts.pairs,
            references: &self.contacts.references,
            small_refs: &self.contacts.small_refs,
            subs: &self.contacts.subs,
            dashpots: &self.contacts.sub_dashpots,
        };
        let mut slices = slices;
        for (p, o) in plan.iter().zip(outcomes) {
            if o.staged == u32::MAX {
                continue;
            }
            let Some(dc) = o.contact.take() else { continue };
            let seeds = &scratch.seeds[o.first_seed as usize..(o.first_seed + o.seed_count) as usize];
            let (bi, bj) = (&self.blocks[p.a as usize], &self.blocks[p.b as usize]);
            let law = self.law_index(p.a, p.b)?;
            // Whether the old contact's nodes are integrated, by its own law (as its turn-back
            // test and its dropped work ask).
            let integrated = p
                .old_contact()
                .is_some_and(|k| super::law_integrated(integrated_laws, self.contacts.pairs[k].law));
            slices.write_detected(
                (o.staged, o.first_sub),
                &old,
                p.old_contact(),
                (p.a, bi),
                (p.b, bj),
                &dc,
                (law, &self.laws.laws()[law as usize]),
                (self.params.mode == crate::contact::DisplacementMode::Large, integrated),
                seeds,
            );
        }
        Ok(())
    }
}
