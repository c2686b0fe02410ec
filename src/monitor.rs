//! Observation that users can extend: the [`Probe`] trait (one quantity sampled from a model),
//! the built-in probes ([`Monitor`]: displacements, velocities, reactions, contact forces,
//! energies, the unbalanced-force ratio), and the [`Recorder`] that samples probes into a
//! [`History`] while a run goes, as the run's [`Observer`].
//!
//! ```
//! use voussoir::monitor::{Probe, Recorder};
//! use voussoir::prelude::*;
//!
//! /// The height of a block's centroid: a probe of one's own.
//! struct Height(BlockId);
//! impl<L: ConstitutiveLaw> Probe<L> for Height {
//!     fn unit(&self) -> &str {
//!         "m"
//!     }
//!     fn value(&self, model: &Model<L>) -> f64 {
//!         model.blocks()[self.0.index()].state().pose.translation.z
//!     }
//! }
//!
//! let mut model: Model = Model::new(ModelParameters::default())?;
//! let stone = model.add_block(RigidBlock::cuboid("stone", Vector::ZERO, Vector::splat(0.1), 2500.0)?)?;
//! let mut recorder = Recorder::new(10); // every tenth step
//! recorder.add_monitor(&model, "kinetic", Monitor::Energy(EnergyTerm::Kinetic))?;
//! recorder.add_probe("height", Height(stone));
//! model.run_steps_observed(100, &mut recorder)?;
//! let history = recorder.history();
//! assert_eq!(history.len(), 10);
//! assert!(history.column(MonitorId(1))[9] < 0.05); // it fell
//! # Ok::<(), voussoir::Error>(())
//! ```

#[cfg(feature = "serde")]
#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

pub use crate::ids::MonitorId;

use crate::block::Block;
use crate::error::Result;
use crate::ids::BlockId;
use crate::law::ConstitutiveLaw;
use crate::math::{Real, Vector};
use crate::model::{Model, Observer};

/// Component of a vector quantity.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub enum Component {
    /// World x.
    X,
    /// World y.
    Y,
    /// World z.
    Z,
    /// Euclidean norm.
    Magnitude,
}

impl Component {
    fn of(self, v: Vector) -> Real {
        match self {
            Component::X => v.x,
            Component::Y => v.y,
            Component::Z => v.z,
            Component::Magnitude => v.length(),
        }
    }
}

/// Which energy term to record.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub enum EnergyTerm {
    /// Kinetic energy.
    Kinetic,
    /// Elastic energy in the joints.
    Elastic,
    /// Work of gravity.
    GravityWork,
    /// Work of applied loads.
    LoadWork,
    /// Work of supports and prescribed velocities.
    BoundaryWork,
    /// Dissipated by slip and failure.
    Friction,
    /// Dissipated by damping.
    Damping,
    /// Accounted minus input energy (should stay near zero).
    BalanceError,
}

/// A quantity sampled during a run.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub enum Monitor {
    /// Displacement (m) of the material point that was at `point` (world) when the block was built.
    Displacement {
        /// The block.
        block: BlockId,
        /// Initial world position of the material point.
        point: Vector,
        /// Component.
        component: Component,
    },
    /// Velocity (m/s) of a material point, given by its initial world position.
    Velocity {
        /// The block.
        block: BlockId,
        /// Initial world position of the material point.
        point: Vector,
        /// Component.
        component: Component,
    },
    /// Force (N) the supports or prescribed velocities apply to a block.
    Reaction {
        /// The block.
        block: BlockId,
        /// Component.
        component: Component,
    },
    /// Total contact force (N) on a block.
    ContactForce {
        /// The block.
        block: BlockId,
        /// Component.
        component: Component,
    },
    /// Resultant force (N) of the contact between two blocks, on the second one (zero when they
    /// are not in contact). Scene files written before the rename say `JointForce`.
    #[cfg_attr(feature = "serde", serde(alias = "JointForce"))]
    ContactResultant {
        /// First block.
        a: BlockId,
        /// Second block: the force is the one acting on it.
        b: BlockId,
        /// Component.
        component: Component,
    },
    /// An energy term (J).
    Energy(EnergyTerm),
    /// The unbalanced-force ratio (-).
    UnbalancedRatio,
}

impl Monitor {
    pub(crate) fn blocks(&self) -> Vec<BlockId> {
        match *self {
            Monitor::Displacement { block, .. }
            | Monitor::Velocity { block, .. }
            | Monitor::Reaction { block, .. }
            | Monitor::ContactForce { block, .. } => vec![block],
            Monitor::ContactResultant { a, b, .. } => vec![a, b],
            _ => Vec::new(),
        }
    }

    /// SI unit of the monitored quantity.
    pub fn unit(&self) -> &'static str {
        match self {
            Monitor::Displacement { .. } => "m",
            Monitor::Velocity { .. } => "m/s",
            Monitor::Reaction { .. } | Monitor::ContactForce { .. } | Monitor::ContactResultant { .. } => "N",
            Monitor::Energy(_) => "J",
            Monitor::UnbalancedRatio => "-",
        }
    }

    /// Value of the monitor in the model's current state.
    pub fn evaluate<L: ConstitutiveLaw>(&self, model: &Model<L>) -> Real {
        let block = |id: BlockId| &model.blocks()[id.index()];
        match *self {
            Monitor::Displacement {
                block: id,
                point,
                component,
            } => component.of(block(id).displacement_of(point)),
            Monitor::Velocity {
                block: id,
                point,
                component,
            } => {
                let b = block(id);
                let now = b.world_point(b.initial_pose().inverse_transform_point(point));
                component.of(b.point_velocity(now))
            }
            Monitor::Reaction { block: id, component } => {
                component.of(model.reaction(id).map(|w| w.force).unwrap_or_default())
            }
            Monitor::ContactForce { block: id, component } => {
                component.of(model.contact_wrench(id).map(|w| w.force).unwrap_or_default())
            }
            Monitor::ContactResultant { a, b, component } => {
                let f = model.contact_between(a, b).map(|c| c.resultant()).unwrap_or_default();
                // The stored resultant acts on the higher-numbered block.
                component.of(if b.0 > a.0 { f } else { -f })
            }
            Monitor::Energy(term) => {
                let e = match term {
                    EnergyTerm::Elastic | EnergyTerm::Friction | EnergyTerm::BalanceError => model.energies(),
                    _ => *model.energy_accumulators(),
                };
                match term {
                    EnergyTerm::Kinetic => e.kinetic,
                    EnergyTerm::Elastic => e.elastic,
                    EnergyTerm::GravityWork => e.gravity_work,
                    EnergyTerm::LoadWork => e.load_work,
                    EnergyTerm::BoundaryWork => e.boundary_work,
                    EnergyTerm::Friction => e.friction,
                    EnergyTerm::Damping => e.damping,
                    EnergyTerm::BalanceError => e.balance_error(),
                }
            }
            Monitor::UnbalancedRatio => model.unbalanced_force_ratio(),
        }
    }
}

/// One quantity sampled from a model: what a [`Recorder`] column holds. The built-in
/// [`Monitor`]s are probes; implement it for quantities of your own.
pub trait Probe<L: ConstitutiveLaw> {
    /// SI unit of the quantity (for the history's header).
    fn unit(&self) -> &str;
    /// The quantity in the model's current state.
    fn value(&self, model: &Model<L>) -> Real;
}

impl<L: ConstitutiveLaw> Probe<L> for Monitor {
    fn unit(&self) -> &str {
        Monitor::unit(self)
    }
    fn value(&self, model: &Model<L>) -> Real {
        self.evaluate(model)
    }
}

/// A column of a [`Recorder`]: a built-in monitor (which scene files can store) or a probe of
/// the user's.
enum Column<L> {
    Monitor(Monitor),
    Probe(Box<dyn Probe<L>>),
}

/// Samples probes into a [`History`] every `interval` steps of the runs it observes
/// ([`Model::run_steps_observed`], [`Model::run_observed`]), or when asked
/// ([`Recorder::record`]).
pub struct Recorder<L: ConstitutiveLaw> {
    columns: Vec<(String, Column<L>)>,
    interval: u64,
    history: History,
}

impl<L: ConstitutiveLaw> std::fmt::Debug for Recorder<L> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Recorder")
            .field("columns", &self.history.names())
            .field("interval", &self.interval)
            .field("samples", &self.history.len())
            .finish()
    }
}

impl<L: ConstitutiveLaw> Recorder<L> {
    /// A recorder that samples every `interval` steps (at least 1).
    pub fn new(interval: u64) -> Self {
        Self {
            columns: Vec::new(),
            interval: interval.max(1),
            history: History::default(),
        }
    }

    /// Adds a built-in monitor as the next column.
    ///
    /// # Errors
    /// [`crate::Error::UnknownBlock`] if the monitor refers to a block `model` does not have;
    /// [`crate::Error::NonFinite`] for a NaN or infinite point.
    pub fn add_monitor(&mut self, model: &Model<L>, name: &str, monitor: Monitor) -> Result<MonitorId> {
        for id in monitor.blocks() {
            model.block(id)?;
        }
        if let Monitor::Displacement { point, .. } | Monitor::Velocity { point, .. } = monitor {
            if !crate::math::is_finite_vector(point) {
                return Err(crate::Error::NonFinite {
                    what: format!("point of monitor {name:?}"),
                });
            }
        }
        Ok(self.push(name, Column::Monitor(monitor)))
    }

    /// Adds a probe of one's own as the next column.
    pub fn add_probe(&mut self, name: &str, probe: impl Probe<L> + 'static) -> MonitorId {
        self.push(name, Column::Probe(Box::new(probe)))
    }

    fn push(&mut self, name: &str, column: Column<L>) -> MonitorId {
        let id = MonitorId(self.columns.len() as u32);
        let unit = match &column {
            Column::Monitor(m) => m.unit().to_owned(),
            Column::Probe(p) => p.unit().to_owned(),
        };
        self.history.add_column(name, unit);
        self.columns.push((name.to_owned(), column));
        id
    }

    /// Steps between samples.
    pub fn interval(&self) -> u64 {
        self.interval
    }

    /// Samples every column now.
    pub fn record(&mut self, model: &Model<L>) {
        let columns = &self.columns;
        self.history.push(
            model.step_count(),
            model.time(),
            columns.iter().map(|(_, c)| match c {
                Column::Monitor(m) => m.evaluate(model),
                Column::Probe(p) => p.value(model),
            }),
        );
    }

    /// The built-in monitors with their names, in column order (probes of one's own left out).
    pub fn monitors(&self) -> impl Iterator<Item = (&str, &Monitor)> + '_ {
        self.columns.iter().filter_map(|(n, c)| match c {
            Column::Monitor(m) => Some((n.as_str(), m)),
            Column::Probe(_) => None,
        })
    }

    /// The samples so far.
    pub fn history(&self) -> &History {
        &self.history
    }

    /// Takes the samples so far, leaving the columns with no rows.
    pub fn take_history(&mut self) -> History {
        let empty = History {
            names: self.history.names.clone(),
            units: self.history.units.clone(),
            columns: vec![Vec::new(); self.history.names.len()],
            ..History::default()
        };
        std::mem::replace(&mut self.history, empty)
    }
}

impl<L: ConstitutiveLaw> Observer<L> for Recorder<L> {
    /// Samples after every `interval`-th step of the model.
    fn after_step(&mut self, model: &Model<L>) -> Result<std::ops::ControlFlow<()>> {
        if model.step_count().is_multiple_of(self.interval) {
            self.record(model);
        }
        Ok(std::ops::ControlFlow::Continue(()))
    }
}

/// Sampled histories: one row per sample, one column per monitor.
///
/// Read back (with serde) only if it is consistent: as many names, units and columns, and as
/// many steps, times and samples in every column; otherwise deserialisation fails with the
/// message of [`crate::Error::InconsistentHistory`], naming the column.
#[derive(Debug, Clone, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(try_from = "HistoryData"))]
pub struct History {
    names: Vec<String>,
    units: Vec<String>,
    steps: Vec<u64>,
    times: Vec<Real>,
    #[cfg_attr(feature = "serde", serde(with = "nullable_columns"))]
    columns: Vec<Vec<Real>>,
}

/// A [`History`] as read, before its consistency is checked.
#[cfg(feature = "serde")]
#[derive(Deserialize)]
struct HistoryData {
    names: Vec<String>,
    units: Vec<String>,
    steps: Vec<u64>,
    times: Vec<Real>,
    #[serde(with = "nullable_columns")]
    columns: Vec<Vec<Real>>,
}

#[cfg(feature = "serde")]
impl TryFrom<HistoryData> for History {
    type Error = crate::Error;

    fn try_from(h: HistoryData) -> Result<Self> {
        let bad = |what: String| Err(crate::Error::InconsistentHistory { what });
        if h.units.len() != h.names.len() || h.columns.len() != h.names.len() {
            return bad(format!(
                "{} names, {} units and {} columns (one of each per monitor expected)",
                h.names.len(),
                h.units.len(),
                h.columns.len()
            ));
        }
        if h.times.len() != h.steps.len() {
            return bad(format!(
                "{} times for {} steps (one per sample expected)",
                h.times.len(),
                h.steps.len()
            ));
        }
        for (c, (column, name)) in h.columns.iter().zip(&h.names).enumerate() {
            if column.len() != h.steps.len() {
                return bad(format!(
                    "column {c} ({name:?}) has {} samples, steps has {}",
                    column.len(),
                    h.steps.len()
                ));
            }
        }
        Ok(History {
            names: h.names,
            units: h.units,
            steps: h.steps,
            times: h.times,
            columns: h.columns,
        })
    }
}

/// JSON has no NaN: missing samples (NaN) are written as `null` and read back as NaN.
#[cfg(feature = "serde")]
mod nullable_columns {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    pub fn serialize<S: Serializer>(cols: &[Vec<f64>], s: S) -> Result<S::Ok, S::Error> {
        let v: Vec<Vec<Option<f64>>> = cols
            .iter()
            .map(|c| c.iter().map(|x| x.is_finite().then_some(*x)).collect())
            .collect();
        v.serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<Vec<f64>>, D::Error> {
        let v: Vec<Vec<Option<f64>>> = Vec::deserialize(d)?;
        Ok(v.into_iter()
            .map(|c| c.into_iter().map(|x| x.unwrap_or(f64::NAN)).collect())
            .collect())
    }
}

impl History {
    pub(crate) fn add_column(&mut self, name: &str, unit: String) {
        self.names.push(name.to_owned());
        self.units.push(unit);
        // A column added late is padded with NaN for the samples it missed.
        self.columns.push(vec![Real::NAN; self.steps.len()]);
    }

    pub(crate) fn push(&mut self, step: u64, time: Real, values: impl Iterator<Item = Real>) {
        self.steps.push(step);
        self.times.push(time);
        for (c, v) in self.columns.iter_mut().zip(values) {
            c.push(v);
        }
    }

    /// Monitor names, in column order.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// Units, in column order.
    pub fn units(&self) -> &[String] {
        &self.units
    }

    /// Step number of each sample.
    pub fn steps(&self) -> &[u64] {
        &self.steps
    }

    /// Time of each sample (s).
    pub fn times(&self) -> &[Real] {
        &self.times
    }

    /// Samples of one monitor.
    ///
    /// # Panics
    /// For an id that is not one of this history's monitors ([`History::try_column`] does not).
    pub fn column(&self, id: MonitorId) -> &[Real] {
        &self.columns[id.0 as usize]
    }

    /// Samples of one monitor, `None` for an id that is not one of this history's monitors.
    pub fn try_column(&self, id: MonitorId) -> Option<&[Real]> {
        self.columns.get(id.0 as usize).map(Vec::as_slice)
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.steps.len()
    }

    /// `true` when nothing has been sampled.
    pub fn is_empty(&self) -> bool {
        self.steps.is_empty()
    }

    /// A history from its parts as they are, unchecked (deserialisation checks them): for tests
    /// of what reads histories with columns that do not fit together.
    #[cfg(test)]
    pub(crate) fn from_parts_unchecked(
        names: Vec<String>,
        units: Vec<String>,
        steps: Vec<u64>,
        times: Vec<Real>,
        columns: Vec<Vec<Real>>,
    ) -> Self {
        Self {
            names,
            units,
            steps,
            times,
            columns,
        }
    }
}
