//! Damping models.

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

use crate::error::{in_range, non_negative, positive, Result};
use crate::math::Real;

/// Damping of the equations of motion.
///
/// * `Local`: Cundall's local damping, `F_i ← F_i − α·|F_i|·sgn(v_i)` per degree of freedom; for
///   quasi-static runs (3DEC's default `α = 0.8`).
/// * `Rayleigh`: `C = a·M + b·K`; the mass part is a viscous body force `−a·m·v`, `−a·I·ω`; the
///   stiffness part is a dashpot `b·kn·A·u̇_n` (and `b·ks·A·u̇_s` while not sliding) at every
///   sub-contact in contact.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub enum Damping {
    /// No damping.
    None,
    /// Cundall local damping with coefficient `alpha` in `[0, 1)`.
    Local {
        /// Damping coefficient α (dimensionless).
        alpha: Real,
    },
    /// Rayleigh damping `C = a·M + b·K`.
    Rayleigh {
        /// Mass-proportional coefficient `a` (1/s).
        mass: Real,
        /// Stiffness-proportional coefficient `b` (s).
        stiffness: Real,
    },
}

impl Default for Damping {
    fn default() -> Self {
        Damping::Local { alpha: 0.8 }
    }
}

impl Damping {
    /// Local damping with 3DEC's default coefficient 0.8.
    pub fn local() -> Self {
        Self::default()
    }

    /// Stiffness-proportional Rayleigh damping giving the ratio `ratio` at `frequency` (Hz):
    /// `b = ξ/(π f)`.
    ///
    /// ```
    /// use voussoir::integrate::Damping;
    /// // The paper: 1 % at 25 Hz.
    /// let d = Damping::rayleigh_stiffness(0.01, 25.0)?;
    /// assert!(matches!(d, Damping::Rayleigh { mass, stiffness } if mass == 0.0 && (stiffness - 1.2732e-4).abs() < 1e-8));
    /// # Ok::<(), voussoir::Error>(())
    /// ```
    ///
    /// # Errors
    /// [`crate::Error::InvalidParameter`] for a negative ratio or non-positive frequency.
    pub fn rayleigh_stiffness(ratio: Real, frequency: Real) -> Result<Self> {
        non_negative("damping ratio", ratio)?;
        positive("damping frequency", frequency)?;
        Ok(Damping::Rayleigh {
            mass: 0.0,
            stiffness: ratio / (std::f64::consts::PI * frequency),
        })
    }

    /// Mass-proportional Rayleigh damping giving `ratio` at `frequency` (Hz): `a = 4π f ξ`.
    ///
    /// # Errors
    /// As [`Damping::rayleigh_stiffness`].
    pub fn rayleigh_mass(ratio: Real, frequency: Real) -> Result<Self> {
        non_negative("damping ratio", ratio)?;
        positive("damping frequency", frequency)?;
        Ok(Damping::Rayleigh {
            mass: 4.0 * std::f64::consts::PI * frequency * ratio,
            stiffness: 0.0,
        })
    }

    /// Mass and stiffness parts that each give half of `ratio` at `frequency`, so the total is
    /// `ratio` there (the minimum of the Rayleigh curve): `a = ξ·ω`, `b = ξ/ω`.
    ///
    /// # Errors
    /// As [`Damping::rayleigh_stiffness`].
    pub fn rayleigh(ratio: Real, frequency: Real) -> Result<Self> {
        non_negative("damping ratio", ratio)?;
        positive("damping frequency", frequency)?;
        let w = 2.0 * std::f64::consts::PI * frequency;
        Ok(Damping::Rayleigh {
            mass: ratio * w,
            stiffness: ratio / w,
        })
    }

    /// The stiffness-proportional coefficient `b` (s), zero for other models.
    pub fn stiffness_coefficient(&self) -> Real {
        match self {
            Damping::Rayleigh { stiffness, .. } => *stiffness,
            _ => 0.0,
        }
    }

    /// Checks the coefficients.
    ///
    /// # Errors
    /// [`crate::Error::InvalidParameter`] naming the bad coefficient.
    pub fn validate(&self) -> Result<()> {
        match *self {
            Damping::None => Ok(()),
            Damping::Local { alpha } => in_range("damping.alpha", alpha, 0.0, 1.0, "must lie in [0, 1)").map(|_| ()),
            Damping::Rayleigh { mass, stiffness } => {
                non_negative("damping.mass", mass)?;
                non_negative("damping.stiffness", stiffness)?;
                Ok(())
            }
        }
    }
}
