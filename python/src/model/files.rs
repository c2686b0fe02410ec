//! Files: histories as CSV, ParaView blocks and sub-contacts, scenes and checkpoints.

use std::path::PathBuf;

use pyo3::prelude::*;
use voussoir::io::scene::Scene;
use voussoir::law::AnyLaw;
use voussoir::model::Model;

use crate::documents::{normalised, read, scene_json};
use crate::errors::OrPy;

use super::PyModel;

#[pymethods]
impl PyModel {
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
        // Before `normalised`, whose `Value` would keep a duplicate key's last value.
        voussoir::io::refuse_duplicate_keys(text).py()?;
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
        voussoir::io::refuse_duplicate_keys(text).py()?;
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
}
