//! The shipped joint laws.

use pyo3::prelude::*;
use voussoir::law::{AnyLaw, ConstitutiveLaw, CoulombSlip, LinearElastic};

use crate::errors::{bad, OrPy};

/// Coulomb slip with tension cut-off, cohesion and residual friction.
///
/// ``CoulombSlip(kn, ks, friction_deg, residual_friction_deg=None, cohesion=0.0,
/// tensile_strength=0.0)``: stiffnesses in Pa/m, angles in degrees ([0, 90)), strengths in Pa;
/// the residual friction angle defaults to the initial one. ``CoulombSlip.dry(kn, ks,
/// friction_deg)`` is the dry joint (no cohesion, no tension).
#[pyclass(name = "CoulombSlip", module = "voussoir", frozen)]
#[derive(Clone)]
pub struct PyCoulombSlip {
    pub inner: CoulombSlip,
}

#[pymethods]
impl PyCoulombSlip {
    #[new]
    #[pyo3(signature = (kn, ks, friction_deg, residual_friction_deg=None, cohesion=0.0, tensile_strength=0.0))]
    fn new(
        kn: f64,
        ks: f64,
        friction_deg: f64,
        residual_friction_deg: Option<f64>,
        cohesion: f64,
        tensile_strength: f64,
    ) -> PyResult<Self> {
        let inner = CoulombSlip::new(
            kn,
            ks,
            friction_deg,
            residual_friction_deg.unwrap_or(friction_deg),
            cohesion,
            tensile_strength,
        )
        .py()?;
        Ok(Self { inner })
    }

    /// A dry joint: no cohesion, no tension, residual friction equal to the initial one.
    #[staticmethod]
    #[pyo3(signature = (kn, ks, friction_deg))]
    fn dry(kn: f64, ks: f64, friction_deg: f64) -> PyResult<Self> {
        Ok(Self {
            inner: CoulombSlip::dry(kn, ks, friction_deg).py()?,
        })
    }

    /// Normal stiffness (Pa/m).
    #[getter]
    fn kn(&self) -> f64 {
        self.inner.normal_stiffness()
    }
    /// Shear stiffness (Pa/m).
    #[getter]
    fn ks(&self) -> f64 {
        self.inner.shear_stiffness()
    }
    /// Friction angle (degrees).
    #[getter]
    fn friction_deg(&self) -> f64 {
        degrees(&self.inner, "friction_deg")
    }
    /// Residual friction angle (degrees).
    #[getter]
    fn residual_friction_deg(&self) -> f64 {
        degrees(&self.inner, "residual_friction_deg")
    }
    /// Cohesion (Pa).
    #[getter]
    fn cohesion(&self) -> f64 {
        self.inner.cohesion()
    }
    /// Tensile strength (Pa).
    #[getter]
    fn tensile_strength(&self) -> f64 {
        self.inner.tensile_strength()
    }

    fn __repr__(&self) -> String {
        format!(
            "CoulombSlip(kn={:e}, ks={:e}, friction_deg={}, residual_friction_deg={}, cohesion={}, tensile_strength={})",
            self.kn(),
            self.ks(),
            self.friction_deg(),
            self.residual_friction_deg(),
            self.cohesion(),
            self.tensile_strength()
        )
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other.cast::<PyCoulombSlip>().is_ok_and(|o| o.get().inner == self.inner)
    }
}

/// An angle of the law in degrees as it was given (the accessors give radians; converting
/// back could differ in the last bit), read from its serialised form.
fn degrees(law: &CoulombSlip, field: &str) -> f64 {
    serde_json::to_value(law)
        .ok()
        .and_then(|v| v.get(field).and_then(serde_json::Value::as_f64))
        .unwrap_or(f64::NAN)
}

/// Linear springs with no strength limit: ``LinearElastic(kn, ks)`` in Pa/m.
#[pyclass(name = "LinearElastic", module = "voussoir", frozen)]
#[derive(Clone)]
pub struct PyLinearElastic {
    pub inner: LinearElastic,
}

#[pymethods]
impl PyLinearElastic {
    #[new]
    #[pyo3(signature = (kn, ks))]
    fn new(kn: f64, ks: f64) -> PyResult<Self> {
        let inner = LinearElastic {
            normal_stiffness: kn,
            shear_stiffness: ks,
        };
        inner.validate().py()?;
        voussoir::error::non_negative("normal_stiffness", kn).py()?;
        voussoir::error::non_negative("shear_stiffness", ks).py()?;
        Ok(Self { inner })
    }
    /// Normal stiffness (Pa/m).
    #[getter]
    fn kn(&self) -> f64 {
        self.inner.normal_stiffness
    }
    /// Shear stiffness (Pa/m).
    #[getter]
    fn ks(&self) -> f64 {
        self.inner.shear_stiffness
    }
    fn __repr__(&self) -> String {
        format!("LinearElastic(kn={:e}, ks={:e})", self.kn(), self.ks())
    }
    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other
            .cast::<PyLinearElastic>()
            .is_ok_and(|o| o.get().inner == self.inner)
    }
}

/// A Python law object as the Rust law.
pub fn law_from_py(obj: &Bound<'_, PyAny>) -> PyResult<AnyLaw> {
    if let Ok(c) = obj.cast::<PyCoulombSlip>() {
        return Ok(c.get().inner.into());
    }
    if let Ok(e) = obj.cast::<PyLinearElastic>() {
        return Ok(e.get().inner.into());
    }
    Err(bad(format!(
        "joint law: expected voussoir.CoulombSlip or voussoir.LinearElastic, got {} (laws written in Python are not \
supported; see docs/custom-law.md for a law of your own in Rust)",
        obj.get_type().name()?
    )))
}

/// The Rust law as a Python object.
pub fn law_to_py<'py>(py: Python<'py>, law: &AnyLaw) -> PyResult<Bound<'py, PyAny>> {
    match law {
        AnyLaw::Coulomb(c) => Ok(Bound::new(py, PyCoulombSlip { inner: *c })?.into_any()),
        AnyLaw::Elastic(e) => Ok(Bound::new(py, PyLinearElastic { inner: *e })?.into_any()),
        _ => Err(bad("a law this version of the Python package does not know")),
    }
}
