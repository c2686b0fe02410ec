//! # voussoir-arch
//!
//! The reference arch of Pulatsu, Gonen & Lourenço (2021, Infrastructures 6(12):178) with
//! [`voussoir`]: the paper's quasi-static load test and drop-weight impact tests, reproduced.
//! Not published: this crate is the paper's data and tooling, kept apart from the library so that
//! neither its dependencies (clap, plotters, indicatif) nor its values sit in the library's
//! build and semver.
//!
//! | module | what |
//! |---|---|
//! | [`scenarios`] | the runs as functions of their parameters, shared by the command line and the tests |
//! | [`cli`] | one command line for the static and impact runs (`cargo run --release --example arch_static` / `arch_impact`) |
//! | [`plot`] | line plots, SVG and PNG |
//! | [`progress`] | progress bars |
//!
//! `cli`, `plot` and `progress` need the default feature `cli` (clap, indicatif, plotters);
//! without it (`default-features = false`, as the Python package has it) the crate is its
//! scenarios alone.
#![warn(missing_docs)]

#[cfg(feature = "cli")]
pub mod cli;
#[cfg(feature = "cli")]
pub mod plot;
#[cfg(feature = "cli")]
pub mod progress;
pub mod scenarios;
