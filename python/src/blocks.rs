//! Blocks, the generators (`voussoir.build`) and the ready-made scenes (`voussoir.scenes`).

use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use voussoir::block::{Block, RigidBlock};
use voussoir::build::arch::{AbutmentShape, Arch, ArchSpec};
use voussoir::build::{BarrelVaultSpec, DomeSpec, MultiLeafSpec, RubbleWallSpec, WallSpec};
use voussoir::law::MaterialId;

use crate::convert::{array_n3, fixity, fixity_to_py, points, vec3, vec3_or_zero, vector};
use crate::errors::OrPy;

/// A rigid convex polyhedral block of uniform density, not yet in a model.
///
/// Build one with ``Block.cuboid`` or ``Block.from_vertices`` (or a generator of
/// ``voussoir.build``) and add it with ``Model.add_block``; blocks are values: ``with_*``
/// return a modified copy.
#[pyclass(name = "Block", module = "voussoir", frozen)]
#[derive(Clone)]
pub struct PyBlock {
    pub inner: RigidBlock,
}

fn finish(
    block: RigidBlock,
    material: u16,
    fixed: Option<&Bound<'_, PyAny>>,
    velocity: Option<&Bound<'_, PyAny>>,
    angular_velocity: Option<&Bound<'_, PyAny>>,
) -> PyResult<PyBlock> {
    let v = vec3_or_zero(velocity, "velocity")?;
    let w = vec3_or_zero(angular_velocity, "angular_velocity")?;
    Ok(PyBlock {
        inner: block
            .with_material(MaterialId(material))
            .with_fixity(fixity(fixed)?)
            .with_velocity(v, w),
    })
}

#[pymethods]
impl PyBlock {
    /// An axis-aligned box from its lowest and highest corners (m), density in kg/m³.
    #[staticmethod]
    #[pyo3(signature = (name, min, max, density, *, material=0, fixed=None, velocity=None, angular_velocity=None))]
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn cuboid(
        name: &str,
        min: &Bound<'_, PyAny>,
        max: &Bound<'_, PyAny>,
        density: f64,
        material: i64,
        fixed: Option<&Bound<'_, PyAny>>,
        velocity: Option<&Bound<'_, PyAny>>,
        angular_velocity: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let material = crate::convert::whole(material, "material", u64::from(u16::MAX))? as u16;
        let b = RigidBlock::cuboid(name, vec3(min, "min")?, vec3(max, "max")?, density).py()?;
        finish(b, material, fixed, velocity, angular_velocity)
    }

    /// The convex hull of world points (an (n, 3) array or a list of triples), or, with
    /// ``faces`` (vertex-index loops, counter-clockwise seen from outside), that polyhedron.
    #[staticmethod]
    #[pyo3(signature = (name, vertices, density, *, faces=None, material=0, fixed=None, velocity=None, angular_velocity=None))]
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn from_vertices(
        name: &str,
        vertices: &Bound<'_, PyAny>,
        density: f64,
        faces: Option<Vec<Vec<usize>>>,
        material: i64,
        fixed: Option<&Bound<'_, PyAny>>,
        velocity: Option<&Bound<'_, PyAny>>,
        angular_velocity: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let material = crate::convert::whole(material, "material", u64::from(u16::MAX))? as u16;
        let pts = points(vertices, "vertices")?;
        let b = match faces {
            Some(f) => RigidBlock::from_faces(name, &pts, &f, density),
            None => RigidBlock::from_vertices(name, &pts, density),
        }
        .py()?;
        finish(b, material, fixed, velocity, angular_velocity)
    }

    /// A copy with another material id.
    fn with_material(&self, material: u16) -> Self {
        Self {
            inner: self.inner.clone().with_material(MaterialId(material)),
        }
    }

    /// A copy with another fixity (``"fixed"``, ``"free"``, a bool, or
    /// ``{"translation": [d, d, d], "rotation": [d, d, d]}``, each ``d`` ``"free"``, ``"fixed"``
    /// or a velocity).
    fn with_fixity(&self, fixity: &Bound<'_, PyAny>) -> PyResult<Self> {
        Ok(Self {
            inner: self.inner.clone().with_fixity(crate::convert::fixity(Some(fixity))?),
        })
    }

    /// A copy with an initial velocity (m/s) and angular velocity (rad/s).
    #[pyo3(signature = (velocity, angular_velocity=None))]
    fn with_velocity(
        &self,
        velocity: &Bound<'_, PyAny>,
        angular_velocity: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        Ok(Self {
            inner: self.inner.clone().with_velocity(
                vec3(velocity, "velocity")?,
                vec3_or_zero(angular_velocity, "angular_velocity")?,
            ),
        })
    }

    /// Name.
    #[getter]
    fn name(&self) -> &str {
        self.inner.name()
    }
    /// Material id.
    #[getter]
    fn material(&self) -> u16 {
        self.inner.material().0
    }
    /// Density (kg/m³).
    #[getter]
    fn density(&self) -> f64 {
        self.inner.density()
    }
    /// Mass (kg).
    #[getter]
    fn mass(&self) -> f64 {
        self.inner.mass_properties().mass
    }
    /// Volume (m³).
    #[getter]
    fn volume(&self) -> f64 {
        self.inner.mass_properties().volume
    }
    /// Centroid (m), a (3,) array.
    #[getter]
    fn centroid<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector(py, self.inner.state().pose.translation)
    }
    /// Vertices in world coordinates (m), an (n, 3) array.
    #[getter]
    fn vertices<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let pose = self.inner.state().pose;
        array_n3(
            py,
            self.inner.shape().vertices().iter().map(|v| pose.transform_point(*v)),
        )
    }
    /// The faces, each the list of its vertices' indices (rows of ``vertices``) in
    /// counter-clockwise order seen from outside (outward normal by the right-hand rule): the
    /// polygons of the block's surface, as COMPAS meshes and ``Model.add_polyhedron(faces=...)``
    /// take them.
    #[getter]
    fn faces(&self) -> Vec<Vec<u32>> {
        let shape = self.inner.shape();
        (0..shape.faces().len()).map(|f| shape.face_loop(f).to_vec()).collect()
    }
    /// Fixity as a dict ``{"translation": [...], "rotation": [...]}``.
    #[getter]
    fn fixity<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
        fixity_to_py(py, self.inner.fixity())
    }
    /// Whether all six degrees of freedom are fixed.
    #[getter]
    fn is_fixed(&self) -> bool {
        self.inner.fixity().is_fixed()
    }

    fn __repr__(&self) -> String {
        let c = self.inner.state().pose.translation;
        format!(
            "Block({:?}, mass={:.6} kg, centroid=({:.6}, {:.6}, {:.6}), material={}{})",
            self.inner.name(),
            self.mass(),
            c.x,
            c.y,
            c.z,
            self.material(),
            if self.is_fixed() { ", fixed" } else { "" }
        )
    }
}

fn wrap(blocks: Vec<RigidBlock>) -> Vec<PyBlock> {
    blocks.into_iter().map(|inner| PyBlock { inner }).collect()
}

/// A circular segmental arch in the x–y plane (gravity along −y: use
/// ``Model(gravity=(0, -9.81, 0))``), extruded along z by ``width``: the left abutment, the
/// voussoirs from left to right, the right abutment; the abutments are fixed.
///
/// ``span`` and ``rise`` are the clear span and the rise of the **intrados** (m; ``rise =
/// span / 2`` gives a semicircle), ``thickness`` the radial ring thickness (m), ``width`` the
/// depth along z (m), ``density`` the stones' density in kg/m³ (default 2446.5 kg/m³, a unit
/// weight of 24 kN/m³). Defaults: the reference arch of Pulatsu, Gonen & Lourenço (2021) (span
/// 1.2 m, rise 0.4 m, ring 0.2 m, 13 voussoirs).
#[pyfunction]
#[pyo3(signature = (*, span=1.2, rise=0.4, thickness=0.2, width=0.15, voussoirs=13, density=2446.4831804281343,
    abutment_outer_width=0.20, abutment_depth=0.30, voussoir_material=0, abutment_material=0))]
#[allow(clippy::too_many_arguments)]
pub fn arch(
    span: f64,
    rise: f64,
    thickness: f64,
    width: f64,
    voussoirs: i64,
    density: f64,
    abutment_outer_width: f64,
    abutment_depth: f64,
    voussoir_material: i64,
    abutment_material: i64,
) -> PyResult<Vec<PyBlock>> {
    let voussoirs = crate::convert::whole(voussoirs, "voussoirs", usize::MAX as u64)? as usize;
    let voussoir_material = crate::convert::whole(voussoir_material, "voussoir_material", u64::from(u16::MAX))? as u16;
    let abutment_material = crate::convert::whole(abutment_material, "abutment_material", u64::from(u16::MAX))? as u16;
    let spec = arch_spec(
        span,
        rise,
        thickness,
        width,
        voussoirs,
        density,
        abutment_outer_width,
        abutment_depth,
        voussoir_material,
        abutment_material,
    );
    Ok(wrap(Arch::new(&spec).py()?.blocks))
}

/// The arch generator's specification from `arch`'s arguments (also `arch_joints`'s).
#[allow(clippy::too_many_arguments)]
pub(crate) fn arch_spec(
    span: f64,
    rise: f64,
    thickness: f64,
    width: f64,
    voussoirs: usize,
    density: f64,
    abutment_outer_width: f64,
    abutment_depth: f64,
    voussoir_material: u16,
    abutment_material: u16,
) -> ArchSpec {
    let mut spec = ArchSpec::reference(width);
    spec.span = span;
    spec.rise = rise;
    spec.thickness = thickness;
    spec.voussoirs = voussoirs;
    spec.density = density;
    spec.abutment = AbutmentShape {
        outer_width: abutment_outer_width,
        depth: abutment_depth,
    };
    spec.voussoir_material = MaterialId(voussoir_material);
    spec.abutment_material = MaterialId(abutment_material);
    spec
}

/// A running-bond wall on a fixed base block (the first block), bricks in courses along x,
/// courses along z (gravity along −z).
#[pyfunction]
#[pyo3(signature = (*, bricks_per_course=10, courses=10, brick=None, density=2000.0, material=0, base_material=0))]
pub fn running_bond_wall(
    bricks_per_course: i64,
    courses: i64,
    brick: Option<&Bound<'_, PyAny>>,
    density: f64,
    material: i64,
    base_material: i64,
) -> PyResult<Vec<PyBlock>> {
    let bricks_per_course = crate::convert::whole(bricks_per_course, "bricks_per_course", usize::MAX as u64)? as usize;
    let courses = crate::convert::whole(courses, "courses", usize::MAX as u64)? as usize;
    let material = crate::convert::whole(material, "material", u64::from(u16::MAX))? as u16;
    let base_material = crate::convert::whole(base_material, "base_material", u64::from(u16::MAX))? as u16;
    let default = WallSpec::default();
    let spec = WallSpec {
        bricks_per_course,
        courses,
        brick: brick.map_or(Ok(default.brick), |b| vec3(b, "brick"))?,
        density,
        material: MaterialId(material),
        base_material: MaterialId(base_material),
    };
    Ok(wrap(voussoir::build::running_bond_wall(&spec).py()?))
}

/// A multi-leaf wall: leaves side by side along y, each of its own brick size (x, y, z), on a
/// fixed base.
#[pyfunction]
#[pyo3(signature = (*, length=2.0, height=1.0, leaves=None, density=2000.0, material=0))]
pub fn multi_leaf_wall(
    length: f64,
    height: f64,
    leaves: Option<&Bound<'_, PyAny>>,
    density: f64,
    material: i64,
) -> PyResult<Vec<PyBlock>> {
    let material = crate::convert::whole(material, "material", u64::from(u16::MAX))? as u16;
    let spec = MultiLeafSpec {
        length,
        height,
        leaves: match leaves {
            Some(l) => points(l, "leaves")?,
            None => MultiLeafSpec::default().leaves,
        },
        density,
        material: MaterialId(material),
    };
    Ok(wrap(voussoir::build::multi_leaf_wall(&spec).py()?))
}

/// A rubble wall of irregular convex stones filling ``length`` (x) × ``thickness`` (y) ×
/// ``height`` (z) m on a fixed base block (the first block): the cells of a grid of seeds about
/// ``stone_size`` apart along the wall and ``leaves`` across, each seed moved at random by up to
/// ``jitter`` of the spacing (0 gives boxes, at most 0.45); a share ``through_stones`` of the
/// places along the face holds one through-stone spanning the thickness. Neighbouring stones
/// share their faces exactly (no gap, no overlap); the same ``seed`` gives the same wall.
/// Stones are named ``stone i j k`` (along, across, up) and ``through i k``.
#[pyfunction]
#[pyo3(signature = (*, length=2.0, thickness=0.5, height=1.2, stone_size=0.2, leaves=2, jitter=0.3, through_stones=0.1, seed=1, density=2200.0, material=0, base_material=0))]
#[allow(clippy::too_many_arguments)]
pub fn rubble_wall(
    length: f64,
    thickness: f64,
    height: f64,
    stone_size: f64,
    leaves: i64,
    jitter: f64,
    through_stones: f64,
    seed: i64,
    density: f64,
    material: i64,
    base_material: i64,
) -> PyResult<Vec<PyBlock>> {
    let leaves = crate::convert::whole(leaves, "leaves", usize::MAX as u64)? as usize;
    let seed = crate::convert::whole(seed, "seed", u64::MAX)?;
    let material = crate::convert::whole(material, "material", u64::from(u16::MAX))? as u16;
    let base_material = crate::convert::whole(base_material, "base_material", u64::from(u16::MAX))? as u16;
    let spec = RubbleWallSpec {
        length,
        thickness,
        height,
        stone_size,
        leaves,
        jitter,
        through_stones,
        seed,
        density,
        material: MaterialId(material),
        base_material: MaterialId(base_material),
    };
    Ok(wrap(voussoir::build::rubble_wall(&spec).py()?))
}

/// A semicircular barrel vault: ``rings`` arch rings side by side along z, each of
/// ``voussoirs`` voussoirs (alternate rings shifted by half a voussoir), on two fixed springer
/// beams.
#[pyfunction]
#[pyo3(signature = (*, radius=2.0, thickness=0.3, ring_length=0.25, rings=10, voussoirs=25, density=2200.0, material=0))]
#[allow(clippy::too_many_arguments)]
pub fn barrel_vault(
    radius: f64,
    thickness: f64,
    ring_length: f64,
    rings: i64,
    voussoirs: i64,
    density: f64,
    material: i64,
) -> PyResult<Vec<PyBlock>> {
    let rings = crate::convert::whole(rings, "rings", usize::MAX as u64)? as usize;
    let voussoirs = crate::convert::whole(voussoirs, "voussoirs", usize::MAX as u64)? as usize;
    let material = crate::convert::whole(material, "material", u64::from(u16::MAX))? as u16;
    let spec = BarrelVaultSpec {
        radius,
        thickness,
        ring_length,
        rings,
        voussoirs,
        density,
        material: MaterialId(material),
    };
    Ok(wrap(voussoir::build::barrel_vault(&spec).py()?))
}

/// A dome of courses of voussoirs (``per_course``: voussoirs in each course, from the
/// springing up) with an oculus whose rim lies at latitude ``oculus_angle`` (rad, in
/// (0, π/2)); ``blocks`` (default 200) sets the default courses for about that many blocks.
#[pyfunction]
#[pyo3(signature = (*, blocks=None, radius=None, thickness=None, per_course=None, oculus_angle=None, density=None, material=0))]
#[allow(clippy::too_many_arguments)]
pub fn dome(
    blocks: Option<i64>,
    radius: Option<f64>,
    thickness: Option<f64>,
    per_course: Option<Vec<usize>>,
    oculus_angle: Option<f64>,
    density: Option<f64>,
    material: i64,
) -> PyResult<Vec<PyBlock>> {
    let blocks = blocks
        .map(|v| crate::convert::whole(v, "blocks", usize::MAX as u64))
        .transpose()?
        .map(|v| v as usize);
    let material = crate::convert::whole(material, "material", u64::from(u16::MAX))? as u16;
    let mut spec = DomeSpec::with_blocks(blocks.unwrap_or(200));
    if let Some(r) = radius {
        spec.radius = r;
    }
    if let Some(t) = thickness {
        spec.thickness = t;
    }
    if let Some(p) = per_course {
        spec.per_course = p;
    }
    if let Some(o) = oculus_angle {
        spec.oculus_angle = o;
    }
    if let Some(d) = density {
        spec.density = d;
    }
    spec.material = MaterialId(material);
    Ok(wrap(voussoir::build::dome(&spec).py()?))
}
