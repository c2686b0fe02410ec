//! The step's contact pass: every contact's kinematics, law updates and resultant, in parallel
//! over fixed chunks of contacts.
//!
//! Each contact owns a contiguous range of the sub-contact list, and the ranges follow the
//! contacts in order, possibly with dead room between them that nothing reads (detection
//! builds them so, `docs/theory.md` §2.3; checkpoint load packs them). The pass
//! therefore splits the contact list and the sub-contact list together, with `split_at_mut`, at
//! chunk boundaries: every task owns its contacts' sub-contacts outright, and no `unsafe` is
//! needed. Sums are kept per chunk of [`CONTACT_CHUNK`] contacts and added in chunk order
//! afterwards, so that they do not depend on the number of threads.

use crate::block::{Block, BlockMotion, RigidBlock};
use crate::contact::{update_contact, update_nodes, KernelContext, LaneBuild, SmallReference};
use crate::geometry::ContactKind;
use crate::integrate::{StiffnessBound, TimeStep};
use crate::law::ConstitutiveLaw;
use crate::math::Real;
use crate::model::{ModelState, Pipeline};

/// Contacts per chunk of the contact pass: sums are taken per chunk, then over the chunks in
/// order.
pub(in crate::model) const CONTACT_CHUNK: usize = 64;

/// Chunks a task runs one after the other rather than splitting further.
const CHUNKS_PER_TASK: usize = 4;

/// How many contacts ahead of the one it steps the contact pass asks for the sub-contacts the
/// step will read ([`prefetch_cells`]).
const PREFETCH_AHEAD: usize = 8;

/// The most cache lines of one contact's sub-contacts asked for ahead (2 kB: a bed joint of
/// the benchmark wall); the hardware's stream prefetcher follows a longer run.
const PREFETCH_LINES: usize = 32;

/// Asks the processor to bring into cache the sub-contacts contact `q`'s step will read (its
/// [`ContactPair::cells_read_by_step`]); `subs` starts at sub-contact `base`. A hint: nothing
/// is read, and the results do not change.
///
/// With joints stepped as a whole, the sub-contacts a step reads are those of the contacts on
/// the cell path, scattered among the cells it skips, in runs too short for the hardware
/// prefetcher to follow: their first loads wait on memory (`docs/performance.md`, "Sub-contacts
/// asked for ahead").
#[inline(always)]
fn prefetch_cells<S>(q: &crate::contact::ContactPair, subs: &[crate::contact::SubContact<S>], base: usize) {
    #[cfg(target_arch = "x86_64")]
    {
        let own = q.first as usize - base..q.first as usize - base + q.count as usize;
        let read = q.cells_read_by_step();
        let Some(cells) = subs.get(own.start + read.start..own.start + read.end) else {
            return;
        };
        let start = cells.as_ptr().cast::<i8>();
        let bytes = std::mem::size_of_val(cells).min(PREFETCH_LINES * 64);
        for offset in (0..bytes).step_by(64) {
            // SAFETY: SSE is part of x86_64's baseline; a prefetch reads nothing and never
            // faults (the address stays within `cells` all the same).
            unsafe {
                std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>(start.wrapping_add(offset));
            }
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (q, subs, base);
}

/// What the contact pass reads, shared by its tasks.
pub(in crate::model) struct ContactPass<'a, L: ConstitutiveLaw> {
    pub blocks: &'a [RigidBlock],
    /// The blocks' motions, index for index.
    pub motions: &'a [BlockMotion],
    pub laws: &'a [L],
    /// The blocks' squared frequency bounds, for the impact probe.
    pub bounds: &'a [StiffnessBound],
    /// The contacts under impact refinement, sorted (empty when none).
    pub refining: &'a [(u32, u32)],
    pub ctx: KernelContext,
}

/// The contact pass's view of the contacts, with its per-chunk sums.
type Slices<'a, S> = crate::contact::ContactSlices<'a, S, PairSums>;

/// Per-chunk sums of the contact pass.
#[derive(Debug, Clone, Copy, Default)]
pub(in crate::model) struct PairSums {
    /// Σ |resultant| (N), for the unbalanced-force ratio.
    pub force_magnitude: Real,
    pub work: Real,
    /// Energy dissipated by the joint laws (J), their fracture work apart.
    pub dissipated: Real,
    /// The joint laws' fracture work (J).
    pub fracture: Real,
    pub dashpot_work: Real,
    /// The largest squared frequency bound of the blocks of an impacting contact (0: none).
    pub impact: Real,
    /// The blocks of the first impacting contacts, and how many there were (all the chunk's
    /// contacts count when they do not fit).
    pub fired: [(u32, u32); 4],
    pub fired_count: u32,
    /// Whether a loaded impacting contact moves fast.
    pub busy: bool,
    /// Whether an impacting contact is a node contact.
    pub node_impact: bool,
}

impl<L: ConstitutiveLaw> ContactPass<'_, L> {
    /// Runs the pass over `slices`: split in halves at chunk boundaries on rayon's pool down to
    /// [`CHUNKS_PER_TASK`] chunks, which run in order.
    pub fn run_all(&self, slices: Slices<'_, L::State>, avx2: bool) {
        let chunks = slices.pairs.len().div_ceil(CONTACT_CHUNK);
        if chunks > CHUNKS_PER_TASK {
            let (left, right) = slices.split(chunks / 2, CONTACT_CHUNK);
            rayon::join(|| self.run_all(left, avx2), || self.run_all(right, avx2));
            return;
        }
        let mut rest = slices;
        while rest.pairs.len() > CONTACT_CHUNK {
            let (chunk, tail) = rest.split(1, CONTACT_CHUNK);
            self.run_chunk(chunk, avx2);
            rest = tail;
        }
        if !rest.pairs.is_empty() {
            self.run_chunk(rest, avx2);
        }
    }

    /// One chunk, compiled for AVX2 where the processor has it.
    #[inline(always)]
    fn run_chunk(&self, chunk: Slices<'_, L::State>, avx2: bool) {
        #[cfg(target_arch = "x86_64")]
        if avx2 {
            // SAFETY: the processor has AVX2 (checked by `dispatch::has_avx2`).
            unsafe { self.run_avx2(chunk) };
            return;
        }
        let _ = avx2;
        self.run(chunk, LaneBuild::Portable);
    }

    /// Updates one chunk of contacts and their sub-contacts, writes their wrenches and adds
    /// their totals to the chunk's sums.
    #[inline(always)]
    fn run(&self, chunk: Slices<'_, L::State>, lanes: LaneBuild) {
        let ctx = KernelContext { lanes, ..self.ctx };
        let Slices {
            pairs,
            references,
            wrenches,
            small_refs,
            sums,
            subs,
            dashpots,
        } = chunk;
        let sums = &mut sums[0];
        let base = pairs[0].first as usize;
        // The cells of the first contacts, then at each contact those of the one
        // `PREFETCH_AHEAD` after it (`prefetch_cells`).
        for q in pairs.iter().take(PREFETCH_AHEAD) {
            prefetch_cells(q, subs, base);
        }
        for k in 0..pairs.len() {
            if let Some(q) = pairs.get(k + PREFETCH_AHEAD) {
                prefetch_cells(q, subs, base);
            }
            let (p, reference, w) = (&mut pairs[k], &mut references[k], &mut wrenches[k]);
            let (ma, mb) = (&self.motions[p.a as usize], &self.motions[p.b as usize]);
            let range = p.first as usize - base..p.first as usize - base + p.count as usize;
            let watch = !self.refining.is_empty() && self.refining.binary_search(&(p.a, p.b)).is_ok();
            // Empty when the model keeps no dashpot forces.
            let dashpots = if dashpots.is_empty() {
                &mut [][..]
            } else {
                &mut dashpots[range.clone()]
            };
            let step = if matches!(p.kind, ContactKind::Nodes) {
                let (a, b) = (&self.blocks[p.a as usize], &self.blocks[p.b as usize]);
                update_nodes(
                    p,
                    reference,
                    &mut subs[range],
                    dashpots,
                    (&a.state, &ma.rotation, a.shape()),
                    (&b.state, &mb.rotation, b.shape()),
                    &self.laws[p.law as usize],
                    ctx,
                    watch,
                )
            } else {
                update_contact(
                    p,
                    reference,
                    SmallReference::of(small_refs, k, ctx.mode),
                    &mut subs[range],
                    dashpots,
                    ma,
                    mb,
                    &self.laws[p.law as usize],
                    ctx,
                    if p.host_is_a { ma.radius } else { mb.radius },
                    watch,
                )
            };
            *w = step.wrench;
            sums.force_magnitude += step.wrench.force.length();
            sums.work += step.work;
            sums.dissipated += step.dissipated;
            sums.fracture += step.fracture;
            sums.dashpot_work += step.dashpot_work;
            if step.impact {
                let w2 = self.bounds[p.a as usize]
                    .omega_squared
                    .max(self.bounds[p.b as usize].omega_squared);
                sums.impact = sums.impact.max(w2);
                if (sums.fired_count as usize) < sums.fired.len() {
                    sums.fired[sums.fired_count as usize] = (p.a, p.b);
                }
                sums.fired_count += 1;
                sums.node_impact |= matches!(p.kind, ContactKind::Nodes);
            }
            sums.busy |= step.busy;
        }
    }

    /// [`ContactPass::run`] compiled for AVX2: the same IEEE operations in the three-operand VEX
    /// encoding, which saves the register copies of SSE2 (about a quarter of the instructions
    /// of the sub-contact loop). No fused multiply-add is enabled, so the results are
    /// bit-identical to [`ContactPass::run`].
    ///
    /// # Safety
    /// The processor must support AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn run_avx2(&self, chunk: Slices<'_, L::State>) {
        self.run(chunk, LaneBuild::Avx2);
    }
}

impl<L: ConstitutiveLaw> ModelState<L> {
    /// The contact pass; returns the largest squared frequency bound of the blocks of the
    /// contacts the impact probe marked (0: none), and whether a loaded contact it marked
    /// since the refinement began moves fast.
    pub(in crate::model) fn contact_pass(&mut self, pipeline: &mut Pipeline<L::State>) -> (Real, bool) {
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
            dt: self.clock.drift,
            impact_speed,
            impact_horizon: 2.0 * self.clock.dt,
            stiffness_damping: self.integrator.damping().stiffness_coefficient(),
            mode: self.params.mode,
            lanes: crate::contact::LaneBuild::Portable,
            joint_level: self.joint_stepping == crate::model::JointStepping::Whole,
            node_density: self.params.contact.density,
            node_rule: self.params.contact.node_rule,
            step: self.clock.step,
        };
        // Rayleigh damping puts dashpot forces on the sub-contacts: the model keeps them from
        // its first damped step on.
        if ctx.stiffness_damping > 0.0 {
            self.contacts.keep_dashpots();
        }
        // The lists run index for index with the contacts and the sub-contacts (kept so by
        // detection and checkpoint load).
        assert!(self.contacts.in_step(), "contact lists out of step");
        assert_eq!(pipeline.motions.len(), self.blocks.len(), "block motions out of step");
        // One pass per contact: its plane, its sub-contacts (in order), its resultant; summed
        // per fixed chunk of contacts, so that the totals do not depend on the thread count.
        pipeline.pair_sums.clear();
        pipeline
            .pair_sums
            .resize(self.contacts.pairs.len().div_ceil(CONTACT_CHUNK), PairSums::default());
        if !self.contacts.pairs.is_empty() {
            let slices = self.contacts.pass_view(&mut pipeline.pair_sums);
            let pass = ContactPass {
                blocks: &self.blocks,
                motions: &pipeline.motions,
                laws: self.laws.laws(),
                bounds: &pipeline.bounds,
                refining: &self.clock.refining,
                ctx,
            };
            pass.run_all(slices, crate::dispatch::has_avx2());
        }
        (
            pipeline.pair_sums.iter().map(|s| s.impact).fold(0.0, Real::max),
            pipeline.pair_sums.iter().any(|s| s.busy),
        )
    }
}
