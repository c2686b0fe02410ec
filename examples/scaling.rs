//! Scaling of a settling running-bond wall with the number of blocks.
//!
//! ```text
//! cargo run --release --example scaling -- --blocks 1000,10000,100000 [--steps 50] [--spacing 0.025] [--out DIR]
//! ```
//!
//! For each size: build the wall (about ten times as long as high), run 20 steps (the first
//! detects every contact), then time `--steps` steps. Prints blocks, contacts, sub-contacts, time
//! per step, sub-contact updates per second, the share of time in contact detection, peak memory
//! per block and the number of threads, and writes `out/scaling/summary.json`. `--spacing` sets the
//! largest sub-contact spacing (m, default 25 mm), for studies of the cost of sub-contact density.

use std::path::PathBuf;
use std::time::Instant;

use serde::Serialize;
use voussoir::prelude::*;
use voussoir::scenes::{benchmark_wall_with_spacing, BENCHMARK_SPACING};

#[derive(Serialize)]
struct Run {
    blocks: usize,
    contacts: usize,
    subcontacts: usize,
    threads: usize,
    /// Largest sub-contact spacing (m).
    spacing: f64,
    s_per_step: f64,
    subcontact_updates_per_s: f64,
    detection_share: f64,
    /// Share of the stepping time in the contact pass (kinematics, laws, resultants, gather).
    contact_share: f64,
    /// Share in the integrator and energy bookkeeping.
    integration_share: f64,
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
    let mut sizes = vec![1_000usize, 10_000];
    let mut steps = 50u64;
    let mut spacing = BENCHMARK_SPACING;
    let mut out = PathBuf::from("out/scaling");
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--blocks" => {
                sizes = args
                    .next()
                    .ok_or("--blocks needs a list")?
                    .split(',')
                    .map(|x| x.trim().parse())
                    .collect::<Result<_, _>>()?
            }
            "--steps" => steps = args.next().ok_or("--steps needs a number")?.parse()?,
            "--spacing" => spacing = args.next().ok_or("--spacing needs a length in m")?.parse()?,
            "--out" => out = args.next().ok_or("--out needs a folder")?.into(),
            other => return Err(format!("unknown argument {other:?}").into()),
        }
    }
    let threads = rayon::current_num_threads();
    println!(
        "running-bond wall, bricks 0.2 × 0.1 × 0.05 m, sub-contact spacing {:.1} mm, {threads} threads",
        spacing * 1e3
    );
    println!(
        "{:>8} {:>9} {:>11} {:>11} {:>14} {:>10} {:>9} {:>11} {:>12}",
        "blocks",
        "contacts",
        "subcontacts",
        "ms/step",
        "updates/s",
        "detection",
        "contacts",
        "integration",
        "bytes/block"
    );
    let mut runs = Vec::new();
    for n in sizes {
        let started = Instant::now();
        let mut model = benchmark_wall_with_spacing(n, spacing)?;
        model.run_steps(20)?;
        let setup = started.elapsed().as_secs_f64();
        model.reset_timings();
        let t0 = Instant::now();
        model.run_steps(steps)?;
        let per_step = t0.elapsed().as_secs_f64() / steps as f64;
        let t = model.timings();
        let run = Run {
            blocks: model.blocks().len(),
            contacts: model.contacts().len(),
            subcontacts: model.subcontact_count(),
            threads,
            spacing,
            s_per_step: per_step,
            subcontact_updates_per_s: model.subcontact_count() as f64 / per_step,
            detection_share: share(t.detection, t.total()),
            contact_share: share(t.contacts, t.total()),
            integration_share: share(t.integration, t.total()),
            peak_rss_bytes: peak_rss_bytes(),
            peak_rss_bytes_per_block: peak_rss_bytes() as f64 / model.blocks().len() as f64,
            build_and_first_detection_s: setup,
        };
        println!(
            "{:>8} {:>9} {:>11} {:>11.3} {:>14.3e} {:>9.1}% {:>8.1}% {:>10.1}% {:>12.0}",
            run.blocks,
            run.contacts,
            run.subcontacts,
            run.s_per_step * 1e3,
            run.subcontact_updates_per_s,
            run.detection_share * 100.0,
            run.contact_share * 100.0,
            run.integration_share * 100.0,
            run.peak_rss_bytes_per_block
        );
        runs.push(run);
    }
    voussoir::io::write_json(&out.join("summary.json"), &serde_json::json!({ "runs": runs }))?;
    println!("summary in {}", out.join("summary.json").display());
    Ok(())
}
