//! What the user changed between steps: one set, written by the setters and read first by
//! [`Model::step`](crate::model::Model::step), instead of flags each setter has to remember.

/// A set of changes since the last step.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct Changes(u8);

impl Changes {
    /// A block was added.
    pub const BLOCKS: Self = Self(1);
    /// A joint law was set.
    pub const LAWS: Self = Self(1 << 1);
    /// The global parameters were replaced.
    pub const PARAMETERS: Self = Self(1 << 2);
    /// A full detection and step evaluation is owed for another reason: the first step, a
    /// checkpoint saved with one pending, or a step re-evaluation that failed (so that the
    /// error repeats rather than the run going on with an unstable step).
    pub const DETECTION: Self = Self(1 << 4);

    /// Adds `other` to the set.
    pub fn insert(&mut self, other: Self) {
        self.0 |= other.0;
    }

    /// Whether the set holds every change of `other`.
    pub fn contains(self, other: Self) -> bool {
        self.0 & other.0 == other.0
    }

    /// Whether the next step must detect all contacts afresh and re-evaluate its time step,
    /// and whether what the last block pass prepared for it (rotation matrices, movement
    /// check) may be stale: any change does.
    pub fn need_full_detection(self) -> bool {
        self.0 != 0
    }

    /// Empties the set (once the step has acted on it).
    pub fn clear(&mut self) {
        self.0 = 0;
    }
}
