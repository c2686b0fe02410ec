//! One command line for the arch runs ([`arch_static`], [`arch_impact`]): the options every run
//! takes ([`CommonOptions`]), flattened beside the run's own, and the parts every run shares:
//! `main` and its error report, the progress bar over the parallel cases, the ParaView series,
//! the output folder and its files.
//!
//! Nothing is computed before the command line is whole: every number is checked against its
//! range when parsed (`--help` gives each range and why), an unknown argument or a value given
//! twice where it would write the same outputs twice is refused, and the output folder is created
//! and probed, with every planned output file checked not to be a folder ([`Outputs::prepare`]).
//! The checks are [`args`], shared with the core crate's examples.
//!
//! An entry point's `main` is one line, as in `arch/examples/arch_impact.rs`:
//!
//! ```no_run
//! voussoir_arch::cli::main::<voussoir_arch::cli::arch_impact::ImpactOptions>();
//! ```

pub mod arch_impact;
pub mod arch_limit;
pub mod arch_static;
#[path = "../../../examples/common/args.rs"]
pub mod args;

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::{Args, CommandFactory, FromArgMatches, Parser};
use rayon::prelude::*;
use serde::Serialize;
use voussoir::io::viewer::Viewer;
use voussoir::io::{vtk, write_json};
use voussoir::Model;

use crate::plot::LinePlot;
use crate::progress;

/// The error type of a run.
pub type BoxError = Box<dyn std::error::Error>;

/// Options every run takes.
#[derive(Debug, Clone, Args)]
pub struct CommonOptions {
    /// Folder for the outputs; each run has its default, [`Run::OUT`].
    #[arg(long, value_name = "DIR", help = "Folder for the outputs")]
    pub out: PathBuf,
    /// Do not write the ParaView series
    #[arg(long)]
    pub no_paraview: bool,
}

/// A run of the command line: its options (flattened beside [`CommonOptions`]) and what it does.
///
/// Before [`Run::run`] computes anything, [`parse`] has checked every value's range and
/// [`Run::check`], and `main` has prepared the output folder for [`Run::outputs`].
pub trait Run: Args {
    /// Name of the program (the example's).
    const NAME: &'static str;
    /// Default output folder.
    const OUT: &'static str;
    /// One line for `--help`.
    const ABOUT: &'static str;
    /// Runs with the parsed options, writing under `out`.
    ///
    /// # Errors
    /// Whatever stops the run; `main` reports it and exits with status 1.
    fn run(&self, out: &Outputs) -> Result<(), BoxError>;

    /// Checks what a value parser cannot see alone (a setup given twice, say), at parse time.
    ///
    /// # Errors
    /// A message naming the option.
    fn check(&self) -> Result<(), String> {
        Ok(())
    }

    /// The files the run will write, relative to the output folder (the ParaView series aside):
    /// none may be a folder.
    fn outputs(&self) -> Vec<String>;
}

#[derive(Debug, Parser)]
struct Cli<R: Run> {
    #[command(flatten)]
    common: CommonOptions,
    #[command(flatten)]
    run: R,
}

/// Parses the command line into `R` and [`CommonOptions`], runs, reports the output folder and
/// the wall time; on an error prints `NAME: error` and exits with status 1.
pub fn main<R: Run>() {
    let (common, run) = parse::<R>(std::env::args_os()).unwrap_or_else(|e| e.exit());
    let out = Outputs::new(&common);
    if let Err(e) = out
        .prepare(&run.outputs())
        .map_err(BoxError::from)
        .and_then(|()| run.run(&out))
    {
        eprintln!("{}: {e}", R::NAME);
        std::process::exit(1);
    }
    println!("outputs in {} ({:.1} s wall)", out.dir().display(), out.elapsed());
}

/// The command of run `R`: name, description, `--out`'s default; a repeated option keeps its
/// last value.
pub fn command<R: Run>() -> clap::Command {
    Cli::<R>::command()
        .name(R::NAME)
        .bin_name(R::NAME)
        .about(R::ABOUT)
        .args_override_self(true)
        .mut_arg("out", |a| a.required(false).default_value(R::OUT))
}

/// Parses `args` (program name first) for run `R`: every value in its range, and
/// [`Run::check`].
///
/// # Errors
/// clap's, for a bad, out-of-range or unknown option, for a failed [`Run::check`] or for
/// `--help`.
pub fn parse<R: Run>(
    args: impl IntoIterator<Item = impl Into<std::ffi::OsString> + Clone>,
) -> Result<(CommonOptions, R), clap::Error> {
    let mut command = command::<R>();
    let matches = command.try_get_matches_from_mut(args)?;
    let cli = Cli::<R>::from_arg_matches(&matches)?;
    cli.run
        .check()
        .map_err(|e| command.error(clap::error::ErrorKind::ValueValidation, e))?;
    Ok((cli.common, cli.run))
}

/// Where a run writes, and since when it runs.
#[derive(Debug)]
pub struct Outputs {
    dir: PathBuf,
    paraview: bool,
    started: Instant,
}

impl Outputs {
    /// The output folder of `common`, timing from now.
    pub fn new(common: &CommonOptions) -> Self {
        Self {
            dir: common.out.clone(),
            paraview: !common.no_paraview,
            started: Instant::now(),
        }
    }

    /// The output folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Whether ParaView series are written (not `--no-paraview`).
    pub fn paraview(&self) -> bool {
        self.paraview
    }

    /// Seconds since the run started.
    pub fn elapsed(&self) -> f64 {
        self.started.elapsed().as_secs_f64()
    }

    /// Makes the output folder ready before the run computes anything
    /// ([`args::prepare_output_dir`]): creates it (and `paraview/` unless `--no-paraview`),
    /// probes that it can be written, and checks that none of `files` is a folder.
    ///
    /// # Errors
    /// [`voussoir::Error::Io`] naming the path at fault.
    pub fn prepare(&self, files: &[String]) -> voussoir::Result<()> {
        let folders: &[&str] = if self.paraview { &["paraview"] } else { &[] };
        args::prepare_output_dir(&self.dir, folders, files)
    }

    /// Runs `cases` in parallel behind a progress bar labelled `message`; `f` gets each case's
    /// index. The results come in the order of the cases; the first error stops the run.
    ///
    /// # Errors
    /// The first error of `f`.
    pub fn run_all<C: Sync, T: Send>(
        &self,
        cases: &[C],
        message: &str,
        f: impl Fn(usize, &C) -> voussoir::Result<T> + Sync,
    ) -> voussoir::Result<Vec<T>> {
        let bar = progress::bar(cases.len() as u64, message);
        let results = cases
            .par_iter()
            .enumerate()
            .map(|(k, case)| {
                let result = f(k, case);
                bar.inc(1);
                result
            })
            .collect::<voussoir::Result<Vec<T>>>()?;
        bar.finish_and_clear();
        Ok(results)
    }

    /// Runs `run` with a ParaView series `name` under `<out>/paraview`, a frame every `every`
    /// (s), when `name` is given and `--no-paraview` is not; otherwise without frames. `run`
    /// gets the frame interval and the frame callback, as the scenarios' `run` take them.
    ///
    /// # Errors
    /// `run`'s.
    pub fn with_frames<T>(
        &self,
        name: Option<&str>,
        every: f64,
        run: impl FnOnce(Option<f64>, &mut (dyn FnMut(&Model) -> voussoir::Result<()> + Send)) -> voussoir::Result<T>,
    ) -> voussoir::Result<T> {
        self.with_frames_and_subcontacts(name, every, 1, run)
    }

    /// [`Outputs::with_frames`] with the sub-contacts written on every `subcontacts_every`-th
    /// frame only ([`vtk::Series::with_subcontacts_every`]). The same frames go into a viewer,
    /// `<out>/<name>.html` ([`Viewer`]: open it in a browser), written also with
    /// `--no-paraview`, and also when the run fails (with the frames up to the failure).
    ///
    /// # Errors
    /// `run`'s; [`voussoir::Error::Io`] if the viewer cannot be written.
    pub fn with_frames_and_subcontacts<T>(
        &self,
        name: Option<&str>,
        every: f64,
        subcontacts_every: usize,
        run: impl FnOnce(Option<f64>, &mut (dyn FnMut(&Model) -> voussoir::Result<()> + Send)) -> voussoir::Result<T>,
    ) -> voussoir::Result<T> {
        let Some(name) = name else {
            return run(None, &mut |_| Ok(()));
        };
        // Times from the first frame: a drop's from its release, a push's from its start, as
        // the histories and plots count them (not the model's, which include the settling).
        let mut series = self.paraview.then(|| {
            vtk::Series::new(self.dir.join("paraview"), name)
                .with_subcontacts_every(subcontacts_every)
                .with_time_from_first_frame()
        });
        let mut viewer = Viewer::new(name).with_time_from_first_frame();
        let result = run(Some(every), &mut |m| {
            if let Some(series) = &mut series {
                series.write_frame(m)?;
            }
            viewer.record(m)
        });
        let written = if viewer.is_empty() {
            Ok(())
        } else {
            viewer.write(&self.viewer_path(name))
        };
        let value = result?;
        written?;
        Ok(value)
    }

    /// Where the viewer of the series `name` goes.
    pub fn viewer_path(&self, name: &str) -> PathBuf {
        self.dir.join(format!("{name}.html"))
    }

    /// Writes `value` as pretty JSON to `file` in the output folder.
    ///
    /// # Errors
    /// [`voussoir::Error::Io`] naming the file.
    pub fn json(&self, file: &str, value: &impl Serialize) -> voussoir::Result<()> {
        write_json(&self.dir.join(file), value)
    }

    /// Writes `text` to `file` in the output folder, creating the folder.
    ///
    /// # Errors
    /// [`voussoir::Error::Io`] naming the file.
    pub fn text(&self, file: &str, text: &str) -> voussoir::Result<()> {
        args::write_text(&self.dir.join(file), text)
    }

    /// Writes `plot` as `<stem>.svg` and `<stem>.png` in the output folder.
    ///
    /// # Errors
    /// [`voussoir::Error::Io`] naming the file.
    pub fn plot(&self, stem: &str, plot: &LinePlot) -> voussoir::Result<()> {
        plot.write_svg(&self.dir.join(format!("{stem}.svg")))?;
        plot.write_png(&self.dir.join(format!("{stem}.png")))
    }
}

#[cfg(test)]
mod tests {
    use super::arch_impact::ImpactOptions;
    use super::arch_static::StaticOptions;
    use super::*;
    use crate::scenarios::arch_impact::{ImpactorBase, ImpactorGuide, Release};

    fn impact(args: &[&str]) -> (CommonOptions, ImpactOptions) {
        parse::<ImpactOptions>(std::iter::once("arch_impact").chain(args.iter().copied())).expect("parses")
    }

    fn statics(args: &[&str]) -> (CommonOptions, StaticOptions) {
        parse::<StaticOptions>(std::iter::once("arch_static").chain(args.iter().copied())).expect("parses")
    }

    /// The defaults of the hand-written parsers that the front end replaced.
    #[test]
    fn defaults_are_the_old_ones() {
        let (c, o) = impact(&[]);
        assert_eq!(c.out, PathBuf::from("out/arch_impact"));
        assert!(!c.no_paraview);
        assert_eq!(o.setups, None);
        assert_eq!((o.kn, o.damping, o.width, o.duration), (None, None, None, None));
        assert_eq!(
            (o.guide, o.base, o.release),
            (ImpactorGuide::Frame, ImpactorBase::Sloped, Release::JustAbove)
        );
        assert_eq!(o.offsets_mm, [-0.5, -0.25, 0.0, 0.25, 0.5]);
        assert!(!o.study && !o.compare_release);
        let (c, o) = statics(&[]);
        assert_eq!(c.out, PathBuf::from("out/arch_static"));
        assert!(!c.no_paraview && !o.baseline_only && !o.no_sweep);
        assert_eq!(o.friction, [27.0, 30.0, 30.5, 35.0]);
    }

    #[test]
    fn options_parse_as_before() {
        let (c, o) = impact(&[
            "--out",
            "x",
            "--setup",
            "M60H20,M75H45",
            "--kn",
            "8e9",
            "--damping",
            "0.02",
            "--width",
            "0.2",
            "--duration",
            "0.5",
            "--guide",
            "seat",
            "--base",
            "flat",
            "--release",
            "full",
            "--offsets",
            "-0.5,0",
            "--study",
            "--compare-release",
            "--no-paraview",
        ]);
        assert_eq!(c.out, PathBuf::from("x"));
        assert!(c.no_paraview);
        assert_eq!(o.setups, Some(vec!["M60H20".to_owned(), "M75H45".to_owned()]));
        assert_eq!(
            (o.kn, o.damping, o.width, o.duration),
            (Some(8e9), Some(0.02), Some(0.2), Some(0.5))
        );
        assert_eq!(
            (o.guide, o.base, o.release),
            (ImpactorGuide::SeatConstrained, ImpactorBase::Flat, Release::FullHeight)
        );
        assert_eq!(o.offsets_mm, [-0.5, 0.0]);
        assert!(o.study && o.compare_release);
        // A repeated option keeps its last value, as the old parsers did.
        let (_, o) = statics(&[
            "--friction",
            "27",
            "--friction",
            "30.5,35",
            "--baseline-only",
            "--no-sweep",
        ]);
        assert_eq!(o.friction, [30.5, 35.0]);
        assert!(o.baseline_only && o.no_sweep);
        let (_, o) = impact(&["--kn", "1e9", "--kn", "2e9"]);
        assert_eq!(o.kn, Some(2e9));
    }

    #[test]
    fn bad_values_are_refused() {
        let bad =
            |args: &[&str]| parse::<ImpactOptions>(std::iter::once("arch_impact").chain(args.iter().copied())).is_err();
        assert!(bad(&["--kn", "abc"]));
        assert!(bad(&["--kn", "inf"]));
        assert!(bad(&["--offsets", "0,NaN"]));
        assert!(bad(&["--guide", "rail"]));
        assert!(bad(&["--unknown"]));
        assert!(parse::<StaticOptions>(["arch_static", "--friction", "x"]).is_err());
    }

    #[test]
    fn the_command_is_consistent() {
        command::<ImpactOptions>().debug_assert();
        command::<StaticOptions>().debug_assert();
    }
}
