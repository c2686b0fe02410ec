//! Base excitation: a block's translations following a prescribed time history (an
//! accelerogram on a shaking table, a recorded ground velocity), the way masonry is assessed
//! for earthquakes.
//!
//! A [`TimeHistory`] is a scalar signal sampled at increasing times and interpolated linearly
//! between its samples (zero outside them). A [`BaseMotion`] gives a block's three world
//! translations a history each, as an acceleration, a velocity or a displacement. The model
//! moves the block so that its displacement at the end of every step is the exact integral of
//! the history ([`BaseMotion::displacement`]): over a step from `t` to `t + Δt` the block's
//! prescribed velocity is `(u(t + Δt) − u(t)) / Δt`. A piecewise-linear acceleration integrates
//! to a piecewise-cubic displacement exactly, so the base does not drift however long the
//! record, and the step may change (around impacts) without error.

use super::time_history::integral;
use super::TimeHistory;
use crate::error::{Error, Result};
use crate::math::{Real, Vector};

/// How a [`BaseMotion`]'s histories are read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum MotionKind {
    /// Accelerations (m/s²), from rest at the first sample.
    Acceleration,
    /// Velocities (m/s).
    Velocity,
    /// Displacements (m) from the block's position when the motion was set.
    Displacement,
}

/// A block's world translations following prescribed histories: the base of a wall on a
/// shaking table. Axes without a history stand still. The block's translations along the axes
/// with a history must be prescribed ([`crate::block::Dof::Velocity`]); the model sets their
/// velocity every step ([`crate::Model::set_base_motion`]).
///
/// # Example
/// A base shaken horizontally at 0.3 g and 3 Hz: its displacement at any time is the exact
/// double integral of the acceleration.
/// ```
/// use voussoir::loading::{BaseMotion, MotionKind, TimeHistory};
///
/// let (a0, f) = (0.3 * 9.81, 3.0);
/// let shake = TimeHistory::sine(a0, f, 2.0, 200)?;
/// let motion = BaseMotion::new(MotionKind::Acceleration, [Some(shake), None, None])?;
/// // From rest, u(t) = a0/ω² (ωt − sin ωt): 2.0 s is six whole periods.
/// let w = 2.0 * std::f64::consts::PI * f;
/// let exact = a0 / (w * w) * (w * 2.0);
/// assert!((motion.displacement(2.0).x - exact).abs() < 1e-4 * exact);
/// # Ok::<(), voussoir::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(try_from = "BaseMotionData"))]
pub struct BaseMotion {
    /// What the histories are.
    pub kind: MotionKind,
    /// One history per world axis (x, y, z); `None`: that axis stands still.
    pub axes: [Option<TimeHistory>; 3],
}

/// The serialised form, validated by [`BaseMotion::new`] on load.
#[cfg(feature = "serde")]
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct BaseMotionData {
    kind: MotionKind,
    axes: [Option<TimeHistory>; 3],
}

#[cfg(feature = "serde")]
impl TryFrom<BaseMotionData> for BaseMotion {
    type Error = Error;
    fn try_from(d: BaseMotionData) -> Result<Self> {
        Self::new(d.kind, d.axes)
    }
}

impl BaseMotion {
    /// A motion from its histories.
    ///
    /// A displacement history ([`MotionKind::Displacement`]) must start at 0 (the block's
    /// position when the motion is set: a first value of 10 mm would move the block 10 mm in
    /// one step) and holds its last value after its end (the block stays where the record
    /// leaves it rather than snapping back). Velocity and acceleration histories are zero
    /// outside their samples: the block keeps the displacement it reached.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] when no axis has a history, or a displacement history
    /// whose first value is not 0.
    pub fn new(kind: MotionKind, axes: [Option<TimeHistory>; 3]) -> Result<Self> {
        if axes.iter().all(Option::is_none) {
            return Err(Error::InvalidParameter {
                name: "base motion".into(),
                value: 0.0,
                expected: "a history on at least one axis",
            });
        }
        if kind == MotionKind::Displacement {
            for (axis, h) in axes.iter().enumerate() {
                if let Some(h) = h.as_ref().filter(|h| h.values()[0] != 0.0) {
                    return Err(Error::InvalidParameter {
                        name: format!(
                            "first value of the displacement history along {}",
                            ["x", "y", "z"][axis]
                        ),
                        value: h.values()[0],
                        expected: "0: a displacement history starts at the block's position when the motion is set \
                                   (subtract the first value from the record)",
                    });
                }
            }
        }
        Ok(Self { kind, axes })
    }

    /// The displacement at time `t` (m) from the position at time 0: the exact integral of
    /// the piecewise-linear history (twice for an acceleration, from rest).
    pub fn displacement(&self, t: Real) -> Vector {
        let mut u = [0.0; 3];
        for (u, h) in u.iter_mut().zip(&self.axes) {
            if let Some(h) = h {
                *u = match self.kind {
                    // Held at its last value after the end.
                    MotionKind::Displacement if t > h.end() => h.values()[h.values().len() - 1],
                    MotionKind::Displacement => h.value_at(t),
                    MotionKind::Velocity => integral(h, t).0,
                    MotionKind::Acceleration => integral(h, t).1,
                };
            }
        }
        Vector::from_array(u)
    }

    /// The mean velocity over `[t, t + dt]` (m/s), the prescribed velocity of a step.
    pub fn mean_velocity(&self, t: Real, dt: Real) -> Vector {
        (self.displacement(t + dt) - self.displacement(t)) / dt
    }

    /// The axes with a history.
    pub fn driven_axes(&self) -> [bool; 3] {
        self.axes.each_ref().map(Option::is_some)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_motion_without_an_axis_is_an_error() {
        assert!(BaseMotion::new(MotionKind::Velocity, [None, None, None]).is_err());
    }
}
