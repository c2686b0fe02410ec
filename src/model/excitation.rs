//! Excitations in the step: the blocks with a [`BaseMotion`] get, before they move, the
//! prescribed velocity that carries them to the motion's displacement at the end of the step;
//! the blocks with a [`LoadHistory`] get the load of the current time.

use super::{Model, ModelState};
use crate::block::Wrench;
use crate::block::{Block, Dof, Fixity};
use crate::error::{Error, Result};
use crate::ids::BlockId;
use crate::law::ConstitutiveLaw;
use crate::math::Real;
use crate::signal::{BaseMotion, LoadHistory};

const AXES: [&str; 3] = ["x", "y", "z"];

/// A motion applied to a block, with the model time its history starts at.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub(crate) struct AppliedMotion {
    pub block: u32,
    pub motion: BaseMotion,
    /// Model time of the history's `t = 0` (s).
    pub start: Real,
}

/// A time-varying load applied to a block, with the model time its history starts at.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub(crate) struct AppliedLoad {
    pub block: u32,
    pub load: LoadHistory,
    /// Model time of the history's `t = 0` (s).
    pub start: Real,
}

impl<L: ConstitutiveLaw> ModelState<L> {
    /// Sets the loads of the blocks with a load history to their value at the current time
    /// `t_n`, before the forces are gathered, and books the load work with the trapezoidal
    /// rule: the gather books `F_n·v_{n−½}·Δt_{n−½}` as for a constant load, and the
    /// difference to `½(F_{n−1} + F_n)·v_{n−½}·Δt_{n−½}` is added here (`F_{n−1}` the load
    /// the block had; nothing on the first step, where the gather books `½ F_0`).
    pub(super) fn apply_load_histories(&mut self) {
        for h in &self.excitations.load_histories {
            let block = &mut self.blocks[h.block as usize];
            let new = h.load.at(self.clock.time - h.start);
            let old: Wrench = block.load;
            if self.clock.step > 0 {
                let (v, om) = (block.state.velocity, block.state.angular_velocity);
                self.energy.load_work +=
                    0.5 * ((old.force - new.force).dot(v) + (old.moment - new.moment).dot(om)) * self.clock.drift;
            }
            block.load = new;
        }
    }

    /// Sets the prescribed velocities of the driven axes for a step of `drift` from the
    /// current time: the mean velocity of the motion over the step, so that the block's
    /// displacement at the end of the step is the motion's exactly.
    pub(super) fn apply_base_motions(&mut self, drift: Real) {
        for m in &self.excitations.motions {
            let t = self.clock.time - m.start;
            let v = m.motion.mean_velocity(t, drift);
            let block = &mut self.blocks[m.block as usize];
            let mut fixity = *block.fixity();
            for (axis, driven) in m.motion.driven_axes().into_iter().enumerate() {
                if driven {
                    fixity.translation[axis] = Dof::Velocity(v[axis]);
                }
            }
            block.replace_fixity(fixity);
        }
    }
}

impl<L: ConstitutiveLaw> Model<L> {
    /// Makes a block's translations follow `motion` from now on (its history's `t = 0` is the
    /// model's current time), replacing any motion the block had; `None` removes it and stops
    /// the block: the axes the removed motion drove become [`Dof::Fixed`] (they used to keep
    /// the velocity of the last step; set the fixity afterwards to let them move again).
    ///
    /// The driven axes of the block must be fixed or prescribed
    /// ([`Dof::Fixed`] or [`Dof::Velocity`]); every step they get the velocity that carries the
    /// block to the motion's displacement at the end of the step
    /// ([`BaseMotion::mean_velocity`]). Their reactions are booked as boundary work.
    ///
    /// # Example
    /// ```
    /// use voussoir::signal::{BaseMotion, MotionKind, TimeHistory};
    /// use voussoir::prelude::*;
    ///
    /// let mut model: Model = Model::new(ModelParameters::default())?;
    /// model.set_joint_law(MaterialId(0), MaterialId(0), CoulombSlip::dry(1e9, 4e8, 30.0)?)?;
    /// let table = model.add_block(
    ///     RigidBlock::cuboid("table", Vector::new(-1.0, -1.0, -0.1), Vector::new(1.0, 1.0, 0.0), 2500.0)?
    ///         .with_fixity(Fixity::FIXED),
    /// )?;
    /// // 0.1 g at 2 Hz along x for a second.
    /// let shake = TimeHistory::sine(0.1 * 9.81, 2.0, 1.0, 100)?;
    /// model.set_base_motion(table, Some(BaseMotion::new(MotionKind::Acceleration, [Some(shake), None, None])?))?;
    /// model.run_until_time(0.25)?;
    /// let x = model.block(table)?.state().pose.translation.x;
    /// let w = 2.0 * std::f64::consts::PI * 2.0;
    /// let exact = 0.981 / (w * w) * (w * 0.25 - (w * 0.25).sin()); // a0/ω² (ωt − sin ωt)
    /// assert!((x - exact).abs() < 1e-3 * exact, "{x} vs {exact}");
    /// # Ok::<(), voussoir::Error>(())
    /// ```
    ///
    /// # Errors
    /// [`Error::UnknownBlock`]; [`Error::InvalidParameter`] when a driven axis of the block
    /// is free.
    pub fn set_base_motion(&mut self, id: BlockId, motion: Option<BaseMotion>) -> Result<()> {
        let mut fixity = *self.block(id)?.fixity();
        let Some(motion) = motion else {
            let Some(k) = self.state.excitations.motions.iter().position(|m| m.block == id.0) else {
                return Ok(());
            };
            let removed = self.state.excitations.motions.remove(k);
            for (axis, driven) in removed.motion.driven_axes().into_iter().enumerate() {
                if driven {
                    fixity.translation[axis] = Dof::Fixed;
                }
            }
            return self.set_fixity(id, fixity);
        };
        for (axis, driven) in motion.driven_axes().into_iter().enumerate() {
            if driven && matches!(fixity.translation[axis], Dof::Free) {
                return Err(Error::InvalidParameter {
                    name: format!("base motion of block {id} along {}", ["x", "y", "z"][axis]),
                    value: axis as Real,
                    expected: "a fixed or prescribed translation (Dof::Fixed or Dof::Velocity) on every driven axis",
                });
            }
        }
        self.state.excitations.motions.retain(|m| m.block != id.0);
        self.state.excitations.motions.push(AppliedMotion {
            block: id.0,
            motion,
            start: self.state.clock.time,
        });
        self.state.excitations.motions.sort_by_key(|m| m.block);
        Ok(())
    }

    /// [`Error::DrivenAxisFreed`] when `fixity` frees a translation of block `id` that its base
    /// motion drives.
    pub(super) fn check_driven_axes(&self, id: BlockId, fixity: &Fixity) -> Result<()> {
        let Some(m) = self.state.excitations.motions.iter().find(|m| m.block == id.0) else {
            return Ok(());
        };
        let driven = m.motion.driven_axes();
        for axis in 0..3 {
            if driven[axis] && matches!(fixity.translation[axis], Dof::Free) {
                let axes: Vec<&str> = (0..3).filter(|&a| driven[a]).map(|a| AXES[a]).collect();
                return Err(Error::DrivenAxisFreed {
                    block: id,
                    axis: AXES[axis],
                    motion: format!(
                        "{:?} on {}, started at t = {} s",
                        m.motion.kind,
                        axes.join(", "),
                        m.start
                    ),
                });
            }
        }
        Ok(())
    }

    /// Makes a block's load follow `load` from now on (its history's `t = 0` is the model's
    /// current time): at every step the block carries `load.at(t − t₀)` instead of a constant
    /// load (a ramp, a pulse, an impact force record; 3DEC's load histories). `None` removes
    /// the history, leaving the block with the load it last had; [`Model::set_load`] also
    /// replaces it with a constant load. The load's work is booked with the trapezoidal rule,
    /// as every force's (`docs/theory.md` §6).
    ///
    /// ```
    /// use voussoir::signal::{LoadHistory, TimeHistory};
    /// use voussoir::prelude::*;
    ///
    /// let params = ModelParameters { gravity: Vector::ZERO, ..ModelParameters::default() };
    /// let mut model: Model = Model::new(params)?;
    /// model.set_joint_law(MaterialId(0), MaterialId(0), CoulombSlip::dry(1e9, 4e8, 30.0)?)?;
    /// model.set_damping(Damping::None)?;
    /// let id = model.add_block(RigidBlock::cuboid("free", Vector::ZERO, Vector::splat(0.2), 2500.0)?)?;
    /// // A force ramped from 0 to 100 N over 0.1 s on a free 20 kg block: x = F t³ / (6 m T).
    /// let ramp = TimeHistory::new(vec![0.0, 0.1], vec![0.0, 1.0])?;
    /// let force = Wrench { force: Vector::new(100.0, 0.0, 0.0), moment: Vector::ZERO };
    /// model.set_load_history(id, Some(LoadHistory::new(force, ramp)?))?;
    /// model.run_until_time(0.1)?;
    /// let t = model.time();
    /// let exact = 100.0 * t.powi(3) / (6.0 * 20.0 * 0.1);
    /// let x = model.block(id)?.state().pose.translation.x - 0.1;
    /// assert!((x - exact).abs() < 2e-3 * exact, "{x} vs {exact}");
    /// # Ok::<(), voussoir::Error>(())
    /// ```
    ///
    /// # Errors
    /// [`Error::UnknownBlock`].
    pub fn set_load_history(&mut self, id: BlockId, load: Option<LoadHistory>) -> Result<()> {
        self.block(id)?;
        self.state.excitations.load_histories.retain(|h| h.block != id.0);
        if let Some(load) = load {
            self.state.excitations.load_histories.push(AppliedLoad {
                block: id.0,
                load,
                start: self.state.clock.time,
            });
            self.state.excitations.load_histories.sort_by_key(|h| h.block);
        }
        Ok(())
    }

    /// The load histories applied, with their blocks and the model time each started at.
    pub fn load_histories(&self) -> impl Iterator<Item = (BlockId, &LoadHistory, Real)> {
        self.state
            .excitations
            .load_histories
            .iter()
            .map(|h| (BlockId(h.block), &h.load, h.start))
    }

    /// The base motions applied, with their blocks and the model time each history started at.
    pub fn base_motions(&self) -> impl Iterator<Item = (BlockId, &BaseMotion, Real)> {
        self.state
            .excitations
            .motions
            .iter()
            .map(|m| (BlockId(m.block), &m.motion, m.start))
    }
}
