//! The Python package `voussoir` (PyO3): its native module `voussoir._voussoir`, which the
//! package's `__init__.py` re-exports. See `python/README.md`.

// The summaries' `serde_json::json!` literals are deep.
#![recursion_limit = "256"]

mod blocks;
mod convergence;
mod convert;
mod documents;
mod errors;
mod laws;
mod limit;
mod mechanism;
mod model;
mod motion;
mod scenarios;
mod series;
mod viewer;

use pyo3::prelude::*;

/// The native module.
#[pymodule]
fn _voussoir(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    // NumPy's C API, taken now: taken first where a result is returned after a long run, its
    // import would meet a pending Ctrl-C and rust-numpy would panic ("Failed to access NumPy
    // array API capsule") instead of raising KeyboardInterrupt.
    numpy::PyArray1::<f64>::zeros(py, 0, false);
    m.add("VoussoirError", py.get_type::<errors::VoussoirError>())?;
    m.add("VoussoirIOError", py.get_type::<errors::VoussoirIOError>())?;
    m.add("LimitInfeasibleError", py.get_type::<errors::LimitInfeasibleError>())?;
    m.add("LimitUnboundedError", py.get_type::<errors::LimitUnboundedError>())?;
    m.add("LimitSolverError", py.get_type::<errors::LimitSolverError>())?;
    m.add_class::<laws::PyCoulombSlip>()?;
    m.add_class::<laws::PyLinearElastic>()?;
    m.add_class::<laws::PyMortarJoint>()?;
    m.add_class::<blocks::PyBlock>()?;
    m.add_class::<model::PyModel>()?;
    m.add_class::<series::PySeries>()?;
    m.add_class::<viewer::PyViewer>()?;
    m.add_class::<motion::PyTimeHistory>()?;
    m.add_function(wrap_pyfunction!(blocks::arch, m)?)?;
    m.add_function(wrap_pyfunction!(blocks::running_bond_wall, m)?)?;
    m.add_function(wrap_pyfunction!(blocks::multi_leaf_wall, m)?)?;
    m.add_function(wrap_pyfunction!(blocks::rubble_wall, m)?)?;
    m.add_function(wrap_pyfunction!(blocks::barrel_vault, m)?)?;
    m.add_function(wrap_pyfunction!(blocks::dome, m)?)?;
    m.add_function(wrap_pyfunction!(series::benchmark_wall, m)?)?;
    m.add_function(wrap_pyfunction!(convergence::check_density_convergence, m)?)?;
    m.add_function(wrap_pyfunction!(convergence::check_servo_convergence, m)?)?;
    m.add_function(wrap_pyfunction!(limit::limit, m)?)?;
    m.add_function(wrap_pyfunction!(mechanism::classify_joints, m)?)?;
    m.add_function(wrap_pyfunction!(mechanism::arch_joints, m)?)?;
    m.add_function(wrap_pyfunction!(scenarios::arch_static, m)?)?;
    m.add_function(wrap_pyfunction!(scenarios::arch_impact, m)?)?;
    m.add_function(wrap_pyfunction!(scenarios::impact_setups, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
