//! The model: blocks, joint laws, gravity and loads; stepping and runs.

#[cfg(feature = "serde")]
mod checkpoint;
mod energy;
mod excitation;
mod observe;
mod parameters;
mod queries;
mod run;
mod setters;
mod step;
// The stages by name, for the rest of the model (checkpoints, setters, queries).
use step::{block_pass, changes, detection, pipeline};

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

#[cfg(feature = "serde")]
pub use checkpoint::reseal_checkpoint;

/// A check that a long step asks whether to stop ([`Model::set_interrupt_check`]).
#[derive(Clone)]
pub struct InterruptCheck(std::sync::Arc<dyn Fn() -> bool + Send + Sync>);

impl InterruptCheck {
    /// The check `stop`: the step stops when it returns `true`.
    pub fn new(stop: impl Fn() -> bool + Send + Sync + 'static) -> Self {
        Self(std::sync::Arc::new(stop))
    }

    /// Whether to stop.
    pub fn stop(&self) -> bool {
        (self.0)()
    }
}

impl std::fmt::Debug for InterruptCheck {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("InterruptCheck")
    }
}
pub use energy::Energies;
pub use observe::Observer;
pub use parameters::{JointStepping, ModelParameters};

use crate::block::RigidBlock;
use crate::contact::ContactStore;
use crate::integrate::{CriticalStep, Integrator, StepRecord};
use crate::law::{ConstitutiveLaw, CoulombSlip, LawTable};
use crate::math::{is_finite_vector, Pose, Real};

use changes::Changes;
/// The model's pipeline: the stages' scratch with the detection's.
type Pipeline<S> = pipeline::PipelineOf<detection::DetectionScratch<S>>;

/// A discrete element model of rigid blocks with joint law type `L`.
///
/// ```
/// use voussoir::prelude::*;
///
/// let mut model: Model = Model::new(ModelParameters::default())?;
/// model.set_joint_law(MaterialId(0), MaterialId(0), CoulombSlip::dry(1e9, 4e8, 30.0)?)?;
/// model.add_block(
///     RigidBlock::cuboid("base", Vector::new(-1.0, -1.0, -0.2), Vector::new(1.0, 1.0, 0.0), 2500.0)?
///         .with_fixity(Fixity::FIXED),
/// )?;
/// let cube = model.add_block(RigidBlock::cuboid("cube", Vector::ZERO, Vector::splat(0.2), 2500.0)?)?;
/// model.run_to_equilibrium(1e-4, 20_000)?;
/// let weight = 2500.0 * 0.008 * 9.81;
/// let support: f64 = model.contacts().map(|c| c.normal_force()).sum();
/// assert!((support - weight).abs() < 1e-3 * weight);
/// assert!(model.block(cube)?.displacement_of(Vector::splat(0.1)).length() < 1e-4);
/// # Ok::<(), voussoir::Error>(())
/// ```
pub struct Model<L: ConstitutiveLaw = CoulombSlip> {
    /// Everything a run continues from (and a checkpoint stores).
    state: ModelState<L>,
    /// What the step computes afresh, and buffers it reuses: no state of the model.
    pipeline: Pipeline<L::State>,
}

/// The model's state: blocks, laws, contacts with their history, time and energies; the
/// stages of the step are its methods, each given the [`Pipeline`] it may use as scratch.
pub(super) struct ModelState<L: ConstitutiveLaw> {
    pub params: ModelParameters,
    pub blocks: Vec<RigidBlock>,
    /// Each block's step record (reaction, damping force, ...), index for index with `blocks`.
    pub records: Vec<StepRecord>,
    pub laws: LawTable<L>,
    pub integrator: Box<dyn Integrator>,
    /// The contacts with their sub-contacts and history.
    pub contacts: ContactStore<L::State>,
    /// What detection keeps between detections.
    pub found: Found,
    /// The step's clock: count, time, lengths, the impact refinement.
    pub clock: StepClock,
    pub energy: Energies,
    /// What the setters changed since the last step (read first by [`Model::step`]).
    pub changes: Changes,
    /// Blocks whose fixity changed since the last detection ([`Model::set_fixity`]): the next
    /// detection looks at their pairs as if they had moved.
    pub refixed: Vec<u32>,
    pub unbalanced_ratio: Real,
    /// Base motions and load histories, by block.
    pub excitations: Excitations,
    /// How closed, sticking joints are stepped ([`Model::set_joint_stepping`]).
    pub joint_stepping: JointStepping,
}

/// What detection keeps from one detection to the next.
#[derive(Debug, Clone, Default)]
pub(super) struct Found {
    /// Each block's pose at the last detection: the next one runs once a block has moved the
    /// re-detection trigger from it.
    pub ref_poses: Vec<Pose>,
    /// The pairs the narrow phase tested and the relative poses it tested them at, sorted by
    /// pair (every contact has one): a pair keeps its verdict until it moves relatively.
    pub tested: Vec<detection::TestedPair>,
    /// Detections run.
    pub detections: u64,
}

/// The step's clock.
#[derive(Debug, Clone, Default)]
pub(super) struct StepClock {
    /// Steps taken.
    pub step: u64,
    /// Simulated time (s).
    pub time: Real,
    /// Whether the first step has been taken.
    pub started: bool,
    /// The step: `safety × critical` (or the fixed one), as set at the last evaluation.
    pub dt: Real,
    /// The step that brought the blocks to their poses (`Δt_{n−½}`): `dt`, or shorter around
    /// impacts (see [`ModelParameters::impact_step`]).
    pub drift: Real,
    /// The critical step of the last evaluation and the block that sets it.
    pub critical: Option<CriticalStep>,
    /// Impact refinement: the time until which it holds, and the largest squared frequency
    /// bound of the blocks that asked for it (0 when not refining).
    pub refine_until: Real,
    pub refine_omega2: Real,
    /// Whether the refinement also caps every block's travel per step at `impact_step` of the
    /// usual (`cap_drift`): a node contact asked for it (a node about to turn to another face
    /// is a kink crossed at the relative speed rather than at a spring's frequency; with
    /// friction, the slips across the kinks booked 1.5 % of m g h in 48 sharp drops without it).
    pub refine_travel: bool,
    /// The contacts (as sorted block pairs) the impact probe marked since the refinement began:
    /// the step is not relaxed while one of them is loaded and moving fast.
    pub refining: Vec<(u32, u32)>,
}

/// The blocks' excitations.
#[derive(Debug, Clone, Default)]
pub(super) struct Excitations {
    /// Base motions, by block ([`Model::set_base_motion`]).
    pub motions: Vec<excitation::AppliedMotion>,
    /// Time-varying loads, by block ([`Model::set_load_history`]).
    pub load_histories: Vec<excitation::AppliedLoad>,
}

/// Wall-clock time spent per stage since the model was built or [`Model::reset_timings`] (s).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct Timings {
    /// Broad and narrow phase, sub-contact history transfer and the critical step (and the
    /// blocks' rotation matrices and movement check, when the last step's block pass did not
    /// take them).
    pub detection: Real,
    /// Joint kinematics, laws and contact resultants.
    pub contacts: Real,
    /// The block pass: gathering each block's forces, the integrator, energies and checks (with
    /// a blockwise integrator also the next step's rotation matrices and movement check).
    pub integration: Real,
    /// Steps timed.
    pub steps: u64,
}

impl Timings {
    /// Total time (s).
    pub fn total(&self) -> Real {
        self.detection + self.contacts + self.integration
    }
}

impl<L: ConstitutiveLaw> std::fmt::Debug for Model<L> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Model")
            .field("blocks", &self.state.blocks.len())
            .field("contacts", &self.state.contacts.pairs.len())
            .field("subcontacts", &self.subcontact_count())
            .field("step", &self.state.clock.step)
            .field("time", &self.state.clock.time)
            .field("dt", &self.state.clock.dt)
            .finish()
    }
}

/// Blocks per chunk of the block passes: sums are taken per chunk, then over the chunks in order,
/// so that they do not depend on the number of threads.
const BLOCK_CHUNK: usize = 512;

/// Per-chunk sums of the block passes.
#[derive(Debug, Clone, Copy, Default)]
struct BlockSums {
    max_unbalanced: Real,
    gravity_work: Real,
    load_work: Real,
    boundary_work: Real,
    damping: Real,
    kinetic: Real,
    /// First block of the chunk that diverged.
    diverged: Option<usize>,
    /// The largest squared speeds of translation and of rotation at the radius of the
    /// chunk's blocks after the move (m²/s², see [`block_pass::move_speeds2`]).
    max_v2: Real,
    max_w2: Real,
    /// First block of the chunk that the step moved further than the contact tolerance, and
    /// how far (m).
    too_far: Option<(usize, Real)>,
    /// Whether a block of the chunk moved beyond the re-detection trigger (fused pass only).
    moved: bool,
}

/// Whether a block's state is non-finite or faster than `√max_speed2`. A non-finite velocity
/// fails the speed test (NaN or infinite); a non-finite position or rotation makes the sum of
/// their components non-finite (as would components beyond 10³⁰⁷, a run away all the same).
#[inline]
fn diverged(b: &RigidBlock, max_speed2: Real) -> bool {
    let s = &b.state;
    let r = b.radius;
    // Each on its own: `max` would hide a NaN of one behind the other.
    let (v2, w2) = (s.velocity.length_squared(), s.angular_velocity.length_squared() * r * r);
    let (t, q) = (s.pose.translation, s.pose.rotation);
    let pose_sum = ((t.x + t.y) + t.z) + ((q.x + q.y) + (q.z + q.w));
    let l = s.angular_momentum;
    !(v2 <= max_speed2 && w2 <= max_speed2 && pose_sum.is_finite() && (l.x + l.y + l.z).is_finite())
}

fn is_finite_state(s: &crate::block::BlockState) -> bool {
    is_finite_vector(s.velocity)
        && is_finite_vector(s.angular_velocity)
        && is_finite_vector(s.pose.translation)
        && s.pose.rotation.is_finite()
}

#[cfg(test)]
mod model_tests;
