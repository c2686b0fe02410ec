//! The quasi-static test of the reference arch (Pulatsu, Gonen & Lourenço 2021; `docs/benchmarks/arch-static.md`).
//!
//! ```text
//! cargo run --release --example arch_static                 # baseline + every study, in parallel
//! cargo run --release --example arch_static -- --baseline-only
//! cargo run --release --example arch_static -- --out results/static --friction 27,30.5,35
//! ```
//!
//! Writes `summary.json`, `force_displacement.csv`, `force_displacement.svg`,
//! `capacity_vs_friction.svg` and a ParaView series of the baseline under `out/arch_static/`.

use clap::{ArgAction, Args};
use serde::Serialize;
use voussoir::contact::DisplacementMode;

use super::{finite, BoxError, Outputs, Run};
use crate::plot::{Curve, LinePlot, Reference};
use crate::scenarios::arch_static::{run, ServoLoading, StaticCase, StaticResult};

/// Peak load of the test (kN).
const EXPERIMENT_PEAK_KN: f64 = 2.71;

/// Options of the quasi-static run.
#[derive(Debug, Clone, Args)]
pub struct StaticOptions {
    /// Run the baseline only
    #[arg(long)]
    pub baseline_only: bool,
    /// Leave out the capacity-versus-friction sweep (25° to 40° by 1°)
    #[arg(long)]
    pub no_sweep: bool,
    /// Friction angles (°) of the study, plotted in force_displacement.svg
    #[arg(
        long,
        value_name = "DEG[,DEG]",
        value_delimiter = ',',
        action = ArgAction::Set,
        value_parser = finite,
        allow_hyphen_values = true,
        default_value = "27,30,30.5,35"
    )]
    pub friction: Vec<f64>,
    /// Quasi-static loading by servo (voussoir::loading::Servo): the plate advances by this
    /// many metres per step from settled states only, in every case but the rate study
    #[arg(long, value_name = "M", value_parser = finite)]
    pub servo: Option<f64>,
    /// Unbalanced-force ratio at which the servo advances the plate
    #[arg(long, value_name = "RATIO", value_parser = finite, default_value = "1e-3")]
    pub servo_ratio: f64,
}

impl Run for StaticOptions {
    const NAME: &'static str = "arch_static";
    const OUT: &'static str = "out/arch_static";
    const ABOUT: &'static str = "The quasi-static test of the reference arch (Pulatsu, Gonen & Lourenço 2021) \
and the paper's parameter studies, in parallel";

    fn run(&self, out: &Outputs) -> Result<(), BoxError> {
        run_static(self, out)
    }
}

/// The study cases of the paper, plus the capacity-versus-friction sweep (under servo loading
/// with `--servo`, the rate study aside).
fn cases(o: &StaticOptions) -> Vec<StaticCase> {
    let mut cases = paper_cases(o);
    if let Some(increment) = o.servo {
        for c in cases.iter_mut().filter(|c| !c.label.starts_with("rate")) {
            c.servo = Some(ServoLoading {
                increment,
                max_unbalanced_ratio: o.servo_ratio,
            });
        }
    }
    cases
}

fn paper_cases(o: &StaticOptions) -> Vec<StaticCase> {
    let base = StaticCase::baseline();
    let mut cases = vec![base.clone()];
    if o.baseline_only {
        return cases;
    }
    let mut angles: Vec<f64> = o.friction.clone();
    if !o.no_sweep {
        angles.extend((25..=40).map(f64::from));
    }
    angles.sort_by(f64::total_cmp);
    angles.dedup();
    for phi in angles {
        if phi != base.friction_deg {
            cases.push(StaticCase {
                label: format!("friction {phi}°"),
                friction_deg: phi,
                ..base.clone()
            });
        }
    }
    for kn in [2e9, 8e9] {
        cases.push(StaticCase {
            label: format!("kn {} GPa/m", kn / 1e9),
            kn,
            ks: kn * base.ks / base.kn,
            ..base.clone()
        });
    }
    for rate in [5e-2, 5e-3] {
        cases.push(StaticCase {
            label: format!("rate {rate} m/s"),
            rate,
            ..base.clone()
        });
    }
    cases.push(StaticCase {
        label: "small displacements".into(),
        mode: DisplacementMode::Small,
        ..base.clone()
    });
    cases.push(StaticCase {
        label: "width 0.20 m".into(),
        width: 0.20,
        ..base.clone()
    });
    cases
}

#[derive(Serialize)]
struct CaseSummary {
    label: String,
    friction_deg: f64,
    kn_pa_per_m: f64,
    ks_pa_per_m: f64,
    rate_m_per_s: f64,
    mode: &'static str,
    width_m: f64,
    peak_load_kn: f64,
    peak_load_kn_per_m: f64,
    raw_peak_load_kn: f64,
    disp_at_peak_mm: f64,
    end_disp_mm: f64,
    end_load_kn: f64,
    settle_unbalanced_ratio: f64,
    mechanism: MechanismSummary,
    /// Per joint at the peak and at the end: open fraction, compression position, slip, hinge.
    joints_at_peak: Vec<voussoir::analysis::JointState>,
    joints_at_end: Vec<voussoir::analysis::JointState>,
    steps: u64,
    dt_s: f64,
    subcontacts: usize,
    wall_s: f64,
}

#[derive(Serialize)]
struct MechanismSummary {
    at_peak: voussoir::analysis::Mechanism,
    at_end: voussoir::analysis::Mechanism,
}

#[derive(Serialize)]
struct Summary {
    experiment: Experiment,
    adopted: serde_json::Value,
    cases: Vec<CaseSummary>,
    total_wall_s: f64,
}

#[derive(Serialize)]
struct Experiment {
    peak_load_kn: f64,
    source: &'static str,
}

fn summarise(r: &StaticResult) -> CaseSummary {
    let c = &r.case;
    let end = r.curve.last().copied();
    CaseSummary {
        label: c.label.clone(),
        friction_deg: c.friction_deg,
        kn_pa_per_m: c.kn,
        ks_pa_per_m: c.ks,
        rate_m_per_s: c.rate,
        mode: if c.mode == DisplacementMode::Large {
            "large"
        } else {
            "small"
        },
        width_m: c.width,
        peak_load_kn: r.peak_load / 1e3,
        peak_load_kn_per_m: r.peak_load / 1e3 / c.width,
        raw_peak_load_kn: r.raw_peak_load / 1e3,
        disp_at_peak_mm: r.displacement_at_peak * 1e3,
        end_disp_mm: end.map_or(0.0, |s| s.displacement * 1e3),
        end_load_kn: end.map_or(0.0, |s| s.load / 1e3),
        settle_unbalanced_ratio: r.settle_ratio,
        mechanism: MechanismSummary {
            at_peak: r.mechanism_at_peak.clone(),
            at_end: r.mechanism_at_end.clone(),
        },
        joints_at_peak: r.joints_at_peak.clone(),
        joints_at_end: r.joints_at_end.clone(),
        steps: r.steps,
        dt_s: r.dt,
        subcontacts: r.subcontacts,
        wall_s: r.wall_s,
    }
}

fn run_static(o: &StaticOptions, out: &Outputs) -> Result<(), BoxError> {
    let cases = cases(o);
    let base = StaticCase::baseline();
    println!(
        "Quasi-static test of the reference arch (Pulatsu et al. 2021), {} cases",
        cases.len()
    );
    println!(
        "Adopted values (docs/benchmarks/arch-static.md): width {} m; plate {:.2} m × {} m steel, vertical velocity only",
        base.width, base.plate_length, base.plate_thickness
    );
    println!(
        "  (free to slide and turn in plane: no horizontal restraint); joints kn {:.1e} Pa/m, ks {:.1e} Pa/m, φ {}°, c = f_t = 0;",
        base.kn, base.ks, base.friction_deg
    );
    println!(
        "  {} sub-contacts per joint edge; local damping {}; settle to unbalanced ratio {:.0e}; load at {} m/s to {} mm or {}% of peak",
        base.per_edge,
        base.local_damping,
        base.settle_ratio,
        base.rate,
        base.max_displacement * 1e3,
        base.stop_fraction * 100.0
    );
    let results: Vec<StaticResult> = out.run_all(&cases, "cases", |k, case| {
        out.with_frames((k == 0).then_some("baseline"), 5e-4, |every, frame| {
            run(case, every, frame)
        })
    })?;

    println!();
    println!(
        "{:<22} {:>8} {:>8} {:>8} {:>7} {:>7}  {:<44} {:>5}",
        "case", "peak kN", "raw kN", "kN/m", "at mm", "wall s", "mechanism at peak (i/e = intrados/extrados)", "exp."
    );
    for r in &results {
        let exp = if r.case.label == "baseline" {
            format!("{EXPERIMENT_PEAK_KN}")
        } else {
            String::new()
        };
        println!(
            "{:<22} {:>8.3} {:>8.3} {:>8.2} {:>7.2} {:>7.1}  {:<44} {:>5}",
            r.case.label,
            r.peak_load / 1e3,
            r.raw_peak_load / 1e3,
            r.peak_load / 1e3 / r.case.width,
            r.displacement_at_peak * 1e3,
            r.wall_s,
            r.mechanism_at_peak.describe(),
            exp
        );
    }
    println!("(peak: load averaged over 1 mm of plate travel, the quasi-static capacity; raw: with the mechanism's inertial oscillation)");
    let b = &results[0];
    println!(
        "\nbaseline: model {:.3} kN vs experiment {EXPERIMENT_PEAK_KN} kN ({:+.1} %); settled to unbalanced ratio {:.1e}",
        b.peak_load / 1e3,
        (b.peak_load / 1e3 / EXPERIMENT_PEAK_KN - 1.0) * 100.0,
        b.settle_ratio
    );

    // Outputs.
    let summary = Summary {
        experiment: Experiment {
            peak_load_kn: EXPERIMENT_PEAK_KN,
            source: "Pulatsu, Gonen & Lourenço 2021, Infrastructures 6(12):178",
        },
        adopted: serde_json::to_value(&base)?,
        cases: results.iter().map(summarise).collect(),
        total_wall_s: out.elapsed(),
    };
    out.json("summary.json", &summary)?;
    let mut csv = String::from(
        "case,displacement [mm],load [kN],load 1 mm average [kN],left support dx [mm],right support dx [mm]\n",
    );
    for r in &results {
        for s in &r.curve {
            csv.push_str(&format!(
                "{},{:e},{:e},{:e},{:e},{:e}\n",
                r.case.label,
                s.displacement * 1e3,
                s.load / 1e3,
                s.smoothed_load / 1e3,
                s.left_support_dx * 1e3,
                s.right_support_dx * 1e3
            ));
        }
    }
    out.text("force_displacement.csv", &csv)?;
    let by_friction: Vec<&StaticResult> = results
        .iter()
        .filter(|r| {
            o.friction.contains(&r.case.friction_deg)
                && (r.case.label == "baseline" || r.case.label.starts_with("friction"))
        })
        .collect();
    let force_displacement = LinePlot {
        title: "Arch under a quarter-span load: load–displacement".into(),
        x_label: "plate displacement [mm]".into(),
        y_label: "load [kN]".into(),
        curves: by_friction
            .iter()
            .map(|r| Curve {
                label: format!("φ = {}° (1 mm average)", r.case.friction_deg),
                points: r
                    .curve
                    .iter()
                    .map(|s| (s.displacement * 1e3, s.smoothed_load / 1e3))
                    .collect(),
            })
            .chain(std::iter::once(Curve {
                label: "φ = 30.5°, raw".into(),
                points: results[0]
                    .curve
                    .iter()
                    .map(|s| (s.displacement * 1e3, s.load / 1e3))
                    .collect(),
            }))
            .collect(),
        references: vec![Reference::Horizontal {
            label: format!("experiment peak {EXPERIMENT_PEAK_KN} kN"),
            y: EXPERIMENT_PEAK_KN,
        }],
        ..Default::default()
    };
    out.svg("force_displacement.svg", &force_displacement)?;
    let mut sweep: Vec<(f64, f64)> = results
        .iter()
        .filter(|r| r.case.label == "baseline" || r.case.label.starts_with("friction"))
        .map(|r| (r.case.friction_deg, r.peak_load / 1e3))
        .collect();
    sweep.sort_by(|a, b| a.0.total_cmp(&b.0));
    let capacity = LinePlot {
        title: "Capacity versus joint friction angle".into(),
        x_label: "friction angle [°]".into(),
        y_label: "peak load [kN]".into(),
        curves: vec![Curve {
            label: "model".into(),
            points: sweep,
        }],
        references: vec![Reference::Point {
            label: "experiment (φ = 30.5°)".into(),
            x: 30.5,
            y: EXPERIMENT_PEAK_KN,
        }],
        ..Default::default()
    };
    out.svg("capacity_vs_friction.svg", &capacity)?;
    Ok(())
}
