//! The model's state and results as numpy arrays and dicts.

use numpy::IntoPyArray;
use numpy::{PyArray2, PyArray3};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use voussoir::block::{Block, Wrench};
use voussoir::law::JointStatus;
use voussoir::math::Vector;

use crate::blocks::PyBlock;
use crate::convert::{array1, array_n3, array_n33, array_nk, vector, Int};
use crate::errors::OrPy;

use super::PyModel;

#[pymethods]
impl PyModel {
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
    /// ``tangent1``, ``tangent2`` (m, 3) the joint's tangent axes (``normal`` × ``tangent1`` =
    /// ``tangent2``) and ``tangent_force`` (m, 2) the resultant's components along them (N),
    /// ``polygon`` a list of (k, 3) arrays, the corners of each contact polygon (m, in order
    /// around it: the area a face-to-face joint's sub-contacts can carry; for a vertex or edge
    /// contact, the hull of its sub-contacts, possibly a segment or a point),
    /// ``subcontact_count`` (m,) ints, ``kind`` a list of ``"face"`` (a face-to-face joint: a grid
    /// of cells on the host face) or ``"nodes"`` (vertices, edges and tilted faces: nodes of both
    /// blocks, ``docs/theory.md`` §2.2).
    fn contacts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
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
                cs.iter()
                    .map(|c| c.application_point().unwrap_or(voussoir::math::Vector::splat(f64::NAN))),
            ),
        )?;
        let axes: Vec<_> = cs.iter().map(|c| c.axes()).collect();
        d.set_item("tangent1", array_n3(py, axes.iter().map(|a| a.tangent)))?;
        d.set_item("tangent2", array_n3(py, axes.iter().map(|a| a.tangent_2())))?;
        d.set_item(
            "tangent_force",
            array_nk::<2>(
                py,
                cs.iter()
                    .zip(&axes)
                    .map(|(c, a)| [c.resultant().dot(a.tangent), c.resultant().dot(a.tangent_2())]),
            ),
        )?;
        d.set_item(
            "kind",
            cs.iter()
                .map(|c| match c.kind() {
                    voussoir::geometry::ContactKind::FaceFace { .. } => "face",
                    voussoir::geometry::ContactKind::Nodes => "nodes",
                })
                .collect::<Vec<_>>(),
        )?;
        d.set_item(
            "polygon",
            cs.iter()
                .map(|c| array_n3(py, this.model.contact_polygon(c).into_iter()))
                .collect::<Vec<_>>(),
        )?;
        d.set_item(
            "subcontact_count",
            array1(py, cs.iter().map(|c| c.subcontact_count() as i64).collect()),
        )?;
        crate::convert::result(py, "Contacts", d)
    }

    /// The sub-contacts of every contact, as a dict of arrays (one row per sub-contact):
    /// ``contact`` (k,) index of its contact in ``contacts()``, ``point`` (k, 3) world position
    /// (m), ``area`` (k,) m², ``normal_force`` (k,) N and ``normal_stress`` (k,) Pa (compression
    /// positive), ``shear_force`` (k, 3) N on block b, ``normal_displacement`` (k,) m (positive
    /// open), ``slip`` (k,) m, ``status`` a list of ``"elastic"``, ``"sliding"``, ``"open"``.
    fn subcontacts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
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
        crate::convert::result(py, "SubContacts", d)
    }

    /// The energy terms (J) as a dict: ``kinetic``, ``initial_kinetic``, ``elastic``,
    /// ``gravity_work``, ``load_work``, ``boundary_work``, ``friction``, ``fracture`` (the
    /// fracture energy softening joints consumed), ``damping``, ``joint_work``, and ``input``,
    /// ``accounted``, ``balance_error``.
    fn energies<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
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
            ("fracture", e.fracture),
            ("damping", e.damping),
            ("joint_work", e.joint_work),
            ("input", e.input()),
            ("accounted", e.accounted()),
            ("balance_error", e.balance_error()),
        ] {
            d.set_item(k, v)?;
        }
        crate::convert::result(py, "Energies", d)
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
}

fn status_name(s: JointStatus) -> &'static str {
    match s {
        JointStatus::Elastic => "elastic",
        JointStatus::Sliding => "sliding",
        JointStatus::Open => "open",
    }
}

pub(super) fn wrench<'py>(py: Python<'py>, w: Wrench) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("force", vector(py, w.force))?;
    d.set_item("moment", vector(py, w.moment))?;
    Ok(d)
}
