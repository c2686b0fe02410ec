//! Time integration: the [`Integrator`] trait, central difference with local (Cundall), Rayleigh
//! or no damping, and the critical time step.
#![doc = include_str!("README.md")]

mod central_difference;
mod damping;
mod time_step;

pub use central_difference::CentralDifference;
pub use damping::Damping;
pub use time_step::{critical_time_step, CriticalStep, Stiffness6, StiffnessBound, TimeStep};

use crate::block::{RigidBlock, Wrench};
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

/// One step of the equations of motion for all blocks (or, for a
/// [blockwise](Integrator::is_blockwise) integrator, for a chunk of them).
///
/// `forces[i]` is the total force and moment on `blocks[i]` (gravity, applied loads and contacts;
/// damping is the integrator's business); `records[i]` receives what happened to it, which the
/// model's energy balance reads. Implementations must give the same result whatever the
/// number of threads.
///
/// # Example
///
/// An explicit integrator of one's own, here a wrapper that caps the translational speed after
/// central difference; it advances each block on its own, so it says so and the model calls it
/// chunk by chunk from its block pass. The record's mean velocity follows the capped velocity
/// (the energy the cap removes is not booked as damping: the balance shows it as an error).
///
/// ```
/// use voussoir::integrate::StepRecord;
/// use voussoir::prelude::*;
///
/// #[derive(Debug, Clone, Copy)]
/// struct Capped(CentralDifference, Real);
///
/// impl Integrator for Capped {
///     fn advance(&self, blocks: &mut [RigidBlock], forces: &[Wrench], dt: Real, records: &mut [StepRecord]) {
///         self.0.advance(blocks, forces, dt, records);
///         for (b, r) in blocks.iter_mut().zip(records.iter_mut()) {
///             let v = b.state().velocity;
///             if v.length() > self.1 {
///                 let capped = v * (self.1 / v.length());
///                 let before = 2.0 * r.mean_velocity - v;
///                 r.mean_velocity = 0.5 * (before + capped);
///                 b.state_mut().velocity = capped;
///             }
///         }
///     }
///     fn is_blockwise(&self) -> bool {
///         true
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
/// # Ok::<(), voussoir::Error>(())
/// ```
pub trait Integrator: Send + Sync + std::fmt::Debug {
    /// Advances velocities to `t + dt/2` and poses to `t + dt`, filling `records`.
    fn advance(&self, blocks: &mut [RigidBlock], forces: &[Wrench], dt: Real, records: &mut [StepRecord]);

    /// One step of a variable step: the velocities get the impulse of the forces over `kick`
    /// (`½(Δt_{n−½} + Δt_{n+½})`, the time the force of level `n` stands for), the poses move
    /// by the new velocities over `drift` (`Δt_{n+½}`). The model calls this every step;
    /// `kick == drift` whenever the step did not change.
    ///
    /// The default calls [`advance`](Self::advance) with `drift`, which is first order at the
    /// steps where the step changes (the model changes it around impacts, see
    /// `ModelParameters::impact_step`); [`CentralDifference`] implements it exactly.
    fn advance_variable(
        &self,
        blocks: &mut [RigidBlock],
        forces: &[Wrench],
        kick: Real,
        drift: Real,
        records: &mut [StepRecord],
    ) {
        let _ = kick;
        self.advance(blocks, forces, drift, records);
    }

    /// Whether [`advance`](Self::advance) treats each block on its own: a block's new state and
    /// record depend only on that block, its force and `dt`, as in any explicit scheme.
    ///
    /// The model then calls `advance` on consecutive chunks of blocks from its own parallel pass
    /// over the blocks, between gathering the chunk's forces and booking its energy, while the
    /// chunk is in cache (one sweep through the blocks per step instead of four). `blocks`,
    /// `forces` and `records` are then the chunk's, indexed from its first block. Results are
    /// the same either way. Default `false`: one call with all the blocks.
    fn is_blockwise(&self) -> bool {
        false
    }

    /// The damping model (the contact code adds the stiffness-proportional dashpots).
    fn damping(&self) -> Damping;

    /// A boxed copy (for cloning models).
    fn boxed_clone(&self) -> Box<dyn Integrator>;
}

impl Clone for Box<dyn Integrator> {
    fn clone(&self) -> Self {
        self.boxed_clone()
    }
}
