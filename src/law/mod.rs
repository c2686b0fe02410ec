//! Joint constitutive laws: the [`ConstitutiveLaw`] trait, the laws voussoir ships ([`AnyLaw`]
//! to mix them), the table that assigns a law to each pair of block materials, and the
//! [`conformance`] check of a law against the trait's contract.
//!
//! Sign conventions: the normal force is positive in compression; the shear force is the force on
//! block `b` of the pair, in the joint plane; the normal displacement `u_n` is positive when the
//! joint opens. Forces are stresses times the sub-contact area. See `docs/theory.md`.

mod any;
pub mod conformance;
mod coulomb;
mod linear_elastic;
mod mortar;
mod table;

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

pub use any::{AnyLaw, AnyState};
pub use coulomb::{CoulombSlip, CoulombState};
pub use linear_elastic::LinearElastic;
pub use mortar::{
    CompressionCap, MortarJoint, MortarJointBuilder, MortarState, MortarStrengths, Softening, LOURENCO_SHEAR_FACTOR,
};
pub use table::LawTable;

pub use crate::ids::MaterialId;

use crate::error::Result;
use crate::math::{plane_basis, Real, Vector, Vector2};

/// Elastic stiffness of a joint per unit area.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct JointStiffness {
    /// Normal stiffness `kn` (Pa/m).
    pub normal: Real,
    /// Shear stiffness `ks` (Pa/m).
    pub shear: Real,
}

/// The axes of a joint (world): its unit normal `n` (from `a` to `b`) and two unit tangents
/// `t₁`, `t₂ = n × t₁` spanning its plane. Shear forces and displacements are given by their
/// components along the tangents. In large-displacement mode the tangents turn with the joint
/// plane from step to step, so the components of a stored shear force stay valid as the plane
/// turns (see `docs/theory.md`, "Sub-contact kinematics").
///
/// ```
/// use voussoir::law::JointAxes;
/// use voussoir::math::{Vector, Vector2};
/// let axes = JointAxes::from_normal(Vector::Z);
/// let s = Vector::new(3.0, -4.0, 0.0);
/// let c = axes.components(s);
/// assert!((axes.shear(c) - s).length() < 1e-15);
/// assert!((c.length() - 5.0).abs() < 1e-15);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointAxes {
    /// Unit normal (from `a` to `b`).
    pub normal: Vector,
    /// First tangent `t₁`, a unit vector normal to `normal`.
    pub tangent: Vector,
}

impl JointAxes {
    /// Axes with normal `normal` (a unit vector) and an arbitrary first tangent.
    pub fn from_normal(normal: Vector) -> Self {
        Self {
            normal,
            tangent: plane_basis(normal).0,
        }
    }
    /// The second tangent `t₂ = n × t₁`.
    #[inline]
    pub fn tangent_2(&self) -> Vector {
        self.normal.cross(self.tangent)
    }
    /// The world vector with tangent components `c`: `c.x t₁ + c.y t₂`.
    #[inline]
    pub fn shear(&self, c: Vector2) -> Vector {
        self.tangent * c.x + self.tangent_2() * c.y
    }
    /// The tangent components of the world vector `v` (its part along `n` is dropped).
    #[inline]
    pub fn components(&self, v: Vector) -> Vector2 {
        Vector2::new(self.tangent.dot(v), self.tangent_2().dot(v))
    }
    /// The world force of `force` on block `b`: `n F_n + F_s`.
    #[inline]
    pub fn force(&self, force: &JointForce) -> Vector {
        self.normal * force.normal + self.shear(force.shear)
    }
}

/// What the kinematics of one step give a law at one sub-contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointStep {
    /// Tributary area of the sub-contact (m²).
    pub area: Real,
    /// Total normal displacement `u_n` (m): positive = open, negative = interpenetration.
    pub normal_displacement: Real,
    /// Normal displacement increment of this step (m).
    pub normal_increment: Real,
    /// Shear displacement increment of block `b` relative to block `a` in the joint plane (m),
    /// as components along the tangents of [`JointStep::axes`].
    pub shear_increment: Vector2,
    /// The joint's normal and tangents (world), for laws that are not isotropic in the plane.
    pub axes: JointAxes,
    /// Time step (s).
    pub dt: Real,
}

/// The forces a law maintains at a sub-contact.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct JointForce {
    /// Normal force (N), positive in compression.
    pub normal: Real,
    /// Shear force on block `b` (N), as components along the joint's tangents
    /// ([`JointAxes`]); on entry the previous step's value, whose axes have turned with the plane.
    pub shear: Vector2,
}

/// A law's linear elastic regime for sub-contacts in the virgin state (`State::default()`), which
/// the contact kernel evaluates without calling [`ConstitutiveLaw::update`]; see
/// [`ConstitutiveLaw::elastic_regime`].
///
/// The trial forces are `F_n = −k_n·u_n·A` and `F_s = F_s⁻ − Δu_s·(k_s·A)`; they stand when the
/// joint is in compression (`F_n > 0`), or in tension below the regime's tensile strength
/// (`F_n > −f_t·A`), and within its strength, `|F_s| ≤ max(L, 0)` with `L = c·A + F_n·tan φ`
/// (tested as `|F_s|² ≤ L²` for `L ≥ 0`; a trial of no shear stands at `L < 0`), computed in
/// exactly this order ([`ElasticRegime::trial`]).
///
/// ```
/// use voussoir::law::{ConstitutiveLaw, CoulombSlip, ElasticRegime};
/// use voussoir::math::Vector2;
/// let law = CoulombSlip::dry(1e9, 4e8, 30.0)?;
/// let regime = law.elastic_regime().expect("Coulomb slip has one");
/// // 1 µm of overlap on 0.01 m²: 10 N of compression carries up to 5.77 N of shear.
/// let stuck = regime.trial(0.01, -1e-6, Vector2::new(-1e-6, 0.0), Vector2::ZERO);
/// assert!((stuck.expect("elastic").shear.x - 4.0).abs() < 1e-12);
/// assert!(regime.trial(0.01, -1e-6, Vector2::new(-2e-6, 0.0), Vector2::ZERO).is_none());
/// assert!(regime.trial(0.01, 1e-6, Vector2::ZERO, Vector2::ZERO).is_none());
/// # Ok::<(), voussoir::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ElasticRegime {
    /// Normal stiffness `k_n` (Pa/m).
    pub normal_stiffness: Real,
    /// Shear stiffness `k_s` (Pa/m).
    pub shear_stiffness: Real,
    /// Cohesion `c` (Pa).
    pub cohesion: Real,
    /// Friction coefficient `tan φ` (may be infinite: no shear limit).
    pub tan_friction: Real,
    /// Whether the regime also covers sliding: in compression beyond the strength, the law
    /// scales the trial shear back onto it, `F_s ← F_s·(max(L, 0)/|F_s|)`, and leaves the state
    /// as it is (no cohesion, tensile strength or peak friction to lose), returning
    /// [`JointStatus::Sliding`] ([`ElasticRegime::step`]). `false` promises nothing.
    pub slides: bool,
    /// Tensile strength `f_t` (Pa) down to which the regime covers tension: the trial stands
    /// for `F_n > −f_t·A` (a bonded joint below its strength). 0: compression only (`F_n > 0`).
    pub tensile_strength: Real,
}

impl ElasticRegime {
    /// The forces after a step with total normal displacement `normal_displacement` (m) and
    /// shear increment `shear_increment` (tangent components, m) on area `area` (m²) from the
    /// shear force `shear` (tangent components, N), if they stay in the regime: in compression
    /// (or tension below the regime's tensile strength) and within the strength. `None`
    /// otherwise (then the law's own update decides).
    #[inline(always)]
    pub fn trial(
        &self,
        area: Real,
        normal_displacement: Real,
        shear_increment: Vector2,
        shear: Vector2,
    ) -> Option<JointForce> {
        let normal = -self.normal_stiffness * normal_displacement * area;
        let shear = shear - shear_increment * (self.shear_stiffness * area);
        let limit = self.cohesion * area + normal * self.tan_friction;
        let trial_squared = shear.length_squared();
        let stands = normal > -self.tensile_strength * area && !beyond_limit(limit, trial_squared);
        stands.then_some(JointForce { normal, shear })
    }

    /// As [`ElasticRegime::trial`], and when the trial shear exceeds the strength of a joint in
    /// compression whose regime [`slides`](ElasticRegime::slides), the slid forces: the trial
    /// shear scaled back onto the strength, with [`JointStatus::Sliding`]. `None` where the law's
    /// own update decides.
    ///
    /// ```
    /// use voussoir::law::{ConstitutiveLaw, CoulombSlip, JointStatus};
    /// use voussoir::math::Vector2;
    /// let regime = CoulombSlip::dry(1e9, 4e8, 45.0)?.elastic_regime().expect("a regime");
    /// // 10 N of compression carries 10 N of shear; a trial of 20 N slides back onto it.
    /// let (force, status) = regime.step(0.01, -1e-6, Vector2::new(-5e-6, 0.0), Vector2::ZERO).expect("slides");
    /// assert_eq!(status, JointStatus::Sliding);
    /// assert!((force.shear.x - 10.0).abs() < 1e-9);
    /// # Ok::<(), voussoir::Error>(())
    /// ```
    #[inline(always)]
    pub fn step(
        &self,
        area: Real,
        normal_displacement: Real,
        shear_increment: Vector2,
        shear: Vector2,
    ) -> Option<(JointForce, JointStatus)> {
        let normal = -self.normal_stiffness * normal_displacement * area;
        let shear = shear - shear_increment * (self.shear_stiffness * area);
        let limit = self.cohesion * area + normal * self.tan_friction;
        // Beyond the tensile strength (no tension at all without one), or NaN: the law decides.
        let within = normal > -self.tensile_strength * area;
        if !within {
            return None;
        }
        let trial_squared = shear.length_squared();
        if !beyond_limit(limit, trial_squared) {
            return Some((JointForce { normal, shear }, JointStatus::Elastic));
        }
        if !self.slides {
            return None;
        }
        let trial = trial_squared.sqrt();
        let shear = shear * if trial > 0.0 { limit.max(0.0) / trial } else { 0.0 };
        Some((JointForce { normal, shear }, JointStatus::Sliding))
    }
}

/// Whether a trial shear of squared length `trial_squared` passes the limit `limit`:
/// `|F_s| > max(L, 0)`, so that a trial of no shear stands at a negative limit (in tension
/// beyond the apex of the Coulomb line) and slides nowhere.
/// [`MortarJoint`]'s update uses the same test, so that its regime and its update agree.
#[inline(always)]
pub(crate) fn beyond_limit(limit: Real, trial_squared: Real) -> bool {
    (limit < 0.0 && trial_squared > 0.0) || trial_squared > limit * limit
}

/// State of a sub-contact after an update, for monitors and output.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub enum JointStatus {
    /// In contact, below the strength.
    #[default]
    Elastic,
    /// In contact, at the shear strength (slipping).
    Sliding,
    /// Open: no compression, no force (or tension below the tensile strength of a bonded joint,
    /// which a law reports as [`JointStatus::Elastic`]).
    Open,
}

/// A joint constitutive law: updates the forces at one sub-contact for one step.
///
/// Laws are plain values (their parameters); per-sub-contact history that the law needs besides
/// the forces (damage, plastic slip, a bonded flag) lives in [`ConstitutiveLaw::State`], which
/// voussoir stores contiguously next to each sub-contact and carries through re-detection and
/// checkpoints. The model is generic over the law type, so calls are statically dispatched; to mix
/// the shipped laws in one model, use [`AnyLaw`]; to mix your own with them, implement the trait
/// for an `enum` of them that forwards every method, the shortcuts [`ConstitutiveLaw::stays_open`]
/// and [`ConstitutiveLaw::elastic_regime`] included.
///
/// [`conformance::check`] tests a law against the promises below (the shortcuts agree with
/// `update`, energies are not negative, updates are deterministic); run it in your law's tests.
///
/// See `docs/custom-law.md` for a walk-through. A minimal law, frictionless and no-tension:
///
/// ```
/// use voussoir::law::{ConstitutiveLaw, JointForce, JointStatus, JointStep, JointStiffness};
/// use voussoir::law::JointAxes;
/// use voussoir::math::{Vector, Vector2};
///
/// #[derive(Debug, Clone)]
/// struct Frictionless { kn: f64 }
///
/// impl ConstitutiveLaw for Frictionless {
///     type State = ();
///     fn stiffness(&self) -> JointStiffness { JointStiffness { normal: self.kn, shear: 0.0 } }
///     fn update(&self, s: &JointStep, f: &mut JointForce, _: &mut ()) -> JointStatus {
///         f.shear = Vector2::ZERO;
///         f.normal = (-self.kn * s.normal_displacement * s.area).max(0.0);
///         if f.normal > 0.0 { JointStatus::Sliding } else { JointStatus::Open }
///     }
/// }
/// let law = Frictionless { kn: 1e9 };
/// let step = JointStep { area: 0.01, normal_displacement: -1e-6, normal_increment: -1e-6,
///     shear_increment: Vector2::ZERO, axes: JointAxes::from_normal(Vector::Z), dt: 1e-5 };
/// let mut f = JointForce::default();
/// assert_eq!(law.update(&step, &mut f, &mut ()), JointStatus::Sliding);
/// assert!((f.normal - 10.0).abs() < 1e-9);
/// ```
pub trait ConstitutiveLaw: Clone + Send + Sync + std::fmt::Debug {
    /// Law-specific history of one sub-contact. `Default` is the virgin state.
    type State: Clone + Default + Send + Sync + std::fmt::Debug + PartialEq;

    /// Initial (largest) stiffness, used for the critical time step and the Rayleigh dashpots.
    fn stiffness(&self) -> JointStiffness;

    /// Updates `force` (holding last step's forces, the shear as components along the joint's
    /// tangents, which have turned with the plane) and `state` for this step's kinematics; returns the resulting status.
    fn update(&self, step: &JointStep, force: &mut JointForce, state: &mut Self::State) -> JointStatus;

    /// Whether a sub-contact that is open with zero force stays so at total normal displacement
    /// `normal_displacement` (m), whatever the rest of the [`JointStep`] (shear and normal
    /// increments, normal, time step): [`ConstitutiveLaw::update`] would return
    /// [`JointStatus::Open`], leave the forces at zero and `state` unchanged. It is asked only
    /// for sub-contacts in large-displacement mode (where every contact's gap is geometric)
    /// whose last status is `Open` with zero forces (and no dashpot force).
    ///
    /// The contact kernel then skips the sub-contact's kinematics and update (separated parts
    /// of joints are common: a quarter of the sub-contacts of a settled running-bond wall). It
    /// must agree exactly with `update` ([`conformance::check`] tests it); the default, `false`,
    /// never skips.
    #[inline]
    fn stays_open(&self, _area: Real, _normal_displacement: Real, _state: &Self::State) -> bool {
        false
    }

    /// The law's linear elastic regime in the virgin state, if it has one: then, for a
    /// sub-contact whose state equals `State::default()`, whenever [`ElasticRegime::trial`]
    /// returns forces, [`ConstitutiveLaw::update`] must set exactly those forces (bit for bit),
    /// leave the state unchanged and return [`JointStatus::Elastic`].
    ///
    /// The contact kernel then updates such sub-contacts (in compression, below their strength:
    /// most of a masonry structure at rest) in a tight loop without calling `update`, and falls
    /// back to `update` for the others. The default, `None`, always calls `update`.
    /// [`conformance::check`] tests the promise over a grid of steps.
    #[inline]
    fn elastic_regime(&self) -> Option<ElasticRegime> {
        None
    }

    /// Elastic energy stored in the joint springs (J), never negative. The default assumes linear
    /// springs with the stiffness of [`ConstitutiveLaw::stiffness`]; a sub-contact without
    /// area (or a law without stiffness) has no springs and stores nothing.
    fn elastic_energy(&self, area: Real, force: &JointForce, _state: &Self::State) -> Real {
        let k = self.stiffness();
        let mut e = 0.0;
        if area.is_nan() || area <= 0.0 {
            return 0.0;
        }
        if k.normal > 0.0 {
            e += 0.5 * force.normal * force.normal / (k.normal * area);
        }
        if k.shear > 0.0 {
            e += 0.5 * force.shear.length_squared() / (k.shear * area);
        }
        e
    }

    /// The fracture energy a step consumed at a sub-contact of area `area` whose state went
    /// from `before` to `after` (J): the part of the step's dissipation that is the work
    /// against softening strengths (a tensile strength or a cohesion falling with the crack's
    /// opening or slip), which voussoir books as [`crate::model::Energies::fracture`] instead of
    /// [`crate::model::Energies::friction`]. Asked only for steps that change the state; never
    /// negative. The default, for laws that do not soften, is 0.
    ///
    /// The contact kernel books the step's dissipation (see `docs/custom-law.md`,
    /// "Dissipation") and takes this part of it for `fracture`, never more than the step
    /// dissipated in all (a sub-contact that comes into being beyond its strength cracks
    /// without work and books none); the rest stays with `friction`.
    #[inline]
    fn fracture_work(&self, _area: Real, _before: &Self::State, _after: &Self::State) -> Real {
        0.0
    }

    /// The state a node of a node contact (vertex–face, edge–edge, edge–face, tilted faces)
    /// starts from. The bond of a mortared or cemented joint (tensile strength, cohesion) acts
    /// across the faces of a joint; a node contact is a touch at a vertex or an edge, whose
    /// nodes stand for a share of the faces only to make a penalty, so it starts unbonded:
    /// compression and the residual friction, no tension, no cohesion (`docs/theory.md` §2.2,
    /// "Node contacts"). A bond across the common edge of two blocks that meet only there (the
    /// diagonal neighbours where four blocks of a stack-bonded wall meet) would hold them
    /// together by a force whose direction flips between the other block's two faces at that
    /// edge.
    ///
    /// The default, `State::default()`, is right for laws without a bond; a law with one
    /// returns its fully debonded state.
    fn unbonded_state(&self) -> Self::State {
        Self::State::default()
    }

    /// Whether the sub-contact has failed (lost cohesion or tensile strength), for output.
    fn is_failed(&self, _state: &Self::State) -> bool {
        false
    }

    /// Checks the law's parameters.
    ///
    /// # Errors
    /// [`crate::Error::InvalidParameter`] naming the bad parameter.
    fn validate(&self) -> Result<()> {
        Ok(())
    }
}

/// A law's own validation, and a stiffness the critical step can rest on (finite, not
/// negative).
pub(crate) fn check_law<L: ConstitutiveLaw>(law: &L) -> Result<()> {
    law.validate()?;
    let k = law.stiffness();
    crate::error::non_negative("stiffness().normal", k.normal)?;
    crate::error::non_negative("stiffness().shear", k.shear)?;
    Ok(())
}
