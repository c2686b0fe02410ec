//! The six drop-weight impact tests of the reference arch (Pulatsu, Gonen & Lourenço 2021;
//! `docs/benchmarks/arch-impact.md`).
//!
//! ```text
//! cargo run --release --example arch_impact                       # six setups × five drop heights
//! cargo run --release --example arch_impact -- --guide seat       # the steel-seat, guided-DOF variant
//! cargo run --release --example arch_impact -- --width 0.2        # the width sensitivity case
//! cargo run --release --example arch_impact -- --study            # + paper Fig. 14 (kn, damping; M60)
//! cargo run --release --example arch_impact -- --compare-release  # + full-height drops (central runs)
//! ```
//!
//! Flags: `--setup NAME[,NAME]`, `--kn PA_PER_M`, `--damping RATIO`, `--width M`, `--duration S`,
//! `--guide frame|seat`, `--base sloped|flat`, `--release above|full`, `--nodes
//! integrated|point` (how node contacts' springs act, [`voussoir::geometry::NodeRule`];
//! integrated by default),
//! `--offsets MM[,MM]`
//! (drop-height perturbations, default `-0.5,-0.25,0,0.25,0.5`), `--settled-states N` (settled
//! states per drop height perturbed at round-off, default 1; results as medians over all the
//! runs), `--out DIR`, `--study`,
//! `--compare-release`, `--paraview-setups NAME[,NAME]|all`, `--no-paraview`. Writes
//! `summary.json`, one history CSV per setup (with the energy terms), `displacement_time.svg`
//! and `max_disp_vs_experiment.svg` (and as PNG), the viewer `M60H20.html` of M60H20's central run (open it in a
//! browser: the blocks played over time, contacts and forces on demand) and its ParaView series
//! (blocks every 10 ms, sub-contacts every 50 ms: about 15 MB; every setup's with
//! `--paraview-setups all`), and
//! `sensitivity.svg` (and `.png`) with `--study`, under `out/arch_impact/`. The ranges of the
//! numbers (`--help`; [`DAMPING_RANGE`], [`DURATION_RANGE`], ...) are checked when parsed, and a
//! setup or an offset given twice is refused.

use std::ops::Bound::{Excluded, Included};

use clap::builder::PossibleValuesParser;
use clap::{ArgAction, Args};
use voussoir::geometry::NodeRule;

use super::args::{self, Interval};
use super::{BoxError, Outputs, Run};
use crate::plot::{Curve, LegendPosition, LinePlot, Reference};
use crate::scenarios::arch_impact::{
    run, setups, ImpactCase, ImpactResult, ImpactSetup, ImpactorBase, ImpactorGuide, Release,
};
use crate::scenarios::impact_summary::ImpactSummary;

/// The six tests, as `--setup` takes them.
pub const SETUP_NAMES: [&str; 6] = ["M60H20", "M60H25", "M60H30", "M75H20", "M75H45", "M80H45"];

/// The values of `--paraview-setups`: a setup, or `all`.
const PARAVIEW_SETUP_NAMES: [&str; 7] = ["M60H20", "M60H25", "M60H30", "M75H20", "M75H45", "M80H45", "all"];

/// Whether the central run of `setup` writes a ParaView series: it is one of
/// `--paraview-setups` (`all`: every one), or by default M60H20 when it runs, else the first
/// setup that runs (`running`, in order).
fn writes_paraview(o: &ImpactOptions, setup: &str, running: &[&str]) -> bool {
    match &o.paraview_setups {
        Some(names) => names.iter().any(|n| n == "all" || n == setup),
        None if running.contains(&"M60H20") => setup == "M60H20",
        None => running.first() == Some(&setup),
    }
}

/// Range of `--kn` (Pa/m).
pub const KN_RANGE: Interval = Interval {
    lo: Included(1e7),
    hi: Included(1e12),
};
/// Range of `--damping`.
pub const DAMPING_RANGE: Interval = Interval {
    lo: Included(0.0),
    hi: Included(0.2),
};
/// Range of `--width` (m).
pub const WIDTH_RANGE: Interval = Interval {
    lo: Included(0.01),
    hi: Included(1.0),
};
/// Range of `--duration` (s).
pub const DURATION_RANGE: Interval = Interval {
    lo: Excluded(0.0),
    hi: Included(10.0),
};
/// Range of each of `--offsets` (mm).
pub const OFFSET_RANGE_MM: Interval = Interval {
    lo: Included(-100.0),
    hi: Included(100.0),
};

/// Options of the impact runs. Unset numbers keep the scenario's values
/// ([`ImpactCase::baseline`]). Every number is checked against its range when parsed, before
/// anything is computed.
#[derive(Debug, Clone, Args)]
pub struct ImpactOptions {
    /// Setups to run, each at most once [default: all six]
    #[arg(
        long = "setup",
        value_name = "NAME[,NAME]",
        value_delimiter = ',',
        action = ArgAction::Set,
        value_parser = PossibleValuesParser::new(SETUP_NAMES)
    )]
    pub setups: Option<Vec<String>>,
    /// Joint normal stiffness (Pa/m), ks scaled with it [default: 4e9]. In [1e7, 1e12]: the
    /// paper studies 2e9 to 8e9; the time step shrinks as 1/√kn, and a softer joint lets the
    /// blocks sink into each other under their weight
    #[arg(long, value_name = "PA_PER_M", value_parser = KN_RANGE.parser(), allow_hyphen_values = true)]
    pub kn: Option<f64>,
    /// Rayleigh damping ratio: the fraction of critical damping at 25 Hz, stiffness-proportional
    /// [default: 0.01]. In [0, 0.2]: masonry has a few per cent, the paper studies 0.005 to 0.02;
    /// stiffness-proportional damping also shrinks the stable time step (M60H20: 1.7× at 0.01,
    /// 23× at 0.2, against none), so that a larger ratio would not end in reasonable time
    #[arg(long, value_name = "RATIO", value_parser = DAMPING_RANGE.parser(), allow_hyphen_values = true)]
    pub damping: Option<f64>,
    /// Width of the arch (m) [default: 0.15]. In [0.01, 1]: the test arch is 0.15 m wide, the
    /// sensitivity case 0.2 m
    #[arg(long, value_name = "M", value_parser = WIDTH_RANGE.parser(), allow_hyphen_values = true)]
    pub width: Option<f64>,
    /// Duration of each run after release (s) [default: 1.0]. In (0, 10]: the impact is over
    /// within the first second, and a collapse ends the run 0.1 s later
    #[arg(long, value_name = "S", value_parser = DURATION_RANGE.parser(), allow_hyphen_values = true)]
    pub duration: Option<f64>,
    /// How the impactor is guided
    #[arg(long, value_enum, default_value_t = ImpactorGuide::Frame)]
    pub guide: ImpactorGuide,
    /// The impactor's striking face
    #[arg(long, value_enum, default_value_t = ImpactorBase::Sloped)]
    pub base: ImpactorBase,
    /// Where the impactor is released
    #[arg(long, value_enum, default_value_t = Release::JustAbove)]
    pub release: Release,
    /// How node contacts' normal springs act: integrated over the surface each node stands for
    /// (which keeps a collapsing hinge's energy), or at the nodes' points (the library's
    /// default; 1.4–1.6 times faster here, its books off by up to 3.5 % in collapses beyond
    /// the tests' drops)
    #[arg(long, value_name = "RULE", default_value_t = NodeRule::Integrated,
        value_parser = clap::builder::TypedValueParser::map(PossibleValuesParser::new(NodeRule::ALL.map(NodeRule::name)), |s| s.parse::<NodeRule>().expect("a listed rule")))]
    pub nodes: NodeRule,
    /// Drop-height perturbations (mm), each at most once; every setup runs at each, the
    /// smallest reported. Each in [-100, 100] (the lowest drop is 200 mm)
    #[arg(
        long = "offsets",
        value_name = "MM[,MM]",
        value_delimiter = ',',
        action = ArgAction::Set,
        value_parser = OFFSET_RANGE_MM.parser(),
        allow_hyphen_values = true,
        default_value = "-0.5,-0.25,0,0.25,0.5"
    )]
    pub offsets_mm: Vec<f64>,
    /// Settled states per drop height, at most 16: the k-th (k = 0..N) settles under gravity
    /// changed by k·1e-12 of itself, a state that differs from the test's at round-off level;
    /// every result is then the median over drop heights and settled states
    #[arg(long, value_name = "N", value_parser = args::whole::<usize>(1), default_value = "1")]
    pub settled_states: usize,
    /// Setups whose central run writes a ParaView series (blocks every 10 ms, sub-contacts every
    /// 50 ms), or `all` [default: M60H20, or the first setup run without it]: about 15 MB a
    /// standing setup
    #[arg(
        long = "paraview-setups",
        value_name = "NAME[,NAME]|all",
        value_delimiter = ',',
        action = ArgAction::Set,
        value_parser = PossibleValuesParser::new(PARAVIEW_SETUP_NAMES)
    )]
    pub paraview_setups: Option<Vec<String>>,
    /// Add the paper's Fig. 14 study (kn and damping, M60 setups)
    #[arg(long)]
    pub study: bool,
    /// Add the other release (full height or just above) for each setup's central run
    #[arg(long)]
    pub compare_release: bool,
}

impl Run for ImpactOptions {
    const NAME: &'static str = "arch_impact";
    const OUT: &'static str = "out/arch_impact";
    const ABOUT: &'static str = "The six drop-weight impact tests of the reference arch \
(Pulatsu, Gonen & Lourenço 2021), each at five drop heights, in parallel";

    fn run(&self, out: &Outputs) -> Result<(), BoxError> {
        run_impact(self, out)
    }

    /// A setup or a drop-height offset given twice would run twice into the same files.
    fn check(&self) -> Result<(), String> {
        args::unique("--setup", self.setups.as_deref().unwrap_or_default())?;
        args::unique("--paraview-setups", self.paraview_setups.as_deref().unwrap_or_default())?;
        args::unique("--offsets", &self.offsets_mm)?;
        if self.settled_states > 16 {
            return Err(format!(
                "--settled-states: {} is more than 16 (each runs every setup at every drop height)",
                self.settled_states
            ));
        }
        Ok(())
    }

    fn outputs(&self) -> Vec<String> {
        let mut files: Vec<String> = [
            "summary.json",
            "tables.md",
            "displacement_time.svg",
            "displacement_time.png",
            "max_disp_vs_experiment.svg",
            "max_disp_vs_experiment.png",
        ]
        .map(String::from)
        .into();
        if self.study {
            files.extend(["sensitivity.svg".into(), "sensitivity.png".into()]);
        }
        // The unknown setups that `groups` refuses are refused by the parser first.
        if let Ok(groups) = groups(self) {
            files.extend(groups.iter().map(|g| history_file(&g.label)));
        }
        files
    }
}

/// The history file of a group.
fn history_file(label: &str) -> String {
    format!("history_{}.csv", label.replace([' ', '%', '/'], "_"))
}

/// A group of runs that differ only by the drop-height perturbation.
#[derive(Clone)]
struct Group {
    label: String,
    /// `main` (one per setup), `study` or `release`.
    kind: &'static str,
    base: ImpactCase,
}

fn groups(o: &ImpactOptions) -> Result<Vec<Group>, String> {
    let all = setups();
    let chosen: Vec<ImpactSetup> = match &o.setups {
        None => all.clone(),
        Some(names) => names
            .iter()
            .map(|n| {
                all.iter()
                    .find(|s| &s.name == n)
                    .cloned()
                    .ok_or(format!("unknown setup {n:?}"))
            })
            .collect::<Result<_, _>>()?,
    };
    let configure = |s: &ImpactSetup| {
        let mut c = ImpactCase::baseline(s.clone());
        c.guide = o.guide;
        c.base = o.base;
        c.release = o.release;
        c.node_rule = o.nodes;
        if let Some(kn) = o.kn {
            c.ks = kn * c.ks / c.kn;
            c.kn = kn;
        }
        if let Some(d) = o.damping {
            c.damping_ratio = d;
        }
        if let Some(w) = o.width {
            c.width = w;
        }
        if let Some(t) = o.duration {
            c.duration = t;
        }
        c
    };
    let mut out: Vec<Group> = chosen
        .iter()
        .map(|s| Group {
            label: s.name.clone(),
            kind: "main",
            base: configure(s),
        })
        .collect();
    if o.study {
        // Paper Fig. 14: kn 2, 4, 8 GPa/m at 1 %; damping 0.5, 1, 2 % at 4 GPa/m. The 4 GPa/m, 1 %
        // point is the main run.
        for s in all.iter().filter(|s| s.name.starts_with("M60")) {
            let base = configure(s);
            for kn in [2e9, 8e9] {
                out.push(Group {
                    label: format!("{} kn {} GPa/m", s.name, kn / 1e9),
                    kind: "study",
                    base: ImpactCase {
                        ks: kn * base.ks / base.kn,
                        kn,
                        ..base.clone()
                    },
                });
            }
            for d in [0.005, 0.02] {
                out.push(Group {
                    label: format!("{} damping {} %", s.name, d * 100.0),
                    kind: "study",
                    base: ImpactCase {
                        damping_ratio: d,
                        ..base.clone()
                    },
                });
            }
            if !chosen.iter().any(|c| c.name == s.name) {
                out.push(Group {
                    label: s.name.clone(),
                    kind: "study",
                    base,
                });
            }
        }
    }
    if o.compare_release {
        let other = match o.release {
            Release::JustAbove => Release::FullHeight,
            Release::FullHeight => Release::JustAbove,
        };
        for s in &chosen {
            out.push(Group {
                label: format!("{} release {}", s.name, release_name(other)),
                kind: "release",
                base: ImpactCase {
                    release: other,
                    ..configure(s)
                },
            });
        }
    }
    for g in &mut out {
        g.base.label = g.label.clone();
    }
    Ok(out)
}

fn release_name(r: Release) -> &'static str {
    match r {
        Release::JustAbove => "just above",
        Release::FullHeight => "full height",
    }
}

fn guide_name(g: ImpactorGuide) -> &'static str {
    match g {
        ImpactorGuide::Frame => "free impactor between fixed frame blocks (contacts only)",
        ImpactorGuide::SeatConstrained => "steel seat on voussoir 5, impactor guided by constrained DOFs",
    }
}

/// The results of one group, central run first.
struct Outcome<'a> {
    group: &'a Group,
    central: &'a ImpactResult,
    runs: Vec<&'a ImpactResult>,
}

impl Outcome<'_> {
    fn summary(&self) -> ImpactSummary {
        ImpactSummary::of(&self.group.label, self.group.kind, self.central, &self.runs)
    }
}

fn history_csv(r: &ImpactResult) -> String {
    let mut csv = String::from(
        "time [s],quarter-span displacement [m],velocity [m/s],acceleration [m/s2],impact force [N],\
impactor velocity [m/s],impactor drift x [m],impactor drift z [m],kinetic [J],impactor kinetic [J],\
ring potential [J],elastic [J],friction [J],damping [J],gravity work [J],energy input [J],energy accounted [J]\n",
    );
    for s in &r.samples {
        csv.push_str(&format!(
            "{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e}\n",
            s.time,
            s.disp,
            s.velocity,
            s.accel,
            s.impact_force,
            s.impactor_velocity,
            s.impactor_drift_x,
            s.impactor_drift_z,
            s.kinetic,
            s.impactor_kinetic,
            s.arch_potential,
            s.elastic,
            s.friction,
            s.damping,
            s.gravity_work,
            s.input,
            s.accounted
        ));
    }
    csv
}

/// Markdown tables of the run, for `docs/benchmarks/arch-impact.md`.
fn markdown(outcomes: &[Outcome], agree: usize, main_count: usize) -> String {
    let mm = |x: f64| format!("{:.1}", x * 1e3);
    let verdict = |c: bool| if c { "collapse" } else { "stands" };
    let mut md = String::new();
    md.push_str(&format!(
        "Outcomes as observed (central runs): **{agree} of {main_count}**.\n\n\
| run | E [J] | model | test | collapsed runs | first impact [mm] | max [mm] | median of max [mm] | spread of max [mm] | test max [mm] | median / test | v max [m/s] | test v | a max [m/s²] | test a | rise [mm] at [s] |\n\
|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n"
    ));
    for x in outcomes {
        let r = x.central;
        let s = &r.case.setup;
        let sp = x.summary().spread_max_disp_m;
        let sp1 = x.summary().spread_first_peak_disp_m;
        let median = x.summary().median_max_disp_m;
        md.push_str(&format!(
            "| {} | {:.1} | {} | {} | {}/{} | {} ({}–{}) | {} | {} | {}–{} | {} | {} | {:.2} | {:.2} | {:.0} | {:.0} | {} at {:.3} |\n",
            x.group.label,
            r.kinetic_energy,
            verdict(r.collapsed),
            verdict(s.collapsed),
            x.summary().collapsed_runs,
            x.runs.len(),
            mm(r.first_peak_disp),
            mm(sp1[0]),
            mm(sp1[1]),
            mm(r.max_disp),
            mm(median),
            mm(sp[0]),
            mm(sp[1]),
            s.max_disp.map_or("—".into(), mm),
            s.max_disp.map_or("—".into(), |d| format!("{:.2}", median / d)),
            r.max_velocity,
            s.max_velocity,
            r.max_accel,
            s.max_accel,
            mm(r.max_rise),
            r.max_rise_time
        ));
    }
    md.push_str(
        "\nEnergy balance of the central runs, changes from just before release to the end of the run (J):\n\n\
| run | input | kinetic | elastic | friction | damping | gravity work | ring potential | max \\|error\\| | steps | dt [s] | wall [s] |\n\
|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for x in outcomes {
        let r = x.central;
        if let Some(l) = r.samples.last() {
            md.push_str(&format!(
                "| {} | {:.1} | {:.2} | {:.2} | {:.1} | {:.1} | {:.1} | {:.1} | {:.3} | {} | {:.2e} | {:.2} |\n",
                x.group.label,
                l.input,
                l.kinetic,
                l.elastic,
                l.friction,
                l.damping,
                l.gravity_work,
                l.arch_potential,
                r.max_energy_error,
                r.steps,
                r.dt,
                r.wall_s
            ));
        }
    }
    md
}

fn run_impact(o: &ImpactOptions, out: &Outputs) -> Result<(), BoxError> {
    let groups = groups(o)?;
    // The setups that run, in order (for the default of `--paraview-setups`).
    let running: Vec<&str> = groups
        .iter()
        .filter(|g| g.kind == "main")
        .map(|g| g.base.setup.name.as_str())
        .collect();
    // Every group runs at every drop-height perturbation (the central one first).
    let mut offsets: Vec<f64> = o.offsets_mm.iter().map(|mm| mm * 1e-3).collect();
    offsets.sort_by(|a, b| a.abs().total_cmp(&b.abs()));
    let cases: Vec<(usize, ImpactCase)> = groups
        .iter()
        .enumerate()
        .flat_map(|(k, g)| {
            offsets.iter().flat_map(move |&dh| {
                (0..o.settled_states).map(move |state| {
                    (
                        k,
                        ImpactCase {
                            height_offset: dh,
                            settle_perturbation: state as f64 * 1e-12,
                            ..g.base.clone()
                        },
                    )
                })
            })
        })
        .collect();
    // Every case's parameters, before any is computed.
    for (_, case) in &cases {
        case.validate()?;
    }
    let base = &groups[0].base;
    println!(
        "Drop-weight impact tests of the reference arch (Pulatsu et al. 2021): {} groups × {} drop heights × {} settled states = {} runs",
        groups.len(),
        offsets.len(),
        o.settled_states,
        cases.len()
    );
    println!(
        "Adopted (docs/benchmarks/arch-impact.md): width {} m; impactor {} m along the span × {} m × width, {};",
        base.width,
        base.impactor_length,
        base.impactor_height,
        guide_name(base.guide)
    );
    if base.guide == ImpactorGuide::Frame {
        println!(
            "  base {:?} (parallel to the 20.7° extrados of voussoir 5 when sloped), striking voussoir 5 directly; frame blocks {} m thick, {} mm away, impactor–frame joint φ {}° (frictionless at 0), {} mm above the extrados;",
            base.base,
            base.guide_thickness,
            base.guide_clearance * 1e3,
            base.guide_friction_deg,
            base.guide_standoff * 1e3
        );
    }
    println!(
        "  release {} ({} mm gap, speed √(2g(H − gap)), so that it strikes at √(2gH)); drop heights H + {:?} mm; arch settled first (local damping 0.8);",
        release_name(base.release),
        base.release_gap * 1e3,
        o.offsets_mm
    );
    println!(
        "  joints kn {:.1e} Pa/m, ks {:.1e} Pa/m, φ {}°; Rayleigh {} % stiffness-proportional at {} Hz; {} s; large displacements; node contacts {};",
        base.kn,
        base.ks,
        base.friction_deg,
        base.damping_ratio * 100.0,
        base.damping_frequency,
        base.duration,
        match base.node_rule {
            NodeRule::Point => "at their points",
            NodeRule::Integrated => "integrated",
        }
    );
    println!("  collapse rule: a voussoir's centroid drops by more than half the ring thickness (0.1 m).");
    let results: Vec<(usize, ImpactResult)> = out.run_all(&cases, "impact runs", |_, (k, case)| {
        let central = groups[*k].kind == "main" && case.height_offset == 0.0 && case.settle_perturbation == 0.0;
        let frames = central && writes_paraview(o, &case.setup.name, &running);
        out.with_frames_and_subcontacts(frames.then_some(case.setup.name.as_str()), 0.01, 5, |every, frame| {
            run(case, every, frame)
        })
        .map(|r| (*k, r))
    })?;
    let outcomes: Vec<Outcome> = groups
        .iter()
        .enumerate()
        .map(|(k, g)| {
            let runs: Vec<&ImpactResult> = results.iter().filter(|(i, _)| *i == k).map(|(_, r)| r).collect();
            Outcome {
                group: g,
                central: runs[0],
                runs,
            }
        })
        .collect();

    println!();
    println!(
        "{:<26} {:>6} {:>8} {:>8} {:>8} {:>13} {:>6} {:>6} {:>6} {:>7} {:>6} {:>8} {:>7} {:>9}",
        "run",
        "E [J]",
        "1st[mm]",
        "max[mm]",
        "median",
        "spread [mm]",
        "exp",
        "rise",
        "v m/s",
        "exp v",
        "a/1e3",
        "|err| J",
        "coll.",
        "outcome"
    );
    for x in &outcomes {
        let r = x.central;
        let s = &r.case.setup;
        let verdict = |c: bool| if c { "collapse" } else { "stands" };
        let exp_disp = s.max_disp.map_or("—".to_owned(), |d| format!("{:.0}", d * 1e3));
        let sp = x.summary().spread_max_disp_m;
        println!(
            "{:<26} {:>6.1} {:>8.1} {:>8.1} {:>8.1} {:>6.1}–{:<6.1} {:>6} {:>6.1} {:>6.2} {:>7.2} {:>6.2} {:>8.2} {:>4}/{:<2} {} / test {}",
            x.group.label,
            r.kinetic_energy,
            r.first_peak_disp * 1e3,
            r.max_disp * 1e3,
            x.summary().median_max_disp_m * 1e3,
            sp[0] * 1e3,
            sp[1] * 1e3,
            exp_disp,
            r.max_rise * 1e3,
            r.max_velocity,
            s.max_velocity,
            r.max_accel / 1e3,
            r.max_energy_error,
            x.summary().collapsed_runs,
            x.runs.len(),
            verdict(r.collapsed),
            verdict(s.collapsed)
        );
    }
    let main: Vec<&Outcome> = outcomes.iter().filter(|x| x.group.kind == "main").collect();
    let agree = main
        .iter()
        .filter(|x| x.central.collapsed == x.central.case.setup.collapsed)
        .count();
    println!(
        "\ncollapse / no collapse as observed: {agree} of {} setups (central runs)",
        main.len()
    );
    let wall: Vec<f64> = results.iter().map(|(_, r)| r.wall_s).collect();
    println!(
        "per-run wall {:.2}–{:.2} s (mean {:.2} s)",
        wall.iter().copied().fold(f64::INFINITY, f64::min),
        wall.iter().copied().fold(0.0, f64::max),
        wall.iter().sum::<f64>() / wall.len() as f64
    );

    let summary = serde_json::json!({
        "parameters": base,
        "height_offsets_m": offsets,
        "collapse_rule": "a voussoir's centroid drops by more than half the ring thickness below its settled position",
        "outcomes_as_observed": agree,
        "setups": main.iter().map(|x| x.summary()).collect::<Vec<_>>(),
        "study": outcomes.iter().filter(|x| x.group.kind == "study").map(|x| x.summary()).collect::<Vec<_>>(),
        "release_comparison": outcomes.iter().filter(|x| x.group.kind == "release").map(|x| x.summary()).collect::<Vec<_>>(),
        "total_wall_s": out.elapsed(),
    });
    out.json("summary.json", &summary)?;
    out.text("tables.md", &markdown(&outcomes, agree, main.len()))?;
    for x in &outcomes {
        out.text(&history_file(&x.group.label), &history_csv(x.central))?;
    }
    let displacement_time = LinePlot {
        title: "Quarter-span vertical displacement".into(),
        x_label: "time after release [s]".into(),
        y_label: "displacement [mm]".into(),
        curves: main
            .iter()
            .map(|x| Curve {
                label: x.central.case.setup.name.clone(),
                points: x.central.samples.iter().map(|s| (s.time, s.disp * 1e3)).collect(),
            })
            .collect(),
        references: Vec::new(),
        legend: LegendPosition::Auto,
    };
    out.plot("displacement_time", &displacement_time)?;
    let standing: Vec<&&Outcome> = main
        .iter()
        .filter(|x| x.central.case.setup.max_disp.is_some())
        .collect();
    let refs: Vec<Reference> = standing
        .iter()
        .map(|x| Reference::Point {
            label: format!("{} test", x.central.case.setup.name),
            x: x.central.kinetic_energy,
            y: x.central.case.setup.max_disp.unwrap_or(0.0) * 1e3,
        })
        .collect();
    let curve = |label: &str, f: &dyn Fn(&Outcome) -> f64| Curve {
        label: label.into(),
        points: standing
            .iter()
            .map(|x| (x.central.kinetic_energy, f(x) * 1e3))
            .collect(),
    };
    let max_disp = LinePlot {
        title: "Maximum quarter-span displacement: model vs test (cf. paper Fig. 13)".into(),
        x_label: "impact energy [J]".into(),
        y_label: "max displacement [mm]".into(),
        curves: vec![
            curve("model (M60 setups)", &|x| x.central.max_disp),
            curve("model, lowest of ±0.5 mm drops", &|x| x.summary().spread_max_disp_m[0]),
            curve("model, highest of ±0.5 mm drops", &|x| {
                x.summary().spread_max_disp_m[1]
            }),
        ],
        references: refs,
        legend: LegendPosition::Auto,
    };
    out.plot("max_disp_vs_experiment", &max_disp)?;
    if o.study {
        let mut curves = Vec::new();
        for s in ["M60H20", "M60H25", "M60H30"] {
            let pick = |pred: &dyn Fn(&ImpactCase) -> Option<f64>| -> Vec<(f64, f64)> {
                let mut v: Vec<(f64, f64)> = outcomes
                    .iter()
                    .filter(|x| x.central.case.setup.name == s && x.group.kind != "release")
                    .filter_map(|x| pred(&x.central.case).map(|p| (p, x.central.max_disp * 1e3)))
                    .collect();
                v.sort_by(|a, b| a.0.total_cmp(&b.0));
                v.dedup_by(|a, b| a.0 == b.0);
                v
            };
            curves.push(Curve {
                label: format!("{s}: vs kn [GPa/m]"),
                points: pick(&|c| (c.damping_ratio == base.damping_ratio).then_some(c.kn / 1e9)),
            });
            curves.push(Curve {
                label: format!("{s}: vs damping [%]"),
                points: pick(&|c| (c.kn == base.kn).then_some(c.damping_ratio * 100.0)),
            });
        }
        let sensitivity = LinePlot {
            title: "Sensitivity of the maximum displacement (cf. paper Fig. 14)".into(),
            x_label: "kn [GPa/m] or damping ratio [%]".into(),
            y_label: "max displacement [mm]".into(),
            curves,
            references: Vec::new(),
            legend: LegendPosition::Auto,
        };
        out.plot("sensitivity", &sensitivity)?;
    }
    Ok(())
}
