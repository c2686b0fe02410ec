//! Writing files so that a failure never leaves a half-written one: the text goes to a
//! temporary file in the same folder, which then replaces the target in one rename. A failed
//! write (a full disk, a killed process) leaves the previous file as it was.

use std::io::Write;
use std::path::Path;

use crate::error::{io_error, Result};

/// Writes `bytes` to `path`, creating its folder: into a temporary file beside it, synced, then
/// renamed over `path`.
///
/// # Errors
/// [`crate::Error::Io`] naming the folder, the temporary file or the target.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<()> {
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty());
    if let Some(dir) = dir {
        std::fs::create_dir_all(dir).map_err(|e| io_error(dir, &e))?;
    }
    let name = path
        .file_name()
        .map_or_else(|| "file".into(), |n| n.to_string_lossy().into_owned());
    let temporary = path.with_file_name(format!(".{name}.{}.tmp", std::process::id()));
    let written = (|| {
        let mut f = std::fs::File::create(&temporary)?;
        f.write_all(bytes)?;
        f.sync_all()
    })();
    if let Err(e) = written {
        let _ = std::fs::remove_file(&temporary);
        return Err(io_error(&temporary, &e));
    }
    std::fs::rename(&temporary, path).map_err(|e| {
        let _ = std::fs::remove_file(&temporary);
        io_error(path, &e)
    })
}
