//! The step's pass over the blocks, after the contact pass: each block gathers its contacts'
//! wrenches, adds gravity and its load, and the integrator moves it; the energy terms due
//! before and after the move are booked on the way (see [`ModelState::block_pass`]).
//!
//! The integrator advances each block on its own ([`Integrator::advance_chunk`]), so the three
//! stages run chunk by chunk in one parallel pass, while the chunk's blocks are in cache, with
//! the next step's rotation matrices and movement check: one sweep through the block array per
//! step instead of four, which matters once the blocks no longer fit in the cache (43 MB of
//! blocks for the 100,000-block wall).

use rayon::prelude::*;

use super::detection::prepare_chunk;
use crate::block::{Block, BlockMotion, Dof, RigidBlock, Wrench};
use crate::contact::{ContactWrench, DisplacementMode};
use crate::error::Error;
use crate::ids::BlockId;
use crate::integrate::{Integrator, StepDurations, StepRecord};
use crate::law::ConstitutiveLaw;
use crate::math::{Real, Vector};
use crate::model::Pipeline;
use crate::model::{diverged, BlockSums, ModelState, BLOCK_CHUNK};

/// What the per-block stages read besides the block itself.
#[derive(Clone, Copy)]
struct BlockPass<'a> {
    wrenches: &'a [ContactWrench],
    /// Block → contact index: `contacts[offsets[i]..offsets[i + 1]]`, each entry `2·contact + side`.
    contacts: &'a [u32],
    offsets: &'a [u32],
    gravity: Vector,
    /// The step that brought the blocks to their current poses, `Δt_{n−½}`: the works of
    /// step `n` are booked over its displacement.
    dt: Real,
    /// `Δt_{n+½} / ½(Δt_{n−½} + Δt_{n+½})`: the drift over the kick of this step (1 while the
    /// step does not change), for the kinetic energy.
    drift_over_kick: Real,
    /// `½` on the first step (no force before it), else `1`: the weight of the `F_{n−1}` half of
    /// gravity's and the loads' work.
    first: Real,
    /// `max_speed²`.
    max_speed2: Real,
    /// The re-detection trigger (m) in large-displacement mode, for the next step's movement
    /// check.
    trigger: Option<Real>,
    /// This step's drift `Δt_{n+½}` (s), over which the blocks move, and its square.
    drift: Real,
    drift2: Real,
    /// The contact tolerance (m): no block may move further in one step; and its square.
    tolerance: Real,
    tolerance2: Real,
}

/// The squared speeds of a block for its next move: of its translation, with prescribed
/// velocities ([`Dof::Velocity`]) in place of the state's on those axes, and of its fastest
/// point in rotation (angular speed times radius). After a step the state's velocity on a
/// prescribed axis is the prescribed one, so these are what the block just moved at, as the
/// block pass measures them from the state alone.
#[inline]
pub(in crate::model) fn move_speeds2(b: &RigidBlock) -> (Real, Real) {
    let mut v = b.state.velocity.to_array();
    for (v, d) in v.iter_mut().zip(b.fixity().translation) {
        if let Dof::Velocity(p) = d {
            *v = p;
        }
    }
    let w2 = b.state.angular_velocity.length_squared() * b.radius * b.radius;
    (Vector::from_array(v).length_squared(), w2)
}

/// The speed bound of the step length from the largest squared speeds of translation and of
/// rotation at the radius (m/s): at least the largest speed of any point of any block.
#[inline]
pub(in crate::model) fn speed_bound(max_v2: Real, max_w2: Real) -> Real {
    max_v2.sqrt() + max_w2.sqrt()
}

/// `total` plus the wrenches of a block's contacts, in index order: `entries` are the block's
/// slice of the block → contact index (`2·contact + side`, side 1 when the block is `b`).
#[inline]
pub(in crate::model) fn add_contact_wrenches(mut total: Wrench, entries: &[u32], wrenches: &[ContactWrench]) -> Wrench {
    for &e in entries {
        let w = &wrenches[(e >> 1) as usize];
        if e & 1 == 1 {
            total.force += w.force;
            total.moment += w.moment_b;
        } else {
            total.force -= w.force;
            total.moment += w.moment_a;
        }
    }
    total
}

impl BlockPass<'_> {
    /// Gathers the forces of the chunk of blocks starting at block `first_block` and books the
    /// energy terms due before the move: gravity and loads, and the `F_{n−1}` halves of the
    /// reactions and damping forces, while the velocities are still `v_{n−½}` and the step
    /// records still hold step `n − 1`.
    fn gather(
        &self,
        first_block: usize,
        blocks: &[RigidBlock],
        forces: &mut [Wrench],
        records: &[StepRecord],
        sums: &mut BlockSums,
    ) {
        let dt = self.dt;
        for (j, ((b, w), r)) in blocks.iter().zip(forces.iter_mut()).zip(records).enumerate() {
            let i = first_block + j;
            let m = b.mass_properties().mass;
            let mut total = b.load;
            total.force += self.gravity * m;
            let entries = &self.contacts[self.offsets[i] as usize..self.offsets[i + 1] as usize];
            let total = add_contact_wrenches(total, entries, self.wrenches);
            *w = total;
            if b.is_free() {
                sums.max_unbalanced = sums.max_unbalanced.max(total.force.length());
            }
            let (v, om) = (b.state.velocity, b.state.angular_velocity);
            sums.gravity_work += self.first * m * self.gravity.dot(v) * dt;
            sums.load_work += self.first * (b.load.force.dot(v) + b.load.moment.dot(om)) * dt;
            sums.boundary_work += 0.5 * (r.reaction.force.dot(v) + r.reaction.moment.dot(om)) * dt;
            sums.damping -= 0.5 * (r.damping.force.dot(v) + r.damping.moment.dot(om)) * dt;
        }
    }

    /// After the move: the `F_n` halves of the reactions and damping forces, the kinetic energy
    /// `½·m·v_{n−½}·v_{n+½} + ½·ω_{n−½}·L_{n+½}`, and the first block of the chunk (starting at
    /// `first_block`) whose state is no longer finite or faster than `max_speed`.
    fn settle(&self, first_block: usize, blocks: &[RigidBlock], records: &[StepRecord], sums: &mut BlockSums) {
        let dt = self.dt;
        for (j, (b, r)) in blocks.iter().zip(records).enumerate() {
            let m = b.mass_properties().mass;
            let (v1, w1) = (b.state.velocity, b.state.angular_velocity);
            // The velocities before the step, from the mean the integrator reports.
            let v0 = 2.0 * r.mean_velocity - v1;
            let w0 = 2.0 * r.mean_angular_velocity - w1;
            // With a step that changes, `v⁻` as if the last step had been as long as this one,
            // `v⁺ − (Δt_{n+½}/kick)(v⁺ − v⁻)`: the product then telescopes with the works over
            // `Δt_{n−½}` (up to `¼ (Δt_{n+½} − Δt_{n−½}) kick |F|²/m` where the step changes).
            let (v0k, w0k) = if self.drift_over_kick == 1.0 {
                (v0, w0)
            } else {
                let s = self.drift_over_kick;
                (v1 - (v1 - v0) * s, w1 - (w1 - w0) * s)
            };
            sums.kinetic += 0.5 * m * v0k.dot(v1) + 0.5 * w0k.dot(b.state.angular_momentum);
            sums.boundary_work += 0.5 * (r.reaction.force.dot(v0) + r.reaction.moment.dot(w0)) * dt;
            sums.damping -= 0.5 * (r.damping.force.dot(v0) + r.damping.moment.dot(w0)) * dt;
            if sums.diverged.is_none() && diverged(b, self.max_speed2) {
                sums.diverged = Some(first_block + j);
            }
            // The move of this step: `v_{n+½} Δt_{n+½}` (and the rotation's at the radius),
            // with square roots only for a block that may have moved past the tolerance
            // (`(a + b)² ≤ 2 (a² + b²)`).
            let v2 = b.state.velocity.length_squared();
            let w2 = b.state.angular_velocity.length_squared() * b.radius * b.radius;
            sums.max_v2 = sums.max_v2.max(v2);
            sums.max_w2 = sums.max_w2.max(w2);
            if sums.too_far.is_none() && 2.0 * (v2 + w2) * self.drift2 > self.tolerance2 {
                let distance = (v2.sqrt() + w2.sqrt()) * self.drift;
                if distance > self.tolerance {
                    sums.too_far = Some((first_block + j, distance));
                }
            }
        }
    }
}

impl<L: ConstitutiveLaw> ModelState<L> {
    /// Gathers every block's forces, moves the blocks and books the energy; returns the first
    /// block whose state is no longer finite or faster than `max_speed`, and the first block
    /// moved further than the contact tolerance with the distance (the largest speed is left in
    /// `pipeline.max_speed`).
    ///
    /// Every force `F` is booked with the trapezoidal rule over the displacement of the step,
    /// `½(F_{n−1} + F_n)·v_{n−½}·Δt` (a force that did not exist before the first step counts as
    /// zero), which together with the kinetic energy `½·m·v_{n−½}·v_{n+½}` makes the balance an
    /// exact identity of central difference for translation. Sums are taken per chunk of
    /// [`BLOCK_CHUNK`] blocks in block order, then over the chunks in order: the results do not
    /// depend on the thread count.
    pub(in crate::model) fn block_pass(
        &mut self,
        pipeline: &mut Pipeline<L::State>,
        kick: Real,
        drift: Real,
    ) -> (Option<usize>, Option<(usize, Real)>) {
        let pass = BlockPass {
            wrenches: &self.contacts.wrenches,
            contacts: &pipeline.block_contacts,
            offsets: &pipeline.block_offsets,
            gravity: self.params.gravity,
            dt: self.clock.drift,
            drift_over_kick: if kick == drift { 1.0 } else { drift / kick },
            first: if self.clock.step == 0 { 0.5 } else { 1.0 },
            max_speed2: self.params.max_speed * self.params.max_speed,
            trigger: (self.params.mode == DisplacementMode::Large)
                .then_some(self.params.contact.redetect_fraction * self.params.contact.tolerance),
            drift,
            drift2: drift * drift,
            tolerance: self.params.contact.tolerance,
            tolerance2: self.params.contact.tolerance * self.params.contact.tolerance,
        };
        pipeline.block_sums.clear();
        pipeline
            .block_sums
            .resize(self.blocks.len().div_ceil(BLOCK_CHUNK), BlockSums::default());
        let integrator: &dyn Integrator = &*self.integrator;
        let step = StepDurations { kick, drift };
        // Also the next step's first stage, while the blocks are in cache: their motions and
        // movement check (`prepare_blocks`).
        pipeline.motions.resize(self.blocks.len(), BlockMotion::default());
        pipeline.detection.moved.resize(self.blocks.len(), false);
        self.blocks
            .par_chunks_mut(BLOCK_CHUNK)
            .zip(pipeline.forces.par_chunks_mut(BLOCK_CHUNK))
            .zip(self.records.par_chunks_mut(BLOCK_CHUNK))
            .zip(pipeline.motions.par_chunks_mut(BLOCK_CHUNK))
            .zip(pipeline.detection.moved.par_chunks_mut(BLOCK_CHUNK))
            .zip(self.found.ref_poses.par_chunks(BLOCK_CHUNK))
            .zip(pipeline.block_sums.par_iter_mut())
            .enumerate()
            .for_each(|(k, ((((((blocks, forces), records), motions), moved), refs), sums))| {
                let first_block = k * BLOCK_CHUNK;
                pass.gather(first_block, blocks, forces, records, sums);
                integrator.advance_chunk(blocks, forces, step, records);
                pass.settle(first_block, blocks, records, sums);
                sums.moved = prepare_chunk(motions, moved, blocks, refs, pass.trigger);
            });
        pipeline.detection.prepared = Some(pipeline.block_sums.iter().any(|s| s.moved));
        self.gather_block_sums(pipeline)
    }

    /// Adds the chunk sums of the block pass to the energies in chunk order, sets the
    /// unbalanced-force ratio and the largest speed, and returns the first diverged block and
    /// the first block moved too far.
    fn gather_block_sums(&mut self, pipeline: &mut Pipeline<L::State>) -> (Option<usize>, Option<(usize, Real)>) {
        let mut max_unbalanced: Real = 0.0;
        let mut kinetic = 0.0;
        let mut first_diverged = None;
        let mut first_too_far = None;
        let (mut max_v2, mut max_w2): (Real, Real) = (0.0, 0.0);
        let e = &mut self.energy;
        for s in &pipeline.block_sums {
            max_unbalanced = max_unbalanced.max(s.max_unbalanced);
            e.gravity_work += s.gravity_work;
            e.load_work += s.load_work;
            e.boundary_work += s.boundary_work;
            e.damping += s.damping;
            kinetic += s.kinetic;
            first_diverged = first_diverged.or(s.diverged);
            first_too_far = first_too_far.or(s.too_far);
            max_v2 = max_v2.max(s.max_v2);
            max_w2 = max_w2.max(s.max_w2);
        }
        pipeline.max_speed = Some(speed_bound(max_v2, max_w2));
        e.kinetic = kinetic;
        for s in &pipeline.pair_sums {
            e.joint_work += s.work;
            e.friction += s.dissipated;
            e.fracture += s.fracture;
            e.damping += s.dashpot_work;
        }
        let force_magnitudes: Real = pipeline.pair_sums.iter().map(|s| s.force_magnitude).sum();
        let mean_contact = if self.contacts.pairs.is_empty() {
            0.0
        } else {
            force_magnitudes / self.contacts.pairs.len() as Real
        };
        self.unbalanced_ratio = if mean_contact > 0.0 {
            max_unbalanced / mean_contact
        } else {
            Real::INFINITY
        };
        (first_diverged, first_too_far)
    }

    /// [`Error::StepTooLong`] for block `i` moved `distance` by the step of length `drift` that
    /// has just been booked.
    pub(in crate::model) fn too_far_error(&self, i: usize, distance: Real, drift: Real) -> Error {
        let tolerance = self.params.contact.tolerance;
        let speed = distance / drift;
        Error::StepTooLong {
            step: self.clock.step,
            time: self.clock.time - drift,
            dt: drift,
            block: BlockId(i as u32),
            distance,
            tolerance,
            speed,
            max_dt: tolerance / speed,
        }
    }

    /// The [`speed_bound`] of the blocks' [`move_speeds2`] (m/s), as the block pass leaves it.
    pub(in crate::model) fn max_move_speed(&self) -> Real {
        let (v2, w2) = self
            .blocks
            .iter()
            .map(move_speeds2)
            .fold((0.0, 0.0), |(a, b): (Real, Real), (v, w)| (a.max(v), b.max(w)));
        speed_bound(v2, w2)
    }
}
