//! Outputs users expect: ParaView series ([`vtk`]), CSV histories and JSON summaries ([`csv`]).

pub mod csv;
pub mod vtk;

use std::path::Path;

use crate::error::Error;

pub(crate) fn io_error(path: &Path, e: &std::io::Error) -> Error {
    Error::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    }
}
