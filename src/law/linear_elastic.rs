//! Linear elastic joint: springs with no strength limit (tension and shear unbounded).

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

use super::{ConstitutiveLaw, ElasticRegime, JointForce, JointStatus, JointStep, JointStiffness};
use crate::error::{positive, Result};

/// Linear normal and shear springs with no limit: `σ = -kn·u_n`, `τ̇ = -ks·u̇_s`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct LinearElastic {
    /// Normal stiffness (Pa/m).
    pub normal_stiffness: f64,
    /// Shear stiffness (Pa/m).
    pub shear_stiffness: f64,
}

impl ConstitutiveLaw for LinearElastic {
    type State = ();

    #[inline]
    fn stiffness(&self) -> JointStiffness {
        JointStiffness {
            normal: self.normal_stiffness,
            shear: self.shear_stiffness,
        }
    }

    #[inline]
    fn update(&self, s: &JointStep, f: &mut JointForce, _: &mut ()) -> JointStatus {
        f.normal = -self.normal_stiffness * s.normal_displacement * s.area;
        f.shear -= s.shear_increment * (self.shear_stiffness * s.area);
        JointStatus::Elastic
    }

    /// In compression the law is its elastic regime with no shear limit (`tan φ = ∞`).
    #[inline]
    fn elastic_regime(&self) -> Option<ElasticRegime> {
        Some(ElasticRegime {
            normal_stiffness: self.normal_stiffness,
            shear_stiffness: self.shear_stiffness,
            cohesion: 0.0,
            tan_friction: f64::INFINITY,
            slides: false,
            tensile_strength: 0.0,
        })
    }

    fn validate(&self) -> Result<()> {
        positive("normal_stiffness", self.normal_stiffness)?;
        positive("shear_stiffness", self.shear_stiffness)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vector2;

    /// The law keeps the contract ([`crate::law::conformance`]): in compression the
    /// trial of its elastic regime is `update`, bit for bit, whatever the shear.
    #[test]
    fn conforms_to_the_law_contract() {
        let law = LinearElastic {
            normal_stiffness: 3e9,
            shear_stiffness: 1.2e9,
        };
        let report = crate::law::conformance::check(&law).expect("conforms");
        assert!(report.regime_stood > 1000 && report.open_promised == 0, "{report:?}");
    }

    /// The regime declines exactly without compression (there `update` carries tension), and
    /// never for the shear: there is no shear limit.
    #[test]
    fn elastic_regime_declines_only_without_compression() {
        let law = LinearElastic {
            normal_stiffness: 3e9,
            shear_stiffness: 1.2e9,
        };
        let regime = law.elastic_regime().expect("regime");
        for gap in [-1e-3, -1e-9, -0.0, 0.0, 1e-6] {
            for du in [0.0, 1e-7, -5e-3] {
                let stands = regime
                    .trial(0.2, gap, Vector2::new(du, 2.0 * du), Vector2::new(1e6, -2e3))
                    .is_some();
                assert_eq!(stands, gap < 0.0, "{gap} {du}");
            }
        }
    }
}
