//! Time histories and base motions from Python (`voussoir::loading`): the seismic use of the
//! engine.

use std::path::PathBuf;

use numpy::PyArray1;
use pyo3::prelude::*;
use voussoir::loading::{BaseMotion, MotionKind, TimeHistory};

use crate::convert::array1;
use crate::errors::{bad, OrPy};

/// A sampled history ``h(t)``, linear between samples: an accelerogram, a velocity or a
/// displacement record (Rust: ``voussoir::loading::TimeHistory``).
///
/// ``TimeHistory(times, values)``: times (s) strictly increasing, at least two samples, values
/// finite. ``TimeHistory.sine(amplitude, frequency, duration, samples_per_period=50)``:
/// ``amplitude * sin(2 pi frequency t)`` from 0 to ``duration``.
/// ``TimeHistory.from_csv(path, time_column=0, value_column=1, scale=1.0)``: two columns of a
/// CSV file (comma, semicolon, tab or blank separated; a header and ``#`` lines skipped), the
/// values times ``scale`` (9.81 for a record in g).
///
/// >>> import voussoir as vs
/// >>> h = vs.TimeHistory([0.0, 1.0, 2.0], [0.0, 2.0, 0.0])
/// >>> h.value_at(0.5), h.end, len(h)
/// (1.0, 2.0, 3)
#[pyclass(name = "TimeHistory", module = "voussoir", frozen)]
#[derive(Clone)]
pub struct PyTimeHistory {
    pub(crate) inner: TimeHistory,
}

#[pymethods]
impl PyTimeHistory {
    #[new]
    fn new(times: Vec<f64>, values: Vec<f64>) -> PyResult<Self> {
        Ok(Self {
            inner: TimeHistory::new(times, values).py()?,
        })
    }

    /// ``amplitude * sin(2 pi frequency t)`` sampled ``samples_per_period`` times a period
    /// from 0 to ``duration`` (s).
    #[staticmethod]
    #[pyo3(signature = (amplitude, frequency, duration, samples_per_period=50))]
    fn sine(amplitude: f64, frequency: f64, duration: f64, samples_per_period: u32) -> PyResult<Self> {
        Ok(Self {
            inner: TimeHistory::sine(amplitude, frequency, duration, samples_per_period).py()?,
        })
    }

    /// Two columns of a CSV file (0-based), the values times ``scale``.
    #[staticmethod]
    #[pyo3(signature = (path, time_column=0, value_column=1, scale=1.0))]
    fn from_csv(path: PathBuf, time_column: usize, value_column: usize, scale: f64) -> PyResult<Self> {
        Ok(Self {
            inner: TimeHistory::from_csv_file(&path, time_column, value_column, scale).py()?,
        })
    }

    /// The sample times (s).
    #[getter]
    fn times<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, self.inner.times().to_vec())
    }

    /// The sample values.
    #[getter]
    fn values<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, self.inner.values().to_vec())
    }

    /// The last sample's time (s).
    #[getter]
    fn end(&self) -> f64 {
        self.inner.end()
    }

    /// The value at ``t``, linear between samples.
    fn value_at(&self, t: f64) -> f64 {
        self.inner.value_at(t)
    }

    fn __len__(&self) -> usize {
        self.inner.times().len()
    }

    fn __repr__(&self) -> String {
        format!(
            "TimeHistory({} samples, {} to {} s)",
            self.inner.times().len(),
            self.inner.times()[0],
            self.inner.end()
        )
    }
}

/// A [`BaseMotion`] from the keyword arguments of `Model.set_base_motion`; `None` when no axis
/// has a history (the motion is removed).
pub fn base_motion(kind: &str, axes: [Option<PyRef<'_, PyTimeHistory>>; 3]) -> PyResult<Option<BaseMotion>> {
    let kind = match kind {
        "acceleration" => MotionKind::Acceleration,
        "velocity" => MotionKind::Velocity,
        "displacement" => MotionKind::Displacement,
        other => {
            return Err(bad(format!(
                "kind {other:?}: expected \"acceleration\", \"velocity\" or \"displacement\""
            )))
        }
    };
    if axes.iter().all(Option::is_none) {
        return Ok(None);
    }
    let axes = axes.map(|h| h.map(|h| h.inner.clone()));
    BaseMotion::new(kind, axes).py().map(Some)
}
