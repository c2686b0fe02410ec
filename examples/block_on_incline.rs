//! A block on a real inclined ramp: sticks below the friction angle, slides above it.
//!
//! `cargo run --release --example block_on_incline [-- <SLOPE_DEG> [<FRICTION_DEG>]]`
//! (`-- --help` for the ranges)
//!
//! Prints the measured acceleration along the slope beside the closed form
//! `a = g (sin ψ − tan φ cos ψ)` (zero when ψ ≤ φ).

#[path = "common/args.rs"]
mod args;

use std::ops::Bound::{Excluded, Included};
use std::time::Instant;

use clap::Parser;
use voussoir::prelude::*;

/// Range of both angles (°): a ramp from flat to just short of vertical; a friction angle of
/// 90° would be an infinite friction coefficient.
const ANGLE: args::Interval = args::Interval {
    lo: Included(0.0),
    hi: Excluded(90.0),
};

/// A brick on a ramp of slope ψ with a joint of friction angle φ: it sticks for ψ ≤ φ and slides
/// with `a = g (sin ψ − tan φ cos ψ)` above.
#[derive(Debug, Parser)]
#[command(name = "block_on_incline", allow_negative_numbers = true, args_override_self = true)]
struct Options {
    /// Slope ψ of the ramp (°), in [0, 90)
    #[arg(value_name = "SLOPE_DEG", value_parser = ANGLE.parser(), default_value = "35")]
    slope_deg: f64,
    /// Friction angle φ of the joint (°), in [0, 90)
    #[arg(value_name = "FRICTION_DEG", value_parser = ANGLE.parser(), default_value = "30")]
    friction_deg: f64,
}

fn main() -> Result<()> {
    let Options {
        slope_deg,
        friction_deg,
    } = Options::parse();
    let (psi, phi, g) = (slope_deg.to_radians(), friction_deg.to_radians(), 9.81);

    let mut model: Model = Model::new(ModelParameters::default())?;
    model.set_joint_law(MaterialId(0), MaterialId(0), CoulombSlip::dry(1e9, 4e8, friction_deg)?)?;
    model.set_damping(Damping::None)?;
    // Build a ramp and a brick lying on it in the ramp's frame, then tilt both by ψ about y.
    let tilt = Pose::from_parts(Vector::ZERO, Rotation::from_rotation_y(-psi));
    let ramp = RigidBlock::cuboid(
        "ramp",
        Vector::new(-1.5, -0.5, -0.2),
        Vector::new(1.5, 0.5, 0.0),
        2500.0,
    )?;
    model.add_block(ramp.transformed(tilt).with_fixity(Fixity::FIXED))?;
    let brick = RigidBlock::cuboid(
        "brick",
        Vector::new(-0.1, -0.1, 0.0),
        Vector::new(0.1, 0.1, 0.1),
        2500.0,
    )?;
    let brick = model.add_block(brick.transformed(tilt))?;

    // Down the slope is -x of the ramp frame.
    let down_slope = -tilt.transform_vector(Vector::X);
    let centroid = model.block(brick)?.state().pose.translation;
    let along = |m: &Model| m.block(brick).map(|b| b.displacement_of(centroid).dot(down_slope));
    let (t0, t1) = (0.05, 0.35);
    let started = Instant::now();
    model.run_until_time(t0)?;
    // Least-squares fit of s(t) = s0 + v0 t + a t²/2 over [t0, t1]: insensitive to the
    // oscillation of the block on its contact springs.
    let mut samples = Vec::new();
    while model.time() < t1 {
        model.step()?;
        samples.push((model.time() - t0, along(&model)?));
    }
    let wall = started.elapsed().as_secs_f64();
    let measured = 2.0 * quadratic_fit(&samples);
    let expected = (g * (psi.sin() - phi.tan() * psi.cos())).max(0.0);
    println!("slope {slope_deg}°, friction {friction_deg}°, kn 1e9 Pa/m, ks 4e8 Pa/m, no damping");
    println!("acceleration along the slope: model {measured:.4} m/s², closed form {expected:.4} m/s²");
    println!(
        "{} steps of {:.3e} s ({} sub-contacts) in {:.2} s wall",
        model.step_count(),
        model.dt(),
        model.subcontact_count(),
        wall
    );
    Ok(())
}

/// Coefficient of t² of the least-squares parabola through `(t, s)` samples.
fn quadratic_fit(samples: &[(f64, f64)]) -> f64 {
    // Normal equations for s = c0 + c1 t + c2 t².
    let mut m = [[0.0; 3]; 3];
    let mut r = [0.0; 3];
    for &(t, s) in samples {
        let basis = [1.0, t, t * t];
        for i in 0..3 {
            for j in 0..3 {
                m[i][j] += basis[i] * basis[j];
            }
            r[i] += basis[i] * s;
        }
    }
    // Cramer's rule for the last unknown.
    let det3 = |a: [[f64; 3]; 3]| {
        a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
            + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])
    };
    let mut m2 = m;
    for i in 0..3 {
        m2[i][2] = r[i];
    }
    det3(m2) / det3(m)
}
