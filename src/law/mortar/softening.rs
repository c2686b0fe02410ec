//! How a [`super::MortarJoint`]'s strengths fall with its softening parameter: the curve
//! `r(D)`, its integral and where it ends.

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

use crate::math::Real;

/// How the strengths of a [`super::MortarJoint`] fall with its softening parameter `D` (see there):
/// the fraction left, `r(D)`, whose integral over `D ≥ 0` is 1 for both shapes, so that a
/// crack dissipates its fracture energy whichever is chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub enum Softening {
    /// `r = e^{−D}` (the default; Lourenço–Rots'), cut to zero where it falls below the
    /// machine epsilon (`D = 52 ln 2 ≈ 36.04`): the fracture energy left beyond is below
    /// `2.2e-16` of the whole.
    #[default]
    Exponential,
    /// `r = max(0, 1 − D/2)`: the strengths reach zero at `D = 2`, when the crack has opened
    /// (or slipped) by `2 G_f / f` (`f` the tensile strength or the cohesion).
    Linear,
}

/// Where [`Softening::Exponential`] is cut: `−ln ε`, so that `e^{−D}` below it is at least
/// the machine epsilon.
pub(super) const EXPONENTIAL_END: Real = 52.0 * std::f64::consts::LN_2;

impl Softening {
    /// The fraction of the strengths left, `r(D)`, for `D ≥ 0`; exactly 1 at `D = 0` and
    /// exactly 0 from the end of the curve on (`52 ln 2`, or 2).
    #[inline]
    pub(super) fn remaining(self, d: Real) -> Real {
        // The intact joint (most sub-contacts) without the exponential: `e^{−0} = 1` exactly.
        if d == 0.0 {
            return 1.0;
        }
        match self {
            Softening::Exponential if d < EXPONENTIAL_END => (-d).exp(),
            Softening::Linear if d < 2.0 => 1.0 - 0.5 * d,
            _ => 0.0,
        }
    }

    /// Where the curve ends: `r(D) = 0` exactly from here on.
    #[inline]
    pub(super) fn end(self) -> Real {
        match self {
            Softening::Exponential => EXPONENTIAL_END,
            Softening::Linear => 2.0,
        }
    }

    /// `∫ r(D) dD` from `d0` to `d0 + dd` (`d0 ≥ 0`, `dd ≥ 0`), without cancellation for a
    /// small `dd`.
    #[inline]
    pub(super) fn integral(self, d0: Real, dd: Real) -> Real {
        match self {
            Softening::Exponential => {
                let (a, b) = (d0.min(EXPONENTIAL_END), (d0 + dd).min(EXPONENTIAL_END));
                // e^{−a} − e^{−b} = e^{−a} (1 − e^{−(b − a)}).
                -(-a).exp() * (a - b).exp_m1()
            }
            Softening::Linear => {
                let (a, b) = (d0.min(2.0), (d0 + dd).min(2.0));
                (b - a) * (1.0 - 0.25 * (a + b))
            }
        }
    }
}
