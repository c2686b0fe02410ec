//! Building and changing a model: [`Model::new`] and the setters (blocks, joint laws, the
//! integrator and its damping, parameters, loads, fixities, velocities, the interrupt check),
//! each of which records what it changed for the next step.

use super::changes::Changes;
use super::Pipeline;
use super::{
    Energies, Excitations, Found, InterruptCheck, JointStepping, Model, ModelParameters, ModelState, StepClock,
};
use crate::block::{Block, BlockId, Fixity, RigidBlock, Wrench};
use crate::contact::ContactStore;
use crate::error::{Error, Result};
use crate::integrate::{CentralDifference, Damping, Integrator, StepRecord, StiffnessBound};
use crate::law::{ConstitutiveLaw, LawTable, MaterialId};
use crate::math::{is_finite_vector, Real, Vector};

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
                records: Vec::new(),
                laws: LawTable::new(),
                integrator: Box::new(CentralDifference::default()),
                contacts: ContactStore::default(),
                found: Found::default(),
                clock: StepClock::default(),
                energy: Energies::default(),
                changes: Changes::DETECTION,
                refixed: Vec::new(),
                unbalanced_ratio: Real::INFINITY,
                excitations: Excitations::default(),
                joint_stepping: JointStepping::default(),
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
    /// ([`crate::geometry::MAX_SUBCONTACTS_PER_EDGE`] along a face edge);
    /// [`Error::AddedBlockOverlap`] for a block added after the first step that overlaps a block
    /// of the model by more than the contact tolerance (before the first step, the first step
    /// refuses such a layout with [`Error::InitialOverlap`]).
    pub fn add_block(&mut self, mut block: RigidBlock) -> Result<BlockId> {
        block.validate()?;
        self.state
            .params
            .contact
            .check_block(block.shape().radius(), block.name())?;
        block.radius = block.shape().radius();
        if self.state.clock.started {
            self.check_added_overlap(&block)?;
        }
        let id = BlockId(self.state.blocks.len() as u32);
        self.state.found.ref_poses.push(block.state.pose);
        self.state.blocks.push(block);
        self.pipeline.forces.push(Wrench::default());
        self.state.records.push(StepRecord::default());
        self.pipeline.bounds.push(StiffnessBound::default());
        self.state.changes.insert(Changes::BLOCKS);
        self.pipeline.max_speed = None;
        Ok(id)
    }

    /// A block added to a running model may not overlap another by more than the contact
    /// tolerance, as none may at the start: the joint springs would throw both apart with the
    /// energy of the whole overlap (a block added 5 mm into another launched both). Pairs of
    /// fixed blocks get no contact and are not checked, as at the start.
    fn check_added_overlap(&self, block: &RigidBlock) -> Result<()> {
        use crate::geometry::{detect, BlockGeometry, NarrowPhaseScratch};
        let tolerance = self.state.params.contact.tolerance;
        let (mut scratch, mut seeds) = (NarrowPhaseScratch::default(), Vec::new());
        let new = BlockGeometry {
            shape: block.shape(),
            pose: &block.state.pose,
        };
        for (i, other) in self.state.blocks.iter().enumerate() {
            let reach = block.radius + other.radius + tolerance;
            if (block.fixity().is_fixed() && other.fixity().is_fixed())
                || (other.state.pose.translation - block.state.pose.translation).length() > reach
            {
                continue;
            }
            let old = BlockGeometry {
                shape: other.shape(),
                pose: &other.state.pose,
            };
            seeds.clear();
            detect(old, new, None, &self.state.params.contact, &mut scratch, &mut seeds);
            let depth = -scratch.separation();
            if depth > tolerance {
                return Err(Error::AddedBlockOverlap {
                    block: block.name().to_owned(),
                    other: BlockId(i as u32),
                    depth,
                    tolerance,
                });
            }
        }
        Ok(())
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

    /// Sets the joint law of the interface between blocks `a` and `b` (either order), which
    /// takes precedence over the law of their materials (a weaker bed joint, a mortared
    /// interface, a steel plate on one stone: per-interface properties, as 3DEC gives them).
    /// Takes effect at the next step, as [`Model::set_joint_law`].
    ///
    /// # Errors
    /// [`Error::UnknownBlock`]; as [`LawTable::insert_interface`].
    ///
    /// [`LawTable::insert_interface`]: crate::law::LawTable::insert_interface
    pub fn set_interface_law(&mut self, a: BlockId, b: BlockId, law: L) -> Result<()> {
        self.block(a)?;
        self.block(b)?;
        self.state.laws.insert_interface(a, b, law)?;
        self.state.changes.insert(Changes::LAWS);
        Ok(())
    }

    /// Sets how the step advances a face-face joint that is closed all over and sticks
    /// ([`JointStepping`]): as a whole (the default) or cell by cell. The answers agree to
    /// round-off; cell by cell is there to compare with. Takes effect at the next step (a joint
    /// stepped as a whole has its sub-contacts written first). Not stored in checkpoints: a
    /// loaded model steps joints as a whole.
    ///
    /// ```
    /// use voussoir::prelude::*;
    /// use voussoir::model::JointStepping;
    ///
    /// let mut model: Model = Model::new(ModelParameters::default())?;
    /// model.set_joint_stepping(JointStepping::Cells);
    /// assert_eq!(model.joint_stepping(), JointStepping::Cells);
    /// # Ok::<(), voussoir::Error>(())
    /// ```
    pub fn set_joint_stepping(&mut self, stepping: JointStepping) {
        self.state.joint_stepping = stepping;
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
        if !self.state.clock.started || params.contact != old.contact || params.mode != old.mode {
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

    /// Sets the constant external load (force, and moment about the centroid) on a block,
    /// replacing any load history ([`Model::set_load_history`]) it had.
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
        self.state.excitations.load_histories.retain(|h| h.block != id.0);
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
        if self.state.clock.started {
            self.state.energy.initial_kinetic += after - before;
            self.state.energy.kinetic += after - before;
        }
        Ok(())
    }

    pub(super) fn block_mut(&mut self, id: BlockId) -> Result<&mut RigidBlock> {
        let count = self.state.blocks.len();
        // A velocity or fixity may change: the next step measures the speeds afresh, and copies
        // the blocks' motions (`BlockMotion`, which the contact pass reads) afresh.
        self.pipeline.max_speed = None;
        self.pipeline.detection.prepared = None;
        self.state
            .blocks
            .get_mut(id.index())
            .ok_or(Error::UnknownBlock { id, count })
    }

    /// Sets the check a step asks whether to stop (`None` removes it): a front end watching for
    /// Ctrl-C or a deadline. A step asks it before it begins, when 20 ms of wall-clock time have
    /// passed since it was last asked there (so that every run, servo wait and push-over, with
    /// or without contact detection, honours it within a step), and a long step asks it between
    /// the batches of its contact detection (about every 25 ms in the first detection of a
    /// 100k-block wall on 2 cores). When it returns `true` the step stops with
    /// [`Error::Interrupted`] before it changes any contact or block: the model is as before the
    /// step (after an interrupted detection, its next step detects every contact afresh). Not
    /// saved in checkpoints.
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
}
