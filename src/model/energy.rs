//! Energy bookkeeping: every term is accumulated independently so that their balance tests the
//! whole engine.

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

use crate::math::Real;

/// Energies and works since the start of the run (J).
///
/// Balance: `kinetic + elastic + friction + fracture + damping = initial_kinetic + gravity_work +
/// load_work + boundary_work`. `kinetic` is evaluated at integer time levels as `½·m·v⁻·v⁺` (the product of
/// the half-step velocities either side, the quantity central difference conserves; it differs
/// from `½·m·v̄²` by `⅛·m·|v⁺ − v⁻|²`); works are each force times the displacement of the step,
/// by the trapezoidal rule, so that the balance is exact for translation; `elastic` is the energy stored
/// in the joint springs; `friction` and `fracture` are what the joint laws dissipated: at every
/// sub-contact step that slid or changed the law's state (failure, softening), the work done on
/// its springs less the change of their elastic energy, of which the law's fracture work
/// ([`crate::law::ConstitutiveLaw::fracture_work`]: the work against softening strengths, such
/// as [`crate::law::MortarJoint`]'s) goes to `fracture` and the rest to `friction`. Elastic and
/// open steps dissipate nothing, so with a frictionless law `friction` stays zero, and
/// `balance_error` measures what the time integration and the discretisation of the joints did
/// not conserve.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct Energies {
    /// Kinetic energy (J).
    pub kinetic: Real,
    /// Kinetic energy before the first step, plus any given later with [`crate::Model::set_velocity`] (J).
    pub initial_kinetic: Real,
    /// Elastic energy in the joint springs (J).
    pub elastic: Real,
    /// Work of gravity (J).
    pub gravity_work: Real,
    /// Work of applied loads (J).
    pub load_work: Real,
    /// Work of the supports and prescribed velocities (J).
    pub boundary_work: Real,
    /// Energy dissipated by slip and joint failure (J): accumulated from the laws' inelastic
    /// steps, never from a balance; their fracture work apart.
    pub friction: Real,
    /// Fracture energy the joints consumed as they cracked and softened (J): the laws'
    /// [`fracture_work`](crate::law::ConstitutiveLaw::fracture_work) at their inelastic steps
    /// (`G_f·A` for a [`MortarJoint`](crate::law::MortarJoint) cracked through over an area
    /// `A`). Zero for laws that do not soften. Absent from checkpoints written before it
    /// existed, which load with 0.
    #[cfg_attr(feature = "serde", serde(default))]
    pub fracture: Real,
    /// Energy dissipated by damping: local, Rayleigh mass part and contact dashpots (J).
    pub damping: Real,
    /// Total work done on the joint springs (J): the elastic energy plus `friction` and
    /// `fracture` plus what the time integration and the joints' discretisation did not
    /// conserve.
    pub joint_work: Real,
}

impl Energies {
    /// Energy put in: initial kinetic energy plus the work of gravity, loads and supports (J).
    pub fn input(&self) -> Real {
        self.initial_kinetic + self.gravity_work + self.load_work + self.boundary_work
    }

    /// Energy accounted for: kinetic, elastic, friction, fracture and damping (J).
    pub fn accounted(&self) -> Real {
        self.kinetic + self.elastic + self.friction + self.damping + self.fracture
    }

    /// `accounted − input` (J); zero for a perfect integrator.
    pub fn balance_error(&self) -> Real {
        self.accounted() - self.input()
    }
}
