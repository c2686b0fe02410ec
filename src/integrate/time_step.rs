//! Critical time step of central difference for a block system on contact springs.

use serde::{Deserialize, Serialize};

use crate::block::BlockId;
use crate::math::Real;

/// How the model chooses its time step.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum TimeStep {
    /// `safety × critical step`, re-evaluated whenever contacts are re-detected.
    Auto {
        /// Fraction of the critical step, in `(0, 1]`. Default 0.9.
        safety: Real,
    },
    /// A fixed step (s); an error if it exceeds the critical step.
    Fixed(Real),
}

impl Default for TimeStep {
    fn default() -> Self {
        TimeStep::Auto { safety: 0.9 }
    }
}

/// Upper bound of a block's squared natural frequency (rad²/s²), assembled from its contacts.
///
/// For a spring of stiffness `k` at lever arm `r` from the centroid, the compliance of a rigid
/// block in any direction is at most `c = 1/m + |r|²/I_min`. Summing `k·(c_self + c_other)` over
/// all springs acting on a block bounds the largest eigenvalue of `M⁻¹K` (a trace / Gershgorin
/// bound), so the estimate is safe with several contacts. Fixed or driven blocks have `c = 0`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StiffnessBound {
    /// Sum of `k·(c_self + c_other)` (1/s²).
    pub omega_squared: Real,
}

/// The critical step and the block that sets it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CriticalStep {
    /// Critical time step with the damping correction (s).
    pub dt: Real,
    /// Highest natural frequency bound (rad/s).
    pub omega_max: Real,
    /// The block with the highest frequency.
    pub block: BlockId,
}

/// `Δt_crit = (2/ω_max)·(√(1+ξ²) − ξ)` with `ξ = b·ω_max/2` for stiffness-proportional damping
/// coefficient `b` (s). Returns `None` when no block has any stiffness.
///
/// ```
/// use voussoir::integrate::{critical_time_step, StiffnessBound};
/// let bounds = [StiffnessBound { omega_squared: 1e6 }, StiffnessBound { omega_squared: 4e6 }];
/// let c = critical_time_step(&bounds, 0.0).unwrap();
/// assert_eq!(c.block.0, 1);
/// assert!((c.dt - 1e-3).abs() < 1e-15); // 2 / 2000 rad/s
/// ```
pub fn critical_time_step(bounds: &[StiffnessBound], stiffness_damping: Real) -> Option<CriticalStep> {
    let (index, w2) = bounds
        .iter()
        .enumerate()
        .map(|(i, b)| (i, b.omega_squared))
        .fold((0, 0.0), |acc, x| if x.1 > acc.1 { x } else { acc });
    if w2 <= 0.0 {
        return None;
    }
    let w = w2.sqrt();
    let xi = 0.5 * stiffness_damping * w;
    Some(CriticalStep {
        dt: 2.0 / w * ((1.0 + xi * xi).sqrt() - xi),
        omega_max: w,
        block: BlockId(index as u32),
    })
}
