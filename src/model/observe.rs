//! Observing runs: what a run calls after every step, so that sampling, logging, progress and
//! stopping conditions live outside the model ([`crate::monitor::Recorder`] is one).

use std::ops::ControlFlow;

use super::Model;
use crate::error::Result;
use crate::law::ConstitutiveLaw;
use crate::math::Real;

/// What a run calls after each step: a recorder, a progress bar, a stopping condition. Return
/// `ControlFlow::Break(())` to stop the run, an error to abort it.
///
/// Closures observe too:
///
/// ```
/// use std::ops::ControlFlow;
/// use voussoir::prelude::*;
///
/// let mut model: Model = Model::new(ModelParameters::default())?;
/// let stone = model.add_block(RigidBlock::cuboid("stone", Vector::ZERO, Vector::splat(0.1), 2500.0)?)?;
/// // Fall until 10 mm below the start.
/// let mut lowest = f64::INFINITY;
/// let stopped = model.run_observed(100_000, &mut |m: &Model| {
///     let z = m.blocks()[stone.index()].state().pose.translation.z;
///     lowest = lowest.min(z);
///     Ok(if z < 0.04 { ControlFlow::Break(()) } else { ControlFlow::Continue(()) })
/// })?;
/// assert!(stopped && lowest < 0.04);
/// # Ok::<(), voussoir::Error>(())
/// ```
pub trait Observer<L: ConstitutiveLaw> {
    /// Called after each step of an observed run.
    ///
    /// # Errors
    /// Any error aborts the run and is returned by it.
    fn after_step(&mut self, model: &Model<L>) -> Result<ControlFlow<()>>;
}

impl<L, F> Observer<L> for F
where
    L: ConstitutiveLaw,
    F: FnMut(&Model<L>) -> Result<ControlFlow<()>>,
{
    fn after_step(&mut self, model: &Model<L>) -> Result<ControlFlow<()>> {
        self(model)
    }
}

impl<L: ConstitutiveLaw> Model<L> {
    /// Runs up to `max_steps` steps, calling `observer` after each; returns whether the
    /// observer stopped the run.
    ///
    /// # Errors
    /// As [`Model::step`], or the observer's error.
    pub fn run_observed(&mut self, max_steps: u64, observer: &mut impl Observer<L>) -> Result<bool> {
        for _ in 0..max_steps {
            self.step()?;
            if observer.after_step(self)?.is_break() {
                return Ok(true);
            }
        }
        Ok(false)
    }

    /// Runs `n` steps (fewer if the observer stops the run), calling `observer` after each.
    ///
    /// # Errors
    /// As [`Model::run_observed`].
    pub fn run_steps_observed(&mut self, n: u64, observer: &mut impl Observer<L>) -> Result<()> {
        self.run_observed(n, observer).map(|_| ())
    }

    /// Runs until the simulated time reaches `t` (s) or the observer stops the run, calling
    /// `observer` after each step; returns whether the observer stopped it.
    ///
    /// # Errors
    /// [`crate::Error::NonFinite`] for a NaN or infinite `t`; otherwise as
    /// [`Model::run_observed`].
    pub fn run_until_time_observed(&mut self, t: Real, observer: &mut impl Observer<L>) -> Result<bool> {
        if !t.is_finite() {
            return Err(crate::error::Error::NonFinite {
                what: format!("end time {t} of run_until_time_observed"),
            });
        }
        while self.state.clock.time < t {
            self.step()?;
            if observer.after_step(self)?.is_break() {
                return Ok(true);
            }
        }
        Ok(false)
    }
}
