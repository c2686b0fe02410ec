//! Generators of block assemblies used by examples, tests and users.

pub mod arch;
mod rubble;
mod vault;
mod wall;

pub use rubble::{rubble_wall, RubbleWallSpec, MAX_RUBBLE_STONES};
pub use vault::{barrel_vault, dome, BarrelVaultSpec, DomeSpec};
pub use wall::{multi_leaf_wall, running_bond_wall, MultiLeafSpec, WallSpec};
