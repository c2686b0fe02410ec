//! The pairs a detection looks at: the tested pairs and their verdicts, the plan of a
//! detection (candidates with their old entries), the parallel narrow phase over it.

use crate::block::{Block, RigidBlock};
use crate::contact::{ContactPair, SubContact};
use crate::geometry::{
    detect, BlockGeometry, ContactKind, ContactParameters, DetectedContact, NarrowPhaseScratch, PreviousContact,
    SubContactSeed,
};
use crate::law::JointForce;
use crate::math::{Pose, Real, Vector};

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

/// A candidate pair of the broad phase (two blocks not both fixed), with its entries in the
/// lists of the last detection.
#[derive(Debug, Clone, Copy)]
pub(super) struct Planned {
    pub(super) a: u32,
    pub(super) b: u32,
    /// Index in [`ModelState::tested`], or `u32::MAX`.
    pub(super) tested: u32,
    /// Index of its contact, or `u32::MAX`.
    pub(super) contact: u32,
}

impl Planned {
    pub(super) fn old_tested(&self) -> Option<usize> {
        (self.tested != u32::MAX).then_some(self.tested as usize)
    }

    pub(super) fn old_contact(&self) -> Option<usize> {
        (self.contact != u32::MAX).then_some(self.contact as usize)
    }
}

/// What the narrow phase made of a planned pair.
#[derive(Debug, Clone)]
pub(super) struct Outcome {
    /// Tested afresh (else its last verdict holds).
    pub(super) tested: bool,
    /// The test's entry for [`ModelState::tested`].
    pub(super) entry: TestedPair,
    pub(super) contact: Option<DetectedContact>,
    /// The contact's seeds in its chunk's buffer.
    pub(super) first_seed: u32,
    pub(super) seed_count: u32,
    /// Its index in the staging lists, once placed (else `u32::MAX`), and that of its first
    /// sub-contact.
    pub(super) staged: u32,
    pub(super) first_sub: u32,
    /// The pair's overlap when tested (m, the depth along the axis of least penetration), or
    /// 0 when they do not overlap.
    pub(super) overlap: Real,
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
            overlap: 0.0,
        }
    }
}

/// One task's buffers of the parallel narrow phase: the seeds of its contacts, and where it
/// stages them.
#[derive(Debug, Clone, Default)]
pub(super) struct ChunkScratch {
    pub(super) narrow: NarrowPhaseScratch,
    pub(super) seeds: Vec<SubContactSeed>,
    /// The index of its first staged contact and of that contact's first sub-contact in the
    /// staging lists (those of the next one when it stages none).
    pub(super) place: (u32, u32),
}

/// What the parallel narrow phase reads.
pub(super) struct PairTest<'a, S> {
    /// Per joint law, whether its node contacts are integrated (`DetectionScratch::integrated_laws`).
    pub(super) integrated_laws: &'a [bool],
    pub(super) blocks: &'a [RigidBlock],
    pub(super) tested: &'a [TestedPair],
    pub(super) pairs: &'a [ContactPair],
    /// The contacts' sub-contacts and their dashpot forces (their history, for
    /// [`PreviousContact::blank`]; empty when the model keeps no dashpot forces).
    pub(super) subs: &'a [SubContact<S>],
    pub(super) dashpots: &'a [Vector],
    pub(super) params: &'a ContactParameters,
    /// The relative motion within which a contact keeps its verdict; `None` tests every pair.
    pub(super) keep_within: Option<Real>,
}

impl<S: PartialEq + Default> PairTest<'_, S> {
    /// Whether contact `c` carries nothing that a change of host could lose
    /// ([`PreviousContact::blank`]): a face-face joint whose sub-contacts have no force and no
    /// dashpot force and are in the fresh state of a face joint's cell (`S::default()`, what
    /// detection gives a new cell). A joint stepped as a whole is blank when open all over (its
    /// cells unloaded and virgin; detection writes such a joint's cells before it looks at the
    /// pair again).
    fn blank(&self, c: usize) -> bool {
        let p = &self.pairs[c];
        if !matches!(p.kind, ContactKind::FaceFace { .. }) {
            return false;
        }
        if p.joint.active {
            return p.joint.open;
        }
        let fresh = S::default();
        self.subs[p.range()]
            .iter()
            .all(|s| s.force == JointForce::default() && s.state == fresh)
            && self
                .dashpots
                .get(p.range())
                .is_none_or(|d| d.iter().all(|d| *d == Vector::ZERO))
    }

    /// Decides and, where needed, tests one chunk of planned pairs.
    pub(super) fn run(&self, plan: &[Planned], outcomes: &mut [Outcome], scratch: &mut ChunkScratch) {
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
            let previous = p.old_contact().map(|c| PreviousContact {
                kind: self.pairs[c].kind,
                host_is_a: self.pairs[c].host_is_a,
                loaded: self.pairs[c].normal_force > 0.0,
                turns_back: self.pairs[c].may_turn_back(
                    &self.subs[self.pairs[c].range()],
                    super::law_integrated(self.integrated_laws, self.pairs[c].law),
                ),
                // (Only an unloaded joint can be blank: a loaded one is not looked at.)
                blank: self.pairs[c].normal_force <= 0.0 && self.blank(c),
            });
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
                overlap: (-separation).max(0.0),
                contact: found,
            };
        }
    }
}

/// The candidate pairs with a block that moved, not between two fixed blocks, each with its
/// entries in the sorted `tested` and contact lists of the last detection, given by their keys
/// (a merge of sorted lists that gallops over the entries between two candidates: the
/// candidates of a local re-detection are few).
pub(super) fn plan(
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
pub(super) fn gallop<T>(list: &[T], start: usize, before: impl Fn(&T) -> bool) -> usize {
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
pub(super) fn update_tested(
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
pub(super) fn relative_motion(now: &Pose, then: &Pose, radius: Real) -> Real {
    let translation = (now.translation - then.translation).length();
    let half_sine = (now.rotation * then.rotation.inverse()).xyz().length().min(1.0);
    translation + 2.0 * radius * half_sine
}
