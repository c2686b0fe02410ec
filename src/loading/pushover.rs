//! A capacity driver: a block pushed by a [`Servo`] until the load it applies has peaked and
//! fallen (3DEC's load-capacity run), with the load–travel curve at the settled states.

use std::ops::ControlFlow;

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

use super::Servo;
use crate::block::Block;
use crate::error::{positive, Error, Result};
use crate::law::ConstitutiveLaw;
use crate::math::Real;
use crate::model::Model;

/// A push-over: [`PushOver::servo`] drives its block; at the settled states, every
/// [`PushOver::sample_travel`] of travel along the servo's direction, the load the block applies
/// to what it touches (the sum of its contact forces, along the direction) is recorded; the
/// run stops when the travel reaches [`PushOver::max_travel`], or once the load (averaged over
/// [`PushOver::smoothing_window`] of travel) has stayed below [`PushOver::stop_fraction`] of
/// its peak for [`PushOver::fallen_travel`] after the peak.
///
/// # Example
/// A block pushed sideways by a frictionless pusher slides when the push reaches the base
/// joint's friction, `tan φ · W`.
/// ```
/// use voussoir::loading::{PushOver, Servo};
/// use voussoir::prelude::*;
///
/// let mut model: Model = Model::new(ModelParameters::default())?;
/// model.set_joint_law(MaterialId(0), MaterialId(0), CoulombSlip::dry(1e9, 4e8, 30.0)?)?;
/// model.set_joint_law(MaterialId(0), MaterialId(1), CoulombSlip::dry(1e9, 4e8, 0.0)?)?;
/// model.set_damping(Damping::Local { alpha: 0.8 })?;
/// model.add_block(
///     RigidBlock::cuboid("base", Vector::new(-1.0, -1.0, -0.2), Vector::new(1.0, 1.0, 0.0), 2500.0)?
///         .with_fixity(Fixity::FIXED),
/// )?;
/// let block = model.add_block(RigidBlock::cuboid("block", Vector::ZERO, Vector::new(0.2, 0.2, 0.2), 2500.0)?)?;
/// let pusher = model.add_block(
///     RigidBlock::cuboid("pusher", Vector::new(-0.1, 0.05, 0.05), Vector::new(0.0, 0.15, 0.15), 2500.0)?
///         .with_material(MaterialId(1))
///         .with_fixity(Fixity::velocity(Vector::ZERO)),
/// )?;
/// model.run_to_equilibrium(1e-5, 100_000)?;
/// let push = PushOver {
///     max_travel: 1e-3,
///     ..PushOver::new(Servo::new(pusher, Vector::X, 2e-6, 1e-3)?)
/// };
/// let r = push.run(&mut model, 10_000_000, |_, _| std::ops::ControlFlow::Continue(()))?;
/// let weight = 2500.0 * 0.008 * 9.81;
/// assert!((r.peak_load / (30f64.to_radians().tan() * weight) - 1.0).abs() < 0.02, "{}", r.peak_load);
/// # let _ = block;
/// # Ok::<(), voussoir::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PushOver {
    /// The servo that drives the block.
    pub servo: Servo,
    /// The travel at which the run stops (m).
    pub max_travel: Real,
    /// Stop once the load has stayed below this fraction of its peak (after the peak) for
    /// [`PushOver::fallen_travel`]; 0 never stops on the load.
    pub stop_fraction: Real,
    /// How long the load must stay below [`PushOver::stop_fraction`] of its peak (m of travel).
    pub fallen_travel: Real,
    /// The travel between two samples of the curve (m); one at or below the servo's increment
    /// samples the first settled state after every advance.
    pub sample_travel: Real,
    /// The travel over which the load is averaged for the peak (m); 0: the peak of the settled
    /// states themselves (which scatter about the curve by the servo's threshold).
    pub smoothing_window: Real,
}

/// One point of a push-over curve, at a settled state.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct PushOverSample {
    /// The model's time (s).
    pub time: Real,
    /// The model's step.
    pub step: u64,
    /// The block's travel along the servo's direction since the run began (m).
    pub travel: Real,
    /// The force the block applies along the direction (N): the sum of its contact forces.
    pub load: Real,
    /// `load` averaged over the last [`PushOver::smoothing_window`] of travel.
    pub smoothed_load: Real,
}

/// Why a push-over stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub enum PushOverStop {
    /// The travel reached [`PushOver::max_travel`].
    MaxTravel,
    /// The load fell below [`PushOver::stop_fraction`] of its peak for
    /// [`PushOver::fallen_travel`].
    Fallen,
    /// The sample callback stopped it.
    Callback,
    /// The step budget ran out.
    MaxSteps,
}

/// The answer of [`PushOver::run`].
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct PushOverResult {
    /// The curve at the settled states.
    pub curve: Vec<PushOverSample>,
    /// The peak of the smoothed load (N): the capacity.
    pub peak_load: Real,
    /// The travel at that peak (m; the middle of its window).
    pub travel_at_peak: Real,
    /// The peak of the load itself (N).
    pub raw_peak_load: Real,
    /// Why the run stopped.
    pub stop: PushOverStop,
}

impl PushOver {
    /// A push-over by `servo` to 10 mm of travel, stopping once the load has stayed below half
    /// its peak for 50 increments, sampled every increment, not averaged.
    pub fn new(servo: Servo) -> Self {
        Self {
            servo,
            max_travel: 0.01,
            stop_fraction: 0.5,
            fallen_travel: 50.0 * servo.increment,
            sample_travel: servo.increment,
            smoothing_window: 0.0,
        }
    }

    fn check(&self) -> Result<()> {
        positive("push-over max_travel", self.max_travel)?;
        positive("push-over sample_travel", self.sample_travel)?;
        for (name, value) in [
            ("push-over fallen_travel", self.fallen_travel),
            ("push-over smoothing_window", self.smoothing_window),
        ] {
            if !(value >= 0.0 && value.is_finite()) {
                return Err(Error::InvalidParameter {
                    name: name.into(),
                    value,
                    expected: "must be zero or positive, and finite",
                });
            }
        }
        if !(0.0..1.0).contains(&self.stop_fraction) {
            return Err(Error::InvalidParameter {
                name: "push-over stop_fraction".into(),
                value: self.stop_fraction,
                expected: "must lie in [0, 1)",
            });
        }
        Ok(())
    }

    /// Runs the push-over on `model` for at most `max_steps` steps; `on_sample` sees each sample
    /// (and the model) as it is taken and may stop the run.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a bad setting; [`Error::Unsupported`] for a model
    /// without a free block (nothing for the servo to wait for); then as [`Servo::run`].
    pub fn run<L: ConstitutiveLaw>(
        &self,
        model: &mut Model<L>,
        max_steps: u64,
        mut on_sample: impl FnMut(&Model<L>, &PushOverSample) -> ControlFlow<()>,
    ) -> Result<PushOverResult> {
        self.check()?;
        // The servo advances only from settled states, judged on the free blocks; with none,
        // every state would count as settled and the samples would catch the joints ringing.
        if !model.blocks().iter().any(|b| b.is_free()) {
            return Err(Error::Unsupported {
                what: format!(
                    "push-over of block {} in a model without a free block: the servo waits for the free blocks to \
                     settle; push a loading device (a plate seated on the structure) rather than the only block \
                     that moves",
                    self.servo.block
                ),
            });
        }
        let block = self.servo.block;
        let start = model.block(block)?.state().pose.translation;
        let direction = self.servo.direction;
        let mut curve: Vec<PushOverSample> = Vec::new();
        let (mut next, mut peak, mut at_peak, mut raw_peak) = (0.0, Real::NEG_INFINITY, 0.0, Real::NEG_INFINITY);
        let (mut window_start, mut window_sum) = (0usize, 0.0);
        let mut fallen_since: Option<Real> = None;
        let mut stop = PushOverStop::MaxSteps;
        let servo = self.servo;
        let mut observer = |m: &Model<L>| -> Result<ControlFlow<()>> {
            if !servo.settled(m) {
                return Ok(ControlFlow::Continue(()));
            }
            let travel = (m.blocks()[block.index()].state().pose.translation - start).dot(direction);
            if travel < next {
                return Ok(ControlFlow::Continue(()));
            }
            next = travel + self.sample_travel;
            let load = -m.contact_wrench(block)?.force.dot(direction);
            curve.push(PushOverSample {
                time: m.time(),
                step: m.step_count(),
                travel,
                load,
                smoothed_load: load,
            });
            window_sum += load;
            while curve[window_start].travel < travel - self.smoothing_window {
                window_sum -= curve[window_start].load;
                window_start += 1;
            }
            let n = curve.len() - window_start;
            let smoothed = window_sum / n as Real;
            let last = curve.len() - 1;
            curve[last].smoothed_load = smoothed;
            raw_peak = raw_peak.max(load);
            if smoothed > peak {
                peak = smoothed;
                at_peak = 0.5 * (travel + curve[window_start].travel);
            }
            let sample = curve[last];
            if on_sample(m, &sample) == ControlFlow::Break(()) {
                stop = PushOverStop::Callback;
                return Ok(ControlFlow::Break(()));
            }
            if travel >= self.max_travel {
                stop = PushOverStop::MaxTravel;
                return Ok(ControlFlow::Break(()));
            }
            let below = peak > 0.0 && smoothed < self.stop_fraction * peak && travel > at_peak;
            fallen_since = if below {
                Some(fallen_since.unwrap_or(travel))
            } else {
                None
            };
            if self.stop_fraction > 0.0 && fallen_since.is_some_and(|since| travel - since >= self.fallen_travel) {
                stop = PushOverStop::Fallen;
                return Ok(ControlFlow::Break(()));
            }
            Ok(ControlFlow::Continue(()))
        };
        self.servo.run(model, max_steps, &mut observer)?;
        Ok(PushOverResult {
            curve,
            peak_load: if peak.is_finite() { peak } else { 0.0 },
            travel_at_peak: at_peak,
            raw_peak_load: if raw_peak.is_finite() { raw_peak } else { 0.0 },
            stop,
        })
    }
}
