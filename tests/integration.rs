//! The integration tests, one crate: each file of `tests/` is a module of it (`tests/common/`
//! the fixtures they share), so that `cargo test` compiles the library's generic step code once
//! for all of them rather than once per file (28 crates took 340 s of CPU to compile on 2
//! cores; `docs/performance.md`). Run one file's tests with
//! `cargo test --release --test integration checkpoint::`. The fuzz targets (`tests/fuzz.rs`)
//! are their own crate, run by `.ci/run` with a time budget.

mod common;

mod base_excitation;
mod checkpoint;
mod collapse;
mod custom_law;
mod dynamics;
mod energy_and_determinism;
mod energy_conservation;
mod errors;
mod examples_cli;
mod friction;
mod generators;
mod golden_fingerprints;
mod history;
mod hostile_answers;
mod hostile_files;
mod hostile_input;
mod inertia;
mod joint_stepping;
mod limit_analysis;
mod load_history;
mod mixed_laws;
mod model_changes;
mod mortar;
mod moving_detection;
mod pushover;
mod quasi_static;
mod run_errors;
mod scene;
mod sharp_contacts;
mod shear_wall;
mod statics;
mod unbonded_nodes;
mod viewer;
mod vtk_output;
