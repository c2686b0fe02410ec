//! [`CompressionCap`]: the elliptical compression cap of a [`super::MortarJoint`] (Lourenço–Rots'
//! third surface), its hardening and softening curve, the work along it, and its return. The
//! equations are in `docs/theory.md`, §4.2 ("Compression cap").

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

use super::bracketed_root;
use crate::error::{non_negative, positive, Result};
use crate::math::Real;

/// Lourenço's shear factor `C_ss` (his calibration on masonry under shear and compression).
pub const LOURENCO_SHEAR_FACTOR: Real = 9.0;

/// The compressive strength a [`super::MortarJoint`] crushes at: an elliptical cap
/// `σ² + C_ss τ² ≤ σ_c(κ_c)²` on the joint's normal stress `σ` (compression positive) and shear
/// stress `τ`, with associated flow, which hardens and softens with the joint's plastic closure
/// `κ_c` ([`super::MortarState::crushing`]) along Lourenço's curve (`docs/theory.md` §4.2):
///
/// * with `peak_closure` `κ_p > 0`: from `f_m/3` up to `f_m` at `κ_p`,
///   `σ_c = f_m (1/3 + (2/3) √(2κ/κ_p − κ²/κ_p²))`; with `κ_p = 0` (the default) the cap starts
///   at `f_m`;
/// * then a parabola down to `f_m/2` over `Δκ`, `σ_c = f_m (1 − h²/2)`, `h = (κ − κ_p)/Δκ`;
/// * then an exponential towards the residual `f_m/7`, with the parabola's slope where they
///   meet: `σ_c = f_m (1/7 + (5/14) e^{−(14/5)(κ − κ_p − Δκ)/Δκ})`.
///
/// `Δκ` follows from the fracture energy `G_c`, taken as the energy per unit area the cap
/// dissipates from its peak on over its residual strength, `∫_{κ_p}^∞ (σ_c − f_m/7) dκ =
/// (481/588) f_m Δκ`: so the energy a crushed joint dissipates is a material property per unit
/// area, whatever the number of sub-contacts. `G_c = 0` drops to the residual at once.
///
/// ```
/// use voussoir::law::CompressionCap;
/// // Lourenço's J4D walls: f_m 10.5 MPa, G_c 5 N/mm, κ_p 0.09 mm.
/// let cap = CompressionCap::new(10.5e6, 5000.0).with_peak_closure(0.09e-3);
/// assert!((cap.strength_at(0.0) - 3.5e6).abs() < 1e-6);
/// assert!((cap.strength_at(0.09e-3) - 10.5e6).abs() < 1e-6);
/// assert!((cap.strength_at(1.0) - 1.5e6).abs() < 1e-6);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct CompressionCap {
    /// Compressive strength `f_m` (Pa): the cap's peak.
    pub strength: Real,
    /// Compressive fracture energy `G_c` (J/m²): what a unit area of joint dissipates from the
    /// peak on, over the residual strength `f_m/7`.
    pub fracture_energy: Real,
    /// `C_ss`: how much shear lowers the strength (`σ² + C_ss τ² ≤ σ_c²`);
    /// [`LOURENCO_SHEAR_FACTOR`] by default, 0 for a cap on the normal stress alone.
    #[cfg_attr(feature = "serde", serde(default = "lourenco_shear_factor"))]
    pub shear_factor: Real,
    /// `κ_p` (m): the plastic closure at the peak; 0 (the default) for a cap that starts at
    /// `f_m`, else it starts at `f_m/3` and hardens.
    #[cfg_attr(feature = "serde", serde(default))]
    pub peak_closure: Real,
}

#[cfg(feature = "serde")]
fn lourenco_shear_factor() -> Real {
    LOURENCO_SHEAR_FACTOR
}

/// `∫_{κ_p}^∞ (σ_c − σ_r) dκ = FRACTION f_m Δκ`: the parabola's 5/6 less the residual's 1/7,
/// and the exponential's (5/14)(5/14).
const ENERGY_FRACTION: Real = 481.0 / 588.0;
/// The exponential's rate, in units of `1/Δκ`: the parabola's slope where they meet,
/// `−f_m/Δκ`, over the exponential's height above the residual, `(5/14) f_m`.
const EXPONENTIAL_RATE: Real = 14.0 / 5.0;

impl CompressionCap {
    /// A cap with strength `f_m` (Pa) and fracture energy `G_c` (J/m²), Lourenço's shear factor
    /// and no hardening.
    pub fn new(strength: Real, fracture_energy: Real) -> Self {
        Self {
            strength,
            fracture_energy,
            shear_factor: LOURENCO_SHEAR_FACTOR,
            peak_closure: 0.0,
        }
    }

    /// The same cap with shear factor `C_ss`.
    #[must_use]
    pub fn with_shear_factor(mut self, shear_factor: Real) -> Self {
        self.shear_factor = shear_factor;
        self
    }

    /// The same cap with hardening from `f_m/3` to `f_m` over the plastic closure `κ_p` (m).
    #[must_use]
    pub fn with_peak_closure(mut self, peak_closure: Real) -> Self {
        self.peak_closure = peak_closure;
        self
    }

    /// The residual strength `f_m/7` (Pa).
    pub fn residual(&self) -> Real {
        self.strength / 7.0
    }

    /// `Δκ` (m): the length of the parabolic softening, `(588/481) G_c / f_m`.
    pub fn softening_length(&self) -> Real {
        self.fracture_energy / (ENERGY_FRACTION * self.strength)
    }

    /// The cap's strength `σ_c(κ_c)` (Pa) at plastic closure `κ_c ≥ 0` (m).
    #[inline(never)]
    pub fn strength_at(&self, kappa: Real) -> Real {
        let (fm, kp) = (self.strength, self.peak_closure);
        if kappa < kp {
            let t = kappa / kp;
            return fm * (1.0 / 3.0 + (2.0 / 3.0) * (t * (2.0 - t)).sqrt());
        }
        let (x, dk) = (kappa - kp, self.softening_length());
        if dk == 0.0 {
            return if x == 0.0 { fm } else { fm / 7.0 };
        }
        if x < dk {
            let h = x / dk;
            fm * (1.0 - 0.5 * h * h)
        } else {
            fm * (1.0 / 7.0 + (5.0 / 14.0) * (-EXPONENTIAL_RATE * (x - dk) / dk).exp())
        }
    }

    /// `∫₀^κ σ_c` (J/m²): the work of crushing per unit area to plastic closure `κ ≥ 0`.
    pub fn work_to(&self, kappa: Real) -> Real {
        let (fm, kp) = (self.strength, self.peak_closure);
        // ∫₀^t √(2u − u²) du = ½ [(t − 1)√(t(2 − t)) + asin(t − 1) + π/2].
        let circle =
            |t: Real| 0.5 * ((t - 1.0) * (t * (2.0 - t)).sqrt() + (t - 1.0).asin() + std::f64::consts::FRAC_PI_2);
        if kappa < kp {
            let t = kappa / kp;
            return fm * kp * (t / 3.0 + (2.0 / 3.0) * circle(t));
        }
        let hardening = fm * kp * (1.0 / 3.0 + std::f64::consts::PI / 6.0);
        let (x, dk) = (kappa - kp, self.softening_length());
        if dk == 0.0 {
            return hardening + fm / 7.0 * x;
        }
        if x < dk {
            let h = x / dk;
            return hardening + fm * dk * (h - h * h * h / 6.0);
        }
        let y = x - dk;
        hardening + fm * dk * (5.0 / 6.0) + fm * (y / 7.0 - (25.0 / 196.0) * dk * (-EXPONENTIAL_RATE * y / dk).exp_m1())
    }

    /// Whether the stresses `σ` (compression positive) and `τ` (magnitude) lie beyond the cap
    /// at plastic closure `κ`.
    #[inline]
    pub(super) fn exceeded(&self, sigma: Real, tau: Real, kappa: Real) -> bool {
        if sigma <= 0.0 {
            return false;
        }
        let sc = self.strength_at(kappa);
        sigma * sigma + self.shear_factor * tau * tau > sc * sc
    }

    /// The cap's return from the trial stresses `σ_t > 0`, `τ_t ≥ 0` at plastic closure `κ₀`,
    /// on the elastic stiffnesses `k_n`, `k_s` with associated flow: the plastic multiplier `λ`
    /// at which `σ = σ_t/(1 + 2k_nλ)`, `τ = τ_t/(1 + 2k_sC_ssλ)` meet the cap at
    /// `κ = κ₀ + (σ_t − σ)/k_n`. Returns `(κ, τ)`.
    pub(super) fn ret(&self, kn: Real, ks: Real, sigma_t: Real, tau_t: Real, kappa0: Real) -> (Real, Real) {
        let css = self.shear_factor;
        let sigma = |l: Real| sigma_t / (1.0 + 2.0 * kn * l);
        let tau = |l: Real| tau_t / (1.0 + 2.0 * ks * css * l);
        let kappa = |l: Real| kappa0 + (sigma_t - sigma(l)) / kn;
        let excess = |l: Real| {
            let (s, t, sc) = (sigma(l), tau(l), self.strength_at(kappa(l)));
            s * s + css * t * t - sc * sc
        };
        // Beyond `hi` both stresses are below half the residual strength, which the cap never
        // falls under: `excess(hi) < 0`.
        let half = 0.5 * self.residual();
        let mut hi = (sigma_t / half - 1.0) / (2.0 * kn);
        if css > 0.0 && tau_t > 0.0 {
            hi = hi.max((css.sqrt() * tau_t / half - 1.0) / (2.0 * ks * css));
        }
        let l = bracketed_root(0.0, hi.max(0.0), excess);
        (kappa(l), tau(l))
    }

    /// Checks the cap's parameters.
    pub(super) fn validate(&self) -> Result<()> {
        positive("cap_strength", self.strength)?;
        non_negative("cap_fracture_energy", self.fracture_energy)?;
        non_negative("cap_shear_factor", self.shear_factor)?;
        non_negative("cap_peak_closure", self.peak_closure)?;
        Ok(())
    }
}
