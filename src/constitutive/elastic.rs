//! Linear elastic joint: springs with no strength limit (tension and shear unbounded).

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

use super::{ConstitutiveLaw, ElasticRegime, JointForce, JointStatus, JointStep, JointStiffness};
use crate::error::{positive, Result};

/// Linear normal and shear springs with no limit: `σ = -kn·u_n`, `τ̇ = -ks·u̇_s`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
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
    use crate::constitutive::JointAxes;
    use crate::math::{Vector, Vector2};

    /// In compression the trial of the elastic regime is `update`, bit for bit, whatever the
    /// shear; in tension `update` carries it and the trial declines.
    #[test]
    fn elastic_regime_agrees_with_update_bit_for_bit() {
        let law = LinearElastic {
            normal_stiffness: 3e9,
            shear_stiffness: 1.2e9,
        };
        let regime = law.elastic_regime().expect("regime");
        for gap in [-1e-3, -1e-9, -0.0, 0.0, 1e-6] {
            for du in [0.0, 1e-7, -5e-3] {
                let (area, shear, increment) = (0.2, Vector2::new(1e6, -2e3), Vector2::new(du, 2.0 * du));
                let step = JointStep {
                    area,
                    normal_displacement: gap,
                    normal_increment: 0.0,
                    shear_increment: increment,
                    axes: JointAxes::from_normal(Vector::Z),
                    dt: 1e-5,
                };
                let mut f = JointForce { normal: 0.0, shear };
                assert_eq!(law.update(&step, &mut f, &mut ()), JointStatus::Elastic);
                match regime.trial(area, gap, increment, shear) {
                    Some(trial) => {
                        assert!(gap < 0.0);
                        assert_eq!(trial, f);
                    }
                    None => assert!(gap >= 0.0, "{gap}"),
                }
            }
        }
    }
}
