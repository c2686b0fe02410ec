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
    detect, BlockGeometry, BroadPhase, ContactParameters, DetectedContact, NarrowPhaseScratch, SubKey, SubcontactSeed,
};
use crate::law::{ConstitutiveLaw, JointAxes, JointForce, JointStatus};
use crate::math::{Matrix, Pose, Real, Vector, Vector2};

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
        let (mut contacts, mut cursor) = (self.staging.pairs.len() as u32, self.staging.subs.len() as u32);
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

/// A contact after detection: an old one kept (its index), or one detected afresh (its index
/// in the staging lists, and the old contact of the same pair it replaces or `u32::MAX`).
#[derive(Debug, Clone, Copy)]
enum Slot {
    Kept(u32),
    Staged { staged: u32, replaces: u32 },
}

impl Slot {
    /// Where the contact's sub-contacts were before the detection: those of the old contact
    /// it keeps or replaces.
    fn home(self, old: &[ContactPair]) -> Option<u32> {
        match self {
            Slot::Kept(c) => Some(old[c as usize].first),
            Slot::Staged { replaces, .. } => old.get(replaces as usize).map(|p| p.first),
        }
    }

    fn count(self, old: &[ContactPair], staged: &[ContactPair]) -> u32 {
        match self {
            Slot::Kept(c) => old[c as usize].count,
            Slot::Staged { staged: s, .. } => staged[s as usize].count,
        }
    }
}

/// The room a re-tested contact is given beyond its sub-contacts when it outgrows the room it
/// had (or a new one has none), so that it can grow again without moving its neighbours
/// (`docs/theory.md` §2.3, "Parallel, in place").
fn headroom(count: u32) -> u32 {
    count / 8 + 2
}

/// The room the sub-contact lists may take with `live` sub-contacts.
fn room_limit(live: usize) -> usize {
    live + live / COMPACT_FRACTION as usize
}

/// The sub-contact list is compacted when the room between contacts exceeds this share of the
/// sub-contacts (`1/COMPACT_FRACTION`).
const COMPACT_FRACTION: u32 = 4;

/// Contacts per segment of a fresh layout, after each of which [`segment_slack`] is left
/// empty: a contact that outgrows its room pushes at most the rest of its segment.
const SEGMENT: usize = 64;

/// The dead room left after a segment of `subs` sub-contacts in a fresh layout: a sixteenth.
fn segment_slack(subs: u32) -> u32 {
    subs / 16 + 4
}

/// Where each contact of `layout` puts its sub-contacts (`firsts`, increasing with the contact):
/// at its home ([`Slot::home`]) unless the contacts before it reach past it, a new contact right
/// after the one before; a re-tested contact that reaches past the next contact's home gets
/// [`headroom`]. A fresh layout (every contact right after the one before, with
/// [`segment_slack`] after every [`SEGMENT`] contacts) when that would leave more than
/// `1/COMPACT_FRACTION` of the room empty, or when `fresh`. Returns the end of the room used,
/// the room the lists may take before they are laid out afresh again, and whether they were.
fn place_subcontacts(
    layout: &[Slot],
    old: &[ContactPair],
    staged: &[ContactPair],
    old_end: u32,
    fresh: bool,
    firsts: &mut Vec<u32>,
) -> (u32, usize, bool) {
    let live: u32 = layout.iter().map(|s| s.count(old, staged)).sum();
    firsts.clear();
    firsts.resize(layout.len(), 0);
    for packed in [false, true] {
        if fresh && !packed {
            continue;
        }
        // The next contact's home, from the back: how far a contact may reach in place.
        let mut next = old_end;
        for (k, slot) in layout.iter().enumerate().rev() {
            firsts[k] = next;
            if let Some(home) = slot.home(old) {
                next = home;
            }
        }
        let (mut cursor, mut segment) = (0, 0);
        for (k, slot) in layout.iter().enumerate() {
            let limit = firsts[k];
            let first = match slot.home(old) {
                Some(home) if !packed => home.max(cursor),
                _ => cursor,
            };
            let count = slot.count(old, staged);
            cursor = first + count;
            if packed {
                segment += count;
                if (k + 1) % SEGMENT == 0 {
                    cursor += segment_slack(segment);
                    segment = 0;
                }
            } else if matches!(slot, Slot::Staged { .. }) && cursor > limit {
                cursor += headroom(count);
            }
            firsts[k] = first;
        }
        if packed || cursor - live <= live / COMPACT_FRACTION {
            return (cursor, room_limit(live as usize), packed);
        }
    }
    unreachable!("the packed layout is returned")
}

/// Moves `list[range]` by `shift` places into dead room (elements never read: what lies
/// between `range` and its destination, or beyond it, is dead), by swapping each element with
/// the dead one at its destination: O(`range.len()`), whatever the shift, where a rotation of
/// the range with the room it moves into costs O(`range.len() + |shift|`) (the first detection
/// of a large model spreads its segments by shifts of up to a sixteenth of the list: quadratic
/// by rotation). The live elements land where a rotation puts them; only the dead ones may end
/// up in another order.
fn move_into_dead_room<T>(list: &mut [T], range: std::ops::Range<usize>, shift: i64) {
    let by = shift.unsigned_abs() as usize;
    if shift > 0 {
        for i in range.rev() {
            list.swap(i, i + by);
        }
    } else if shift < 0 {
        for i in range {
            list.swap(i, i - by);
        }
    }
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
    /// Moves a run of old contacts to their new indices, if they move in `direction`, into the
    /// dead room they move into ([`move_into_dead_room`]; their sub-contacts stay).
    fn move_contacts(&mut self, run: &Run, direction: Direction) {
        let (c, k, len) = (run.old as usize, run.new as usize, run.len as usize);
        let shift = k as i64 - c as i64;
        if (direction == Direction::Front && shift < 0) || (direction == Direction::Back && shift > 0) {
            move_into_dead_room(self.pairs, c..c + len, shift);
            move_into_dead_room(self.references, c..c + len, shift);
            move_into_dead_room(self.wrenches, c..c + len, shift);
        }
    }

    /// Moves the sub-contacts `range` by `shift`, if they move in `direction`, into the dead
    /// room they move into ([`move_into_dead_room`]).
    fn move_subcontacts(&mut self, range: std::ops::Range<usize>, shift: i64, direction: Direction) {
        if (direction == Direction::Front && shift < 0) || (direction == Direction::Back && shift > 0) {
            move_into_dead_room(self.subs, range.clone(), shift);
            move_into_dead_room(self.records, range, shift);
        }
    }
}

/// Sub-contacts `start..end` of consecutive kept contacts (and the dead room between them) that
/// move by `shift`.
#[derive(Debug, Clone, Copy)]
struct SubRun {
    start: u32,
    end: u32,
    shift: i64,
}

/// How many detections spliced the contacts in place (and how many of those pushed contacts
/// back), through the full splice, and of those how many laid the lists out afresh.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct SpliceCounts {
    pub in_place: u64,
    pub pushed: u64,
    pub full: u64,
    pub fresh: u64,
}

/// Which splices a detection may use: any, the full one only, or the full one with a fresh
/// layout every time. The results are the same bits (`tests`).
#[cfg(test)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum SpliceMode {
    Any,
    Full,
    Fresh,
}

/// A re-tested contact that replaces old contact `contact` (same index) with staged contact
/// `staged`, its sub-contacts from `first`.
#[derive(Debug, Clone, Copy)]
struct Replaced {
    contact: u32,
    staged: u32,
    first: u32,
}

/// Neighbouring kept contacts whose sub-contacts the in-place splice pushes back by `shift`.
#[derive(Debug, Clone)]
struct Pushed {
    contacts: std::ops::Range<u32>,
    shift: u32,
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
    /// Its index in the staging lists, once placed (else `u32::MAX`), and that of its first
    /// sub-contact.
    staged: u32,
    first_sub: u32,
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
            first_sub: 0,
        }
    }
}

/// One task's buffers of the parallel narrow phase: the seeds of its contacts, and where it
/// stages them.
#[derive(Debug, Clone, Default)]
struct ChunkScratch {
    narrow: NarrowPhaseScratch,
    seeds: Vec<SubcontactSeed>,
    /// The index of its first staged contact and of that contact's first sub-contact in the
    /// staging lists (those of the next one when it stages none).
    place: (u32, u32),
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
                first_sub: 0,
                contact: found,
            };
        }
    }
}

/// The candidate pairs with a block that moved, not between two fixed blocks, each with its
/// entries in the sorted `tested` and contact lists of the last detection, given by their keys
/// (a merge of sorted lists that gallops over the entries between two candidates: the
/// candidates of a local re-detection are few).
fn plan(
    candidates: &[(u32, u32)],
    fixed: &[bool],
    moved: &[bool],
    tested: &[(u32, u32)],
    contacts: &[(u32, u32)],
    out: &mut Vec<Planned>,
) {
    out.clear();
    let (mut t, mut c) = (0, 0);
    for &(a, b) in candidates {
        let (a_, b_) = (a as usize, b as usize);
        if !moved[a_] && !moved[b_] || fixed[a_] && fixed[b_] {
            continue;
        }
        t = gallop(tested, t, |&key| key < (a, b));
        c = gallop(contacts, c, |&key| key < (a, b));
        let found_t = tested.get(t) == Some(&(a, b));
        let found_c = contacts.get(c) == Some(&(a, b));
        out.push(Planned {
            a,
            b,
            tested: if found_t { t as u32 } else { u32::MAX },
            contact: if found_c { c as u32 } else { u32::MAX },
        });
    }
}

/// The first index from `start` on at which `before` is false (`before` true on a prefix of
/// `list[start..]`): doubling steps, then a binary search, O(log distance).
fn gallop<T>(list: &[T], start: usize, before: impl Fn(&T) -> bool) -> usize {
    let mut step = 1;
    let mut low = start;
    while low + step <= list.len() && before(&list[low + step - 1]) {
        low += step;
        step *= 2;
    }
    let high = (low + step).min(list.len());
    low + list[low..high].partition_point(before)
}

/// Brings `tested` up to date with the detection's outcomes: in place when every planned pair
/// was tested before and the contacts were spliced in place, else merged afresh through
/// `buffer` (the pairs of two blocks that did not move keep their entries; those with a moved
/// block that are no longer candidates lose them). Returns whether it was in place.
fn update_tested(
    tested: &mut Vec<TestedPair>,
    plan: &[Planned],
    outcomes: &[Outcome],
    moved: &[bool],
    in_place: bool,
    buffer: &mut Vec<TestedPair>,
) -> bool {
    let moved_pair = |t: &TestedPair| moved[t.a as usize] || moved[t.b as usize];
    // After an in-place splice no contact was lost, so the entries of pairs with a moved block
    // that are no longer candidates are those of pairs found apart: their verdicts still hold
    // (they depend on the relative pose alone), and they may stay until the next merge.
    if in_place && plan.iter().all(|p| p.tested != u32::MAX) {
        for (p, o) in plan.iter().zip(outcomes) {
            if o.tested {
                tested[p.tested as usize] = o.entry;
            }
        }
        return true;
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
    false
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
        self.ref_poses
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
            for m in &self.motions {
                sc.fixed[m.block as usize] = self.blocks[m.block as usize].fixity().is_fixed();
            }
        }
        if sc.contact_keys.len() != self.pairs.len() {
            sc.contact_keys.clear();
            sc.contact_keys.extend(self.pairs.iter().map(|p| (p.a, p.b)));
        }
        if sc.tested_keys.len() != self.tested.len() {
            sc.tested_keys.clear();
            sc.tested_keys.extend(self.tested.iter().map(|t| (t.a, t.b)));
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
        let test = PairTest {
            blocks: &self.blocks,
            tested: &self.tested,
            params: &params,
            keep_within: (!full).then_some(KEEP_FRACTION * trigger),
            pairs: &self.pairs,
        };
        // In batches, so that the seeds of a full detection are not all held at once: the tests
        // of a batch in parallel; the places of its contacts in the staging lists, in plan
        // order; then each task writes its contacts into its part of the lists, in parallel.
        // A full detection stages its contacts in a fresh layout (`place_subcontacts`): dead
        // room after every `SEGMENT` contacts.
        sc.staging.lists().clear();
        sc.staging_spread = full;
        sc.segment_subs = 0;
        for start in (0..sc.plan.len()).step_by(BATCH) {
            let batch = start..(start + BATCH).min(sc.plan.len());
            sc.outcomes[batch.clone()]
                .par_chunks_mut(chunk)
                .zip(sc.plan[batch.clone()].par_chunks(chunk))
                .zip(sc.chunks.par_iter_mut())
                .for_each(|((outcomes, plan), scratch)| test.run(plan, outcomes, scratch));
            let tasks = batch.len().div_ceil(chunk);
            sc.place_staged(batch.clone(), chunk);
            let slices = sc.staging.grow();
            self.stage(
                &mut sc.chunks[..tasks],
                &sc.plan[batch.clone()],
                &mut sc.outcomes[batch],
                chunk,
                slices,
            )?;
        }
        if sc.staging_spread && sc.staging.pairs.len().is_multiple_of(SEGMENT) {
            // No dead room after the last segment.
            let end = sc.staging.pairs.last().map_or(0, |p| (p.first + p.count) as usize);
            sc.staging.subs.truncate(end);
            sc.staging.records.truncate(end);
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
            sc.contact_keys.extend(self.pairs.iter().map(|p| (p.a, p.b)));
        }
        // A full detection follows a change of parameters (the tolerance that the slack of a
        // pair found apart was measured against): its entries are merged afresh.
        let merged = !update_tested(
            &mut self.tested,
            &sc.plan,
            &sc.outcomes,
            &sc.moved,
            in_place && !full,
            &mut sc.tested,
        );
        if merged {
            sc.tested_keys.clear();
            sc.tested_keys.extend(self.tested.iter().map(|t| (t.a, t.b)));
        }
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
        } else {
            let mut blocks = std::mem::take(&mut pipeline.refresh_blocks);
            blocks.clear();
            if in_place {
                let replaced = &pipeline.detection.replaced;
                self.take_grown(replaced.iter().map(|r| r.contact as usize), &mut blocks);
            } else {
                self.take_grown(0..self.pairs.len(), &mut blocks);
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

    /// Stages the contacts the narrow phase found in the planned pairs of `chunks` (`chunk`
    /// pairs each, the last one possibly fewer) at the places [`DetectionScratch::place_staged`]
    /// gave them, with the history of the old ones: the tasks in parallel, each into its part of
    /// the staging lists. The error is the first in plan order (a missing joint law).
    fn stage(
        &self,
        chunks: &mut [ChunkScratch],
        plan: &[Planned],
        outcomes: &mut [Outcome],
        chunk: usize,
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
                || self.stage(chunks_a, plan_a, outcomes_a, chunk, slices_a),
                || self.stage(chunks_b, plan_b, outcomes_b, chunk, slices_b),
            );
            return a.and(b);
        }
        let Some(scratch) = chunks.first() else { return Ok(()) };
        let old = OldContacts {
            pairs: &self.pairs,
            references: &self.references,
            subs: &self.subs,
            records: &self.sub_records,
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
            slices.write_detected(
                (o.staged, o.first_sub),
                &old,
                p.old_contact(),
                (p.a, bi),
                (p.b, bj),
                &dc,
                law,
                seeds,
            );
        }
        Ok(())
    }

    /// The usual splice, whose cost follows the re-tested contacts alone: when no contact
    /// appeared or was lost, the re-tested contacts are written over the old ones, each in the
    /// room of the one it replaces (its sub-contacts and the dead room after them). One that
    /// outgrows its room takes [`headroom`] besides and pushes the contacts after it towards the
    /// back, as far as the dead room between them absorbs the push (`docs/theory.md` §2.3).
    /// Returns the work of the dropped sub-contacts, as [`ModelState::splice_contacts`] would,
    /// or `None`, with nothing changed, when it does not apply: a contact appeared or was lost,
    /// or the room would pass the limit the last compaction set.
    fn splice_in_place(&mut self, sc: &mut DetectionScratch<L::State>, index: BlockIndex<'_>) -> Option<(Real, Real)> {
        let n = self.blocks.len();
        if index.offsets.len() != n + 1 || index.offsets[n] as usize != 2 * self.pairs.len() {
            return None;
        }
        sc.replaced.clear();
        let mut planned_contacts = 0;
        for (p, o) in sc.plan.iter().zip(&sc.outcomes) {
            match (p.old_contact(), o.staged != u32::MAX) {
                (None, false) => {}
                (None, true) => return None, // a new contact
                (Some(_), _) if !o.tested => planned_contacts += 1,
                (Some(_), false) => return None, // a contact lost
                (Some(k), true) => {
                    planned_contacts += 1;
                    sc.replaced.push(Replaced {
                        contact: k as u32,
                        staged: o.staged,
                        first: self.pairs[k].first,
                    });
                }
            }
        }
        // Every old contact with a moved block was planned: none lost its candidate pair.
        let moved = &sc.moved;
        let mut moved_contacts = 0;
        for i in (0..n).filter(|&i| moved[i]) {
            for &e in &index.contacts[index.offsets[i] as usize..index.offsets[i + 1] as usize] {
                // Counted once: at `a`, or at `b` when `a` did not move.
                if e % 2 == 0 || !moved[self.pairs[(e / 2) as usize].a as usize] {
                    moved_contacts += 1;
                }
            }
        }
        if moved_contacts != planned_contacts {
            return None;
        }
        // Where the re-tested contacts go, and the kept ones they push.
        sc.pushed.clear();
        let contacts = self.pairs.len();
        let room = self.subs.len() as u32;
        let mut needed = room;
        let mut window_end = 0;
        let count = |staged: u32| sc.staging.pairs[staged as usize].count;
        for r in 0..sc.replaced.len() {
            let Replaced { contact: k, staged, .. } = sc.replaced[r];
            let k = k as usize;
            if k < window_end {
                continue; // placed by the push of a contact before it
            }
            let end = self.pairs.get(k + 1).map_or(room, |q| q.first);
            let (first, m) = (self.pairs[k].first, count(staged));
            if first + m <= end {
                continue;
            }
            // It outgrew its room: the contacts after it go right after the one before them
            // until one's home is far enough back.
            let mut cursor = first + m + headroom(m);
            let (mut j, mut next) = (k + 1, r + 1);
            while j < contacts && cursor > self.pairs[j].first {
                match sc.replaced.get(next).copied() {
                    Some(q) if q.contact as usize == j => {
                        sc.replaced[next].first = cursor;
                        cursor += count(q.staged);
                        next += 1;
                    }
                    _ => {
                        // Neighbours pushed by as much move as one run.
                        let (p, shift) = (&self.pairs[j], cursor - self.pairs[j].first);
                        match sc.pushed.last_mut() {
                            Some(run) if run.contacts.end as usize == j && run.shift == shift => run.contacts.end += 1,
                            _ => sc.pushed.push(Pushed {
                                contacts: j as u32..j as u32 + 1,
                                shift,
                            }),
                        }
                        cursor += p.count;
                    }
                }
                j += 1;
            }
            needed = needed.max(cursor);
            window_end = j;
        }
        if needed as usize > sc.room_limit {
            return None;
        }
        // The work of the dropped sub-contacts, in contact order as `dropped_work` sums it,
        // before anything moves.
        let old = OldContacts {
            pairs: &self.pairs,
            references: &self.references,
            subs: &self.subs,
            records: &self.sub_records,
        };
        let dt = if self.drift > 0.0 { self.drift } else { self.dt };
        let mut owed = (0.0, 0.0);
        for r in &sc.replaced {
            let successor = (&sc.staging.pairs[r.staged as usize], sc.staging.records.as_slice());
            add_dropped_work(
                &old,
                r.contact as usize,
                Some(successor),
                &self.blocks,
                self.params.mode,
                dt,
                &mut owed,
            );
        }
        if needed > room {
            // Dead room (sub-contacts not in any contact's range are never read).
            let (sub, record) = dead_subcontact();
            self.subs.resize(needed as usize, sub);
            self.sub_records.resize(needed as usize, record);
        }
        // Pushed contacts move from the last: each moves into room that is dead by then (the
        // old room of the ones after it, which moved further back, or of re-tested ones).
        for run in sc.pushed.iter().rev() {
            let contacts = &mut self.pairs[run.contacts.start as usize..run.contacts.end as usize];
            let last = &contacts[contacts.len() - 1];
            let (start, end) = (
                contacts[0].first as usize,
                (last.first + last.count + run.shift) as usize,
            );
            let moved = start..end - run.shift as usize;
            move_into_dead_room(&mut self.subs, moved.clone(), i64::from(run.shift));
            move_into_dead_room(&mut self.sub_records, moved, i64::from(run.shift));
            for p in contacts {
                p.first += run.shift;
            }
        }
        for r in &sc.replaced {
            let (k, s) = (r.contact as usize, r.staged as usize);
            let q = &sc.staging.pairs[s];
            let to = r.first as usize..(r.first + q.count) as usize;
            self.subs[to.clone()].clone_from_slice(&sc.staging.subs[q.range()]);
            self.sub_records[to].clone_from_slice(&sc.staging.records[q.range()]);
            self.pairs[k] = q.clone();
            self.pairs[k].first = r.first;
            self.references[k] = sc.staging.references[s].clone();
            self.wrenches[k] = sc.staging.wrenches[s];
        }
        sc.reindex = false;
        sc.splices.in_place += 1;
        sc.splices.pushed += u64::from(!sc.pushed.is_empty() || needed > room);
        if STAGING_FRACTION * sc.staging.subs.capacity() > self.subs.len().max(1) {
            sc.release_staging();
        }
        Some(owed)
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
                sc.layout.push(Slot::Staged {
                    staged: o.staged,
                    replaces: p.contact,
                });
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
            (&sc.staging.pairs, &sc.staging.records),
            &sc.kept,
            &self.blocks,
            self.params.mode,
            if self.drift > 0.0 { self.drift } else { self.dt },
        );
        sc.reindex = sc.layout.len() != self.pairs.len()
            || sc.layout.iter().enumerate().any(|(k, slot)| match *slot {
                Slot::Kept(c) => c as usize != k,
                Slot::Staged { staged, .. } => {
                    let q = &sc.staging.pairs[staged as usize];
                    self.pairs.get(k).is_none_or(|p| (p.a, p.b) != (q.a, q.b))
                }
            });
        if sc.layout.iter().all(|slot| matches!(slot, Slot::Staged { .. })) {
            // Every contact detected afresh (the first detection, a full one): the staging lists
            // are the new lists, and the old ones are released rather than kept as staging.
            std::mem::swap(&mut self.pairs, &mut sc.staging.pairs);
            std::mem::swap(&mut self.references, &mut sc.staging.references);
            std::mem::swap(&mut self.wrenches, &mut sc.staging.wrenches);
            std::mem::swap(&mut self.subs, &mut sc.staging.subs);
            std::mem::swap(&mut self.sub_records, &mut sc.staging.records);
            sc.release_staging();
            sc.room_limit = room_limit(self.pairs.iter().map(|p| p.count as usize).sum());
            sc.splices.full += 1;
            sc.splices.fresh += 1;
            if !sc.staging_spread {
                self.spread_segments();
            }
            return Ok(owed);
        }
        // Where each contact goes: its index in `layout`, its sub-contacts from `firsts`, with
        // room between contacts (`place_subcontacts`).
        let (end, limit, fresh) = place_subcontacts(
            &sc.layout,
            &self.pairs,
            &sc.staging.pairs,
            self.subs.len() as u32,
            sc.room_limit == 0 || sc.fresh_forced(),
            &mut sc.firsts,
        );
        sc.room_limit = limit;
        sc.splices.full += 1;
        sc.splices.fresh += u64::from(fresh);
        let (contacts, room) = (sc.layout.len(), end as usize);
        if contacts > self.pairs.len() {
            // Room for the new contacts (the fillers are overwritten below).
            let filler = (sc.staging.pairs[0].clone(), sc.staging.references[0].clone());
            self.pairs.resize(contacts, filler.0);
            self.references.resize(contacts, filler.1);
            self.wrenches.resize(contacts, ContactWrench::default());
        }
        if room > self.subs.len() {
            // Dead room (sub-contacts not in any contact's range are never read).
            let (sub, record) = dead_subcontact();
            self.subs.resize(room, sub);
            self.sub_records.resize(room, record);
        }
        // The kept contacts' sub-contacts move first, in runs of equal shift (while the contacts
        // still hold their old ranges), then the contacts, in runs that were neighbours and stay
        // neighbours. Each moves towards the front left to right, then towards the back right
        // to left: neither overwrites data still to be moved (`docs/theory.md` §2.3).
        sc.sub_runs.clear();
        sc.runs.clear();
        let mut last_shift = 0;
        for (k, slot) in sc.layout.iter().enumerate() {
            let Slot::Kept(c) = *slot else { continue };
            let p = &self.pairs[c as usize];
            let (start, end) = (p.first, p.first + p.count);
            let shift = i64::from(sc.firsts[k]) - i64::from(start);
            // A run takes in the dead room between its contacts (that of re-tested ones).
            match sc.sub_runs.last_mut() {
                _ if shift == 0 => {}
                Some(run) if last_shift == shift => run.end = end,
                _ => sc.sub_runs.push(SubRun { start, end, shift }),
            }
            last_shift = shift;
            match sc.runs.last_mut() {
                Some(run) if run.old + run.len == c && run.new + run.len == k as u32 => run.len += 1,
                _ => sc.runs.push(Run {
                    old: c,
                    new: k as u32,
                    len: 1,
                }),
            }
        }
        let mut lists = ContactLists {
            pairs: &mut self.pairs,
            references: &mut self.references,
            wrenches: &mut self.wrenches,
            subs: &mut self.subs,
            records: &mut self.sub_records,
        };
        for run in &sc.sub_runs {
            lists.move_subcontacts(run.start as usize..run.end as usize, run.shift, Direction::Front);
        }
        for run in sc.sub_runs.iter().rev() {
            lists.move_subcontacts(run.start as usize..run.end as usize, run.shift, Direction::Back);
        }
        for run in &sc.runs {
            lists.move_contacts(run, Direction::Front);
        }
        for run in sc.runs.iter().rev() {
            lists.move_contacts(run, Direction::Back);
        }
        for (k, slot) in sc.layout.iter().enumerate() {
            let first = sc.firsts[k];
            match *slot {
                Slot::Kept(_) => lists.pairs[k].first = first,
                Slot::Staged { staged: s, .. } => {
                    let q = &sc.staging.pairs[s as usize];
                    let (from, to) = (q.range(), first as usize..(first + q.count) as usize);
                    lists.subs[to.clone()].clone_from_slice(&sc.staging.subs[from.clone()]);
                    lists.records[to].clone_from_slice(&sc.staging.records[from]);
                    lists.pairs[k] = q.clone();
                    lists.pairs[k].first = first;
                    lists.references[k] = sc.staging.references[s as usize].clone();
                    lists.wrenches[k] = sc.staging.wrenches[s as usize];
                }
            }
        }
        self.pairs.truncate(contacts);
        self.references.truncate(contacts);
        self.wrenches.truncate(contacts);
        self.subs.truncate(room);
        self.sub_records.truncate(room);
        if STAGING_FRACTION * sc.staging.subs.capacity() > self.subs.len().max(1) {
            sc.release_staging();
        }
        Ok(owed)
    }

    /// Leaves [`segment_slack`] after every [`SEGMENT`] contacts of packed lists (as a full
    /// detection stages them): the fresh layout of [`place_subcontacts`].
    fn spread_segments(&mut self) {
        let segments = self.pairs.len().div_ceil(SEGMENT);
        let contacts = self.pairs.len();
        let segment = |k: usize| k * SEGMENT..((k + 1) * SEGMENT).min(contacts);
        let slack = |pairs: &[ContactPair], k: usize| segment_slack(pairs[segment(k)].iter().map(|p| p.count).sum());
        // Segment `k` moves back by the slack of the segments before it, the last one first,
        // into room that is dead by then.
        let mut shift: u32 = (0..segments.saturating_sub(1)).map(|k| slack(&self.pairs, k)).sum();
        let (sub, record) = dead_subcontact();
        self.subs.resize(self.subs.len() + shift as usize, sub);
        self.sub_records.resize(self.sub_records.len() + shift as usize, record);
        for k in (1..segments).rev() {
            let contacts = &mut self.pairs[segment(k)];
            let last = &contacts[contacts.len() - 1];
            let (start, end) = (contacts[0].first as usize, (last.first + last.count) as usize);
            move_into_dead_room(&mut self.subs, start..end, i64::from(shift));
            move_into_dead_room(&mut self.sub_records, start..end, i64::from(shift));
            for p in contacts.iter_mut() {
                p.first += shift;
            }
            shift -= slack(&self.pairs, k - 1);
        }
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

/// The block → contact index of the pipeline (`Pipeline::block_contacts`).
#[derive(Clone, Copy)]
struct BlockIndex<'a> {
    offsets: &'a [u32],
    contacts: &'a [u32],
}

/// A sub-contact and a record to fill dead room with (never read).
fn dead_subcontact<S: Default>() -> (SubContact<S>, SubContactRecord) {
    let sub = SubContact {
        plane: Vector2::ZERO,
        area: 0.0,
        gap: 0.0,
        force: JointForce::default(),
        slip: 0.0,
        status: JointStatus::Open,
        state: S::default(),
    };
    (sub, SubContactRecord::new(SubKey(0)))
}

/// A contact and its reference to fill room in the staging lists with until a contact is
/// written there.
fn dead_contact() -> (ContactPair, ContactReference) {
    let pair = ContactPair {
        a: 0,
        b: 0,
        kind: crate::geometry::ContactKind::Point {
            plane_normal: Vector::ZERO,
            plane_offset: 0.0,
        },
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
    };
    let reference = ContactReference {
        ref_a: Vector::ZERO,
        ref_b: Vector::ZERO,
        ref_host_rotation: crate::math::Rotation::IDENTITY,
        area: 0.0,
        bound_area: 0.0,
    };
    (pair, reference)
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

/// Contacts staged by detection: the contact lists' own (owned) form, of the whole detection
/// and of each task of its narrow phase.
#[derive(Debug, Clone)]
struct StagedLists<S> {
    pairs: Vec<ContactPair>,
    references: Vec<ContactReference>,
    wrenches: Vec<ContactWrench>,
    subs: Vec<SubContact<S>>,
    records: Vec<SubContactRecord>,
    /// The contacts and sub-contacts (dead room included) placed so far.
    placed: (usize, usize),
}

impl<S> Default for StagedLists<S> {
    fn default() -> Self {
        Self {
            pairs: Vec::new(),
            references: Vec::new(),
            wrenches: Vec::new(),
            subs: Vec::new(),
            records: Vec::new(),
            placed: (0, 0),
        }
    }
}

impl<S> StagedLists<S> {
    fn lists(&mut self) -> ContactLists<'_, S> {
        ContactLists {
            pairs: &mut self.pairs,
            references: &mut self.references,
            wrenches: &mut self.wrenches,
            subs: &mut self.subs,
            records: &mut self.records,
        }
    }
}

impl<S: Clone + Default + Send + Sync> StagedLists<S> {
    /// Extends the lists to the places [`DetectionScratch::place_staged`] gave (`placed`), with
    /// dead entries written in parallel (the first touch of a large list's memory is most of
    /// its cost), and returns the slices of the new entries, for the contacts to be written.
    fn grow(&mut self) -> StagingSlices<'_, S> {
        let (pair_base, sub_base) = (self.pairs.len(), self.subs.len());
        let (contacts, subs) = self.placed;
        let (pair, reference) = dead_contact();
        let (sub, record) = dead_subcontact();
        self.pairs.par_extend(rayon::iter::repeat_n(pair, contacts - pair_base));
        self.references
            .par_extend(rayon::iter::repeat_n(reference, contacts - pair_base));
        self.wrenches
            .par_extend(rayon::iter::repeat_n(ContactWrench::default(), contacts - pair_base));
        self.subs.par_extend(rayon::iter::repeat_n(sub, subs - sub_base));
        self.records.par_extend(rayon::iter::repeat_n(record, subs - sub_base));
        StagingSlices {
            pair_base,
            sub_base,
            pairs: &mut self.pairs[pair_base..],
            references: &mut self.references[pair_base..],
            wrenches: &mut self.wrenches[pair_base..],
            subs: &mut self.subs[sub_base..],
            records: &mut self.records[sub_base..],
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
}

/// Slices of the staging lists that one task of the narrow phase writes its contacts into:
/// `pairs[0]` is contact `pair_base` of the detection, `subs[0]` its sub-contact `sub_base`.
struct StagingSlices<'a, S> {
    pair_base: usize,
    sub_base: usize,
    pairs: &'a mut [ContactPair],
    references: &'a mut [ContactReference],
    wrenches: &'a mut [ContactWrench],
    subs: &'a mut [SubContact<S>],
    records: &'a mut [SubContactRecord],
}

impl<'a, S> StagingSlices<'a, S> {
    /// The slices from contact `pair` and sub-contact `sub` of the detection on (the second
    /// part), and those before (the first).
    fn split_at(self, pair: usize, sub: usize) -> (Self, Self) {
        let (p, s) = (pair - self.pair_base, sub - self.sub_base);
        let (pairs_a, pairs_b) = self.pairs.split_at_mut(p);
        let (references_a, references_b) = self.references.split_at_mut(p);
        let (wrenches_a, wrenches_b) = self.wrenches.split_at_mut(p);
        let (subs_a, subs_b) = self.subs.split_at_mut(s);
        let (records_a, records_b) = self.records.split_at_mut(s);
        (
            Self {
                pair_base: self.pair_base,
                sub_base: self.sub_base,
                pairs: pairs_a,
                references: references_a,
                wrenches: wrenches_a,
                subs: subs_a,
                records: records_a,
            },
            Self {
                pair_base: pair,
                sub_base: sub,
                pairs: pairs_b,
                references: references_b,
                wrenches: wrenches_b,
                subs: subs_b,
                records: records_b,
            },
        )
    }
}

impl<S: Clone + Default> StagingSlices<'_, S> {
    /// Writes the contact the narrow phase found between blocks `i < j` as contact `staged` of
    /// the detection, its sub-contacts (`seeds`) from `first` on (`law` the index of its joint
    /// law), carrying the history of old contact `k_old` by sub-contact key when it joins the
    /// same features with the same host.
    #[allow(clippy::too_many_arguments)]
    fn write_detected(
        &mut self,
        (staged, first): (u32, u32),
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
        let at = first as usize - self.sub_base;
        let (subs, records) = (
            &mut self.subs[at..at + seeds.len()],
            &mut self.records[at..at + seeds.len()],
        );
        for ((seed, sub_slot), record_slot) in seeds.iter().zip(subs.iter_mut()).zip(records.iter_mut()) {
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
            *sub_slot = sub;
            *record_slot = record;
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
        pair.refresh_springs(subs);
        let k = staged as usize - self.pair_base;
        self.pairs[k] = pair;
        self.wrenches[k] = ContactWrench::default();
        self.references[k] = ContactReference {
            ref_a: bi.state.pose.translation,
            ref_b: bj.state.pose.translation,
            ref_host_rotation: host.state.pose.rotation,
            area: seeds.iter().map(|s| s.area).sum(),
            bound_area,
        };
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::block::BlockState;
    use crate::law::CoulombSlip;
    use crate::model::{Energies, Model};
    use crate::scenes::{shaking_wall, BENCHMARK_SPACING};

    /// The sub-contact ranges increase with the contacts, do not overlap, and lie in the lists,
    /// which stay within the room the last fresh layout allowed.
    fn check_layout<L: ConstitutiveLaw>(state: &ModelState<L>, room_limit: usize) {
        let mut end = 0;
        for (k, p) in state.pairs.iter().enumerate() {
            assert!(p.first >= end, "contact {k} starts at {} before {end}", p.first);
            end = p.first + p.count;
        }
        assert!(end as usize <= state.subs.len(), "sub-contacts past the lists");
        assert_eq!(state.subs.len(), state.sub_records.len());
        assert!(
            state.subs.len() <= room_limit,
            "{} sub-contacts' room past {room_limit}",
            state.subs.len()
        );
    }

    /// Eight bricks (0.2 × 0.1 × 0.05 m, 30 mm apart) sliding at 2 m/s, undamped, on 5° friction,
    /// over a row of twelve fixed ones: their contacts with the row grow, shrink, appear
    /// and vanish as they pass, while two bricks resting aside keep theirs.
    fn conveyor() -> Model<CoulombSlip> {
        use crate::block::Fixity;
        use crate::ids::MaterialId;
        use crate::integrate::Damping;
        let mut model = Model::new(crate::model::ModelParameters::default()).expect("model");
        model
            .set_joint_law(
                MaterialId(0),
                MaterialId(0),
                CoulombSlip::dry(1e9, 4e8, 5.0).expect("law"),
            )
            .expect("law");
        model.set_damping(Damping::None).expect("undamped");
        let brick = |x: Real, z: Real| {
            RigidBlock::cuboid(
                "brick",
                Vector::new(x, 0.0, z),
                Vector::new(x + 0.2, 0.1, z + 0.05),
                2000.0,
            )
            .expect("brick")
        };
        // Bricks resting on fixed ones aside, first and last: contacts kept through every
        // detection, before and after the others.
        let aside = |model: &mut Model<CoulombSlip>, y: Real| {
            let aside = |b: RigidBlock| b.transformed(Pose::from_translation(Vector::new(0.0, y, 0.0)));
            model
                .add_block(aside(brick(0.0, -0.05)).with_fixity(Fixity::FIXED))
                .expect("aside");
            model.add_block(aside(brick(0.0, 0.0))).expect("aside");
        };
        aside(&mut model, 0.5);
        for k in 0..12 {
            model
                .add_block(brick(0.2 * k as Real, -0.05).with_fixity(Fixity::FIXED))
                .expect("row");
        }
        for k in 0..8 {
            let moving = brick(0.1 + 0.23 * k as Real, 0.0).with_velocity(Vector::new(2.0, 0.0, 0.0), Vector::ZERO);
            model.add_block(moving).expect("brick");
        }
        aside(&mut model, -0.5);
        model
    }

    /// Every contact with its sub-contacts and their records (its `first` left out).
    type Contacts<S> = Vec<(ContactPair, Vec<SubContact<S>>, Vec<SubContactRecord>)>;

    /// `model` run for `steps` steps with the splices `mode` allows: the blocks' states, the
    /// energies, the splice counts and the contacts at the end.
    fn run<L: ConstitutiveLaw>(
        mut model: Model<L>,
        mode: SpliceMode,
        steps: usize,
    ) -> (Vec<BlockState>, Energies, SpliceCounts, Contacts<L::State>) {
        model.pipeline.detection.splice_mode = mode;
        for _ in 0..steps {
            model.step().expect("step");
            check_layout(&model.state, model.pipeline.detection.room_limit);
        }
        let states = model.blocks().iter().map(|b| *b.state()).collect();
        let s = &model.state;
        let contacts = s
            .pairs
            .iter()
            .map(|p| {
                let pair = ContactPair { first: 0, ..p.clone() };
                (pair, s.subs[p.range()].to_vec(), s.sub_records[p.range()].to_vec())
            })
            .collect();
        (states, model.energies(), model.pipeline.detection.splices, contacts)
    }

    /// The in-place splice (re-tested contacts written over the old ones, pushing their
    /// neighbours back when they outgrow their room), the full splice into the gapped layout,
    /// and the full splice into a fresh layout every time give the same bits, through bricks
    /// sliding over a row (contacts growing, shrinking, appearing and vanishing) and a shaking
    /// wall's rocking: the sub-contact layout never shows in the results. Each path is taken.
    #[test]
    fn in_place_full_and_fresh_splices_give_the_same_bits() {
        type Scene = fn() -> Model<CoulombSlip>;
        let scenes: [(&str, Scene, usize); 2] = [
            ("conveyor", conveyor, 4000),
            (
                "shaking wall",
                || shaking_wall(300, BENCHMARK_SPACING).expect("wall"),
                1500,
            ),
        ];
        let mut counts = Vec::new();
        for (name, scene, steps) in scenes {
            let any = run(scene(), SpliceMode::Any, steps);
            let full = run(scene(), SpliceMode::Full, steps);
            let fresh = run(scene(), SpliceMode::Fresh, steps);
            for other in [&full, &fresh] {
                assert!(any.0 == other.0, "{name}: block states differ");
                assert_eq!(any.1, other.1, "{name}: energies differ");
                assert!(any.3 == other.3, "{name}: contacts differ");
            }
            let (f, r) = (full.2, fresh.2);
            assert_eq!(f.in_place, 0, "{name}");
            assert!(
                r.fresh == r.full && r.full > 100,
                "{name}: fresh layouts not exercised: {r:?}"
            );
            counts.push((any.2, f));
        }
        let ((conveyor, conveyor_full), (wall, _)) = (counts[0], counts[1]);
        assert!(
            conveyor.in_place > 100 && conveyor.pushed > 10 && conveyor.full > 5,
            "in-place splices with pushes, and full ones, not exercised: {conveyor:?}"
        );
        assert!(
            conveyor_full.fresh < conveyor_full.full,
            "gapped full splices not exercised: {conveyor_full:?}"
        );
        assert!(wall.in_place > 100, "the shaking wall's splices are in place: {wall:?}");
    }

    /// Spreading packed lists into segments moves every contact's sub-contacts and records with
    /// it, and leaves the slack between segments.
    #[test]
    fn spreading_segments_keeps_every_contacts_subcontacts() {
        let mut model = shaking_wall(300, BENCHMARK_SPACING).expect("wall");
        model.step().expect("first detection");
        let state = &mut model.state;
        let contacts = state.pairs.len();
        assert!(contacts > 4 * SEGMENT, "{contacts} contacts");
        let each: Vec<_> = state
            .pairs
            .iter()
            .map(|p| (state.subs[p.range()].to_vec(), state.sub_records[p.range()].to_vec()))
            .collect();
        // Packed again, as a full detection stages them.
        let (mut subs, mut records) = (Vec::new(), Vec::new());
        for (p, (s, r)) in state.pairs.iter_mut().zip(&each) {
            p.first = subs.len() as u32;
            subs.extend_from_slice(s);
            records.extend_from_slice(r);
        }
        let live = subs.len();
        (state.subs, state.sub_records) = (subs, records);
        state.spread_segments();
        check_layout(state, room_limit(live));
        for (k, (p, (s, r))) in state.pairs.iter().zip(&each).enumerate() {
            assert!(state.subs[p.range()] == s[..], "contact {k}'s sub-contacts");
            assert!(state.sub_records[p.range()] == r[..], "contact {k}'s records");
        }
        let gaps = contacts.div_ceil(SEGMENT) - 1;
        assert!(
            state.subs.len() >= live + 4 * gaps,
            "{} for {live} live",
            state.subs.len()
        );
        for k in 1..=gaps {
            let (before, after) = (&state.pairs[k * SEGMENT - 1], &state.pairs[k * SEGMENT]);
            assert!(
                after.first >= before.first + before.count + 4,
                "no slack before segment {k}"
            );
        }
    }

    /// Galloping finds the partition point from any start.
    #[test]
    fn gallop_finds_the_partition_point() {
        let list: Vec<u32> = (0..200).map(|k| k / 3).collect();
        for start in [0, 1, 17, 100, 199, 200] {
            for x in [0, 1, 5, 33, 50, 66, 67, 80] {
                let expected = start + list[start..].partition_point(|&v| v < x);
                assert_eq!(gallop(&list, start, |&v| v < x), expected, "start {start}, x {x}");
            }
        }
    }
}
