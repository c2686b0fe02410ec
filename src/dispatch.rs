//! Choice between the portable build of the hot loops and their AVX2 build.
//!
//! The hot loops (the contact pass and the integrator) are compiled twice: as the target allows
//! (SSE2 on x86-64) and with AVX2 enabled, chosen at run time. AVX2 here buys the three-operand
//! VEX encoding, which saves the register copies that two-operand SSE2 needs (about a quarter of
//! the instructions of the sub-contact loop). Fused multiply-add is *not* enabled: it would round
//! differently, and results must not depend on the machine's instruction set. Both builds run
//! the same IEEE operations in the same order and give bit-identical results
//! (`model::tests::avx2_and_portable_builds_are_bit_identical`).

use std::sync::atomic::{AtomicBool, Ordering};

/// Set by tests to run the portable build on a processor with AVX2.
static PORTABLE_ONLY: AtomicBool = AtomicBool::new(false);

/// Whether to run the AVX2 build: the processor supports it (detection is cached by the
/// standard library) and tests have not asked for the portable one.
#[inline]
pub(crate) fn has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        !PORTABLE_ONLY.load(Ordering::Relaxed) && std::arch::is_x86_feature_detected!("avx2")
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
