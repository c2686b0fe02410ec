//! The summary of a group of impact runs, built once for the command line (`summary.json`)
//! and the Python bindings (`voussoir.scenarios.arch_impact`).

use serde::Serialize;

use super::arch_impact::{ImpactResult, ImpactSample, ImpactorBase, ImpactorGuide, Release};

/// The test's own numbers.
#[derive(Debug, Clone, Serialize)]
pub struct Experiment {
    /// Whether it collapsed.
    pub collapsed: bool,
    /// The largest quarter-span displacement (m).
    pub max_disp_m: Option<f64>,
    /// The largest quarter-span speed (m/s).
    pub max_velocity_m_per_s: f64,
    /// The largest quarter-span acceleration (m/s²).
    pub max_accel_m_per_s2: f64,
}

/// One run of a group (the central one and the drop-height offsets).
#[derive(Debug, Clone, Serialize)]
pub struct RunSummary {
    /// The drop height's offset from the test's (m).
    pub height_offset_m: f64,
    /// The relative change of gravity its arch settled under (0: the test's settled state).
    pub settle_perturbation: f64,
    /// The quarter-span displacement at its first peak (m).
    pub first_peak_disp_m: f64,
    /// The largest quarter-span displacement (m).
    pub max_disp_m: f64,
    /// The largest quarter-span speed (m/s).
    pub max_velocity_m_per_s: f64,
    /// Whether it collapsed.
    pub collapsed: bool,
    /// The largest excess of the energy accounted over the energy put in (J).
    pub max_energy_excess_j: f64,
    /// The largest absolute energy balance error (J).
    pub max_energy_error_j: f64,
    /// Wall-clock time (s).
    pub wall_s: f64,
}

/// The energy books at the end of the central run (changes since release, J).
#[derive(Debug, Clone, Serialize)]
pub struct EnergySummary {
    /// At the end of the run, changes since release (J).
    pub input_j: f64,
    /// Kinetic energy (J).
    pub kinetic_j: f64,
    /// Elastic energy in the joints (J).
    pub elastic_j: f64,
    /// Dissipated by slip and joint failure (J).
    pub friction_j: f64,
    /// Dissipated by damping (J).
    pub damping_j: f64,
    /// Work of gravity (J).
    pub gravity_work_j: f64,
    /// Energy accounted less energy put in at the end (J).
    pub final_excess_j: f64,
    /// Its largest value over the run (J).
    pub max_excess_j: f64,
    /// The largest absolute balance error over the run (J).
    pub max_abs_error_j: f64,
}

/// A group of runs (a setup at its drop-height offsets) as `summary.json` and Python's
/// `arch_impact` report it: the central run's results, the spread over the group, the books
/// and the test.
#[derive(Debug, Clone, Serialize)]
pub struct ImpactSummary {
    /// The test (`M60H20`, ...).
    pub name: String,
    /// The group's label (the setup, or a study's variant).
    pub label: String,
    /// `"main"`, `"study"` or `"release"`.
    pub kind: String,
    /// How the impactor is guided.
    pub guide: ImpactorGuide,
    /// The impactor's bottom face.
    pub base: ImpactorBase,
    /// Where the impactor starts.
    pub release: Release,
    /// How node contacts' normal springs acted (`"point"` or `"integrated"`).
    pub node_rule: voussoir::geometry::NodeRule,
    /// The impactor's mass (kg).
    pub mass_kg: f64,
    /// The drop height (m).
    pub height_m: f64,
    /// The impactor's speed at release (m/s).
    pub v0_m_per_s: f64,
    /// Its speed at the first contact (m/s).
    pub contact_speed_m_per_s: f64,
    /// Its kinetic energy at the first contact (J).
    pub impact_energy_j: f64,
    /// The joints' normal stiffness (Pa/m).
    pub kn_pa_per_m: f64,
    /// The stiffness-proportional damping ratio.
    pub damping_ratio: f64,
    /// The arch's width (m).
    pub width_m: f64,
    /// The quarter-span displacement at its first peak (m).
    pub first_peak_disp_m: f64,
    /// The largest quarter-span displacement (m).
    pub max_disp_m: f64,
    /// The least and largest maximum displacement over the group (m).
    pub spread_max_disp_m: [f64; 2],
    /// The median of the runs' largest quarter-span displacements (m): the group's result, where
    /// the central run's moves with round-off (issue 43, item 5).
    pub median_max_disp_m: f64,
    /// The least and largest first-peak displacement over the group (m).
    pub spread_first_peak_disp_m: [f64; 2],
    /// The largest upward quarter-span displacement (m).
    pub max_rise_m: f64,
    /// When it happened (s after release).
    pub max_rise_time_s: f64,
    /// The largest quarter-span speed (m/s).
    pub max_velocity_m_per_s: f64,
    /// The largest quarter-span acceleration (m/s²).
    pub max_accel_m_per_s2: f64,
    /// The largest force between impactor and arch (N).
    pub max_impact_force_n: f64,
    /// The impactor's largest horizontal drifts, x and z (m).
    pub max_impactor_drift_m: [f64; 2],
    /// The impactor's largest rotation (rad).
    pub max_impactor_rotation_rad: f64,
    /// Whether it collapsed.
    pub collapsed: bool,
    /// How many runs of the group collapsed.
    pub collapsed_runs: usize,
    /// How many runs the group has.
    pub runs_count: usize,
    /// When the central run collapsed (s after release), if it did.
    pub collapse_time_s: Option<f64>,
    /// The energy books at the end of the central run.
    pub energy: EnergySummary,
    /// Steps of the central run.
    pub steps: u64,
    /// Its time step (s).
    pub dt_s: f64,
    /// Wall-clock time (s).
    pub wall_s: f64,
    /// Each run of the group.
    pub runs: Vec<RunSummary>,
    /// The test's own numbers.
    pub experiment: Experiment,
}

impl ImpactSummary {
    /// The summary of a group whose central run is `central` and whose runs are `runs` (the
    /// central one among them), labelled `label` of kind `kind` (`"main"`, `"study"`,
    /// `"release"`).
    pub fn of(label: &str, kind: &str, central: &ImpactResult, runs: &[&ImpactResult]) -> Self {
        let spread = |f: &dyn Fn(&ImpactResult) -> f64| {
            let v: Vec<f64> = runs.iter().map(|r| f(r)).collect();
            [
                v.iter().copied().fold(f64::INFINITY, f64::min),
                v.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            ]
        };
        let r = central;
        let c = &r.case;
        let s = &c.setup;
        let last = r.samples.last().copied();
        let e = |f: fn(&ImpactSample) -> f64| last.map_or(0.0, |x| f(&x));
        Self {
            name: s.name.clone(),
            label: label.to_owned(),
            kind: kind.to_owned(),
            guide: c.guide,
            base: c.base,
            release: c.release,
            node_rule: c.node_rule,
            mass_kg: s.mass,
            height_m: c.drop_height(),
            v0_m_per_s: r.v0,
            contact_speed_m_per_s: r.contact_speed,
            impact_energy_j: r.kinetic_energy,
            kn_pa_per_m: c.kn,
            damping_ratio: c.damping_ratio,
            width_m: c.width,
            first_peak_disp_m: r.first_peak_disp,
            max_disp_m: r.max_disp,
            spread_max_disp_m: spread(&|r| r.max_disp),
            median_max_disp_m: median(runs.iter().map(|r| r.max_disp).collect()),
            spread_first_peak_disp_m: spread(&|r| r.first_peak_disp),
            max_rise_m: r.max_rise,
            max_rise_time_s: r.max_rise_time,
            max_velocity_m_per_s: r.max_velocity,
            max_accel_m_per_s2: r.max_accel,
            max_impact_force_n: r.max_impact_force,
            max_impactor_drift_m: r.max_impactor_drift,
            max_impactor_rotation_rad: r.max_impactor_rotation,
            collapsed: r.collapsed,
            collapsed_runs: runs.iter().filter(|r| r.collapsed).count(),
            runs_count: runs.len(),
            collapse_time_s: r.collapse_time,
            energy: EnergySummary {
                input_j: e(|x| x.input),
                kinetic_j: e(|x| x.kinetic),
                elastic_j: e(|x| x.elastic),
                friction_j: e(|x| x.friction),
                damping_j: e(|x| x.damping),
                gravity_work_j: e(|x| x.gravity_work),
                final_excess_j: r.final_energy_excess,
                max_excess_j: r.max_energy_excess,
                max_abs_error_j: r.max_energy_error,
            },
            steps: r.steps,
            dt_s: r.dt,
            wall_s: r.wall_s,
            runs: runs
                .iter()
                .map(|x| RunSummary {
                    height_offset_m: x.case.height_offset,
                    settle_perturbation: x.case.settle_perturbation,
                    first_peak_disp_m: x.first_peak_disp,
                    max_disp_m: x.max_disp,
                    max_velocity_m_per_s: x.max_velocity,
                    collapsed: x.collapsed,
                    max_energy_excess_j: x.max_energy_excess,
                    max_energy_error_j: x.max_energy_error,
                    wall_s: x.wall_s,
                })
                .collect(),
            experiment: Experiment {
                collapsed: s.collapsed,
                max_disp_m: s.max_disp,
                max_velocity_m_per_s: s.max_velocity,
                max_accel_m_per_s2: s.max_accel,
            },
        }
    }
}

/// The median of `v` (the mean of the middle two for an even count; NaN for none).
fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    match v.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => v[n / 2],
        n => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    }
}
