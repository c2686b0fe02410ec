//! The joint laws of a model: per pair of block materials, and per pair of blocks (an
//! interface) where one joint differs from its materials' (as 3DEC's and `compas_3dec`'s
//! per-interface properties).

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

use super::{check_law, ConstitutiveLaw, MaterialId};
use crate::error::{Error, Result};
use crate::ids::BlockId;
use crate::math::Real;

/// The joint law of each pair of block materials (the pair is unordered), and of single pairs
/// of blocks (interfaces), which take precedence over their materials'.
///
/// ```
/// use voussoir::block::BlockId;
/// use voussoir::law::{CoulombSlip, LawTable, MaterialId};
/// let stone = MaterialId(0);
/// let steel = MaterialId(1);
/// let mut joints = LawTable::new();
/// joints.insert(stone, stone, CoulombSlip::dry(4e9, 1.6e9, 30.5)?)?;
/// joints.insert(stone, steel, CoulombSlip::dry(4e9, 1.6e9, 0.0)?)?;
/// assert!(joints.get(steel, stone).is_some());
/// // One joint of the stones, between blocks 3 and 4, is weaker.
/// joints.insert_interface(BlockId(4), BlockId(3), CoulombSlip::dry(4e9, 1.6e9, 20.0)?)?;
/// let law = |a, b| joints.laws()[joints.index_for((BlockId(a), stone), (BlockId(b), stone)).unwrap() as usize];
/// assert!((law(3, 4).friction_angle().to_degrees() - 20.0).abs() < 1e-12);
/// assert!((law(2, 3).friction_angle().to_degrees() - 30.5).abs() < 1e-12);
/// # Ok::<(), voussoir::Error>(())
/// ```
#[derive(Debug, Clone)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct LawTable<L> {
    laws: Vec<L>,
    /// `((min material, max material), law index)`, sorted.
    index: Vec<((MaterialId, MaterialId), u32)>,
    /// `((min block, max block), law index)`, sorted: the interfaces' own laws.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Vec::is_empty"))]
    interfaces: Vec<((BlockId, BlockId), u32)>,
}

impl<L> Default for LawTable<L> {
    fn default() -> Self {
        Self {
            laws: Vec::new(),
            index: Vec::new(),
            interfaces: Vec::new(),
        }
    }
}

impl<L: ConstitutiveLaw> LawTable<L> {
    /// An empty table.
    pub fn new() -> Self {
        Self::default()
    }

    /// Sets the law between materials `a` and `b` (either order), replacing any previous one.
    ///
    /// # Errors
    /// The law's own [`ConstitutiveLaw::validate`] error; [`crate::Error::InvalidParameter`]
    /// for a stiffness that is negative or not finite (the critical step rests on it).
    pub fn insert(&mut self, a: MaterialId, b: MaterialId, law: L) -> Result<()> {
        check_law(&law)?;
        let key = (a.min(b), a.max(b));
        match self.index.binary_search_by_key(&key, |e| e.0) {
            Ok(k) => self.laws[self.index[k].1 as usize] = law,
            Err(k) => {
                self.index.insert(k, (key, self.laws.len() as u32));
                self.laws.push(law);
            }
        }
        Ok(())
    }

    /// Sets the law of the interface between blocks `a` and `b` (either order), replacing any
    /// previous one: their joint takes it whatever their materials.
    ///
    /// # Errors
    /// As [`LawTable::insert`]; [`Error::InvalidParameter`] when `a` and `b` are the same block.
    pub fn insert_interface(&mut self, a: BlockId, b: BlockId, law: L) -> Result<()> {
        if a == b {
            return Err(Error::InvalidParameter {
                name: format!("interface law between block {a} and itself"),
                value: Real::from(a.0),
                expected: "an interface joins two different blocks",
            });
        }
        check_law(&law)?;
        let key = (a.min(b), a.max(b));
        match self.interfaces.binary_search_by_key(&key, |e| e.0) {
            Ok(k) => self.laws[self.interfaces[k].1 as usize] = law,
            Err(k) => {
                self.interfaces.insert(k, (key, self.laws.len() as u32));
                self.laws.push(law);
            }
        }
        Ok(())
    }

    /// The law between `a` and `b`.
    pub fn get(&self, a: MaterialId, b: MaterialId) -> Option<&L> {
        self.index_of(a, b).map(|i| &self.laws[i as usize])
    }

    /// The law of the interface between blocks `a` and `b`, if it has its own.
    pub fn get_interface(&self, a: BlockId, b: BlockId) -> Option<&L> {
        let key = (a.min(b), a.max(b));
        self.interfaces
            .binary_search_by_key(&key, |e| e.0)
            .ok()
            .map(|k| &self.laws[self.interfaces[k].1 as usize])
    }

    pub(crate) fn index_of(&self, a: MaterialId, b: MaterialId) -> Option<u32> {
        let key = (a.min(b), a.max(b));
        self.index
            .binary_search_by_key(&key, |e| e.0)
            .ok()
            .map(|k| self.index[k].1)
    }

    /// The index in [`LawTable::laws`] of the law of the joint between two blocks, given as
    /// `(block, its material)`: the interface's own law if it has one, else its materials'.
    pub fn index_for(&self, a: (BlockId, MaterialId), b: (BlockId, MaterialId)) -> Option<u32> {
        if !self.interfaces.is_empty() {
            let key = (a.0.min(b.0), a.0.max(b.0));
            if let Ok(k) = self.interfaces.binary_search_by_key(&key, |e| e.0) {
                return Some(self.interfaces[k].1);
            }
        }
        self.index_of(a.1, b.1)
    }

    /// The `(material, material, law)` entries, sorted by material pair.
    pub fn entries(&self) -> impl Iterator<Item = (MaterialId, MaterialId, &L)> + '_ {
        self.index.iter().map(|&((a, b), i)| (a, b, &self.laws[i as usize]))
    }

    /// The `(block, block, law)` entries of the interfaces with their own law, sorted by pair.
    pub fn interface_entries(&self) -> impl Iterator<Item = (BlockId, BlockId, &L)> + '_ {
        self.interfaces
            .iter()
            .map(|&((a, b), i)| (a, b, &self.laws[i as usize]))
    }

    /// Checks the table's internal indices (after deserialisation).
    #[cfg(feature = "serde")]
    pub(crate) fn check(&self) -> bool {
        self.index.iter().all(|e| (e.1 as usize) < self.laws.len())
            && self.index.windows(2).all(|w| w[0].0 < w[1].0)
            && self
                .interfaces
                .iter()
                .all(|e| (e.1 as usize) < self.laws.len() && e.0 .0 < e.0 .1)
            && self.interfaces.windows(2).all(|w| w[0].0 < w[1].0)
    }

    /// All laws, indexed as contacts refer to them.
    pub fn laws(&self) -> &[L] {
        &self.laws
    }
}
