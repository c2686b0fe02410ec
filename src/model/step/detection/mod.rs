//! Contact re-detection with history transfer, the block → contact index, and the time step.

use parry3d_f64::bounding_volume::{Aabb, BoundingVolume};
use parry3d_f64::shape::Shape;
use rayon::prelude::*;

use super::changes::Changes;
use crate::block::{Block, BlockId, BlockMotion, RigidBlock};
use crate::contact::{integrated_stiffness, DisplacementMode};
use crate::error::{Error, Result};
use crate::geometry::BroadPhase;
use crate::law::ConstitutiveLaw;
use crate::math::{Pose, Real};
use crate::model::Pipeline;
use crate::model::{ModelState, BLOCK_CHUNK};

#[cfg(test)]
mod detection_tests;
mod pairs;
mod splice;
mod staging;

pub(crate) use pairs::TestedPair;
use pairs::*;
use splice::*;
use staging::*;

/// The staging lists are freed after a detection when they hold more than this share of the
/// sub-contacts' room (`1/STAGING_FRACTION`): a full re-detection must not leave a second copy
/// of the contacts behind.
const STAGING_FRACTION: usize = 8;

/// A contact keeps its geometry at a detection while its blocks moved less than this fraction
/// of the trigger relative to each other since its test. Until the next look, at the next
/// detection where one of its blocks moved the trigger, the pair moves relatively by up to three
/// more triggers (`docs/theory.md` §2.3): its geometry lags its relative motion by at most 3.5
/// triggers, 0.875 of the tolerance at the defaults, as a block clipped afresh lags by up to 3.
const KEEP_FRACTION: Real = 0.5;

/// Planned pairs per batch of the narrow phase (`MAX_PLAN_CHUNK` per task).
const BATCH: usize = 64 * MAX_PLAN_CHUNK;

/// Planned pairs per task of the parallel narrow phase, at most: a batch is split in 64 tasks,
/// of at least `MIN_PLAN_CHUNK` pairs (the few pairs of a local re-detection still run in
/// parallel). Each pair's outcome depends on that pair alone, so the split does not change it.
/// A batch's seeds are held at once (48 bytes each, about 17 per pair of a wall): 4,096 pairs
/// hold 3 MB.
const MAX_PLAN_CHUNK: usize = 64;

const MIN_PLAN_CHUNK: usize = 4;

/// The pairs per task of the narrow phase over `pairs` planned pairs.
fn plan_chunk(pairs: usize) -> usize {
    pairs.min(BATCH).div_ceil(64).clamp(MIN_PLAN_CHUNK, MAX_PLAN_CHUNK)
}

/// Buffers reused from one detection to the next.
#[derive(Debug, Clone)]
pub(crate) struct DetectionScratch<S> {
    /// Set by the fused block pass ([`ModelState::block_pass`](crate::model::ModelState::block_pass)) after it moved the blocks and
    /// took their rotation matrices and movement check for the next step: whether any block
    /// moved beyond the re-detection trigger. Taken (reset) by the next step.
    pub prepared: Option<bool>,
    /// Pairs the narrow phase tested since the model was built (a statistic, like the timings).
    pub tests: u64,
    broad: BroadPhase,
    candidates: Vec<(u32, u32)>,
    /// Whether each block is fixed (as of the last detection).
    fixed: Vec<bool>,
    /// The pairs of the contacts and of [`ModelState::tested`], in order: what [`plan`] looks
    /// up, packed. Taken afresh when the lists change other than in place.
    contact_keys: Vec<(u32, u32)>,
    tested_keys: Vec<(u32, u32)>,
    plan: Vec<Planned>,
    outcomes: Vec<Outcome>,
    chunks: Vec<ChunkScratch>,
    /// Blocks that moved beyond the trigger since their reference poses, as the last block pass
    /// (or [`ModelState::prepare_blocks`]) found them.
    pub moved: Vec<bool>,
    /// Each block's box at its reference pose, loosened to hold it at any pose within the
    /// trigger ([`reference_box`]): the broad phase's boxes.
    boxes: Vec<Aabb>,
    /// Old contacts kept as they were.
    kept: Vec<bool>,
    /// Per joint law: whether node contacts of that law are integrated (large-displacement
    /// mode, `NodeRule::Integrated`, a linear normal spring), so
    /// that a loaded one may turn back into a joint ([`ContactPair::may_turn_back`]). Taken at
    /// each detection.
    integrated_laws: Vec<bool>,
    /// The contacts after detection, in order, and where each one's sub-contacts start.
    layout: Vec<Slot>,
    firsts: Vec<u32>,
    runs: Vec<Run>,
    sub_runs: Vec<SubRun>,
    /// The in-place splice's re-tested contacts, and the kept ones it pushes back.
    replaced: Vec<Replaced>,
    pushed: Vec<Pushed>,
    /// The room (sub-contacts, dead or alive) the in-place splice may use before a full splice
    /// compacts the lists: set by the full splice.
    room_limit: usize,
    /// How the splices went (statistics).
    pub splices: SpliceCounts,
    /// Which splices may run (tests compare them).
    #[cfg(test)]
    pub splice_mode: SpliceMode,
    /// Whether contacts changed places (the block → contact index is rebuilt).
    reindex: bool,
    /// Merge buffer of [`update_tested`].
    tested: Vec<TestedPair>,
    /// The contacts detected afresh, in plan order, with the history of the old ones.
    staging: StagedLists<S>,
    /// Whether the staging lists are in a fresh layout (a full detection), and the
    /// sub-contacts of their last segment so far.
    staging_spread: bool,
    segment_subs: u32,
}

impl<S> DetectionScratch<S> {
    /// Whether a test asks for a fresh layout at every full splice.
    #[cfg(test)]
    fn fresh_forced(&self) -> bool {
        self.splice_mode == SpliceMode::Fresh
    }

    #[cfg(not(test))]
    fn fresh_forced(&self) -> bool {
        false
    }

    /// Frees the staging lists (after they held a large share of the contacts).
    fn release_staging(&mut self) {
        self.staging = StagedLists::default();
    }

    /// Frees the buffers sized by a full detection's candidate pairs: the plan, the outcomes,
    /// the candidates and the tasks' seeds.
    fn release_full(&mut self) {
        self.release_staging();
        self.candidates = Vec::new();
        self.plan = Vec::new();
        self.outcomes = Vec::new();
        for chunk in &mut self.chunks {
            chunk.seeds = Vec::new();
        }
    }

    /// Gives the contacts found in the planned pairs `batch` (tasks of `chunk` pairs) their
    /// places in the staging lists, after those already staged, in plan order: each outcome's
    /// `staged` and `first_sub`, each task's `place`. In a fresh layout (`staging_spread`)
    /// [`segment_slack`] follows every [`SEGMENT`] contacts.
    fn place_staged(&mut self, batch: std::ops::Range<usize>, chunk: usize) {
        let (mut contacts, mut cursor) = (
            self.staging.store.pairs.len() as u32,
            self.staging.store.subs.len() as u32,
        );
        for (k, outcomes) in self.outcomes[batch].chunks_mut(chunk).enumerate() {
            self.chunks[k].place = (contacts, cursor);
            for o in outcomes {
                if o.contact.is_none() || o.seed_count == 0 {
                    o.staged = u32::MAX;
                    continue;
                }
                (o.staged, o.first_sub) = (contacts, cursor);
                contacts += 1;
                cursor += o.seed_count;
                if self.staging_spread {
                    self.segment_subs += o.seed_count;
                    if (contacts as usize).is_multiple_of(SEGMENT) {
                        cursor += segment_slack(self.segment_subs);
                        self.segment_subs = 0;
                    }
                }
            }
        }
        self.staging.placed = (contacts as usize, cursor as usize);
    }
}

/// Whether the node contacts of joint law `law` are integrated, by the detection's table of the
/// laws ([`DetectionScratch`]'s `integrated_laws`): a law index the laws no longer have (they
/// changed since the contact was made) reads as not integrated. The turn-back test, the
/// handover of forces and the dropped work all ask here, of the old contact's law.
pub(super) fn law_integrated(integrated_laws: &[bool], law: u32) -> bool {
    integrated_laws.get(law as usize) == Some(&true)
}

impl<S> Default for DetectionScratch<S> {
    fn default() -> Self {
        Self {
            prepared: None,
            tests: 0,
            broad: BroadPhase::default(),
            candidates: Vec::new(),
            fixed: Vec::new(),
            contact_keys: Vec::new(),
            tested_keys: Vec::new(),
            plan: Vec::new(),
            outcomes: Vec::new(),
            chunks: Vec::new(),
            moved: Vec::new(),
            boxes: Vec::new(),
            kept: Vec::new(),
            integrated_laws: Vec::new(),
            layout: Vec::new(),
            firsts: Vec::new(),
            runs: Vec::new(),
            sub_runs: Vec::new(),
            replaced: Vec::new(),
            pushed: Vec::new(),
            room_limit: 0,
            splices: SpliceCounts::default(),
            #[cfg(test)]
            splice_mode: SpliceMode::Any,
            reindex: false,
            tested: Vec::new(),
            staging: StagedLists::default(),
            staging_spread: false,
            segment_subs: 0,
        }
    }
}

/// The motions of a chunk of blocks ([`BlockMotion`]: poses, velocities, rotation matrices) and,
/// given the re-detection `trigger`, which of them moved beyond it since their reference poses
/// in `refs` (`moved`, all `false` without a trigger); returns whether any did.
#[inline]
pub(in crate::model) fn prepare_chunk(
    motions: &mut [BlockMotion],
    moved: &mut [bool],
    blocks: &[RigidBlock],
    refs: &[Pose],
    trigger: Option<Real>,
) -> bool {
    let mut any = false;
    for (((motion, moved), b), r) in motions.iter_mut().zip(moved).zip(blocks).zip(refs) {
        *motion = BlockMotion::of(b);
        *moved = trigger.is_some_and(|trigger| moved_beyond(b, r, trigger));
        any |= *moved;
    }
    any
}

/// The box of a block at its reference pose `r` loosened by `reach`: half the contact
/// tolerance plus the trigger, so that it holds the block's box loosened by half the tolerance
/// at any pose within the trigger of `r`.
fn reference_box(b: &RigidBlock, r: &Pose, reach: Real) -> Aabb {
    b.shape().parry().compute_aabb(r).loosened(reach)
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

/// The block → contact index of the pipeline (`Pipeline::block_contacts`).
#[derive(Clone, Copy)]
struct BlockIndex<'a> {
    offsets: &'a [u32],
    contacts: &'a [u32],
}

impl<L: ConstitutiveLaw> ModelState<L> {
    /// The step's first pass over the blocks: their motions ([`BlockMotion`]: the poses,
    /// velocities and rotation matrices the contact pass reads, in one compact list), and (`check`) which
    /// blocks moved more than the re-detection trigger since their reference poses (the flags in
    /// [`DetectionScratch::moved`]; whether any did is returned). (After a step of a blockwise
    /// integrator the block pass has done this already, see [`DetectionScratch::prepared`].)
    pub(in crate::model) fn prepare_blocks(&mut self, pipeline: &mut Pipeline<L::State>, check: bool) -> bool {
        let trigger = self.params.contact.redetect_fraction * self.params.contact.tolerance;
        let n = self.blocks.len();
        pipeline.motions.resize(n, BlockMotion::default());
        pipeline.detection.moved.resize(n, false);
        pipeline
            .motions
            .par_chunks_mut(BLOCK_CHUNK)
            .zip(pipeline.detection.moved.par_chunks_mut(BLOCK_CHUNK))
            .zip(self.blocks.par_chunks(BLOCK_CHUNK))
            .zip(self.found.ref_poses.par_chunks(BLOCK_CHUNK))
            .map(|(((motions, moved), blocks), refs)| {
                prepare_chunk(motions, moved, blocks, refs, check.then_some(trigger))
            })
            .reduce(|| false, |a, b| a || b)
    }

    /// Whether node contacts of joint law `law` are integrated over the surface each node stands
    /// for ([`integrated_stiffness`], the step's own test).
    fn nodes_integrated(&self, law: usize) -> bool {
        integrated_stiffness(&self.laws.laws()[law], self.params.mode, self.params.contact.node_rule).is_some()
    }

    /// Re-detects contacts (`docs/theory.md` §2.3).
    ///
    /// Only pairs with a block that moved beyond the trigger since its reference pose are looked
    /// at (the flags the last block pass left in [`DetectionScratch::moved`]; a full detection
    /// looks at every pair). Of those, a pair the narrow phase tested before keeps its verdict
    /// while the relative pose of its two blocks stays within the trigger (a contact) or within
    /// its separation beyond the tolerance (a pair found apart) of the one it was tested at; the
    /// others are tested afresh, in parallel, and their sub-contacts take the history of the old
    /// ones by key. Where the contacts keep their pairs and sub-contact counts (the usual case),
    /// the re-tested contacts are rewritten in place; otherwise the lists are rebuilt in pair
    /// order. Either way the result does not depend on the number of threads.
    pub(in crate::model) fn detect(&mut self, pipeline: &mut Pipeline<L::State>) -> Result<()> {
        let params = self.params.contact;
        let full = self.changes.need_full_detection() || self.params.mode == DisplacementMode::Small;
        let trigger = params.redetect_fraction * params.tolerance;
        let n = self.blocks.len();
        let sc = &mut pipeline.detection;
        sc.integrated_laws.clear();
        sc.integrated_laws
            .extend((0..self.laws.laws().len()).map(|law| self.nodes_integrated(law)));
        if full || sc.moved.len() != n {
            sc.moved.clear();
            sc.moved.resize(n, true);
        }
        // A joint stepped as a whole that detection may look at again (one of its blocks
        // moved) has its cells written first: detection reads their history.
        let store = &mut self.contacts;
        for p in store.pairs.iter_mut() {
            if p.joint.active && (sc.moved[p.a as usize] || sc.moved[p.b as usize]) {
                let range = p.range();
                p.joint.write_cells(&mut store.subs[range]);
            }
        }
        // The moved blocks take their current poses as reference poses, and their boxes.
        let reach = 0.5 * params.tolerance + trigger;
        let fresh_boxes = sc.boxes.len() != n;
        if fresh_boxes {
            sc.boxes.clear();
            sc.boxes.extend(
                self.blocks
                    .iter()
                    .zip(&self.found.ref_poses)
                    .map(|(b, r)| reference_box(b, r, reach)),
            );
        }
        self.found
            .ref_poses
            .par_chunks_mut(BLOCK_CHUNK)
            .zip(sc.boxes.par_chunks_mut(BLOCK_CHUNK))
            .zip(self.blocks.par_chunks(BLOCK_CHUNK))
            .zip(sc.moved.par_chunks(BLOCK_CHUNK))
            .for_each(|(((refs, boxes), blocks), moved)| {
                let moved_blocks = refs.iter_mut().zip(boxes).zip(blocks).zip(moved).filter(|(_, m)| **m);
                for (((r, bx), b), _) in moved_blocks {
                    *r = b.state.pose;
                    *bx = reference_box(b, r, reach);
                }
            });
        sc.broad
            .pairs_of_moved_boxes(&sc.boxes, &sc.moved, params.tolerance, &mut sc.candidates);
        if full || sc.fixed.len() != n {
            sc.fixed.clear();
            sc.fixed.extend(self.blocks.iter().map(|b| b.fixity().is_fixed()));
        } else {
            // A change of fixity asks for a full detection, but a base motion prescribes the
            // velocities of its block's axes (`Fixed` becomes `Velocity`) without one, and its
            // block keeps them once the motion is removed: the flags of the moved blocks and of
            // those under a motion are taken afresh (a planned pair has a moved block).
            for i in (0..n).filter(|&i| sc.moved[i]) {
                sc.fixed[i] = self.blocks[i].fixity().is_fixed();
            }
            for m in &self.excitations.motions {
                sc.fixed[m.block as usize] = self.blocks[m.block as usize].fixity().is_fixed();
            }
        }
        if sc.contact_keys.len() != self.contacts.pairs.len() {
            sc.contact_keys.clear();
            sc.contact_keys.extend(self.contacts.pairs.iter().map(|p| (p.a, p.b)));
        }
        if sc.tested_keys.len() != self.found.tested.len() {
            sc.tested_keys.clear();
            sc.tested_keys.extend(self.found.tested.iter().map(|t| (t.a, t.b)));
        }
        plan(
            &sc.candidates,
            &sc.fixed,
            &sc.moved,
            &sc.tested_keys,
            &sc.contact_keys,
            &mut sc.plan,
        );
        sc.outcomes.clear();
        sc.outcomes.resize(sc.plan.len(), Outcome::default());
        let chunk = plan_chunk(sc.plan.len());
        let chunks = sc.plan.len().min(BATCH).div_ceil(chunk);
        if sc.chunks.len() < chunks {
            sc.chunks.resize_with(chunks, ChunkScratch::default);
        }
        // (Taken out while the tests borrow it, put back for the splice.)
        let integrated_laws = std::mem::take(&mut sc.integrated_laws);
        let test = PairTest {
            integrated_laws: &integrated_laws,
            blocks: &self.blocks,
            tested: &self.found.tested,
            params: &params,
            keep_within: (!full).then_some(KEEP_FRACTION * trigger),
            pairs: &self.contacts.pairs,
            subs: &self.contacts.subs,
            dashpots: &self.contacts.sub_dashpots,
        };
        // In batches, so that the seeds of a full detection are not all held at once: the tests
        // of a batch in parallel; the places of its contacts in the staging lists, in plan
        // order; then each task writes its contacts into its part of the lists, in parallel.
        // A full detection stages its contacts in a fresh layout (`place_subcontacts`): dead
        // room after every `SEGMENT` contacts.
        sc.staging.lists().clear();
        sc.staging.store.dashpots_kept = self.contacts.dashpots_kept;
        // The contacts' geometry at detection, in small-displacement mode only (the splice
        // makes the model's lists keep it or drop it alike).
        sc.staging
            .store
            .keep_small_refs(self.params.mode == DisplacementMode::Small);
        sc.staging_spread = full;
        sc.segment_subs = 0;
        for start in (0..sc.plan.len()).step_by(BATCH) {
            if pipeline.interrupt.as_ref().is_some_and(|check| check.stop()) {
                // Nothing of the contacts has changed yet, but the moved blocks took their
                // reference poses: the next detection is a full one.
                self.changes.insert(Changes::DETECTION);
                return Err(Error::Interrupted { step: self.clock.step });
            }
            let batch = start..(start + BATCH).min(sc.plan.len());
            sc.outcomes[batch.clone()]
                .par_chunks_mut(chunk)
                .zip(sc.plan[batch.clone()].par_chunks(chunk))
                .zip(sc.chunks.par_iter_mut())
                .for_each(|((outcomes, plan), scratch)| test.run(plan, outcomes, scratch));
            if self.clock.started {
                // Blocks passing through each other (the joints overloaded): an error at the
                // first such pair in plan order, before anything changes. (At the first
                // detection, deep initial overlaps are `Error::InitialOverlap`.)
                if let Some(e) = self.overlap_error(sc, batch.clone()) {
                    // The moved blocks took their reference poses already: the next
                    // detection is a full one.
                    self.changes.insert(Changes::DETECTION);
                    return Err(e);
                }
            }
            let tasks = batch.len().div_ceil(chunk);
            sc.place_staged(batch.clone(), chunk);
            let slices = sc.staging.grow();
            self.stage(
                &mut sc.chunks[..tasks],
                &sc.plan[batch.clone()],
                &mut sc.outcomes[batch],
                (chunk, &integrated_laws),
                slices,
            )?;
        }
        sc.integrated_laws = integrated_laws;
        if sc.staging_spread && sc.staging.store.pairs.len().is_multiple_of(SEGMENT) {
            // No dead room after the last segment.
            let end = sc
                .staging
                .store
                .pairs
                .last()
                .map_or(0, |p| (p.first + p.count) as usize);
            sc.staging.store.subs.truncate(end);
            sc.staging.store.sub_dashpots.truncate(end);
        }
        let index = BlockIndex {
            offsets: &pipeline.block_offsets,
            contacts: &pipeline.block_contacts,
        };
        #[cfg(test)]
        let index = Some(index).filter(|_| sc.splice_mode == SpliceMode::Any);
        #[cfg(not(test))]
        let index = Some(index);
        let (in_place, (work, dashpot)) = match index.and_then(|index| self.splice_in_place(sc, index)) {
            Some(owed) => (true, owed),
            None => (false, self.splice_contacts(sc)?),
        };
        self.energy.joint_work += work;
        self.energy.damping += dashpot;
        if !in_place {
            sc.contact_keys.clear();
            sc.contact_keys.extend(self.contacts.pairs.iter().map(|p| (p.a, p.b)));
        }
        // A full detection follows a change of parameters (the tolerance that the slack of a
        // pair found apart was measured against): its entries are merged afresh.
        let merged = !update_tested(
            &mut self.found.tested,
            &sc.plan,
            &sc.outcomes,
            &sc.moved,
            in_place && !full,
            &mut sc.tested,
        );
        if merged {
            sc.tested_keys.clear();
            sc.tested_keys.extend(self.found.tested.iter().map(|t| (t.a, t.b)));
        }
        sc.tests += sc.outcomes.iter().filter(|o| o.tested).count() as u64;
        self.found.detections += 1;
        if sc.reindex {
            self.rebuild_block_index(pipeline);
        }
        // The critical step is re-evaluated when a contact appeared or one grew by more than 5 %
        // since the last evaluation (lost contacts only make the step safer): the bounds of
        // those contacts' blocks. A forced full detection follows a change of laws, parameters
        // or fixity: every block's bound is re-evaluated then. The flag is set (or stays set) if
        // that fails, so the error repeats rather than the run going on with an unstable step.
        if full || self.clock.critical.is_none() {
            self.changes.insert(Changes::DETECTION);
            self.refresh_time_step(pipeline)?;
        } else {
            let mut blocks = std::mem::take(&mut pipeline.refresh_blocks);
            blocks.clear();
            if in_place {
                let replaced = &pipeline.detection.replaced;
                self.take_grown(replaced.iter().map(|r| r.contact as usize), &mut blocks);
            } else {
                self.take_grown(0..self.contacts.pairs.len(), &mut blocks);
            }
            let grew = !blocks.is_empty();
            pipeline.refresh_blocks = blocks;
            if grew {
                self.changes.insert(Changes::DETECTION);
                self.refresh_time_step_of_grown(pipeline)?;
            }
        }
        if full {
            // A full detection's buffers (the plan and outcomes of every candidate pair, a
            // batch's seeds) are not what the next, local detections need: freed.
            pipeline.detection.release_full();
        }
        self.changes.clear();
        Ok(())
    }

    /// [`Error::Overlap`] for the first pair of `batch` (in plan order) whose overlap exceeds
    /// half the smaller block's radius.
    fn overlap_error(&self, sc: &DetectionScratch<L::State>, batch: std::ops::Range<usize>) -> Option<Error> {
        sc.plan[batch.clone()]
            .iter()
            .zip(&sc.outcomes[batch])
            .filter(|(_, o)| o.overlap > 0.0)
            .find_map(|(p, o)| {
                let limit = 0.5 * self.blocks[p.a as usize].radius.min(self.blocks[p.b as usize].radius);
                (o.overlap > limit).then_some(Error::Overlap {
                    step: self.clock.step,
                    a: BlockId(p.a),
                    b: BlockId(p.b),
                    depth: o.overlap,
                    limit,
                })
            })
    }

    /// The index of the joint law between blocks `i` and `j`: their interface's own, else
    /// their materials'.
    fn law_index(&self, i: u32, j: u32) -> Result<u32> {
        let (bi, bj) = (&self.blocks[i as usize], &self.blocks[j as usize]);
        self.laws
            .index_for((BlockId(i), bi.material()), (BlockId(j), bj.material()))
            .ok_or(Error::MissingJointLaw {
                a: bi.material(),
                b: bj.material(),
                block_a: BlockId(i),
                block_b: BlockId(j),
            })
    }

    pub(in crate::model) fn rebuild_block_index(&mut self, pipeline: &mut Pipeline<L::State>) {
        let n = self.blocks.len();
        pipeline.block_offsets.clear();
        pipeline.block_offsets.resize(n + 1, 0);
        for p in &self.contacts.pairs {
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
        for (c, p) in self.contacts.pairs.iter().enumerate() {
            for (k, side) in [(p.a as usize, 0), (p.b as usize, 1)] {
                pipeline.block_contacts[fill[k] as usize] = 2 * c as u32 + side;
                fill[k] += 1;
            }
        }
    }
}
