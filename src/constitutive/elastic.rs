//! Linear elastic joint: springs with no strength limit (tension and shear unbounded).

use serde::{Deserialize, Serialize};

use super::{ConstitutiveLaw, JointForce, JointStatus, JointStep, JointStiffness};
use crate::error::{positive, Result};

/// Linear normal and shear springs with no limit: `σ = -kn·u_n`, `τ̇ = -ks·u̇_s`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
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

    fn validate(&self) -> Result<()> {
        positive("normal_stiffness", self.normal_stiffness)?;
        positive("shear_stiffness", self.shear_stiffness)?;
        Ok(())
    }
}
