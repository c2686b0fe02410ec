//! The argument checks that every example's command line shares: value parsers for clap (finite
//! numbers in a range, whole numbers from a least value), a check for repeated values, and the
//! output folder, created and probed before any computing starts.
//!
//! One file for both crates: the core crate's examples include it with
//! `#[path = "common/args.rs"] mod args;`, and `voussoir-arch` (which is not published) makes it
//! its public module `voussoir_arch::cli::args`. It needs only `std` and `voussoir`, so that it
//! can be compiled into either; clap takes the parsers as plain functions
//! (`#[arg(value_parser = args::real(..))]`), and names the flag in front of their message:
//!
//! ```text
//! error: invalid value '100' for '--damping <RATIO>': 100 is out of range: must lie in [0, 0.2]
//! ```

// Each example uses only some of the checks.
#![allow(dead_code)]

use std::fmt::Display;
use std::ops::Bound;
use std::path::Path;
use std::str::FromStr;

/// A number that must be finite (spaces around it allowed).
///
/// # Errors
/// A message for clap when it is not a number or not finite.
pub fn finite(s: &str) -> Result<f64, String> {
    let x: f64 = s.trim().parse().map_err(|_| format!("not a number: {s:?}"))?;
    if x.is_finite() {
        Ok(x)
    } else {
        Err(format!("{s:?} is not finite: must be a finite number"))
    }
}

/// An interval of real numbers, each end open, closed or absent.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Interval {
    /// Lower end.
    pub lo: Bound<f64>,
    /// Upper end.
    pub hi: Bound<f64>,
}

impl Interval {
    /// A clap value parser for a finite number in the interval.
    pub fn parser(self) -> impl Fn(&str) -> Result<f64, String> + Clone + Send + Sync + 'static {
        move |s| check_real(s, self)
    }

    /// Whether `x` lies in the interval (never for NaN).
    pub fn contains(&self, x: f64) -> bool {
        let above = match self.lo {
            Bound::Included(a) => x >= a,
            Bound::Excluded(a) => x > a,
            Bound::Unbounded => x > f64::NEG_INFINITY,
        };
        let below = match self.hi {
            Bound::Included(b) => x <= b,
            Bound::Excluded(b) => x < b,
            Bound::Unbounded => x < f64::INFINITY,
        };
        above && below
    }
}

impl Display for Interval {
    /// In the usual notation: `[0, 0.2]`, `(0, 90)`, `[1e7, 1e12]`, `(0, ∞)`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.lo {
            Bound::Included(a) => write!(f, "[{}, ", Number(a))?,
            Bound::Excluded(a) => write!(f, "({}, ", Number(a))?,
            Bound::Unbounded => write!(f, "(−∞, ")?,
        }
        match self.hi {
            Bound::Included(b) => write!(f, "{}]", Number(b)),
            Bound::Excluded(b) => write!(f, "{})", Number(b)),
            Bound::Unbounded => write!(f, "∞)"),
        }
    }
}

/// A number as a reader writes it: `0.2`, `1e12`, `1e-6`.
struct Number(f64);

impl Display for Number {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let a = self.0.abs();
        if a >= 1e5 || (a != 0.0 && a < 1e-3) {
            write!(f, "{:e}", self.0)
        } else {
            write!(f, "{}", self.0)
        }
    }
}

/// A finite number in `lo`..`hi` (each end [`Bound::Included`], [`Bound::Excluded`] or
/// [`Bound::Unbounded`]), as a clap value parser: `real(Excluded(0.0), Included(10.0))` takes
/// `(0, 10]`.
pub fn real(lo: Bound<f64>, hi: Bound<f64>) -> impl Fn(&str) -> Result<f64, String> + Clone + Send + Sync + 'static {
    Interval { lo, hi }.parser()
}

/// A finite number greater than zero, as a clap value parser.
pub fn positive(s: &str) -> Result<f64, String> {
    check_real(
        s,
        Interval {
            lo: Bound::Excluded(0.0),
            hi: Bound::Unbounded,
        },
    )
}

/// Parses `s` as a finite number in `range`.
///
/// # Errors
/// A message naming the value and the range.
pub fn check_real(s: &str, range: Interval) -> Result<f64, String> {
    let x = finite(s).map_err(|e| format!("{e} in {range}"))?;
    if range.contains(x) {
        Ok(x)
    } else {
        Err(format!("{} is out of range: must lie in {range}", s.trim()))
    }
}

/// A whole number at least `min`, as a clap value parser: `whole::<u64>(1)`.
pub fn whole<T>(min: T) -> impl Fn(&str) -> Result<T, String> + Clone + Send + Sync + 'static
where
    T: FromStr + PartialOrd + Display + Copy + Send + Sync + 'static,
{
    move |s| {
        let n: T = s
            .trim()
            .parse()
            .map_err(|_| format!("not a whole number: {s:?} (must be ≥ {min})"))?;
        if n >= min {
            Ok(n)
        } else {
            Err(format!("{n} is out of range: must be ≥ {min}"))
        }
    }
}

/// Refuses a list in which a value comes twice, naming `flag` and the value.
///
/// # Errors
/// `--flag: "x" is given twice`.
pub fn unique<T: PartialEq + std::fmt::Debug>(flag: &str, values: &[T]) -> Result<(), String> {
    for (k, v) in values.iter().enumerate() {
        if values[..k].contains(v) {
            return Err(format!(
                "{flag}: {v:?} is given twice (each would write the same outputs): give it once"
            ));
        }
    }
    Ok(())
}

/// Makes the output folder `dir` ready before a run computes anything: creates it (and the
/// sub-folders `folders`), writes and removes a probe file in it, and checks that none of the
/// planned output `files` (relative to `dir`) is a folder. A run that would fail only at its end,
/// with its results lost, fails here instead.
///
/// # Errors
/// [`voussoir::Error::Io`] naming the path at fault: a file in place of the folder or of a
/// sub-folder, a folder in place of an output file, a folder that cannot be written.
pub fn prepare_output_dir(dir: &Path, folders: &[&str], files: &[String]) -> voussoir::Result<()> {
    create_folder(dir)?;
    let probe = dir.join(format!(".probe.{}", std::process::id()));
    std::fs::write(&probe, b"probe")
        .and_then(|()| std::fs::remove_file(&probe))
        .map_err(|e| io_error(dir, format!("cannot write in the output folder ({e})")))?;
    for folder in folders {
        create_folder(&dir.join(folder))?;
    }
    for file in files {
        let path = dir.join(file);
        if path.is_dir() {
            return Err(io_error(
                &path,
                "is a folder, in place of an output file: move it or choose another --out".into(),
            ));
        }
    }
    Ok(())
}

fn create_folder(dir: &Path) -> voussoir::Result<()> {
    if dir.exists() && !dir.is_dir() {
        return Err(io_error(
            dir,
            "is a file, in place of an output folder: move it or choose another --out".into(),
        ));
    }
    std::fs::create_dir_all(dir).map_err(|e| io_error(dir, format!("cannot create the output folder ({e})")))
}

/// Writes `text` to `path`, creating its folder, atomically (a temporary file beside it renamed
/// over it: a failure never leaves a half-written file).
///
/// # Errors
/// [`voussoir::Error::Io`] naming the file (or its folder).
pub fn write_text(path: &Path, text: &str) -> voussoir::Result<()> {
    voussoir::io::write_atomically(path, text.as_bytes())
}

fn io_error(path: &Path, message: String) -> voussoir::Error {
    voussoir::Error::Io {
        path: path.display().to_string(),
        message,
    }
}
