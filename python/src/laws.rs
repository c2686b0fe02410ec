//! The shipped joint laws.

use pyo3::prelude::*;
use voussoir::law::{AnyLaw, CompressionCap, ConstitutiveLaw, CoulombSlip, LinearElastic, MortarJoint, Softening};

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

/// A mortared joint that cracks in tension and shear and softens by its fracture energies
/// (Lourenço–Rots' composite interface, per unit area: a crack dissipates its fracture energy
/// whatever the number of sub-contacts).
///
/// ``MortarJoint(kn, ks, friction_deg, residual_friction_deg=None, tensile_strength=0.0,
/// mode_i_fracture_energy=None, cohesion=0.0, mode_ii_fracture_energy=None, dilatancy_deg=0.0,
/// softening="exponential", cap_strength=None, cap_fracture_energy=None, cap_shear_factor=9.0,
/// cap_peak_closure=0.0)``: stiffnesses in Pa/m, angles in degrees
/// ([0, 90)), strengths in Pa, fracture energies in J/m² (N/m). The tensile strength softens
/// with the crack's opening on ``mode_i_fracture_energy`` and the cohesion with its slip on
/// ``mode_ii_fracture_energy`` (each required with its strength; 0 is brittle, as
/// ``CoulombSlip``); the friction goes from ``friction_deg`` to ``residual_friction_deg`` as the
/// cohesion goes; opening erodes the cohesion and slip the tensile strength alike.
/// ``softening`` is ``"exponential"`` or ``"linear"``. ``dilatancy_deg`` (needs a cohesion and
/// a mode-II fracture energy) opens a slipping joint, decaying as it softens.
/// ``cap_strength`` (Pa) gives the joint a compression cap on which it crushes (Lourenço–Rots'
/// ellipse ``σ² + C_ss τ² ≤ σ_c²``): ``cap_fracture_energy`` (J/m², required with it) is the
/// energy a unit area dissipates past the cap's peak over its residual ``f_m/7``,
/// ``cap_shear_factor`` is ``C_ss`` (Lourenço's 9 by default), ``cap_peak_closure`` (m) the
/// plastic closure at the peak (0: the cap starts at ``f_m``, else at ``f_m/3`` and hardens).
/// Without a cap the law does not crush (``Model.contacts()`` gives each sub-contact's stress);
/// with one the step is slower. The fracture energy consumed,
/// crushing included, is ``Model.energies()["fracture"]``; see ``docs/theory.md`` §4.2.
#[pyclass(name = "MortarJoint", module = "voussoir", frozen)]
#[derive(Clone)]
pub struct PyMortarJoint {
    pub inner: MortarJoint,
}

/// The fracture energy `name` given with a strength: required unless the strength is zero.
fn fracture_energy(name: &str, strength: f64, energy: Option<f64>) -> PyResult<f64> {
    match energy {
        Some(g) => Ok(g),
        None if strength == 0.0 => Ok(0.0),
        None => Err(voussoir::Error::InvalidParameter {
            name: name.into(),
            value: f64::NAN,
            expected: "must be given with its strength (0 for a brittle joint)",
        })
        .py(),
    }
}

#[pymethods]
impl PyMortarJoint {
    #[new]
    #[pyo3(signature = (
        kn,
        ks,
        friction_deg,
        residual_friction_deg=None,
        tensile_strength=0.0,
        mode_i_fracture_energy=None,
        cohesion=0.0,
        mode_ii_fracture_energy=None,
        dilatancy_deg=0.0,
        softening="exponential",
        cap_strength=None,
        cap_fracture_energy=None,
        cap_shear_factor=voussoir::law::LOURENCO_SHEAR_FACTOR,
        cap_peak_closure=0.0,
    ))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        kn: f64,
        ks: f64,
        friction_deg: f64,
        residual_friction_deg: Option<f64>,
        tensile_strength: f64,
        mode_i_fracture_energy: Option<f64>,
        cohesion: f64,
        mode_ii_fracture_energy: Option<f64>,
        dilatancy_deg: f64,
        softening: &str,
        cap_strength: Option<f64>,
        cap_fracture_energy: Option<f64>,
        cap_shear_factor: f64,
        cap_peak_closure: f64,
    ) -> PyResult<Self> {
        let g_i = fracture_energy("mode_i_fracture_energy", tensile_strength, mode_i_fracture_energy)?;
        let g_ii = fracture_energy("mode_ii_fracture_energy", cohesion, mode_ii_fracture_energy)?;
        let shape = match softening {
            "exponential" => Softening::Exponential,
            "linear" => Softening::Linear,
            other => {
                return Err(bad(format!(
                    "softening: expected \"exponential\" or \"linear\", got {other:?}"
                )))
            }
        };
        let mut builder = MortarJoint::builder(kn, ks, friction_deg)
            .residual_friction(residual_friction_deg.unwrap_or(friction_deg))
            .tension(tensile_strength, g_i)
            .cohesion(cohesion, g_ii)
            .dilatancy(dilatancy_deg)
            .softening(shape);
        if let Some(f_m) = cap_strength {
            let g_c = cap_fracture_energy.ok_or_else(|| {
                bad("cap_fracture_energy: must be given with cap_strength (0 for a brittle cap)".to_owned())
            })?;
            builder = builder.compression_cap(
                CompressionCap::new(f_m, g_c)
                    .with_shear_factor(cap_shear_factor)
                    .with_peak_closure(cap_peak_closure),
            );
        } else if cap_fracture_energy.is_some() {
            return Err(bad("cap_fracture_energy: given without cap_strength".to_owned()));
        }
        Ok(Self {
            inner: builder.build().py()?,
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
    /// Initial friction angle (degrees).
    #[getter]
    fn friction_deg(&self) -> f64 {
        mortar_field(&self.inner, "friction_deg")
    }
    /// Residual friction angle (degrees).
    #[getter]
    fn residual_friction_deg(&self) -> f64 {
        mortar_field(&self.inner, "residual_friction_deg")
    }
    /// Dilatancy angle (degrees).
    #[getter]
    fn dilatancy_deg(&self) -> f64 {
        mortar_field(&self.inner, "dilatancy_deg")
    }
    /// Tensile strength (Pa).
    #[getter]
    fn tensile_strength(&self) -> f64 {
        self.inner.tensile_strength()
    }
    /// Mode-I fracture energy (J/m²).
    #[getter]
    fn mode_i_fracture_energy(&self) -> f64 {
        self.inner.mode_i_fracture_energy()
    }
    /// Cohesion (Pa).
    #[getter]
    fn cohesion(&self) -> f64 {
        self.inner.cohesion()
    }
    /// Mode-II fracture energy (J/m²).
    #[getter]
    fn mode_ii_fracture_energy(&self) -> f64 {
        self.inner.mode_ii_fracture_energy()
    }
    /// ``"exponential"`` or ``"linear"``.
    #[getter]
    fn softening(&self) -> &'static str {
        match self.inner.softening() {
            Softening::Exponential => "exponential",
            Softening::Linear => "linear",
        }
    }
    /// The compression cap's strength ``f_m`` (Pa), or None without a cap.
    #[getter]
    fn cap_strength(&self) -> Option<f64> {
        self.inner.compression_cap().map(|c| c.strength)
    }
    /// The compression cap's fracture energy ``G_c`` (J/m²), or None without a cap.
    #[getter]
    fn cap_fracture_energy(&self) -> Option<f64> {
        self.inner.compression_cap().map(|c| c.fracture_energy)
    }
    /// The compression cap's shear factor ``C_ss``, or None without a cap.
    #[getter]
    fn cap_shear_factor(&self) -> Option<f64> {
        self.inner.compression_cap().map(|c| c.shear_factor)
    }
    /// The compression cap's plastic closure at its peak ``κ_p`` (m), or None without a cap.
    #[getter]
    fn cap_peak_closure(&self) -> Option<f64> {
        self.inner.compression_cap().map(|c| c.peak_closure)
    }

    fn __repr__(&self) -> String {
        let mut f_m = String::new();
        if let Some(c) = self.inner.compression_cap() {
            f_m += &format!(
                ", cap_strength={}, cap_fracture_energy={}, cap_shear_factor={}, cap_peak_closure={}",
                c.strength, c.fracture_energy, c.shear_factor, c.peak_closure
            );
        }
        format!(
            "MortarJoint(kn={:e}, ks={:e}, friction_deg={}, residual_friction_deg={}, tensile_strength={}, \
             mode_i_fracture_energy={}, cohesion={}, mode_ii_fracture_energy={}, dilatancy_deg={}, softening={:?}{f_m})",
            self.kn(),
            self.ks(),
            self.friction_deg(),
            self.residual_friction_deg(),
            self.tensile_strength(),
            self.mode_i_fracture_energy(),
            self.cohesion(),
            self.mode_ii_fracture_energy(),
            self.dilatancy_deg(),
            self.softening(),
        )
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other.cast::<PyMortarJoint>().is_ok_and(|o| o.get().inner == self.inner)
    }
}

/// A field of a mortar joint as it was given (angles in degrees), read from its serialised
/// form.
fn mortar_field(law: &MortarJoint, field: &str) -> f64 {
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
    if let Ok(m) = obj.cast::<PyMortarJoint>() {
        return Ok(m.get().inner.into());
    }
    Err(bad(format!(
        "joint law: expected voussoir.CoulombSlip, voussoir.MortarJoint or voussoir.LinearElastic, got {} (laws written \
in Python are not supported; see docs/custom-law.md for a law of your own in Rust)",
        obj.get_type().name()?
    )))
}

/// The Rust law as a Python object.
pub fn law_to_py<'py>(py: Python<'py>, law: &AnyLaw) -> PyResult<Bound<'py, PyAny>> {
    match law {
        AnyLaw::Coulomb(c) => Ok(Bound::new(py, PyCoulombSlip { inner: *c })?.into_any()),
        AnyLaw::Elastic(e) => Ok(Bound::new(py, PyLinearElastic { inner: *e })?.into_any()),
        AnyLaw::Mortar(m) => Ok(Bound::new(py, PyMortarJoint { inner: *m })?.into_any()),
        _ => Err(bad("a law this version of the Python package does not know")),
    }
}
