//! Time-varying loads: a wrench scaled by a history, `W(t) = W₀ h(t)`.

use super::TimeHistory;
use crate::block::Wrench;
use crate::error::{Error, Result};
use crate::math::Real;

/// A load that varies in time: the wrench `load` (a force at the block's centroid and a moment,
/// N and N·m) scaled by the factor `history` (dimensionless), `W(t) = load · h(t)`, with `t`
/// counted from when it is applied ([`crate::model::Model::set_load_history`]). Before the
/// history's first sample the factor is 0; after its last it keeps its last value (a ramp
/// ending at 1 holds the full load).
///
/// ```
/// use voussoir::block::Wrench;
/// use voussoir::loading::{LoadHistory, TimeHistory};
/// use voussoir::math::Vector;
///
/// // 1 kN along x ramped up over 0.1 s, then held.
/// let ramp = TimeHistory::new(vec![0.0, 0.1], vec![0.0, 1.0])?;
/// let load = LoadHistory::new(Wrench { force: Vector::new(1e3, 0.0, 0.0), moment: Vector::ZERO }, ramp)?;
/// assert_eq!(load.at(0.05).force.x, 500.0);
/// assert_eq!(load.at(2.0).force.x, 1e3);
/// # Ok::<(), voussoir::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(try_from = "LoadHistoryData"))]
pub struct LoadHistory {
    /// The wrench at factor 1.
    pub load: Wrench,
    /// The factor in time.
    pub history: TimeHistory,
}

/// The serialised form, validated by [`LoadHistory::new`] on load.
#[cfg(feature = "serde")]
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct LoadHistoryData {
    load: Wrench,
    history: TimeHistory,
}

#[cfg(feature = "serde")]
impl TryFrom<LoadHistoryData> for LoadHistory {
    type Error = Error;
    fn try_from(d: LoadHistoryData) -> Result<Self> {
        Self::new(d.load, d.history)
    }
}

impl LoadHistory {
    /// A load history.
    ///
    /// # Errors
    /// [`Error::NonFinite`] for a force or moment that is not finite.
    pub fn new(load: Wrench, history: TimeHistory) -> Result<Self> {
        for (what, v) in [("force", load.force), ("moment", load.moment)] {
            if !v.is_finite() {
                return Err(Error::NonFinite {
                    what: format!("load history {what} {v}"),
                });
            }
        }
        Ok(Self { load, history })
    }

    /// The factor at `t` (s from the start): linear between samples, 0 before the first, the
    /// last value after the last.
    pub fn factor(&self, t: Real) -> Real {
        if t > self.history.end() {
            self.history.values()[self.history.values().len() - 1]
        } else {
            self.history.value_at(t)
        }
    }

    /// The wrench at `t` (s from the start).
    pub fn at(&self, t: Real) -> Wrench {
        let h = self.factor(t);
        Wrench {
            force: self.load.force * h,
            moment: self.load.moment * h,
        }
    }
}
