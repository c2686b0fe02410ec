//! Outputs users expect: ParaView series ([`vtk`]), CSV histories ([`csv`]), SVG plots ([`plot`])
//! progress bars ([`progress`]) and scene files ([`scene`]). Checkpoints are methods of
//! [`crate::Model`] (`save_checkpoint`, `load_checkpoint`).

pub mod csv;
pub mod plot;
pub mod progress;
pub mod scene;
pub mod vtk;

use std::path::Path;

use crate::error::Error;

pub(crate) fn io_error(path: &Path, e: &std::io::Error) -> Error {
    Error::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    }
}
