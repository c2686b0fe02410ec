//! Monitors and their histories.

use pyo3::prelude::*;
use pyo3::types::PyDict;
use voussoir::block::BlockId;
use voussoir::law::AnyLaw;
use voussoir::model::Model;
use voussoir::monitor::{Component, EnergyTerm, Monitor, Recorder};
use voussoir::Error;

use crate::convert::{array1, vec3, Int};
use crate::errors::{bad, OrPy};

use super::PyModel;

/// The monitors and their samples. Kept here rather than in a `voussoir::monitor::Recorder`
/// so that a run can take it across `Python::detach` (a `Recorder` may hold probes that are
/// not `Send`); it samples as a `Recorder` does, after every `interval`-th step.
#[derive(Default)]
pub(super) struct Samples {
    pub(super) monitors: Vec<(String, Monitor)>,
    pub(super) interval: u64,
    pub(super) steps: Vec<u64>,
    pub(super) times: Vec<f64>,
    pub(super) columns: Vec<Vec<f64>>,
}

impl Samples {
    pub(super) fn new() -> Self {
        Self {
            interval: 1,
            ..Self::default()
        }
    }

    pub(super) fn after_step(&mut self, model: &Model<AnyLaw>) {
        if !self.monitors.is_empty() && model.step_count().is_multiple_of(self.interval) {
            self.steps.push(model.step_count());
            self.times.push(model.time());
            for ((_, m), c) in self.monitors.iter().zip(&mut self.columns) {
                c.push(m.evaluate(model));
            }
        }
    }

    /// Adds a monitor; its name must be new and not `step` or `time` (the columns of
    /// `history()` that every history has).
    pub(super) fn add(&mut self, name: &str, monitor: Monitor) -> PyResult<()> {
        if name == "step" || name == "time" {
            return Err(bad(format!(
                "monitor name {name:?} is taken by the history's own {name:?} column: choose another"
            )));
        }
        if self.monitors.iter().any(|(n, _)| n == name) {
            return Err(bad(format!(
                "a monitor named {name:?} exists already: names must differ"
            )));
        }
        self.monitors.push((name.to_owned(), monitor));
        // A monitor added late has NaN for the samples it missed, as in a Recorder.
        self.columns.push(vec![f64::NAN; self.steps.len()]);
        Ok(())
    }

    /// As a `voussoir::monitor::Recorder` (monitors and interval; no samples).
    pub(super) fn recorder(&self, model: &Model<AnyLaw>) -> voussoir::Result<Recorder<AnyLaw>> {
        let mut r = Recorder::new(self.interval);
        for (name, m) in &self.monitors {
            r.add_monitor(model, name, *m)?;
        }
        Ok(r)
    }

    /// As a `voussoir::monitor::History`, through its JSON form.
    pub(super) fn history(&self) -> voussoir::Result<voussoir::monitor::History> {
        let value = serde_json::json!({
            "names": self.monitors.iter().map(|(n, _)| n.clone()).collect::<Vec<_>>(),
            "units": self.monitors.iter().map(|(_, m)| m.unit()).collect::<Vec<_>>(),
            "steps": self.steps,
            "times": self.times,
            "columns": self.columns.iter()
                .map(|c| c.iter().map(|x| x.is_finite().then_some(*x)).collect::<Vec<_>>())
                .collect::<Vec<_>>(),
        });
        serde_json::from_value(value).map_err(|e| Error::Io {
            path: "(history)".into(),
            message: e.to_string(),
        })
    }
}

fn component(s: &str) -> PyResult<Component> {
    match s.to_ascii_lowercase().as_str() {
        "x" => Ok(Component::X),
        "y" => Ok(Component::Y),
        "z" => Ok(Component::Z),
        "magnitude" | "norm" => Ok(Component::Magnitude),
        other => Err(bad(format!(
            "component {other:?}: expected \"x\", \"y\", \"z\" or \"magnitude\""
        ))),
    }
}

fn energy_term(s: &str) -> PyResult<EnergyTerm> {
    Ok(match s.to_ascii_lowercase().as_str() {
        "kinetic" => EnergyTerm::Kinetic,
        "elastic" => EnergyTerm::Elastic,
        "gravity_work" => EnergyTerm::GravityWork,
        "load_work" => EnergyTerm::LoadWork,
        "boundary_work" => EnergyTerm::BoundaryWork,
        "friction" => EnergyTerm::Friction,
        "damping" => EnergyTerm::Damping,
        "balance_error" => EnergyTerm::BalanceError,
        other => {
            return Err(bad(format!(
                "energy term {other:?}: expected one of kinetic, elastic, gravity_work, load_work, boundary_work, \
friction, damping, balance_error"
            )))
        }
    })
}

#[pymethods]
impl PyModel {
    // ---- monitors -------------------------------------------------------------------------

    /// Adds a monitor, sampled after every ``monitor_interval``-th step of the runs:
    /// ``"displacement"`` or ``"velocity"`` of the material point of ``block`` that was at
    /// ``point`` (world) when it was built; ``"reaction"`` or ``"contact_force"`` of ``block``;
    /// ``"contact_resultant"`` between blocks ``a`` and ``b`` (on b); each with ``component``
    /// ``"x"``, ``"y"``, ``"z"`` or ``"magnitude"``; ``"energy"`` with ``term`` (kinetic,
    /// elastic, gravity_work, load_work, boundary_work, friction, damping, balance_error);
    /// ``"unbalanced_ratio"``.
    #[pyo3(signature = (name, kind, *, block=None, point=None, component="z", a=None, b=None, term=None))]
    #[allow(clippy::too_many_arguments)]
    fn add_monitor(
        &self,
        py: Python<'_>,
        name: &str,
        kind: &str,
        block: Option<Int>,
        point: Option<&Bound<'_, PyAny>>,
        component: &str,
        a: Option<Int>,
        b: Option<Int>,
        term: Option<&str>,
    ) -> PyResult<()> {
        let mut this = self.lock(py);
        let c = self::component(component)?;
        let need_block = || -> PyResult<BlockId> {
            let k = block
                .as_ref()
                .ok_or_else(|| bad(format!("monitor {name:?} of kind {kind:?}: give block=")))?;
            this.id(k, "block index")
        };
        let monitor = match kind.to_ascii_lowercase().as_str() {
            "displacement" | "velocity" => {
                let p = point.ok_or_else(|| bad(format!("monitor {name:?} of kind {kind:?}: give point=")))?;
                let (block, point) = (need_block()?, vec3(p, "point")?);
                if kind.eq_ignore_ascii_case("displacement") {
                    Monitor::Displacement {
                        block,
                        point,
                        component: c,
                    }
                } else {
                    Monitor::Velocity {
                        block,
                        point,
                        component: c,
                    }
                }
            }
            "reaction" => Monitor::Reaction {
                block: need_block()?,
                component: c,
            },
            "contact_force" => Monitor::ContactForce {
                block: need_block()?,
                component: c,
            },
            "contact_resultant" => {
                let (Some(a), Some(b)) = (a, b) else {
                    return Err(bad(format!(
                        "monitor {name:?} of kind \"contact_resultant\": give a= and b="
                    )));
                };
                Monitor::ContactResultant {
                    a: this.id(&a, "block index a")?,
                    b: this.id(&b, "block index b")?,
                    component: c,
                }
            }
            "energy" => Monitor::Energy(energy_term(
                term.ok_or_else(|| bad(format!("monitor {name:?} of kind \"energy\": give term=")))?,
            )?),
            "unbalanced_ratio" => Monitor::UnbalancedRatio,
            other => {
                return Err(bad(format!(
                    "monitor kind {other:?}: expected displacement, velocity, reaction, contact_force, \
contact_resultant, energy or unbalanced_ratio"
                )))
            }
        };
        // The library's own checks, with its messages.
        Recorder::<AnyLaw>::new(1)
            .add_monitor(&this.model, name, monitor)
            .py()?;
        this.samples.add(name, monitor)
    }

    /// Steps between monitor samples (default 1).
    #[getter]
    fn monitor_interval(&self, py: Python<'_>) -> u64 {
        let this = self.lock(py);
        this.samples.interval
    }

    #[setter]
    fn set_monitor_interval(&self, py: Python<'_>, n: u64) -> PyResult<()> {
        let mut this = self.lock(py);
        if n == 0 {
            return Err(bad("monitor_interval: must be at least 1 step"));
        }
        this.samples.interval = n;
        Ok(())
    }

    /// Names of the monitors, in order.
    fn monitor_names(&self, py: Python<'_>) -> Vec<String> {
        let this = self.lock(py);
        this.samples.monitors.iter().map(|(n, _)| n.clone()).collect()
    }

    /// The sampled histories: ``{"step": ints, "time": s, <monitor name>: values, ...}``, each
    /// a 1-D array (NaN where a monitor added late has no sample).
    fn history<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let this = self.lock(py);
        let d = PyDict::new(py);
        d.set_item("step", array1(py, this.samples.steps.clone()))?;
        d.set_item("time", array1(py, this.samples.times.clone()))?;
        for ((name, _), c) in this.samples.monitors.iter().zip(&this.samples.columns) {
            d.set_item(name, array1(py, c.clone()))?;
        }
        crate::convert::result(py, "History", d)
    }

    /// SI units of the monitors: ``{name: unit}``.
    fn history_units<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let this = self.lock(py);
        let d = PyDict::new(py);
        for (name, m) in &this.samples.monitors {
            d.set_item(name, m.unit())?;
        }
        Ok(d)
    }

    /// Forgets the samples (keeps the monitors).
    fn clear_history(&self, py: Python<'_>) {
        let mut this = self.lock(py);
        this.samples.steps.clear();
        this.samples.times.clear();
        for c in &mut this.samples.columns {
            c.clear();
        }
    }
}
