//! Generators of block assemblies used by examples, tests and users.

pub mod arch;
mod vault;
mod wall;

pub use vault::{barrel_vault, dome, BarrelVaultSpec, DomeSpec};
pub use wall::{
    benchmark_wall, benchmark_wall_with_spacing, multi_leaf_wall, running_bond_wall, MultiLeafSpec, WallSpec,
    BENCHMARK_SPACING,
};
