//! Limit analysis of the reference arch under the static test's load on voussoir 5
//! ([`crate::scenarios::arch_limit`]).
//!
//! ```text
//! cargo run --release --example limit_arch                       # φ = 30.5°, settled arch
//! cargo run --release --example limit_arch -- --friction 36 --out results/limit
//! ```
//!
//! Prints the collapse load and mechanism (and the joints' motion) and writes `limit.json`
//! (the summary, the contact forces at collapse and the blocks' velocities) and the mechanism as
//! a ParaView series (`paraview/mechanism_blocks.pvd`).

use clap::Args;
use serde::Serialize;

use std::ops::Bound::{Excluded, Included};

use super::args::{whole, Interval};
use super::{BoxError, Outputs, Run};
use crate::scenarios::arch_limit::{run, write_mechanism, LimitCase};
use crate::scenarios::arch_static::{LimitSummary, StaticCase};

/// Options of the limit analysis.
#[derive(Debug, Clone, Args)]
pub struct LimitArgs {
    /// Joint friction angle (°), in (0, 90)
    #[arg(long, value_name = "DEG", value_parser = super::arch_static::FRICTION_RANGE.parser(), default_value = "30.5")]
    pub friction: f64,
    /// Analyse the arch as built instead of settled under gravity
    #[arg(long)]
    pub no_settle: bool,
    /// Frames of the mechanism in the ParaView series
    #[arg(long, value_name = "N", value_parser = whole::<usize>(2), default_value = "21")]
    pub frames: usize,
    /// Largest displacement of a block's vertex in the last frame of the mechanism (m), in
    /// (0, 1]
    #[arg(long, value_name = "M", value_parser = AMPLITUDE_RANGE.parser(), default_value = "0.03")]
    pub amplitude: f64,
}

/// Range of `--amplitude` (m): a visible mechanism on a 1.2 m span.
pub const AMPLITUDE_RANGE: Interval = Interval {
    lo: Excluded(0.0),
    hi: Included(1.0),
};

impl Run for LimitArgs {
    const NAME: &'static str = "limit_arch";
    const OUT: &'static str = "out/limit_arch";
    const ABOUT: &'static str = "Limit analysis of the reference arch (Pulatsu, Gonen & Lourenço 2021) under a point \
load on voussoir 5: collapse load and mechanism";

    fn outputs(&self) -> Vec<String> {
        vec!["limit.json".into()]
    }

    fn run(&self, out: &Outputs) -> Result<(), BoxError> {
        let case = LimitCase {
            case: StaticCase {
                label: format!("limit, friction {}°", self.friction),
                friction_deg: self.friction,
                ..StaticCase::baseline()
            },
            settle: !self.no_settle,
        };
        let r = run(&case)?;
        let s = &r.summary;
        println!(
            "Limit analysis of the reference arch, φ = {}° (associative Coulomb cones, no tension), {}",
            self.friction,
            if case.settle {
                format!("settled under gravity ({} steps)", r.steps)
            } else {
                "as built".into()
            }
        );
        println!(
            "collapse load on voussoir 5: {:.3} kN ({:.2} kN/m) = λ {:.3} kN on the plate + its weight {:.1} N",
            s.load / 1e3,
            s.load / 1e3 / case.case.width,
            s.multiplier / 1e3,
            s.plate_weight
        );
        println!(
            "mechanism: {} (i/e = intrados/extrados); {} contacts, {} corners; solved in {} iterations, {:.1} ms",
            s.mechanism.describe(),
            r.result.contacts.len(),
            r.result.contacts.iter().map(|c| c.vertices.len()).sum::<usize>(),
            r.result.iterations,
            s.wall_s * 1e3
        );
        println!(
            "\n{:>5} {:>14} {:>14} {:>12}  state",
            "joint", "opening i", "opening e", "sliding"
        );
        for j in &s.joints {
            let state = match (j.hinge, j.is_sliding) {
                (Some(side), sliding) => format!("hinge ({side:?}){}", if sliding { ", sliding" } else { "" }),
                (None, true) => "sliding".into(),
                (None, false) => String::new(),
            };
            println!(
                "{:>5} {:>14.4e} {:>14.4e} {:>12.4e}  {state}",
                j.joint, j.opening_intrados, j.opening_extrados, j.sliding
            );
        }
        println!("(rates of the mechanism scaled so that the plate moves down at unit speed)");
        #[derive(Serialize)]
        struct Report<'a> {
            case: &'a LimitCase,
            summary: &'a LimitSummary,
            result: &'a voussoir::analysis::limit::LimitResult,
        }
        out.json(
            "limit.json",
            &Report {
                case: &case,
                summary: s,
                result: &r.result,
            },
        )?;
        if out.paraview() {
            let pvd = write_mechanism(
                &out.dir().join("paraview"),
                "mechanism",
                &r.model,
                &r.result,
                self.frames,
                self.amplitude,
            )?;
            println!("mechanism for ParaView: {}", pvd.display());
        }
        Ok(())
    }
}
