//! A rubble wall (irregular convex stones, through-stones) settled under gravity, then tipped
//! over by a tilting table.
//!
//! ```text
//! cargo run --release --example rubble_wall [-- --stone-size 0.2] [--tilt-deg 35] [--seconds 1.5] [--out DIR]
//! ```
//!
//! The wall (`build::rubble_wall`, 2 m × 0.5 m × 1.2 m, two leaves with a tenth of through-stones)
//! settles with local damping; then the damping is switched off and gravity is turned by
//! `--tilt-deg` about the wall's length, as a tilting table does, and the wall is followed for
//! `--seconds`: it leans, its stones rock on their edges and corners, and beyond about the wall's
//! slenderness angle it falls. Writes a ParaView series (`rubble_wall_blocks.pvd`), a viewer
//! (`rubble_wall.html`, open it in a browser) and prints the energy
//! balance (input against kinetic + elastic + friction + damping) and the time per step.

#[path = "common/args.rs"]
mod args;

use std::ops::Bound::{Excluded, Included};
use std::path::PathBuf;
use std::time::Instant;

use clap::Parser;
use voussoir::build::{rubble_wall, RubbleWallSpec};
use voussoir::io::viewer::Viewer;
use voussoir::io::vtk::Series;
use voussoir::prelude::*;

const STONE: args::Interval = args::Interval {
    lo: Included(0.1),
    hi: Included(0.5),
};
const TILT: args::Interval = args::Interval {
    lo: Included(0.0),
    hi: Excluded(90.0),
};
const SECONDS: args::Interval = args::Interval {
    lo: Excluded(0.0),
    hi: Included(10.0),
};

/// A rubble wall settled, then tipped by a tilting table.
#[derive(Debug, Parser)]
#[command(name = "rubble_wall", args_override_self = true)]
struct Options {
    /// Typical stone size (m), in [0.1, 0.5]
    #[arg(long, value_name = "M", value_parser = STONE.parser(), default_value = "0.2")]
    stone_size: f64,
    /// Tilt of gravity about the wall's length after settling (°), in [0, 90)
    #[arg(long, value_name = "DEG", value_parser = TILT.parser(), default_value = "35")]
    tilt_deg: f64,
    /// Time followed after the tilt (s), in (0, 10]
    #[arg(long, value_name = "S", value_parser = SECONDS.parser(), default_value = "1.5")]
    seconds: f64,
    /// Output folder (ParaView series)
    #[arg(long, value_name = "DIR", default_value = "out/rubble_wall")]
    out: PathBuf,
}

fn main() {
    if let Err(e) = run() {
        eprintln!("rubble_wall: {e}");
        std::process::exit(1);
    }
}

fn run() -> Result<()> {
    let options = Options::parse();
    args::prepare_output_dir(
        &options.out,
        &["rubble_wall"],
        &["rubble_wall_blocks.pvd".to_owned(), "rubble_wall.html".to_owned()],
    )?;
    let spec = RubbleWallSpec {
        stone_size: options.stone_size,
        ..RubbleWallSpec::default()
    };
    let mut model: Model = Model::new(ModelParameters::default())?;
    model.set_joint_law(MaterialId(0), MaterialId(0), CoulombSlip::dry(1e9, 4e8, 35.0)?)?;
    for block in rubble_wall(&spec)? {
        model.add_block(block)?;
    }
    let stones = model.blocks().len() - 1;
    println!(
        "rubble wall {} × {} × {} m: {stones} stones of about {} m ({} through-stones)",
        spec.length,
        spec.thickness,
        spec.height,
        spec.stone_size,
        model
            .blocks()
            .iter()
            .filter(|b| b.name().starts_with("through"))
            .count()
    );

    let started = Instant::now();
    model.run_to_equilibrium(1e-4, 200_000)?;
    let settled = model.step_count();
    println!(
        "settled in {settled} steps ({:.2} s model time), unbalanced ratio {:.1e}, {} contacts",
        model.time(),
        model.unbalanced_force_ratio(),
        model.contacts().len()
    );

    // The tilting table: gravity turned about the wall's length (x), undamped from here on.
    model.set_damping(Damping::None)?;
    let tilt = options.tilt_deg.to_radians();
    let g = 9.81;
    model.set_parameters(ModelParameters {
        gravity: Vector::new(0.0, g * tilt.sin(), -g * tilt.cos()),
        ..*model.parameters()
    })?;
    let before = model.energies();
    let mut series = Series::new(&options.out, "rubble_wall");
    let mut viewer = Viewer::new("rubble wall on a tilting table").with_time_from_first_frame();
    series.write_frame(&model)?;
    viewer.record(&model)?;
    let (t0, frames) = (model.time(), 30);
    let mut next = 1;
    let moving = Instant::now();
    let steps_before = model.step_count();
    while model.time() < t0 + options.seconds {
        model.step()?;
        if model.time() >= t0 + options.seconds * next as f64 / frames as f64 {
            series.write_frame(&model)?;
            viewer.record(&model)?;
            next += 1;
        }
    }
    let moving_steps = model.step_count() - steps_before;
    viewer.write(&options.out.join("rubble_wall.html"))?;
    let per_step = moving.elapsed().as_secs_f64() / moving_steps as f64;
    let e = model.energies();
    let input = e.input() - before.input();
    let accounted = e.accounted() - before.accounted();
    let top = model
        .blocks()
        .iter()
        .map(|b| b.state().pose.translation.z)
        .fold(f64::NEG_INFINITY, f64::max);
    println!(
        "tilted {:.0}°, followed {:.2} s in {moving_steps} steps: {:.3} ms/step, highest stone centre at {top:.3} m",
        options.tilt_deg,
        options.seconds,
        per_step * 1e3
    );
    println!(
        "energy since the tilt: input {input:.3} J, accounted {accounted:.3} J (kinetic {:.3}, elastic {:.3}, friction {:.3}), balance error {:.2} % of the input",
        e.kinetic,
        e.elastic,
        e.friction - before.friction,
        100.0 * (accounted - input) / input.abs().max(f64::MIN_POSITIVE)
    );
    println!(
        "viewer {} (open in a browser); ParaView series in {} ({:.1} s wall in all)",
        options.out.join("rubble_wall.html").display(),
        options.out.join("rubble_wall_blocks.pvd").display(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}
