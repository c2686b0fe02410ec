//! Monitors and their histories: displacements, velocities, reactions, contact forces, energies
//! and the unbalanced-force ratio.

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

use crate::block::{Block, BlockId};
use crate::constitutive::ConstitutiveLaw;
use crate::math::{Real, Vector};
use crate::model::Model;

/// Typed index of a monitor (its column in the [`History`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct MonitorId(pub u32);

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
    /// Resultant force (N) of the joint between two blocks, on the second one (zero when they
    /// are not in contact).
    JointForce {
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
            Monitor::JointForce { a, b, .. } => vec![a, b],
            _ => Vec::new(),
        }
    }

    /// SI unit of the monitored quantity.
    pub fn unit(&self) -> &'static str {
        match self {
            Monitor::Displacement { .. } => "m",
            Monitor::Velocity { .. } => "m/s",
            Monitor::Reaction { .. } | Monitor::ContactForce { .. } | Monitor::JointForce { .. } => "N",
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
            Monitor::JointForce { a, b, component } => {
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

/// Sampled histories: one row per sample, one column per monitor.
#[derive(Debug, Clone, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct History {
    names: Vec<String>,
    units: Vec<String>,
    steps: Vec<u64>,
    times: Vec<Real>,
    #[cfg_attr(feature = "serde", serde(with = "nullable_columns"))]
    columns: Vec<Vec<Real>>,
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
    pub(crate) fn add_column(&mut self, name: &str, unit: &'static str) {
        self.names.push(name.to_owned());
        self.units.push(unit.to_owned());
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
    pub fn column(&self, id: MonitorId) -> &[Real] {
        &self.columns[id.0 as usize]
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.steps.len()
    }

    /// `true` when nothing has been sampled.
    pub fn is_empty(&self) -> bool {
        self.steps.is_empty()
    }
}
