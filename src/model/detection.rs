//! Contact re-detection with history transfer, the block → contact index, and the time step.

use rayon::prelude::*;

use super::changes::Changes;
use super::pipeline::Pipeline;
use super::{ModelState, BLOCK_CHUNK};
use crate::block::{Block, BlockId, RigidBlock};
use crate::contact::{
    AnchorPlane, ContactPair, ContactReference, ContactWrench, DisplacementMode, ForceMoments, SubContact,
    SubContactRecord,
};
use crate::error::{Error, Result};
use crate::geometry::{detect, BlockGeometry, BroadPhase, DetectedContact, NarrowPhaseScratch, SubcontactSeed};
use crate::law::{ConstitutiveLaw, JointAxes, JointForce, JointStatus};
use crate::math::{Matrix, Real, Vector};

/// Buffers reused from one detection to the next.
#[derive(Debug, Clone)]
pub(crate) struct DetectionScratch<S> {
    /// Set by the fused block pass ([`Model::advance_blocks`]) after it moved the blocks and
    /// took their rotation matrices and movement check for the next step: whether any block
    /// moved beyond the re-detection trigger. Taken (reset) by the next step.
    pub prepared: Option<bool>,
    broad: BroadPhase,
    narrow: NarrowPhaseScratch,
    candidates: Vec<(u32, u32)>,
    seeds: Vec<SubcontactSeed>,
    moved: Vec<bool>,
    pairs: Vec<ContactPair>,
    references: Vec<ContactReference>,
    wrenches: Vec<ContactWrench>,
    subs: Vec<SubContact<S>>,
    records: Vec<SubContactRecord>,
}

impl<S> Default for DetectionScratch<S> {
    fn default() -> Self {
        Self {
            prepared: None,
            broad: BroadPhase::default(),
            narrow: NarrowPhaseScratch::default(),
            candidates: Vec::new(),
            seeds: Vec::new(),
            moved: Vec::new(),
            pairs: Vec::new(),
            references: Vec::new(),
            wrenches: Vec::new(),
            subs: Vec::new(),
            records: Vec::new(),
        }
    }
}

impl<L: ConstitutiveLaw> ModelState<L> {
    /// The step's first pass over the blocks: their rotation matrices, which the contact pass
    /// reads instead of turning every contact's normals by quaternions, and (`check`) whether
    /// any material point of a block moved more than the re-detection trigger since the block's
    /// last detection. (After a step of a blockwise integrator the block pass has done this
    /// already, see [`DetectionScratch::prepared`].)
    pub(super) fn prepare_blocks(&mut self, pipeline: &mut Pipeline<L::State>, check: bool) -> bool {
        let trigger = self.params.contact.redetect_fraction * self.params.contact.tolerance;
        pipeline.rotations.resize(self.blocks.len(), Matrix::IDENTITY);
        pipeline
            .rotations
            .par_chunks_mut(BLOCK_CHUNK)
            .zip(self.blocks.par_chunks(BLOCK_CHUNK))
            .zip(self.ref_poses.par_chunks(BLOCK_CHUNK))
            .map(|((rotations, blocks), refs)| prepare_chunk(rotations, blocks, refs, check.then_some(trigger)))
            .reduce(|| false, |a, b| a || b)
    }

    /// Re-detects contacts: pairs where a block moved beyond the trigger get a fresh narrow phase
    /// with sub-contact history carried over by key; other pairs are kept as they are.
    pub(super) fn detect(&mut self, pipeline: &mut Pipeline<L::State>) -> Result<()> {
        let params = self.params.contact;
        let full = self.changes.need_full_detection() || self.params.mode == DisplacementMode::Small;
        let trigger = params.redetect_fraction * params.tolerance;
        let sc = &mut pipeline.detection;
        sc.moved.clear();
        sc.moved.extend(
            self.blocks
                .iter()
                .zip(&self.ref_poses)
                .map(|(b, r)| full || moved_beyond(b, r, trigger)),
        );
        sc.broad.pairs_incremental(
            self.blocks.iter().map(|b| (b.shape(), &b.state.pose)),
            params.tolerance,
            &mut sc.candidates,
        );
        let mut new = NewContacts {
            pairs: &mut sc.pairs,
            references: &mut sc.references,
            wrenches: &mut sc.wrenches,
            subs: &mut sc.subs,
            records: &mut sc.records,
        };
        new.clear();
        let old = OldContacts {
            pairs: &self.pairs,
            references: &self.references,
            subs: &self.subs,
            records: &self.sub_records,
        };
        for &(i, j) in &sc.candidates {
            let k_old = old.pairs.binary_search_by_key(&(i, j), |p| (p.a, p.b)).ok();
            let (bi, bj) = (&self.blocks[i as usize], &self.blocks[j as usize]);
            if bi.fixity().is_fixed() && bj.fixity().is_fixed() {
                continue;
            }
            if !sc.moved[i as usize] && !sc.moved[j as usize] {
                if let Some(k) = k_old {
                    new.keep(&old, k, self.wrenches.get(k).copied().unwrap_or_default());
                }
                continue;
            }
            sc.seeds.clear();
            let found = detect(
                BlockGeometry {
                    shape: bi.shape(),
                    pose: &bi.state.pose,
                },
                BlockGeometry {
                    shape: bj.shape(),
                    pose: &bj.state.pose,
                },
                k_old.map(|k| (old.pairs[k].kind, old.pairs[k].host_is_a)),
                &params,
                &mut sc.narrow,
                &mut sc.seeds,
            );
            let Some(dc) = found else { continue };
            if sc.seeds.is_empty() {
                continue;
            }
            let law = self
                .laws
                .index_of(bi.material(), bj.material())
                .ok_or(Error::MissingJointLaw {
                    a: bi.material(),
                    b: bj.material(),
                    block_a: BlockId(i),
                    block_b: BlockId(j),
                })?;
            new.add_detected(&old, k_old, (i, bi), (j, bj), &dc, law, &sc.seeds);
        }
        // The critical step is re-evaluated when a contact appeared or one grew by more than 5 %
        // since the last evaluation (lost contacts only make the step safer).
        let stiffer = sc.references.iter().any(|r| r.area > 1.05 * r.bound_area);
        let (work, dashpot) = dropped_work(
            old,
            (&sc.pairs, &sc.records),
            &sc.moved,
            &self.blocks,
            self.params.mode,
            if self.drift > 0.0 { self.drift } else { self.dt },
        );
        self.energy.joint_work += work;
        self.energy.damping += dashpot;
        std::mem::swap(&mut self.pairs, &mut sc.pairs);
        std::mem::swap(&mut self.references, &mut sc.references);
        std::mem::swap(&mut self.wrenches, &mut sc.wrenches);
        std::mem::swap(&mut self.subs, &mut sc.subs);
        std::mem::swap(&mut self.sub_records, &mut sc.records);
        for (i, moved) in sc.moved.iter().enumerate() {
            if *moved {
                self.ref_poses[i] = self.blocks[i].state.pose;
            }
        }
        self.detections += 1;
        self.rebuild_block_index(pipeline);
        // A forced full detection follows a change of laws, parameters or fixity: the step is
        // re-evaluated then too, as after a re-detection that found stiffer contacts. The flag
        // is set (or stays set) if that fails, so the error repeats rather than the run going on
        // with an unstable step.
        if stiffer || full || self.critical.is_none() {
            self.changes.insert(Changes::DETECTION);
            self.refresh_time_step(pipeline)?;
        }
        self.changes.clear();
        Ok(())
    }

    pub(super) fn rebuild_block_index(&mut self, pipeline: &mut Pipeline<L::State>) {
        let n = self.blocks.len();
        pipeline.block_offsets.clear();
        pipeline.block_offsets.resize(n + 1, 0);
        for p in &self.pairs {
            pipeline.block_offsets[p.a as usize + 1] += 1;
            pipeline.block_offsets[p.b as usize + 1] += 1;
        }
        for i in 0..n {
            pipeline.block_offsets[i + 1] += pipeline.block_offsets[i];
        }
        pipeline.block_contacts.clear();
        pipeline.block_contacts.resize(pipeline.block_offsets[n] as usize, 0);
        let mut fill: Vec<u32> = pipeline.block_offsets[..n].to_vec();
        // Each entry is `2 × contact + side`, side 1 when the block is the contact's `b`.
        for (c, p) in self.pairs.iter().enumerate() {
            for (k, side) in [(p.a as usize, 0), (p.b as usize, 1)] {
                pipeline.block_contacts[fill[k] as usize] = 2 * c as u32 + side;
                fill[k] += 1;
            }
        }
    }
}

/// The rotation matrices of a chunk of blocks and, given the re-detection `trigger`, whether
/// any of them moved beyond it since its reference pose in `refs`.
#[inline]
pub(super) fn prepare_chunk(
    rotations: &mut [Matrix],
    blocks: &[crate::block::RigidBlock],
    refs: &[crate::math::Pose],
    trigger: Option<Real>,
) -> bool {
    let mut moved = false;
    for ((rotation, b), r) in rotations.iter_mut().zip(blocks).zip(refs) {
        *rotation = Matrix::from_quat(b.state.pose.rotation);
        if let Some(trigger) = trigger {
            moved |= moved_beyond(b, r, trigger);
        }
    }
    moved
}

/// Whether the largest displacement of a point of the block since pose `r`, bounded by the
/// translation plus radius × rotation angle, exceeds `trigger`.
///
/// The angle `θ = 2 asin(s)`, with `s` the norm of the vector part of the relative rotation,
/// lies between `2s` and `πs`: the arcsine is evaluated only when the two bounds disagree.
fn moved_beyond(b: &crate::block::RigidBlock, r: &crate::math::Pose, trigger: Real) -> bool {
    let p = &b.state.pose;
    let translation = (p.translation - r.translation).length();
    let dq = p.rotation * r.rotation.inverse();
    let s = dq.xyz().length().min(1.0);
    let radius = b.radius;
    if translation + radius * 2.0 * s > trigger {
        return true;
    }
    if translation + radius * std::f64::consts::PI * s <= trigger {
        return false;
    }
    translation + radius * 2.0 * s.asin() > trigger
}

/// The contact lists before a re-detection, for [`dropped_work`].
struct OldContacts<'a, S> {
    pairs: &'a [ContactPair],
    references: &'a [ContactReference],
    subs: &'a [SubContact<S>],
    records: &'a [SubContactRecord],
}

/// The contact lists detection builds, swapped in for the model's at its end.
struct NewContacts<'a, S> {
    pairs: &'a mut Vec<ContactPair>,
    references: &'a mut Vec<ContactReference>,
    wrenches: &'a mut Vec<ContactWrench>,
    subs: &'a mut Vec<SubContact<S>>,
    records: &'a mut Vec<SubContactRecord>,
}

impl<S: Clone + Default> NewContacts<'_, S> {
    fn clear(&mut self) {
        self.pairs.clear();
        self.references.clear();
        self.wrenches.clear();
        self.subs.clear();
        self.records.clear();
    }

    /// Keeps old contact `k` as it is (neither block moved beyond the trigger), with its wrench.
    fn keep(&mut self, old: &OldContacts<'_, S>, k: usize, wrench: ContactWrench) {
        let p = &old.pairs[k];
        let mut kept = p.clone();
        kept.first = self.subs.len() as u32;
        self.subs.extend_from_slice(&old.subs[p.range()]);
        self.records.extend_from_slice(&old.records[p.range()]);
        self.pairs.push(kept);
        self.references.push(old.references[k].clone());
        self.wrenches.push(wrench);
    }

    /// Adds the contact the narrow phase found between blocks `i < j` (`seeds` its sub-contacts,
    /// `law` the index of its joint law), carrying the history of old contact `k_old` by
    /// sub-contact key when it joins the same features with the same host.
    #[allow(clippy::too_many_arguments)]
    fn add_detected(
        &mut self,
        old: &OldContacts<'_, S>,
        k_old: Option<usize>,
        (i, bi): (u32, &RigidBlock),
        (j, bj): (u32, &RigidBlock),
        dc: &DetectedContact,
        law: u32,
        seeds: &[SubcontactSeed],
    ) {
        let host = if dc.host_is_a { bi } else { bj };
        let bound_area = k_old.map_or(0.0, |k| old.references[k].bound_area);
        let old_subs = k_old.map(|k| {
            let p = &old.pairs[k];
            (p.kind.same_joint(&dc.kind) && p.host_is_a == dc.host_is_a)
                .then(|| (&old.subs[p.range()], &old.records[p.range()]))
        });
        let old_subs = old_subs.flatten();
        // Carried spring forces were composed in the old contact's axes: their shear forces
        // are components along its tangents, and the next step's energy increment needs its
        // normal as the previous one. A new contact starts with any tangents.
        let axes = match (k_old, old_subs) {
            (Some(k), Some(_)) => old.pairs[k].axes(),
            _ => JointAxes::from_normal(dc.normal),
        };
        let (old_subs, old_records) = old_subs.unwrap_or((&[], &[]));
        let anchors = AnchorPlane::through(seeds.iter().map(|s| s.anchor));
        let first = self.subs.len() as u32;
        for seed in seeds {
            let mut sub = SubContact {
                plane: anchors.coordinates(seed.anchor),
                area: seed.area,
                gap: seed.gap,
                force: JointForce::default(),
                slip: 0.0,
                status: JointStatus::Open,
                state: S::default(),
            };
            let mut record = SubContactRecord::new(seed.key);
            if let Ok(k) = old_records.binary_search_by_key(&seed.key, |r| r.key) {
                let o = &old_subs[k];
                sub.force = o.force;
                sub.slip = o.slip;
                sub.status = o.status;
                sub.state = o.state.clone();
                record = old_records[k].clone();
            }
            self.subs.push(sub);
            self.records.push(record);
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
        };
        pair.cache_local_faces(bi.shape(), bj.shape());
        pair.refresh_springs(self.subs);
        self.pairs.push(pair);
        self.wrenches.push(ContactWrench::default());
        self.references.push(ContactReference {
            ref_a: bi.state.pose.translation,
            ref_b: bj.state.pose.translation,
            ref_host_rotation: host.state.pose.rotation,
            area: seeds.iter().map(|s| s.area).sum(),
            bound_area,
        });
    }
}

/// The work still owed by sub-contacts that re-detection drops while they carry a force:
/// `(joint work, dashpot dissipation)` (J).
///
/// The blocks received each sub-contact force `F_{n−1}` for a whole step, but the joint work
/// books it by the trapezoidal rule, half in step `n − 1` and half in step `n`: a dropped
/// sub-contact never gets its second half `−½·F_{n−1}·Δu_n`, and the balance drifts by that much
/// at every drop. Evaluated before the new lists replace the old ones (`dt` is still the step
/// that produced the current poses); the stored energy that vanishes with the sub-contact is
/// not dissipation and shows in [`crate::Energies::balance_error`].
fn dropped_work<S>(
    old: OldContacts<'_, S>,
    new: (&[ContactPair], &[SubContactRecord]),
    moved: &[bool],
    blocks: &[crate::block::RigidBlock],
    mode: DisplacementMode,
    dt: Real,
) -> (Real, Real) {
    let (mut work, mut dashpot) = (0.0, 0.0);
    for (p, reference) in old.pairs.iter().zip(old.references) {
        let successor = new
            .0
            .binary_search_by_key(&(p.a, p.b), |q| (q.a, q.b))
            .ok()
            .map(|k| &new.0[k]);
        let carried = successor
            .filter(|q| q.kind.same_joint(&p.kind) && q.host_is_a == p.host_is_a)
            .map(|q| &new.1[q.range()]);
        // A contact between two blocks that did not move is kept as it was, with all its
        // sub-contacts.
        if carried.is_some() && !moved[p.a as usize] && !moved[p.b as usize] {
            continue;
        }
        let (sa, sb) = (&blocks[p.a as usize].state, &blocks[p.b as usize].state);
        let frame = p.frame(reference, &sa.pose, &sb.pose, mode);
        let (xa, xb) = reference.centroids(&sa.pose, &sb.pose, mode);
        for (s, r) in old.subs[p.range()].iter().zip(&old.records[p.range()]) {
            let spring = p.axes().force(&s.force);
            if spring == Vector::ZERO && r.dashpot == Vector::ZERO {
                continue;
            }
            if carried.is_some_and(|records| records.binary_search_by_key(&r.key, |t| t.key).is_ok()) {
                continue;
            }
            let pt = frame.transform_point(p.anchor(s));
            let v_rel =
                (sb.velocity + sb.angular_velocity.cross(pt - xb)) - (sa.velocity + sa.angular_velocity.cross(pt - xa));
            let du = v_rel * dt;
            work -= 0.5 * spring.dot(du);
            dashpot -= 0.5 * r.dashpot.dot(du);
        }
    }
    (work, dashpot)
}
