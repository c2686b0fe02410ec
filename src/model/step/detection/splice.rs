//! Bringing the contact lists up to date with a detection: in place (re-tested contacts
//! written over the old ones) or in general (kept contacts moved, new ones placed), the layout
//! of sub-contacts with dead room, and the work owed by dropped sub-contacts.

use super::*;
use crate::block::{Block, RigidBlock};
use crate::contact::{
    stored_node_frame, ContactLists, ContactPair, ContactReference, ContactStore, ContactWrench, DisplacementMode,
    OldContacts, SmallReference, SubContact,
};
use crate::error::Result;
use crate::geometry::{ContactKind, NodeId};
use crate::law::ConstitutiveLaw;
use crate::math::{Matrix, Real, Vector};
use crate::model::ModelState;

/// A contact after detection: an old one kept (its index), or one detected afresh (its index
/// in the staging lists, and the old contact of the same pair it replaces or `u32::MAX`).
#[derive(Debug, Clone, Copy)]
pub(super) enum Slot {
    Kept(u32),
    Staged { staged: u32, replaces: u32 },
}

impl Slot {
    /// Where the contact's sub-contacts were before the detection: those of the old contact
    /// it keeps or replaces.
    pub(super) fn home(self, old: &[ContactPair]) -> Option<u32> {
        match self {
            Slot::Kept(c) => Some(old[c as usize].first),
            Slot::Staged { replaces, .. } => old.get(replaces as usize).map(|p| p.first),
        }
    }

    pub(super) fn count(self, old: &[ContactPair], staged: &[ContactPair]) -> u32 {
        match self {
            Slot::Kept(c) => old[c as usize].count,
            Slot::Staged { staged: s, .. } => staged[s as usize].count,
        }
    }
}

/// The room a re-tested contact is given beyond its sub-contacts when it outgrows the room it
/// had (or a new one has none), so that it can grow again without moving its neighbours
/// (`docs/theory.md` §2.3, "Parallel, in place").
pub(super) fn headroom(count: u32) -> u32 {
    count / 8 + 2
}

/// The room the sub-contact lists may take with `live` sub-contacts.
pub(super) fn room_limit(live: usize) -> usize {
    live + live / COMPACT_FRACTION as usize
}

/// The sub-contact list is compacted when the room between contacts exceeds this share of the
/// sub-contacts (`1/COMPACT_FRACTION`).
pub(super) const COMPACT_FRACTION: u32 = 4;

/// Contacts per segment of a fresh layout, after each of which [`segment_slack`] is left
/// empty: a contact that outgrows its room pushes at most the rest of its segment.
pub(super) const SEGMENT: usize = 64;

/// The dead room left after a segment of `subs` sub-contacts in a fresh layout: a sixteenth.
pub(super) fn segment_slack(subs: u32) -> u32 {
    subs / 16 + 4
}

/// Where each contact of `layout` puts its sub-contacts (`firsts`, increasing with the contact):
/// at its home ([`Slot::home`]) unless the contacts before it reach past it, a new contact right
/// after the one before; a re-tested contact that reaches past the next contact's home gets
/// [`headroom`]. A fresh layout (every contact right after the one before, with
/// [`segment_slack`] after every [`SEGMENT`] contacts) when that would leave more than
/// `1/COMPACT_FRACTION` of the room empty, or when `fresh`. Returns the end of the room used,
/// the room the lists may take before they are laid out afresh again, and whether they were.
pub(super) fn place_subcontacts(
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
pub(super) fn move_into_dead_room<T>(list: &mut [T], range: std::ops::Range<usize>, shift: i64) {
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

impl<S: Clone + Default> ContactStore<S> {
    /// Makes the sub-contact lists (the sub-contacts and their dashpot forces, when kept) `len`
    /// long: dead room added at the end (never read), or the end cut off.
    pub(super) fn resize_subcontacts(&mut self, len: usize) {
        self.subs.resize(len, dead_subcontact());
        if self.dashpots_kept {
            self.sub_dashpots.resize(len, Vector::ZERO);
        }
    }

    /// Moves sub-contacts `range` (with their dashpot forces) by `shift` places into dead room
    /// ([`move_into_dead_room`]).
    pub(super) fn move_subcontacts(&mut self, range: std::ops::Range<usize>, shift: i64) {
        move_into_dead_room(&mut self.subs, range.clone(), shift);
        if self.dashpots_kept {
            move_into_dead_room(&mut self.sub_dashpots, range, shift);
        }
    }

    /// Writes `from`'s sub-contacts `range` (with their dashpot forces) from sub-contact `to`
    /// on.
    pub(super) fn copy_subcontacts(&mut self, to: usize, from: &Self, range: std::ops::Range<usize>) {
        let end = to + range.len();
        self.subs[to..end].clone_from_slice(&from.subs[range.clone()]);
        if self.dashpots_kept {
            self.sub_dashpots[to..end].copy_from_slice(&from.sub_dashpots[range]);
        }
    }
}

/// Which runs of kept contacts [`ContactLists::move_run`] moves.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Direction {
    /// Those that move towards the front (or stay), run by run from the first.
    Front,
    /// Those that move towards the back, run by run from the last.
    Back,
}

impl<S> ContactLists<'_, S> {
    /// Moves a run of old contacts to their new indices, if they move in `direction`, into the
    /// dead room they move into ([`move_into_dead_room`]; their sub-contacts stay).
    pub(super) fn move_contacts(&mut self, run: &Run, direction: Direction) {
        let (c, k, len) = (run.old as usize, run.new as usize, run.len as usize);
        let shift = k as i64 - c as i64;
        if (direction == Direction::Front && shift < 0) || (direction == Direction::Back && shift > 0) {
            move_into_dead_room(self.pairs, c..c + len, shift);
            move_into_dead_room(self.references, c..c + len, shift);
            move_into_dead_room(self.wrenches, c..c + len, shift);
            if self.small_kept {
                move_into_dead_room(self.small_refs, c..c + len, shift);
            }
        }
    }

    /// Moves the sub-contacts `range` by `shift`, if they move in `direction`, into the dead
    /// room they move into ([`move_into_dead_room`]).
    pub(super) fn move_subcontacts(&mut self, range: std::ops::Range<usize>, shift: i64, direction: Direction) {
        if (direction == Direction::Front && shift < 0) || (direction == Direction::Back && shift > 0) {
            move_into_dead_room(self.subs, range.clone(), shift);
            if self.dashpots_kept {
                move_into_dead_room(self.dashpots, range, shift);
            }
        }
    }
}

/// Sub-contacts `start..end` of consecutive kept contacts (and the dead room between them) that
/// move by `shift`.
#[derive(Debug, Clone, Copy)]
pub(super) struct SubRun {
    pub(super) start: u32,
    pub(super) end: u32,
    pub(super) shift: i64,
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
pub(super) struct Replaced {
    pub(super) contact: u32,
    pub(super) staged: u32,
    pub(super) first: u32,
}

/// Neighbouring kept contacts whose sub-contacts the in-place splice pushes back by `shift`.
#[derive(Debug, Clone)]
pub(super) struct Pushed {
    pub(super) contacts: std::ops::Range<u32>,
    pub(super) shift: u32,
}

/// Consecutive old contacts `old..old + len` that go to `new..new + len`.
#[derive(Debug, Clone, Copy)]
pub(super) struct Run {
    pub(super) old: u32,
    pub(super) new: u32,
    pub(super) len: u32,
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
pub(super) fn dropped_work<S: PartialEq + Default>(
    old: &OldContacts<'_, S>,
    new: (&[ContactPair], &[ContactReference], &[SubContact<S>]),
    kept: &[bool],
    blocks: &[RigidBlock],
    (mode, integrated_laws): (DisplacementMode, &[bool]),
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
            .map(|s| (&new.0[s], &new.1[s], new.2));
        add_dropped_work(old, k, successor, blocks, (mode, integrated_laws), dt, &mut owed);
    }
    owed
}

/// Adds to `owed` the work ([`dropped_work`]) of the sub-contacts of old contact `k` that its
/// `successor` (the new contact of the same pair, its reference and the new sub-contacts it
/// indexes) does not carry on.
pub(super) fn add_dropped_work<S: PartialEq + Default>(
    old: &OldContacts<'_, S>,
    k: usize,
    successor: Option<(&ContactPair, &ContactReference, &[SubContact<S>])>,
    blocks: &[RigidBlock],
    (mode, integrated_laws): (DisplacementMode, &[bool]),
    dt: Real,
    owed: &mut (Real, Real),
) {
    let (p, reference) = (&old.pairs[k], &old.references[k]);
    // The geometry the contact stepped with (the current poses when its references were not
    // kept: it was found in large-displacement mode).
    let small = SmallReference::of(old.small_refs, k, mode);
    debug_assert!(!p.joint.active, "a joint stepped as a whole dropped unwritten");
    let carried = successor
        .filter(|(q, ..)| q.kind.same_joint(&p.kind) && q.host_is_a == p.host_is_a)
        .map(|(q, reference, subs)| (q, reference, &subs[q.range()]));
    // A node contact turning into a joint hands its spring forces to the joint's cells, whose
    // springs book their second half (`staging.rs`); its dashpot forces are dropped.
    let integrated = super::law_integrated(integrated_laws, p.law);
    let handed = successor.is_some_and(|(q, ..)| p.hands_forces_to_cells(&old.subs[p.range()], integrated, &q.kind));
    let (sa, sb) = (&blocks[p.a as usize].state, &blocks[p.b as usize].state);
    let frame = p.frame(small, &sa.pose, &sb.pose);
    let (xa, xb) = SmallReference::centroids(small, &sa.pose, &sb.pose);
    let nodes = matches!(p.kind, ContactKind::Nodes);
    let (ba, bb) = (&blocks[p.a as usize], &blocks[p.b as usize]);
    let rotations = if nodes {
        (Matrix::from_quat(sa.pose.rotation), Matrix::from_quat(sb.pose.rotation))
    } else {
        (Matrix::IDENTITY, Matrix::IDENTITY)
    };
    for (n, (s, i)) in old.subs[p.range()].iter().zip(p.range()).enumerate() {
        let dashpot = old.dashpot(i);
        let (pt, axes) = if nodes {
            stored_node_frame(
                NodeId::from_key(p.key(reference, n, s)),
                s.plane.x as usize,
                (sa, &rotations.0, ba.shape()),
                (sb, &rotations.1, bb.shape()),
            )
        } else {
            (frame.transform_point(p.anchor(s)), p.axes())
        };
        let spring = if handed { Vector::ZERO } else { axes.force(&s.force) };
        if spring == Vector::ZERO && dashpot == Vector::ZERO {
            continue;
        }
        if carried.is_some_and(|(q, kept, own)| q.find_key(kept, own, p.key(reference, n, s)).is_some()) {
            continue;
        }
        let v_rel =
            (sb.velocity + sb.angular_velocity.cross(pt - xb)) - (sa.velocity + sa.angular_velocity.cross(pt - xa));
        let du = v_rel * dt;
        owed.0 -= 0.5 * spring.dot(du);
        owed.1 -= 0.5 * dashpot.dot(du);
    }
}

impl<L: ConstitutiveLaw> ModelState<L> {
    /// The usual splice, whose cost follows the re-tested contacts alone: when no contact
    /// appeared or was lost, the re-tested contacts are written over the old ones, each in the
    /// room of the one it replaces (its sub-contacts and the dead room after them). One that
    /// outgrows its room takes [`headroom`] besides and pushes the contacts after it towards the
    /// back, as far as the dead room between them absorbs the push (`docs/theory.md` §2.3).
    /// Returns the work of the dropped sub-contacts, as [`ModelState::splice_contacts`] would,
    /// or `None`, with nothing changed, when it does not apply: a contact appeared or was lost,
    /// or the room would pass the limit the last compaction set.
    pub(super) fn splice_in_place(
        &mut self,
        sc: &mut DetectionScratch<L::State>,
        index: BlockIndex<'_>,
    ) -> Option<(Real, Real)> {
        let n = self.blocks.len();
        if index.offsets.len() != n + 1 || index.offsets[n] as usize != 2 * self.contacts.pairs.len() {
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
                        first: self.contacts.pairs[k].first,
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
                if e % 2 == 0 || !moved[self.contacts.pairs[(e / 2) as usize].a as usize] {
                    moved_contacts += 1;
                }
            }
        }
        if moved_contacts != planned_contacts {
            return None;
        }
        // Where the re-tested contacts go, and the kept ones they push.
        sc.pushed.clear();
        let contacts = self.contacts.pairs.len();
        let room = self.contacts.subs.len() as u32;
        let mut needed = room;
        let mut window_end = 0;
        let count = |staged: u32| sc.staging.store.pairs[staged as usize].count;
        for r in 0..sc.replaced.len() {
            let Replaced { contact: k, staged, .. } = sc.replaced[r];
            let k = k as usize;
            if k < window_end {
                continue; // placed by the push of a contact before it
            }
            let end = self.contacts.pairs.get(k + 1).map_or(room, |q| q.first);
            let (first, m) = (self.contacts.pairs[k].first, count(staged));
            if first + m <= end {
                continue;
            }
            // It outgrew its room: the contacts after it go right after the one before them
            // until one's home is far enough back.
            let mut cursor = first + m + headroom(m);
            let (mut j, mut next) = (k + 1, r + 1);
            while j < contacts && cursor > self.contacts.pairs[j].first {
                match sc.replaced.get(next).copied() {
                    Some(q) if q.contact as usize == j => {
                        sc.replaced[next].first = cursor;
                        cursor += count(q.staged);
                        next += 1;
                    }
                    _ => {
                        // Neighbours pushed by as much move as one run.
                        let (p, shift) = (&self.contacts.pairs[j], cursor - self.contacts.pairs[j].first);
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
        let old = self.contacts.old();
        let dt = if self.clock.drift > 0.0 {
            self.clock.drift
        } else {
            self.clock.dt
        };
        let mut owed = (0.0, 0.0);
        for r in &sc.replaced {
            let successor = (
                &sc.staging.store.pairs[r.staged as usize],
                &sc.staging.store.references[r.staged as usize],
                sc.staging.store.subs.as_slice(),
            );
            add_dropped_work(
                &old,
                r.contact as usize,
                Some(successor),
                &self.blocks,
                (self.params.mode, &sc.integrated_laws),
                dt,
                &mut owed,
            );
        }
        // Every contact is re-tested in small-displacement mode (a full detection): each
        // gets its reference below.
        self.contacts.keep_small_refs(sc.staging.store.small_kept);
        if needed > room {
            // Dead room (sub-contacts not in any contact's range are never read).
            self.contacts.resize_subcontacts(needed as usize);
        }
        // Pushed contacts move from the last: each moves into room that is dead by then (the
        // old room of the ones after it, which moved further back, or of re-tested ones).
        for run in sc.pushed.iter().rev() {
            let contacts = &mut self.contacts.pairs[run.contacts.start as usize..run.contacts.end as usize];
            let last = &contacts[contacts.len() - 1];
            let (start, end) = (
                contacts[0].first as usize,
                (last.first + last.count + run.shift) as usize,
            );
            let moved = start..end - run.shift as usize;
            for p in contacts {
                p.first += run.shift;
            }
            self.contacts.move_subcontacts(moved, i64::from(run.shift));
        }
        for r in &sc.replaced {
            let (k, s) = (r.contact as usize, r.staged as usize);
            let q = &sc.staging.store.pairs[s];
            let to = r.first as usize..(r.first + q.count) as usize;
            self.contacts.copy_subcontacts(to.start, &sc.staging.store, q.range());
            self.contacts.pairs[k] = q.clone();
            self.contacts.pairs[k].first = r.first;
            self.contacts.references[k] = sc.staging.store.references[s].clone();
            self.contacts.wrenches[k] = sc.staging.store.wrenches[s];
            if self.contacts.small_kept {
                self.contacts.small_refs[k] = sc.staging.store.small_refs[s];
            }
        }
        sc.reindex = false;
        sc.splices.in_place += 1;
        sc.splices.pushed += u64::from(!sc.pushed.is_empty() || needed > room);
        if STAGING_FRACTION * sc.staging.store.subs.capacity() > self.contacts.subs.len().max(1) {
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
    pub(super) fn splice_contacts(&mut self, sc: &mut DetectionScratch<L::State>) -> Result<(Real, Real)> {
        // The new order: kept old contacts and staged new ones, by pair.
        let old = self.contacts.old();
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
            (
                &sc.staging.store.pairs,
                &sc.staging.store.references,
                &sc.staging.store.subs,
            ),
            &sc.kept,
            &self.blocks,
            (self.params.mode, &sc.integrated_laws),
            if self.clock.drift > 0.0 {
                self.clock.drift
            } else {
                self.clock.dt
            },
        );
        sc.reindex = sc.layout.len() != self.contacts.pairs.len()
            || sc.layout.iter().enumerate().any(|(k, slot)| match *slot {
                Slot::Kept(c) => c as usize != k,
                Slot::Staged { staged, .. } => {
                    let q = &sc.staging.store.pairs[staged as usize];
                    self.contacts.pairs.get(k).is_none_or(|p| (p.a, p.b) != (q.a, q.b))
                }
            });
        if sc.layout.iter().all(|slot| matches!(slot, Slot::Staged { .. })) {
            // Every contact detected afresh (the first detection, a full one): the staging lists
            // are the new lists, and the old ones are released rather than kept as staging.
            std::mem::swap(&mut self.contacts.pairs, &mut sc.staging.store.pairs);
            std::mem::swap(&mut self.contacts.references, &mut sc.staging.store.references);
            std::mem::swap(&mut self.contacts.wrenches, &mut sc.staging.store.wrenches);
            std::mem::swap(&mut self.contacts.small_refs, &mut sc.staging.store.small_refs);
            std::mem::swap(&mut self.contacts.small_kept, &mut sc.staging.store.small_kept);
            std::mem::swap(&mut self.contacts.subs, &mut sc.staging.store.subs);
            std::mem::swap(&mut self.contacts.sub_dashpots, &mut sc.staging.store.sub_dashpots);
            sc.release_staging();
            sc.room_limit = room_limit(self.contacts.pairs.iter().map(|p| p.count as usize).sum());
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
            &self.contacts.pairs,
            &sc.staging.store.pairs,
            self.contacts.subs.len() as u32,
            sc.room_limit == 0 || sc.fresh_forced(),
            &mut sc.firsts,
        );
        sc.room_limit = limit;
        sc.splices.full += 1;
        sc.splices.fresh += u64::from(fresh);
        let (contacts, room) = (sc.layout.len(), end as usize);
        // Every contact is re-tested in small-displacement mode (a full detection): each
        // gets its reference below.
        self.contacts.keep_small_refs(sc.staging.store.small_kept);
        if contacts > self.contacts.pairs.len() {
            // Room for the new contacts (the fillers are overwritten below).
            let filler = (
                sc.staging.store.pairs[0].clone(),
                sc.staging.store.references[0].clone(),
            );
            self.contacts.pairs.resize(contacts, filler.0);
            self.contacts.references.resize(contacts, filler.1);
            self.contacts.wrenches.resize(contacts, ContactWrench::default());
            if self.contacts.small_kept {
                self.contacts.small_refs.resize(contacts, SmallReference::DEAD);
            }
        }
        if room > self.contacts.subs.len() {
            // Dead room (sub-contacts not in any contact's range are never read).
            self.contacts.resize_subcontacts(room);
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
            let p = &self.contacts.pairs[c as usize];
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
        let mut lists = self.contacts.lists();
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
                    let q = &sc.staging.store.pairs[s as usize];
                    let (from, to) = (q.range(), first as usize..(first + q.count) as usize);
                    lists.subs[to.clone()].clone_from_slice(&sc.staging.store.subs[from.clone()]);
                    if lists.dashpots_kept {
                        lists.dashpots[to].copy_from_slice(&sc.staging.store.sub_dashpots[from]);
                    }
                    lists.pairs[k] = q.clone();
                    lists.pairs[k].first = first;
                    lists.references[k] = sc.staging.store.references[s as usize].clone();
                    lists.wrenches[k] = sc.staging.store.wrenches[s as usize];
                    if lists.small_kept {
                        lists.small_refs[k] = sc.staging.store.small_refs[s as usize];
                    }
                }
            }
        }
        self.contacts.pairs.truncate(contacts);
        self.contacts.references.truncate(contacts);
        self.contacts.wrenches.truncate(contacts);
        self.contacts.small_refs.truncate(contacts);
        self.contacts.resize_subcontacts(room);
        if STAGING_FRACTION * sc.staging.store.subs.capacity() > self.contacts.subs.len().max(1) {
            sc.release_staging();
        }
        Ok(owed)
    }

    /// Leaves [`segment_slack`] after every [`SEGMENT`] contacts of packed lists (as a full
    /// detection stages them): the fresh layout of [`place_subcontacts`].
    pub(super) fn spread_segments(&mut self) {
        let segments = self.contacts.pairs.len().div_ceil(SEGMENT);
        let contacts = self.contacts.pairs.len();
        let segment = |k: usize| k * SEGMENT..((k + 1) * SEGMENT).min(contacts);
        let slack = |pairs: &[ContactPair], k: usize| segment_slack(pairs[segment(k)].iter().map(|p| p.count).sum());
        // Segment `k` moves back by the slack of the segments before it, the last one first,
        // into room that is dead by then.
        let mut shift: u32 = (0..segments.saturating_sub(1))
            .map(|k| slack(&self.contacts.pairs, k))
            .sum();
        self.contacts
            .resize_subcontacts(self.contacts.subs.len() + shift as usize);
        for k in (1..segments).rev() {
            let contacts = &mut self.contacts.pairs[segment(k)];
            let last = &contacts[contacts.len() - 1];
            let (start, end) = (contacts[0].first as usize, (last.first + last.count) as usize);
            for p in contacts.iter_mut() {
                p.first += shift;
            }
            self.contacts.move_subcontacts(start..end, i64::from(shift));
            shift -= slack(&self.contacts.pairs, k - 1);
        }
    }
}
