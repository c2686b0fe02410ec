//! `voussoir.Model`: a model of rigid blocks with the shipped joint laws (`Model<AnyLaw>`).
//! This file holds the class, its lock and how it is built and loaded; the methods are split
//! by concern: `run.rs` (runs, callbacks, progress), `state.rs` (results as numpy arrays),
//! `monitors.rs` (monitors and histories), `files.rs` (ParaView, CSV, scenes, checkpoints).

mod files;
mod monitors;
mod run;
mod state;

use std::sync::atomic::Ordering;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use voussoir::block::{Block, BlockId, Wrench};
use voussoir::contact::DisplacementMode;
use voussoir::geometry::SubContactDensity;
use voussoir::integrate::{Damping, TimeStep};
use voussoir::law::{AnyLaw, MaterialId};
use voussoir::model::{InterruptCheck, JointStepping, Model, ModelParameters};

use crate::blocks::PyBlock;
use crate::convert::{array1, vec3, vec3_or_zero, vector, Int};
use crate::errors::{bad, OrPy};
use crate::laws::{law_from_py, law_to_py};

use monitors::Samples;

/// A discrete element model of rigid blocks.
///
/// ``Model(*, gravity=(0, 0, -9.81), contact_tolerance=1e-3, subcontacts_per_edge=15,
/// subcontact_spacing=None, time_step=None, safety=0.5, mode="large", max_speed=1000.0,
/// impact_step=0.1, node_rule="point")``: ``time_step`` None is automatic at ``safety`` times
/// the critical step, a number is a fixed step (s); ``subcontact_spacing`` (m), when given,
/// replaces ``subcontacts_per_edge``; ``impact_step`` None turns the impact refinement off;
/// ``node_rule`` is how node contacts' normal springs act (vertices, edges, tilted faces):
/// ``"point"`` at each node's point, ``"integrated"`` over the surface each node stands for,
/// which keeps the energy of a loaded hinge that turns into a node contact (and back into a
/// joint when its faces close flat) at several times the cost of a node (``docs/theory.md``
/// §2.2, §6).
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
    /// The monitors added with `add_monitor`, in order.
    pub(crate) fn monitors(&self) -> &[(String, voussoir::monitor::Monitor)] {
        &self.samples.monitors
    }

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
}

/// A material id from a Python int (`ValueError` naming `what` outside [0, 65535]).
fn material(k: &Int, what: &str) -> PyResult<MaterialId> {
    Ok(MaterialId(k.at_most(what, u64::from(u16::MAX))? as u16))
}

#[pymethods]
impl PyModel {
    #[new]
    #[pyo3(signature = (*, gravity=None, contact_tolerance=ModelParameters::default().contact.tolerance,
        subcontacts_per_edge=i64::from(voussoir::geometry::DEFAULT_SUBCONTACTS_PER_EDGE), subcontact_spacing=None,
        time_step=None, safety=voussoir::integrate::DEFAULT_SAFETY, mode="large",
        max_speed=ModelParameters::default().max_speed, impact_step=ModelParameters::default().impact_step,
        node_rule="point"))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        gravity: Option<&Bound<'_, PyAny>>,
        contact_tolerance: f64,
        subcontacts_per_edge: i64,
        subcontact_spacing: Option<f64>,
        time_step: Option<f64>,
        safety: f64,
        mode: &str,
        max_speed: f64,
        impact_step: Option<f64>,
        node_rule: &str,
    ) -> PyResult<Self> {
        let subcontacts_per_edge =
            crate::convert::whole(subcontacts_per_edge, "subcontacts_per_edge", u64::from(u16::MAX))? as u16;
        let mut params = ModelParameters::default();
        if let Some(g) = gravity {
            params.gravity = vec3(g, "gravity")?;
        }
        params.contact.tolerance = contact_tolerance;
        params.contact.density = match subcontact_spacing {
            Some(h) => SubContactDensity::Spacing(h),
            None => SubContactDensity::PerEdge(subcontacts_per_edge),
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
        params.contact.node_rule = node_rule.parse().map_err(bad)?;
        Ok(Self::wrap(Model::new(params).py()?))
    }

    /// The constructor's defaults, from the Rust library's ``ModelParameters::default()`` (the
    /// one place they are written): ``gravity``, ``contact_tolerance``,
    /// ``subcontacts_per_edge``, ``safety``, ``mode``, ``max_speed``, ``impact_step``,
    /// ``node_rule``.
    ///
    /// >>> import voussoir as vs
    /// >>> vs.Model.defaults()["subcontacts_per_edge"]
    /// 15
    #[staticmethod]
    fn defaults(py: Python<'_>) -> PyResult<Bound<'_, pyo3::types::PyDict>> {
        let p = ModelParameters::default();
        let d = pyo3::types::PyDict::new(py);
        d.set_item("gravity", (p.gravity.x, p.gravity.y, p.gravity.z))?;
        d.set_item("contact_tolerance", p.contact.tolerance)?;
        d.set_item("subcontacts_per_edge", voussoir::geometry::DEFAULT_SUBCONTACTS_PER_EDGE)?;
        d.set_item(
            "safety",
            match p.time_step {
                TimeStep::Auto { safety } => safety,
                TimeStep::Fixed(_) => voussoir::integrate::DEFAULT_SAFETY,
            },
        )?;
        d.set_item(
            "mode",
            match p.mode {
                DisplacementMode::Large => "large",
                DisplacementMode::Small => "small",
            },
        )?;
        d.set_item("max_speed", p.max_speed)?;
        d.set_item("impact_step", p.impact_step)?;
        d.set_item("node_rule", p.contact.node_rule.name())?;
        Ok(d)
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

    /// Sets the joint law of the interface between blocks ``a`` and ``b`` (either order): it
    /// takes precedence over the law of their materials (per-interface properties, as 3DEC and
    /// ``compas_3dec`` give them). Takes effect at the next step.
    fn set_interface_law(&self, py: Python<'_>, a: Int, b: Int, law: &Bound<'_, PyAny>) -> PyResult<()> {
        let mut this = self.lock(py);
        let (a, b) = (this.id(&a, "block a")?, this.id(&b, "block b")?);
        let law = law_from_py(law)?;
        this.model.set_interface_law(a, b, law).py()
    }

    /// The joint law of the interface between blocks ``a`` and ``b`` if it has its own (set
    /// with ``set_interface_law``), or None.
    fn interface_law<'py>(&self, py: Python<'py>, a: Int, b: Int) -> PyResult<Option<Bound<'py, PyAny>>> {
        let this = self.lock(py);
        let (a, b) = (this.id(&a, "block a")?, this.id(&b, "block b")?);
        this.model
            .law_table()
            .get_interface(a, b)
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

    /// Sets how a face-face joint that is closed all over and sticks is stepped: ``"whole"``
    /// (the default: a few dozen operations a step, whatever its sub-contacts; they are written
    /// when it opens or slips, or when they are read) or ``"cells"`` (every sub-contact every
    /// step, to compare with). Both give the same answers to round-off.
    fn set_joint_stepping(&self, py: Python<'_>, stepping: &str) -> PyResult<()> {
        let mut this = self.lock(py);
        let stepping = match stepping.to_ascii_lowercase().as_str() {
            "whole" => JointStepping::Whole,
            "cells" => JointStepping::Cells,
            other => {
                return Err(bad(format!(
                    "joint stepping {other:?}: expected \"whole\" or \"cells\""
                )))
            }
        };
        this.model.set_joint_stepping(stepping);
        Ok(())
    }

    /// How closed, sticking joints are stepped: ``"whole"`` or ``"cells"``.
    #[getter]
    fn joint_stepping(&self, py: Python<'_>) -> &'static str {
        match self.lock(py).model.joint_stepping() {
            JointStepping::Whole => "whole",
            JointStepping::Cells => "cells",
        }
    }

    /// How many joints were stepped as a whole in the last step (closed all over and sticking,
    /// open all over and unloaded, or open in part, a hinge, with their closed cells sticking
    /// stepped as a whole and the others one by one).
    fn whole_joint_count(&self, py: Python<'_>) -> usize {
        self.lock(py).model.whole_joint_count()
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

    /// Adds blocks (any iterable of ``Block``: a list from ``voussoir.build``, a generator);
    /// returns their indices. All or nothing: when one is refused, none is added (the error
    /// names the first refused, by its position in the iterable).
    fn add_blocks(&self, py: Python<'_>, blocks: &Bound<'_, PyAny>) -> PyResult<Vec<usize>> {
        // Taken in full before the model is locked: a generator may read the model.
        let mut taken: Vec<PyRef<'_, PyBlock>> = Vec::new();
        let items = blocks.try_iter().map_err(|_| {
            pyo3::exceptions::PyTypeError::new_err(format!(
                "blocks: expected an iterable of Block, got {}",
                blocks.get_type().name().map_or_else(|_| "?".into(), |n| n.to_string())
            ))
        })?;
        for (k, item) in items.enumerate() {
            if k == crate::convert::MAX_ITEMS {
                return Err(crate::convert::too_many("blocks"));
            }
            let item = item?;
            taken.push(item.extract().map_err(|_| {
                pyo3::exceptions::PyTypeError::new_err(format!(
                    "blocks[{k}]: expected a Block, got {}; no block was added",
                    item.get_type().name().map_or_else(|_| "?".into(), |n| n.to_string())
                ))
            })?);
        }
        let blocks = taken;
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
        material: i64,
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
        material: i64,
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
    /// at the push-over's samples. ``progress=True`` shows a bar of the travel towards
    /// ``max_travel`` with the load (as ``run_steps``).
    ///
    /// Returns a dict: ``peak_load`` (N, the capacity), ``travel_at_peak`` (m),
    /// ``raw_peak_load``, ``stop`` (``"max_travel"``, ``"fallen"`` or ``"max_steps"``) and
    /// ``curve`` (arrays ``time``, ``step``, ``travel``, ``load``, ``smoothed_load``).
    #[pyo3(signature = (block, direction, increment, *, max_unbalanced_ratio=1e-3, max_travel=0.01, stop_fraction=0.5, fallen_travel=None, sample_travel=None, smoothing_window=0.0, max_steps=100_000_000, progress=false))]
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
        max_steps: i64,
        progress: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let max_steps = crate::convert::whole(max_steps, "max_steps", u64::MAX)?;
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
        let bar = if progress {
            let (step, time) = (guard.model.step_count(), guard.model.time());
            let bar = py.import("voussoir._progress")?.getattr("RunProgress")?.call1((
                "push_over",
                max_travel,
                step,
                time,
            ))?;
            Some(bar.unbind())
        } else {
            None
        };
        let this = &mut *guard;
        let (model, samples) = (&mut this.model, &mut this.samples);
        let result = py.detach(|| {
            let mut shown = std::time::Instant::now();
            push.run(model, max_steps, |m, sample| {
                samples.after_step(m);
                if let Some(bar) = &bar {
                    if shown.elapsed() >= std::time::Duration::from_millis(200) {
                        shown = std::time::Instant::now();
                        // A failing bar does not stop the analysis.
                        Python::attach(|py| {
                            let _ = bar.call_method1(py, "update_travel", (sample.step, sample.travel, sample.load));
                        });
                    }
                }
                std::ops::ControlFlow::Continue(())
            })
        });
        let interrupted = self.take_interrupt();
        drop(guard);
        if let Some(bar) = bar {
            if let Some(last) = result.as_ref().ok().and_then(|r| r.curve.last()) {
                bar.call_method1(py, "update_travel", (last.step, last.travel, last.load))?;
            }
            bar.call_method0(py, "close")?;
        }
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
        crate::convert::result(py, "PushOverResult", out)
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

    /// Makes a block's load vary in time from now on: ``force`` (N, at its centroid) and
    /// ``moment`` (N·m) scaled by the factor ``history`` (a ``TimeHistory``; its ``t = 0`` is
    /// the model's current time; the factor is 0 before its first sample and keeps its last
    /// value after its last, so that a ramp to 1 holds the full load). ``history=None``
    /// removes the history and leaves the block with the load it last had; ``set_load``
    /// replaces it with a constant load. Rust: ``Model::set_load_history``.
    ///
    /// >>> import voussoir as vs
    /// >>> m = vs.Model(gravity=(0, 0, 0))
    /// >>> m.set_damping("none")
    /// >>> b = m.add_cuboid("block", (0, 0, 0), (0.2, 0.2, 0.2), 2500.0)  # 20 kg
    /// >>> m.set_load_history(b, vs.TimeHistory([0.0, 0.1], [0.0, 1.0]), force=(100, 0, 0))
    /// >>> m.run_until_time(0.1)
    /// True
    /// >>> x = float(m.displacements()[b, 0])  # F t³ / (6 m T) for a ramp to F over T
    /// >>> abs(x / (100 * m.time ** 3 / (6 * 20 * 0.1)) - 1) < 2e-3
    /// True
    #[pyo3(signature = (block, history, force=None, moment=None))]
    fn set_load_history(
        &self,
        py: Python<'_>,
        block: Int,
        history: Option<PyRef<'_, crate::motion::PyTimeHistory>>,
        force: Option<&Bound<'_, PyAny>>,
        moment: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let load = match history {
            Some(h) => {
                let w = Wrench {
                    force: vec3_or_zero(force, "force")?,
                    moment: vec3_or_zero(moment, "moment")?,
                };
                Some(voussoir::loading::LoadHistory::new(w, h.inner.clone()).py()?)
            }
            None => None,
        };
        let mut this = self.lock(py);
        let id = this.id(&block, "block index")?;
        this.model.set_load_history(id, load).py()
    }

    /// The block's load now: ``{"force": (3,), "moment": (3,)}`` (a load history's value at
    /// the last step).
    fn load<'py>(&self, py: Python<'py>, block: Int) -> PyResult<Bound<'py, PyDict>> {
        let this = self.lock(py);
        let w = this.model.block(this.id(&block, "block index")?).py()?.load();
        state::wrench(py, w)
    }

    /// Sets the constant load on a block, replacing any load history: a force (N) at its
    /// centroid and a moment (N·m).
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
