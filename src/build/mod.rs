//! Generators of block assemblies used by examples, tests and users.

pub mod arch;
mod wall;

pub use wall::{running_bond_wall, WallSpec};
