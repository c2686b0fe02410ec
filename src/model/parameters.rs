//! The model's global parameters: [`ModelParameters`], their defaults and their validation.

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

use crate::contact::DisplacementMode;
use crate::error::{positive, Error, Result};
use crate::geometry::ContactParameters;
use crate::integrate::TimeStep;
use crate::math::{is_finite_vector, Real, Vector};

/// Global parameters of a model, with documented defaults.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(default, deny_unknown_fields))]
pub struct ModelParameters {
    /// Gravitational acceleration (m/s²). Default `(0, 0, −9.81)`.
    pub gravity: Vector,
    /// Contact detection and discretisation.
    pub contact: ContactParameters,
    /// Time step choice. Default automatic at 0.5 of the critical step.
    pub time_step: TimeStep,
    /// Large (default) or small displacements.
    pub mode: DisplacementMode,
    /// A block faster than this (m/s) means the run has diverged. Default 1000 m/s.
    pub max_speed: Real,
    /// Impact-resolving step: with an automatic step, while a sub-contact is about to close or
    /// open fast (an impact, a release), the step is refined to this fraction of the critical
    /// step of the blocks involved, and relaxed back once their contacts no longer cross the
    /// spring's kink (`docs/theory.md` §5.4). Default `Some(0.1)`; `None` keeps the step.
    pub impact_step: Option<Real>,
}

/// How the step advances a face-face joint that is closed all over and sticks (every cell in
/// its law's elastic regime, none sliding), or open all over with its cells unloaded: as a
/// whole, or cell by cell
/// ([`Model::set_joint_stepping`](crate::Model::set_joint_stepping), `docs/theory.md` §3.1).
///
/// Both give the same forces and poses to round-off; as a whole, such a joint costs a few dozen
/// operations a step whatever its number of sub-contacts, and its sub-contacts are not read or
/// written until it opens or slips (or a reader, an output or a checkpoint asks for them).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub enum JointStepping {
    /// A closed, sticking joint is stepped as a whole (the default).
    #[default]
    Whole,
    /// Every sub-contact is stepped by itself, every step (for comparison).
    Cells,
}

impl Default for ModelParameters {
    fn default() -> Self {
        Self {
            gravity: Vector::new(0.0, 0.0, -9.81),
            contact: ContactParameters::default(),
            time_step: TimeStep::default(),
            mode: DisplacementMode::Large,
            max_speed: 1e3,
            impact_step: Some(0.1),
        }
    }
}

impl ModelParameters {
    /// Checks every field.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] or [`Error::NonFinite`] naming the field.
    pub fn validate(&self) -> Result<()> {
        if !is_finite_vector(self.gravity) {
            return Err(Error::NonFinite { what: "gravity".into() });
        }
        self.contact.validate()?;
        match self.time_step {
            TimeStep::Auto { safety } => {
                crate::error::in_range("time_step.safety", safety, 1e-6, 1.0 + 1e-12, "must lie in (0, 1]")?;
            }
            TimeStep::Fixed(dt) => {
                positive("time_step", dt)?;
            }
        }
        positive("max_speed", self.max_speed)?;
        if let Some(r) = self.impact_step {
            crate::error::in_range("impact_step", r, 1e-6, 1.0 + 1e-12, "must lie in (0, 1]")?;
        }
        Ok(())
    }
}
