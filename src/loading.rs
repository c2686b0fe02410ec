//! Quasi-static loading: displacement control whose answer does not depend on the loading
//! speed.
//!
//! A block driven at a prescribed velocity (a loading plate) loads a structure dynamically: the
//! structure lags behind the plate, and what the plate measures includes inertia. The faster
//! the plate, the more inertia; a peak load read at a fast rate overestimates the capacity, and
//! the collapse mechanism may change (`docs/benchmarks/arch-static.md`).
//!
//! [`Servo`] removes the rate from the answer: the plate advances by a fixed increment per
//! step ([`Servo::increment`]) only while the model is close to equilibrium — the
//! unbalanced-force ratio ([`Model::unbalanced_force_ratio`]) at or below
//! [`Servo::max_unbalanced_ratio`] — and stands still otherwise, until the structure has
//! settled under the load it carries. The plate's path is thus followed through a sequence of
//! equilibria; there is no loading speed at all, and the answer is read at the settled states
//! ([`Servo::settled`]). Use it (with local damping, which settles the structure between
//! advances) for capacities, pushover curves and softening branches. Use a plain prescribed
//! velocity ([`crate::block::Fixity::velocity`]) when the rate is part of the problem (impact,
//! a test run at a known speed). Check the answer of any quasi-static run by halving the
//! increment and the threshold ([`Servo::refined`], [`Servo::check_convergence`]): a converged
//! answer does not move.
//!
//! Choosing the parameters:
//! - **`max_unbalanced_ratio`** sets how close to equilibrium each state is: it is the
//!   parameter the answer depends on most. Where joints slide or hinges form, the path between
//!   equilibria matters (friction is path-dependent), and a loose threshold loads the structure
//!   a little dynamically; 1e-3 is a sensible start, and [`Servo::check_convergence`] says
//!   whether it is tight enough.
//! - **`increment`** sets how far apart the equilibria are: small against the displacements
//!   of interest (the answer is read every many increments), not so small that the run is
//!   made of increments. The cost of settling after an increment grows only with its
//!   logarithm, so a larger increment is cheaper per metre of travel.
//! - **The time step.** Inertia plays no part in a quasi-static answer, so the step's margin
//!   below the stability limit, which impacts and changing contacts need, is not needed
//!   either: [`crate::integrate::TimeStep::Auto`] with `safety` 0.8–0.9 (the limit is an
//!   upper bound of the frequencies, `docs/theory.md`) halves the steps of a servo run against
//!   the default 0.5. Check that the answer does not change.
//! - **Mass scaling** (3DEC's static mode) is not offered: in an assembly of similar blocks,
//!   such as an arch, it barely changes the ratio of the highest to the lowest frequency, which
//!   is what settling costs.
//!
//! ```
//! use std::ops::ControlFlow;
//! use voussoir::loading::Servo;
//! use voussoir::prelude::*;
//!
//! // A cube between a fixed base and a plate pushed down: two joints in series, each `kn·A`,
//! // so once the plate touches, its force grows by `kn·A·Δδ/2` for a travel `Δδ`.
//! let (kn, a) = (1e9, 0.04);
//! let mut model: Model = Model::new(ModelParameters::default())?;
//! model.set_joint_law(MaterialId(0), MaterialId(0), CoulombSlip::dry(kn, kn, 30.0)?)?;
//! model.set_damping(Damping::Local { alpha: 0.8 })?;
//! model.add_block(
//!     RigidBlock::cuboid("base", Vector::new(-0.5, -0.5, -0.1), Vector::new(0.5, 0.5, 0.0), 2500.0)?
//!         .with_fixity(Fixity::FIXED),
//! )?;
//! let cube = model.add_block(RigidBlock::cuboid("cube", Vector::new(-0.1, -0.1, 0.0), Vector::new(0.1, 0.1, 0.2), 2500.0)?)?;
//! let plate = model.add_block(
//!     RigidBlock::cuboid("plate", Vector::new(-0.3, -0.3, 0.2), Vector::new(0.3, 0.3, 0.25), 7800.0)?
//!         .with_fixity(Fixity::velocity(Vector::ZERO)),
//! )?;
//! let servo = Servo::new(plate, Vector::new(0.0, 0.0, -1.0), 1e-7, 1e-3)?; // 0.1 µm a step
//! # let _ = servo.refined();
//! let z0 = model.block(plate)?.state().pose.translation.z;
//! let mut samples = Vec::new(); // (travel, plate force) at 20 and 40 µm
//! servo.run(&mut model, 1_000_000, &mut |m: &Model| {
//!     let travel = z0 - m.blocks()[plate.index()].state().pose.translation.z;
//!     if servo.settled(m) && travel >= 2e-5 * (samples.len() + 1) as f64 {
//!         samples.push((travel, m.contact_between(cube, plate).map_or(0.0, |c| c.normal_force())));
//!     }
//!     Ok(if samples.len() == 2 { ControlFlow::Break(()) } else { ControlFlow::Continue(()) })
//! })?;
//! let [(t1, f1), (t2, f2)] = [samples[0], samples[1]];
//! let expected = kn * a * (t2 - t1) / 2.0;
//! assert!(((f2 - f1) - expected).abs() < 0.01 * expected, "{} N vs {expected} N", f2 - f1);
//! # Ok::<(), voussoir::Error>(())
//! ```

use std::ops::ControlFlow;

use crate::error::{positive, Error, Result};
use crate::ids::BlockId;
use crate::law::ConstitutiveLaw;
use crate::math::{is_finite_vector, Real, Vector};
use crate::model::{Model, Observer};

/// Servo-controlled displacement loading: `block` advances by `increment` along `direction`
/// in a step that starts with the model's unbalanced-force ratio at most
/// `max_unbalanced_ratio`, and stands still in the others.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Servo {
    /// The driven block; its translations along which it is driven must be prescribed
    /// ([`crate::block::Dof::Velocity`]), e.g. `Fixity::velocity(Vector::ZERO)`.
    pub block: BlockId,
    /// Unit direction of the advance.
    pub direction: Vector,
    /// The advance per advancing step (m): small against the displacements of interest (the
    /// answer is read every many increments) and against the contact tolerance.
    pub increment: Real,
    /// The unbalanced-force ratio at or below which the block advances (1e-3 is a common
    /// choice): the tighter, the closer to equilibrium each advance starts, and the longer the
    /// run.
    pub max_unbalanced_ratio: Real,
}

impl Servo {
    /// A servo advancing `block` by `increment` (m) along `direction` (normalised here) in the
    /// steps that start with the unbalanced-force ratio at most `max_unbalanced_ratio`.
    ///
    /// # Errors
    /// [`Error::NonFinite`] for a non-finite direction; [`Error::InvalidParameter`] for a zero
    /// direction, or an increment or ratio that is not positive and finite.
    pub fn new(block: BlockId, direction: Vector, increment: Real, max_unbalanced_ratio: Real) -> Result<Self> {
        if !is_finite_vector(direction) {
            return Err(Error::NonFinite {
                what: format!("servo direction of block {block}"),
            });
        }
        positive("servo direction length", direction.length())?;
        positive("servo increment", increment)?;
        positive("servo max_unbalanced_ratio", max_unbalanced_ratio)?;
        Ok(Self {
            block,
            direction: direction.normalize(),
            increment,
            max_unbalanced_ratio,
        })
    }

    /// The same servo with half the increment and half the threshold: the check of a
    /// quasi-static answer, which must not move under it.
    pub fn refined(&self) -> Self {
        Self {
            increment: 0.5 * self.increment,
            max_unbalanced_ratio: 0.5 * self.max_unbalanced_ratio,
            ..*self
        }
    }

    /// Runs a quasi-static analysis with this servo and with [`refined`](Self::refined), in
    /// parallel, and returns the quantity each run reports (a peak load, a displacement): the
    /// check of a quasi-static answer ([`Convergence::relative_change`]).
    ///
    /// `run` builds and runs the whole analysis under the servo it is given; it must not
    /// depend on anything else that changes between the calls.
    ///
    /// # Errors
    /// The first error of either run.
    ///
    /// # Example
    /// ```
    /// use voussoir::ids::BlockId;
    /// use voussoir::loading::Servo;
    ///
    /// let servo = Servo::new(BlockId(2), voussoir::math::Vector::NEG_Z, 1e-6, 1e-3)?;
    /// // A stand-in for an analysis whose answer drifts with the threshold by 2 % per 1e-3.
    /// let peak = |s: Servo| Ok::<_, voussoir::Error>(1000.0 * (1.0 + 20.0 * s.max_unbalanced_ratio));
    /// let c = servo.check_convergence(peak)?;
    /// assert_eq!((c.value, c.refined), (1020.0, 1010.0));
    /// assert!((c.relative_change() - 10.0 / 1020.0).abs() < 1e-15);
    /// assert!(c.converged(0.03) && !c.converged(0.005));
    /// # Ok::<(), voussoir::Error>(())
    /// ```
    pub fn check_convergence<F>(&self, run: F) -> Result<Convergence>
    where
        F: Fn(Servo) -> Result<Real> + Sync,
    {
        let (value, refined) = rayon::join(|| run(*self), || run(self.refined()));
        Ok(Convergence {
            value: value?,
            refined: refined?,
        })
    }

    /// Whether the model is settled by this servo's measure (the last step's unbalanced-force
    /// ratio at most the threshold): the states to read a quasi-static answer from.
    pub fn settled<L: ConstitutiveLaw>(&self, model: &Model<L>) -> bool {
        model.unbalanced_force_ratio() <= self.max_unbalanced_ratio
    }

    /// Runs up to `max_steps` steps under servo control, calling `observer` after each; returns
    /// whether the observer stopped the run. Before each step the block is set advancing or
    /// standing from the last step's unbalanced-force ratio (standing before the first step,
    /// whose ratio and step are not known).
    ///
    /// # Errors
    /// As [`Model::set_prescribed_velocity`] (a block without a prescribed translation), and as
    /// [`Model::run_observed`].
    pub fn run<L: ConstitutiveLaw>(
        &self,
        model: &mut Model<L>,
        max_steps: u64,
        observer: &mut impl Observer<L>,
    ) -> Result<bool> {
        let mut velocity = None;
        for _ in 0..max_steps {
            // The advance over the coming step is `increment` (the step is `dt`, or shorter
            // while refined around an impact).
            let v = if self.settled(model) && model.dt() > 0.0 {
                self.direction * (self.increment / model.dt())
            } else {
                Vector::ZERO
            };
            if velocity != Some(v) {
                model.set_prescribed_velocity(self.block, v)?;
                velocity = Some(v);
            }
            model.step()?;
            if observer.after_step(model)? == ControlFlow::Break(()) {
                return Ok(true);
            }
        }
        Ok(false)
    }
}

/// A quantity from a quasi-static run and from the same run refined (half the increment and
/// threshold of a servo, or half the rate of a rate-loaded run): how far the answer is from
/// converged.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Convergence {
    /// The quantity from the run.
    pub value: Real,
    /// The quantity from the refined run.
    pub refined: Real,
}

impl Convergence {
    /// `|refined − value| / |value|` (infinite for a zero `value` with a non-zero `refined`,
    /// zero when both are zero).
    pub fn relative_change(&self) -> Real {
        let change = (self.refined - self.value).abs();
        if change == 0.0 {
            0.0
        } else {
            change / self.value.abs()
        }
    }

    /// Whether the refinement moved the quantity by at most `tolerance` (relative).
    pub fn converged(&self, tolerance: Real) -> bool {
        self.relative_change() <= tolerance
    }
}
