//! Time integration: the [`Integrator`] trait, central difference with local (Cundall), Rayleigh
//! or no damping, and the critical time step.
#![doc = include_str!("README.md")]

mod central_difference;
mod critical_step;
mod damping;
mod stability;

pub use central_difference::CentralDifference;
pub use critical_step::{critical_time_step, CriticalStep, Stiffness6, StiffnessBound, TimeStep, DEFAULT_SAFETY};
pub use damping::Damping;

pub(crate) use stability::{
    block_bound, block_side, bound_from_sides, contact_eigenvalues, AreaMoments, ContactStiffness,
};

use crate::block::{Block, BlockState, Fixity, RigidBlock, Wrench};
use crate::geometry::MassProperties;
use crate::math::{Real, Vector};

/// What an integrator reports for one block and one step.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StepRecord {
    /// Force and moment the constraints applied to the constrained degrees of freedom.
    pub reaction: Wrench,
    /// Damping force and moment applied this step (local or mass-proportional).
    pub damping: Wrench,
    /// Mean of the old and new velocity (m/s): the velocity at the integer time level.
    pub mean_velocity: Vector,
    /// Mean of the old and new angular velocity (rad/s).
    pub mean_angular_velocity: Vector,
}

/// The two durations of a step of central difference (s): the velocities get the impulse of
/// the forces over `kick` (`½(Δt_{n−½} + Δt_{n+½})`, the time the force of level `n` stands
/// for), the poses move by the new velocities over `drift` (`Δt_{n+½}`). `kick == drift`
/// whenever the step did not change (the model changes it around impacts, see
/// `ModelParameters::impact_step`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepDurations {
    /// Time the forces act over (s).
    pub kick: Real,
    /// Time the poses move over (s).
    pub drift: Real,
}

impl StepDurations {
    /// A constant step `dt`.
    pub fn constant(dt: Real) -> Self {
        Self { kick: dt, drift: dt }
    }
}

/// The equations of motion of one block, and their stability limit.
///
/// An integrator advances each block on its own, from its state, mass, fixity and the total
/// wrench on it (gravity, applied load and contacts; damping is the integrator's business), as
/// any explicit scheme does: the model calls it from its parallel pass over the blocks, between
/// gathering a chunk's forces and booking its energy, while the chunk is in cache. It also owns
/// its stability limit ([`critical_step`](Self::critical_step)), which the model evaluates
/// whenever contacts change.
///
/// # Example
///
/// An explicit integrator of one's own, here a wrapper that caps the translational speed after
/// central difference. The record's mean velocity follows the capped velocity (the energy the
/// cap removes is not booked as damping: the balance shows it as an error).
///
/// ```
/// use voussoir::block::BlockState;
/// use voussoir::geometry::MassProperties;
/// use voussoir::integrate::{StepDurations, StepRecord};
/// use voussoir::prelude::*;
///
/// #[derive(Debug, Clone, Copy)]
/// struct Capped(CentralDifference, Real);
///
/// impl Integrator for Capped {
///     fn advance_block(
///         &self,
///         state: &mut BlockState,
///         mass: &MassProperties,
///         fixity: &Fixity,
///         wrench: &Wrench,
///         step: StepDurations,
///     ) -> StepRecord {
///         let mut r = self.0.advance_block(state, mass, fixity, wrench, step);
///         let v = state.velocity;
///         if v.length() > self.1 {
///             let capped = v * (self.1 / v.length());
///             let before = 2.0 * r.mean_velocity - v;
///             r.mean_velocity = 0.5 * (before + capped);
///             state.velocity = capped;
///         }
///         r
///     }
///     fn damping(&self) -> Damping {
///         self.0.damping()
///     }
///     fn boxed_clone(&self) -> Box<dyn Integrator> {
///         Box::new(*self)
///     }
/// }
///
/// let mut model: Model = Model::new(ModelParameters::default())?;
/// let brick = RigidBlock::cuboid("brick", Vector::ZERO, Vector::new(0.2, 0.1, 0.05), 2000.0)?;
/// model.add_block(brick)?;
/// model.set_integrator(Capped(CentralDifference::new(Damping::None), 0.01))?;
/// model.run_steps(100)?;
/// assert!((model.blocks()[0].state().velocity.length() - 0.01).abs() < 1e-12);
/// // A checkpoint cannot restore a custom integrator: it says so rather than swap it.
/// assert!(model.to_checkpoint_string().is_err());
/// # Ok::<(), voussoir::Error>(())
/// ```
pub trait Integrator: Send + Sync + std::fmt::Debug {
    /// Advances one block's velocities by `step.kick` and its pose by `step.drift`, holding
    /// its fixed and prescribed degrees of freedom as `fixity` says, and reports the reaction
    /// of the constraints, the damping applied and the mean velocities over the step.
    /// The result must not depend on anything but the arguments.
    fn advance_block(
        &self,
        state: &mut BlockState,
        mass: &MassProperties,
        fixity: &Fixity,
        wrench: &Wrench,
        step: StepDurations,
    ) -> StepRecord;

    /// Advances a chunk of blocks (`wrenches[i]` on `blocks[i]`, records to `records[i]`).
    /// The default calls [`advance_block`](Self::advance_block) for each; an implementation may
    /// override it with a faster loop that gives the same bits.
    fn advance_chunk(
        &self,
        blocks: &mut [RigidBlock],
        wrenches: &[Wrench],
        step: StepDurations,
        records: &mut [StepRecord],
    ) {
        for ((b, w), r) in blocks.iter_mut().zip(wrenches).zip(records) {
            let (mass, fixity) = (b.mass_properties(), *b.fixity());
            *r = self.advance_block(b.state_mut(), &mass, &fixity, w, step);
        }
    }

    /// The critical step of the model whose blocks have the given bounds of their squared
    /// natural frequency, and the block that sets it (`None` without any stiffness).
    ///
    /// The default is that of central difference with this integrator's damping:
    /// [`critical_time_step`] with the stiffness-proportional coefficient, shortened by
    /// `1/√(1 + α)` under local damping of coefficient `α` (local damping turns a force that
    /// opposes the motion into `(1 + α)·F`: in those half-cycles the joints act `1 + α` times
    /// stiffer; without this, a block resting on a base never settles at a safety factor above
    /// 0.745).
    fn critical_step(&self, bounds: &[StiffnessBound]) -> Option<CriticalStep> {
        let damping = self.damping();
        critical_time_step(bounds, damping.stiffness_coefficient()).map(|mut c| {
            if let Damping::Local { alpha } = damping {
                c.dt /= (1.0 + alpha).sqrt();
            }
            c
        })
    }

    /// The damping model (the contact code adds the stiffness-proportional dashpots).
    fn damping(&self) -> Damping;

    /// A boxed copy (for cloning models).
    fn boxed_clone(&self) -> Box<dyn Integrator>;

    /// What a checkpoint needs to restore this integrator: `Some(damping)` for
    /// [`CentralDifference`], `None` (the default) for an integrator a checkpoint cannot
    /// rebuild, which [`crate::Model::to_checkpoint_string`] then refuses to save.
    fn checkpoint_damping(&self) -> Option<Damping> {
        None
    }
}

impl Clone for Box<dyn Integrator> {
    fn clone(&self) -> Self {
        self.boxed_clone()
    }
}
