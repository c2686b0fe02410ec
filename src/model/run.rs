//! Stepping and running a model: [`Model::step`] and the run loops built on it (a number of
//! steps, until a time, until a condition, to equilibrium). The runs that call an
//! [`Observer`](super::Observer) after every step are in `observe.rs`.

use super::Model;
use crate::error::{positive, Error, Result};
use crate::law::ConstitutiveLaw;
use crate::math::Real;

impl<L: ConstitutiveLaw> Model<L> {
    /// One step.
    ///
    /// # Errors
    /// [`Error::EmptyModel`] for a model without blocks; [`Error::InitialOverlap`] at the
    /// first step for blocks that overlap by more than the contact tolerance;
    /// [`Error::MissingJointLaw`] when blocks of materials with no law touch;
    /// [`Error::TimeStepTooLarge`] for a fixed step above the critical one;
    /// [`Error::Diverged`] naming the step and block when the state becomes non-finite or runaway;
    /// [`Error::Interrupted`] when the interrupt check ([`Model::set_interrupt_check`]) says to
    /// stop, asked before the step (at most every 20 ms of wall-clock time, so that every long
    /// run, servo wait or push-over honours it) and between the batches of a contact detection.
    pub fn step(&mut self) -> Result<()> {
        if self.pipeline.interrupt_due() {
            return Err(Error::Interrupted {
                step: self.state.clock.step,
            });
        }
        self.state.step(&mut self.pipeline)
    }

    /// Runs `n` steps.
    ///
    /// # Errors
    /// As [`Model::step`].
    pub fn run_steps(&mut self, n: u64) -> Result<()> {
        for _ in 0..n {
            self.step()?;
        }
        Ok(())
    }

    /// Runs until the simulated time reaches `t` (s).
    ///
    /// # Errors
    /// [`Error::NonFinite`] for a NaN or infinite `t`; otherwise as [`Model::step`].
    pub fn run_until_time(&mut self, t: Real) -> Result<()> {
        if !t.is_finite() {
            return Err(Error::NonFinite {
                what: format!("end time {t} of run_until_time"),
            });
        }
        while self.state.clock.time < t {
            self.step()?;
        }
        Ok(())
    }

    /// Runs until `done(model)` returns true (checked after each step) or `max_steps` steps;
    /// returns whether the condition was met.
    ///
    /// # Errors
    /// As [`Model::step`].
    pub fn run_until(&mut self, max_steps: u64, mut done: impl FnMut(&Self) -> bool) -> Result<bool> {
        for _ in 0..max_steps {
            self.step()?;
            if done(self) {
                return Ok(true);
            }
        }
        Ok(false)
    }

    /// Runs until the unbalanced-force ratio falls below `target`; returns the steps taken.
    ///
    /// # Errors
    /// [`Error::NotConverged`] after `max_steps`; [`Error::Unsupported`] at once for a model in
    /// which no block has a free degree of freedom (all fixed or driven: nothing to bring to
    /// equilibrium, and the run took all its steps to say "last value inf");
    /// otherwise as [`Model::step`].
    pub fn run_to_equilibrium(&mut self, target: Real, max_steps: u64) -> Result<u64> {
        positive("equilibrium target ratio", target)?;
        let held = |b: &crate::block::RigidBlock| {
            let f = crate::block::Block::fixity(b);
            f.translation
                .iter()
                .chain(&f.rotation)
                .all(|d| *d != crate::block::Dof::Free)
        };
        if !self.state.blocks.is_empty() && self.state.blocks.iter().all(held) {
            return Err(Error::Unsupported {
                what: "run_to_equilibrium on a model in which no block has a free degree of freedom: nothing is free, so there \
                       is no unbalanced force to bring down (free a block, or step with run_steps)"
                    .into(),
            });
        }
        for k in 1..=max_steps {
            self.step()?;
            if self.state.unbalanced_ratio < target {
                return Ok(k);
            }
        }
        Err(Error::NotConverged {
            what: "unbalanced-force ratio target",
            steps: max_steps,
            last: self.state.unbalanced_ratio,
        })
    }
}
