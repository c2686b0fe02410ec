//! The contacts as the step stores them: the pairs, their references and wrenches, the
//! sub-contacts (each with its key, or for a node its contact's reference), struct of arrays
//! (each contact owns a contiguous range of the sub-contacts, `ContactPair::range`), the
//! contacts' geometry at detection in small-displacement mode, and the sub-contacts' dashpot
//! forces when the model has any. One owner, [`ContactStore`], and the views the stages take of
//! it: [`OldContacts`] (detection reading the contacts it replaces),
//! [`ContactLists`] (detection rearranging them) and [`ContactSlices`] (the contact pass
//! writing them, split at chunk boundaries).

use super::{ContactPair, ContactReference, ContactWrench, SmallReference, SubContact};
use crate::math::Vector;

/// The contacts of a model (or detection's staging lists): struct of arrays, kept index for
/// index (`pairs`, `references`, `wrenches` and, when kept, `small_refs`; `subs` and, when
/// kept, `sub_dashpots`). A sub-contact's key is no list of its own: a face-face cell holds its
/// grid indices in what was its padding, a node contact's reference its nodes' keys
/// ([`super::ContactPair::key`]).
#[derive(Debug, Clone)]
pub(crate) struct ContactStore<S> {
    /// The contacts, sorted by block pair.
    pub pairs: Vec<ContactPair>,
    /// The contacts' reference geometry and areas, index for index with `pairs`.
    pub references: Vec<ContactReference>,
    /// The contacts' resultants and moments, index for index with `pairs`: written by the
    /// contact pass, read by the per-block gather and the accessors (kept out of
    /// `ContactPair`, whose stream they would lengthen by 72 bytes per contact). Detection
    /// carries a kept contact's wrench and starts a new one at zero; checkpointed.
    pub wrenches: Vec<ContactWrench>,
    /// The contacts' geometry at detection, which small-displacement mode steps with, index
    /// for index with `pairs` while `small_kept` — empty otherwise (no allocation): large
    /// displacements step with the current poses, and a switch to small displacements detects
    /// every contact afresh, so that they never read it. Detection keeps it in
    /// small-displacement mode and drops it in large mode; a checkpoint loaded in small mode
    /// keeps the stored one.
    pub small_refs: Vec<SmallReference>,
    /// Whether `small_refs` is kept (index for index with `pairs`).
    pub small_kept: bool,
    /// The sub-contacts, each contact's in its range.
    pub subs: Vec<SubContact<S>>,
    /// The sub-contacts' stiffness-proportional (Rayleigh) dashpot forces on `b` (world) of the
    /// last step, index for index with `subs` while `dashpots_kept` — empty otherwise, while
    /// no sub-contact of the model can hold one (no Rayleigh damping since the model was built
    /// or loaded): every dashpot force is then zero, and the list costs nothing. Filled with
    /// zeros when a step first needs it ([`ContactStore::keep_dashpots`]), and kept since.
    pub sub_dashpots: Vec<Vector>,
    /// Whether `sub_dashpots` is kept (index for index with `subs`).
    pub dashpots_kept: bool,
}

impl<S> Default for ContactStore<S> {
    fn default() -> Self {
        Self {
            pairs: Vec::new(),
            references: Vec::new(),
            wrenches: Vec::new(),
            small_refs: Vec::new(),
            small_kept: false,
            subs: Vec::new(),
            sub_dashpots: Vec::new(),
            dashpots_kept: false,
        }
    }
}

impl<S> ContactStore<S> {
    /// The contacts as detection reads the ones it replaces.
    pub(crate) fn old(&self) -> OldContacts<'_, S> {
        OldContacts {
            pairs: &self.pairs,
            references: &self.references,
            small_refs: &self.small_refs,
            subs: &self.subs,
            dashpots: &self.sub_dashpots,
        }
    }

    /// Keeps the sub-contacts' dashpot forces from now on (zero where none was kept).
    pub(crate) fn keep_dashpots(&mut self) {
        if !self.dashpots_kept {
            self.dashpots_kept = true;
            self.sub_dashpots.clear();
            self.sub_dashpots.resize(self.subs.len(), Vector::ZERO);
        }
    }

    /// Keeps the contacts' small-displacement references (`keep`) or drops them, freeing
    /// their memory. Kept afresh, every contact gets a dead one ([`SmallReference::DEAD`]),
    /// to be written over: in small-displacement mode every detection detects every contact
    /// afresh.
    pub(crate) fn keep_small_refs(&mut self, keep: bool) {
        if keep && !self.small_kept {
            self.small_refs.clear();
            self.small_refs.resize(self.pairs.len(), SmallReference::DEAD);
        } else if !keep && self.small_kept {
            self.small_refs = Vec::new();
        }
        self.small_kept = keep;
    }

    /// The dashpot force of sub-contact `i` (zero when none are kept); read by checkpoints.
    #[cfg(feature = "serde")]
    pub(crate) fn dashpot(&self, i: usize) -> Vector {
        self.sub_dashpots.get(i).copied().unwrap_or(Vector::ZERO)
    }

    /// The lists as detection rearranges them.
    pub(crate) fn lists(&mut self) -> ContactLists<'_, S> {
        ContactLists {
            pairs: &mut self.pairs,
            references: &mut self.references,
            wrenches: &mut self.wrenches,
            small_refs: &mut self.small_refs,
            small_kept: self.small_kept,
            subs: &mut self.subs,
            dashpots: &mut self.sub_dashpots,
            dashpots_kept: self.dashpots_kept,
        }
    }

    /// The contact pass's view: the contacts from the first as it writes them, with one of
    /// `sums` per chunk of contacts.
    pub(crate) fn pass_view<'a, T>(&'a mut self, sums: &'a mut [T]) -> ContactSlices<'a, S, T> {
        let first_sub = self.pairs.first().map_or(0, |p| p.first as usize);
        ContactSlices {
            pairs: &mut self.pairs,
            references: &mut self.references,
            wrenches: &mut self.wrenches,
            small_refs: if self.small_kept { &mut self.small_refs } else { &mut [] },
            sums,
            subs: &mut self.subs[first_sub..],
            dashpots: if self.dashpots_kept {
                &mut self.sub_dashpots[first_sub..]
            } else {
                &mut []
            },
        }
    }

    /// Whether the lists that run index for index do (kept so by detection and checkpoint
    /// load; the step asserts it).
    pub(crate) fn in_step(&self) -> bool {
        self.sub_dashpots.len() == if self.dashpots_kept { self.subs.len() } else { 0 }
            && self.wrenches.len() == self.pairs.len()
            && self.references.len() == self.pairs.len()
            && self.small_refs.len() == if self.small_kept { self.pairs.len() } else { 0 }
    }
}

/// The contacts detection replaces, read-only.
pub(crate) struct OldContacts<'a, S> {
    pub(crate) pairs: &'a [ContactPair],
    pub(crate) references: &'a [ContactReference],
    /// Empty when the contacts keep no small-displacement references.
    pub(crate) small_refs: &'a [SmallReference],
    pub(crate) subs: &'a [SubContact<S>],
    /// Empty when the model keeps no dashpot forces.
    pub(crate) dashpots: &'a [Vector],
}

impl<S> OldContacts<'_, S> {
    /// The dashpot force of sub-contact `i` (zero when none are kept).
    pub(crate) fn dashpot(&self, i: usize) -> Vector {
        self.dashpots.get(i).copied().unwrap_or(Vector::ZERO)
    }
}

/// Contact lists as detection writes them: the staging lists, or the model's as they are
/// rearranged.
pub(crate) struct ContactLists<'a, S> {
    pub(crate) pairs: &'a mut Vec<ContactPair>,
    pub(crate) references: &'a mut Vec<ContactReference>,
    pub(crate) wrenches: &'a mut Vec<ContactWrench>,
    /// Index for index with `pairs` when `small_kept`, empty otherwise.
    pub(crate) small_refs: &'a mut Vec<SmallReference>,
    pub(crate) small_kept: bool,
    pub(crate) subs: &'a mut Vec<SubContact<S>>,
    /// Index for index with `subs` when `dashpots_kept`, empty otherwise.
    pub(crate) dashpots: &'a mut Vec<Vector>,
    pub(crate) dashpots_kept: bool,
}

impl<S> ContactLists<'_, S> {
    /// Empties every list.
    pub(crate) fn clear(&mut self) {
        self.pairs.clear();
        self.references.clear();
        self.wrenches.clear();
        self.small_refs.clear();
        self.subs.clear();
        self.dashpots.clear();
    }
}

/// What the contact pass writes: the contacts, their wrenches and per-chunk sums `T`, and the
/// sub-contacts, all starting at the same contact.
pub(crate) struct ContactSlices<'a, S, T> {
    pub pairs: &'a mut [ContactPair],
    /// The contacts' references, index for index with `pairs` (the step writes a hinge's).
    pub references: &'a mut [ContactReference],
    pub wrenches: &'a mut [ContactWrench],
    /// The contacts' small-displacement references, or empty when the contacts keep none.
    pub small_refs: &'a mut [SmallReference],
    /// One per chunk of contacts.
    pub sums: &'a mut [T],
    /// The sub-contacts of `pairs`, from the first contact's first one.
    pub subs: &'a mut [SubContact<S>],
    /// The sub-contacts' dashpot forces, or empty when the model keeps none.
    pub dashpots: &'a mut [Vector],
}

impl<S, T> ContactSlices<'_, S, T> {
    /// Splits after `chunks` chunks of `chunk` contacts (at least one contact must follow).
    pub(crate) fn split(self, chunks: usize, chunk: usize) -> (Self, Self) {
        let at = chunks * chunk;
        let base = self.pairs[0].first as usize;
        let sub_at = self.pairs[at].first as usize - base;
        let (pairs, pairs_right) = self.pairs.split_at_mut(at);
        let (references, references_right) = self.references.split_at_mut(at);
        let (wrenches, wrenches_right) = self.wrenches.split_at_mut(at);
        let (small_refs, small_refs_right) = if self.small_refs.is_empty() {
            (self.small_refs, &mut [][..])
        } else {
            self.small_refs.split_at_mut(at)
        };
        let (sums, sums_right) = self.sums.split_at_mut(chunks);
        let (subs, subs_right) = self.subs.split_at_mut(sub_at);
        let (dashpots, dashpots_right) = if self.dashpots.is_empty() {
            (self.dashpots, &mut [][..])
        } else {
            self.dashpots.split_at_mut(sub_at)
        };
        (
            Self {
                pairs,
                references,
                wrenches,
                small_refs,
                sums,
                subs,
                dashpots,
            },
            Self {
                pairs: pairs_right,
                references: references_right,
                wrenches: wrenches_right,
                small_refs: small_refs_right,
                sums: sums_right,
                subs: subs_right,
                dashpots: dashpots_right,
            },
        )
    }
}
