//! Rust errors as Python exceptions, with the Rust messages.

use pyo3::create_exception;
use pyo3::exceptions::{PyMemoryError, PyOSError, PyValueError};
use pyo3::PyErr;

create_exception!(
    voussoir,
    VoussoirError,
    PyValueError,
    "A voussoir error: bad input (the message names the parameter, block or material and the value), \
a run that diverged or did not converge, a corrupt scene or checkpoint. A subclass of ValueError."
);
create_exception!(
    voussoir,
    VoussoirIOError,
    PyOSError,
    "Reading or writing a file failed (the message names the file). A subclass of OSError."
);
create_exception!(
    voussoir,
    LimitInfeasibleError,
    VoussoirError,
    "Limit analysis with a live load: the dead loads (gravity and the blocks' constant loads) are \
not carried, with or without the live load, or only with its help (``check_dead_load``): the \
structure cannot carry its own weight. The dead-load question alone (``carries_dead_load``, or \
``limit`` with no live load) answers False instead of raising. A subclass of VoussoirError."
);
create_exception!(
    voussoir,
    LimitUnboundedError,
    VoussoirError,
    "Limit analysis: the live load's multiplier has no upper bound (the live load acts on supports' \
constrained degrees of freedom, goes straight into them, or wedges blocks that friction locks). \
A subclass of VoussoirError."
);
create_exception!(
    voussoir,
    LimitSolverError,
    VoussoirError,
    "Limit analysis: the conic solver stopped without an answer or a certificate (e.g. at \
``max_iterations``; the message gives its status). A subclass of VoussoirError."
);

/// The exception for a Rust error: [`VoussoirIOError`] for [`voussoir::Error::Io`],
/// `MemoryError` for [`voussoir::Error::TooLarge`] (a size beyond the library's limits),
/// [`LimitInfeasibleError`], [`LimitUnboundedError`] and [`LimitSolverError`] for
/// [`voussoir::Error::LimitInfeasible`], [`LimitUnbounded`](voussoir::Error::LimitUnbounded)
/// and [`LimitSolver`](voussoir::Error::LimitSolver) (subclasses of [`VoussoirError`]),
/// [`VoussoirError`] for the others, with the same message.
pub fn to_py(e: voussoir::Error) -> PyErr {
    match e {
        voussoir::Error::Io { .. } => VoussoirIOError::new_err(e.to_string()),
        voussoir::Error::TooLarge { .. } => PyMemoryError::new_err(e.to_string()),
        voussoir::Error::LimitInfeasible { .. } => LimitInfeasibleError::new_err(e.to_string()),
        voussoir::Error::LimitUnbounded { .. } => LimitUnboundedError::new_err(e.to_string()),
        voussoir::Error::LimitSolver { .. } => LimitSolverError::new_err(e.to_string()),
        _ => VoussoirError::new_err(e.to_string()),
    }
}

/// `?` on a voussoir result in a function returning `PyResult`.
pub trait OrPy<T> {
    /// The result with the error as a Python exception.
    fn py(self) -> pyo3::PyResult<T>;
}

impl<T> OrPy<T> for voussoir::Result<T> {
    fn py(self) -> pyo3::PyResult<T> {
        self.map_err(to_py)
    }
}

/// A [`VoussoirError`] with a message of ours (bad arguments the Rust API does not see).
pub fn bad(message: impl Into<String>) -> PyErr {
    VoussoirError::new_err(message.into())
}
