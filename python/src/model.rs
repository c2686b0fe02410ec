//! `voussoir.Model`: a model of rigid blocks with the shipped joint laws (`Model<AnyLaw>`), its
//! runs (GIL released, Ctrl-C and a progress callback between steps), its results as numpy
//! arrays, its monitors and its files.

use std::path::PathBuf;
use std::sync::atomic::Ordering;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use numpy::IntoPyArray;
use numpy::{PyArray1, PyArray2, PyArray3};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use voussoir::block::{Block, BlockId, Wrench};
use voussoir::contact::DisplacementMode;
use voussoir::geometry::SubcontactDensity;
use voussoir::integrate::{Damping, TimeStep};
use voussoir::io::scene::Scene;
use voussoir::law::{AnyLaw, JointStatus, MaterialId};
use voussoir::math::Vector;
use voussoir::model::{InterruptCheck, Model, ModelParameters};
use voussoir::monitor::{Component, EnergyTerm, Monitor, Recorder};
use voussoir::Error;

use crate::blocks::PyBlock;
use crate::convert::{array1, array_n3, array_n33, array_nk, vec3, vec3_or_zero, vector, Int};
use crate::documents::{normalised, read, scene_json};
use crate::errors::{bad, OrPy};
use crate::laws::{law_from_py, law_to_py};

/// How often a run without a callback comes back to Python to look for Ctrl-C (wall time).
const SIGNAL_INTERVAL: Duration = Duration::from_millis(100);

/// The monitors and their samples. Kept here rather than in a `voussoir::monitor::Recorder`
/// so that a run can take it across `Python::detach` (a `Recorder` may hold probes that are
/// not `Send`); it samples as a `Recorder` does, after every `interval`-th step.
#[derive(Default)]
struct Samples {
    monitors: Vec<(String, Monitor)>,
    interval: u64,
    steps: Vec<u64>,
    times: Vec<f64>,
    columns: Vec<Vec<f64>>,
}

impl Samples {
    fn new() -> Self {
        Self {
            interval: 1,
            ..Self::default()
        }
    }

    fn after_step(&mut self, model: &Model<AnyLaw>) {
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
    fn add(&mut self, name: &str, monitor: Monitor) -> PyResult<()> {
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
    fn recorder(&self, model: &Model<AnyLaw>) -> voussoir::Result<Recorder<AnyLaw>> {
        let mut r = Recorder::new(self.interval);
        for (name, m) in &self.monitors {
            r.add_monitor(model, name, *m)?;
        }
        Ok(r)
    }

    /// As a `voussoir::monitor::History`, through its JSON form.
    fn history(&self) -> voussoir::Result<voussoir::monitor::History> {
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

/// What a run runs to.
#[derive(Clone, Copy)]
enum Goal {
    Steps(u64),
    Time(f64),
    Equilibrium { target: f64, max_steps: u64 },
}

/// A discrete element model of rigid blocks.
///
/// ``Model(*, gravity=(0, 0, -9.81), contact_tolerance=1e-3, subcontacts_per_edge=15,
/// subcontact_spacing=None, time_step=None, safety=0.5, mode="large", max_speed=1000.0,
/// impact_step=0.1)``: ``time_step`` None is automatic at ``safety`` times the critical step,
/// a number is a fixed step (s); ``subcontact_spacing`` (m), when given, replaces
/// ``subcontacts_per_edge``; ``impact_step`` None turns the impact refinement off.
///
/// Joint laws are set per pair of materials (``set_joint_law``); block indices are ints, the
/// rows of the arrays that ``positions()``, ``velocities()`` etc. return.
#[pyclass(name = "Model", module = "voussoir", frozen)]
pub struct PyModel {
    /// The model and its recorded histories, behind a lock: a run holds it while a chunk of
    /// steps runs (the GIL let go), and a reader in another thread waits for it (the GIL let go
    /// while waiting) instead of finding the model borrowed.
    inner: Mutex<Inner>,
    /// Threads waiting for `inner`: a run lets them in between its chunks.
    waiting: std::sync::atomic::AtomicUsize,
    /// The KeyboardInterrupt the model's interrupt check took from Python within a step, to be
    /// raised once the step has stopped.
    interrupted: Arc<Mutex<Option<PyErr>>>,
}

/// What [`PyModel`] locks.
pub(crate) struct Inner {
    pub(crate) model: Model<AnyLaw>,
    samples: Samples,
}

impl Inner {
    /// The block of index `block` (`VoussoirError` naming the argument `what` when out of range).
    fn id(&self, block: &Int, what: &str) -> PyResult<BlockId> {
        block.block(what, self.model.blocks().len())
    }
}

impl PyModel {
    /// The model, locked; while another thread holds it (a run's chunk, or a reader), waits
    /// with the GIL let go, so that the holder can take the GIL if it needs it.
    pub(crate) fn lock(&self, py: Python<'_>) -> std::sync::MutexGuard<'_, Inner> {
        loop {
            match self.inner.try_lock() {
                Ok(guard) => return guard,
                Err(std::sync::TryLockError::Poisoned(p)) => return p.into_inner(),
                Err(std::sync::TryLockError::WouldBlock) => {
                    // Wait until it is free (the guard dropped at once: it cannot leave the
                    // closure without the GIL), then take it with the GIL held.
                    self.waiting.fetch_add(1, Ordering::SeqCst);
                    py.detach(|| drop(self.inner.lock()));
                    self.waiting.fetch_sub(1, Ordering::SeqCst);
                }
            }
        }
    }

    /// Lets the threads waiting for the model take it (a run, between its chunks): waits, the
    /// GIL let go, until none waits or for at most 20 ms.
    fn let_waiting_in(&self, py: Python<'_>) {
        if self.waiting.load(Ordering::SeqCst) == 0 {
            return;
        }
        py.detach(|| {
            let start = Instant::now();
            while self.waiting.load(Ordering::SeqCst) > 0 && start.elapsed() < Duration::from_millis(20) {
                std::thread::yield_now();
            }
        });
    }

    /// Wraps `model`, with an interrupt check that looks for Ctrl-C from within a long step
    /// (between the batches of a contact detection: the first step of a 100k-block wall takes
    /// seconds), taking the GIL back for the look.
    fn wrap(mut model: Model<AnyLaw>) -> Self {
        let interrupted = Arc::new(Mutex::new(None));
        let seen = Arc::clone(&interrupted);
        model.set_interrupt_check(Some(InterruptCheck::new(move || {
            Python::attach(|py| match py.check_signals() {
                Ok(()) => false,
                Err(e) => {
                    if let Ok(mut slot) = seen.lock() {
                        *slot = Some(e);
                    }
                    true
                }
            })
        })));
        Self {
            inner: Mutex::new(Inner {
                model,
                samples: Samples::new(),
            }),
            waiting: std::sync::atomic::AtomicUsize::new(0),
            interrupted,
        }
    }

    /// The KeyboardInterrupt an interrupted step took, if any.
    fn take_interrupt(&self) -> Option<PyErr> {
        self.interrupted.lock().ok().and_then(|mut slot| slot.take())
    }

    /// Runs to `goal`, in chunks of at most [`SIGNAL_INTERVAL`]: the GIL is let go during a
    /// chunk; between chunks Ctrl-C is looked for and, every `every` steps,
    /// `callback(step, time)` is called. Returns the steps taken and whether the goal was
    /// reached (false: the callback returned a false value).
    ///
    /// The model is locked only while a chunk runs, not while the callback does: the callback
    /// may read the model (time, ratios, positions, contacts, energies) and drive it (loads,
    /// prescribed velocities, stopping by returning False). Another Python thread that reads
    /// the model during a chunk waits for the chunk's end (at most [`SIGNAL_INTERVAL`]) instead
    /// of finding it borrowed (`Already mutably borrowed` in 13 of 50 reads before), and a
    /// chunk waits for a reader that holds it.
    fn run(
        slf: &Bound<'_, Self>,
        goal: Goal,
        callback: Option<&Bound<'_, PyAny>>,
        every: u64,
    ) -> PyResult<(u64, bool)> {
        let py = slf.py();
        if every == 0 {
            return Err(bad("every: must be at least 1 step"));
        }
        if let Some(cb) = callback {
            check_callback(py, cb)?;
        }
        match goal {
            Goal::Time(t) if !t.is_finite() => {
                return Err(Error::NonFinite {
                    what: format!("end time {t} of run_until_time"),
                })
                .py()
            }
            Goal::Equilibrium { target, .. } => {
                voussoir::error::positive("equilibrium target ratio", target).py()?;
            }
            _ => {}
        }
        let mut taken = 0u64;
        let mut since_callback = 0u64;
        loop {
            let chunk = if callback.is_some() {
                every - since_callback
            } else {
                u64::MAX
            };
            let me = slf.get();
            let mut guard = me.lock(py);
            let this = &mut *guard;
            let (model, samples) = (&mut this.model, &mut this.samples);
            let outcome = py.detach(move || -> voussoir::Result<(u64, bool)> {
                let start = Instant::now();
                let mut n = 0u64;
                loop {
                    let done = match goal {
                        Goal::Steps(total) => taken + n >= total,
                        Goal::Time(t) => model.time() >= t,
                        Goal::Equilibrium { target, max_steps } => {
                            if n > 0 && model.unbalanced_force_ratio() < target {
                                true
                            } else if taken + n >= max_steps {
                                return Err(Error::NotConverged {
                                    what: "unbalanced-force ratio target",
                                    steps: max_steps,
                                    last: model.unbalanced_force_ratio(),
                                });
                            } else {
                                false
                            }
                        }
                    };
                    if done {
                        return Ok((n, true));
                    }
                    if n >= chunk || (n.is_multiple_of(16) && start.elapsed() >= SIGNAL_INTERVAL) {
                        return Ok((n, false));
                    }
                    model.step()?;
                    samples.after_step(model);
                    n += 1;
                }
            });
            if let Some(e) = me.take_interrupt() {
                return Err(e);
            }
            let (step, time) = (this.model.step_count(), this.model.time());
            // The model is free again: the callback may read and drive it, and threads waiting
            // for it take it.
            drop(guard);
            me.let_waiting_in(py);
            let (n, done) = outcome.py()?;
            taken += n;
            since_callback += n;
            py.check_signals()?;
            if let Some(cb) = callback {
                if since_callback >= every {
                    since_callback = 0;
                    let answer = cb.call1((step, time))?;
                    // None goes on; any false value (False, numpy.False_, 0) stops.
                    if !answer.is_none() && !answer.is_truthy()? {
                        return Ok((taken, false));
                    }
                }
            }
            if done {
                return Ok((taken, true));
            }
        }
    }
}

/// Refuses, before the first step, a callback that is not callable or cannot be called as
/// `callback(step, time)` (its signature, where Python can tell it, does not bind two
/// positional arguments).
fn check_callback(py: Python<'_>, cb: &Bound<'_, PyAny>) -> PyResult<()> {
    if !cb.is_callable() {
        return Err(pyo3::exceptions::PyTypeError::new_err(format!(
            "callback: {} is not callable; expected callback(step, time)",
            cb.get_type().name()?
        )));
    }
    let Ok(signature) = py.import("inspect")?.call_method1("signature", (cb,)) else {
        // A builtin without a signature: it is called as it is.
        return Ok(());
    };
    if let Err(e) = signature.call_method1("bind", (0u64, 0.0f64)) {
        return Err(pyo3::exceptions::PyTypeError::new_err(format!(
            "callback{}: cannot be called as callback(step, time): {}",
            signature.str()?,
            e.value(py).str()?
        )));
    }
    Ok(())
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

fn status_name(s: JointStatus) -> &'static str {
    match s {
        JointStatus::Elastic => "elastic",
        JointStatus::Sliding => "sliding",
        JointStatus::Open => "open",
    }
}

/// A material id from a Python int (`ValueError` naming `what` outside [0, 65535]).
fn material(k: &Int, what: &str) -> PyResult<MaterialId> {
    Ok(MaterialId(k.at_most(what, u64::from(u16::MAX))? as u16))
}

#[pymethods]
impl PyModel {
    #[new]
    #[pyo3(signature = (*, gravity=None, contact_tolerance=1e-3, subcontacts_per_edge=15, subcontact_spacing=None,
        time_step=None, safety=0.5, mode="large", max_speed=1000.0, impact_step=Some(0.1)))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        gravity: Option<&Bound<'_, PyAny>>,
        contact_tolerance: f64,
        subcontacts_per_edge: u16,
        subcontact_spacing: Option<f64>,
        time_step: Option<f64>,
        safety: f64,
        mode: &str,
        max_speed: f64,
        impact_step: Option<f64>,
    ) -> PyResult<Self> {
        let mut params = ModelParameters::default();
        if let Some(g) = gravity {
            params.gravity = vec3(g, "gravity")?;
        }
        params.contact.tolerance = contact_tolerance;
        params.contact.density = match subcontact_spacing {
            Some(h) => SubcontactDensity::Spacing(h),
            None => SubcontactDensity::PerEdge(subcontacts_per_edge),
        };
        params.time_step = match time_step {
            Some(dt) => TimeStep::Fixed(dt),
            None => TimeStep::Auto { safety },
        };
        params.mode = match mode.to_ascii_lowercase().as_str() {
            "large" => DisplacementMode::Large,
            "small" => DisplacementMode::Small,
            other => return Err(bad(format!("mode {other:?}: expected \"large\" or \"small\""))),
        };
        params.max_speed = max_speed;
        params.impact_step = impact_step;
        Ok(Self::wrap(Model::new(params).py()?))
    }

    // ---- building -------------------------------------------------------------------------

    /// Sets the joint law between two materials (ints, either order): a ``CoulombSlip`` or a
    /// ``LinearElastic``.
    fn set_joint_law(&self, py: Python<'_>, a: Int, b: Int, law: &Bound<'_, PyAny>) -> PyResult<()> {
        let mut this = self.lock(py);
        let (a, b) = (material(&a, "material a")?, material(&b, "material b")?);
        let law = law_from_py(law)?;
        this.model.set_joint_law(a, b, law).py()
    }

    /// The joint law between two materials, or None.
    fn joint_law<'py>(&self, py: Python<'py>, a: Int, b: Int) -> PyResult<Option<Bound<'py, PyAny>>> {
        let this = self.lock(py);
        this.model
            .law_table()
            .get(material(&a, "material a")?, material(&b, "material b")?)
            .map(|l| law_to_py(py, l))
            .transpose()
    }

    /// Sets the damping: ``"none"``; ``"local"`` (Cundall, ``alpha`` in [0, 1), default 0.8);
    /// ``"rayleigh"`` with ``ratio`` (of critical) at ``frequency`` (Hz), mass and stiffness
    /// parts equal, or with the coefficients ``mass`` (1/s) and ``stiffness`` (s);
    /// ``"rayleigh_mass"`` or ``"rayleigh_stiffness"`` with ``ratio`` and ``frequency``.
    #[pyo3(signature = (kind, *, alpha=0.8, ratio=None, frequency=None, mass=None, stiffness=None))]
    #[allow(clippy::too_many_arguments)]
    fn set_damping(
        &self,
        py: Python<'_>,
        kind: &str,
        alpha: f64,
        ratio: Option<f64>,
        frequency: Option<f64>,
        mass: Option<f64>,
        stiffness: Option<f64>,
    ) -> PyResult<()> {
        let mut this = self.lock(py);
        let need = |what: &str| -> PyResult<(f64, f64)> {
            match (ratio, frequency) {
                (Some(r), Some(f)) => Ok((r, f)),
                _ => Err(bad(format!(
                    "damping {what:?}: give ratio= and frequency=",
                    what = what
                ))),
            }
        };
        let damping = match kind.to_ascii_lowercase().as_str() {
            "none" => Damping::None,
            "local" => Damping::Local { alpha },
            "rayleigh" => match (mass, stiffness) {
                (None, None) => {
                    let (r, f) = need("rayleigh")?;
                    Damping::rayleigh(r, f).py()?
                }
                (m, s) => Damping::Rayleigh {
                    mass: m.unwrap_or(0.0),
                    stiffness: s.unwrap_or(0.0),
                },
            },
            "rayleigh_mass" => {
                let (r, f) = need("rayleigh_mass")?;
                Damping::rayleigh_mass(r, f).py()?
            }
            "rayleigh_stiffness" => {
                let (r, f) = need("rayleigh_stiffness")?;
                Damping::rayleigh_stiffness(r, f).py()?
            }
            other => {
                return Err(bad(format!(
                    "damping {other:?}: expected \"none\", \"local\", \"rayleigh\", \"rayleigh_mass\" or \"rayleigh_stiffness\""
                )))
            }
        };
        this.model.set_damping(damping).py()
    }

    /// The damping as a dict: ``{"kind": "none"}``, ``{"kind": "local", "alpha": α}`` or
    /// ``{"kind": "rayleigh", "mass": a, "stiffness": b}``.
    #[getter]
    fn damping<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let this = self.lock(py);
        let d = PyDict::new(py);
        match this.model.damping() {
            Damping::None => d.set_item("kind", "none")?,
            Damping::Local { alpha } => {
                d.set_item("kind", "local")?;
                d.set_item("alpha", alpha)?;
            }
            Damping::Rayleigh { mass, stiffness } => {
                d.set_item("kind", "rayleigh")?;
                d.set_item("mass", mass)?;
                d.set_item("stiffness", stiffness)?;
            }
        }
        Ok(d)
    }

    /// Gravity (m/s²), a (3,) array; settable.
    #[getter]
    fn gravity<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let this = self.lock(py);
        vector(py, this.model.parameters().gravity)
    }

    #[setter]
    fn set_gravity(&self, py: Python<'_>, g: &Bound<'_, PyAny>) -> PyResult<()> {
        let mut this = self.lock(py);
        let mut p = *this.model.parameters();
        p.gravity = vec3(g, "gravity")?;
        this.model.set_parameters(p).py()
    }

    /// Adds a ``Block``; returns its index.
    fn add_block(&self, py: Python<'_>, block: PyRef<'_, PyBlock>) -> PyResult<usize> {
        let mut this = self.lock(py);
        Ok(this.model.add_block(block.inner.clone()).py()?.index())
    }

    /// Adds blocks (a list from ``voussoir.build``, say); returns their indices. All or nothing:
    /// when one is refused, none is added (the error names the first refused, by its position
    /// in the list).
    fn add_blocks(&self, py: Python<'_>, blocks: Vec<PyRef<'_, PyBlock>>) -> PyResult<Vec<usize>> {
        let mut this = self.lock(py);
        // The checks of `add_block` depend on the parameters only: tried on an empty model first.
        let mut trial = Model::<AnyLaw>::new(*this.model.parameters()).py()?;
        for (k, b) in blocks.iter().enumerate() {
            trial
                .add_block(b.inner.clone())
                .map_err(|e| bad(format!("blocks[{k}] ({:?}): {e}; no block was added", b.inner.name())))?;
        }
        blocks
            .iter()
            .map(|b| Ok(this.model.add_block(b.inner.clone()).py()?.index()))
            .collect()
    }

    /// Adds an axis-aligned box from its lowest and highest corners (m), density in kg/m³;
    /// returns its index.
    #[pyo3(signature = (name, min, max, density, *, material=0, fixed=None, velocity=None, angular_velocity=None))]
    #[allow(clippy::too_many_arguments)]
    fn add_cuboid(
        &self,
        py: Python<'_>,
        name: &str,
        min: &Bound<'_, PyAny>,
        max: &Bound<'_, PyAny>,
        density: f64,
        material: u16,
        fixed: Option<&Bound<'_, PyAny>>,
        velocity: Option<&Bound<'_, PyAny>>,
        angular_velocity: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<usize> {
        let mut this = self.lock(py);
        let b =
            crate::blocks::PyBlock::cuboid(name, min, max, density, material, fixed, velocity, angular_velocity)?.inner;
        Ok(this.model.add_block(b).py()?.index())
    }

    /// Adds the convex hull of world points (an (n, 3) array or a list of triples), or, with
    /// ``faces``, that polyhedron; returns its index.
    #[pyo3(signature = (name, vertices, density, *, faces=None, material=0, fixed=None, velocity=None, angular_velocity=None))]
    #[allow(clippy::too_many_arguments)]
    fn add_polyhedron(
        &self,
        py: Python<'_>,
        name: &str,
        vertices: &Bound<'_, PyAny>,
        density: f64,
        faces: Option<Vec<Vec<usize>>>,
        material: u16,
        fixed: Option<&Bound<'_, PyAny>>,
        velocity: Option<&Bound<'_, PyAny>>,
        angular_velocity: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<usize> {
        let mut this = self.lock(py);
        let b = crate::blocks::PyBlock::from_vertices(
            name,
            vertices,
            density,
            faces,
            material,
            fixed,
            velocity,
            angular_velocity,
        )?
        .inner;
        Ok(this.model.add_block(b).py()?.index())
    }

    /// Sets a block's fixity: ``"fixed"``, ``"free"``, a bool, or ``{"translation": [d, d, d],
    /// "rotation": [d, d, d]}`` with each ``d`` ``"free"``, ``"fixed"`` or a velocity.
    fn set_fixity(&self, py: Python<'_>, block: Int, fixity: &Bound<'_, PyAny>) -> PyResult<()> {
        let mut this = self.lock(py);
        let id = this.id(&block, "block index")?;
        let f = crate::convert::fixity(Some(fixity))?;
        this.model.set_fixity(id, f).py()
    }

    /// Pushes ``block`` along ``direction`` under servo control until the load it applies has
    /// peaked and fallen (a push-over to the capacity, as 3DEC's load-capacity run; Rust:
    /// ``voussoir::loading::PushOver``): the block advances by ``increment`` (m) in each step
    /// that starts with the unbalanced-force ratio at most ``max_unbalanced_ratio`` and stands
    /// still otherwise, so that the answer has no loading rate. Every ``sample_travel``
    /// (default: ``increment``) of travel, at a settled state, the load the block applies
    /// along ``direction`` (the sum of its contact forces) is recorded. The run stops at
    /// ``max_travel``, or once the load (averaged over ``smoothing_window`` of travel) has
    /// stayed below ``stop_fraction`` of its peak for ``fallen_travel`` (default 50
    /// increments), or after ``max_steps``. The block's translations along ``direction`` must
    /// be prescribed (``fixity={"translation": [0.0, "fixed", "fixed"]}`` for x); use local
    /// damping. Check the answer with ``check_servo_convergence``. The model's monitors record
    /// at the push-over's samples.
    ///
    /// Returns a dict: ``peak_load`` (N, the capacity), ``travel_at_peak`` (m),
    /// ``raw_peak_load``, ``stop`` (``"max_travel"``, ``"fallen"`` or ``"max_steps"``) and
    /// ``curve`` (arrays ``time``, ``step``, ``travel``, ``load``, ``smoothed_load``).
    #[pyo3(signature = (block, direction, increment, *, max_unbalanced_ratio=1e-3, max_travel=0.01, stop_fraction=0.5, fallen_travel=None, sample_travel=None, smoothing_window=0.0, max_steps=100_000_000))]
    #[allow(clippy::too_many_arguments)]
    fn push_over<'py>(
        &self,
        py: Python<'py>,
        block: Int,
        direction: &Bound<'py, PyAny>,
        increment: f64,
        max_unbalanced_ratio: f64,
        max_travel: f64,
        stop_fraction: f64,
        fallen_travel: Option<f64>,
        sample_travel: Option<f64>,
        smoothing_window: f64,
        max_steps: u64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let direction = vec3(direction, "direction")?;
        let mut guard = self.lock(py);
        let id = guard.id(&block, "block index")?;
        let servo = voussoir::loading::Servo::new(id, direction, increment, max_unbalanced_ratio).py()?;
        let mut push = voussoir::loading::PushOver::new(servo);
        push.max_travel = max_travel;
        push.stop_fraction = stop_fraction;
        push.smoothing_window = smoothing_window;
        if let Some(t) = fallen_travel {
            push.fallen_travel = t;
        }
        if let Some(t) = sample_travel {
            push.sample_travel = t;
        }
        let this = &mut *guard;
        let (model, samples) = (&mut this.model, &mut this.samples);
        let result = py.detach(move || {
            push.run(model, max_steps, |m, _| {
                samples.after_step(m);
                std::ops::ControlFlow::Continue(())
            })
        });
        let interrupted = self.take_interrupt();
        drop(guard);
        if let Some(e) = interrupted {
            return Err(e);
        }
        let r = result.py()?;
        let out = PyDict::new(py);
        out.set_item("peak_load", r.peak_load)?;
        out.set_item("travel_at_peak", r.travel_at_peak)?;
        out.set_item("raw_peak_load", r.raw_peak_load)?;
        out.set_item(
            "stop",
            match r.stop {
                voussoir::loading::PushOverStop::MaxTravel => "max_travel",
                voussoir::loading::PushOverStop::Fallen => "fallen",
                voussoir::loading::PushOverStop::Callback => "callback",
                voussoir::loading::PushOverStop::MaxSteps => "max_steps",
            },
        )?;
        let curve = PyDict::new(py);
        curve.set_item("time", array1(py, r.curve.iter().map(|s| s.time).collect()))?;
        curve.set_item("step", array1(py, r.curve.iter().map(|s| s.step).collect()))?;
        curve.set_item("travel", array1(py, r.curve.iter().map(|s| s.travel).collect()))?;
        curve.set_item("load", array1(py, r.curve.iter().map(|s| s.load).collect()))?;
        curve.set_item(
            "smoothed_load",
            array1(py, r.curve.iter().map(|s| s.smoothed_load).collect()),
        )?;
        out.set_item("curve", curve)?;
        Ok(out)
    }

    /// Makes a block's translations follow base-motion histories from now on (the histories'
    /// ``t = 0`` is the model's current time), replacing any motion the block had: ``x``, ``y``,
    /// ``z`` are ``TimeHistory`` objects (or None: that axis stands still) of ``kind``
    /// ``"acceleration"`` (m/s², from rest), ``"velocity"`` (m/s) or ``"displacement"`` (m,
    /// starting at 0). With no history at all the motion is removed and the axes it drove are
    /// fixed. The driven axes must be fixed or prescribed (a shaking table: ``fixed=True``);
    /// every step they get the velocity that carries the block to the motion's displacement at
    /// the end of the step, and their reactions are booked as boundary work.
    #[pyo3(signature = (block, x=None, y=None, z=None, *, kind="acceleration"))]
    #[allow(clippy::too_many_arguments)]
    fn set_base_motion(
        &self,
        py: Python<'_>,
        block: Int,
        x: Option<PyRef<'_, crate::motion::PyTimeHistory>>,
        y: Option<PyRef<'_, crate::motion::PyTimeHistory>>,
        z: Option<PyRef<'_, crate::motion::PyTimeHistory>>,
        kind: &str,
    ) -> PyResult<()> {
        let motion = crate::motion::base_motion(kind, [x, y, z])?;
        let mut this = self.lock(py);
        let id = this.id(&block, "block index")?;
        this.model.set_base_motion(id, motion).py()
    }

    /// Sets the load on a block: a force (N) at its centroid and a moment (N·m).
    #[pyo3(signature = (block, force=None, moment=None))]
    fn set_load(
        &self,
        py: Python<'_>,
        block: Int,
        force: Option<&Bound<'_, PyAny>>,
        moment: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let mut this = self.lock(py);
        let id = this.id(&block, "block index")?;
        let w = Wrench {
            force: vec3_or_zero(force, "force")?,
            moment: vec3_or_zero(moment, "moment")?,
        };
        this.model.set_load(id, w).py()
    }

    /// Sets a block's velocity (m/s) and angular velocity (rad/s).
    #[pyo3(signature = (block, velocity, angular_velocity=None))]
    fn set_velocity(
        &self,
        py: Python<'_>,
        block: Int,
        velocity: &Bound<'_, PyAny>,
        angular_velocity: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let mut this = self.lock(py);
        let id = this.id(&block, "block index")?;
        this.model
            .set_velocity(
                id,
                vec3(velocity, "velocity")?,
                vec3_or_zero(angular_velocity, "angular_velocity")?,
            )
            .py()
    }

    /// Changes the values of a block's prescribed translation velocities (m/s): each
    /// translation that its fixity prescribes (a number in ``set_fixity``) takes the matching
    /// component; free and fixed ones stay. Cheap enough to call between every step.
    fn set_prescribed_velocity(&self, py: Python<'_>, block: Int, velocity: &Bound<'_, PyAny>) -> PyResult<()> {
        let mut this = self.lock(py);
        let id = this.id(&block, "block index")?;
        this.model.set_prescribed_velocity(id, vec3(velocity, "velocity")?).py()
    }

    // ---- running --------------------------------------------------------------------------

    /// One step.
    fn step(slf: &Bound<'_, Self>) -> PyResult<()> {
        Self::run(slf, Goal::Steps(1), None, 1).map(|_| ())
    }

    /// Runs ``n`` steps. ``callback(step, time)`` is called every ``every`` steps; the run stops
    /// if it returns a false value (``False``, ``numpy.False_``; ``None`` goes on) or raises.
    /// The model is free while the callback runs: it may read the model and drive it (loads,
    /// prescribed velocities). A callback that is not callable, or cannot take ``(step, time)``,
    /// is refused (``TypeError``) before the first step. Returns True if all steps ran.
    #[pyo3(signature = (n, callback=None, every=1000))]
    fn run_steps(slf: &Bound<'_, Self>, n: u64, callback: Option<&Bound<'_, PyAny>>, every: u64) -> PyResult<bool> {
        Ok(Self::run(slf, Goal::Steps(n), callback, every)?.1)
    }

    /// Runs until the simulated time reaches ``t`` (s); callback as ``run_steps``. Returns True
    /// if the time was reached.
    #[pyo3(signature = (t, callback=None, every=1000))]
    fn run_until_time(
        slf: &Bound<'_, Self>,
        t: f64,
        callback: Option<&Bound<'_, PyAny>>,
        every: u64,
    ) -> PyResult<bool> {
        Ok(Self::run(slf, Goal::Time(t), callback, every)?.1)
    }

    /// Runs until the unbalanced-force ratio falls below ``ratio``; returns the steps taken.
    /// Raises ``VoussoirError`` after ``max_steps``; callback as ``run_steps`` (a run it stops
    /// returns the steps taken so far).
    #[pyo3(signature = (ratio=1e-5, max_steps=1_000_000, callback=None, every=1000))]
    fn run_to_equilibrium(
        slf: &Bound<'_, Self>,
        ratio: f64,
        max_steps: u64,
        callback: Option<&Bound<'_, PyAny>>,
        every: u64,
    ) -> PyResult<u64> {
        Ok(Self::run(
            slf,
            Goal::Equilibrium {
                target: ratio,
                max_steps,
            },
            callback,
            every,
        )?
        .0)
    }

    // ---- state ----------------------------------------------------------------------------

    /// Number of blocks.
    fn __len__(&self, py: Python<'_>) -> usize {
        let this = self.lock(py);
        this.model.blocks().len()
    }

    /// Number of blocks.
    #[getter]
    fn block_count(&self, py: Python<'_>) -> usize {
        let this = self.lock(py);
        this.model.blocks().len()
    }
    /// Simulated time (s).
    #[getter]
    fn time(&self, py: Python<'_>) -> f64 {
        let this = self.lock(py);
        this.model.time()
    }
    /// Steps taken.
    #[getter]
    fn step_count(&self, py: Python<'_>) -> u64 {
        let this = self.lock(py);
        this.model.step_count()
    }
    /// Current time step (s); 0 before the first step.
    #[getter]
    fn dt(&self, py: Python<'_>) -> f64 {
        let this = self.lock(py);
        this.model.dt()
    }
    /// The critical time step (s) of the last detection, or None before the first step.
    #[getter]
    fn critical_step(&self, py: Python<'_>) -> Option<f64> {
        let this = self.lock(py);
        this.model.critical_step().map(|c| c.dt)
    }
    /// Unbalanced-force ratio of the last step.
    #[getter]
    fn unbalanced_force_ratio(&self, py: Python<'_>) -> f64 {
        let this = self.lock(py);
        this.model.unbalanced_force_ratio()
    }
    /// Number of contacts.
    #[getter]
    fn contact_count(&self, py: Python<'_>) -> usize {
        let this = self.lock(py);
        let count = this.model.contacts().len();
        count
    }
    /// Number of sub-contacts.
    #[getter]
    fn subcontact_count(&self, py: Python<'_>) -> usize {
        let this = self.lock(py);
        this.model.subcontact_count()
    }

    /// A copy of block ``i`` as it is now (a ``Block``).
    fn block(&self, py: Python<'_>, i: Int) -> PyResult<PyBlock> {
        let this = self.lock(py);
        let id = this.id(&i, "block index")?;
        Ok(PyBlock {
            inner: this.model.block(id).py()?.clone(),
        })
    }

    /// Block names, in index order.
    fn block_names(&self, py: Python<'_>) -> Vec<String> {
        let this = self.lock(py);
        this.model.blocks().iter().map(|b| b.name().to_owned()).collect()
    }

    /// Centroids (m), an (n, 3) array.
    fn positions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let this = self.lock(py);
        array_n3(py, this.model.blocks().iter().map(|b| b.state().pose.translation))
    }

    /// Centroid displacements since the blocks were built (m), an (n, 3) array.
    fn displacements<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let this = self.lock(py);
        array_n3(
            py,
            this.model
                .blocks()
                .iter()
                .map(|b| b.state().pose.translation - b.initial_pose().translation),
        )
    }

    /// Orientations as unit quaternions ``(x, y, z, w)`` (scalar last, as scipy's
    /// ``Rotation.from_quat``), an (n, 4) array: the rotation from each block's principal frame
    /// to the world.
    fn rotations<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let this = self.lock(py);
        array_nk(
            py,
            this.model.blocks().iter().map(|b| {
                let q = b.state().pose.rotation;
                [q.x, q.y, q.z, q.w]
            }),
        )
    }

    /// Each block's rotation since its initial pose (the turn that takes its initial
    /// orientation to the current one, world axes) as rotation vectors (axis times angle,
    /// rad), an (n, 3) array: what a voussoir has turned, without composing ``rotations()``
    /// (principal frame to world) with the initial orientation.
    fn rotations_from_initial<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let this = self.lock(py);
        array_n3(
            py,
            this.model
                .blocks()
                .iter()
                .map(|b| (b.state().pose.rotation * b.initial_pose().rotation.inverse()).to_scaled_axis()),
        )
    }

    /// Orientations as rotation matrices (principal frame to world), an (n, 3, 3) array.
    fn rotation_matrices<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f64>> {
        let this = self.lock(py);
        array_n33(
            py,
            this.model.blocks().iter().map(|b| {
                let q = b.state().pose.rotation;
                let (x, y, z) = (q * Vector::X, q * Vector::Y, q * Vector::Z); // the columns
                [[x.x, y.x, z.x], [x.y, y.y, z.y], [x.z, y.z, z.z]]
            }),
        )
    }

    /// Velocities of the centroids (m/s), an (n, 3) array.
    fn velocities<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let this = self.lock(py);
        array_n3(py, this.model.blocks().iter().map(|b| b.state().velocity))
    }

    /// Angular velocities (rad/s, world), an (n, 3) array.
    fn angular_velocities<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let this = self.lock(py);
        array_n3(py, this.model.blocks().iter().map(|b| b.state().angular_velocity))
    }

    /// The contacts, as a dict of arrays (one row per contact): ``blocks`` (m, 2) ints (a < b),
    /// ``normal`` (m, 3) unit normal a → b, ``normal_force`` (m,) N (compression positive),
    /// ``force`` (m, 3) resultant on b (N), ``moment_a``, ``moment_b`` (m, 3) its moments about
    /// the centroids (N·m), ``shear_force`` (m, 3) the resultant's component in the joint
    /// plane, ``application_point`` (m, 3) the centre of the sub-contacts' normal forces
    /// (where each acts within its cell), at which the resultant gives the contact's moment
    /// about any axis in the joint plane (NaN for a contact without compression),
    /// ``subcontact_count`` (m,) ints.
    fn contacts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let this = self.lock(py);
        let cs: Vec<_> = this.model.contacts().collect();
        let d = PyDict::new(py);
        let pairs: Vec<i64> = cs
            .iter()
            .flat_map(|c| {
                let (a, b) = c.blocks();
                [i64::from(a.0), i64::from(b.0)]
            })
            .collect();
        let n = cs.len();
        d.set_item(
            "blocks",
            numpy::ndarray::Array2::from_shape_vec((n, 2), pairs)
                .expect("2 per row")
                .into_pyarray(py),
        )?;
        d.set_item("normal", array_n3(py, cs.iter().map(|c| c.normal())))?;
        d.set_item(
            "normal_force",
            array1(py, cs.iter().map(|c| c.normal_force()).collect()),
        )?;
        d.set_item("force", array_n3(py, cs.iter().map(|c| c.resultant())))?;
        d.set_item("moment_a", array_n3(py, cs.iter().map(|c| c.wrench().moment_a)))?;
        d.set_item("moment_b", array_n3(py, cs.iter().map(|c| c.wrench().moment_b)))?;
        d.set_item(
            "shear_force",
            array_n3(
                py,
                cs.iter().map(|c| {
                    let (f, n) = (c.resultant(), c.normal());
                    f - n * n.dot(f)
                }),
            ),
        )?;
        d.set_item(
            "application_point",
            array_n3(
                py,
                cs.iter().map(|c| {
                    let (mut total, mut moment) = (0.0, voussoir::math::Vector::ZERO);
                    for s in c.subcontacts() {
                        let n = s.normal_force();
                        if n > 0.0 {
                            total += n;
                            moment += s.normal_force_point() * n;
                        }
                    }
                    if total > 0.0 {
                        moment / total
                    } else {
                        voussoir::math::Vector::splat(f64::NAN)
                    }
                }),
            ),
        )?;
        d.set_item(
            "subcontact_count",
            array1(py, cs.iter().map(|c| c.subcontact_count() as i64).collect()),
        )?;
        Ok(d)
    }

    /// The sub-contacts of every contact, as a dict of arrays (one row per sub-contact):
    /// ``contact`` (k,) index of its contact in ``contacts()``, ``point`` (k, 3) world position
    /// (m), ``area`` (k,) m², ``normal_force`` (k,) N and ``normal_stress`` (k,) Pa (compression
    /// positive), ``shear_force`` (k, 3) N on block b, ``normal_displacement`` (k,) m (positive
    /// open), ``slip`` (k,) m, ``status`` a list of ``"elastic"``, ``"sliding"``, ``"open"``.
    fn subcontacts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let this = self.lock(py);
        let mut contact = Vec::new();
        let mut point = Vec::new();
        let mut area = Vec::new();
        let mut fnormal = Vec::new();
        let mut stress = Vec::new();
        let mut shear = Vec::new();
        let mut un = Vec::new();
        let mut slip = Vec::new();
        let mut status = Vec::new();
        for (k, c) in this.model.contacts().enumerate() {
            for s in c.subcontacts() {
                contact.push(k as i64);
                point.push(s.point());
                area.push(s.area());
                fnormal.push(s.normal_force());
                stress.push(s.normal_stress());
                shear.push(s.shear_force());
                un.push(s.normal_displacement());
                slip.push(s.slip());
                status.push(status_name(s.status()));
            }
        }
        let d = PyDict::new(py);
        d.set_item("contact", array1(py, contact))?;
        d.set_item("point", array_n3(py, point.into_iter()))?;
        d.set_item("area", array1(py, area))?;
        d.set_item("normal_force", array1(py, fnormal))?;
        d.set_item("normal_stress", array1(py, stress))?;
        d.set_item("shear_force", array_n3(py, shear.into_iter()))?;
        d.set_item("normal_displacement", array1(py, un))?;
        d.set_item("slip", array1(py, slip))?;
        d.set_item("status", status)?;
        Ok(d)
    }

    /// The energy terms (J) as a dict: ``kinetic``, ``initial_kinetic``, ``elastic``,
    /// ``gravity_work``, ``load_work``, ``boundary_work``, ``friction``, ``damping``,
    /// ``joint_work``, and ``input``, ``accounted``, ``balance_error``.
    fn energies<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let this = self.lock(py);
        let e = this.model.energies();
        let d = PyDict::new(py);
        for (k, v) in [
            ("kinetic", e.kinetic),
            ("initial_kinetic", e.initial_kinetic),
            ("elastic", e.elastic),
            ("gravity_work", e.gravity_work),
            ("load_work", e.load_work),
            ("boundary_work", e.boundary_work),
            ("friction", e.friction),
            ("damping", e.damping),
            ("joint_work", e.joint_work),
            ("input", e.input()),
            ("accounted", e.accounted()),
            ("balance_error", e.balance_error()),
        ] {
            d.set_item(k, v)?;
        }
        Ok(d)
    }

    /// The force (N) and moment (N·m) that supports and prescribed velocities applied to a
    /// block in the last step: ``{"force": (3,), "moment": (3,)}``.
    fn reaction<'py>(&self, py: Python<'py>, block: Int) -> PyResult<Bound<'py, PyDict>> {
        let this = self.lock(py);
        let w = this.model.reaction(this.id(&block, "block index")?).py()?;
        wrench(py, w)
    }

    /// The total contact force (N) and moment (N·m, about the centroid) on a block:
    /// ``{"force": (3,), "moment": (3,)}``.
    fn contact_wrench<'py>(&self, py: Python<'py>, block: Int) -> PyResult<Bound<'py, PyDict>> {
        let this = self.lock(py);
        let w = this.model.contact_wrench(this.id(&block, "block index")?).py()?;
        wrench(py, w)
    }

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
    fn history<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let this = self.lock(py);
        let d = PyDict::new(py);
        d.set_item("step", array1(py, this.samples.steps.clone()))?;
        d.set_item("time", array1(py, this.samples.times.clone()))?;
        for ((name, _), c) in this.samples.monitors.iter().zip(&this.samples.columns) {
            d.set_item(name, array1(py, c.clone()))?;
        }
        Ok(d)
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

    // ---- files ----------------------------------------------------------------------------

    /// Writes the histories as CSV (``time [s],step,<name> [unit],...``), creating the folder.
    fn write_history_csv(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let this = self.lock(py);
        let h = this.samples.history().py()?;
        voussoir::io::csv::write_history(&path, &h).py()
    }

    /// Writes the blocks as a ParaView file (``.vtu``) at ``path``: with ``cells="surfaces"``
    /// (the default, as ``ParaviewSeries`` writes them) one polygon per face, with the block's
    /// cell data on each face and ``face``, which ParaView and meshio both read; with
    /// ``cells="polyhedra"`` one polyhedron cell per block (ParaView; meshio cannot read blocks
    /// of different vertex counts as polyhedra).
    #[pyo3(signature = (path, *, cells = "surfaces"))]
    fn write_vtk_blocks(&self, py: Python<'_>, path: PathBuf, cells: &str) -> PyResult<()> {
        let this = self.lock(py);
        let blocks = this.model.blocks();
        let initial = |i: usize| *blocks[i].initial_pose();
        match cells {
            "surfaces" => voussoir::io::vtk::write_block_surfaces(&path, blocks, initial).py(),
            "polyhedra" => voussoir::io::vtk::write_blocks(&path, blocks, initial).py(),
            other => Err(pyo3::exceptions::PyValueError::new_err(format!(
                "cells must be \"surfaces\" or \"polyhedra\", not {other:?}"
            ))),
        }
    }

    /// Writes the sub-contacts (points with forces, stresses, status) as a ParaView file
    /// (``.vtu``) at ``path``.
    fn write_vtk_subcontacts(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let this = self.lock(py);
        voussoir::io::vtk::write_subcontacts(&path, &this.model).py()
    }

    /// The model's definition (parameters, damping, laws, blocks as they are now, monitors) as
    /// scene JSON (``docs/scene-format.md``). With Coulomb laws only, the laws are written as a
    /// Rust ``Scene<CoulombSlip>`` reads them; otherwise with their kind (``Scene<AnyLaw>``).
    fn to_scene_json(&self, py: Python<'_>) -> PyResult<String> {
        let this = self.lock(py);
        let recorder = this.samples.recorder(&this.model).py()?;
        scene_json(&Scene::from_model(&this.model).with_recorder(&recorder)).py()
    }

    /// Writes ``to_scene_json()`` to a file, atomically: into a temporary file beside it, then
    /// renamed over it (a failed write leaves the previous file whole). A symbolic link is
    /// written through (its target is replaced, the link kept).
    fn save_scene(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let text = self.to_scene_json(py)?;
        voussoir::io::write_atomically(&path, text.as_bytes()).py()
    }

    /// A model from scene JSON, with its monitors (laws with or without their kind).
    #[staticmethod]
    pub(crate) fn from_scene_json(text: &str) -> PyResult<Self> {
        let scene = match normalised(text) {
            Some(t) => Scene::<AnyLaw>::from_json(&t),
            None => Scene::<AnyLaw>::from_json(text),
        }
        .py()?;
        let model = scene.build().py()?;
        let recorder = scene.recorder(&model).py()?;
        let mut m = Self::wrap(model);
        let samples = &mut m.inner.get_mut().unwrap_or_else(|p| p.into_inner()).samples;
        samples.interval = recorder.interval();
        for (name, monitor) in recorder.monitors() {
            samples.add(name, *monitor)?;
        }
        Ok(m)
    }

    /// Reads a scene file (``docs/scene-format.md``).
    #[staticmethod]
    fn load_scene(path: PathBuf) -> PyResult<Self> {
        Self::from_scene_json(&read(&path)?)
    }

    /// The full state as checkpoint JSON (a run restored from it continues bit-identically).
    /// Monitors and histories are not in it.
    fn to_checkpoint_string(&self, py: Python<'_>) -> PyResult<String> {
        let this = self.lock(py);
        this.model.to_checkpoint_string().py()
    }

    /// Writes a checkpoint file.
    fn save_checkpoint(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let this = self.lock(py);
        this.model.save_checkpoint(&path).py()
    }

    /// A model from checkpoint JSON (of this package, or of a Rust model with one law type).
    #[staticmethod]
    fn from_checkpoint_string(text: &str) -> PyResult<Self> {
        let model = match normalised(text) {
            Some(t) => Model::<AnyLaw>::from_checkpoint_str(&t),
            None => Model::<AnyLaw>::from_checkpoint_str(text),
        }
        .py()?;
        Ok(Self::wrap(model))
    }

    /// Reads a checkpoint file.
    #[staticmethod]
    fn load_checkpoint(path: PathBuf) -> PyResult<Self> {
        Self::from_checkpoint_string(&read(&path)?)
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        let this = self.lock(py);
        format!(
            "Model({} blocks, {} contacts, step {}, t = {} s)",
            this.model.blocks().len(),
            this.model.contacts().len(),
            this.model.step_count(),
            this.model.time()
        )
    }
}

fn wrench<'py>(py: Python<'py>, w: Wrench) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("force", vector(py, w.force))?;
    d.set_item("moment", vector(py, w.moment))?;
    Ok(d)
}
