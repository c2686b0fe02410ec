//! ParaView series and the benchmarks' wall.

use std::path::PathBuf;

use pyo3::prelude::*;
use voussoir::io::scene::Scene;

use crate::errors::OrPy;
use crate::model::PyModel;

/// A ParaView series: ``ParaviewSeries(folder, name, *, subcontacts_every=1)``;
/// ``write_frame(model)`` writes the blocks (the polygons of their faces) and the sub-contacts
/// (points) of the model as a frame and rewrites the ``.pvd`` collections (``blocks_pvd``),
/// which ParaView opens as a time series; ``meshio.read`` opens each frame's files. With
/// ``subcontacts_every=n`` the sub-contacts, the large files, are written on every n-th frame
/// only (the first, then every n-th), the blocks on every frame. With
/// ``time_from_first_frame=True`` the collections' times count from the first frame (a run's
/// start) instead of the model's time (which includes any settling before). One series writes a name in a
/// folder at a time (a lock file ``.<name>.lock`` from the first frame until the series is
/// freed): a second one, in this process or another, raises ``VoussoirIOError``; so does a
/// frame after the folder was deleted or emptied mid-run.
#[pyclass(name = "ParaviewSeries", module = "voussoir")]
pub struct PySeries {
    inner: voussoir::io::vtk::Series,
}

#[pymethods]
impl PySeries {
    #[new]
    #[pyo3(signature = (folder, name="model", *, subcontacts_every=1, time_from_first_frame=false))]
    fn new(folder: PathBuf, name: &str, subcontacts_every: usize, time_from_first_frame: bool) -> PyResult<Self> {
        if subcontacts_every == 0 {
            return Err(pyo3::exceptions::PyValueError::new_err(
                "subcontacts_every must be at least 1 (every frame)",
            ));
        }
        let mut inner = voussoir::io::vtk::Series::new(folder, name).with_subcontacts_every(subcontacts_every);
        if time_from_first_frame {
            inner = inner.with_time_from_first_frame();
        }
        Ok(Self { inner })
    }

    /// Writes a frame of the model.
    fn write_frame(&mut self, py: Python<'_>, model: PyRef<'_, PyModel>) -> PyResult<()> {
        self.inner.write_frame(&model.lock(py).model).py()
    }

    /// The blocks' ``.pvd`` collection.
    #[getter]
    fn blocks_pvd(&self) -> PathBuf {
        self.inner.blocks_pvd()
    }

    fn __len__(&self) -> usize {
        self.inner.len()
    }
}

/// The benchmarks' wall (``voussoir::scenes::benchmark_wall``): about ``blocks`` bricks in
/// running bond on a fixed base, dry Coulomb joints (kn 1 GPa/m, ks 0.4 GPa/m, φ 30°),
/// sub-contacts at most ``spacing`` m apart (default 0.025), local damping; not yet stepped.
#[pyfunction]
#[pyo3(signature = (blocks, *, spacing=None))]
pub fn benchmark_wall(blocks: usize, spacing: Option<f64>) -> PyResult<PyModel> {
    let model = match spacing {
        Some(h) => voussoir::scenes::benchmark_wall_with_spacing(blocks, h),
        None => voussoir::scenes::benchmark_wall(blocks),
    }
    .py()?;
    // A Model<CoulombSlip> as a Model<AnyLaw>, through its scene.
    let scene = Scene::from_model(&model);
    let text = scene.to_json().py()?;
    PyModel::from_scene_json(&text)
}
