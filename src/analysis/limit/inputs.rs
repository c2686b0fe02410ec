//! What a limit analysis takes: the joints' strengths ([`JointStrength`], from a law through
//! [`LimitStrength`]), the friction model, the solver's options and the live loads.

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

use crate::block::BlockId;
use crate::error::{non_negative, Result};
use crate::law::{AnyLaw, CoulombSlip, LinearElastic};
use crate::math::{Real, Vector};

/// The strength of a joint in limit analysis: the Coulomb cone `‖t‖ ≤ μ n + c A` over its area
/// `A`, with no tension.
///
/// ```
/// use voussoir::analysis::limit::JointStrength;
/// let s = JointStrength::from_degrees(30.5, 0.0)?;
/// assert!((s.friction - 30.5f64.to_radians().tan()).abs() < 1e-15);
/// assert!(JointStrength::new(-0.1, 0.0).is_err());
/// # Ok::<(), voussoir::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct JointStrength {
    /// Friction coefficient `μ = tan φ`.
    pub friction: Real,
    /// Cohesion `c` (Pa), shared equally by the polygon's corners.
    pub cohesion: Real,
}

impl JointStrength {
    /// A joint with friction coefficient `μ` and cohesion `c` (Pa).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`](crate::Error::InvalidParameter) for a negative or non-finite value.
    pub fn new(friction: Real, cohesion: Real) -> Result<Self> {
        Ok(Self {
            friction: non_negative("limit analysis friction coefficient", friction)?,
            cohesion: non_negative("limit analysis cohesion", cohesion)?,
        })
    }

    /// A joint with friction angle `φ` (degrees, in `[0°, 90°)`) and cohesion `c` (Pa).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`](crate::Error::InvalidParameter) for an angle outside `[0°, 90°)` or a bad cohesion.
    pub fn from_degrees(friction_deg: Real, cohesion: Real) -> Result<Self> {
        crate::error::in_range(
            "limit analysis friction angle (degrees)",
            friction_deg,
            0.0,
            90.0,
            "must lie in [0°, 90°)",
        )?;
        Self::new(friction_deg.to_radians().tan(), cohesion)
    }
}

/// Joint laws that know their strength for limit analysis.
///
/// [`CoulombSlip`] gives its (initial) friction angle and cohesion — the intact joint's; its
/// tensile strength is left out (no tension). A law with no strength limit
/// ([`LinearElastic`]) gives `None`, and [`LimitProblem::from_model`](super::LimitProblem::from_model) refuses its contacts; give
/// their strength with [`LimitProblem::from_model_with`](super::LimitProblem::from_model_with).
pub trait LimitStrength {
    /// The joint's strength, or `None` when the law has no strength limit.
    fn limit_strength(&self) -> Option<JointStrength>;
}

impl LimitStrength for CoulombSlip {
    fn limit_strength(&self) -> Option<JointStrength> {
        Some(JointStrength {
            friction: self.friction_angle().tan(),
            cohesion: self.cohesion(),
        })
    }
}

impl LimitStrength for LinearElastic {
    fn limit_strength(&self) -> Option<JointStrength> {
        None
    }
}

impl LimitStrength for AnyLaw {
    fn limit_strength(&self) -> Option<JointStrength> {
        match self {
            AnyLaw::Coulomb(law) => law.limit_strength(),
            AnyLaw::Mortar(law) => law.limit_strength(),
            AnyLaw::Elastic(law) => law.limit_strength(),
        }
    }
}

/// How the Coulomb cone is imposed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub enum FrictionModel {
    /// The exact cone `‖t‖ ≤ μ n + c A/m`, a second-order cone (the default).
    #[default]
    Cone,
    /// A pyramid of `facets` planes (at least 3) inscribed in the cone, the first facing the
    /// joint's first tangent: `t·d_k ≤ cos(π/facets) (μ n + c A/m)`. A linear programme whose
    /// answer is a lower bound of the cone's, by at most `1 − cos(π/facets)` (1.9 % at 16
    /// facets) when the joint slides.
    Pyramid {
        /// Number of planes.
        facets: usize,
    },
}

/// Settings of a limit analysis.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct LimitOptions {
    /// Cone or pyramid. Default: the cone.
    pub friction: FrictionModel,
    /// Also check that the dead loads alone are carried (`λ = 0` admissible), a second solve
    /// of the same size. Default `true`. Without it a structure that stands only when pushed by
    /// the live load gets its largest multiplier without complaint.
    pub check_dead_load: bool,
    /// Interior-point iteration limit. Default 200 (Clarabel's).
    pub max_iterations: u32,
}

impl Default for LimitOptions {
    fn default() -> Self {
        Self {
            friction: FrictionModel::Cone,
            check_dead_load: true,
            max_iterations: 200,
        }
    }
}

/// A live load: the force `λ · force` on `block` at `point`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct LiveLoad {
    /// The loaded block.
    pub block: BlockId,
    /// Where the force acts (m, world).
    pub point: Vector,
    /// The force per unit multiplier (N): with a unit vector, `λ` is in newtons.
    pub force: Vector,
}
