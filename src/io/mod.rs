//! Outputs users expect: ParaView series ([`vtk`]), a self-contained HTML viewer of a run
//! ([`viewer`]), CSV histories ([`csv`]) and scene files ([`scene`]). Checkpoints are methods of [`crate::Model`] (`save_checkpoint`,
//! `load_checkpoint`).
//!
//! Needs the `io` feature (on by default), which turns on `serde`.

pub mod csv;
pub mod scene;
pub mod viewer;
pub mod vtk;

use std::path::Path;

use crate::error::Error;
/// Writes bytes so that a failure never leaves a half-written file (see the function).
pub use crate::file::{read_text, write_atomically, MAX_TEXT_BYTES};
pub use crate::json_keys::refuse_duplicate_keys;

/// Writes any serialisable value as pretty JSON (for example an example's `summary.json`),
/// creating the folder. Non-finite numbers become `null`.
///
/// # Errors
/// [`Error::Io`] naming the file.
pub fn write_json(path: &Path, value: &impl serde::Serialize) -> crate::Result<()> {
    let text = serde_json::to_string_pretty(value).map_err(|e| Error::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    })?;
    crate::file::write_atomically(path, text.as_bytes())
}
