//! `voussoir.scenarios`: the reference arch's quasi-static and impact tests (the
//! `voussoir-arch` crate's scenarios), returning what their `summary.json` holds per case.
//!
//! The command line's summary structures are private to `voussoir-arch`'s `cli`; the dicts here
//! are built field for field the same (`arch/src/cli/arch_static.rs` `CaseSummary`,
//! `arch/src/cli/arch_impact.rs` `GroupSummary`), plus the data of the CSV files (`curve`,
//! `history`).

use pyo3::prelude::*;
use rayon::prelude::*;
use serde_json::{json, Value};
use voussoir::contact::DisplacementMode;
use voussoir::loading::Convergence;
use voussoir::model::Model;
use voussoir_arch::scenarios::arch_impact::{
    self as impact, ImpactCase, ImpactResult, ImpactSample, ImpactorBase, ImpactorGuide, Release,
};
use voussoir_arch::scenarios::arch_static::{self as statics, ServoLoading, StaticCase, StaticResult};
use voussoir_arch::scenarios::impact_summary::ImpactSummary;

use crate::convert::json_to_py;
use crate::errors::{bad, OrPy};

/// Plate travel (m) and time (s) between two looks for Ctrl-C during a scenario.
const STATIC_CHECK_TRAVEL: f64 = 1e-4;
const IMPACT_CHECK_TIME: f64 = 2e-3;

/// Runs `f` with the GIL released; `f` is handed an observer of frames that looks for Ctrl-C
/// (a KeyboardInterrupt stops the run between steps and is raised here).
fn interruptible<T: Send>(
    py: Python<'_>,
    f: impl FnOnce(&(dyn Fn(&Model) -> voussoir::Result<()> + Sync)) -> voussoir::Result<T> + Send,
) -> PyResult<T> {
    let interrupt = std::sync::Mutex::new(None::<PyErr>);
    let check = |_: &Model| -> voussoir::Result<()> {
        match Python::attach(|py| py.check_signals()) {
            Ok(()) => Ok(()),
            Err(e) => {
                *interrupt.lock().expect("not poisoned") = Some(e);
                Err(voussoir::Error::Unsupported {
                    what: "interrupted".into(),
                })
            }
        }
    };
    let result = py.detach(|| f(&check));
    if let Some(e) = interrupt.into_inner().expect("not poisoned") {
        return Err(e);
    }
    result.py()
}

fn static_summary(r: &StaticResult, convergence: Option<&Convergence>) -> Value {
    let c = &r.case;
    let end = r.curve.last().copied();
    json!({
        "label": c.label,
        "loading": if c.is_rate_study() { "rate" } else { "servo" },
        "servo": c.servo,
        "friction_deg": c.friction_deg,
        "kn_pa_per_m": c.kn,
        "ks_pa_per_m": c.ks,
        "rate_m_per_s": c.rate,
        "mode": if c.mode == DisplacementMode::Large { "large" } else { "small" },
        "width_m": c.width,
        "plate": match c.plate_support {
            statics::PlateSupport::Rolling => "rolling",
            statics::PlateSupport::Held => "held",
        },
        "joint_friction_deg": c.joint_friction,
        "peak_load_kn": r.peak_load / 1e3,
        "peak_load_kn_per_m": r.peak_load / 1e3 / c.width,
        "raw_peak_load_kn": r.raw_peak_load / 1e3,
        "disp_at_peak_mm": r.displacement_at_peak * 1e3,
        "rate_convergence": convergence.map(|v| json!({
            "peak_kn": v.value / 1e3,
            "peak_half_kn": v.refined / 1e3,
            "change_percent": 100.0 * v.relative_change(),
            "checked": !c.is_rate_study(),
        })),
        "end_disp_mm": end.map_or(0.0, |s| s.displacement * 1e3),
        "end_load_kn": end.map_or(0.0, |s| s.load / 1e3),
        "settle_unbalanced_ratio": r.settle_ratio,
        "mechanism": { "at_peak": r.mechanism_at_peak, "at_end": r.mechanism_at_end },
        "joints_at_peak": r.joints_at_peak,
        "joints_at_end": r.joints_at_end,
        "steps": r.steps,
        "dt_s": r.dt,
        "subcontacts": r.subcontacts,
        "wall_s": r.wall_s,
        // Not in summary.json: the case's rows of force_displacement.csv.
        "curve": {
            "displacement_mm": r.curve.iter().map(|s| s.displacement * 1e3).collect::<Vec<_>>(),
            "load_kn": r.curve.iter().map(|s| s.load / 1e3).collect::<Vec<_>>(),
            "smoothed_load_kn": r.curve.iter().map(|s| s.smoothed_load / 1e3).collect::<Vec<_>>(),
            "left_support_dx_mm": r.curve.iter().map(|s| s.left_support_dx * 1e3).collect::<Vec<_>>(),
            "right_support_dx_mm": r.curve.iter().map(|s| s.right_support_dx * 1e3).collect::<Vec<_>>(),
        },
    })
}

/// The quasi-static test of the reference arch (Pulatsu, Gonen & Lourenço 2021): one case,
/// as ``cargo run --release --example arch_static`` runs it, returned as that run's
/// ``summary.json`` entry of the case (``cases[k]``) plus ``curve`` (its rows of
/// ``force_displacement.csv``: displacement_mm, load_kn, smoothed_load_kn, left/right
/// support dx in mm).
///
/// Defaults: the baseline (φ 30.5°, kn 4 GPa/m, ks = 0.4 kn, width 0.15 m, large
/// displacements, 15 sub-contacts per edge, servo 20 µm from unbalanced ratio ≤ 1e-3, to 12 mm
/// or half the peak). ``ks`` None scales with ``kn`` as the command line does; ``rate`` (m/s)
/// loads at that speed as the paper's rate study instead of the servo; ``convergence_check``
/// also runs the refined case (half the increment and threshold), in parallel, and fills
/// ``rate_convergence``. ``plate`` is ``"rolling"`` (only its vertical velocity prescribed, the
/// adopted baseline) or ``"held"`` (its whole velocity prescribed: straight down without
/// turning, as the paper's "fix velocity"). ``joint_friction`` gives chosen joints of the ring
/// a friction angle of their own, ``{joint: degrees}`` with joints numbered 0 (left springing)
/// to 13 (right springing), the others keeping ``friction_deg``: ``{5: 40, 13: 40}`` keeps
/// joints 5 and 13 from sliding, and the arch forms the test's mechanism; the summary echoes
/// it as ``joint_friction_deg``.
#[pyfunction]
#[pyo3(signature = (*, friction_deg=30.5, kn=4e9, ks=None, width=0.15, mode="large", per_edge=15,
    servo_increment=2e-5, servo_ratio=1e-3, rate=None, max_displacement=0.012, stop_fraction=0.5,
    local_damping=0.8, convergence_check=false, label=None, plate="rolling", joint_friction=None))]
#[allow(clippy::too_many_arguments)]
pub fn arch_static<'py>(
    py: Python<'py>,
    friction_deg: f64,
    kn: f64,
    ks: Option<f64>,
    width: f64,
    mode: &str,
    per_edge: i64,
    servo_increment: f64,
    servo_ratio: f64,
    rate: Option<f64>,
    max_displacement: f64,
    stop_fraction: f64,
    local_damping: f64,
    convergence_check: bool,
    label: Option<String>,
    plate: &str,
    joint_friction: Option<std::collections::BTreeMap<i64, f64>>,
) -> PyResult<Bound<'py, PyAny>> {
    let per_edge = crate::convert::whole(per_edge, "per_edge", u64::from(u16::MAX))? as u16;
    let plate_support = match plate.to_ascii_lowercase().as_str() {
        "rolling" => statics::PlateSupport::Rolling,
        "held" => statics::PlateSupport::Held,
        other => return Err(bad(format!("plate {other:?}: expected \"rolling\" or \"held\""))),
    };
    let base = StaticCase::baseline();
    let mut case = match rate {
        Some(r) => {
            voussoir::error::positive("rate", r).py()?;
            StaticCase::rate_study(r)
        }
        None => {
            // The library's validation, with its message (as the command line).
            voussoir::loading::Servo::new(
                voussoir::ids::BlockId(0),
                voussoir::math::Vector::Y,
                servo_increment,
                servo_ratio,
            )
            .py()?;
            StaticCase {
                servo: Some(ServoLoading {
                    increment: servo_increment,
                    max_unbalanced_ratio: servo_ratio,
                }),
                ..base.clone()
            }
        }
    };
    case.friction_deg = friction_deg;
    case.ks = ks.unwrap_or(kn * base.ks / base.kn);
    case.kn = kn;
    case.width = width;
    case.mode = match mode.to_ascii_lowercase().as_str() {
        "large" => DisplacementMode::Large,
        "small" => DisplacementMode::Small,
        other => return Err(bad(format!("mode {other:?}: expected \"large\" or \"small\""))),
    };
    case.per_edge = per_edge;
    case.max_displacement = voussoir::error::positive("max_displacement", max_displacement).py()?;
    case.stop_fraction = stop_fraction;
    case.local_damping = local_damping;
    case.plate_support = plate_support;
    for (joint, deg) in joint_friction.unwrap_or_default() {
        // Negative indices are refused here, those past the ring by the scenario, which names the range.
        let joint = crate::convert::whole(joint, "joint_friction: joint index", u64::from(u32::MAX))?;
        case.joint_friction.insert(joint as usize, deg);
    }
    if let Some(l) = label {
        case.label = l;
    }
    let (result, convergence) = interruptible(py, |check| {
        if convergence_check {
            statics::run_converged(&case, Some(STATIC_CHECK_TRAVEL), check).map(|(r, c)| (r, Some(c)))
        } else {
            statics::run(&case, Some(STATIC_CHECK_TRAVEL), check).map(|r| (r, None))
        }
    })?;
    json_to_py(py, &static_summary(&result, convergence.as_ref()))
}

fn release_of(s: &str) -> PyResult<Release> {
    s.parse().map_err(bad)
}

fn impact_summary(label: &str, kind: &str, runs: &[ImpactResult]) -> PyResult<Value> {
    let Some(r) = runs.first() else {
        return Err(bad(
            "offsets_mm: at least one drop-height offset (0 for the test's own height)",
        ));
    };
    let refs: Vec<&ImpactResult> = runs.iter().collect();
    // The summary the command line writes to summary.json, built once (`ImpactSummary`).
    let mut summary = serde_json::to_value(ImpactSummary::of(label, kind, r, &refs))
        .map_err(|e| bad(format!("impact summary: {e}")))?;
    let column = |f: fn(&ImpactSample) -> f64| r.samples.iter().map(f).collect::<Vec<_>>();
    // Not in summary.json: the central run's history_<setup>.csv, SI units.
    let history = json!({
            "time_s": column(|x| x.time),
            "disp_m": column(|x| x.disp),
            "velocity_m_per_s": column(|x| x.velocity),
            "accel_m_per_s2": column(|x| x.accel),
            "impact_force_n": column(|x| x.impact_force),
            "impactor_velocity_m_per_s": column(|x| x.impactor_velocity),
            "impactor_drift_x_m": column(|x| x.impactor_drift_x),
            "impactor_drift_z_m": column(|x| x.impactor_drift_z),
            "kinetic_j": column(|x| x.kinetic),
            "impactor_kinetic_j": column(|x| x.impactor_kinetic),
            "ring_potential_j": column(|x| x.arch_potential),
            "elastic_j": column(|x| x.elastic),
            "friction_j": column(|x| x.friction),
            "damping_j": column(|x| x.damping),
            "gravity_work_j": column(|x| x.gravity_work),
            "input_j": column(|x| x.input),
            "accounted_j": column(|x| x.accounted),
    });
    if let Value::Object(map) = &mut summary {
        map.insert("history".into(), history);
    }
    Ok(summary)
}

/// One drop-weight impact test of the reference arch (Pulatsu, Gonen & Lourenço 2021), as
/// ``cargo run --release --example arch_impact -- --setup NAME`` runs it, returned as that
/// run's ``summary.json`` entry of the setup (``setups[k]``) plus ``history`` (the central
/// run's ``history_<setup>.csv`` columns, SI units).
///
/// ``setup``: one of M80H45, M75H45, M75H20, M60H20, M60H25, M60H30 (``impact_setups()``).
/// Every drop-height offset in ``offsets_mm`` is run (in parallel), the smallest in magnitude
/// being the central run; the default runs the central one only (the command line's default is
/// ``(-0.5, -0.25, 0, 0.25, 0.5)``). ``settled_states`` (1 to 16) runs each drop height from
/// that many settled states, the k-th settled under gravity changed by ``k·1e-12`` of itself
/// (a state that differs from the test's at round-off level); ``median_max_disp_m`` is the
/// median of the largest displacement over all the runs, the result to compare where the
/// central run's moves with round-off. ``ks`` scales with ``kn``; ``damping`` is the
/// stiffness-proportional Rayleigh ratio at 25 Hz; ``guide`` ``"frame"`` or ``"seat"``,
/// ``base`` ``"sloped"`` or ``"flat"``, ``release`` ``"above"`` or ``"full"``; ``node_rule``
/// ``"integrated"`` (node contacts' springs integrated over the surface each node stands for:
/// the books of a collapse close) or ``"point"`` (the library's default, 1.4–1.6 times
/// faster here; ``docs/benchmarks/arch-impact.md``).
#[pyfunction]
#[pyo3(signature = (setup="M60H20", *, kn=4e9, damping=0.01, width=0.15, duration=1.0, friction_deg=30.5,
    per_edge=15, guide="frame", base="sloped", release="above", offsets_mm=vec![0.0], settled_states=1,
    node_rule="integrated"))]
#[allow(clippy::too_many_arguments)]
pub fn arch_impact<'py>(
    py: Python<'py>,
    setup: &str,
    kn: f64,
    damping: f64,
    width: f64,
    duration: f64,
    friction_deg: f64,
    per_edge: i64,
    guide: &str,
    base: &str,
    release: &str,
    offsets_mm: Vec<f64>,
    settled_states: i64,
    node_rule: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let per_edge = crate::convert::whole(per_edge, "per_edge", u64::from(u16::MAX))? as u16;
    let all = impact::setups();
    let chosen = all.iter().find(|s| s.name == setup).cloned().ok_or_else(|| {
        bad(format!(
            "setup {setup:?}: expected one of {}",
            all.iter().map(|s| s.name.as_str()).collect::<Vec<_>>().join(", ")
        ))
    })?;
    if offsets_mm.is_empty() {
        return Err(bad("offsets_mm: give at least one drop-height offset"));
    }
    if !(1..=16).contains(&settled_states) {
        return Err(bad(format!(
            "settled_states {settled_states}: expected 1 to 16 settled states per drop height"
        )));
    }
    let mut c = ImpactCase::baseline(chosen);
    c.ks = kn * c.ks / c.kn;
    c.kn = kn;
    c.damping_ratio = damping;
    c.width = width;
    c.duration = duration;
    c.friction_deg = friction_deg;
    c.per_edge = per_edge;
    c.guide = guide.parse::<ImpactorGuide>().map_err(bad)?;
    c.base = base.parse::<ImpactorBase>().map_err(bad)?;
    c.release = release_of(release)?;
    c.node_rule = node_rule.parse().map_err(bad)?;
    let mut offsets: Vec<f64> = offsets_mm.iter().map(|mm| mm * 1e-3).collect();
    offsets.sort_by(|a, b| a.abs().total_cmp(&b.abs()));
    let cases: Vec<ImpactCase> = offsets
        .iter()
        .flat_map(|&dh| (0..settled_states).map(move |state| (dh, state as f64 * 1e-12)))
        .map(|(dh, perturbation)| ImpactCase {
            height_offset: dh,
            settle_perturbation: perturbation,
            ..c.clone()
        })
        .collect();
    for case in &cases {
        case.validate().py()?;
    }
    let runs = interruptible(py, |check| {
        cases
            .par_iter()
            .map(|case| impact::run(case, Some(IMPACT_CHECK_TIME), check))
            .collect::<voussoir::Result<Vec<_>>>()
    })?;
    json_to_py(py, &impact_summary(setup, "main", &runs)?)
}

/// The six impact tests with what was observed (name, mass, height, collapsed, max_disp,
/// max_velocity, max_accel; SI units).
#[pyfunction]
pub fn impact_setups(py: Python<'_>) -> PyResult<Bound<'_, PyAny>> {
    let v = serde_json::to_value(impact::setups()).map_err(|e| bad(e.to_string()))?;
    json_to_py(py, &v)
}
