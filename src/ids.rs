//! Typed ids: the leaf every other module names blocks, materials, joints and monitors by.
//!
//! Kept apart from the modules that own the things they name, so that errors, generators and
//! outputs can name them without depending on those modules (as rapier keeps its handles).

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

/// Typed index of a block in a [`crate::Model`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct BlockId(pub u32);

impl std::fmt::Display for BlockId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "#{}", self.0)
    }
}

impl From<BlockId> for usize {
    /// The index into the model's block list, as [`BlockId::index`].
    fn from(id: BlockId) -> usize {
        id.index()
    }
}

impl BlockId {
    /// The index into the model's block list.
    #[inline]
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// Material of a block; joint laws are chosen per pair of materials.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct MaterialId(pub u16);

impl std::fmt::Display for MaterialId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "material {}", self.0)
    }
}

/// Typed index of a contact in the model's current contact list (valid until the next
/// re-detection).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct ContactId(pub u32);

/// Typed index of a monitor (its column in the [`crate::monitor::History`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct MonitorId(pub u32);
