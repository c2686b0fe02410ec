//! Generators of block assemblies used by examples, tests and users.

use crate::error::{Error, Result};

pub mod arch;
mod rubble;
mod vault;
mod wall;

pub use rubble::{rubble_wall, RubbleWallSpec, MAX_RUBBLE_STONES};
pub use vault::{barrel_vault, dome, BarrelVaultSpec, DomeSpec};
pub use wall::{multi_leaf_wall, running_bond_wall, MultiLeafSpec, WallSpec};

/// The most blocks a generator builds (ten million: about 4 GB of blocks and more in
/// contacts, beyond what a step of this library handles on one machine). A larger count is
/// [`Error::TooLarge`] before anything is allocated, instead of the allocation aborting the
/// process.
pub const MAX_GENERATED_BLOCKS: u64 = 10_000_000;

/// [`Error::TooLarge`] when `count` (a product of factors, computed without overflow) passes
/// [`MAX_GENERATED_BLOCKS`].
pub(crate) fn check_block_count(what: &str, factors: &[u128]) -> Result<()> {
    let count = factors
        .iter()
        .try_fold(1u128, |a, &f| a.checked_mul(f))
        .unwrap_or(u128::MAX);
    if count > u128::from(MAX_GENERATED_BLOCKS) {
        return Err(Error::TooLarge {
            what: what.to_owned(),
            requested: count,
            limit: MAX_GENERATED_BLOCKS,
        });
    }
    Ok(())
}
