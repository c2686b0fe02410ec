//! The drop-weight impact tests of the reference arch (`BENCHMARKS.md` §4).
//!
//! Model: the arch of [`crate::build::arch::ArchSpec::reference`]; a steel seat resting on the extrados of voussoir 5
//! with a horizontal top (the bearing of the test); a rigid impactor of the test's mass, 0.10 m
//! along the span × the arch width, **guided by constrained degrees of freedom**: only its
//! vertical translation is free. The arch and seat are first settled under gravity with local
//! damping while the impactor is held just above the seat; then the impactor is released **just
//! above the seat with `v0 = √(2gH)`** and the run continues with stiffness-proportional Rayleigh
//! damping for `duration` seconds, or until the arch collapses.
//!
//! Collapse rule ([`collapsed_voussoir`]): a voussoir's centroid has dropped by more than half
//! the ring thickness below its settled position. First-impact peak: the largest downward
//! quarter-span displacement until the impactor first leaves the seat.

use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::block::{Block, BlockId, Dof, Fixity, RigidBlock};
use crate::build::arch::Arch;
use crate::error::Result;
use crate::integrate::Damping;
use crate::math::{Real, Vector};
use crate::model::Model;

/// One of the six tests, with what was observed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ImpactSetup {
    /// Name, e.g. `"M60H20"`.
    pub name: String,
    /// Drop mass (kg).
    pub mass: Real,
    /// Drop height (m).
    pub height: Real,
    /// Observed: the arch collapsed.
    pub collapsed: bool,
    /// Observed maximum quarter-span vertical displacement (m), when it stood.
    pub max_disp: Option<Real>,
    /// Observed peak quarter-span velocity (m/s).
    pub max_velocity: Real,
    /// Observed peak quarter-span acceleration (m/s²).
    pub max_accel: Real,
}

/// The six tests of the paper (Table 3 and §4 of `BENCHMARKS.md`).
pub fn setups() -> Vec<ImpactSetup> {
    let s = |name: &str, mass, height, collapsed, max_disp, max_velocity, max_accel| ImpactSetup {
        name: name.into(),
        mass,
        height,
        collapsed,
        max_disp,
        max_velocity,
        max_accel,
    };
    vec![
        s("M80H45", 81.00, 0.450, true, None, 3.19, 5115.0),
        s("M75H45", 74.35, 0.455, true, None, 2.99, 2139.0),
        s("M75H20", 74.35, 0.205, true, None, 1.91, 1416.0),
        s("M60H20", 60.93, 0.205, false, Some(0.034), 1.99, 1417.0),
        s("M60H25", 60.93, 0.255, false, Some(0.040), 2.13, 1589.0),
        s("M60H30", 60.93, 0.305, false, Some(0.053), 2.08, 1440.0),
    ]
}

/// One analysis: a setup and the model parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ImpactCase {
    /// The test.
    pub setup: ImpactSetup,
    /// Label (setup plus what differs from the baseline).
    pub label: String,
    /// Normal joint stiffness (Pa/m).
    pub kn: Real,
    /// Shear joint stiffness (Pa/m).
    pub ks: Real,
    /// Friction angle (degrees).
    pub friction_deg: Real,
    /// Rayleigh damping ratio (stiffness-proportional).
    pub damping_ratio: Real,
    /// Frequency at which the ratio is set (Hz).
    pub damping_frequency: Real,
    /// Out-of-plane width (m).
    pub width: Real,
    /// Simulated time after release (s).
    pub duration: Real,
    /// Sub-contacts per joint edge.
    pub per_edge: u16,
    /// Impactor footprint along the span (m).
    pub impactor_length: Real,
    /// Impactor height (m); its density is set to give the test's mass.
    pub impactor_height: Real,
    /// Seat thickness above the highest extrados corner of voussoir 5 (m).
    pub seat_thickness: Real,
    /// Gap between impactor and seat at release (m).
    pub release_gap: Real,
    /// Interval of the recorded histories (s).
    pub sample_interval: Real,
}

impl ImpactCase {
    /// The paper's values for a setup: kn = 4 GPa/m, ks = 1.6 GPa/m, φ = 30.5°, 1 % stiffness-
    /// proportional damping at 25 Hz, width 0.15 m, 1 s.
    pub fn baseline(setup: ImpactSetup) -> Self {
        Self {
            label: setup.name.clone(),
            setup,
            kn: 4e9,
            ks: 1.6e9,
            friction_deg: 30.5,
            damping_ratio: 0.01,
            damping_frequency: 25.0,
            width: 0.15,
            duration: 1.0,
            per_edge: 15,
            impactor_length: 0.10,
            impactor_height: 0.20,
            seat_thickness: 0.01,
            release_gap: 5e-4,
            sample_interval: 5e-4,
        }
    }

    /// Impact velocity `√(2gH)` (m/s).
    pub fn impact_velocity(&self) -> Real {
        (2.0 * 9.81 * self.setup.height).sqrt()
    }
}

/// A sample of the histories.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ImpactSample {
    /// Time since release (s).
    pub time: Real,
    /// Vertical displacement of the quarter-span point (extrados midpoint of voussoir 5) since
    /// settling (m, up positive).
    pub disp: Real,
    /// Its vertical velocity (m/s).
    pub velocity: Real,
    /// Its vertical acceleration, from the velocity change over the sample interval (m/s²).
    pub accel: Real,
    /// Force between impactor and seat (N).
    pub impact_force: Real,
    /// Impactor velocity (m/s, up positive).
    pub impactor_velocity: Real,
    /// Kinetic energy (J).
    pub kinetic: Real,
    /// Energy input since release: initial kinetic + works of gravity, loads and supports (J).
    pub input: Real,
    /// Kinetic + elastic + dissipated energy (J).
    pub accounted: Real,
}

/// The outcome of a case.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ImpactResult {
    /// The case.
    pub case: ImpactCase,
    /// Impactor velocity just before contact (m/s, downwards positive).
    pub v0: Real,
    /// Impactor momentum just before contact (kg·m/s).
    pub momentum: Real,
    /// Impactor kinetic energy just before contact (J).
    pub kinetic_energy: Real,
    /// Largest downward quarter-span displacement during the first impact, until the impactor
    /// first leaves the seat (m).
    pub first_peak_disp: Real,
    /// Largest downward quarter-span displacement over the run (m).
    pub max_disp: Real,
    /// Largest quarter-span speed (m/s).
    pub max_velocity: Real,
    /// Largest quarter-span acceleration (m/s²).
    pub max_accel: Real,
    /// Largest impact force (N).
    pub max_impact_force: Real,
    /// Whether the collapse rule fired, and when (s after release).
    pub collapsed: bool,
    /// Time of collapse (s).
    pub collapse_time: Option<Real>,
    /// Largest excess of energy over input during the run (J).
    pub max_energy_excess: Real,
    /// Histories.
    pub samples: Vec<ImpactSample>,
    /// Steps after release.
    pub steps: u64,
    /// Time step (s).
    pub dt: Real,
    /// Wall-clock time (s).
    pub wall_s: Real,
}

/// The model of a case and the ids of what it monitors.
#[derive(Debug)]
pub struct ImpactModel {
    /// The model.
    pub model: Model,
    /// The arch.
    pub arch: Arch,
    /// The seat on voussoir 5.
    pub seat: BlockId,
    /// The impactor.
    pub impactor: BlockId,
}

const VOUSSOIR: usize = 5;

/// Builds the model (not settled; impactor held).
///
/// # Errors
/// Invalid parameters.
pub fn build(case: &ImpactCase) -> Result<ImpactModel> {
    let (mut model, arch) = super::reference_arch_model(super::ArchJoints {
        width: case.width,
        per_edge: case.per_edge,
        kn: case.kn,
        ks: case.ks,
        friction_deg: case.friction_deg,
        mode: crate::contact::DisplacementMode::Large,
    })?;
    let steel = super::STEEL;
    let e0 = arch.joints[VOUSSOIR - 1].extrados;
    let e1 = arch.joints[VOUSSOIR].extrados;
    let top = e0.y.max(e1.y) + case.seat_thickness;
    let b = case.width;
    let seat_outline = [e0, e1, Vector::new(e1.x, top, 0.0), Vector::new(e0.x, top, 0.0)];
    let seat_pts: Vec<Vector> = seat_outline
        .iter()
        .flat_map(|p| [Vector::new(p.x, p.y, 0.0), Vector::new(p.x, p.y, b)])
        .collect();
    let seat = model.add_block(RigidBlock::from_vertices("seat", &seat_pts, 7850.0)?.with_material(steel))?;
    let xc = arch.extrados_midpoint(VOUSSOIR).x;
    let (l, h) = (case.impactor_length, case.impactor_height);
    let density = case.setup.mass / (l * h * b);
    let lo = Vector::new(xc - 0.5 * l, top + case.release_gap, 0.0);
    let impactor = RigidBlock::cuboid("impactor", lo, lo + Vector::new(l, h, b), density)?
        .with_material(steel)
        .with_fixity(Fixity::FIXED);
    let impactor = model.add_block(impactor)?;
    Ok(ImpactModel {
        model,
        arch,
        seat,
        impactor,
    })
}

/// The guide: only the vertical translation is free.
fn guided() -> Fixity {
    Fixity {
        translation: [Dof::Fixed, Dof::Free, Dof::Fixed],
        rotation: [Dof::Fixed; 3],
    }
}

/// The collapse rule: the first voussoir (1-based) whose centroid has dropped by more than half
/// the ring thickness below `settled`, if any.
pub fn collapsed_voussoir(model: &Model, arch: &Arch, settled: &[Vector]) -> Option<usize> {
    let limit = 0.5 * arch.spec.thickness;
    (1..=arch.spec.voussoirs).find(|&k| {
        let now = model.blocks()[arch.voussoir(k)].state().pose.translation;
        settled[k - 1].y - now.y > limit
    })
}

/// Runs a case.
///
/// # Errors
/// Divergence or settling failure.
pub fn run(
    case: &ImpactCase,
    frame_every: Option<Real>,
    mut on_frame: impl FnMut(&Model) -> Result<()>,
) -> Result<ImpactResult> {
    let started = Instant::now();
    let ImpactModel {
        mut model,
        arch,
        seat,
        impactor,
    } = build(case)?;
    model.run_to_equilibrium(1e-5, 200_000)?;
    let settled: Vec<Vector> = (1..=arch.spec.voussoirs)
        .map(|k| model.blocks()[arch.voussoir(k)].state().pose.translation)
        .collect();
    let quarter = arch.extrados_midpoint(VOUSSOIR);
    let q_block = BlockId(arch.voussoir(VOUSSOIR) as u32);
    let q_local = model.blocks()[q_block.index()]
        .initial_pose()
        .inverse_transform_point(quarter);
    let q_settled = model.blocks()[q_block.index()].world_point(q_local);

    // Release.
    let v0 = case.impact_velocity();
    model.set_fixity(impactor, guided())?;
    model.set_velocity(impactor, Vector::new(0.0, -v0, 0.0), Vector::ZERO)?;
    model.set_damping(Damping::rayleigh_stiffness(case.damping_ratio, case.damping_frequency)?)?;
    let t0 = model.time();
    let step0 = model.step_count();
    let e0 = model.energies();
    let input0 = e0.input();
    let mut samples = Vec::new();
    let mut last_v = 0.0;
    let mut next_sample = 0.0;
    let mut next_frame = 0.0;
    let (mut first_peak, mut first_done, mut impact_started): (Real, bool, bool) = (0.0, false, false);
    let (mut max_disp, mut max_v, mut max_a, mut max_f, mut max_excess): (Real, Real, Real, Real, Real) =
        (0.0, 0.0, 0.0, 0.0, 0.0);
    let mut collapse_time = None;
    let mut last_sample_t = 0.0;
    loop {
        model.step()?;
        let t = model.time() - t0;
        if t + 1e-12 < next_sample && t < case.duration {
            continue;
        }
        next_sample += case.sample_interval;
        let qb = &model.blocks()[q_block.index()];
        let p = qb.world_point(q_local);
        let disp = p.y - q_settled.y;
        let velocity = qb.point_velocity(p).y;
        let accel = if t > last_sample_t {
            (velocity - last_v) / (t - last_sample_t)
        } else {
            0.0
        };
        last_v = velocity;
        last_sample_t = t;
        let force = model.contact_between(seat, impactor).map_or(0.0, |c| c.resultant().y);
        let e = model.energies();
        let sample = ImpactSample {
            time: t,
            disp,
            velocity,
            accel,
            impact_force: force,
            impactor_velocity: model.blocks()[impactor.index()].state().velocity.y,
            kinetic: e.kinetic,
            input: e.input() - input0,
            accounted: e.accounted() - e0.accounted(),
        };
        if force > 0.0 {
            impact_started = true;
        }
        if impact_started && !first_done {
            first_peak = first_peak.max(-disp);
            // The first impact ends when the impactor leaves the seat (the contact force returns
            // to zero); if it rides the arch down, the first peak is the overall maximum.
            if force <= 0.0 {
                first_done = true;
            }
        }
        max_disp = max_disp.max(-disp);
        max_v = max_v.max(velocity.abs());
        max_a = max_a.max(accel.abs());
        max_f = max_f.max(force);
        max_excess = max_excess.max(sample.accounted - sample.input);
        samples.push(sample);
        if let Some(every) = frame_every {
            if t >= next_frame {
                on_frame(&model)?;
                next_frame += every;
            }
        }
        if collapse_time.is_none() && collapsed_voussoir(&model, &arch, &settled).is_some() {
            collapse_time = Some(t);
        }
        // After a collapse, keep 0.1 s for the record, then stop.
        if t >= case.duration || collapse_time.is_some_and(|tc| t > tc + 0.1) {
            break;
        }
    }
    let mass = case.setup.mass;
    Ok(ImpactResult {
        case: case.clone(),
        v0,
        momentum: mass * v0,
        kinetic_energy: 0.5 * mass * v0 * v0,
        first_peak_disp: first_peak,
        max_disp,
        max_velocity: max_v,
        max_accel: max_a,
        max_impact_force: max_f,
        collapsed: collapse_time.is_some(),
        collapse_time,
        max_energy_excess: max_excess,
        samples,
        steps: model.step_count() - step0,
        dt: model.dt(),
        wall_s: started.elapsed().as_secs_f64(),
    })
}
