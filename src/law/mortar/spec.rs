//! The serialised form of [`MortarJoint`] (scenes, checkpoints).

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

use super::{CompressionCap, MortarJoint, Softening};
use crate::error::{Error, Result};
use crate::math::Real;

/// The serialised form of [`MortarJoint`]: angles in degrees, validated on load. A strength
/// given without its fracture energy is refused (write 0 for a brittle joint).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
// Named as the law it reads: checkpoints store the law type by its serde name.
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, rename = "MortarJoint"))]
pub(super) struct MortarSpec {
    /// Pa/m.
    normal_stiffness: Real,
    /// Pa/m.
    shear_stiffness: Real,
    friction_deg: Real,
    /// The initial friction angle when absent.
    #[cfg_attr(feature = "serde", serde(default))]
    residual_friction_deg: Option<Real>,
    /// Pa.
    #[cfg_attr(feature = "serde", serde(default))]
    tensile_strength: Real,
    /// J/m²; required with a tensile strength.
    #[cfg_attr(feature = "serde", serde(default))]
    mode_i_fracture_energy: Option<Real>,
    /// Pa.
    #[cfg_attr(feature = "serde", serde(default))]
    cohesion: Real,
    /// J/m²; required with a cohesion.
    #[cfg_attr(feature = "serde", serde(default))]
    mode_ii_fracture_energy: Option<Real>,
    #[cfg_attr(feature = "serde", serde(default))]
    dilatancy_deg: Real,
    #[cfg_attr(feature = "serde", serde(default))]
    softening: Softening,
    /// The stress above which earlier versions flagged a sub-contact (Pa): read from old files
    /// and dropped (it changed no force), never written.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing))]
    compressive_strength: Option<Real>,
    /// The crushing cap, if any.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Option::is_none"))]
    compression_cap: Option<CompressionCap>,
}

/// The fracture energy of a strength read from a file: required when the strength is not zero.
fn fracture_energy(name: &str, strength: Real, energy: Option<Real>) -> Result<Real> {
    match energy {
        Some(g) => Ok(g),
        None if strength == 0.0 => Ok(0.0),
        None => Err(Error::InvalidParameter {
            name: name.to_owned(),
            value: Real::NAN,
            expected: "must be given with its strength (0 for a brittle joint)",
        }),
    }
}

impl TryFrom<MortarSpec> for MortarJoint {
    type Error = Error;
    fn try_from(s: MortarSpec) -> Result<Self> {
        let g_i = fracture_energy("mode_i_fracture_energy", s.tensile_strength, s.mode_i_fracture_energy)?;
        let g_ii = fracture_energy("mode_ii_fracture_energy", s.cohesion, s.mode_ii_fracture_energy)?;
        let mut builder = MortarJoint::builder(s.normal_stiffness, s.shear_stiffness, s.friction_deg)
            .residual_friction(s.residual_friction_deg.unwrap_or(s.friction_deg))
            .tension(s.tensile_strength, g_i)
            .cohesion(s.cohesion, g_ii)
            .dilatancy(s.dilatancy_deg)
            .softening(s.softening);
        if let Some(cap) = s.compression_cap {
            builder = builder.compression_cap(cap);
        }
        builder.build()
    }
}

impl From<MortarJoint> for MortarSpec {
    fn from(l: MortarJoint) -> Self {
        Self {
            normal_stiffness: l.normal_stiffness,
            shear_stiffness: l.shear_stiffness,
            friction_deg: l.friction_deg,
            residual_friction_deg: Some(l.residual_friction_deg),
            tensile_strength: l.tensile_strength,
            mode_i_fracture_energy: Some(l.mode_i_fracture_energy),
            cohesion: l.cohesion,
            mode_ii_fracture_energy: Some(l.mode_ii_fracture_energy),
            dilatancy_deg: l.dilatancy_deg,
            softening: l.softening,
            compressive_strength: None,
            compression_cap: l.cap,
        }
    }
}
