//! Coulomb slip with tension cut-off, cohesion and residual friction (3DEC's joint model).

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

use super::{ConstitutiveLaw, ElasticRegime, JointForce, JointStatus, JointStep, JointStiffness};
use crate::error::{in_range, non_negative, positive, Result};
use crate::math::{Real, Vector2};

/// Coulomb slip joint.
///
/// Per sub-contact of area `A`, with `u_n` the normal displacement (positive = opening):
///
/// * normal: `F_n = -kn·A·u_n`; if `F_n < -f_t·A` the joint fails in tension and `F_n = F_s = 0`;
/// * shear (incremental): `F_s ← F_s - ks·A·Δu_s`, capped at `c·A + F_n·tan φ`;
/// * failure in tension or shear sets cohesion and tensile strength to zero and `φ` to `φ_r`.
///
/// The constructors take angles in degrees and validate every parameter; the accessors return
/// radians.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(try_from = "CoulombSpec", into = "CoulombSpec"))]
pub struct CoulombSlip {
    normal_stiffness: Real,
    shear_stiffness: Real,
    /// Degrees, as given (so that serialisation round-trips exactly).
    friction_deg: Real,
    residual_friction_deg: Real,
    cohesion: Real,
    tensile_strength: Real,
    /// `tan φ`, `tan φ_r`, cached out of the hot loop.
    tan_friction: Real,
    tan_residual: Real,
}

/// The serialised form of [`CoulombSlip`]: angles in degrees, validated on load.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
// Named as the law it reads: checkpoints store the law type by its serde name.
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, rename = "CoulombSlip"))]
struct CoulombSpec {
    /// Pa/m.
    normal_stiffness: Real,
    /// Pa/m.
    shear_stiffness: Real,
    friction_deg: Real,
    residual_friction_deg: Real,
    /// Pa.
    #[cfg_attr(feature = "serde", serde(default))]
    cohesion: Real,
    /// Pa.
    #[cfg_attr(feature = "serde", serde(default))]
    tensile_strength: Real,
}

impl TryFrom<CoulombSpec> for CoulombSlip {
    type Error = crate::Error;
    fn try_from(s: CoulombSpec) -> Result<Self> {
        CoulombSlip::new(
            s.normal_stiffness,
            s.shear_stiffness,
            s.friction_deg,
            s.residual_friction_deg,
            s.cohesion,
            s.tensile_strength,
        )
    }
}

impl From<CoulombSlip> for CoulombSpec {
    fn from(l: CoulombSlip) -> Self {
        Self {
            normal_stiffness: l.normal_stiffness,
            shear_stiffness: l.shear_stiffness,
            friction_deg: l.friction_deg,
            residual_friction_deg: l.residual_friction_deg,
            cohesion: l.cohesion,
            tensile_strength: l.tensile_strength,
        }
    }
}

/// Per-sub-contact history of [`CoulombSlip`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct CoulombState {
    /// Cohesion and tensile strength lost, residual friction active.
    pub failed: bool,
}

impl CoulombSlip {
    /// A dry joint (no cohesion, no tension), residual friction equal to the initial one.
    ///
    /// # Errors
    /// [`crate::Error::InvalidParameter`] for non-positive stiffness or a friction angle outside
    /// `[0°, 90°)`.
    pub fn dry(kn: Real, ks: Real, friction_deg: Real) -> Result<Self> {
        Self::new(kn, ks, friction_deg, friction_deg, 0.0, 0.0)
    }

    /// The full law: stiffness (Pa/m), initial and residual friction (degrees), cohesion and
    /// tensile strength (Pa).
    ///
    /// # Errors
    /// [`crate::Error::InvalidParameter`] naming the first bad value.
    pub fn new(
        kn: Real,
        ks: Real,
        friction_deg: Real,
        residual_friction_deg: Real,
        cohesion: Real,
        tensile_strength: Real,
    ) -> Result<Self> {
        let law = Self {
            normal_stiffness: kn,
            shear_stiffness: ks,
            friction_deg,
            residual_friction_deg,
            cohesion,
            tensile_strength,
            tan_friction: friction_deg.to_radians().tan(),
            tan_residual: residual_friction_deg.to_radians().tan(),
        };
        law.validate()?;
        Ok(law)
    }

    /// Normal stiffness `kn` (Pa/m).
    pub fn normal_stiffness(&self) -> Real {
        self.normal_stiffness
    }
    /// Shear stiffness `ks` (Pa/m).
    pub fn shear_stiffness(&self) -> Real {
        self.shear_stiffness
    }
    /// Initial friction angle `φ` (rad).
    pub fn friction_angle(&self) -> Real {
        self.friction_deg.to_radians()
    }
    /// Residual friction angle `φ_r` (rad).
    pub fn residual_friction_angle(&self) -> Real {
        self.residual_friction_deg.to_radians()
    }
    /// Cohesion `c` (Pa).
    pub fn cohesion(&self) -> Real {
        self.cohesion
    }
    /// Tensile strength `f_t` (Pa).
    pub fn tensile_strength(&self) -> Real {
        self.tensile_strength
    }
}

impl ConstitutiveLaw for CoulombSlip {
    type State = CoulombState;

    #[inline]
    fn stiffness(&self) -> JointStiffness {
        JointStiffness {
            normal: self.normal_stiffness,
            shear: self.shear_stiffness,
        }
    }

    #[inline]
    fn update(&self, s: &JointStep, f: &mut JointForce, state: &mut CoulombState) -> JointStatus {
        let a = s.area;
        f.normal = -self.normal_stiffness * s.normal_displacement * a;
        let (tensile, cohesion, tan_phi) = if state.failed {
            (0.0, 0.0, self.tan_residual)
        } else {
            (self.tensile_strength, self.cohesion, self.tan_friction)
        };
        // Open: beyond the tensile strength of a bonded joint; no compression for a joint without
        // tensile strength (a dry one, or a failed one), touching included: at zero gap it
        // carries no force, and no shear strength without cohesion.
        let open = if tensile == 0.0 {
            f.normal <= 0.0
        } else {
            f.normal < -tensile * a
        };
        if open {
            if f.normal < 0.0 && tensile > 0.0 {
                state.failed = true;
            }
            f.normal = 0.0;
            f.shear = Vector2::ZERO;
            return JointStatus::Open;
        }
        f.shear -= s.shear_increment * (self.shear_stiffness * a);
        let limit = cohesion * a + f.normal * tan_phi;
        // `|F_s| > limit`, without a square root while the joint sticks.
        let trial_squared = f.shear.length_squared();
        if limit < 0.0 || trial_squared > limit * limit {
            let trial = trial_squared.sqrt();
            f.shear *= if trial > 0.0 { limit.max(0.0) / trial } else { 0.0 };
            if cohesion > 0.0 || tensile > 0.0 || self.tan_residual != self.tan_friction {
                state.failed = true;
            }
            return JointStatus::Sliding;
        }
        JointStatus::Elastic
    }

    /// The open test of [`CoulombSlip::update`], evaluated the same way: true for a joint
    /// without tensile strength (failed, or intact with none) and without compression; false
    /// for an intact joint with tensile strength (opening it is a failure, a change of state).
    #[inline]
    fn stays_open(&self, area: Real, normal_displacement: Real, state: &CoulombState) -> bool {
        let normal = -self.normal_stiffness * normal_displacement * area;
        (state.failed || self.tensile_strength == 0.0) && normal <= 0.0
    }

    /// Intact joint in compression below its strength: `c` and `tan φ` (peak values); sliding
    /// too when nothing fails as it slides (no cohesion, no tensile strength, residual friction
    /// equal to the peak: a dry joint).
    #[inline]
    fn elastic_regime(&self) -> Option<ElasticRegime> {
        Some(ElasticRegime {
            normal_stiffness: self.normal_stiffness,
            shear_stiffness: self.shear_stiffness,
            cohesion: self.cohesion,
            tan_friction: self.tan_friction,
            slides: self.cohesion == 0.0 && self.tensile_strength == 0.0 && self.tan_residual == self.tan_friction,
            // Compression only: a bonded joint in tension goes through `update`.
            tensile_strength: 0.0,
        })
    }

    /// Failed, for a bonded joint (with cohesion or tensile strength): residual friction, no
    /// tension, no cohesion. A dry joint's virgin state.
    fn unbonded_state(&self) -> CoulombState {
        CoulombState {
            failed: self.cohesion > 0.0 || self.tensile_strength > 0.0,
        }
    }

    fn is_failed(&self, state: &CoulombState) -> bool {
        state.failed
    }

    fn validate(&self) -> Result<()> {
        positive("normal_stiffness", self.normal_stiffness)?;
        positive("shear_stiffness", self.shear_stiffness)?;
        in_range(
            "friction_angle",
            self.friction_deg,
            0.0,
            90.0,
            "must lie in [0, 90) degrees",
        )?;
        in_range(
            "residual_friction_angle",
            self.residual_friction_deg,
            0.0,
            90.0,
            "must lie in [0, 90) degrees",
        )?;
        non_negative("cohesion", self.cohesion)?;
        non_negative("tensile_strength", self.tensile_strength)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use super::super::JointAxes;
    use crate::math::Vector;

    fn step(un: Real, dus: Vector2) -> JointStep {
        JointStep {
            area: 1.0,
            normal_displacement: un,
            normal_increment: 0.0,
            shear_increment: dus,
            axes: JointAxes::from_normal(Vector::Z),
            dt: 1.0,
        }
    }

    #[test]
    fn slip_caps_shear_at_friction_and_cohesion_is_lost_at_failure() {
        let law = CoulombSlip::new(1e9, 1e9, 30.0, 20.0, 1e5, 5e4).unwrap();
        let mut f = JointForce::default();
        let mut s = CoulombState::default();
        // Compressed by 1e-4 m: N = 1e5 N.
        assert_eq!(
            law.update(&step(-1e-4, Vector2::ZERO), &mut f, &mut s),
            JointStatus::Elastic
        );
        // Push 1 mm in x: trial 1e6 N > c + N tan 30 = 1e5 + 5.77e4.
        assert_eq!(
            law.update(&step(-1e-4, Vector2::new(1e-3, 0.0)), &mut f, &mut s),
            JointStatus::Sliding
        );
        let cap = 1e5 + 1e5 * 30f64.to_radians().tan();
        assert!((f.shear.x + cap).abs() < 1e-6, "{f:?}");
        assert!(s.failed);
        // Now residual: cap = N tan 20.
        law.update(&step(-1e-4, Vector2::new(1e-3, 0.0)), &mut f, &mut s);
        assert!((f.shear.x + 1e5 * 20f64.to_radians().tan()).abs() < 1e-6);
    }

    #[test]
    fn tension_cut_off_and_failure() {
        // With cohesion, so that tension does not exhaust the shear strength (c·A + F_n·tan φ > 0).
        let law = CoulombSlip::new(1e9, 1e9, 30.0, 30.0, 1e5, 5e4).unwrap();
        let mut f = JointForce::default();
        let mut s = CoulombState::default();
        // 4e-5 m opening: tension 4e4 < 5e4, carried.
        assert_eq!(
            law.update(&step(4e-5, Vector2::ZERO), &mut f, &mut s),
            JointStatus::Elastic
        );
        assert!((f.normal + 4e4).abs() < 1e-6);
        assert_eq!(
            law.update(&step(6e-5, Vector2::ZERO), &mut f, &mut s),
            JointStatus::Open
        );
        assert!(s.failed && f.normal == 0.0);
        // Once failed, no tension at all.
        assert_eq!(
            law.update(&step(1e-6, Vector2::ZERO), &mut f, &mut s),
            JointStatus::Open
        );
    }

    fn laws() -> [CoulombSlip; 3] {
        [
            CoulombSlip::dry(4e9, 1.6e9, 30.0).unwrap(),
            CoulombSlip::new(4e9, 1.6e9, 35.0, 25.0, 2e5, 0.0).unwrap(),
            CoulombSlip::new(1e9, 1e9, 30.0, 20.0, 1e5, 5e4).unwrap(),
        ]
    }

    /// Dry, cohesive and bonded joints keep the law contract (`elastic_regime` and `stays_open`
    /// agree with `update`, see [`crate::law::conformance`]), and offer both shortcuts.
    #[test]
    fn conforms_to_the_law_contract() {
        for law in laws() {
            let report = crate::law::conformance::check(&law).unwrap_or_else(|e| panic!("{law:?}: {e}"));
            assert!(report.regime_stood > 1000 && report.open_promised > 100, "{report:?}");
        }
    }

    /// The elastic regime is the whole elastic domain of a virgin joint in compression: where
    /// the trial declines, `update` ends open, sliding, or elastic without compression (a bonded
    /// joint in tension). (Where it stands, `update` agrees bit for bit: the conformance check.)
    /// Over a grid of displacements around the open and slip limits (both signs of zero
    /// included), from shear forces at, inside and beyond the strength.
    #[test]
    fn elastic_regime_covers_the_elastic_domain_in_compression() {
        let gaps = [-1e-3, -2.5e-5, -1e-9, -1e-300, -0.0, 0.0, 1e-12, 4e-5];
        let increments = [0.0, 1e-9, 3e-6, -2e-5, 1e-4];
        let (mut stood, mut declined) = (0, 0);
        for (l, law) in laws().iter().enumerate() {
            let regime = law.elastic_regime().expect("regime");
            for &gap in &gaps {
                for &du in &increments {
                    for &carried in &[0.0, 7.5e3, -4.1e4, 1.2e5] {
                        let area = 0.37;
                        let (shear, increment) = (Vector2::new(carried, -0.3 * carried), Vector2::new(du, 0.6 * du));
                        if regime.trial(area, gap, increment, shear).is_some() {
                            stood += 1;
                            continue;
                        }
                        declined += 1;
                        let step = JointStep {
                            area,
                            ..step(gap, increment)
                        };
                        let mut f = JointForce { normal: 1.0, shear };
                        let status = law.update(&step, &mut f, &mut CoulombState::default());
                        assert!(
                            status != JointStatus::Elastic || f.normal <= 0.0,
                            "law {l}, gap {gap}, du {du}: {status:?} {f:?}"
                        );
                    }
                }
            }
        }
        assert!(stood > 100 && declined > 100, "{stood} {declined}");
    }

    /// A dry joint that just touches (zero gap, either sign of zero) carries nothing and is
    /// open, whatever shear it carried and however it moves along the joint: no compression,
    /// no strength. A bonded one holds there (zero normal force is within its tensile
    /// strength) and keeps its cohesive shear strength.
    #[test]
    fn a_dry_joint_touching_at_zero_gap_is_open_and_carries_nothing() {
        for gap in [0.0, -0.0] {
            for du in [0.0, 2e-6] {
                let mut f = JointForce {
                    normal: 50.0,
                    shear: Vector2::new(20.0, -5.0),
                };
                let mut state = CoulombState::default();
                let status = laws()[0].update(&step(gap, Vector2::new(du, 0.0)), &mut f, &mut state);
                assert_eq!(
                    (status, f.normal, f.shear),
                    (JointStatus::Open, 0.0, Vector2::ZERO),
                    "{gap} {du}"
                );
                assert!(!state.failed);
                assert!(laws()[0].stays_open(0.01, gap, &state));
            }
        }
        let bonded = laws()[2];
        let mut f = JointForce::default();
        let status = bonded.update(
            &step(0.0, Vector2::new(1e-9, 0.0)),
            &mut f,
            &mut CoulombState::default(),
        );
        assert_eq!(status, JointStatus::Elastic);
        assert!(f.shear.x < 0.0);
    }

    /// `stays_open` promises for separated dry and failed joints, not for intact bonded ones
    /// (opening them is a failure). (That `update` keeps the promise: the conformance check.)
    #[test]
    fn stays_open_promises_for_dry_and_failed_joints() {
        let gaps = [-1e-3, -1e-9, -0.0, 0.0, 1e-300, 1e-12, 4e-5, 6e-5, 1.0];
        let mut promised = [0usize; 3];
        for (l, law) in laws().iter().enumerate() {
            for failed in [false, true] {
                for &gap in &gaps {
                    if law.stays_open(1.0, gap, &CoulombState { failed }) {
                        promised[l] += 1;
                    }
                }
            }
        }
        // Dry joints: every gap that is not negative (zero included: touching, no force),
        // intact or failed.
        assert_eq!(promised[0], 7 + 7);
        // The bonded joint only once failed.
        assert_eq!(promised[2], 7);
        assert!(!laws()[2].stays_open(1.0, 1.0, &CoulombState { failed: false }));
    }

    #[test]
    fn bad_parameters_are_named() {
        let e = CoulombSlip::dry(4e9, 1.6e9, 95.0).unwrap_err();
        assert!(e.to_string().contains("friction_angle"), "{e}");
        let e = CoulombSlip::dry(-1.0, 1.6e9, 30.0).unwrap_err();
        assert!(e.to_string().contains("normal_stiffness"), "{e}");
        let e = CoulombSlip::new(1e9, 1e9, 30.0, 30.0, Real::NAN, 0.0).unwrap_err();
        assert!(e.to_string().contains("cohesion"), "{e}");
    }
}
