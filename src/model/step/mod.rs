//! The step: its stages in order, each a method of the model's state given the pipeline's
//! scratch it uses (`docs/architecture.md`).

// The stages, in the step's order (`docs/architecture.md`, "The step").
pub(super) mod block_pass;
pub(super) mod changes;
pub(super) mod contact_pass;
pub(super) mod detection;
pub(super) mod step_length;
pub(super) mod time_step;
// The stages' scratch.
pub(super) mod pipeline;

use self::changes::Changes;
use crate::block::{Block, BlockId};
use crate::contact::DisplacementMode;
use crate::error::{Error, Result};
use crate::law::ConstitutiveLaw;
use crate::math::Real;
use crate::model::Pipeline;
use crate::model::{is_finite_state, ModelState};

impl<L: ConstitutiveLaw> ModelState<L> {
    /// One step: the stages in order, each given the state and the pipeline it uses.
    pub(in crate::model) fn step(&mut self, pipeline: &mut Pipeline<L::State>) -> Result<()> {
        if self.blocks.is_empty() {
            return Err(Error::EmptyModel);
        }
        let started = std::time::Instant::now();
        let large = self.params.mode == DisplacementMode::Large;
        // The changes since the last step come first: any of them asks for a full detection,
        // and makes what the last block pass prepared possibly stale.
        let changed = self.changes.need_full_detection();
        let moved = match pipeline.detection.prepared.take() {
            Some(moved) if self.clock.started && !changed => moved,
            _ => self.prepare_blocks(pipeline, large && self.clock.started && !changed),
        };
        if !self.clock.started {
            self.start(pipeline)?;
        } else if large {
            // A block whose fixity changed is looked at as if it had moved.
            let refixed = !changed && !self.refixed.is_empty();
            if refixed {
                let flags = &mut pipeline.detection.moved;
                flags.resize(self.blocks.len(), false);
                for &i in &self.refixed {
                    flags[i as usize] = true;
                }
            }
            if changed || moved || refixed {
                self.detect(pipeline)?;
            }
        } else if changed && self.changes.contains(Changes::PARAMETERS) {
            // New contact parameters, or a switch from large displacements: every contact found
            // afresh, so that the geometry small displacements keep is that of this instant for
            // every contact (after large displacements, each contact's reference was its own
            // last detection's).
            self.detect(pipeline)?;
        } else if changed {
            // Small displacements keep the contact geometry they found: only the step is
            // re-evaluated.
            self.refresh_time_step(pipeline)?;
            self.changes.clear();
        }
        self.refixed.clear();
        let first = self.clock.drift == 0.0;
        if first {
            // The first step: the initial velocities stand for those of the half step before.
            self.clock.drift = self.clock.dt;
        }
        let detected = std::time::Instant::now();
        let (impact, busy) = self.contact_pass(pipeline);
        let previous = self.clock.drift;
        let drift = self.next_drift(pipeline, impact, busy);
        // No block may move further than the contact tolerance in one step.
        let drift = self.cap_drift(pipeline, drift);
        // The first step's half step before is as long as the step itself (also when cut).
        let previous = if first { previous.min(drift) } else { previous };
        self.apply_base_motions(drift);
        self.apply_load_histories();
        let forces = std::time::Instant::now();
        let (diverged, too_far) = self.block_pass(pipeline, 0.5 * (previous + drift), drift);
        self.clock.drift = drift;
        let t = &mut pipeline.timings;
        t.detection += (detected - started).as_secs_f64();
        t.contacts += (forces - detected).as_secs_f64();
        t.integration += forces.elapsed().as_secs_f64();
        t.steps += 1;
        self.clock.step += 1;
        self.clock.time += drift;
        if let Some(i) = diverged {
            return Err(self.divergence_error(i));
        }
        if let Some((i, distance)) = too_far {
            return Err(self.too_far_error(i, distance, drift));
        }
        Ok(())
    }

    /// Blocks that start overlapping by more than the contact tolerance are an error: the joint
    /// springs would push them apart with the energy of the whole overlap, which no physical
    /// state holds (two cubes overlapping by half used to fly apart at 107 m/s).
    fn check_initial_overlap(&self) -> Result<()> {
        let tolerance = self.params.contact.tolerance;
        for p in &self.contacts.pairs {
            let depth = -self.contacts.subs[p.range()]
                .iter()
                .map(|s| s.gap)
                .fold(Real::INFINITY, Real::min);
            if depth > tolerance {
                return Err(Error::InitialOverlap {
                    a: BlockId(p.a),
                    b: BlockId(p.b),
                    depth,
                    tolerance,
                });
            }
        }
        Ok(())
    }

    fn start(&mut self, pipeline: &mut Pipeline<L::State>) -> Result<()> {
        self.params.validate()?;
        self.integrator.damping().validate()?;
        self.changes.insert(Changes::DETECTION);
        self.detect(pipeline)?;
        self.check_initial_overlap()?;
        self.energy.initial_kinetic = self.blocks.iter().map(|b| b.kinetic_energy()).sum();
        self.energy.kinetic = self.energy.initial_kinetic;
        self.clock.started = true;
        Ok(())
    }

    fn divergence_error(&self, i: usize) -> Error {
        let s = &self.blocks[i].state;
        let r = self.blocks[i].shape().radius();
        let speed = s
            .velocity
            .length_squared()
            .max(s.angular_velocity.length_squared() * r * r)
            .sqrt();
        Error::Diverged {
            step: self.clock.step,
            time: self.clock.time,
            block: BlockId(i as u32),
            reason: if speed.is_finite() && is_finite_state(s) {
                format!("speed {speed:.3e} m/s exceeds max_speed {} m/s", self.params.max_speed)
            } else {
                "position or velocity is not finite".into()
            },
        }
    }
}
