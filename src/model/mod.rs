//! The model: blocks, joint laws, gravity and loads; stepping and runs.

mod changes;
#[cfg(feature = "serde")]
mod checkpoint;
#[cfg(feature = "serde")]
mod checkpoint_tested;
mod contact_pass;
mod detection;
mod energy;
mod excitation;
mod motion;
mod observe;
mod pipeline;
mod step;
mod time_step;

use rayon::prelude::*;
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

use crate::block::{Block, BlockId, Fixity, RigidBlock, Wrench};
use crate::contact::{
    ContactPair, ContactReference, ContactView, ContactWrench, DisplacementMode, SubContact, SubContactRecord,
};
use crate::error::{positive, Error, Result};
use crate::geometry::ContactParameters;
use crate::integrate::{CentralDifference, CriticalStep, Damping, Integrator, StepRecord, StiffnessBound, TimeStep};
use crate::law::{ConstitutiveLaw, CoulombSlip, LawTable, MaterialId};
use crate::math::{is_finite_vector, Pose, Real, Vector};

use changes::Changes;
use pipeline::Pipeline;

/// Global parameters of a model, with documented defaults.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(default, deny_unknown_fields))]
pub struct ModelParameters {
    /// Gravitational acceleration (m/s²). Default `(0, 0, −9.81)`.
    pub gravity: Vector,
    /// Contact detection and discretisation.
    pub contact: ContactParameters,
    /// Time step choice. Default automatic at 0.5 of the critical step.
    pub time_step: TimeStep,
    /// Large (default) or small displacements.
    pub mode: DisplacementMode,
    /// A block faster than this (m/s) means the run has diverged. Default 1000 m/s.
    pub max_speed: Real,
    /// Impact-resolving step: with an automatic step, while a sub-contact is about to close or
    /// open fast (an impact, a release), the step is refined to this fraction of the critical
    /// step of the blocks involved, and relaxed back once their contacts no longer cross the
    /// spring's kink (`docs/theory.md` §5.4). Default `Some(0.1)`; `None` keeps the step.
    pub impact_step: Option<Real>,
}

impl Default for ModelParameters {
    fn default() -> Self {
        Self {
            gravity: Vector::new(0.0, 0.0, -9.81),
            contact: ContactParameters::default(),
            time_step: TimeStep::default(),
            mode: DisplacementMode::Large,
            max_speed: 1e3,
            impact_step: Some(0.1),
        }
    }
}

impl ModelParameters {
    /// Checks every field.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] or [`Error::NonFinite`] naming the field.
    pub fn validate(&self) -> Result<()> {
        if !is_finite_vector(self.gravity) {
            return Err(Error::NonFinite { what: "gravity".into() });
        }
        self.contact.validate()?;
        match self.time_step {
            TimeStep::Auto { safety } => {
                crate::error::in_range("time_step.safety", safety, 1e-6, 1.0 + 1e-12, "must lie in (0, 1]")?;
            }
            TimeStep::Fixed(dt) => {
                positive("time_step", dt)?;
            }
        }
        positive("max_speed", self.max_speed)?;
        if let Some(r) = self.impact_step {
            crate::error::in_range("impact_step", r, 1e-6, 1.0 + 1e-12, "must lie in (0, 1]")?;
        }
        Ok(())
    }
}

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
    pub laws: LawTable<L>,
    pub integrator: Box<dyn Integrator>,
    pub pairs: Vec<ContactPair>,
    /// The contacts' reference geometry and areas, index for index with `pairs`.
    pub references: Vec<ContactReference>,
    pub subs: Vec<SubContact<L::State>>,
    /// The sub-contacts' records (key, slip, dashpot force), index for index with `subs`.
    pub sub_records: Vec<SubContactRecord>,
    pub records: Vec<StepRecord>,
    /// The contacts' resultants and moments, index for index with `pairs`: written by the
    /// contact pass, read by the per-block gather and the accessors (kept out of `ContactPair`,
    /// whose stream they would lengthen by 72 bytes per contact). Detection carries a kept
    /// contact's wrench and starts a new one at zero; checkpointed.
    pub wrenches: Vec<ContactWrench>,
    /// Each block's pose at the last detection: the next one runs once a block has moved the
    /// re-detection trigger from it.
    pub ref_poses: Vec<Pose>,
    /// The pairs the narrow phase tested and the relative poses it tested them at, sorted by
    /// pair (every contact has one): a pair keeps its verdict until it moves relatively.
    pub tested: Vec<detection::TestedPair>,
    /// The step: `safety × critical` (or the fixed one), as set at the last evaluation.
    pub dt: Real,
    /// The step that brought the blocks to their poses (`Δt_{n−½}`): `dt`, or shorter around
    /// impacts (see [`ModelParameters::impact_step`]).
    pub drift: Real,
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
    pub critical: Option<CriticalStep>,
    pub step: u64,
    pub time: Real,
    pub energy: Energies,
    pub started: bool,
    /// What the setters changed since the last step (read first by [`Model::step`]).
    pub changes: Changes,
    /// Blocks whose fixity changed since the last detection ([`Model::set_fixity`]): the next
    /// detection looks at their pairs as if they had moved.
    pub refixed: Vec<u32>,
    pub unbalanced_ratio: Real,
    pub detections: u64,
    /// Base motions, by block ([`Model::set_base_motion`]).
    pub motions: Vec<excitation::AppliedMotion>,
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
            .field("contacts", &self.state.pairs.len())
            .field("subcontacts", &self.subcontact_count())
            .field("step", &self.state.step)
            .field("time", &self.state.time)
            .field("dt", &self.state.dt)
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
    /// chunk's blocks after the move (m²/s², see [`motion::move_speeds2`]).
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

impl<L: ConstitutiveLaw> Model<L> {
    /// An empty model.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] or [`Error::NonFinite`] for bad parameters.
    pub fn new(params: ModelParameters) -> Result<Self> {
        params.validate()?;
        Ok(Self {
            state: ModelState {
                params,
                blocks: Vec::new(),
                laws: LawTable::new(),
                integrator: Box::new(CentralDifference::default()),
                pairs: Vec::new(),
                references: Vec::new(),
                subs: Vec::new(),
                sub_records: Vec::new(),
                records: Vec::new(),
                wrenches: Vec::new(),
                ref_poses: Vec::new(),
                tested: Vec::new(),
                dt: 0.0,
                drift: 0.0,
                refine_until: 0.0,
                refine_omega2: 0.0,
                refine_travel: false,
                refining: Vec::new(),
                critical: None,
                step: 0,
                time: 0.0,
                energy: Energies::default(),
                started: false,
                changes: Changes::DETECTION,
                refixed: Vec::new(),
                unbalanced_ratio: Real::INFINITY,
                detections: 0,
                motions: Vec::new(),
            },
            pipeline: Pipeline::default(),
        })
    }

    /// Adds a block and returns its id.
    ///
    /// # Errors
    /// [`Error::NonFinite`] for a NaN or infinite velocity, position, rotation, load or
    /// prescribed velocity; [`Error::InvalidParameter`] for a rotation that is not a unit
    /// quaternion, or a block too large for the sub-contact spacing
    /// ([`crate::geometry::MAX_SUBCONTACTS_PER_EDGE`] along a face edge).
    pub fn add_block(&mut self, mut block: RigidBlock) -> Result<BlockId> {
        block.validate()?;
        self.state
            .params
            .contact
            .check_block(block.shape().radius(), block.name())?;
        block.radius = block.shape().radius();
        let id = BlockId(self.state.blocks.len() as u32);
        self.state.ref_poses.push(block.state.pose);
        self.state.blocks.push(block);
        self.pipeline.forces.push(Wrench::default());
        self.state.records.push(StepRecord::default());
        self.pipeline.bounds.push(StiffnessBound::default());
        self.state.changes.insert(Changes::BLOCKS);
        self.pipeline.max_speed = None;
        Ok(id)
    }

    /// Sets the joint law between two materials (either order).
    ///
    /// # Errors
    /// The law's validation error.
    pub fn set_joint_law(&mut self, a: MaterialId, b: MaterialId, law: L) -> Result<()> {
        self.state.laws.insert(a, b, law)?;
        self.state.changes.insert(Changes::LAWS);
        Ok(())
    }

    /// Replaces the integrator.
    pub fn set_integrator(&mut self, integrator: impl Integrator + 'static) -> Result<()> {
        integrator.damping().validate()?;
        let old = std::mem::replace(&mut self.state.integrator, Box::new(integrator));
        if let Err(e) = self.state.refresh_time_step(&mut self.pipeline) {
            self.state.integrator = old;
            let _ = self.state.refresh_time_step(&mut self.pipeline);
            return Err(e);
        }
        Ok(())
    }

    /// Central difference with the given damping (shortcut for [`Model::set_integrator`]).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for bad coefficients; [`Error::TimeStepTooLarge`] if a fixed
    /// step is no longer stable with the new damping; [`Error::Unsupported`] while a custom
    /// integrator is set (which this would silently replace: use [`Model::set_integrator`]).
    pub fn set_damping(&mut self, damping: Damping) -> Result<()> {
        if self.state.integrator.checkpoint_damping().is_none() {
            return Err(Error::Unsupported {
                what: format!(
                    "set_damping would replace the custom integrator {:?}; set a new one with set_integrator",
                    self.state.integrator
                ),
            });
        }
        self.set_integrator(CentralDifference::new(damping))
    }

    /// Replaces the global parameters (gravity, contact parameters, time step, mode).
    ///
    /// New contact parameters or a new mode detect every contact afresh at the next step;
    /// once the model has stepped, other changes (gravity, the step's choice, the speed limit,
    /// the impact step) re-evaluate the critical step at once and keep the contacts; the same
    /// parameters change nothing.
    ///
    /// # Errors
    /// As [`ModelParameters::validate`]; [`Error::TimeStepTooLarge`] for a fixed step above the
    /// limit of the current contacts (the parameters are then left as they were).
    pub fn set_parameters(&mut self, params: ModelParameters) -> Result<()> {
        params.validate()?;
        for b in &self.state.blocks {
            params.contact.check_block(b.shape().radius(), b.name())?;
        }
        let old = std::mem::replace(&mut self.state.params, params);
        if !self.state.started || params.contact != old.contact || params.mode != old.mode {
            // Contacts are detected and discretised afresh with the new contact parameters.
            self.state.changes.insert(Changes::PARAMETERS);
        } else if params != old {
            // Gravity, the step's choice, the speed limit: no contact changes, the step is
            // re-evaluated now (as `set_integrator` does), and nothing changes on an error.
            if let Err(e) = self.state.refresh_time_step(&mut self.pipeline) {
                self.state.params = old;
                let _ = self.state.refresh_time_step(&mut self.pipeline);
                return Err(e);
            }
        }
        Ok(())
    }

    /// The global parameters.
    pub fn parameters(&self) -> &ModelParameters {
        &self.state.params
    }

    /// Sets the constant external load (force, and moment about the centroid) on a block.
    ///
    /// # Errors
    /// [`Error::UnknownBlock`], [`Error::NonFinite`].
    pub fn set_load(&mut self, id: BlockId, load: Wrench) -> Result<()> {
        if !is_finite_vector(load.force) || !is_finite_vector(load.moment) {
            return Err(Error::NonFinite {
                what: format!("load on block {id}"),
            });
        }
        self.block_mut(id)?.load = load;
        Ok(())
    }

    /// Sets the fixity of a block.
    ///
    /// Costs what the block's neighbourhood costs, not the model's: the critical step is
    /// re-evaluated for the block and those in contact with it, and the next step looks at the
    /// block's pairs as if it had moved (a released block meets the fixed blocks it had no
    /// contact with; a fixed one drops its contacts with fixed blocks).
    ///
    /// A translation driven by a base motion ([`Model::set_base_motion`]) cannot be set free
    /// while the motion applies (the motion would put it back at the next step, and a model
    /// saved in between would not load): remove the motion first. Setting it fixed or
    /// prescribed is accepted; the motion sets its velocity at every step.
    ///
    /// # Errors
    /// [`Error::UnknownBlock`], [`Error::NonFinite`] for a NaN prescribed velocity,
    /// [`Error::DrivenAxisFreed`] naming the block, the axis and the motion.
    pub fn set_fixity(&mut self, id: BlockId, fixity: Fixity) -> Result<()> {
        self.block(id)?;
        self.check_driven_axes(id, &fixity)?;
        let b = self.block_mut(id)?;
        let old = b.fixity().to_owned();
        b.replace_fixity(fixity);
        if let Err(e) = b.validate() {
            b.replace_fixity(old);
            return Err(e);
        }
        if let Err(e) = self.state.refresh_time_step_around(&mut self.pipeline, id.0) {
            let b = self.block_mut(id)?;
            b.replace_fixity(old);
            let _ = self.state.refresh_time_step_around(&mut self.pipeline, id.0);
            return Err(e);
        }
        // A released block may touch blocks it had no contact with while both were fixed, and
        // a fixed one loses its contacts with fixed blocks: the next detection looks at this
        // block's pairs as if it had moved (not at every pair of the model).
        self.state.refixed.push(id.0);
        Ok(())
    }

    /// Changes the values of a block's prescribed translation velocities (m/s), keeping which
    /// degrees of freedom are free, fixed or prescribed: each translation of the block that is
    /// prescribed ([`Dof::Velocity`](crate::block::Dof::Velocity)) takes the matching component
    /// of `velocity`; free and fixed ones are left as they are. Unlike [`Model::set_fixity`] this
    /// changes no contact and asks for no detection, so a controller may call it every step
    /// (see [`crate::loading::Servo`]).
    ///
    /// # Errors
    /// [`Error::UnknownBlock`]; [`Error::NonFinite`]; [`Error::InvalidParameter`] when no
    /// translation of the block is prescribed.
    pub fn set_prescribed_velocity(&mut self, id: BlockId, velocity: Vector) -> Result<()> {
        if !is_finite_vector(velocity) {
            return Err(Error::NonFinite {
                what: format!("prescribed velocity of block {id}"),
            });
        }
        let b = self.block_mut(id)?;
        let mut fixity = *b.fixity();
        let mut any = false;
        for (d, v) in fixity.translation.iter_mut().zip(velocity.to_array()) {
            if let crate::block::Dof::Velocity(old) = d {
                *old = v;
                any = true;
            }
        }
        if !any {
            return Err(Error::InvalidParameter {
                name: format!("prescribed velocity of block {id}"),
                value: velocity.length(),
                expected: "a block with a translation at prescribed velocity (Dof::Velocity)",
            });
        }
        b.replace_fixity(fixity);
        Ok(())
    }

    /// Sets a block's velocity (m/s) and angular velocity (rad/s). During a run, the change of
    /// kinetic energy counts as energy put in ([`Energies::initial_kinetic`]).
    ///
    /// # Errors
    /// [`Error::UnknownBlock`], [`Error::NonFinite`] (also for a kinetic energy that overflows).
    pub fn set_velocity(&mut self, id: BlockId, velocity: Vector, angular_velocity: Vector) -> Result<()> {
        if !is_finite_vector(velocity) || !is_finite_vector(angular_velocity) {
            return Err(Error::NonFinite {
                what: format!("velocity of block {id}"),
            });
        }
        let b = self.block_mut(id)?;
        let before = b.kinetic_energy();
        let (v0, w0) = (b.state.velocity, b.state.angular_velocity);
        b.replace_velocity(velocity, angular_velocity);
        let after = b.kinetic_energy();
        if !after.is_finite() {
            // 1e308 m/s: the kinetic energy overflows (and a checkpoint would not load).
            b.replace_velocity(v0, w0);
            return Err(Error::NonFinite {
                what: format!("kinetic energy of block {id} at the velocity given (beyond f64's range)"),
            });
        }
        // Kinetic energy given by the user counts as energy put in.
        if self.state.started {
            self.state.energy.initial_kinetic += after - before;
            self.state.energy.kinetic += after - before;
        }
        Ok(())
    }

    fn block_mut(&mut self, id: BlockId) -> Result<&mut RigidBlock> {
        let count = self.state.blocks.len();
        // A velocity or fixity may change: the next step measures the speeds afresh.
        self.pipeline.max_speed = None;
        self.state
            .blocks
            .get_mut(id.index())
            .ok_or(Error::UnknownBlock { id, count })
    }

    /// A block by id.
    ///
    /// # Errors
    /// [`Error::UnknownBlock`].
    pub fn block(&self, id: BlockId) -> Result<&RigidBlock> {
        self.state.blocks.get(id.index()).ok_or(Error::UnknownBlock {
            id,
            count: self.state.blocks.len(),
        })
    }

    /// All blocks, indexed by [`BlockId::index`].
    pub fn blocks(&self) -> &[RigidBlock] {
        &self.state.blocks
    }

    /// The joint laws.
    pub fn law_table(&self) -> &LawTable<L> {
        &self.state.laws
    }

    /// The current contacts, each with its sub-contacts.
    pub fn contacts(&self) -> impl ExactSizeIterator<Item = ContactView<'_, L::State>> + '_ {
        (0..self.state.pairs.len()).map(move |k| self.view(k))
    }

    /// The contact between two blocks, if any.
    pub fn contact_between(&self, a: BlockId, b: BlockId) -> Option<ContactView<'_, L::State>> {
        let key = (a.0.min(b.0), a.0.max(b.0));
        self.state
            .pairs
            .binary_search_by_key(&key, |p| (p.a, p.b))
            .ok()
            .map(|k| self.view(k))
    }

    fn view(&self, k: usize) -> ContactView<'_, L::State> {
        let p = &self.state.pairs[k];
        let (sa, sb) = (
            &self.state.blocks[p.a as usize].state,
            &self.state.blocks[p.b as usize].state,
        );
        let nodes = matches!(p.kind, crate::geometry::ContactKind::Nodes).then(|| crate::contact::NodeGeometry {
            states: [sa, sb],
            rotations: [
                crate::math::Matrix::from_quat(sa.pose.rotation),
                crate::math::Matrix::from_quat(sb.pose.rotation),
            ],
            shapes: [
                self.state.blocks[p.a as usize].shape(),
                self.state.blocks[p.b as usize].shape(),
            ],
        });
        let law = &self.state.laws.laws()[p.law as usize];
        let exact = matches!(p.kind, crate::geometry::ContactKind::FaceFace { .. })
            && self.state.params.mode == DisplacementMode::Large
            && law.elastic_regime().is_some_and(|r| r.normal_stiffness > 0.0);
        let cells = exact.then(|| crate::contact::CellGeometry {
            law: law as &dyn crate::contact::TensionFree<L::State>,
            coefficients: crate::contact::face_gap_coefficients(p, &sa.pose, &sb.pose),
        });
        ContactView::new(
            p,
            &self.state.subs[p.range()],
            &self.state.sub_records[p.range()],
            p.frame(&self.state.references[k], &sa.pose, &sb.pose, self.state.params.mode),
            self.state.wrenches[k],
            (nodes, cells),
        )
    }

    /// Total number of sub-contacts.
    pub fn subcontact_count(&self) -> usize {
        self.state.pairs.iter().map(|p| p.count as usize).sum()
    }

    /// Steps taken.
    pub fn step_count(&self) -> u64 {
        self.state.step
    }

    /// Simulated time (s).
    pub fn time(&self) -> Real {
        self.state.time
    }

    /// The time step in use (s); zero before the first step.
    pub fn dt(&self) -> Real {
        self.state.dt
    }

    /// The duration of the last step (s): [`dt`](Self::dt), or shorter while the step was refined
    /// around an impact (see [`ModelParameters::impact_step`]); `dt` before the first step.
    pub fn last_step(&self) -> Real {
        if self.state.drift > 0.0 {
            self.state.drift
        } else {
            self.state.dt
        }
    }

    /// The critical time step and the block that limits it (after the first step).
    pub fn critical_step(&self) -> Option<CriticalStep> {
        self.state.critical
    }

    /// Energies since the start.
    ///
    /// The elastic energy stored in the joints is not needed to step, so it is summed over the
    /// sub-contacts here, when asked for: a call costs about one pass over the sub-contacts.
    pub fn energies(&self) -> Energies {
        let mut e = self.state.energy;
        e.elastic = self.elastic_energy();
        e
    }

    /// Elastic energy in the joint springs (J): per contact in sub-contact order, contacts in
    /// fixed chunks, chunks in order, so the sum does not depend on the thread count.
    fn elastic_energy(&self) -> Real {
        let laws = self.state.laws.laws();
        let chunk_sums: Vec<Real> = self
            .state
            .pairs
            .par_chunks(1024)
            .map(|chunk| {
                chunk
                    .iter()
                    .map(|p| {
                        let law = &laws[p.law as usize];
                        self.state.subs[p.range()]
                            .iter()
                            .map(|s| law.elastic_energy(s.area, &s.force, &s.state))
                            .sum::<Real>()
                            + p.spread_energy
                    })
                    .sum::<Real>()
            })
            .collect();
        chunk_sums.iter().sum()
    }

    /// The accumulated energy terms without the elastic and friction terms (which
    /// [`Model::energies`] fills in).
    pub(crate) fn energy_accumulators(&self) -> &Energies {
        &self.state.energy
    }

    /// Number of contact detections run so far.
    pub fn detection_count(&self) -> u64 {
        self.state.detections
    }

    /// Number of block pairs the narrow phase tested since the model was built or restored: at
    /// a detection, only the pairs with a block that moved beyond the re-detection trigger whose
    /// relative pose changed beyond it since their last test (`docs/theory.md` §2.3). A
    /// statistic, like [`Model::timings`]; a checkpoint does not store it.
    pub fn pair_tests(&self) -> u64 {
        self.pipeline.detection.tests
    }

    /// Unbalanced-force ratio of the last step: the largest out-of-balance force on a free block
    /// divided by the mean contact force (infinite before the first step or without contacts).
    pub fn unbalanced_force_ratio(&self) -> Real {
        self.state.unbalanced_ratio
    }

    /// Force and moment the supports or prescribed velocities applied to a block in the last step.
    ///
    /// # Errors
    /// [`Error::UnknownBlock`].
    pub fn reaction(&self, id: BlockId) -> Result<Wrench> {
        self.block(id)?;
        Ok(self.state.records[id.index()].reaction)
    }

    /// Total contact force and moment (about its centroid) on a block in the last step.
    ///
    /// # Errors
    /// [`Error::UnknownBlock`].
    pub fn contact_wrench(&self, id: BlockId) -> Result<Wrench> {
        self.block(id)?;
        Ok(self.contact_wrench_of(id.index()))
    }

    fn contact_wrench_of(&self, i: usize) -> Wrench {
        // Before the first detection (no step yet, or a block added since), the block has no
        // contacts the model knows of.
        let offsets = &self.pipeline.block_offsets;
        let (Some(&start), Some(&end)) = (offsets.get(i), offsets.get(i + 1)) else {
            return Wrench::default();
        };
        let entries = &self.pipeline.block_contacts[start as usize..end as usize];
        motion::add_contact_wrenches(Wrench::default(), entries, &self.state.wrenches)
    }

    /// Time spent per stage (wall clock).
    pub fn timings(&self) -> &Timings {
        &self.pipeline.timings
    }

    /// Restarts the stage timers.
    pub fn reset_timings(&mut self) {
        self.pipeline.timings = Timings::default();
    }

    /// Sets the check a long step asks, between the batches of a contact detection, whether to
    /// stop (`None` removes it): a front end watching for Ctrl-C or a deadline. When it returns
    /// `true` the step stops with [`Error::Interrupted`] before it changes any contact or block:
    /// the model is as before the step, and its next step detects every contact afresh. The
    /// first detection of a 100k-block wall asks it about every 25 ms on 2 cores. Not saved in
    /// checkpoints.
    ///
    /// ```
    /// use std::sync::atomic::{AtomicBool, Ordering};
    /// use std::sync::Arc;
    /// use voussoir::model::InterruptCheck;
    /// use voussoir::prelude::*;
    ///
    /// let mut model = voussoir::scenes::benchmark_wall(200)?;
    /// let stop = Arc::new(AtomicBool::new(true));
    /// let flag = Arc::clone(&stop);
    /// model.set_interrupt_check(Some(InterruptCheck::new(move || flag.load(Ordering::Relaxed))));
    /// assert!(matches!(model.step(), Err(Error::Interrupted { step: 0 })));
    /// stop.store(false, Ordering::Relaxed);
    /// model.step()?;
    /// assert_eq!(model.step_count(), 1);
    /// # Ok::<(), voussoir::Error>(())
    /// ```
    pub fn set_interrupt_check(&mut self, check: Option<InterruptCheck>) {
        self.pipeline.interrupt = check;
    }

    /// The integrator's damping model.
    pub fn damping(&self) -> Damping {
        self.state.integrator.damping()
    }

    /// One step.
    ///
    /// # Errors
    /// [`Error::EmptyModel`] for a model without blocks; [`Error::InitialOverlap`] at the
    /// first step for blocks that overlap by more than the contact tolerance;
    /// [`Error::MissingJointLaw`] when blocks of materials with no law touch;
    /// [`Error::TimeStepTooLarge`] for a fixed step above the critical one;
    /// [`Error::Diverged`] naming the step and block when the state becomes non-finite or runaway.
    pub fn step(&mut self) -> Result<()> {
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
        while self.state.time < t {
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
    /// [`Error::NotConverged`] after `max_steps`; otherwise as [`Model::step`].
    pub fn run_to_equilibrium(&mut self, target: Real, max_steps: u64) -> Result<u64> {
        positive("equilibrium target ratio", target)?;
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::{update_contact, KernelContext};
    use crate::law::JointStatus;

    /// The AVX2 builds of the contact pass and the integrator and the portable ones give
    /// bit-identical results (no
    /// fused multiply-add, same operations in the same order). Meaningful on a processor with
    /// AVX2; elsewhere both runs take the portable path.
    #[test]
    fn avx2_and_portable_builds_are_bit_identical() {
        let run = |portable: bool| {
            crate::dispatch::set_portable_only(portable);
            let mut model = crate::scenes::benchmark_wall(300).expect("wall");
            model.run_steps(300).expect("run");
            crate::dispatch::set_portable_only(false);
            let states: Vec<_> = model.blocks().iter().map(|b| *b.state()).collect();
            (states, model.energies())
        };
        let (fast, fast_energy) = run(false);
        let (portable, portable_energy) = run(true);
        assert!(fast
            .iter()
            .zip(&portable)
            .any(|(a, b)| a.velocity != Vector::ZERO && a == b));
        assert_eq!(fast, portable);
        assert_eq!(fast_energy, portable_energy);
    }

    /// A column of four cubes on a fixed base, each overhanging the one below by 40 mm: it
    /// leans and topples, so blocks move beyond the re-detection trigger, joints open onto
    /// edges (node contacts) and contacts change.
    pub(crate) fn toppling_column(params: ModelParameters) -> Model {
        let mut column: Model = Model::new(params).expect("model");
        column
            .set_joint_law(
                MaterialId(0),
                MaterialId(0),
                CoulombSlip::dry(1e8, 4e7, 30.0).expect("law"),
            )
            .expect("law");
        let base = RigidBlock::cuboid(
            "base",
            Vector::new(-1.0, -1.0, -0.2),
            Vector::new(1.0, 1.0, 0.0),
            2500.0,
        )
        .expect("base")
        .with_fixity(crate::block::Fixity::FIXED);
        column.add_block(base).expect("base");
        for level in 0..4 {
            let (x, z) = (0.04 * level as Real, 0.1 * level as Real);
            let cube = RigidBlock::cuboid(
                "cube",
                Vector::new(x - 0.05, -0.05, z),
                Vector::new(x + 0.05, 0.05, z + 0.1),
                2500.0,
            )
            .expect("cube");
            column.add_block(cube).expect("cube");
        }
        column
    }

    /// Runs both sub-contact loops on every contact of `model` from its current state and
    /// checks that each sub-contact gets bit for bit the same forces, gap, status, law state and
    /// slip, and each contact the same sums to round-off. Returns the numbers of sub-contacts
    /// compared, sliding, open, and of nodes of node contacts (not compared: one loop).
    fn compare_loops<L: ConstitutiveLaw<State = crate::law::CoulombState>>(model: &Model, law: &L) -> [usize; 4] {
        let ctx = KernelContext {
            dt: model.state.dt,
            impact_speed: Real::INFINITY,
            impact_horizon: 0.0,
            stiffness_damping: 0.0,
            mode: model.state.params.mode,
        };
        let (mut grouped_subs, mut single_subs) = (model.state.subs.clone(), model.state.subs.clone());
        let (mut grouped_records, mut single_records) =
            (model.state.sub_records.clone(), model.state.sub_records.clone());
        let (mut grouped_pairs, mut single_pairs) = (model.state.pairs.clone(), model.state.pairs.clone());
        let mut counts = [0; 4];
        for k in 0..model.state.pairs.len() {
            let r = model.state.pairs[k].range();
            let (a, b) = (model.state.pairs[k].a as usize, model.state.pairs[k].b as usize);
            let (ra, rb) = (
                crate::math::Matrix::from_quat(model.state.blocks[a].state.pose.rotation),
                crate::math::Matrix::from_quat(model.state.blocks[b].state.pose.rotation),
            );
            let (sa, sb) = ((&model.state.blocks[a].state, &ra), (&model.state.blocks[b].state, &rb));
            if matches!(model.state.pairs[k].kind, crate::geometry::ContactKind::Nodes) {
                // Node contacts have one loop (`contact/nodes.rs`).
                counts[3] += r.len();
                continue;
            }
            // The grouped loop runs without dashpot forces; the single loop when the contact may
            // hold some (none are held here, so it books zero dashpot forces).
            let (mut grouped_wrench, mut single_wrench) = (ContactWrench::default(), ContactWrench::default());
            for (dashpots, pairs, subs, records, wrench) in [
                (
                    false,
                    &mut grouped_pairs,
                    &mut grouped_subs,
                    &mut grouped_records,
                    &mut grouped_wrench,
                ),
                (
                    true,
                    &mut single_pairs,
                    &mut single_subs,
                    &mut single_records,
                    &mut single_wrench,
                ),
            ] {
                pairs[k].dashpots = dashpots;
                *wrench = update_contact(
                    &mut pairs[k],
                    &model.state.references[k],
                    &mut subs[r.clone()],
                    &mut records[r.clone()],
                    sa,
                    sb,
                    law,
                    ctx,
                    0.0,
                    false,
                )
                .wrench;
            }
            for i in r {
                assert_eq!(grouped_subs[i], single_subs[i], "contact {k}, sub-contact {i}");
                assert_eq!(grouped_records[i], single_records[i], "contact {k}, sub-contact {i}");
                counts[0] += 1;
                counts[1] += usize::from(single_subs[i].status == JointStatus::Sliding);
                counts[2] += usize::from(single_subs[i].status == JointStatus::Open);
            }
            let (g, s) = (&grouped_pairs[k], &single_pairs[k]);
            let scale = s.normal_force.abs().max(1e-9);
            let (gw, sw) = (grouped_wrench, single_wrench);
            assert!((gw.force - sw.force).length() <= 1e-12 * scale, "contact {k}");
            assert!((g.normal_force - s.normal_force).abs() <= 1e-12 * scale, "contact {k}");
            let arm = (gw.moment_a - sw.moment_a).length() + (gw.moment_b - sw.moment_b).length();
            assert!(arm <= 1e-12 * scale, "contact {k}: {arm}");
        }
        counts
    }

    /// [`CoulombSlip`] with its law but without its elastic regime, so that the kernel takes
    /// the four-at-a-time loop.
    #[derive(Debug, Clone)]
    struct WithoutRegime(CoulombSlip);

    impl ConstitutiveLaw for WithoutRegime {
        type State = crate::law::CoulombState;
        fn stiffness(&self) -> crate::law::JointStiffness {
            self.0.stiffness()
        }
        fn update(
            &self,
            step: &crate::law::JointStep,
            force: &mut crate::law::JointForce,
            state: &mut Self::State,
        ) -> JointStatus {
            self.0.update(step, force, state)
        }
        fn stays_open(&self, area: Real, gap: Real, state: &Self::State) -> bool {
            self.0.stays_open(area, gap, state)
        }
    }

    /// Both loops for contacts without dashpot forces — sub-contacts in their elastic regime
    /// first (a law with an [`crate::law::ElasticRegime`]), four at a time (a law
    /// without) — give each sub-contact bit for bit the forces, gap, status, law state and slip
    /// of the one-at-a-time loop (which runs when the contact has dashpot forces); only the
    /// contact sums of the four-at-a-time loop, taken in another order, differ by round-off.
    /// On a settling wall, and on a toppling column (incremental gaps) in large-
    /// and small-displacement mode.
    #[test]
    fn grouped_and_single_sub_contact_loops_agree() {
        let mut wall = crate::scenes::benchmark_wall(300).expect("wall");
        wall.run_steps(40).expect("run");
        let coulomb = wall.state.laws.laws()[0];
        for counts in [
            compare_loops(&wall, &coulomb),
            compare_loops(&wall, &WithoutRegime(coulomb)),
        ] {
            let [compared, sliding, open, _] = counts;
            assert!(
                compared > 10_000 && sliding > 100 && open > 100,
                "{compared} {sliding} {open}"
            );
        }

        for mode in [DisplacementMode::Large, DisplacementMode::Small] {
            let mut params = ModelParameters {
                mode,
                ..ModelParameters::default()
            };
            // Faces more than 15° apart make node contacts too (counted, not compared).
            params.contact.face_angle_tolerance = 15f64.to_radians();
            let mut column = toppling_column(params);
            let mut totals = [0; 4];
            let coulomb = column.state.laws.laws()[0];
            for _ in 0..8 {
                column.run_steps(150).expect("run");
                for counts in [
                    compare_loops(&column, &coulomb),
                    compare_loops(&column, &WithoutRegime(coulomb)),
                ] {
                    totals.iter_mut().zip(counts).for_each(|(t, c)| *t += c);
                }
            }
            assert!(totals[0] > 1_000 && totals[2] > 10, "{mode:?}: {totals:?}");
        }
    }

    /// Re-detection carries each sub-contact's shear force as the same world vector, also where
    /// the joint's tangents are not the ones a new contact with that normal would get (they have
    /// turned with the plane): the carried components are read in the old contact's axes. A
    /// tilted, near-vertical joint whose first tangent is turned 40° about the normal from the
    /// fresh one; reading the components in fresh axes would turn every shear force by 40°.
    #[test]
    fn redetection_carries_shear_forces_in_turned_axes() {
        use crate::geometry::SubKey;
        use crate::law::JointAxes;
        use crate::math::Pose;
        let mut model: Model = Model::new(ModelParameters::default()).expect("model");
        model
            .set_joint_law(
                MaterialId(0),
                MaterialId(0),
                CoulombSlip::dry(1e9, 4e8, 30.0).expect("law"),
            )
            .expect("law");
        // Two cubes side by side (joint normal along x), the pair tilted generically.
        let tilt = Pose {
            translation: Vector::new(0.3, -0.2, 1.0),
            rotation: crate::math::Rotation::from_scaled_axis(Vector::new(0.15, -0.25, 0.6)),
        };
        let cube = |name: &str, x: Real| {
            RigidBlock::cuboid(name, Vector::new(x, 0.0, 0.0), Vector::new(x + 0.2, 0.2, 0.2), 2500.0)
                .expect("cube")
                .transformed(tilt)
                .with_fixity(crate::block::Fixity::FIXED)
        };
        model.add_block(cube("a", 0.0)).expect("a");
        // Held still too, but not `FIXED` (two fixed blocks get no contact).
        let b = cube("b", 0.2).with_fixity(crate::block::Fixity::velocity(Vector::ZERO));
        model.add_block(b).expect("b");
        model.run_steps(1).expect("detection");
        assert_eq!(model.state.pairs.len(), 1, "one joint");
        let (normal, range) = (model.state.pairs[0].normal, model.state.pairs[0].range());
        assert!(normal.z.abs() < 0.6, "a steep joint: {normal}");
        // Turn the tangents 40° about the normal and load the springs elastically.
        let fresh = JointAxes::from_normal(normal);
        let turned = crate::math::Rotation::from_axis_angle(normal, 40f64.to_radians()) * fresh.tangent;
        model.state.pairs[0].tangent = turned;
        for (i, sub) in model.state.subs[range].iter_mut().enumerate() {
            sub.force.normal = 100.0 + i as Real;
            sub.force.shear = crate::math::Vector2::new(30.0 - i as Real, 5.0 + 2.0 * i as Real);
            sub.status = JointStatus::Elastic;
        }
        let mut subs = model.state.subs[model.state.pairs[0].range()].to_vec();
        let law = model.state.laws.laws()[0];
        let poses = (model.state.blocks[0].state.pose, model.state.blocks[1].state.pose);
        model.state.pairs[0].refresh_springs(&mut subs, &law, Some((&poses.0, &poses.1)));
        let world_shears = |m: &Model| -> Vec<(SubKey, Vector)> {
            let view = m.contacts().next().expect("the joint");
            view.subcontacts().map(|s| (s.key(), s.shear_force())).collect()
        };
        let before = world_shears(&model);
        model.state.changes.insert(Changes::DETECTION);
        model.state.detect(&mut model.pipeline).expect("re-detection");
        let after = world_shears(&model);
        assert_eq!(before.len(), after.len());
        let mut worst: Real = 0.0;
        for ((k0, f0), (k1, f1)) in before.iter().zip(&after) {
            assert_eq!(k0, k1);
            worst = worst.max((*f1 - *f0).length() / f0.length());
        }
        assert!(worst < 1e-14, "shear forces changed by {worst} (relative)");
        // What fresh axes would have given: the test can tell.
        let misread = before[0].1.length() * 2.0 * (20f64.to_radians()).sin();
        let first = model.state.subs[model.state.pairs[0].range()][0].force.shear;
        assert!((fresh.shear(first) - before[0].1).length() > 0.5 * misread);
    }

    /// A custom integrator is neither saved as another nor silently replaced by `set_damping`.
    #[test]
    fn custom_integrators_are_not_swapped_behind_the_users_back() {
        use crate::block::{BlockState, Fixity};
        use crate::geometry::MassProperties;
        use crate::integrate::{StepDurations, StepRecord};

        #[derive(Debug, Clone, Copy)]
        struct Mine(CentralDifference);
        impl Integrator for Mine {
            fn advance_block(
                &self,
                state: &mut BlockState,
                mass: &MassProperties,
                fixity: &Fixity,
                wrench: &Wrench,
                step: StepDurations,
            ) -> StepRecord {
                self.0.advance_block(state, mass, fixity, wrench, step)
            }
            fn damping(&self) -> Damping {
                self.0.damping()
            }
            fn boxed_clone(&self) -> Box<dyn Integrator> {
                Box::new(*self)
            }
        }
        let mut model: Model = Model::new(ModelParameters::default()).unwrap();
        model
            .add_block(RigidBlock::cuboid("b", Vector::ZERO, Vector::splat(0.1), 2000.0).unwrap())
            .unwrap();
        model
            .set_integrator(Mine(CentralDifference::new(Damping::None)))
            .unwrap();
        model.run_steps(3).unwrap();
        assert!(matches!(
            model.set_damping(Damping::None),
            Err(Error::Unsupported { .. })
        ));
        #[cfg(feature = "serde")]
        assert!(matches!(model.to_checkpoint_string(), Err(Error::Unsupported { .. })));
        // Central difference is restored by a checkpoint, and set_damping replaces it.
        model.set_integrator(CentralDifference::new(Damping::None)).unwrap();
        model.set_damping(Damping::Local { alpha: 0.8 }).unwrap();
        #[cfg(feature = "serde")]
        assert!(model.to_checkpoint_string().is_ok());
    }
}
