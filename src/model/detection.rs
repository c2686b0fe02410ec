//! Contact re-detection with history transfer, the block → contact index, and the time step.

use parry3d_f64::bounding_volume::{Aabb, BoundingVolume};
use parry3d_f64::shape::Shape;
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
use crate::geometry::{
    detect, BlockGeometry, BroadPhase, ContactParameters, DetectedContact, NarrowPhaseScratch, SubcontactSeed,
};
use crate::law::{ConstitutiveLaw, JointAxes, JointForce, JointStatus};
use crate::math::{Matrix, Pose, Real, Vector};

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

/// Planned pairs per batch of the narrow phase (`PLAN_CHUNK` per task).
const BATCH: usize = 64 * PLAN_CHUNK;

/// Planned pairs per task of the parallel narrow phase.
const PLAN_CHUNK: usize = 256;

/// A block pair the narrow phase tested, with the relative pose it was tested at: its verdict
/// holds until the pair has moved relatively past the trigger (a contact) or past `slack` (a
/// pair found apart), as looked at when one of its blocks moves past the trigger
/// (`docs/theory.md` §2.3). Sorted by `(a, b)` in [`ModelState::tested`]; every contact has one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct TestedPair {
    pub a: u32,
    pub b: u32,
    /// The pose of the pair's smaller block (by radius; `b` on a tie) in the body frame of the
    /// other, at the test ([`relative_pose`]).
    pub relative: Pose,
    /// For a pair found apart, its separation beyond the contact tolerance (m), which it may
    /// close before it can come within the tolerance; 0 otherwise.
    pub slack: Real,
}

/// Buffers reused from one detection to the next.
#[derive(Debug, Clone)]
pub(crate) struct DetectionScratch<S> {
    /// Set by the fused block pass ([`Model::advance_blocks`]) after it moved the blocks and
    /// took their rotation matrices and movement check for the next step: whether any block
    /// moved beyond the re-detection trigger. Taken (reset) by the next step.
    pub prepared: Option<bool>,
    /// Pairs the narrow phase tested since the model was built (a statistic, like the timings).
    pub tests: u64,
    broad: BroadPhase,
    candidates: Vec<(u32, u32)>,
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
    /// The contacts after detection, in order, and where each one's sub-contacts start.
    layout: Vec<Slot>,
    firsts: Vec<u32>,
    runs: Vec<Run>,
    /// Whether contacts changed places (the block → contact index is rebuilt).
    reindex: bool,
    /// Merge buffer of [`update_tested`].
    tested: Vec<TestedPair>,
    pairs: Vec<ContactPair>,
    references: Vec<ContactReference>,
    wrenches: Vec<ContactWrench>,
    subs: Vec<SubContact<S>>,
    records: Vec<SubContactRecord>,
}

impl<S> DetectionScratch<S> {
    /// Frees the staging lists (after they held a large share of the contacts).
    fn release_staging(&mut self) {
        self.pairs = Vec::new();
        self.references = Vec::new();
        self.wrenches = Vec::new();
        self.subs = Vec::new();
        self.records = Vec::new();
    }
}

impl<S> Default for DetectionScratch<S> {
    fn default() -> Self {
        Self {
            prepared: None,
            tests: 0,
            broad: BroadPhase::default(),
            candidates: Vec::new(),
            plan: Vec::new(),
            outcomes: Vec::new(),
            chunks: Vec::new(),
            moved: Vec::new(),
            boxes: Vec::new(),
            kept: Vec::new(),
            layout: Vec::new(),
            firsts: Vec::new(),
            runs: Vec::new(),
            reindex: false,
            tested: Vec::new(),
            pairs: Vec::new(),
            references: Vec::new(),
            wrenches: Vec::new(),
            subs: Vec::new(),
            records: Vec::new(),
        }
    }
}

/// A contact after detection: an old one kept (its index), or one detected afresh (its index
/// in the staging lists).
#[derive(Debug, Clone, Copy)]
enum Slot {
    Kept(u32),
    Staged(u32),
}

/// Which runs of kept contacts [`ContactLists::move_run`] moves.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Direction {
    /// Those that move towards the front (or stay), run by run from the first.
    Front,
    /// Those that move towards the back, run by run from the last.
    Back,
}

impl<S> ContactLists<'_, S> {
    /// Moves a run of old contacts to its new indices and their sub-contacts to start at
    /// `first`, each of the two if it moves in `direction`, by rotating the run with the dead
    /// room it moves into. The `Back` pass comes second, and sets the contacts' `first`.
    fn move_run(&mut self, run: &Run, first: u32, direction: Direction) {
        let (c, k, len) = (run.old as usize, run.new as usize, run.len as usize);
        // Where the run is now: at `k` once the `Front` pass moved it there.
        let at = if direction == Direction::Back && k <= c { k } else { c };
        let start = self.pairs[at].first as usize;
        let end = {
            let last = &self.pairs[at + len - 1];
            (last.first + last.count) as usize
        };
        let to = first as usize;
        match direction {
            Direction::Front if k < c => {
                self.pairs[k..c + len].rotate_left(c - k);
                self.references[k..c + len].rotate_left(c - k);
                self.wrenches[k..c + len].rotate_left(c - k);
            }
            Direction::Back if k > c => {
                self.pairs[c..k + len].rotate_right(k - c);
                self.references[c..k + len].rotate_right(k - c);
                self.wrenches[c..k + len].rotate_right(k - c);
            }
            _ => {}
        }
        match direction {
            Direction::Front if to < start => {
                self.subs[to..end].rotate_left(start - to);
                self.records[to..end].rotate_left(start - to);
            }
            Direction::Back if to > start => {
                let new_end = to + (end - start);
                self.subs[start..new_end].rotate_right(to - start);
                self.records[start..new_end].rotate_right(to - start);
            }
            _ => {}
        }
        if direction == Direction::Back {
            let mut next = first;
            for pair in &mut self.pairs[k..k + len] {
                pair.first = next;
                next += pair.count;
            }
        }
    }
}

/// Consecutive old contacts `old..old + len` that go to `new..new + len`.
#[derive(Debug, Clone, Copy)]
struct Run {
    old: u32,
    new: u32,
    len: u32,
}

/// A candidate pair of the broad phase (two blocks not both fixed), with its entries in the
/// lists of the last detection.
#[derive(Debug, Clone, Copy)]
struct Planned {
    a: u32,
    b: u32,
    /// Index in [`ModelState::tested`], or `u32::MAX`.
    tested: u32,
    /// Index of its contact, or `u32::MAX`.
    contact: u32,
}

impl Planned {
    fn old_tested(&self) -> Option<usize> {
        (self.tested != u32::MAX).then_some(self.tested as usize)
    }

    fn old_contact(&self) -> Option<usize> {
        (self.contact != u32::MAX).then_some(self.contact as usize)
    }
}

/// What the narrow phase made of a planned pair.
#[derive(Debug, Clone)]
struct Outcome {
    /// Tested afresh (else its last verdict holds).
    tested: bool,
    /// The test's entry for [`ModelState::tested`].
    entry: TestedPair,
    contact: Option<DetectedContact>,
    /// The contact's seeds in its chunk's buffer.
    first_seed: u32,
    seed_count: u32,
    /// Its index in the staging lists, once staged (else `u32::MAX`).
    staged: u32,
}

impl Default for Outcome {
    fn default() -> Self {
        Self {
            tested: false,
            entry: TestedPair {
                a: 0,
                b: 0,
                relative: Pose::IDENTITY,
                slack: 0.0,
            },
            contact: None,
            first_seed: 0,
            seed_count: 0,
            staged: u32::MAX,
        }
    }
}

/// One task's buffers of the parallel narrow phase.
#[derive(Debug, Clone, Default)]
struct ChunkScratch {
    narrow: NarrowPhaseScratch,
    seeds: Vec<SubcontactSeed>,
}

impl ChunkScratch {
    fn seeds(&self, o: &Outcome) -> &[SubcontactSeed] {
        &self.seeds[o.first_seed as usize..(o.first_seed + o.seed_count) as usize]
    }
}

/// What the parallel narrow phase reads.
struct PairTest<'a> {
    blocks: &'a [RigidBlock],
    tested: &'a [TestedPair],
    pairs: &'a [ContactPair],
    params: &'a ContactParameters,
    /// The relative motion within which a contact keeps its verdict; `None` tests every pair.
    keep_within: Option<Real>,
}

impl PairTest<'_> {
    /// Decides and, where needed, tests one chunk of planned pairs.
    fn run(&self, plan: &[Planned], outcomes: &mut [Outcome], scratch: &mut ChunkScratch) {
        scratch.seeds.clear();
        for (p, o) in plan.iter().zip(outcomes) {
            o.tested = false;
            let (bi, bj) = (&self.blocks[p.a as usize], &self.blocks[p.b as usize]);
            let (relative, radius) = relative_pose(bi, bj);
            if let (Some(trigger), Some(t)) = (self.keep_within, p.old_tested()) {
                let last = &self.tested[t];
                let within = if p.old_contact().is_some() { trigger } else { last.slack };
                if relative_motion(&relative, &last.relative, radius) <= within {
                    continue;
                }
            }
            let first = scratch.seeds.len();
            let previous = p.old_contact().map(|c| (self.pairs[c].kind, self.pairs[c].host_is_a));
            let found = detect(
                BlockGeometry {
                    shape: bi.shape(),
                    pose: &bi.state.pose,
                },
                BlockGeometry {
                    shape: bj.shape(),
                    pose: &bj.state.pose,
                },
                previous,
                self.params,
                &mut scratch.narrow,
                &mut scratch.seeds,
            );
            let separation = scratch.narrow.separation();
            *o = Outcome {
                tested: true,
                entry: TestedPair {
                    a: p.a,
                    b: p.b,
                    relative,
                    slack: if found.is_none() && separation > self.params.tolerance {
                        separation - self.params.tolerance
                    } else {
                        0.0
                    },
                },
                first_seed: first as u32,
                seed_count: (scratch.seeds.len() - first) as u32,
                staged: u32::MAX,
                contact: found,
            };
        }
    }
}

/// The candidate pairs with a block that moved, not between two fixed blocks, each with its
/// entries in the sorted `tested` and `pairs` of the last detection (a merge of sorted lists).
fn plan(
    candidates: &[(u32, u32)],
    blocks: &[RigidBlock],
    moved: &[bool],
    tested: &[TestedPair],
    pairs: &[ContactPair],
    out: &mut Vec<Planned>,
) {
    out.clear();
    let (mut t, mut c) = (0, 0);
    for &(a, b) in candidates {
        if !moved[a as usize] && !moved[b as usize] {
            continue;
        }
        if blocks[a as usize].fixity().is_fixed() && blocks[b as usize].fixity().is_fixed() {
            continue;
        }
        while t < tested.len() && (tested[t].a, tested[t].b) < (a, b) {
            t += 1;
        }
        while c < pairs.len() && (pairs[c].a, pairs[c].b) < (a, b) {
            c += 1;
        }
        let found_t = t < tested.len() && (tested[t].a, tested[t].b) == (a, b);
        let found_c = c < pairs.len() && (pairs[c].a, pairs[c].b) == (a, b);
        out.push(Planned {
            a,
            b,
            tested: if found_t { t as u32 } else { u32::MAX },
            contact: if found_c { c as u32 } else { u32::MAX },
        });
    }
}

/// Brings `tested` up to date with the detection's outcomes: in place when the planned pairs
/// are those with a moved block tested before, else merged afresh through `buffer` (the pairs of
/// two blocks that did not move keep their entries; those with a moved block that are no longer
/// candidates lose them).
fn update_tested(
    tested: &mut Vec<TestedPair>,
    plan: &[Planned],
    outcomes: &[Outcome],
    moved: &[bool],
    buffer: &mut Vec<TestedPair>,
) {
    let moved_pair = |t: &TestedPair| moved[t.a as usize] || moved[t.b as usize];
    if plan.iter().all(|p| p.tested != u32::MAX) && tested.iter().filter(|t| moved_pair(t)).count() == plan.len() {
        for (p, o) in plan.iter().zip(outcomes) {
            if o.tested {
                tested[p.tested as usize] = o.entry;
            }
        }
        return;
    }
    buffer.clear();
    let mut t = 0;
    for (p, o) in plan.iter().zip(outcomes) {
        while t < tested.len() && (tested[t].a, tested[t].b) < (p.a, p.b) {
            if !moved_pair(&tested[t]) {
                buffer.push(tested[t]);
            }
            t += 1;
        }
        buffer.push(match p.old_tested() {
            Some(k) if !o.tested => tested[k],
            _ => o.entry,
        });
    }
    buffer.extend(tested[t..].iter().filter(|t| !moved_pair(t)));
    std::mem::swap(tested, buffer);
}

/// The pose of the smaller of two blocks (by radius; `b` on a tie) in the body frame of the
/// other, and the smaller radius: what the contact geometry of the pair depends on.
#[inline]
pub(crate) fn relative_pose(a: &RigidBlock, b: &RigidBlock) -> (Pose, Real) {
    let (frame, moving) = if b.radius > a.radius { (b, a) } else { (a, b) };
    let (f, m) = (&frame.state.pose, &moving.state.pose);
    let to_frame = f.rotation.inverse();
    (
        Pose::from_parts(to_frame * (m.translation - f.translation), to_frame * m.rotation),
        moving.radius,
    )
}

/// The largest displacement of a point of a block of `radius` between relative poses `then` and
/// `now`: the translation plus the chord `2 r sin(θ/2)` of the rotation angle `θ` between them.
#[inline]
fn relative_motion(now: &Pose, then: &Pose, radius: Real) -> Real {
    let translation = (now.translation - then.translation).length();
    let half_sine = (now.rotation * then.rotation.inverse()).xyz().length().min(1.0);
    translation + 2.0 * radius * half_sine
}

impl<L: ConstitutiveLaw> ModelState<L> {
    /// The step's first pass over the blocks: their rotation matrices, which the contact pass
    /// reads instead of turning every contact's normals by quaternions, and (`check`) which
    /// blocks moved more than the re-detection trigger since their reference poses (the flags in
    /// [`DetectionScratch::moved`]; whether any did is returned). (After a step of a blockwise
    /// integrator the block pass has done this already, see [`DetectionScratch::prepared`].)
    pub(super) fn prepare_blocks(&mut self, pipeline: &mut Pipeline<L::State>, check: bool) -> bool {
        let trigger = self.params.contact.redetect_fraction * self.params.contact.tolerance;
        let n = self.blocks.len();
        pipeline.rotations.resize(n, Matrix::IDENTITY);
        pipeline.detection.moved.resize(n, false);
        pipeline
            .rotations
            .par_chunks_mut(BLOCK_CHUNK)
            .zip(pipeline.detection.moved.par_chunks_mut(BLOCK_CHUNK))
            .zip(self.blocks.par_chunks(BLOCK_CHUNK))
            .zip(self.ref_poses.par_chunks(BLOCK_CHUNK))
            .map(|(((rotations, moved), blocks), refs)| {
                prepare_chunk(rotations, moved, blocks, refs, check.then_some(trigger))
            })
            .reduce(|| false, |a, b| a || b)
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
    pub(super) fn detect(&mut self, pipeline: &mut Pipeline<L::State>) -> Result<()> {
        let params = self.params.contact;
        let full = self.changes.need_full_detection() || self.params.mode == DisplacementMode::Small;
        let trigger = params.redetect_fraction * params.tolerance;
        let n = self.blocks.len();
        let sc = &mut pipeline.detection;
        if full || sc.moved.len() != n {
            sc.moved.clear();
            sc.moved.resize(n, true);
        }
        // The moved blocks take their current poses as reference poses, and their boxes.
        let reach = 0.5 * params.tolerance + trigger;
        let fresh_boxes = sc.boxes.len() != n;
        if fresh_boxes {
            sc.boxes.clear();
            sc.boxes.extend(
                self.blocks
                    .iter()
                    .zip(&self.ref_poses)
                    .map(|(b, r)| reference_box(b, r, reach)),
            );
        }
        for (i, b) in self.blocks.iter().enumerate() {
            if sc.moved[i] {
                self.ref_poses[i] = b.state.pose;
                sc.boxes[i] = reference_box(b, &b.state.pose, reach);
            }
        }
        sc.broad.pairs_of_boxes(&sc.boxes, params.tolerance, &mut sc.candidates);
        plan(
            &sc.candidates,
            &self.blocks,
            &sc.moved,
            &self.tested,
            &self.pairs,
            &mut sc.plan,
        );
        sc.outcomes.clear();
        sc.outcomes.resize(sc.plan.len(), Outcome::default());
        let chunks = sc.plan.len().min(BATCH).div_ceil(PLAN_CHUNK);
        if sc.chunks.len() < chunks {
            sc.chunks.resize_with(chunks, ChunkScratch::default);
        }
        let test = PairTest {
            blocks: &self.blocks,
            tested: &self.tested,
            params: &params,
            keep_within: (!full).then_some(KEEP_FRACTION * trigger),
            pairs: &self.pairs,
        };
        // In batches, so that the seeds of a full detection are not all held at once: the tests
        // of a batch in parallel, then its contacts staged in order.
        ContactLists::of(sc).clear();
        for start in (0..sc.plan.len()).step_by(BATCH) {
            let batch = start..(start + BATCH).min(sc.plan.len());
            sc.outcomes[batch.clone()]
                .par_chunks_mut(PLAN_CHUNK)
                .zip(sc.plan[batch.clone()].par_chunks(PLAN_CHUNK))
                .zip(sc.chunks.par_iter_mut())
                .for_each(|((outcomes, plan), scratch)| test.run(plan, outcomes, scratch));
            self.stage(sc, batch)?;
        }
        let (work, dashpot) = self.splice_contacts(sc)?;
        self.energy.joint_work += work;
        self.energy.damping += dashpot;
        update_tested(&mut self.tested, &sc.plan, &sc.outcomes, &sc.moved, &mut sc.tested);
        sc.tests += sc.outcomes.iter().filter(|o| o.tested).count() as u64;
        self.detections += 1;
        if sc.reindex {
            self.rebuild_block_index(pipeline);
        }
        // The critical step is re-evaluated when a contact appeared or one grew by more than 5 %
        // since the last evaluation (lost contacts only make the step safer): the bounds of
        // those contacts' blocks. A forced full detection follows a change of laws, parameters
        // or fixity: every block's bound is re-evaluated then. The flag is set (or stays set) if
        // that fails, so the error repeats rather than the run going on with an unstable step.
        if full || self.critical.is_none() {
            self.changes.insert(Changes::DETECTION);
            self.refresh_time_step(pipeline)?;
        } else if self.contacts_grew() {
            self.changes.insert(Changes::DETECTION);
            self.refresh_time_step_of_grown(pipeline)?;
        }
        self.changes.clear();
        Ok(())
    }

    /// Stages the contacts the narrow phase found in the planned pairs `batch` (in order), with
    /// the history of the old ones, and notes where in their outcomes.
    fn stage(&self, sc: &mut DetectionScratch<L::State>, batch: std::ops::Range<usize>) -> Result<()> {
        let old = OldContacts {
            pairs: &self.pairs,
            references: &self.references,
            subs: &self.subs,
            records: &self.sub_records,
        };
        let first = batch.start;
        for k in batch {
            let (p, o) = (&sc.plan[k], &mut sc.outcomes[k]);
            let Some(dc) = o.contact.take() else { continue };
            if o.seed_count == 0 {
                continue;
            }
            let seeds = sc.chunks[(k - first) / PLAN_CHUNK].seeds(o);
            let (bi, bj) = (&self.blocks[p.a as usize], &self.blocks[p.b as usize]);
            let law = self.law_index(p.a, p.b)?;
            o.staged = sc.pairs.len() as u32;
            let mut staged = ContactLists {
                pairs: &mut sc.pairs,
                references: &mut sc.references,
                wrenches: &mut sc.wrenches,
                subs: &mut sc.subs,
                records: &mut sc.records,
            };
            staged.add_detected(&old, p.old_contact(), (p.a, bi), (p.b, bj), &dc, law, seeds);
        }
        Ok(())
    }

    /// Brings the contact lists up to date with the narrow phase's outcomes, in place: the
    /// contacts of two blocks that did not move and those whose pair kept its verdict keep their
    /// data, moved to their new positions (`docs/theory.md` §2.3, "Parallel, in place"); the
    /// re-tested ones are built in `sc`'s staging lists first, with the history of the old
    /// ones, then written to theirs. Nothing of the model changes before every law is found.
    /// Returns the work of the dropped sub-contacts ([`dropped_work`]) and sets `sc.reindex`
    /// when contacts changed places.
    fn splice_contacts(&mut self, sc: &mut DetectionScratch<L::State>) -> Result<(Real, Real)> {
        // The new order: kept old contacts and staged new ones, by pair.
        let old = OldContacts {
            pairs: &self.pairs,
            references: &self.references,
            subs: &self.subs,
            records: &self.sub_records,
        };
        sc.kept.clear();
        sc.kept.resize(old.pairs.len(), false);
        sc.layout.clear();
        let moved = &sc.moved;
        let unmoved = |c: usize| !moved[old.pairs[c].a as usize] && !moved[old.pairs[c].b as usize];
        let mut c = 0;
        for (p, o) in sc.plan.iter().zip(&sc.outcomes) {
            while c < old.pairs.len() && (old.pairs[c].a, old.pairs[c].b) < (p.a, p.b) {
                if unmoved(c) {
                    sc.layout.push(Slot::Kept(c as u32));
                    sc.kept[c] = true;
                }
                c += 1;
            }
            if !o.tested {
                if let Some(c) = p.old_contact() {
                    sc.layout.push(Slot::Kept(c as u32));
                    sc.kept[c] = true;
                }
            } else if o.staged != u32::MAX {
                sc.layout.push(Slot::Staged(o.staged));
            }
        }
        for c in c..old.pairs.len() {
            if unmoved(c) {
                sc.layout.push(Slot::Kept(c as u32));
                sc.kept[c] = true;
            }
        }
        let owed = dropped_work(
            &old,
            (&sc.pairs, &sc.records),
            &sc.kept,
            &self.blocks,
            self.params.mode,
            if self.drift > 0.0 { self.drift } else { self.dt },
        );
        // Where each contact goes: its index in `layout`, its sub-contacts from `first`.
        sc.firsts.clear();
        let mut total = 0u32;
        for slot in &sc.layout {
            sc.firsts.push(total);
            total += match *slot {
                Slot::Kept(c) => self.pairs[c as usize].count,
                Slot::Staged(s) => sc.pairs[s as usize].count,
            };
        }
        sc.reindex = sc.layout.len() != self.pairs.len()
            || sc.layout.iter().enumerate().any(|(k, slot)| match *slot {
                Slot::Kept(c) => c as usize != k,
                Slot::Staged(s) => {
                    let q = &sc.pairs[s as usize];
                    self.pairs.get(k).is_none_or(|p| (p.a, p.b) != (q.a, q.b))
                }
            });
        let (contacts, subs) = (sc.layout.len(), total as usize);
        if sc.layout.iter().all(|slot| matches!(slot, Slot::Staged(_))) {
            // Every contact detected afresh (the first detection, a full one): the staging lists
            // are the new lists, and the old ones are released rather than kept as staging.
            std::mem::swap(&mut self.pairs, &mut sc.pairs);
            std::mem::swap(&mut self.references, &mut sc.references);
            std::mem::swap(&mut self.wrenches, &mut sc.wrenches);
            std::mem::swap(&mut self.subs, &mut sc.subs);
            std::mem::swap(&mut self.sub_records, &mut sc.records);
            sc.release_staging();
            return Ok(owed);
        }
        if contacts > self.pairs.len() {
            // Room for the new contacts (the fillers are overwritten below).
            let filler = (sc.pairs[0].clone(), sc.references[0].clone());
            self.pairs.resize(contacts, filler.0);
            self.references.resize(contacts, filler.1);
            self.wrenches.resize(contacts, ContactWrench::default());
        }
        if subs > self.subs.len() {
            self.subs.resize(subs, sc.subs[0].clone());
            self.sub_records.resize(subs, sc.records[0].clone());
        }
        // Kept contacts move towards the front left to right, then towards the back right to
        // left: neither overwrites data still to be moved (`docs/performance.md`).
        let mut lists = ContactLists {
            pairs: &mut self.pairs,
            references: &mut self.references,
            wrenches: &mut self.wrenches,
            subs: &mut self.subs,
            records: &mut self.sub_records,
        };
        // Runs of kept contacts that were neighbours and stay neighbours move as one.
        sc.runs.clear();
        for (k, slot) in sc.layout.iter().enumerate() {
            let Slot::Kept(c) = *slot else { continue };
            match sc.runs.last_mut() {
                Some(run) if run.old + run.len == c && run.new + run.len == k as u32 => run.len += 1,
                _ => sc.runs.push(Run {
                    old: c,
                    new: k as u32,
                    len: 1,
                }),
            }
        }
        for run in &sc.runs {
            lists.move_run(run, sc.firsts[run.new as usize], Direction::Front);
        }
        for run in sc.runs.iter().rev() {
            lists.move_run(run, sc.firsts[run.new as usize], Direction::Back);
        }
        for (k, slot) in sc.layout.iter().enumerate() {
            if let Slot::Staged(s) = *slot {
                let q = &sc.pairs[s as usize];
                let (from, to) = (q.range(), sc.firsts[k] as usize..(sc.firsts[k] + q.count) as usize);
                lists.subs[to.clone()].clone_from_slice(&sc.subs[from.clone()]);
                lists.records[to].clone_from_slice(&sc.records[from]);
                lists.pairs[k] = q.clone();
                lists.pairs[k].first = sc.firsts[k];
                lists.references[k] = sc.references[s as usize].clone();
                lists.wrenches[k] = sc.wrenches[s as usize];
            }
        }
        self.pairs.truncate(contacts);
        self.references.truncate(contacts);
        self.wrenches.truncate(contacts);
        self.subs.truncate(subs);
        self.sub_records.truncate(subs);
        if STAGING_FRACTION * sc.subs.capacity() > self.subs.len().max(1) {
            sc.release_staging();
        }
        Ok(owed)
    }

    /// The index of the joint law between blocks `i` and `j`.
    fn law_index(&self, i: u32, j: u32) -> Result<u32> {
        let (bi, bj) = (&self.blocks[i as usize], &self.blocks[j as usize]);
        self.laws
            .index_of(bi.material(), bj.material())
            .ok_or(Error::MissingJointLaw {
                a: bi.material(),
                b: bj.material(),
                block_a: BlockId(i),
                block_b: BlockId(j),
            })
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

/// The rotation matrices of a chunk of blocks and, given the re-detection `trigger`, which of
/// them moved beyond it since their reference poses in `refs` (`moved`, all `false` without a
/// trigger); returns whether any did.
#[inline]
pub(super) fn prepare_chunk(
    rotations: &mut [Matrix],
    moved: &mut [bool],
    blocks: &[RigidBlock],
    refs: &[Pose],
    trigger: Option<Real>,
) -> bool {
    let mut any = false;
    for (((rotation, moved), b), r) in rotations.iter_mut().zip(moved).zip(blocks).zip(refs) {
        *rotation = Matrix::from_quat(b.state.pose.rotation);
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

/// The contact lists before a re-detection, for [`dropped_work`].
struct OldContacts<'a, S> {
    pairs: &'a [ContactPair],
    references: &'a [ContactReference],
    subs: &'a [SubContact<S>],
    records: &'a [SubContactRecord],
}

/// Contact lists as detection writes them: the staging lists, or the model's as they are
/// rearranged.
struct ContactLists<'a, S> {
    pairs: &'a mut Vec<ContactPair>,
    references: &'a mut Vec<ContactReference>,
    wrenches: &'a mut Vec<ContactWrench>,
    subs: &'a mut Vec<SubContact<S>>,
    records: &'a mut Vec<SubContactRecord>,
}

impl<'a, S> ContactLists<'a, S> {
    /// The staging lists of `sc`.
    fn of(sc: &'a mut DetectionScratch<S>) -> Self {
        Self {
            pairs: &mut sc.pairs,
            references: &mut sc.references,
            wrenches: &mut sc.wrenches,
            subs: &mut sc.subs,
            records: &mut sc.records,
        }
    }
}

impl<S: Clone + Default> ContactLists<'_, S> {
    fn clear(&mut self) {
        self.pairs.clear();
        self.references.clear();
        self.wrenches.clear();
        self.subs.clear();
        self.records.clear();
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
    old: &OldContacts<'_, S>,
    new: (&[ContactPair], &[SubContactRecord]),
    kept: &[bool],
    blocks: &[RigidBlock],
    mode: DisplacementMode,
    dt: Real,
) -> (Real, Real) {
    let mut owed = (0.0, 0.0);
    for (k, p) in old.pairs.iter().enumerate() {
        // A contact whose pair kept its verdict is kept as it was, with all its sub-contacts.
        if kept[k] {
            continue;
        }
        let successor = new
            .0
            .binary_search_by_key(&(p.a, p.b), |q| (q.a, q.b))
            .ok()
            .map(|s| (&new.0[s], new.1));
        add_dropped_work(old, k, successor, blocks, mode, dt, &mut owed);
    }
    owed
}

/// Adds to `owed` the work ([`dropped_work`]) of the sub-contacts of old contact `k` that its
/// `successor` (the new contact of the same pair, with the new sub-contact records it indexes)
/// does not carry on.
fn add_dropped_work<S>(
    old: &OldContacts<'_, S>,
    k: usize,
    successor: Option<(&ContactPair, &[SubContactRecord])>,
    blocks: &[RigidBlock],
    mode: DisplacementMode,
    dt: Real,
    owed: &mut (Real, Real),
) {
    let (p, reference) = (&old.pairs[k], &old.references[k]);
    let carried = successor
        .filter(|(q, _)| q.kind.same_joint(&p.kind) && q.host_is_a == p.host_is_a)
        .map(|(q, records)| &records[q.range()]);
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
        owed.0 -= 0.5 * spring.dot(du);
        owed.1 -= 0.5 * r.dashpot.dot(du);
    }
}
