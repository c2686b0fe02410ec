//! The step's pass over the blocks, after the contact pass: each block gathers its contacts'
//! wrenches, adds gravity and its load, and the integrator moves it; the energy terms due
//! before and after the move are booked on the way (see [`Model::advance_blocks`]).
//!
//! For an integrator that treats each block on its own ([`Integrator::is_blockwise`], as
//! [`CentralDifference`](crate::integrate::CentralDifference)) the three stages run chunk by
//! chunk in one parallel pass, while the chunk's blocks are in cache, with the next step's
//! rotation matrices and movement check: one sweep through the block array per step instead of
//! four, which matters once the blocks no longer fit in the cache (43 MB of blocks for the
//! 100,000-block wall).

use rayon::prelude::*;

use super::detection::prepare_chunk;
use super::{diverged, BlockSums, Model, BLOCK_CHUNK};
use crate::block::{Block, RigidBlock, Wrench};
use crate::constitutive::ConstitutiveLaw;
use crate::contact::{ContactWrench, DisplacementMode};
use crate::integrate::{Integrator, StepRecord};
use crate::math::{Matrix, Real, Vector};

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
}

/// `total` plus the wrenches of a block's contacts, in index order: `entries` are the block's
/// slice of the block → contact index (`2·contact + side`, side 1 when the block is `b`).
#[inline]
pub(super) fn add_contact_wrenches(mut total: Wrench, entries: &[u32], wrenches: &[ContactWrench]) -> Wrench {
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
        }
    }
}

impl<L: ConstitutiveLaw> Model<L> {
    /// Gathers every block's forces, moves the blocks and books the energy; returns the first
    /// block whose state is no longer finite or faster than `max_speed`.
    ///
    /// Every force `F` is booked with the trapezoidal rule over the displacement of the step,
    /// `½(F_{n−1} + F_n)·v_{n−½}·Δt` (a force that did not exist before the first step counts as
    /// zero), which together with the kinetic energy `½·m·v_{n−½}·v_{n+½}` makes the balance an
    /// exact identity of central difference for translation. Sums are taken per chunk of
    /// [`BLOCK_CHUNK`] blocks in block order, then over the chunks in order, whichever path
    /// runs: the results do not depend on the thread count, nor on whether the stages are fused.
    pub(super) fn advance_blocks(&mut self, kick: Real, drift: Real) -> Option<usize> {
        let pass = BlockPass {
            wrenches: &self.wrenches,
            contacts: &self.block_contacts,
            offsets: &self.block_offsets,
            gravity: self.params.gravity,
            dt: self.drift,
            drift_over_kick: if kick == drift { 1.0 } else { drift / kick },
            first: if self.step == 0 { 0.5 } else { 1.0 },
            max_speed2: self.params.max_speed * self.params.max_speed,
            trigger: (self.params.mode == DisplacementMode::Large)
                .then_some(self.params.contact.redetect_fraction * self.params.contact.tolerance),
        };
        self.block_sums.clear();
        self.block_sums
            .resize(self.blocks.len().div_ceil(BLOCK_CHUNK), BlockSums::default());
        let integrator: &dyn Integrator = &*self.integrator;
        if integrator.is_blockwise() {
            // Also the next step's first stage, while the blocks are in cache: their rotation
            // matrices and movement check (`prepare_blocks`).
            self.rotations.resize(self.blocks.len(), Matrix::IDENTITY);
            self.blocks
                .par_chunks_mut(BLOCK_CHUNK)
                .zip(self.forces.par_chunks_mut(BLOCK_CHUNK))
                .zip(self.records.par_chunks_mut(BLOCK_CHUNK))
                .zip(self.rotations.par_chunks_mut(BLOCK_CHUNK))
                .zip(self.ref_poses.par_chunks(BLOCK_CHUNK))
                .zip(self.block_sums.par_iter_mut())
                .enumerate()
                .for_each(|(k, (((((blocks, forces), records), rotations), refs), sums))| {
                    let first_block = k * BLOCK_CHUNK;
                    pass.gather(first_block, blocks, forces, records, sums);
                    integrator.advance_variable(blocks, forces, kick, drift, records);
                    pass.settle(first_block, blocks, records, sums);
                    sums.moved = prepare_chunk(rotations, blocks, refs, pass.trigger);
                });
            self.scratch.prepared = Some(self.block_sums.iter().any(|s| s.moved));
        } else {
            let blocks = &self.blocks;
            self.forces
                .par_chunks_mut(BLOCK_CHUNK)
                .zip(self.records.par_chunks(BLOCK_CHUNK))
                .zip(self.block_sums.par_iter_mut())
                .enumerate()
                .for_each(|(k, ((forces, records), sums))| {
                    let first_block = k * BLOCK_CHUNK;
                    let end = (first_block + BLOCK_CHUNK).min(blocks.len());
                    pass.gather(first_block, &blocks[first_block..end], forces, records, sums);
                });
            integrator.advance_variable(&mut self.blocks, &self.forces, kick, drift, &mut self.records);
            self.blocks
                .par_chunks(BLOCK_CHUNK)
                .zip(self.records.par_chunks(BLOCK_CHUNK))
                .zip(self.block_sums.par_iter_mut())
                .enumerate()
                .for_each(|(k, ((blocks, records), sums))| pass.settle(k * BLOCK_CHUNK, blocks, records, sums));
        }
        self.gather_block_sums()
    }

    /// Adds the chunk sums of the block pass to the energies in chunk order, sets the
    /// unbalanced-force ratio, and returns the first diverged block.
    fn gather_block_sums(&mut self) -> Option<usize> {
        let mut max_unbalanced: Real = 0.0;
        let mut kinetic = 0.0;
        let mut first_diverged = None;
        let e = &mut self.energy;
        for s in &self.block_sums {
            max_unbalanced = max_unbalanced.max(s.max_unbalanced);
            e.gravity_work += s.gravity_work;
            e.load_work += s.load_work;
            e.boundary_work += s.boundary_work;
            e.damping += s.damping;
            kinetic += s.kinetic;
            first_diverged = first_diverged.or(s.diverged);
        }
        e.kinetic = kinetic;
        for s in &self.pair_sums {
            e.joint_work += s.work;
            e.friction += s.dissipated;
            e.damping += s.dashpot_work;
        }
        let force_magnitudes: Real = self.pair_sums.iter().map(|s| s.force_magnitude).sum();
        let mean_contact = if self.pairs.is_empty() {
            0.0
        } else {
            force_magnitudes / self.pairs.len() as Real
        };
        self.unbalanced_ratio = if mean_contact > 0.0 {
            max_unbalanced / mean_contact
        } else {
            Real::INFINITY
        };
        first_diverged
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::block::RigidBlock;
    use crate::integrate::{CentralDifference, Damping};
    use crate::model::ModelParameters;

    /// Central difference called once with all the blocks: the three separate passes.
    #[derive(Debug, Clone, Copy)]
    struct Separate(CentralDifference);

    impl Integrator for Separate {
        fn advance(&self, blocks: &mut [RigidBlock], forces: &[Wrench], dt: Real, records: &mut [StepRecord]) {
            self.0.advance(blocks, forces, dt, records);
        }
        fn advance_variable(
            &self,
            blocks: &mut [RigidBlock],
            forces: &[Wrench],
            kick: Real,
            drift: Real,
            records: &mut [StepRecord],
        ) {
            self.0.advance_variable(blocks, forces, kick, drift, records);
        }
        fn damping(&self) -> crate::integrate::Damping {
            self.0.damping()
        }
        fn boxed_clone(&self) -> Box<dyn Integrator> {
            Box::new(*self)
        }
    }

    fn toppling_column() -> Model {
        crate::model::tests::toppling_column(ModelParameters::default())
    }

    /// What the comparisons below compare: every block state, the energies, the detection,
    /// sub-contact and step counts, the step and the unbalanced-force ratio.
    type Fingerprint = (
        Vec<crate::block::BlockState>,
        crate::model::Energies,
        u64,
        usize,
        u64,
        Real,
        Real,
    );

    fn fingerprint(m: &Model) -> Fingerprint {
        (
            m.blocks().iter().map(|b| *b.state()).collect(),
            m.energies(),
            m.detection_count(),
            m.subcontact_count(),
            m.step_count(),
            m.dt(),
            m.unbalanced_ratio,
        )
    }

    /// A fused and a separate-passes copy of a model.
    fn pair(make: &dyn Fn() -> Model, damping: Damping) -> (Model, Model) {
        let (mut fused, mut separate) = (make(), make());
        fused
            .set_integrator(CentralDifference::new(damping))
            .expect("integrator");
        separate
            .set_integrator(Separate(CentralDifference::new(damping)))
            .expect("integrator");
        assert!(fused.integrator.is_blockwise() && !separate.integrator.is_blockwise());
        (fused, separate)
    }

    /// Steps both `n` times, comparing after every step; a step may fail, alike in both.
    fn step_both(fused: &mut Model, separate: &mut Model, n: usize, what: &str) {
        for k in 0..n {
            assert_eq!(fused.step().is_ok(), separate.step().is_ok(), "{what}, step {k}");
            assert_eq!(fingerprint(fused), fingerprint(separate), "{what}, step {k}");
        }
    }

    /// The benchmark wall of 1,200 blocks (three chunks) under gravity tilted by 40° sideways:
    /// blocks slide and topple all along the wall, beyond the re-detection trigger.
    fn tilted_wall() -> Model {
        let mut wall = crate::model::benchmark_wall(1200).expect("wall");
        let t: Real = 40.0_f64.to_radians();
        let params = ModelParameters {
            gravity: Vector::new(0.0, t.sin(), -t.cos()) * 9.81,
            ..*wall.parameters()
        };
        wall.set_parameters(params).expect("params");
        assert!(wall.blocks().len() > 2 * BLOCK_CHUNK);
        wall
    }

    /// The fused block pass (gather, integrator, energy and the next step's movement check
    /// chunk by chunk) and the separate passes give bit-identical states, energies, detection
    /// and sub-contact counts after every step: on a toppling column (re-detection triggered by
    /// the fused pass's movement check) with local and Rayleigh damping, and on a tilted wall of
    /// three chunks, where some re-detections are triggered by blocks of the later chunks only.
    #[test]
    fn fused_and_separate_block_passes_agree() {
        for damping in [
            Damping::Local { alpha: 0.1 },
            Damping::Rayleigh {
                mass: 5.0,
                stiffness: 0.0,
            },
        ] {
            let (mut fused, mut separate) = pair(&toppling_column, damping);
            step_both(&mut fused, &mut separate, 1500, &format!("column, {damping:?}"));
            assert!(
                fused.detection_count() > 5,
                "{damping:?}: {} detections",
                fused.detection_count()
            );
        }
        let (mut fused, mut separate) = pair(&tilted_wall, Damping::Local { alpha: 0.8 });
        let mut later_chunks_only = 0;
        for k in 0..300 {
            step_both(&mut fused, &mut separate, 1, &format!("wall, step {k}"));
            assert!(
                fused.scratch.prepared.is_some(),
                "the fused pass prepares the next step"
            );
            if fused.scratch.prepared == Some(true) && !fused.block_sums[0].moved {
                later_chunks_only += 1;
            }
        }
        assert!(
            fused.detection_count() > 3 && later_chunks_only > 0,
            "{} detections, {later_chunks_only} triggered by later chunks only",
            fused.detection_count()
        );
    }

    /// The fused pass over several chunks gives the same bits with one, two and three threads.
    #[test]
    fn fused_pass_is_independent_of_the_thread_count() {
        let pool = |n| rayon::ThreadPoolBuilder::new().num_threads(n).build().expect("pool");
        let run = || {
            let mut m = tilted_wall();
            m.run_steps(300).expect("run");
            fingerprint(&m)
        };
        let (one, two, three) = (pool(1).install(run), pool(2).install(run), pool(3).install(run));
        assert!(one.2 > 2, "{} detections", one.2);
        assert_eq!(one, two);
        assert_eq!(one, three);
    }

    /// Changes between steps — switching the integrator both ways, adding a block, new
    /// parameters, a checkpoint round trip, a divergence and recovery — keep the fused path
    /// bit-identical to the separate passes (none may leave stale rotation matrices or a stale
    /// movement check behind).
    #[test]
    fn changes_between_steps_keep_fused_and_separate_identical() {
        let cd = CentralDifference::new(Damping::Local { alpha: 0.1 });
        let (mut fused, mut separate) = pair(&toppling_column, cd.damping);
        step_both(&mut fused, &mut separate, 200, "start");
        // (Setting an integrator re-evaluates the step: set one on both.)
        fused.set_integrator(Separate(cd)).expect("integrator");
        separate.set_integrator(Separate(cd)).expect("integrator");
        step_both(&mut fused, &mut separate, 50, "switched to separate");
        fused.set_integrator(cd).expect("integrator");
        separate.set_integrator(Separate(cd)).expect("integrator");
        step_both(&mut fused, &mut separate, 50, "switched back");
        for m in [&mut fused, &mut separate] {
            let cube = RigidBlock::cuboid("new", Vector::new(0.5, 0.5, 0.0), Vector::new(0.6, 0.6, 0.1), 2500.0)
                .expect("cube");
            m.add_block(cube).expect("add");
        }
        step_both(&mut fused, &mut separate, 100, "add_block");
        for m in [&mut fused, &mut separate] {
            let mut p = *m.parameters();
            p.contact.redetect_fraction = 0.05;
            m.set_parameters(p).expect("parameters");
        }
        step_both(&mut fused, &mut separate, 100, "set_parameters");
        fused = Model::from_checkpoint_str(&fused.to_checkpoint_string().expect("save")).expect("load");
        separate = Model::from_checkpoint_str(&separate.to_checkpoint_string().expect("save")).expect("load");
        fused.set_integrator(cd).expect("integrator");
        separate.set_integrator(Separate(cd)).expect("integrator");
        step_both(&mut fused, &mut separate, 100, "checkpoint");
        for m in [&mut fused, &mut separate] {
            let id = crate::block::BlockId(2);
            m.set_velocity(id, Vector::new(2e3, 0.0, 0.0), Vector::ZERO)
                .expect("velocity");
            assert!(matches!(m.step(), Err(crate::Error::Diverged { .. })));
            m.set_velocity(id, Vector::ZERO, Vector::ZERO).expect("velocity");
        }
        step_both(&mut fused, &mut separate, 100, "after divergence");
    }
}
