//! Servo-controlled displacement loading and the convergence check of a quasi-static answer.

use std::ops::ControlFlow;

use crate::error::{positive, Error, Result};
use crate::ids::BlockId;
use crate::law::ConstitutiveLaw;
use crate::math::{is_finite_vector, Convergence, Real, Vector};
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
    /// answer is read every many increments) and against the contact tolerance (at most half
    /// of it, checked by [`Servo::run`]).
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
    /// Before the first step: [`Error::UnknownBlock`]; [`Error::InvalidParameter`] when a
    /// translation the servo drives along is not prescribed ([`crate::block::Dof::Velocity`]:
    /// the servo would run its steps without moving the block), or when the increment is above
    /// half the contact tolerance (an advance that drives the block into its neighbours
    /// faster than the contacts can push back: 1 mm a step drove a cube 66 mm into its base);
    /// [`Error::Unsupported`] when the block has a base motion (which sets its velocity every
    /// step, overriding the servo). Then as [`Model::run_observed`].
    pub fn run<L: ConstitutiveLaw>(
        &self,
        model: &mut Model<L>,
        max_steps: u64,
        observer: &mut impl Observer<L>,
    ) -> Result<bool> {
        self.check(model)?;
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

impl Servo {
    /// The checks of [`Servo::run`] against the model.
    fn check<L: ConstitutiveLaw>(&self, model: &Model<L>) -> Result<()> {
        let fixity = *crate::block::Block::fixity(model.block(self.block)?);
        if model.base_motions().any(|(b, _, _)| b == self.block) {
            return Err(Error::Unsupported {
                what: format!(
                    "servo on block {}: the block has a base motion, which sets its velocity every step and \
                     would override the servo; remove the motion first",
                    self.block
                ),
            });
        }
        for (axis, d) in self.direction.to_array().into_iter().enumerate() {
            if d != 0.0 && !matches!(fixity.translation[axis], crate::block::Dof::Velocity(_)) {
                return Err(Error::InvalidParameter {
                    name: format!(
                        "servo direction of block {} along {}",
                        self.block,
                        ["x", "y", "z"][axis]
                    ),
                    value: d,
                    expected: "a prescribed translation (Dof::Velocity) on every axis the servo drives along",
                });
            }
        }
        let limit = SERVO_TRAVEL * model.parameters().contact.tolerance;
        if self.increment > limit {
            return Err(Error::InvalidParameter {
                name: format!("servo increment (at most {limit} m, half the contact tolerance)"),
                value: self.increment,
                expected: "an advance per step of at most half the contact tolerance",
            });
        }
        Ok(())
    }
}

/// The largest servo advance per step, as a fraction of the contact tolerance.
const SERVO_TRAVEL: Real = 0.5;
