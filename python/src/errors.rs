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

/// The exception for a Rust error: [`VoussoirIOError`] for [`voussoir::Error::Io`],
/// `MemoryError` for [`voussoir::Error::TooLarge`] (a size beyond the library's limits),
/// [`VoussoirError`] for the others, with the same message.
pub fn to_py(e: voussoir::Error) -> PyErr {
    match e {
        voussoir::Error::Io { .. } => VoussoirIOError::new_err(e.to_string()),
        voussoir::Error::TooLarge { .. } => PyMemoryError::new_err(e.to_string()),
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
