//! The quasi-static test of the reference arch (Pulatsu, Gonen & Lourenço 2021; `docs/benchmarks/arch-static.md`).
//!
//! ```text
//! cargo run --release --example arch_static                 # baseline + every study, in parallel
//! cargo run --release --example arch_static -- --baseline-only
//! cargo run --release --example arch_static -- --out results/static --friction 27,30.5,35
//! ```
//!
//! Every case but the rate study is loaded quasi-statically (servo) and run twice, the second
//! time refined (half the servo's increment and threshold; the rate study: half the rate): the
//! change of the peak is `rate_convergence` in `summary.json`, and the run fails, naming the
//! cases, if a quasi-static case moves by more than 3 %.
//!
//! Every case also gets the limit analysis of its settled arch (`limit_load_kn` and the limit
//! mechanism in `summary.json` and the table, the second curve of `capacity_vs_friction.svg`).
//!
//! Writes `summary.json`, `force_displacement.csv`, `force_displacement.svg`,
//! `capacity_vs_friction.svg` (both also as PNG), a viewer of the baseline (`baseline.html`) and its ParaView series
//! under `out/arch_static/`.

use std::ops::Bound::{Excluded, Included};

use clap::{ArgAction, Args};
use serde::Serialize;
use voussoir::contact::DisplacementMode;

use super::args::Interval;
use super::{BoxError, Outputs, Run};
use crate::plot::{Curve, LinePlot, Reference};
use crate::scenarios::arch_static::{run, run_converged, PlateSupport, ServoLoading, StaticCase, StaticResult};
use voussoir::loading::Convergence;

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
    /// Friction angles (°) of the study, plotted in force_displacement.svg; each in (0, 90): a
    /// joint without friction has no capacity, and tan φ is infinite at 90°
    #[arg(
        long,
        value_name = "DEG[,DEG]",
        value_delimiter = ',',
        action = ArgAction::Set,
        value_parser = FRICTION_RANGE.parser(),
        allow_hyphen_values = true,
        default_value = "27,30,30.5,35"
    )]
    pub friction: Vec<f64>,
    /// Servo increment (m): the plate advances this far per step from settled states only
    /// (every case but the rate study). In (0, 5e-4]: the peak is read from settled states, a
    /// step of a millimetre or more would pass it by, and the servo advances at most half the
    /// contact tolerance (1 mm) a step
    #[arg(
        long,
        value_name = "M",
        value_parser = SERVO_INCREMENT_RANGE.parser(),
        allow_hyphen_values = true,
        default_value = "2e-5"
    )]
    pub servo_increment: f64,
    /// Unbalanced-force ratio at or below which the servo advances the plate. In (0, 0.1]: a
    /// larger ratio is not a settled state, and 0 is never reached
    #[arg(
        long,
        value_name = "RATIO",
        value_parser = SERVO_RATIO_RANGE.parser(),
        allow_hyphen_values = true,
        default_value = "1e-3"
    )]
    pub servo_ratio: f64,
    /// Leave out the rate study (5e-2, 1e-2 and 5e-3 m/s, the paper's study of inertia)
    #[arg(long)]
    pub no_rate_study: bool,
    /// Skip the refined runs of the convergence check (about halves the run time)
    #[arg(long)]
    pub no_convergence_check: bool,
    /// How the loading plate is held: rolling (only its vertical velocity prescribed; the
    /// adopted baseline) or held (its whole velocity prescribed, the paper's "fix velocity")
    #[arg(long, value_enum, default_value = "rolling")]
    pub plate: PlateArg,
    /// Joints of the ring with a friction angle of their own, J=DEG: joint J from 0 (left
    /// springing) to 13 (right springing), DEG in (0, 90); every other joint keeps the case's
    /// angle. Applies to every case but the rate study, as `--plate` does. E.g. 5=40,13=40 keeps
    /// joints 5 and 13 from sliding, and the arch forms the test's mechanism
    #[arg(
        long,
        value_name = "J=DEG[,J=DEG]",
        value_delimiter = ',',
        action = ArgAction::Set,
        value_parser = joint_friction
    )]
    pub joint_friction: Vec<(usize, f64)>,
}

/// One `--joint-friction` entry, `J=DEG`.
fn joint_friction(s: &str) -> Result<(usize, f64), String> {
    let (joint, deg) = s
        .split_once('=')
        .ok_or_else(|| format!("{s:?}: expected J=DEG, a joint's index and its friction angle in degrees"))?;
    let joint: usize = joint
        .trim()
        .parse()
        .map_err(|_| format!("{s:?}: the joint {joint:?} is not an index from 0 to 13"))?;
    Ok((joint, FRICTION_RANGE.parser()(deg.trim())?))
}

/// `--plate`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum PlateArg {
    /// Only the vertical velocity prescribed: free to slide and turn.
    Rolling,
    /// The whole velocity prescribed: straight down, without turning.
    Held,
}

/// Range of `--friction` (°).
pub const FRICTION_RANGE: Interval = Interval {
    lo: Excluded(0.0),
    hi: Excluded(90.0),
};
/// Range of `--servo-increment` (m): at most half the contact tolerance (1 mm), as
/// `voussoir::loading::Servo::run` requires.
pub const SERVO_INCREMENT_RANGE: Interval = Interval {
    lo: Excluded(0.0),
    hi: Included(5e-4),
};
/// Range of `--servo-ratio`.
pub const SERVO_RATIO_RANGE: Interval = Interval {
    lo: Excluded(0.0),
    hi: Included(0.1),
};

/// The largest change of a quasi-static case's peak under refinement (relative).
pub const CONVERGENCE_TOLERANCE: f64 = 0.03;

impl Run for StaticOptions {
    const NAME: &'static str = "arch_static";
    const OUT: &'static str = "out/arch_static";
    const ABOUT: &'static str = "The quasi-static test of the reference arch (Pulatsu, Gonen & Lourenço 2021) \
and the paper's parameter studies, in parallel";

    fn run(&self, out: &Outputs) -> Result<(), BoxError> {
        run_static(self, out)
    }

    fn outputs(&self) -> Vec<String> {
        [
            "summary.json",
            "force_displacement.csv",
            "force_displacement.svg",
            "force_displacement.png",
            "capacity_vs_friction.svg",
            "capacity_vs_friction.png",
        ]
        .map(String::from)
        .into()
    }
}

/// The study cases of the paper, plus the capacity-versus-friction sweep, under servo loading
/// with the options' servo; the rate study last.
fn cases(o: &StaticOptions) -> Result<Vec<StaticCase>, BoxError> {
    let servo = ServoLoading {
        increment: o.servo_increment,
        max_unbalanced_ratio: o.servo_ratio,
    };
    // The library's validation, with its message.
    voussoir::loading::Servo::new(
        voussoir::ids::BlockId(0),
        voussoir::math::Vector::Y,
        servo.increment,
        servo.max_unbalanced_ratio,
    )?;
    let mut base = StaticCase {
        servo: Some(servo),
        plate_support: match o.plate {
            PlateArg::Rolling => PlateSupport::Rolling,
            PlateArg::Held => PlateSupport::Held,
        },
        ..StaticCase::baseline()
    };
    for &(joint, deg) in &o.joint_friction {
        if base.joint_friction.insert(joint, deg).is_some() {
            return Err(format!("--joint-friction: joint {joint} is given twice").into());
        }
    }
    Ok(paper_cases(o, base))
}

fn paper_cases(o: &StaticOptions, base: StaticCase) -> Vec<StaticCase> {
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
    if !o.no_rate_study {
        cases.extend([5e-2, 1e-2, 5e-3].map(StaticCase::rate_study));
    }
    cases
}

#[derive(Serialize)]
struct CaseSummary {
    label: String,
    /// "servo" (quasi-static) or "rate" (the rate study of inertia effects).
    loading: &'static str,
    servo: Option<ServoLoading>,
    friction_deg: f64,
    kn_pa_per_m: f64,
    ks_pa_per_m: f64,
    rate_m_per_s: f64,
    mode: &'static str,
    width_m: f64,
    /// How the plate is held: "rolling" or "held" (`--plate`).
    plate: &'static str,
    /// Joints with a friction angle of their own (`--joint-friction`): joint index → degrees.
    joint_friction_deg: std::collections::BTreeMap<usize, f64>,
    peak_load_kn: f64,
    peak_load_kn_per_m: f64,
    raw_peak_load_kn: f64,
    disp_at_peak_mm: f64,
    /// The peak again with half the servo's increment and threshold (half the rate in the rate
    /// study); absent with `--no-convergence-check`.
    rate_convergence: Option<RateConvergence>,
    end_disp_mm: f64,
    end_load_kn: f64,
    settle_unbalanced_ratio: f64,
    mechanism: MechanismSummary,
    /// The limit analysis of the settled arch (rigid blocks, associative Coulomb joints of the
    /// case's friction, no tension): the plate's load on voussoir 5 at collapse.
    limit_load_kn: f64,
    limit_load_kn_per_m: f64,
    /// DEM peak / limit load − 1 (%): by Radenković's theorem not above 0 but for the DEM's own
    /// errors (`docs/benchmarks/arch-static.md`, "Limit analysis").
    peak_over_limit_percent: f64,
    limit_mechanism: voussoir::analysis::Mechanism,
    /// Per joint of the ring: its opening and sliding rates in the limit mechanism.
    limit_joints: Vec<voussoir::analysis::limit::JointMotion>,
    /// Per joint at the peak and at the end: open fraction, compression position, slip, hinge.
    joints_at_peak: Vec<voussoir::analysis::JointState>,
    joints_at_end: Vec<voussoir::analysis::JointState>,
    steps: u64,
    dt_s: f64,
    subcontacts: usize,
    wall_s: f64,
}

#[derive(Serialize)]
struct RateConvergence {
    peak_kn: f64,
    peak_half_kn: f64,
    /// |peak_half − peak| / peak (%).
    change_percent: f64,
    /// Whether the change is held to the 3 % tolerance (quasi-static cases; the rate study is
    /// reported, not checked).
    checked: bool,
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

fn summarise(r: &StaticResult, convergence: Option<&Convergence>) -> CaseSummary {
    let c = &r.case;
    let end = r.curve.last().copied();
    CaseSummary {
        label: c.label.clone(),
        loading: if c.is_rate_study() { "rate" } else { "servo" },
        servo: c.servo,
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
        plate: match c.plate_support {
            PlateSupport::Rolling => "rolling",
            PlateSupport::Held => "held",
        },
        joint_friction_deg: c.joint_friction.clone(),
        peak_load_kn: r.peak_load / 1e3,
        peak_load_kn_per_m: r.peak_load / 1e3 / c.width,
        raw_peak_load_kn: r.raw_peak_load / 1e3,
        disp_at_peak_mm: r.displacement_at_peak * 1e3,
        rate_convergence: convergence.map(|v| RateConvergence {
            peak_kn: v.value / 1e3,
            peak_half_kn: v.refined / 1e3,
            change_percent: 100.0 * v.relative_change(),
            checked: !c.is_rate_study(),
        }),
        end_disp_mm: end.map_or(0.0, |s| s.displacement * 1e3),
        end_load_kn: end.map_or(0.0, |s| s.load / 1e3),
        settle_unbalanced_ratio: r.settle_ratio,
        mechanism: MechanismSummary {
            at_peak: r.mechanism_at_peak.clone(),
            at_end: r.mechanism_at_end.clone(),
        },
        limit_load_kn: r.limit.load / 1e3,
        limit_load_kn_per_m: r.limit.load / 1e3 / c.width,
        peak_over_limit_percent: 100.0 * (r.peak_load / r.limit.load - 1.0),
        limit_mechanism: r.limit.mechanism.clone(),
        limit_joints: r.limit.joints.clone(),
        joints_at_peak: r.joints_at_peak.clone(),
        joints_at_end: r.joints_at_end.clone(),
        steps: r.steps,
        dt_s: r.dt,
        subcontacts: r.subcontacts,
        wall_s: r.wall_s,
    }
}

fn run_static(o: &StaticOptions, out: &Outputs) -> Result<(), BoxError> {
    let cases = cases(o)?;
    let base = &cases[0];
    let servo = base.servo.unwrap_or(ServoLoading::DEFAULT);
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
        "  {} sub-contacts per joint edge; local damping {}; settle to unbalanced ratio {:.0e}; to {} mm or {}% of peak;",
        base.per_edge,
        base.local_damping,
        base.settle_ratio,
        base.max_displacement * 1e3,
        base.stop_fraction * 100.0
    );
    println!(
        "  servo: {} µm increments from states with unbalanced ratio ≤ {:.0e}, time step {} of the limit{}",
        servo.increment * 1e6,
        servo.max_unbalanced_ratio,
        base.time_step_safety,
        if o.no_convergence_check {
            ""
        } else {
            "; every case also refined (half increment and threshold; rate study: half the rate)"
        }
    );
    let runs: Vec<(StaticResult, Option<Convergence>)> = out.run_all(&cases, "cases", |k, case| {
        out.with_frames((k == 0).then_some("baseline"), 5e-4, |every, frame| {
            if o.no_convergence_check {
                run(case, every, frame).map(|r| (r, None))
            } else {
                run_converged(case, every, frame).map(|(r, c)| (r, Some(c)))
            }
        })
    })?;
    let results: Vec<StaticResult> = runs.iter().map(|r| r.0.clone()).collect();

    println!();
    println!(
        "{:<22} {:>8} {:>8} {:>8} {:>7} {:>8} {:>7}  {:<44} {:>5} {:>8} {:>6}  limit mechanism",
        "case",
        "peak kN",
        "raw kN",
        "kN/m",
        "at mm",
        "refine %",
        "wall s",
        "mechanism at peak (i/e = intrados/extrados)",
        "exp.",
        "limit kN",
        "DEM/LA",
    );
    for (r, c) in &runs {
        let exp = if r.case.label == "baseline" {
            format!("{EXPERIMENT_PEAK_KN}")
        } else {
            String::new()
        };
        println!(
            "{:<22} {:>8.3} {:>8.3} {:>8.2} {:>7.2} {:>8} {:>7.1}  {:<44} {:>5} {:>8.3} {:>6.3}  {}",
            r.case.label,
            r.peak_load / 1e3,
            r.raw_peak_load / 1e3,
            r.peak_load / 1e3 / r.case.width,
            r.displacement_at_peak * 1e3,
            c.map_or("-".into(), |c| format!("{:.2}", 100.0 * c.relative_change())),
            r.wall_s,
            r.mechanism_at_peak.describe(),
            exp,
            r.limit.load / 1e3,
            r.peak_load / r.limit.load,
            r.limit.mechanism.describe()
        );
    }
    println!(
        "(peak: of the settled states under servo loading; in the rate study, of the load averaged over 1 mm of travel, \
raw: with the mechanism's inertial oscillation; refine %: change of the peak when refined; \
limit: rigid-block limit analysis of the settled arch, associative Coulomb joints, docs/theory.md §9)"
    );
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
        adopted: serde_json::to_value(base)?,
        cases: runs.iter().map(|(r, c)| summarise(r, c.as_ref())).collect(),
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
                label: format!("φ = {}°, quasi-static", r.case.friction_deg),
                points: r
                    .curve
                    .iter()
                    .map(|s| (s.displacement * 1e3, s.smoothed_load / 1e3))
                    .collect(),
            })
            .chain(
                results
                    .iter()
                    .filter(|r| r.case.is_rate_study() && r.case.rate == 1e-2)
                    .map(|r| Curve {
                        label: "φ = 30.5°, at 1e-2 m/s (1 mm average)".into(),
                        points: r
                            .curve
                            .iter()
                            .map(|s| (s.displacement * 1e3, s.smoothed_load / 1e3))
                            .collect(),
                    }),
            )
            .collect(),
        references: vec![Reference::Horizontal {
            label: format!("experiment peak {EXPERIMENT_PEAK_KN} kN"),
            y: EXPERIMENT_PEAK_KN,
        }],
        ..Default::default()
    };
    out.plot("force_displacement", &force_displacement)?;
    let mut sweep: Vec<(f64, f64, f64)> = results
        .iter()
        .filter(|r| r.case.label == "baseline" || r.case.label.starts_with("friction"))
        .map(|r| (r.case.friction_deg, r.peak_load / 1e3, r.limit.load / 1e3))
        .collect();
    sweep.sort_by(|a, b| a.0.total_cmp(&b.0));
    let capacity = LinePlot {
        title: "Capacity versus joint friction angle".into(),
        x_label: "friction angle [°]".into(),
        y_label: "peak load [kN]".into(),
        curves: vec![
            Curve {
                label: "model (DEM, quasi-static peak)".into(),
                points: sweep.iter().map(|p| (p.0, p.1)).collect(),
            },
            Curve {
                label: "limit analysis (rigid blocks, associative)".into(),
                points: sweep.iter().map(|p| (p.0, p.2)).collect(),
            },
        ],
        references: vec![Reference::Point {
            label: "experiment (φ = 30.5°)".into(),
            x: 30.5,
            y: EXPERIMENT_PEAK_KN,
        }],
        ..Default::default()
    };
    out.plot("capacity_vs_friction", &capacity)?;
    // The convergence check, after every output is written.
    let unconverged: Vec<String> = runs
        .iter()
        .filter_map(|(r, c)| {
            let c = c.as_ref()?;
            (!r.case.is_rate_study() && !c.converged(CONVERGENCE_TOLERANCE)).then(|| {
                format!(
                    "{} ({:.3} → {:.3} kN, {:.1} %)",
                    r.case.label,
                    c.value / 1e3,
                    c.refined / 1e3,
                    100.0 * c.relative_change()
                )
            })
        })
        .collect();
    if !unconverged.is_empty() {
        return Err(format!(
            "not converged: the peak moved by more than {} % when refined in {}",
            100.0 * CONVERGENCE_TOLERANCE,
            unconverged.join("; ")
        )
        .into());
    }
    Ok(())
}
