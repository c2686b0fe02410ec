//! The six drop-weight impact tests of the reference arch (Pulatsu, Gonen & Lourenço 2021;
//! `BENCHMARKS.md` §4).
//!
//! ```text
//! cargo run --release --example arch_impact                       # all six setups, in parallel
//! cargo run --release --example arch_impact -- --setup M60H20 --kn 8e9 --damping 0.02
//! cargo run --release --example arch_impact -- --study            # kn and damping sensitivity (M60)
//! ```
//!
//! Flags: `--setup NAME[,NAME]`, `--kn PA_PER_M`, `--damping RATIO`, `--width M`, `--duration S`,
//! `--out DIR`, `--study`, `--no-paraview`. Writes `summary.json`, one history CSV per setup,
//! `displacement_time.svg`, `max_disp_vs_experiment.svg`, a ParaView series per setup (and
//! `sensitivity.svg` with `--study`) under `out/arch_impact/`.

use std::path::PathBuf;
use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;
use voussoir::io::plot::{Curve, LinePlot, Reference};
use voussoir::io::{progress, vtk, write_json};
use voussoir::scenarios::arch_impact::{run, setups, ImpactCase, ImpactResult};

struct Options {
    out: PathBuf,
    setups: Option<Vec<String>>,
    kn: Option<f64>,
    damping: Option<f64>,
    width: Option<f64>,
    duration: Option<f64>,
    study: bool,
    paraview: bool,
}

fn parse() -> Result<Options, String> {
    let mut o = Options {
        out: PathBuf::from("out/arch_impact"),
        setups: None,
        kn: None,
        damping: None,
        width: None,
        duration: None,
        study: false,
        paraview: true,
    };
    let mut args = std::env::args().skip(1);
    let number = |name: &str, v: Option<String>| -> Result<f64, String> {
        let v = v.ok_or(format!("{name} needs a value"))?;
        v.parse().map_err(|_| format!("{name}: not a number: {v:?}"))
    };
    while let Some(a) = args.next() {
        match a.as_str() {
            "--out" => o.out = args.next().ok_or("--out needs a folder")?.into(),
            "--setup" => {
                o.setups = Some(
                    args.next()
                        .ok_or("--setup needs a name")?
                        .split(',')
                        .map(str::to_owned)
                        .collect(),
                )
            }
            "--kn" => o.kn = Some(number("--kn", args.next())?),
            "--damping" => o.damping = Some(number("--damping", args.next())?),
            "--width" => o.width = Some(number("--width", args.next())?),
            "--duration" => o.duration = Some(number("--duration", args.next())?),
            "--study" => o.study = true,
            "--no-paraview" => o.paraview = false,
            "-h" | "--help" => {
                println!("arch_impact [--setup M60H20,..] [--kn 4e9] [--damping 0.01] [--width 0.15] [--duration 1.0] [--out DIR] [--study] [--no-paraview]");
                std::process::exit(0);
            }
            other => return Err(format!("unknown argument {other:?} (try --help)")),
        }
    }
    Ok(o)
}

fn cases(o: &Options) -> Result<Vec<ImpactCase>, String> {
    let all = setups();
    let chosen: Vec<_> = match &o.setups {
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
    let configure = |s: &voussoir::scenarios::arch_impact::ImpactSetup| {
        let mut c = ImpactCase::baseline(s.clone());
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
    let mut cases: Vec<ImpactCase> = chosen.iter().map(configure).collect();
    if o.study {
        for s in all.iter().filter(|s| s.name.starts_with("M60")) {
            let base = configure(s);
            for kn in [2e9, 8e9] {
                cases.push(ImpactCase {
                    label: format!("{} kn {} GPa/m", s.name, kn / 1e9),
                    ks: kn * base.ks / base.kn,
                    kn,
                    ..base.clone()
                });
            }
            for d in [0.005, 0.02] {
                cases.push(ImpactCase {
                    label: format!("{} damping {} %", s.name, d * 100.0),
                    damping_ratio: d,
                    ..base.clone()
                });
            }
        }
    }
    Ok(cases)
}

#[derive(Serialize)]
struct Experiment {
    collapsed: bool,
    max_disp_m: Option<f64>,
    max_velocity_m_per_s: f64,
    max_accel_m_per_s2: f64,
}

#[derive(Serialize)]
struct SetupSummary {
    name: String,
    label: String,
    mass_kg: f64,
    height_m: f64,
    v0_m_per_s: f64,
    impact_energy_j: f64,
    kn_pa_per_m: f64,
    damping_ratio: f64,
    width_m: f64,
    first_peak_disp_m: f64,
    max_disp_m: f64,
    max_velocity_m_per_s: f64,
    max_accel_m_per_s2: f64,
    max_impact_force_n: f64,
    collapsed: bool,
    collapse_time_s: Option<f64>,
    max_energy_excess_j: f64,
    steps: u64,
    dt_s: f64,
    steps_per_s: f64,
    wall_s: f64,
    experiment: Experiment,
}

fn summarise(r: &ImpactResult) -> SetupSummary {
    let c = &r.case;
    let s = &c.setup;
    SetupSummary {
        name: s.name.clone(),
        label: c.label.clone(),
        mass_kg: s.mass,
        height_m: s.height,
        v0_m_per_s: r.v0,
        impact_energy_j: r.kinetic_energy,
        kn_pa_per_m: c.kn,
        damping_ratio: c.damping_ratio,
        width_m: c.width,
        first_peak_disp_m: r.first_peak_disp,
        max_disp_m: r.max_disp,
        max_velocity_m_per_s: r.max_velocity,
        max_accel_m_per_s2: r.max_accel,
        max_impact_force_n: r.max_impact_force,
        collapsed: r.collapsed,
        collapse_time_s: r.collapse_time,
        max_energy_excess_j: r.max_energy_excess,
        steps: r.steps,
        dt_s: r.dt,
        steps_per_s: r.steps as f64 / r.wall_s,
        wall_s: r.wall_s,
        experiment: Experiment {
            collapsed: s.collapsed,
            max_disp_m: s.max_disp,
            max_velocity_m_per_s: s.max_velocity,
            max_accel_m_per_s2: s.max_accel,
        },
    }
}

fn main() {
    if let Err(e) = try_main() {
        eprintln!("arch_impact: {e}");
        std::process::exit(1);
    }
}

fn try_main() -> Result<(), Box<dyn std::error::Error>> {
    let o = parse()?;
    let started = Instant::now();
    let cases = cases(&o)?;
    let base = &cases[0];
    println!(
        "Drop-weight impact tests of the reference arch (Pulatsu et al. 2021), {} runs",
        cases.len()
    );
    println!(
        "Adopted (BENCHMARKS.md): width {} m; impactor {} m × {} m × width, guided (only vertical translation free),",
        base.width, base.impactor_length, base.impactor_height
    );
    println!(
        "  released {} mm above a steel seat on voussoir 5 with v0 = √(2gH); arch settled first (local damping 0.8);",
        base.release_gap * 1e3
    );
    println!(
        "  joints kn {:.1e} Pa/m, ks {:.1e} Pa/m, φ {}°; Rayleigh {} % stiffness-proportional at {} Hz; {} s; large displacements;",
        base.kn,
        base.ks,
        base.friction_deg,
        base.damping_ratio * 100.0,
        base.damping_frequency,
        base.duration
    );
    println!("  collapse rule: a voussoir's centroid drops by more than half the ring thickness (0.1 m).");
    let bar = progress::bar(cases.len() as u64, "impact runs");
    let results: Vec<ImpactResult> = cases
        .par_iter()
        .map(|case| {
            let result = if o.paraview && case.label == case.setup.name {
                let mut series = vtk::Series::new(o.out.join("paraview"), &case.setup.name);
                run(case, Some(0.01), |m| series.write_frame(m))
            } else {
                run(case, None, |_| Ok(()))
            };
            bar.inc(1);
            result
        })
        .collect::<Result<_, _>>()?;
    bar.finish_and_clear();

    println!();
    println!(
        "{:<24} {:>7} {:>9} {:>9} {:>9} {:>8} {:>8} {:>10} {:>9} {:>7} {:>9}",
        "run",
        "E [J]",
        "1st [mm]",
        "max [mm]",
        "exp [mm]",
        "v [m/s]",
        "exp v",
        "a [m/s²]",
        "exp a",
        "wall s",
        "steps/s"
    );
    for r in &results {
        let s = &r.case.setup;
        let verdict = |c: bool| if c { "collapse" } else { "stands" };
        let exp_disp = s.max_disp.map_or("—".to_owned(), |d| format!("{:.0}", d * 1e3));
        println!(
            "{:<24} {:>7.1} {:>9.1} {:>9.1} {:>9} {:>8.2} {:>8.2} {:>10.0} {:>9.0} {:>7.1} {:>9.0}   model {} / test {}",
            r.case.label,
            r.kinetic_energy,
            r.first_peak_disp * 1e3,
            r.max_disp * 1e3,
            exp_disp,
            r.max_velocity,
            s.max_velocity,
            r.max_accel,
            s.max_accel,
            r.wall_s,
            r.steps as f64 / r.wall_s,
            verdict(r.collapsed),
            verdict(s.collapsed)
        );
    }
    let agree = results
        .iter()
        .filter(|r| r.case.label == r.case.setup.name && r.collapsed == r.case.setup.collapsed)
        .count();
    let total = results.iter().filter(|r| r.case.label == r.case.setup.name).count();
    println!("\ncollapse / no collapse as observed: {agree} of {total} setups");

    std::fs::create_dir_all(&o.out)?;
    let summary = serde_json::json!({
        "parameters": base,
        "collapse_rule": "a voussoir's centroid drops by more than half the ring thickness below its settled position",
        "setups": results.iter().map(summarise).collect::<Vec<_>>(),
        "total_wall_s": started.elapsed().as_secs_f64(),
    });
    write_json(&o.out.join("summary.json"), &summary)?;
    for r in &results {
        let mut csv = String::from("time [s],quarter-span displacement [m],velocity [m/s],acceleration [m/s2],impact force [N],impactor velocity [m/s],kinetic [J],energy input [J],energy accounted [J]\n");
        for s in &r.samples {
            csv.push_str(&format!(
                "{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e}\n",
                s.time,
                s.disp,
                s.velocity,
                s.accel,
                s.impact_force,
                s.impactor_velocity,
                s.kinetic,
                s.input,
                s.accounted
            ));
        }
        let file = format!("history_{}.csv", r.case.label.replace([' ', '%', '/'], "_"));
        std::fs::write(o.out.join(file), csv)?;
    }
    let main_runs: Vec<&ImpactResult> = results.iter().filter(|r| r.case.label == r.case.setup.name).collect();
    LinePlot {
        title: "Quarter-span vertical displacement".into(),
        x_label: "time after impact [s]".into(),
        y_label: "displacement [mm]".into(),
        curves: main_runs
            .iter()
            .map(|r| Curve {
                label: r.case.setup.name.clone(),
                points: r.samples.iter().map(|s| (s.time, s.disp * 1e3)).collect(),
            })
            .collect(),
        references: Vec::new(),
    }
    .write_svg(&o.out.join("displacement_time.svg"))?;
    let standing: Vec<&&ImpactResult> = main_runs.iter().filter(|r| r.case.setup.max_disp.is_some()).collect();
    let mut refs: Vec<Reference> = standing
        .iter()
        .map(|r| Reference::Point {
            label: format!("{} test", r.case.setup.name),
            x: r.kinetic_energy,
            y: r.case.setup.max_disp.unwrap_or(0.0) * 1e3,
        })
        .collect();
    refs.truncate(3);
    LinePlot {
        title: "Maximum quarter-span displacement: model vs test (cf. paper Fig. 13)".into(),
        x_label: "impact energy [J]".into(),
        y_label: "max displacement [mm]".into(),
        curves: vec![Curve {
            label: "model (M60 setups)".into(),
            points: standing.iter().map(|r| (r.kinetic_energy, r.max_disp * 1e3)).collect(),
        }],
        references: refs,
    }
    .write_svg(&o.out.join("max_disp_vs_experiment.svg"))?;
    if o.study {
        let mut curves = Vec::new();
        for s in ["M60H20", "M60H25", "M60H30"] {
            let pick = |pred: &dyn Fn(&ImpactResult) -> Option<f64>| -> Vec<(f64, f64)> {
                let mut v: Vec<(f64, f64)> = results
                    .iter()
                    .filter(|r| r.case.setup.name == s)
                    .filter_map(|r| pred(r).map(|x| (x, r.max_disp * 1e3)))
                    .collect();
                v.sort_by(|a, b| a.0.total_cmp(&b.0));
                v
            };
            curves.push(Curve {
                label: format!("{s}: vs kn [GPa/m]"),
                points: pick(&|r| (r.case.damping_ratio == base.damping_ratio).then_some(r.case.kn / 1e9)),
            });
            curves.push(Curve {
                label: format!("{s}: vs damping [%]"),
                points: pick(&|r| (r.case.kn == base.kn).then_some(r.case.damping_ratio * 100.0)),
            });
        }
        LinePlot {
            title: "Sensitivity of the maximum displacement (cf. paper Fig. 14)".into(),
            x_label: "kn [GPa/m] or damping ratio [%]".into(),
            y_label: "max displacement [mm]".into(),
            curves,
            references: Vec::new(),
        }
        .write_svg(&o.out.join("sensitivity.svg"))?;
    }
    println!(
        "outputs in {} ({:.1} s wall)",
        o.out.display(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}
