//! [`MortarJoint`]: a mortared joint that cracks in tension and shear and softens by its
//! fracture energies, per unit area (Lourenço–Rots' composite interface). The equations, the
//! return mapping and the energy argument are in `docs/theory.md`, §4.2; the serialised form is
//! `spec.rs`, the tests against closed forms `tests.rs`.

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

mod cap;
mod softening;
mod spec;

pub use cap::{CompressionCap, LOURENCO_SHEAR_FACTOR};
pub use softening::Softening;
#[cfg(test)]
use softening::EXPONENTIAL_END;

use super::{ConstitutiveLaw, ElasticRegime, JointForce, JointStatus, JointStep, JointStiffness};
use crate::error::{in_range, non_negative, positive, Error, Result};
use crate::math::{Real, Vector2};

/// A mortared masonry joint that cracks and softens by its fracture energies: tension cut-off,
/// Coulomb friction with cohesion, both softening with the crack's opening and slip so that a
/// crack dissipates the fracture energy `G_f^I` (opening) or `G_f^II` (slip at zero normal
/// stress) per unit area, whatever the number of sub-contacts (Lourenço–Rots' composite
/// interface, regularised per unit area).
///
/// Per sub-contact, in stresses (force = stress × the sub-contact's area), with `κ_t` the
/// crack's plastic opening and `κ_s` its plastic slip ([`MortarState`]):
///
/// * softening parameter `D = f_t0 κ_t / G_f^I + c₀ κ_s / G_f^II` and the fraction of the
///   strengths left `r(D)` ([`Softening`]: `e^{−D}` or `max(0, 1 − D/2)`);
///   tensile strength `f_t = f_t0 r`, cohesion `c = c₀ r`, friction
///   `tan φ = r tan φ₀ + (1 − r) tan φ_r` (friction goes from `φ₀` to `φ_r` as the cohesion
///   goes). Opening erodes the cohesion and slip the tensile strength: `f_t/f_t0 = c/c₀`
///   always, which is Lourenço–Rots' coupling `f_t = f_t0 exp(−f_t0 (κ_t + α κ_s)/G_f^I)`,
///   `α = G_f^I c₀ / (G_f^II f_t0)`;
/// * normal stress (compression positive), with the dilatant opening `u_d` and `e = u_n − u_d`:
///   `σ = −k_n e` for `e ≤ 0` (a closed crack carries compression), `σ = −k_n max(e − κ_t, 0)`
///   for `e > 0` (tension unloads and reloads on `k_n` to the crack's opening `κ_t`; between
///   the crack is open and carries nothing);
/// * shear (incremental): `τ ← τ − k_s Δu_s`;
/// * strength: `−σ ≤ f_t` and `|τ| ≤ max(c + σ tan φ, 0)`; beyond, the return mapping finds
///   the plastic opening and slip of the step with the strengths at the *end* of the step
///   (implicit in `D`), on the elastic stiffnesses;
/// * dilatancy (optional, 0 by default): slipping opens the joint at `tan ψ = tan ψ₀ r_s`,
///   `r_s = r(c₀ κ_s / G_f^II)` (it decays as the slip grinds the joint smooth), so
///   `u_d = tan ψ₀ (G_f^II / c₀) ∫₀^{c₀κ_s/G_f^II} r`.
///
/// A fracture energy of zero is brittle: the strengths drop at once, as [`super::CoulombSlip`]'s
/// do (with both zero, for a joint with a cohesion of at least `f_t0 tan φ₀`, the law gives
/// `CoulombSlip`'s forces, failures and dissipation bit for bit, the step that fails in shear
/// carrying the peak strength as there).
///
/// Compression is not capped unless a [`CompressionCap`] is given
/// ([`MortarJointBuilder::compression_cap`]): then the joint crushes on Lourenço–Rots' elliptical
/// cap `σ² + C_ss τ² ≤ σ_c(κ_c)²`, hardening and softening with its plastic closure `κ_c`
/// ([`MortarState::crushing`]) by the compressive fracture energy `G_c`. Without a cap, where a
/// joint's compressive stress passes the masonry's strength can be read from the sub-contacts'
/// stresses ([`crate::contact::SubContactView::normal_stress`]).
///
/// The fracture energy a step consumes is reported by [`ConstitutiveLaw::fracture_work`] and
/// booked in [`crate::model::Energies::fracture`].
///
/// ```
/// use voussoir::law::{ConstitutiveLaw, JointAxes, JointForce, JointStep, MortarJoint, MortarState};
/// use voussoir::math::{Vector, Vector2};
///
/// // f_t = 0.2 MPa, G_f^I = 10 N/m; c = 0.3 MPa, G_f^II = 50 N/m; φ 35° to 30°.
/// let law = MortarJoint::builder(1e11, 4e10, 35.0)
///     .residual_friction(30.0)
///     .tension(2e5, 10.0)
///     .cohesion(3e5, 50.0)
///     .build()?;
/// // Open one sub-contact of 0.01 m² in small steps to 3 mm: it dissipates G_f^I·A = 0.1 J.
/// let (mut force, mut state) = (JointForce::default(), MortarState::default());
/// let mut fracture = 0.0;
/// for k in 1..=30_000 {
///     let step = JointStep {
///         area: 0.01,
///         normal_displacement: 1e-7 * k as f64,
///         normal_increment: 1e-7,
///         shear_increment: Vector2::ZERO,
///         axes: JointAxes::from_normal(Vector::Z),
///         dt: 1e-5,
///     };
///     let before = state;
///     law.update(&step, &mut force, &mut state);
///     fracture += law.fracture_work(0.01, &before, &state);
/// }
/// // To the round-off of 30,000 increments.
/// assert!((fracture - 0.1).abs() < 1e-10, "{fracture}");
/// assert_eq!(law.strengths(&state).tensile, 0.0);
/// # Ok::<(), voussoir::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(try_from = "spec::MortarSpec", into = "spec::MortarSpec"))]
pub struct MortarJoint {
    normal_stiffness: Real,
    shear_stiffness: Real,
    /// Degrees, as given (so that serialisation round-trips exactly).
    friction_deg: Real,
    residual_friction_deg: Real,
    dilatancy_deg: Real,
    tensile_strength: Real,
    mode_i_fracture_energy: Real,
    cohesion: Real,
    mode_ii_fracture_energy: Real,
    softening: Softening,
    cap: Option<CompressionCap>,
    /// `tan φ₀`, `tan φ_r`, `tan ψ₀`, cached out of the hot loop.
    tan_friction: Real,
    tan_residual: Real,
    tan_dilatancy: Real,
}

/// Builds a [`MortarJoint`]: [`MortarJoint::builder`] takes the stiffnesses and the friction
/// angle, each method adds a property, [`MortarJointBuilder::build`] validates them all.
/// Without [`tension`](Self::tension) the joint has no tensile strength, without
/// [`cohesion`](Self::cohesion) no cohesion (a dry joint).
#[derive(Debug, Clone, Copy, PartialEq)]
#[must_use = "a builder does nothing until `build` is called"]
pub struct MortarJointBuilder {
    law: MortarJoint,
}

impl MortarJointBuilder {
    /// Residual friction angle `φ_r` (degrees, in `[0°, 90°)`), reached as the cohesion goes;
    /// the initial one by default.
    pub fn residual_friction(mut self, degrees: Real) -> Self {
        self.law.residual_friction_deg = degrees;
        self
    }

    /// Tensile strength `f_t0` (Pa) and mode-I fracture energy `G_f^I` (J/m² = N/m), the
    /// energy a unit area of crack dissipates as it opens (0: brittle).
    pub fn tension(mut self, tensile_strength: Real, fracture_energy: Real) -> Self {
        self.law.tensile_strength = tensile_strength;
        self.law.mode_i_fracture_energy = fracture_energy;
        self
    }

    /// Cohesion `c₀` (Pa) and mode-II fracture energy `G_f^II` (J/m²), the energy a unit area
    /// of joint dissipates as it slips at zero normal stress while its cohesion goes (0:
    /// brittle).
    pub fn cohesion(mut self, cohesion: Real, fracture_energy: Real) -> Self {
        self.law.cohesion = cohesion;
        self.law.mode_ii_fracture_energy = fracture_energy;
        self
    }

    /// Dilatancy angle `ψ₀` (degrees, in `[0°, 90°)`; 0 by default), decaying with the
    /// cohesion's softening by slip: it needs a cohesion and a mode-II fracture energy.
    pub fn dilatancy(mut self, degrees: Real) -> Self {
        self.law.dilatancy_deg = degrees;
        self
    }

    /// The shape of the softening curves ([`Softening::Exponential`] by default).
    pub fn softening(mut self, softening: Softening) -> Self {
        self.law.softening = softening;
        self
    }

    /// A compression cap: the joint crushes ([`CompressionCap`]); without one it does not.
    pub fn compression_cap(mut self, cap: CompressionCap) -> Self {
        self.law.cap = Some(cap);
        self
    }

    /// The law, validated.
    ///
    /// # Errors
    /// [`crate::Error::InvalidParameter`] naming the first bad value: a stiffness not positive
    /// and finite, an angle outside `[0°, 90°)`, a strength or fracture energy negative or not
    /// finite, a dilatancy without cohesion or mode-II fracture energy, a cap's strength not
    /// positive and finite or its other parameters negative or not finite (`cap_strength`,
    /// `cap_fracture_energy`, `cap_shear_factor`, `cap_peak_closure`).
    pub fn build(self) -> Result<MortarJoint> {
        let mut law = self.law;
        law.tan_friction = law.friction_deg.to_radians().tan();
        law.tan_residual = law.residual_friction_deg.to_radians().tan();
        law.tan_dilatancy = law.dilatancy_deg.to_radians().tan();
        law.validate()?;
        Ok(law)
    }
}

/// Per-sub-contact history of [`MortarJoint`]. `Default` is the intact joint.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
pub struct MortarState {
    /// The crack's plastic opening `κ_t` (m): the opening at which tension unloads to zero.
    pub crack_opening: Real,
    /// Plastic slip `κ_s` (m) accumulated while it softens the cohesion or dilates the joint
    /// (slip beyond, on a joint with nothing left to lose, is not counted: see
    /// [`crate::contact::SubContactView::slip`] for all the slip).
    pub plastic_slip: Real,
    /// The plastic closure `κ_c` (m) of a joint that crushed on its [`CompressionCap`]: its
    /// faces carry compression from `κ_c` further in than before; also the cap's hardening
    /// parameter. Zero without a cap.
    pub crushing: Real,
}

/// The strengths of a [`MortarJoint`] in a given state ([`MortarJoint::strengths`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MortarStrengths {
    /// Fraction of the intact strengths left, `r(D)` (1 intact, 0 cracked through).
    pub remaining: Real,
    /// Tensile strength `f_t` (Pa).
    pub tensile: Real,
    /// Cohesion `c` (Pa).
    pub cohesion: Real,
    /// Friction coefficient `tan φ`.
    pub tan_friction: Real,
    /// Dilatancy `tan ψ`.
    pub tan_dilatancy: Real,
    /// The compression cap's strength `σ_c(κ_c)` (Pa); infinite without a cap.
    pub compressive: Real,
}

/// At most this many alternations of the tension and the shear return in one step (each
/// leaves its own mode on its strength; the plastic opening and slip only grow, and are
/// bounded, so the alternation converges; at a corner of the two surfaces it takes a few).
const MAX_ROUNDS: usize = 100;

/// At most this many iterations of a bracketed root search (Illinois; it stops earlier when
/// the bracket is a few ulps wide).
const MAX_ITERATIONS: usize = 200;

/// The root of `f` in `[lo, hi]` where `f(lo) > 0 ≥ f(hi)`: the upper end of a bracket a few
/// ulps wide, so that `f` there is not positive (the strength it measures is not exceeded);
/// `lo` itself when `f(lo)` is not positive.
/// Regula falsi with the Illinois modification, and bisection when it stalls; deterministic.
fn bracketed_root(mut lo: Real, mut hi: Real, f: impl Fn(Real) -> Real) -> Real {
    let (mut f_lo, mut f_hi) = (f(lo), f(hi));
    // Not exceeded at the lower end (to round-off): nothing to return.
    if f_lo.is_nan() || f_lo <= 0.0 {
        return lo;
    }
    if f_hi.is_nan() || f_hi > 0.0 {
        return hi;
    }
    let mut last = 0i8;
    for k in 0..MAX_ITERATIONS {
        if hi - lo <= 4.0 * Real::EPSILON * hi.abs().max(lo.abs()) {
            break;
        }
        let mut x = (lo * f_hi - hi * f_lo) / (f_hi - f_lo);
        if k % 8 == 7 || !(x > lo && x < hi) {
            x = lo + 0.5 * (hi - lo);
        }
        let fx = f(x);
        if fx > 0.0 {
            (lo, f_lo) = (x, fx);
            if last == 1 {
                f_hi *= 0.5;
            }
            last = 1;
        } else {
            (hi, f_hi) = (x, fx);
            if last == -1 {
                f_lo *= 0.5;
            }
            last = -1;
        }
    }
    hi
}

impl MortarJoint {
    /// A builder with the normal and shear stiffnesses `kn`, `ks` (Pa/m) and the friction
    /// angle `φ₀` (degrees, in `[0°, 90°)`); the other properties are added to it.
    pub fn builder(kn: Real, ks: Real, friction_deg: Real) -> MortarJointBuilder {
        MortarJointBuilder {
            law: Self {
                normal_stiffness: kn,
                shear_stiffness: ks,
                friction_deg,
                residual_friction_deg: friction_deg,
                dilatancy_deg: 0.0,
                tensile_strength: 0.0,
                mode_i_fracture_energy: 0.0,
                cohesion: 0.0,
                mode_ii_fracture_energy: 0.0,
                softening: Softening::Exponential,
                cap: None,
                tan_friction: Real::NAN,
                tan_residual: Real::NAN,
                tan_dilatancy: Real::NAN,
            },
        }
    }

    /// Normal stiffness `kn` (Pa/m).
    pub fn normal_stiffness(&self) -> Real {
        self.normal_stiffness
    }
    /// Shear stiffness `ks` (Pa/m).
    pub fn shear_stiffness(&self) -> Real {
        self.shear_stiffness
    }
    /// Initial friction angle `φ₀` (rad).
    pub fn friction_angle(&self) -> Real {
        self.friction_deg.to_radians()
    }
    /// Residual friction angle `φ_r` (rad).
    pub fn residual_friction_angle(&self) -> Real {
        self.residual_friction_deg.to_radians()
    }
    /// Initial dilatancy angle `ψ₀` (rad).
    pub fn dilatancy_angle(&self) -> Real {
        self.dilatancy_deg.to_radians()
    }
    /// Intact tensile strength `f_t0` (Pa).
    pub fn tensile_strength(&self) -> Real {
        self.tensile_strength
    }
    /// Mode-I fracture energy `G_f^I` (J/m²).
    pub fn mode_i_fracture_energy(&self) -> Real {
        self.mode_i_fracture_energy
    }
    /// Intact cohesion `c₀` (Pa).
    pub fn cohesion(&self) -> Real {
        self.cohesion
    }
    /// Mode-II fracture energy `G_f^II` (J/m²).
    pub fn mode_ii_fracture_energy(&self) -> Real {
        self.mode_ii_fracture_energy
    }
    /// The shape of the softening curves.
    pub fn softening(&self) -> Softening {
        self.softening
    }
    /// The compression cap, if the joint crushes.
    pub fn compression_cap(&self) -> Option<CompressionCap> {
        self.cap
    }

    /// The softening parameter `D = f_t0 κ_t/G_f^I + c₀ κ_s/G_f^II` of `state` (infinite
    /// once a brittle mode has failed).
    #[inline]
    pub fn softening_parameter(&self, state: &MortarState) -> Real {
        self.damage(state.crack_opening, state.plastic_slip)
    }

    /// The strengths left in `state`.
    ///
    /// ```
    /// use voussoir::law::{MortarJoint, MortarState};
    /// let law = MortarJoint::builder(1e11, 4e10, 35.0).residual_friction(30.0)
    ///     .tension(2e5, 10.0).cohesion(3e5, 50.0).build()?;
    /// // A crack opened by G_f^I/f_t0 = 50 µm: D = 1, both strengths at 1/e.
    /// let s = law.strengths(&MortarState { crack_opening: 5e-5, ..MortarState::default() });
    /// assert!((s.tensile - 2e5 / 1f64.exp()).abs() < 1e-9);
    /// assert!((s.cohesion - 3e5 / 1f64.exp()).abs() < 1e-9);
    /// # Ok::<(), voussoir::Error>(())
    /// ```
    pub fn strengths(&self, state: &MortarState) -> MortarStrengths {
        let r = self.softening.remaining(self.softening_parameter(state));
        MortarStrengths {
            remaining: r,
            tensile: self.tensile_strength * r,
            cohesion: self.cohesion * r,
            tan_friction: self.tan_friction_at(r),
            tan_dilatancy: self.tan_dilatancy * self.softening.remaining(self.shear_damage(state.plastic_slip)),
            compressive: self.cap.map_or(Real::INFINITY, |cap| cap.strength_at(state.crushing)),
        }
    }

    /// The joint's dilatant opening `u_d` (m) in `state`: where its faces touch again.
    pub fn dilatant_opening(&self, state: &MortarState) -> Real {
        self.dilatant_opening_at(state.plastic_slip)
    }

    /// `f_t0 κ_t / G_f^I` (infinite for a brittle joint that has cracked).
    #[inline]
    fn tension_damage(&self, crack: Real) -> Real {
        if crack == 0.0 || self.tensile_strength == 0.0 {
            0.0
        } else if self.mode_i_fracture_energy == 0.0 {
            Real::INFINITY
        } else {
            self.tensile_strength * crack / self.mode_i_fracture_energy
        }
    }

    /// `c₀ κ_s / G_f^II` (infinite for a brittle joint that has slipped).
    #[inline]
    fn shear_damage(&self, slip: Real) -> Real {
        if slip == 0.0 || self.cohesion == 0.0 {
            0.0
        } else if self.mode_ii_fracture_energy == 0.0 {
            Real::INFINITY
        } else {
            self.cohesion * slip / self.mode_ii_fracture_energy
        }
    }

    #[inline]
    fn damage(&self, crack: Real, slip: Real) -> Real {
        self.tension_damage(crack) + self.shear_damage(slip)
    }

    /// `tan φ = r tan φ₀ + (1 − r) tan φ_r`: exactly `tan φ₀` for `r = 1`.
    #[inline]
    fn tan_friction_at(&self, r: Real) -> Real {
        self.tan_friction * r + self.tan_residual * (1.0 - r)
    }

    /// `u_d = tan ψ₀ (G_f^II/c₀) ∫₀^{c₀κ_s/G_f^II} r`; exactly `0.0` without slip or dilatancy.
    #[inline]
    fn dilatant_opening_at(&self, slip: Real) -> Real {
        if self.tan_dilatancy == 0.0 || slip == 0.0 {
            return 0.0;
        }
        let d = self.shear_damage(slip);
        self.tan_dilatancy * (self.mode_ii_fracture_energy / self.cohesion) * self.softening.integral(0.0, d)
    }

    /// Where the joint's faces touch, as a normal displacement: the dilatant opening less the
    /// crushing; exactly `0.0` for the intact joint.
    #[inline]
    fn contact_offset(&self, slip: Real, crushing: Real) -> Real {
        self.dilatant_opening_at(slip) - crushing
    }

    /// The normal force on area `a` at normal displacement `u`, contact offset `offset`
    /// ([`Self::contact_offset`]) and crack opening `crack`; `−kn·u·a` to the bit for the
    /// intact joint.
    #[inline]
    fn normal_force(&self, u: Real, offset: Real, crack: Real, a: Real) -> Real {
        let e = u - offset;
        let elastic = if e > 0.0 { (e - crack).max(0.0) } else { e };
        -self.normal_stiffness * elastic * a
    }

    /// Whether slip changes the state at fraction left `r` and plastic slip `slip`: while
    /// there is cohesion to soften, or dilatancy left.
    #[inline]
    fn slip_softens(&self, r: Real, slip: Real) -> bool {
        (self.cohesion > 0.0 && r > 0.0)
            || (self.tan_dilatancy > 0.0 && self.softening.remaining(self.shear_damage(slip)) > 0.0)
    }

    /// The tension return: the crack opening, from `crack` on, at which the tension at
    /// displacement `e` beyond the dilatant opening meets the tensile strength (all of it at
    /// once for a brittle joint).
    fn tension_return(&self, e: Real, crack: Real, slip: Real) -> Real {
        if self.mode_i_fracture_energy == 0.0 {
            return e;
        }
        let (kn, ft) = (self.normal_stiffness, self.tensile_strength);
        let d_s = self.shear_damage(slip);
        bracketed_root(crack, e, |x| {
            kn * (e - x) - ft * self.softening.remaining(self.tension_damage(x) + d_s)
        })
    }

    /// The shear limit per unit area, `max(c + σ tan φ, 0)`, at normal displacement `u`, crack
    /// opening `crack`, plastic slip `slip` and crushing `crushing`.
    #[inline]
    fn shear_limit(&self, u: Real, crack: Real, slip: Real, crushing: Real) -> Real {
        let r = self.softening.remaining(self.damage(crack, slip));
        let sigma = self.normal_force(u, self.contact_offset(slip, crushing), crack, 1.0);
        (self.cohesion * r + sigma * self.tan_friction_at(r)).max(0.0)
    }

    /// The shear return: the plastic slip of the step, from `done` on, at which the shear
    /// stress `tau` of the trial less `k_s` times it meets the shear limit (`slip0` the plastic
    /// slip before the step).
    fn shear_return(&self, u: Real, crack: Real, crushing: Real, slip0: Real, tau: Real, done: Real) -> Real {
        let ks = self.shear_stiffness;
        bracketed_root(done, tau / ks, |q| {
            (tau - ks * q) - self.shear_limit(u, crack, slip0 + q, crushing)
        })
    }
}

impl ConstitutiveLaw for MortarJoint {
    type State = MortarState;

    #[inline]
    fn stiffness(&self) -> JointStiffness {
        JointStiffness {
            normal: self.normal_stiffness,
            shear: self.shear_stiffness,
        }
    }

    fn update(&self, s: &JointStep, f: &mut JointForce, state: &mut MortarState) -> JointStatus {
        let a = s.area;
        let u = s.normal_displacement;
        let r = self.softening.remaining(self.softening_parameter(state));
        f.normal = self.normal_force(
            u,
            self.contact_offset(state.plastic_slip, state.crushing),
            state.crack_opening,
            a,
        );
        let tensile = self.tensile_strength * r;
        // Open: no tensile strength (left) and no compression, touching included.
        if tensile == 0.0 && f.normal <= 0.0 {
            f.normal = 0.0;
            f.shear = Vector2::ZERO;
            return JointStatus::Open;
        }
        f.shear -= s.shear_increment * (self.shear_stiffness * a);
        let cohesion = self.cohesion * r;
        let tan_phi = self.tan_friction_at(r);
        let tension_beyond = f.normal < -tensile * a;
        let limit = cohesion * a + f.normal * tan_phi;
        let trial_squared = f.shear.length_squared();
        // `|F_s| > max(limit, 0)`, without a square root while the joint holds. A trial of no
        // shear beyond the apex of the Coulomb line (`limit < 0`) has nothing to slip.
        let shear_beyond = super::beyond_limit(limit, trial_squared);
        let cap_beyond = match &self.cap {
            Some(cap) => cap.exceeded(f.normal / a, trial_squared.sqrt() / a, state.crushing),
            None => false,
        };
        if !tension_beyond && !shear_beyond && !cap_beyond {
            return JointStatus::Elastic;
        }
        let trial = trial_squared.sqrt();
        if !tension_beyond
            && !cap_beyond
            && (!self.slip_softens(r, state.plastic_slip) || self.mode_ii_fracture_energy == 0.0)
        {
            // Slip that loses nothing more (a dry joint, or one cracked through), or the
            // brittle failure of a cohesive joint, as `CoulombSlip`: onto the strength of the
            // start of the step (which leaves the cap as it was: only the shear falls).
            let cap = limit.max(0.0);
            f.shear *= if trial > 0.0 { cap / trial } else { 0.0 };
            if self.slip_softens(r, state.plastic_slip) {
                state.plastic_slip += (trial - cap) / (self.shear_stiffness * a);
            }
            return JointStatus::Sliding;
        }
        self.return_mapping(s, f, state, tension_beyond, trial)
    }

    /// The open test of [`MortarJoint::update`], evaluated the same way: no tensile strength
    /// left (or none given) and no compression.
    #[inline]
    fn stays_open(&self, area: Real, normal_displacement: Real, state: &MortarState) -> bool {
        let r = self.softening.remaining(self.softening_parameter(state));
        let normal = self.normal_force(
            normal_displacement,
            self.contact_offset(state.plastic_slip, state.crushing),
            state.crack_opening,
            area,
        );
        self.tensile_strength * r == 0.0 && normal <= 0.0
    }

    /// The intact joint in compression, or in tension below `f_t0`, within its strength: `c₀` and
    /// `tan φ₀`; sliding too when nothing softens as it slides (no cohesion, no dilatancy). None
    /// with a cap.
    #[inline]
    fn elastic_regime(&self) -> Option<ElasticRegime> {
        if self.cap.is_some() {
            return None;
        }
        Some(ElasticRegime {
            normal_stiffness: self.normal_stiffness,
            shear_stiffness: self.shear_stiffness,
            cohesion: self.cohesion,
            tan_friction: self.tan_friction,
            slides: self.cohesion == 0.0 && self.tan_dilatancy == 0.0,
            tensile_strength: self.tensile_strength,
        })
    }

    /// The fracture energy consumed from `before` to `after` (J): the work against the softening
    /// strengths, `A ∫ (f_t dκ_t + c dκ_s) = A (f_t0 Δκ_t + c₀ Δκ_s) ∫r dD / ΔD` along the
    /// step's proportional path — exactly `G_f^I A Δ∫r` in pure opening and `G_f^II A Δ∫r` in
    /// pure slip; none for a brittle failure — and the work of crushing against the cap,
    /// `A ∫ σ_c dκ_c` ([`CompressionCap::work_to`]).
    fn fracture_work(&self, area: Real, before: &MortarState, after: &MortarState) -> Real {
        let d0 = self.softening_parameter(before);
        let (dt, ds) = (
            after.crack_opening - before.crack_opening,
            after.plastic_slip - before.plastic_slip,
        );
        let increment = |strength: Real, energy: Real, dk: Real| {
            if dk == 0.0 || strength == 0.0 {
                0.0
            } else {
                strength * dk / energy
            }
        };
        let dd = increment(self.tensile_strength, self.mode_i_fracture_energy, dt)
            + increment(self.cohesion, self.mode_ii_fracture_energy, ds);
        let crushing = match self.cap {
            Some(cap) if after.crushing > before.crushing => {
                area * (cap.work_to(after.crushing) - cap.work_to(before.crushing))
            }
            _ => 0.0,
        };
        if !(dd > 0.0 && dd.is_finite() && d0.is_finite()) {
            return crushing;
        }
        let work = self.tensile_strength * dt + self.cohesion * ds;
        area * work * (self.softening.integral(d0, dd) / dd) + crushing
    }

    /// Cracked through: the crack opened to the end of the softening curve, so that the
    /// tensile strength and the cohesion are exactly zero and the friction is the residual one
    /// (by slip instead for a joint with cohesion and no tensile strength; such a joint with
    /// dilatancy keeps the virgin state, whose fully slipped state would push its nodes out by
    /// the whole dilatant opening). A joint without a bond: the virgin state.
    fn unbonded_state(&self) -> MortarState {
        // The smallest κ at which `damage(κ)` reaches the curve's end (no rounding short).
        let through = |strength: Real, energy: Real, damage: &dyn Fn(Real) -> Real| {
            let mut k = if energy == 0.0 {
                Real::MIN_POSITIVE
            } else {
                self.softening.end() * energy / strength
            };
            while damage(k) < self.softening.end() {
                k *= 1.0 + Real::EPSILON;
            }
            k
        };
        if self.tensile_strength > 0.0 {
            MortarState {
                crack_opening: through(self.tensile_strength, self.mode_i_fracture_energy, &|k| {
                    self.tension_damage(k)
                }),
                ..MortarState::default()
            }
        } else if self.cohesion > 0.0 && self.tan_dilatancy == 0.0 {
            MortarState {
                plastic_slip: through(self.cohesion, self.mode_ii_fracture_energy, &|k| self.shear_damage(k)),
                ..MortarState::default()
            }
        } else {
            MortarState::default()
        }
    }

    /// Cracked, softened or crushed at all.
    fn is_failed(&self, state: &MortarState) -> bool {
        self.softening_parameter(state) > 0.0 || state.crushing > 0.0
    }

    fn validate(&self) -> Result<()> {
        positive("normal_stiffness", self.normal_stiffness)?;
        positive("shear_stiffness", self.shear_stiffness)?;
        let angle = "must lie in [0, 90) degrees";
        in_range("friction_angle", self.friction_deg, 0.0, 90.0, angle)?;
        in_range("residual_friction_angle", self.residual_friction_deg, 0.0, 90.0, angle)?;
        in_range("dilatancy_angle", self.dilatancy_deg, 0.0, 90.0, angle)?;
        non_negative("tensile_strength", self.tensile_strength)?;
        non_negative("mode_i_fracture_energy", self.mode_i_fracture_energy)?;
        non_negative("cohesion", self.cohesion)?;
        non_negative("mode_ii_fracture_energy", self.mode_ii_fracture_energy)?;
        if self.dilatancy_deg > 0.0 && !(self.cohesion > 0.0 && self.mode_ii_fracture_energy > 0.0) {
            return Err(Error::InvalidParameter {
                name: "dilatancy_angle".into(),
                value: self.dilatancy_deg,
                expected: "needs a cohesion and a mode-II fracture energy (the dilatancy decays with the \
                           cohesion's softening)",
            });
        }
        if let Some(cap) = self.cap {
            cap.validate()?;
        }
        Ok(())
    }
}

impl MortarJoint {
    /// The return mapping of [`ConstitutiveLaw::update`] from the trial (shear force `f.shear`
    /// of magnitude `trial`), per unit area: the tension, the shear and the cap return in turn,
    /// each onto its strength at the end of the step, until none is exceeded. Out of line: most
    /// updates are elastic and return before it.
    #[inline(never)]
    fn return_mapping(
        &self,
        s: &JointStep,
        f: &mut JointForce,
        state: &mut MortarState,
        tension_beyond: bool,
        trial: Real,
    ) -> JointStatus {
        let (a, u) = (s.area, s.normal_displacement);
        let ks = self.shear_stiffness;
        let slip0 = state.plastic_slip;
        let tau = trial / a;
        let (mut crack, mut slip, mut crushing) = (state.crack_opening, slip0, state.crushing);
        // Plastic slip of the step on the Coulomb surface (m); slip beyond what softens is not
        // state. And the cap's plastic shear displacement (m), which softens nothing.
        let (mut slipped, mut cap_slipped): (Real, Real) = (0.0, 0.0);
        for round in 0..MAX_ROUNDS {
            let mut changed = false;
            let r = self.softening.remaining(self.damage(crack, slip));
            let e = u - self.contact_offset(slip, crushing);
            // The first round takes the tension test on the forces above (as `CoulombSlip`).
            let beyond = if round == 0 {
                tension_beyond
            } else {
                r > 0.0 && e > crack && self.normal_stiffness * (e - crack) > self.tensile_strength * r
            };
            if beyond {
                let before = crack;
                crack = self.tension_return(e, crack, slip);
                changed = crack != before;
            }
            let limit = self.shear_limit(u, crack, slip, crushing);
            // The shear left after the cap's plastic shear.
            let tau_cap = tau - ks * cap_slipped;
            if tau_cap - ks * slipped > limit {
                let r = self.softening.remaining(self.damage(crack, slip));
                if self.slip_softens(r, slip) && self.mode_ii_fracture_energy > 0.0 {
                    let before = slipped;
                    slipped = self.shear_return(u, crack, crushing, slip0, tau_cap, slipped);
                    slip = slip0 + slipped;
                    changed |= slipped != before;
                } else {
                    // Nothing left to soften (or brittle): onto the strength, at once.
                    let more = (tau_cap - limit) / ks;
                    if self.slip_softens(r, slip) {
                        slip = slip0 + more;
                        changed = true;
                    }
                    slipped = more;
                }
            }
            if let Some(cap) = self.cap {
                let sigma = self.normal_force(u, self.contact_offset(slip, crushing), crack, 1.0);
                let tau_now = (tau_cap - ks * slipped).max(0.0);
                if cap.exceeded(sigma, tau_now, crushing) {
                    let (kappa, tau_after) = cap.ret(self.normal_stiffness, ks, sigma, tau_now, crushing);
                    changed |= kappa != crushing;
                    crushing = kappa;
                    cap_slipped += (tau_now - tau_after) / ks;
                }
            }
            if !changed {
                break;
            }
        }
        state.crack_opening = crack;
        state.plastic_slip = slip;
        state.crushing = crushing;
        let r = self.softening.remaining(self.damage(crack, slip));
        f.normal = self.normal_force(u, self.contact_offset(slip, crushing), crack, a);
        if self.tensile_strength * r == 0.0 && f.normal <= 0.0 {
            f.normal = 0.0;
            f.shear = Vector2::ZERO;
            return JointStatus::Open;
        }
        let left = (tau - ks * (slipped + cap_slipped)).max(0.0);
        f.shear *= if trial > 0.0 { left / tau } else { 0.0 };
        if slipped > 0.0 || cap_slipped > 0.0 {
            JointStatus::Sliding
        } else {
            JointStatus::Elastic
        }
    }
}

#[cfg(feature = "limit")]
impl crate::analysis::limit::LimitStrength for MortarJoint {
    /// The intact joint's friction and cohesion, as [`super::CoulombSlip`]'s (no tension).
    fn limit_strength(&self) -> Option<crate::analysis::limit::JointStrength> {
        Some(crate::analysis::limit::JointStrength {
            friction: self.tan_friction,
            cohesion: self.cohesion,
        })
    }
}

#[cfg(test)]
mod cap_tests;
#[cfg(test)]
mod tests;
