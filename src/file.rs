//! Writing files so that a failure never leaves a half-written one: the text goes to a
//! temporary file in the same folder, which then replaces the target in one rename. A failed
//! write (a full disk, a killed process) leaves the previous file as it was.
//!
//! The temporary file's name is unique per call (the process id and a process-wide counter) and
//! the file is created only if it does not exist (`O_EXCL`), so that two threads or two
//! processes saving to one path never write into one temporary file: each save that returns `Ok`
//! renamed a whole file of its own (the last rename wins). The temporary name stays within 255
//! bytes whatever the target's name (a long name is cut and a hash of it added). A target that
//! is a symbolic link is written through: the link's (final) target is replaced, the link kept.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::{io_error, Result};

/// The longest file name most file systems take (ext4, APFS, NTFS: 255 bytes or units).
const MAX_NAME_BYTES: usize = 255;
/// Symbolic links followed before giving up (as Linux's `MAXSYMLINKS`).
const MAX_LINKS: usize = 40;
/// Counts the temporary files made by this process.
static TEMPORARIES: AtomicU64 = AtomicU64::new(0);

/// Writes `bytes` to `path`, creating its folder: into a temporary file beside it, synced, then
/// renamed over `path`. A `path` that is a symbolic link is followed: its target is replaced and
/// the link stays. A target that exists and is not a regular file (a folder, a device such as
/// `/dev/null`, a pipe) is refused, never replaced.
///
/// # Errors
/// [`crate::Error::Io`] naming the folder, the temporary file or the target (also for a cycle of
/// symbolic links).
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<()> {
    let path = &resolve_links(path)?;
    // Renaming over a device, a pipe or a folder would replace it (as root, `/dev/full` by a
    // regular file): only regular files are replaced.
    if let Ok(m) = std::fs::metadata(path) {
        if !m.is_file() {
            return Err(crate::Error::Io {
                path: path.display().to_string(),
                message: "not a regular file (a folder, a device or a pipe): not replaced".into(),
            });
        }
    }
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty());
    if let Some(dir) = dir {
        std::fs::create_dir_all(dir).map_err(|e| io_error(dir, &e))?;
    }
    let (temporary, mut file) = create_temporary(path)?;
    let written = (|| {
        file.write_all(bytes)?;
        file.sync_all()
    })();
    drop(file);
    if let Err(e) = written {
        let _ = std::fs::remove_file(&temporary);
        return Err(io_error(&temporary, &e));
    }
    std::fs::rename(&temporary, path).map_err(|e| {
        let _ = std::fs::remove_file(&temporary);
        io_error(path, &e)
    })
}

/// `path` with its symbolic links (as the last component) followed to the file they name; the
/// path itself when it is not a link or does not exist.
fn resolve_links(path: &Path) -> Result<PathBuf> {
    let mut current = path.to_path_buf();
    for _ in 0..MAX_LINKS {
        match std::fs::symlink_metadata(&current) {
            Ok(m) if m.file_type().is_symlink() => {
                let target = std::fs::read_link(&current).map_err(|e| io_error(&current, &e))?;
                current = match current.parent() {
                    Some(dir) if target.is_relative() => dir.join(target),
                    _ => target,
                };
            }
            _ => return Ok(current),
        }
    }
    Err(crate::Error::Io {
        path: path.display().to_string(),
        message: format!("more than {MAX_LINKS} symbolic links to follow (a cycle?)"),
    })
}

/// The temporary file's name for `name` and a call number: `.{name}.{pid}.{n}.tmp`, with `name`
/// cut (at a character boundary) and followed by a hash of the whole name when the result would
/// pass 255 bytes.
fn temporary_name(name: &str, n: u64) -> String {
    let suffix = format!(".{}.{n}.tmp", std::process::id());
    if 1 + name.len() + suffix.len() <= MAX_NAME_BYTES {
        return format!(".{name}{suffix}");
    }
    let hash = format!("~{:016x}", fnv1a(name.as_bytes()));
    let mut keep = MAX_NAME_BYTES - 1 - suffix.len() - hash.len();
    while !name.is_char_boundary(keep) {
        keep -= 1;
    }
    format!(".{}{hash}{suffix}", &name[..keep])
}

/// The 64-bit FNV-1a hash of `bytes` (a short stand-in for a long name).
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// The largest text file voussoir reads (checkpoints, scenes, time histories): 4 GiB. A
/// checkpoint of the 100,000-block wall is about 0.5 GB.
pub const MAX_TEXT_BYTES: u64 = 4 << 30;

/// Reads a UTF-8 text file of at most [`MAX_TEXT_BYTES`], refusing at the first NUL byte (no
/// text format voussoir reads holds one: a UTF-16 file is refused at once). Only regular files
/// are read: a folder, a device such as `/dev/zero`, a named pipe or a socket is refused before
/// any read (a pipe would block for ever, a device read without end).
///
/// # Errors
/// [`crate::Error::Io`] naming the file: unreadable, not a regular file (saying what it is),
/// larger than the limit, holding a NUL byte (saying where), or not UTF-8.
pub fn read_text(path: &Path) -> Result<String> {
    use std::io::Read;
    let fail = |message: String| crate::Error::Io {
        path: path.display().to_string(),
        message,
    };
    let mut file = open_regular(path)?;
    let mut bytes = Vec::new();
    let mut chunk = vec![0u8; 1 << 16];
    loop {
        let n = match file.read(&mut chunk) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(io_error(path, &e)),
        };
        if let Some(k) = chunk[..n].iter().position(|&b| b == 0) {
            let utf16 = if bytes.is_empty() && (chunk.starts_with(&[0xFF, 0xFE]) || chunk.starts_with(&[0xFE, 0xFF])) {
                " (a UTF-16 file: save it as UTF-8)"
            } else {
                ""
            };
            return Err(fail(format!(
                "a NUL byte at byte {}: not a text file{utf16}",
                bytes.len() + k
            )));
        }
        if (bytes.len() + n) as u64 > MAX_TEXT_BYTES {
            return Err(fail(format!(
                "larger than {MAX_TEXT_BYTES} bytes, the most voussoir reads"
            )));
        }
        bytes.extend_from_slice(&chunk[..n]);
    }
    String::from_utf8(bytes).map_err(|e| {
        fail(format!(
            "not UTF-8 text (an invalid byte at byte {})",
            e.utf8_error().valid_up_to()
        ))
    })
}

/// Opens `path` for reading if it is a regular file (after following links); a folder, a device
/// (`/dev/zero`, `/dev/stdin`), a named pipe or a socket is refused at once. On Unix the file is
/// opened without blocking (`O_NONBLOCK`: opening a named pipe waits for a writer otherwise, for
/// ever and deaf to Ctrl-C) and its type read from the open file, so that nothing can swap it
/// between the look and the read; reads of a regular file never block, the flag changes nothing
/// for them.
fn open_regular(path: &Path) -> Result<std::fs::File> {
    #[cfg(unix)]
    let file = {
        use std::os::unix::fs::OpenOptionsExt;
        std::fs::OpenOptions::new()
            .read(true)
            .custom_flags(libc::O_NONBLOCK)
            .open(path)
            .map_err(|e| refused_or(path, &e))?
    };
    #[cfg(not(unix))]
    let file = std::fs::File::open(path).map_err(|e| refused_or(path, &e))?;
    let kind = file.metadata().map_err(|e| io_error(path, &e))?.file_type();
    if kind.is_file() {
        return Ok(file);
    }
    Err(refused(path, kind))
}

/// The error for a file that is not a regular one.
fn refused(path: &Path, kind: std::fs::FileType) -> crate::Error {
    crate::Error::Io {
        path: path.display().to_string(),
        message: format!("{}: only a regular file is read", not_regular(kind)),
    }
}

/// The error for a file that did not open: [`refused`] if it exists and is not a regular file
/// (a socket does not open at all), the system's error otherwise.
fn refused_or(path: &Path, e: &std::io::Error) -> crate::Error {
    match std::fs::metadata(path) {
        Ok(m) if !m.is_file() => refused(path, m.file_type()),
        _ => io_error(path, e),
    }
}

/// What a file that is not a regular one is, for messages.
fn not_regular(kind: std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_fifo() {
            return "a named pipe";
        }
        if kind.is_socket() {
            return "a socket";
        }
        if kind.is_char_device() || kind.is_block_device() {
            return "a device";
        }
    }
    if kind.is_dir() {
        "a folder"
    } else {
        "not a regular file"
    }
}

/// Creates a new temporary file beside `path` (never opening one that exists).
fn create_temporary(path: &Path) -> Result<(PathBuf, std::fs::File)> {
    let name = path
        .file_name()
        .map_or_else(|| "file".into(), |n| n.to_string_lossy().into_owned());
    let mut last = None;
    for _ in 0..16 {
        let n = TEMPORARIES.fetch_add(1, Ordering::Relaxed);
        let temporary = path.with_file_name(temporary_name(&name, n));
        match std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&temporary)
        {
            Ok(f) => return Ok((temporary, f)),
            // A file of another process that had our id and count: take the next count.
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => last = Some((temporary, e)),
            Err(e) => return Err(io_error(&temporary, &e)),
        }
    }
    let (temporary, e) = last.expect("the loop ran");
    Err(io_error(&temporary, &e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn temporary_names_stay_within_255_bytes() {
        for len in [1, 200, 230, 240, 245, 250, 255] {
            let name = "a".repeat(len);
            let t = temporary_name(&name, u64::MAX);
            assert!(t.len() <= MAX_NAME_BYTES, "{len}: {} bytes", t.len());
            assert!(t.starts_with('.') && t.ends_with(".tmp"));
        }
        let wide = "é".repeat(127); // 254 bytes, cut at a character boundary
        assert!(temporary_name(&wide, 7).len() <= MAX_NAME_BYTES);
        assert_ne!(temporary_name("x", 1), temporary_name("x", 2));
        assert_ne!(
            temporary_name(&"a".repeat(250), 1),
            temporary_name(&format!("{}b", "a".repeat(249)), 1)
        );
    }
}
