//! The model's time step: the contacts' stiffness handed to the integrator's stability limit
//! ([`crate::integrate::Integrator::critical_step`]), then the step the parameters ask for.

use crate::error::{Error, Result};
use crate::model::ModelState;
use crate::model::Pipeline;
use rayon::prelude::*;

use crate::block::Block;
use crate::contact::{stored_node_frame, SmallReference};
use crate::geometry::{ContactKind, NodeId};
use crate::integrate::{
    block_bound, block_side, bound_from_sides, contact_eigenvalues, AreaMoments, ContactStiffness, StiffnessBound,
    TimeStep,
};
use crate::law::ConstitutiveLaw;
use crate::math::{Matrix, Real, Vector};

impl<L: ConstitutiveLaw> ModelState<L> {
    /// Re-evaluates the critical step from the current contacts and each block's potential
    /// contact on its largest face, then sets `dt`.
    pub(in crate::model) fn refresh_time_step(&mut self, pipeline: &mut Pipeline<L::State>) -> Result<()> {
        if self.blocks.is_empty() {
            return Ok(());
        }
        // Blocks added since the last detection (a setter may ask before the first step).
        let n = self.blocks.len();
        if pipeline.block_offsets.len() != n + 1 || pipeline.block_offsets[n] as usize != 2 * self.contacts.pairs.len()
        {
            self.rebuild_block_index(pipeline);
        }
        for reference in &mut self.contacts.references {
            reference.bound_area = reference.area;
        }
        pipeline.bounds.resize(n, StiffnessBound::default());
        let sources = self.bound_sources(&pipeline.block_offsets, &pipeline.block_contacts);
        let (offsets, entries) = (&pipeline.block_offsets, &pipeline.block_contacts);
        // Each block's side of each of its contacts, once: its stiffness added into the block's
        // own and its largest eigenvalue, by blocks in parallel (each task a run of blocks and
        // their entries of the block → contact index).
        let mut sides = vec![0.0; entries.len()];
        let mut own: Vec<Option<Real>> = vec![None; n];
        let mut tasks = Vec::with_capacity(n.div_ceil(BLOCKS_PER_TASK));
        let mut rest = sides.as_mut_slice();
        for (t, own) in own.chunks_mut(BLOCKS_PER_TASK).enumerate() {
            let first = t * BLOCKS_PER_TASK;
            let len = (offsets[first + own.len()] - offsets[first]) as usize;
            let (head, tail) = std::mem::take(&mut rest).split_at_mut(len);
            rest = tail;
            tasks.push((first, own, head));
        }
        tasks.into_par_iter().for_each(|(first, own, sides)| {
            let base = offsets[first] as usize;
            for (d, own) in own.iter_mut().enumerate() {
                let i = first + d;
                let (s, e) = (offsets[i] as usize, offsets[i + 1] as usize);
                let contacts = entries[s..e].iter().map(|&x| sources.contact((x / 2) as usize));
                *own = block_side(&self.blocks, i, contacts, &mut sides[s - base..e - base]);
            }
        });
        // Each contact's eigenvalues on its two blocks ([`contact_eigenvalues`]).
        let mut eigenvalues = vec![[0.0; 2]; self.contacts.pairs.len()];
        for (&x, &side) in entries.iter().zip(&sides) {
            eigenvalues[(x / 2) as usize][(x % 2) as usize] = side;
        }
        let k_max = sources.k_max;
        let blocks = &self.blocks;
        pipeline.bounds.par_iter_mut().enumerate().for_each(|(i, bound)| {
            let contacts = entries[offsets[i] as usize..offsets[i + 1] as usize]
                .iter()
                .map(|&x| eigenvalues[(x / 2) as usize]);
            *bound = bound_from_sides(blocks, i, own[i], contacts, k_max);
        });
        self.set_time_step(pipeline)
    }

    /// Of `contacts`, those whose area grew by more than 5 % since their last evaluation (or
    /// that are new): their areas are taken as evaluated, and their blocks added to `blocks`.
    /// Only a contact detected afresh can have grown: a caller may pass those alone.
    pub(in crate::model) fn take_grown(&mut self, contacts: impl Iterator<Item = usize>, blocks: &mut Vec<u32>) {
        for k in contacts {
            let reference = &mut self.contacts.references[k];
            if reference.area > GROWTH * reference.bound_area {
                reference.bound_area = reference.area;
                blocks.extend([self.contacts.pairs[k].a, self.contacts.pairs[k].b]);
            }
        }
    }

    /// Re-evaluates the bounds of block `i` and of the blocks in contact with it (whose bounds
    /// couple with its own through its fixity), then the critical step: what a change of `i`'s
    /// fixity changes, without a pass over every block. The whole evaluation when the block →
    /// contact index or the bounds are not up to date (blocks added since the last step).
    pub(in crate::model) fn refresh_time_step_around(
        &mut self,
        pipeline: &mut Pipeline<L::State>,
        i: u32,
    ) -> Result<()> {
        let n = self.blocks.len();
        let offsets = &pipeline.block_offsets;
        if offsets.len() != n + 1 || offsets[n] as usize != 2 * self.contacts.pairs.len() || pipeline.bounds.len() != n
        {
            return self.refresh_time_step(pipeline);
        }
        let mut blocks = std::mem::take(&mut pipeline.refresh_blocks);
        blocks.clear();
        blocks.push(i);
        let entries = &pipeline.block_contacts[offsets[i as usize] as usize..offsets[i as usize + 1] as usize];
        for &e in entries {
            let p = &self.contacts.pairs[(e / 2) as usize];
            blocks.extend([p.a, p.b]);
        }
        pipeline.refresh_blocks = blocks;
        self.refresh_time_step_of_grown(pipeline)
    }

    /// Re-evaluates the bounds of the blocks in `pipeline.refresh_blocks` (those of the grown
    /// contacts, [`ModelState::take_grown`]), then the critical step from all the bounds: a
    /// block's bound depends only on its own contacts. Needs the block → contact index.
    pub(in crate::model) fn refresh_time_step_of_grown(&mut self, pipeline: &mut Pipeline<L::State>) -> Result<()> {
        let mut blocks = std::mem::take(&mut pipeline.refresh_blocks);
        blocks.sort_unstable();
        blocks.dedup();
        let mut fresh = std::mem::take(&mut pipeline.refresh_bounds);
        {
            let sources = self.bound_sources(&pipeline.block_offsets, &pipeline.block_contacts);
            fresh.clear();
            fresh.par_extend(blocks.par_iter().map(|&i| sources.bound(i as usize)));
        }
        for (&i, bound) in blocks.iter().zip(&fresh) {
            pipeline.bounds[i as usize] = *bound;
        }
        pipeline.refresh_blocks = blocks;
        pipeline.refresh_bounds = fresh;
        self.set_time_step(pipeline)
    }

    /// What a block's stability bound is computed from.
    fn bound_sources<'a>(&'a self, offsets: &'a [u32], contacts: &'a [u32]) -> BoundSources<'a, L> {
        BoundSources {
            state: self,
            offsets,
            contacts,
            k_max: self
                .laws
                .laws()
                .iter()
                .map(|l| {
                    let k = l.stiffness();
                    k.normal + 2.0 * k.shear
                })
                .fold(0.0, Real::max),
        }
    }

    /// The critical step from the blocks' bounds, then `dt`.
    fn set_time_step(&mut self, pipeline: &Pipeline<L::State>) -> Result<()> {
        self.clock.critical = self.integrator.critical_step(&pipeline.bounds);
        let Some(crit) = self.clock.critical else {
            // No stiffness anywhere: free flight; keep a previous step or a small default.
            if self.clock.dt == 0.0 {
                self.clock.dt = match self.params.time_step {
                    TimeStep::Fixed(dt) => dt,
                    TimeStep::Auto { .. } => 1e-4,
                };
            }
            return Ok(());
        };
        if !(crit.dt.is_finite() && crit.dt > 0.0) {
            // Stiffnesses near f64's limit (a law of 1.7e308 Pa/m) overflow the bound: the step
            // would be NaN or zero. (Found by the fuzzer.)
            self.clock.critical = None;
            return Err(Error::InvalidParameter {
                name: format!("critical time step (set by block {})", crit.block),
                value: crit.dt,
                expected: "positive and finite: the stiffness of the block's contacts overflows f64 \
                           (lower the joint stiffness)",
            });
        }
        self.clock.dt = match self.params.time_step {
            TimeStep::Auto { safety } => safety * crit.dt,
            TimeStep::Fixed(dt) => {
                if dt > crit.dt {
                    return Err(Error::TimeStepTooLarge {
                        dt,
                        limit: crit.dt,
                        block: crit.block,
                    });
                }
                dt
            }
        };
        Ok(())
    }
}

/// A contact whose area grew by more than this factor since the critical step was last
/// evaluated for it has its blocks' bounds re-evaluated (lost or shrinking contacts only make
/// the step safer).
const GROWTH: Real = 1.05;

/// The model's blocks and contacts, and the block → contact index, as the stability bounds
/// read them.
struct BoundSources<'a, L: ConstitutiveLaw> {
    state: &'a ModelState<L>,
    offsets: &'a [u32],
    contacts: &'a [u32],
    k_max: Real,
}

/// Blocks per task of the parallel pass over every block's side of its contacts.
const BLOCKS_PER_TASK: usize = 128;

impl<L: ConstitutiveLaw> BoundSources<'_, L> {
    /// Block `i`'s bound, from its contacts in contact order.
    fn bound(&self, i: usize) -> StiffnessBound {
        let entries = &self.contacts[self.offsets[i] as usize..self.offsets[i + 1] as usize];
        let contacts = entries.iter().map(|&e| {
            let k = (e / 2) as usize;
            let c = self.contact(k);
            let eigenvalues = contact_eigenvalues(&self.state.blocks, &c);
            (c, eigenvalues)
        });
        block_bound(&self.state.blocks, i, contacts, self.k_max)
    }

    /// What the bound needs of contact `k`: the area moments of its sub-contact points about the
    /// first one (for digits), its normal and stiffness.
    fn contact(&self, k: usize) -> ContactStiffness {
        let s = self.state;
        let (p, reference) = (&s.contacts.pairs[k], &s.contacts.references[k]);
        let subs = &s.contacts.subs[p.range()];
        let (sa, sb) = (&s.blocks[p.a as usize].state, &s.blocks[p.b as usize].state);
        let mut stiffness = s.laws.laws()[p.law as usize].stiffness();
        let mut moments = AreaMoments::default();
        let origin;
        if matches!(p.kind, ContactKind::Nodes) {
            // Every listed node, pressed or not, each along its own normal: bounded by the
            // stiffer spring in every direction.
            let (ba, bb) = (&s.blocks[p.a as usize], &s.blocks[p.b as usize]);
            let (ra, rb) = (Matrix::from_quat(sa.pose.rotation), Matrix::from_quat(sb.pose.rotation));
            let keys = reference.node_keys();
            let point = |k: usize| {
                stored_node_frame(
                    NodeId::from_key(keys[k]),
                    subs[k].plane.x as usize,
                    (sa, &ra, ba.shape()),
                    (sb, &rb, bb.shape()),
                )
                .0
            };
            origin = if subs.is_empty() { Vector::ZERO } else { point(0) };
            for (k, sub) in subs.iter().enumerate() {
                moments.add(point(k) - origin, sub.area);
            }
            let k = stiffness.normal.max(stiffness.shear);
            (stiffness.normal, stiffness.shear) = (k, k);
        } else {
            // The cells' area moments on the anchor plane, turned into the world about the
            // plane's origin: the same moments as cell by cell, without a pass over the cells.
            let small = SmallReference::of(&s.contacts.small_refs, k, s.params.mode);
            let frame = p.frame(small, &sa.pose, &sb.pose);
            let plane = &p.anchors;
            origin = frame.transform_point(plane.origin);
            moments = AreaMoments::of_plane(p.cells.area_moments, frame.rotation * plane.u, frame.rotation * plane.v);
        }
        ContactStiffness {
            a: p.a as usize,
            b: p.b as usize,
            normal: p.normal,
            stiffness,
            origin,
            moments,
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::block::{Block, Dof, Fixity};

    /// The whole evaluation (each block's side of its contacts once) gives every block the
    /// bound the per-block evaluation of the incremental path gives, to the bit: a settling
    /// wall on a fixed base (every degree of freedom prescribed) with a brick whose rotations
    /// are prescribed.
    #[test]
    fn the_whole_evaluation_is_the_per_block_one_to_the_bit() {
        let mut model = crate::scenes::benchmark_wall(400).expect("wall");
        let held = crate::block::BlockId(7);
        let fixity = Fixity {
            rotation: [Dof::Fixed; 3],
            ..Fixity::FREE
        };
        model.set_fixity(held, fixity).expect("fixity");
        model.run_steps(40).expect("run");
        let (state, pipeline) = (&mut model.state, &mut model.pipeline);
        state.refresh_time_step(pipeline).expect("refresh");
        let sources = state.bound_sources(&pipeline.block_offsets, &pipeline.block_contacts);
        let fixed = state.blocks.iter().filter(|b| b.fixity().is_fixed()).count();
        assert!(fixed > 0 && state.contacts.pairs.len() > state.blocks.len());
        for (i, bound) in pipeline.bounds.iter().enumerate() {
            let single = sources.bound(i);
            assert_eq!(
                bound.omega_squared.to_bits(),
                single.omega_squared.to_bits(),
                "block {i}"
            );
        }
        assert!(pipeline.bounds.iter().any(|b| b.omega_squared > 0.0));
    }
}
