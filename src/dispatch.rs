//! Choice between the portable build of the hot loops and their AVX2 build.
//!
//! The hot loops (the contact pass and the integrator) are compiled twice: as the target allows
//! (SSE2 on x86-64) and with AVX2 enabled, chosen at run time. AVX2 here buys the three-operand
//! VEX encoding, which saves the register copies that two-operand SSE2 needs (about a quarter of
//! the instructions of the sub-contact loop). Fused multiply-add is *not* enabled: it would round
//! differently, and results must not depend on the machine's instruction set. Both builds run
//! the same IEEE operations in the same order and give bit-identical results
//! (`model::tests::avx2_and_portable_builds_are_bit_identical`).
//!
//! Setting the environment variable `VOUSSOIR_PORTABLE` (to anything but `0` or nothing)
//! before the first step runs the portable build everywhere: for tools that do not decode
//! every AVX2 instruction the AVX2 build holds (valgrind 3.19's cachegrind and callgrind
//! stop on a `vmovq` between registers), as `scripts/compare_builds.py --instructions` runs
//! them. The results are the same bits either way; only the speed changes.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::OnceLock;

/// Set by tests to run the portable build on a processor with AVX2.
static PORTABLE_ONLY: AtomicBool = AtomicBool::new(false);

/// The environment variable that asks for the portable build (module documentation).
#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
const PORTABLE_VARIABLE: &str = "VOUSSOIR_PORTABLE";

/// Whether `value`, the environment variable's, asks for the portable build: set, and neither
/// empty nor `0`.
#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
fn asks_for_portable(value: Option<&std::ffi::OsStr>) -> bool {
    value.is_some_and(|v| !v.is_empty() && v != "0")
}

/// Whether the environment asked for the portable build, read once per process.
#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
pub(crate) fn portable_requested() -> bool {
    static REQUESTED: OnceLock<bool> = OnceLock::new();
    *REQUESTED.get_or_init(|| asks_for_portable(std::env::var_os(PORTABLE_VARIABLE).as_deref()))
}

/// Whether to run the AVX2 build: the processor supports it (detection is cached by the
/// standard library), and neither tests nor the environment (`VOUSSOIR_PORTABLE`) asked for
/// the portable one.
#[inline]
pub(crate) fn has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        !PORTABLE_ONLY.load(Ordering::Relaxed) && !portable_requested() && std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Forces the portable build (tests).
#[cfg(test)]
pub(crate) fn set_portable_only(portable: bool) {
    PORTABLE_ONLY.store(portable, Ordering::Relaxed);
}

#[cfg(test)]
mod tests {
    use super::asks_for_portable;
    use std::ffi::OsStr;

    /// `VOUSSOIR_PORTABLE` asks for the portable build when set to anything but nothing or `0`.
    #[test]
    fn the_variable_asks_for_the_portable_build_unless_unset_empty_or_zero() {
        assert!(!asks_for_portable(None));
        assert!(!asks_for_portable(Some(OsStr::new(""))));
        assert!(!asks_for_portable(Some(OsStr::new("0"))));
        assert!(asks_for_portable(Some(OsStr::new("1"))));
        assert!(asks_for_portable(Some(OsStr::new("yes"))));
    }
}
