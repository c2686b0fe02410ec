//! Runs from Python: in chunks with the GIL let go, Ctrl-C and the callback between chunks.

use std::time::{Duration, Instant};

use pyo3::prelude::*;
use voussoir::Error;

use crate::errors::{bad, OrPy};

use super::PyModel;

/// How often a run without a callback comes back to Python to look for Ctrl-C (wall time).
const SIGNAL_INTERVAL: Duration = Duration::from_millis(100);

/// What a run runs to.
#[derive(Clone, Copy)]
enum Goal {
    Steps(u64),
    Time(f64),
    Equilibrium { target: f64, max_steps: u64 },
}

impl PyModel {
    /// The KeyboardInterrupt an interrupted step took, if any.
    pub(super) fn take_interrupt(&self) -> Option<PyErr> {
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
        progress: bool,
    ) -> PyResult<(u64, bool)> {
        let py = slf.py();
        if !progress {
            return Self::run_chunks(slf, goal, callback, every, None);
        }
        let (step, time) = {
            let this = slf.get().lock(py);
            (this.model.step_count(), this.model.time())
        };
        let (kind, total) = match goal {
            Goal::Steps(n) => ("steps", (step + n) as f64),
            Goal::Time(t) => ("time", t),
            Goal::Equilibrium { max_steps, .. } => ("equilibrium", (step + max_steps) as f64),
        };
        let bar = py
            .import("voussoir._progress")?
            .getattr("RunProgress")?
            .call1((kind, total, step, time))?;
        let outcome = Self::run_chunks(slf, goal, callback, every, Some(&bar));
        // Closed also when the run fails, so that the bar does not stay half drawn.
        bar.call_method0("close")?;
        outcome
    }

    /// [`Self::run`]'s loop; `bar.update(step, time, ratio)` after every chunk.
    fn run_chunks(
        slf: &Bound<'_, Self>,
        goal: Goal,
        callback: Option<&Bound<'_, PyAny>>,
        every: u64,
        bar: Option<&Bound<'_, PyAny>>,
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
            let ratio = this.model.unbalanced_force_ratio();
            // The model is free again: the callback may read and drive it, and threads waiting
            // for it take it.
            drop(guard);
            me.let_waiting_in(py);
            let (n, done) = outcome.py()?;
            taken += n;
            since_callback += n;
            if let Some(bar) = bar {
                bar.call_method1("update", (step, time, ratio))?;
            }
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

#[pymethods]
impl PyModel {
    // ---- running --------------------------------------------------------------------------

    /// One step.
    fn step(slf: &Bound<'_, Self>) -> PyResult<()> {
        Self::run(slf, Goal::Steps(1), None, 1, false).map(|_| ())
    }

    /// Runs ``n`` steps. ``callback(step, time)`` is called every ``every`` steps; the run stops
    /// if it returns a false value (``False``, ``numpy.False_``; ``None`` goes on) or raises.
    /// The model is free while the callback runs: it may read the model and drive it (loads,
    /// prescribed velocities). A callback that is not callable, or cannot take ``(step, time)``,
    /// is refused (``TypeError``) before the first step. ``progress=True`` shows a progress
    /// bar (``tqdm.auto`` when tqdm is installed: a text bar in a terminal, a widget in
    /// Jupyter; otherwise a line on standard error), with the step, time and unbalanced-force
    /// ratio. Returns True if all steps ran.
    #[pyo3(signature = (n, callback=None, every=1000, *, progress=false))]
    fn run_steps(
        slf: &Bound<'_, Self>,
        n: i64,
        callback: Option<&Bound<'_, PyAny>>,
        every: i64,
        progress: bool,
    ) -> PyResult<bool> {
        let n = crate::convert::whole(n, "n", u64::MAX)?;
        let every = crate::convert::whole(every, "every", u64::MAX)?;
        Ok(Self::run(slf, Goal::Steps(n), callback, every, progress)?.1)
    }

    /// Runs until the simulated time reaches ``t`` (s); callback and progress as
    /// ``run_steps`` (the bar counts simulated seconds). Returns True if the time was reached.
    #[pyo3(signature = (t, callback=None, every=1000, *, progress=false))]
    fn run_until_time(
        slf: &Bound<'_, Self>,
        t: f64,
        callback: Option<&Bound<'_, PyAny>>,
        every: i64,
        progress: bool,
    ) -> PyResult<bool> {
        let every = crate::convert::whole(every, "every", u64::MAX)?;
        Ok(Self::run(slf, Goal::Time(t), callback, every, progress)?.1)
    }

    /// Runs until the unbalanced-force ratio falls below ``ratio``; returns the steps taken.
    /// Raises ``VoussoirError`` after ``max_steps``; callback as ``run_steps`` (a run it stops
    /// returns the steps taken so far); progress as ``run_steps`` (the bar counts steps up to
    /// ``max_steps`` and shows the ratio).
    #[pyo3(signature = (ratio=1e-5, max_steps=1_000_000, callback=None, every=1000, *, progress=false))]
    fn run_to_equilibrium(
        slf: &Bound<'_, Self>,
        ratio: f64,
        max_steps: i64,
        callback: Option<&Bound<'_, PyAny>>,
        every: i64,
        progress: bool,
    ) -> PyResult<u64> {
        let max_steps = crate::convert::whole(max_steps, "max_steps", u64::MAX)?;
        let every = crate::convert::whole(every, "every", u64::MAX)?;
        Ok(Self::run(
            slf,
            Goal::Equilibrium {
                target: ratio,
                max_steps,
            },
            callback,
            every,
            progress,
        )?
        .0)
    }
}
