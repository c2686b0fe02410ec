//! The next step's length (the step's stage between the contact pass and the block pass):
//! `dt`, shortened around impacts by the impact refinement ([`ModelParameters::impact_step`]),
//! then cut so that the fastest block moves at most half the contact tolerance.
//!
//! [`ModelParameters::impact_step`]: crate::model::ModelParameters::impact_step

use super::contact_pass::CONTACT_CHUNK;
use crate::integrate::TimeStep;
use crate::law::ConstitutiveLaw;
use crate::math::Real;
use crate::model::{ModelState, Pipeline};

/// The fraction of the contact tolerance that an automatic step lets the fastest block move
/// (estimated from the speeds at the end of the last step and gravity): half, so that a speed
/// that doubles within a step still moves no block further than the tolerance, beyond which a
/// contact could be missed and the run stops ([`Error::StepTooLong`](crate::Error::StepTooLong)).
const STEP_TRAVEL: Real = 0.5;

impl<L: ConstitutiveLaw> ModelState<L> {
    /// The step to take from the current poses, `Δt_{n+½}`, given the largest squared frequency
    /// bound of the blocks whose contacts are about to close or open fast (0: none) and whether
    /// a loaded impacting contact moves fast (`busy`): `dt`, or, from an impact,
    /// `impact_step × 2/ω` for the fastest block that asked for it, until the refinement's hold
    /// (three of that block's critical steps after the last probe that fired, which spans the
    /// middle of a flat impact, where the sub-contacts are deep and the probe is quiet) has
    /// passed and none of the contacts the probe marked is both loaded and fast. The step thus
    /// changes while the impacting contacts are open, or once the motion is quiet.
    pub(in crate::model) fn next_drift(&mut self, pipeline: &Pipeline<L::State>, impact: Real, busy: bool) -> Real {
        let (Some(r), TimeStep::Auto { .. }) = (self.params.impact_step, self.params.time_step) else {
            return self.clock.dt;
        };
        if impact > 0.0 {
            self.clock.refine_travel |= pipeline.pair_sums.iter().any(|s| s.node_impact);
            let hold = 3.0 * 2.0 / impact.sqrt();
            self.clock.refine_until = self.clock.refine_until.max(self.clock.time + hold);
            self.clock.refine_omega2 = self.clock.refine_omega2.max(impact);
            for (k, s) in pipeline.pair_sums.iter().enumerate() {
                if s.fired_count as usize <= s.fired.len() {
                    self.clock
                        .refining
                        .extend_from_slice(&s.fired[..s.fired_count as usize]);
                } else {
                    let end = ((k + 1) * CONTACT_CHUNK).min(self.contacts.pairs.len());
                    self.clock
                        .refining
                        .extend(self.contacts.pairs[k * CONTACT_CHUNK..end].iter().map(|p| (p.a, p.b)));
                }
            }
            self.clock.refining.sort_unstable();
            self.clock.refining.dedup();
        }
        if self.clock.refine_omega2 > 0.0 && (self.clock.time < self.clock.refine_until || busy) {
            self.clock.dt.min(r * 2.0 / self.clock.refine_omega2.sqrt())
        } else {
            self.clock.refine_omega2 = 0.0;
            self.clock.refine_travel = false;
            self.clock.refining.clear();
            self.clock.dt
        }
    }

    /// `drift` cut, with an automatic step ([`TimeStep::Auto`]), so that the fastest block moves
    /// at most [`STEP_TRAVEL`] of the contact tolerance: `d` with `v d + g d² = STEP_TRAVEL ×
    /// tolerance`, `v` a bound of the largest speed at the end of the last step
    /// ([`speed_bound`](super::block_pass::speed_bound)), `g` the gravity (central difference moves a block by its velocity
    /// after the kick, `(v + g d) d`). A fixed step is not cut (the block pass stops the run
    /// instead).
    pub(in crate::model) fn cap_drift(&self, pipeline: &mut Pipeline<L::State>, drift: Real) -> Real {
        if !matches!(self.params.time_step, TimeStep::Auto { .. }) {
            return drift;
        }
        let v = *pipeline.max_speed.get_or_insert_with(|| self.max_move_speed());
        // While a node contact's impact is being resolved, the travel too: a kink of a node's
        // potential inside the other block (its normal turning to another face) is crossed at
        // the relative speed, by steps as short as a spring's kink is.
        let refine = match self.params.impact_step {
            Some(r) if self.clock.refine_omega2 > 0.0 && self.clock.refine_travel => r,
            _ => 1.0,
        };
        let c = STEP_TRAVEL * refine * self.params.contact.tolerance;
        let a = self.params.gravity.length();
        let root = v + (v * v + 4.0 * a * c).sqrt();
        if root > 0.0 {
            drift.min(2.0 * c / root)
        } else {
            drift
        }
    }
}
