//! Scaling of a running-bond wall with the number of blocks, settling or shaking.
//!
//! ```text
//! cargo run --release --example scaling -- --blocks 1000,10000,100000 [--scene rest|shake] [--steps 50] [--warmup 20] [--spacing 0.025] [--out DIR]
//! ```
//!
//! For each size: build the wall (about ten times as long as high), run `--warmup` steps (the
//! first detects every contact), then time `--steps` steps. `--scene rest` (the default) is
//! `scenes::benchmark_wall`, settling under gravity with local damping; `--scene shake` is
//! `scenes::shaking_wall`, the same wall undamped with its base shaken across it at 0.3 g and
//! 3 Hz from the first step. Prints blocks, contacts, sub-contacts, time per step, sub-contact
//! updates per second, the share of time in contact detection, re-detections per step, peak
//! memory per block and the number of threads, and writes `out/scaling/summary.json`. `--spacing` sets the
//! largest sub-contact spacing (m, default 25 mm), for studies of the cost of sub-contact density.
//! `-- --help` gives the ranges; the output folder is created and probed before the first wall is
//! built.

#[path = "common/args.rs"]
mod args;

use std::ops::Bound::{Excluded, Included};
use std::path::PathBuf;
use std::time::Instant;

use clap::{ArgAction, Parser};
use serde::Serialize;
use voussoir::prelude::*;
use voussoir::scenes::{benchmark_wall_with_spacing, shaking_wall, BENCHMARK_SPACING};

/// Range of `--spacing` (m).
const SPACING: args::Interval = args::Interval {
    lo: Excluded(0.0),
    hi: Included(0.2),
};

/// What the wall does.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, Serialize)]
#[serde(rename_all = "lowercase")]
enum Scene {
    /// Settles under gravity with local damping (`scenes::benchmark_wall`)
    Rest,
    /// Undamped, its base shaken across the wall at 0.3 g, 3 Hz from the first step (`scenes::shaking_wall`)
    Shake,
}

/// Scaling of a running-bond wall (bricks 0.2 × 0.1 × 0.05 m), settling or shaking, with the
/// number of blocks: time per step, detection share, re-detections per step, sub-contact updates
/// per second, peak memory per block.
#[derive(Debug, Parser)]
#[command(name = "scaling", args_override_self = true)]
struct Options {
    /// Wall sizes (blocks), each at least 1
    #[arg(
        long = "blocks",
        value_name = "N[,N]",
        value_delimiter = ',',
        action = ArgAction::Set,
        value_parser = args::whole::<usize>(1),
        default_value = "1000,10000"
    )]
    sizes: Vec<usize>,
    /// What the wall does
    #[arg(long, value_enum, default_value_t = Scene::Rest)]
    scene: Scene,
    /// Timed steps per size, at least 1 (after the `--warmup` untimed ones)
    #[arg(long, value_name = "N", value_parser = args::whole::<u64>(1), default_value = "50")]
    steps: u64,
    /// Untimed steps per size before the timed ones, at least 1 (the first detects every contact)
    #[arg(long, value_name = "N", value_parser = args::whole::<u64>(1), default_value = "20")]
    warmup: u64,
    /// Largest sub-contact spacing (m), in (0, 0.2]: at most the bricks' length
    #[arg(long, value_name = "M", value_parser = SPACING.parser(), default_value_t = BENCHMARK_SPACING)]
    spacing: f64,
    /// Folder for summary.json
    #[arg(long, value_name = "DIR", default_value = "out/scaling")]
    out: PathBuf,
}

#[derive(Serialize)]
struct Run {
    scene: Scene,
    blocks: usize,
    contacts: usize,
    subcontacts: usize,
    threads: usize,
    /// Largest sub-contact spacing (m).
    spacing: f64,
    /// Time step (s) and model time at the end of the timed steps (s).
    dt: f64,
    end_time: f64,
    warmup_steps: u64,
    timed_steps: u64,
    s_per_step: f64,
    /// Sub-contacts summed over the timed steps, per second of wall-clock time.
    subcontact_updates_per_s: f64,
    /// Share of the stepping time in contact detection (`Model::timings`: detection / total).
    detection_share: f64,
    /// Contact detections during the timed steps (the first, full one is in the warm-up), per step.
    redetections_per_step: f64,
    /// Block pairs the narrow phase tested during the timed steps, per step
    /// (`Model::pair_tests`).
    pair_tests_per_step: f64,
    /// Share of the stepping time in the contact pass (kinematics, laws, resultants, gather).
    contact_share: f64,
    /// Share in the integrator and energy bookkeeping.
    integration_share: f64,
    /// Peak resident set size of the process so far (`VmHWM`: the largest wall run so far) and
    /// per block of this wall.
    peak_rss_bytes: u64,
    peak_rss_bytes_per_block: f64,
    build_and_first_detection_s: f64,
}

/// Peak resident set size of this process (Linux `VmHWM`), 0 elsewhere.
fn peak_rss_bytes() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1).and_then(|kb| kb.parse::<u64>().ok()))
        })
        .map_or(0, |kb| kb * 1024)
}

fn share(part: f64, total: f64) -> f64 {
    if total > 0.0 {
        part / total
    } else {
        0.0
    }
}

fn main() {
    if let Err(e) = try_main() {
        eprintln!("scaling: {e}");
        std::process::exit(1);
    }
}

fn try_main() -> Result<(), Box<dyn std::error::Error>> {
    let Options {
        sizes,
        scene,
        steps,
        warmup,
        spacing,
        out,
    } = Options::parse();
    args::prepare_output_dir(&out, &[], &["summary.json".to_owned()])?;
    let threads = rayon::current_num_threads();
    println!(
        "running-bond wall, bricks 0.2 × 0.1 × 0.05 m, sub-contact spacing {:.1} mm, {threads} threads, {}",
        spacing * 1e3,
        match scene {
            Scene::Rest => "settling (local damping)",
            Scene::Shake => "shaking across at 0.3 g, 3 Hz (undamped)",
        }
    );
    println!(
        "{:>8} {:>9} {:>11} {:>11} {:>14} {:>10} {:>10} {:>10} {:>9} {:>11} {:>12} {:>9}",
        "blocks",
        "contacts",
        "subcontacts",
        "ms/step",
        "updates/s",
        "detection",
        "redet/step",
        "tests/step",
        "contacts",
        "integration",
        "bytes/block",
        "peak MB"
    );
    let mut runs = Vec::new();
    for n in sizes {
        let started = Instant::now();
        let mut model = match scene {
            Scene::Rest => benchmark_wall_with_spacing(n, spacing)?,
            Scene::Shake => shaking_wall(n, spacing)?,
        };
        model.run_steps(warmup)?;
        let setup = started.elapsed().as_secs_f64();
        model.reset_timings();
        let detections = model.detection_count();
        let tests = model.pair_tests();
        // Sub-contacts change with re-detection: count the updates step by step (`step` is what
        // `run_steps` calls; the count is a length).
        let mut updates = 0_usize;
        let t0 = Instant::now();
        for _ in 0..steps {
            model.step()?;
            updates += model.subcontact_count();
        }
        let elapsed = t0.elapsed().as_secs_f64();
        let per_step = elapsed / steps as f64;
        let t = model.timings();
        let run = Run {
            scene,
            blocks: model.blocks().len(),
            contacts: model.contacts().len(),
            subcontacts: model.subcontact_count(),
            threads,
            spacing,
            dt: model.dt(),
            end_time: model.time(),
            warmup_steps: warmup,
            timed_steps: steps,
            s_per_step: per_step,
            subcontact_updates_per_s: updates as f64 / elapsed,
            detection_share: share(t.detection, t.total()),
            redetections_per_step: (model.detection_count() - detections) as f64 / steps as f64,
            pair_tests_per_step: (model.pair_tests() - tests) as f64 / steps as f64,
            contact_share: share(t.contacts, t.total()),
            integration_share: share(t.integration, t.total()),
            peak_rss_bytes: peak_rss_bytes(),
            peak_rss_bytes_per_block: peak_rss_bytes() as f64 / model.blocks().len() as f64,
            build_and_first_detection_s: setup,
        };
        println!(
            "{:>8} {:>9} {:>11} {:>11.3} {:>14.3e} {:>9.1}% {:>10.3} {:>10.1} {:>8.1}% {:>10.1}% {:>12.0} {:>9.0}",
            run.blocks,
            run.contacts,
            run.subcontacts,
            run.s_per_step * 1e3,
            run.subcontact_updates_per_s,
            run.detection_share * 100.0,
            run.redetections_per_step,
            run.pair_tests_per_step,
            run.contact_share * 100.0,
            run.integration_share * 100.0,
            run.peak_rss_bytes_per_block,
            run.peak_rss_bytes as f64 / 1e6
        );
        runs.push(run);
    }
    voussoir::io::write_json(&out.join("summary.json"), &serde_json::json!({ "runs": runs }))?;
    println!("summary in {}", out.join("summary.json").display());
    Ok(())
}
