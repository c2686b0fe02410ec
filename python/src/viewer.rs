//! The HTML viewer of a run (`voussoir::io::viewer`).

use std::path::PathBuf;

use pyo3::prelude::*;
use voussoir::io::viewer::Viewer;

use crate::errors::OrPy;
use crate::model::PyModel;

/// A run in one self-contained HTML page: ``Viewer(title="voussoir", *, contacts=True,
/// time_from_first_frame=False)``. ``record(model)`` adds the model's state as a frame (every
/// block's pose, displacement, speed and rotation; with ``contacts``, every contact's polygon
/// and resultant); ``write(path)`` writes the page, which any browser opens without a network:
/// the blocks in 3-D played over time with a slider, coloured by a chosen field, the joints
/// and contact forces on demand, and curves beside them (the largest displacement, the kinetic
/// energy, the model's monitors, sampled at each frame, and any ``add_curve``). In Jupyter a
/// viewer shows itself inline (``_repr_html_``).
///
/// >>> import voussoir, tempfile, pathlib
/// >>> m = voussoir.Model()
/// >>> _ = m.add_block(voussoir.Block.cuboid("cube", (0, 0, 0), (0.2, 0.2, 0.2), density=2500))
/// >>> v = voussoir.Viewer("a falling cube")
/// >>> for _ in range(3):
/// ...     _ = m.run_steps(100)
/// ...     v.record(m)
/// >>> len(v)
/// 3
/// >>> path = v.write(pathlib.Path(tempfile.mkdtemp()) / "cube.html")
/// >>> path.read_text().startswith("<!DOCTYPE html>")
/// True
#[pyclass(name = "Viewer", module = "voussoir")]
pub struct PyViewer {
    inner: Viewer,
}

#[pymethods]
impl PyViewer {
    #[new]
    #[pyo3(signature = (title="voussoir", *, contacts=true, time_from_first_frame=false))]
    fn new(title: &str, contacts: bool, time_from_first_frame: bool) -> Self {
        let mut inner = Viewer::new(title);
        if !contacts {
            inner = inner.without_contacts();
        }
        if time_from_first_frame {
            inner = inner.with_time_from_first_frame();
        }
        Self { inner }
    }

    /// Adds the model's current state as the next frame, and samples the model's monitors
    /// (``Model.add_monitor``) as curves; a monitor added since earlier frames has a gap there.
    /// Raises ``VoussoirError`` for another model's blocks than the first frame's.
    fn record(&mut self, py: Python<'_>, model: PyRef<'_, PyModel>) -> PyResult<()> {
        let this = model.lock(py);
        for (name, monitor) in this.monitors() {
            if !self.inner.has_monitor(name) {
                self.inner.add_monitor(name, *monitor).py()?;
            }
        }
        self.inner.record(&this.model).py()
    }

    /// Adds a curve of points ``x``, ``y`` beside the blocks. With ``time_axis`` (the
    /// default), ``x`` is time on the frames' clock and the page marks the frame shown on it.
    /// NaN values leave gaps. Raises ``VoussoirError`` for a name taken or lengths that differ.
    #[pyo3(signature = (name, x, y, *, x_label="time (s)", y_label="", time_axis=true))]
    fn add_curve(
        &mut self,
        name: &str,
        x: Vec<f64>,
        y: Vec<f64>,
        x_label: &str,
        y_label: &str,
        time_axis: bool,
    ) -> PyResult<()> {
        self.inner.add_curve(name, (x_label, y_label), &x, &y, time_axis).py()
    }

    /// The page, as a string (``VoussoirError`` before the first frame).
    fn html(&self) -> PyResult<String> {
        self.inner.to_html().py()
    }

    /// Writes the page to ``path`` (atomically, creating the folder) and returns the path.
    fn write(&self, path: PathBuf) -> PyResult<PathBuf> {
        self.inner.write(&path).py()?;
        Ok(path)
    }

    /// The page inside an ``iframe`` (its own document, so that its script and style stay
    /// apart from the notebook's): how Jupyter shows a viewer inline.
    fn _repr_html_(&self) -> PyResult<String> {
        let page = self.inner.to_html().py()?;
        let mut escaped = String::with_capacity(page.len() + page.len() / 8);
        for c in page.chars() {
            match c {
                '&' => escaped.push_str("&amp;"),
                '"' => escaped.push_str("&quot;"),
                c => escaped.push(c),
            }
        }
        Ok(format!(
            "<iframe srcdoc=\"{escaped}\" style=\"width: 100%; height: 560px; border: 1px solid #ddd;\" \
             sandbox=\"allow-scripts\" title=\"voussoir viewer\"></iframe>"
        ))
    }

    /// The frames' times (s).
    #[getter]
    fn times(&self) -> Vec<f64> {
        self.inner.times()
    }

    fn __len__(&self) -> usize {
        self.inner.len()
    }

    fn __repr__(&self) -> String {
        format!("Viewer({} frames)", self.inner.len())
    }
}
