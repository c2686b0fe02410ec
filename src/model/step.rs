//! The step: its stages in order, each a method of the model's state given the pipeline's
//! scratch it uses (`docs/architecture.md`).

use super::changes::Changes;
use super::contact_pass::{ContactPass, ContactSlices, PairSums, CONTACT_CHUNK};
use super::Pipeline;
use super::{is_finite_state, ModelState};
use crate::block::{Block, BlockId};
use crate::contact::{DisplacementMode, KernelContext};
use crate::error::{Error, Result};
use crate::integrate::TimeStep;
use crate::law::ConstitutiveLaw;
use crate::math::Real;

impl<L: ConstitutiveLaw> ModelState<L> {
    /// One step: the stages in order, each given the state and the pipeline it uses.
    pub(super) fn step(&mut self, pipeline: &mut Pipeline<L::State>) -> Result<()> {
        if self.blocks.is_empty() {
            return Err(Error::EmptyModel);
        }
        let started = std::time::Instant::now();
        let large = self.params.mode == DisplacementMode::Large;
        // The changes since the last step come first: any of them asks for a full detection,
        // and makes what the last block pass prepared possibly stale.
        let changed = self.changes.need_full_detection();
        let moved = match pipeline.detection.prepared.take() {
            Some(moved) if self.started && !changed => moved,
            _ => self.prepare_blocks(pipeline, large && self.started && !changed),
        };
        if !self.started {
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
        } else if changed {
            // Small displacements keep the initial contact geometry: only the step is re-evaluated.
            self.refresh_time_step(pipeline)?;
            self.changes.clear();
        }
        self.refixed.clear();
        let first = self.drift == 0.0;
        if first {
            // The first step: the initial velocities stand for those of the half step before.
            self.drift = self.dt;
        }
        let detected = std::time::Instant::now();
        let (impact, busy) = self.compute_forces(pipeline);
        let previous = self.drift;
        let drift = self.next_drift(pipeline, impact, busy);
        // No block may move further than the contact tolerance in one step.
        let drift = self.cap_drift(pipeline, drift);
        // The first step's half step before is as long as the step itself (also when cut).
        let previous = if first { previous.min(drift) } else { previous };
        self.apply_base_motions(drift);
        self.apply_load_histories();
        let forces = std::time::Instant::now();
        let (diverged, too_far) = self.advance_blocks(pipeline, 0.5 * (previous + drift), drift);
        self.drift = drift;
        let t = &mut pipeline.timings;
        t.detection += (detected - started).as_secs_f64();
        t.contacts += (forces - detected).as_secs_f64();
        t.integration += forces.elapsed().as_secs_f64();
        t.steps += 1;
        self.step += 1;
        self.time += drift;
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
        for p in &self.pairs {
            let depth = -self.subs[p.range()]
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
        self.started = true;
        Ok(())
    }

    /// The step to take from the current poses, `Δt_{n+½}`, given the largest squared frequency
    /// bound of the blocks whose contacts are about to close or open fast (0: none) and whether
    /// a loaded impacting contact moves fast (`busy`): `dt`, or, from an impact,
    /// `impact_step × 2/ω` for the fastest block that asked for it, until the refinement's hold
    /// (three of that block's critical steps after the last probe that fired, which spans the
    /// middle of a flat impact, where the sub-contacts are deep and the probe is quiet) has
    /// passed and none of the contacts the probe marked is both loaded and fast. The step thus
    /// changes while the impacting contacts are open, or once the motion is quiet.
    fn next_drift(&mut self, pipeline: &Pipeline<L::State>, impact: Real, busy: bool) -> Real {
        let (Some(r), TimeStep::Auto { .. }) = (self.params.impact_step, self.params.time_step) else {
            return self.dt;
        };
        if impact > 0.0 {
            self.refine_travel |= pipeline.pair_sums.iter().any(|s| s.node_impact);
            let hold = 3.0 * 2.0 / impact.sqrt();
            self.refine_until = self.refine_until.max(self.time + hold);
            self.refine_omega2 = self.refine_omega2.max(impact);
            for (k, s) in pipeline.pair_sums.iter().enumerate() {
                if s.fired_count as usize <= s.fired.len() {
                    self.refining.extend_from_slice(&s.fired[..s.fired_count as usize]);
                } else {
                    let end = ((k + 1) * CONTACT_CHUNK).min(self.pairs.len());
                    self.refining
                        .extend(self.pairs[k * CONTACT_CHUNK..end].iter().map(|p| (p.a, p.b)));
                }
            }
            self.refining.sort_unstable();
            self.refining.dedup();
        }
        if self.refine_omega2 > 0.0 && (self.time < self.refine_until || busy) {
            self.dt.min(r * 2.0 / self.refine_omega2.sqrt())
        } else {
            self.refine_omega2 = 0.0;
            self.refine_travel = false;
            self.refining.clear();
            self.dt
        }
    }

    /// The contact pass; returns the largest squared frequency bound of the blocks of the
    /// contacts the impact probe marked (0: none), and whether a loaded contact it marked
    /// since the refinement began moves fast.
    fn compute_forces(&mut self, pipeline: &mut Pipeline<L::State>) -> (Real, bool) {
        // The probe: normal speeds beyond that of a fall through the contact tolerance,
        // `√(2 g tol)` (a block settling on its joints moves much slower), crossing the kink
        // within two steps.
        let probe = matches!(self.params.time_step, TimeStep::Auto { .. }) && self.params.impact_step.is_some();
        let impact_speed = if probe {
            (2.0 * self.params.gravity.length() * self.params.contact.tolerance).sqrt()
        } else {
            Real::INFINITY
        };
        let ctx = KernelContext {
            dt: self.drift,
            impact_speed,
            impact_horizon: 2.0 * self.dt,
            stiffness_damping: self.integrator.damping().stiffness_coefficient(),
            mode: self.params.mode,
            lanes: crate::contact::LaneBuild::Portable,
        };
        // The records run index for index with the sub-contacts (kept so by detection and
        // checkpoint load).
        assert_eq!(
            self.sub_records.len(),
            self.subs.len(),
            "sub-contact records out of step"
        );
        assert_eq!(
            pipeline.rotations.len(),
            self.blocks.len(),
            "rotation matrices out of step"
        );
        assert_eq!(self.wrenches.len(), self.pairs.len(), "contact wrenches out of step");
        let pass = ContactPass {
            blocks: &self.blocks,
            rotations: &pipeline.rotations,
            references: &self.references,
            laws: self.laws.laws(),
            bounds: &pipeline.bounds,
            refining: &self.refining,
            ctx,
        };
        // One pass per contact: its plane, its sub-contacts (in order), its resultant; summed
        // per fixed chunk of contacts, so that the totals do not depend on the thread count.
        pipeline.pair_sums.clear();
        pipeline
            .pair_sums
            .resize(self.pairs.len().div_ceil(CONTACT_CHUNK), PairSums::default());
        if !self.pairs.is_empty() {
            let first_sub = self.pairs[0].first as usize;
            pass.run_all(
                ContactSlices {
                    first: 0,
                    pairs: &mut self.pairs,
                    wrenches: &mut self.wrenches,
                    sums: &mut pipeline.pair_sums,
                    subs: &mut self.subs[first_sub..],
                    records: &mut self.sub_records[first_sub..],
                },
                crate::dispatch::has_avx2(),
            );
        }
        (
            pipeline.pair_sums.iter().map(|s| s.impact).fold(0.0, Real::max),
            pipeline.pair_sums.iter().any(|s| s.busy),
        )
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
            step: self.step,
            time: self.time,
            block: BlockId(i as u32),
            reason: if speed.is_finite() && is_finite_state(s) {
                format!("speed {speed:.3e} m/s exceeds max_speed {} m/s", self.params.max_speed)
            } else {
                "position or velocity is not finite".into()
            },
        }
    }
}
