//! The convergence check of the joints' discretisation from Python.

use pyo3::prelude::*;
use pyo3::types::PyDict;
use voussoir::geometry::SubContactDensity;
use voussoir::loading::Convergence;

/// The keyword arguments of ``Model`` that give `density`.
fn density_kwargs<'py>(py: Python<'py>, density: SubContactDensity) -> PyResult<Bound<'py, PyDict>> {
    let kwargs = PyDict::new(py);
    match density {
        SubContactDensity::PerEdge(n) => kwargs.set_item("subcontacts_per_edge", n)?,
        SubContactDensity::Spacing(h) => kwargs.set_item("subcontact_spacing", h)?,
    }
    Ok(kwargs)
}

/// check_density_convergence(run, *, subcontacts_per_edge=15, subcontact_spacing=None)
/// --
///
/// Runs an analysis at a sub-contact density and at the density with the joints' cells halved
/// along each edge (``2 n - 1`` per edge, or half the spacing), and reports how much the
/// quantity it returns (a collapse load, a displacement) changed: the check that an answer does
/// not depend on how finely the joints are divided (Rust:
/// ``SubContactDensity::check_convergence``).
///
/// ``run`` is called with the density as the keyword argument ``Model`` takes
/// (``subcontacts_per_edge=n`` or ``subcontact_spacing=h``), builds and runs the whole
/// analysis, and returns a number. The two runs go one after the other.
///
/// Returns a dict: ``value``, ``refined`` (the two results), ``relative_change``
/// (``|refined - value| / |value|``), ``density`` and ``refined_density`` (the keyword
/// arguments each run was given).
///
/// >>> import voussoir as vs
/// >>> c = vs.check_density_convergence(lambda subcontacts_per_edge: 1.0 + 0.1 / subcontacts_per_edge)
/// >>> c["refined_density"], round(c["relative_change"], 5)
/// ({'subcontacts_per_edge': 29}, 0.0032)
#[pyfunction]
#[pyo3(signature = (run, *, subcontacts_per_edge=15, subcontact_spacing=None))]
pub fn check_density_convergence<'py>(
    py: Python<'py>,
    run: &Bound<'py, PyAny>,
    subcontacts_per_edge: i64,
    subcontact_spacing: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let subcontacts_per_edge =
        crate::convert::whole(subcontacts_per_edge, "subcontacts_per_edge", u64::from(u16::MAX))? as u16;
    if !run.is_callable() {
        return Err(pyo3::exceptions::PyTypeError::new_err(
            "check_density_convergence: run must be callable",
        ));
    }
    let density = match subcontact_spacing {
        Some(h) => SubContactDensity::Spacing(h),
        None => SubContactDensity::PerEdge(subcontacts_per_edge),
    };
    let params = voussoir::geometry::ContactParameters {
        density,
        ..Default::default()
    };
    params.validate().map_err(crate::errors::to_py)?;
    let refined_density = density.refined();
    let call =
        |d: SubContactDensity| -> PyResult<f64> { run.call((), Some(&density_kwargs(py, d)?))?.extract::<f64>() };
    let c = Convergence {
        value: call(density)?,
        refined: call(refined_density)?,
    };
    let out = PyDict::new(py);
    out.set_item("value", c.value)?;
    out.set_item("refined", c.refined)?;
    out.set_item("relative_change", c.relative_change())?;
    out.set_item("density", density_kwargs(py, density)?)?;
    out.set_item("refined_density", density_kwargs(py, refined_density)?)?;
    Ok(out)
}

/// check_servo_convergence(run, *, increment, max_unbalanced_ratio=1e-3)
/// --
///
/// Runs a quasi-static analysis with a servo's increment and threshold and again with both
/// halved, and reports how much the quantity it returns (a peak load) changed: the check that
/// a quasi-static answer does not depend on the loading (Rust: ``Servo::check_convergence``).
///
/// ``run`` is called with the keyword arguments ``increment`` and ``max_unbalanced_ratio`` (as
/// ``Model.push_over`` takes them), builds and runs the whole analysis, and returns a number.
///
/// Returns a dict: ``value``, ``refined``, ``relative_change``, ``servo`` and
/// ``refined_servo`` (the keyword arguments of each run).
///
/// >>> import voussoir as vs
/// >>> c = vs.check_servo_convergence(lambda increment, max_unbalanced_ratio: 1.0 + max_unbalanced_ratio, increment=1e-5)
/// >>> round(c["relative_change"], 6), c["refined_servo"]["increment"]
/// (0.0005, 5e-06)
#[pyfunction]
#[pyo3(signature = (run, *, increment, max_unbalanced_ratio=1e-3))]
pub fn check_servo_convergence<'py>(
    py: Python<'py>,
    run: &Bound<'py, PyAny>,
    increment: f64,
    max_unbalanced_ratio: f64,
) -> PyResult<Bound<'py, PyDict>> {
    if !run.is_callable() {
        return Err(pyo3::exceptions::PyTypeError::new_err(
            "check_servo_convergence: run must be callable",
        ));
    }
    let servo = voussoir::loading::Servo::new(
        voussoir::ids::BlockId(0),
        voussoir::math::Vector::X,
        increment,
        max_unbalanced_ratio,
    )
    .map_err(crate::errors::to_py)?;
    let kwargs = |s: &voussoir::loading::Servo| -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("increment", s.increment)?;
        d.set_item("max_unbalanced_ratio", s.max_unbalanced_ratio)?;
        Ok(d)
    };
    let refined = servo.refined();
    let call = |s: &voussoir::loading::Servo| -> PyResult<f64> { run.call((), Some(&kwargs(s)?))?.extract::<f64>() };
    let c = Convergence {
        value: call(&servo)?,
        refined: call(&refined)?,
    };
    let out = PyDict::new(py);
    out.set_item("value", c.value)?;
    out.set_item("refined", c.refined)?;
    out.set_item("relative_change", c.relative_change())?;
    out.set_item("servo", kwargs(&servo)?)?;
    out.set_item("refined_servo", kwargs(&refined)?)?;
    Ok(out)
}
