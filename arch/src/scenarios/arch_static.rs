//! The quasi-static test of the reference arch (Pulatsu, Gonen & Lourenço 2021; `docs/benchmarks/arch-static.md`): a displacement-controlled
//! vertical load on voussoir 5 through a plate that does not restrain it horizontally.
//!
//! Model: the arch of [`voussoir::build::arch::ArchSpec::reference`]; a steel plate seated on the extrados of voussoir 5
//! (footprint 0.10 m along the span, full width), whose **vertical velocity only** is prescribed:
//! it is free to translate horizontally and to rotate in the plane of the arch (the roller and
//! bearing of the test), so the load it transmits is vertical. The plate–stone joint has the
//! stone joint's law. The arch is first settled under gravity with local damping, then the plate
//! is driven down quasi-statically by a servo ([`voussoir::loading::Servo`]: it advances only
//! from settled states, and the load is read at them), or at a constant rate for the study of
//! inertia effects ([`StaticCase::rate_study`]), with local damping on, until the plate has
//! travelled `max_displacement` or the load has stayed below `stop_fraction` of its peak over 1 mm.
//! [`run_converged`] also runs the case refined and reports how much its peak moves.
//! [`limit_analysis`] gives the rigid-block collapse load of the settled arch beside the DEM's
//! peak (`docs/benchmarks/arch-static.md`, "Limit analysis").

use std::collections::BTreeMap;
use std::ops::ControlFlow;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use voussoir::analysis::limit::{JointMotion, LimitOptions, LimitProblem, LimitResult, LiveLoad};
use voussoir::analysis::{classify_joints, JointRef, JointState, Mechanism, MechanismCriteria};
use voussoir::block::{Block, BlockId, Dof, Fixity, RigidBlock};
use voussoir::build::arch::Arch;
use voussoir::contact::DisplacementMode;
use voussoir::error::Result;
use voussoir::integrate::Damping;
use voussoir::loading::{Convergence, Servo};
use voussoir::math::{Pose, Real, Rotation, Vector};
use voussoir::model::Model;

/// Plate travel between the samples of a servo-loaded case (m): the rate-loaded cases sample
/// every 2e-5 s × rate… of travel, i.e. 20 µm at 1e-2 m/s.
const SERVO_SAMPLE_TRAVEL: Real = 2e-5;

/// One analysis case. [`StaticCase::baseline`] holds the paper's values.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StaticCase {
    /// Label for tables and files.
    pub label: String,
    /// Joint friction angle (degrees); initial = residual.
    pub friction_deg: Real,
    /// Normal joint stiffness (Pa/m).
    pub kn: Real,
    /// Shear stiffness (Pa/m).
    pub ks: Real,
    /// Plate velocity (m/s, downwards) when the case is loaded at a rate (`servo` is `None`).
    pub rate: Real,
    /// Large or small displacements.
    pub mode: DisplacementMode,
    /// Out-of-plane width of the arch (m).
    pub width: Real,
    /// Sub-contacts per joint edge.
    pub per_edge: u16,
    /// Local damping coefficient.
    pub local_damping: Real,
    /// Stop when the plate has travelled this far (m).
    pub max_displacement: Real,
    /// Stop when the load has stayed below this fraction of its peak (after the peak) over
    /// [`FALLEN_TRAVEL`] of plate travel.
    pub stop_fraction: Real,
    /// Unbalanced-force ratio at which the gravity settling stops.
    pub settle_ratio: Real,
    /// Plate footprint along the span (m).
    pub plate_length: Real,
    /// Plate thickness (m).
    pub plate_thickness: Real,
    /// Plate density (kg/m³, steel).
    pub plate_density: Real,
    /// Window of plate travel (m) over which the load is averaged for the peak; zero (the
    /// default, servo loading): no averaging, the peak is that of the settled states.
    ///
    /// Loaded at a rate, once hinges form the arch moves as a mechanism, and local damping
    /// (proportional to the out-of-balance force, which is small in a mechanism) lets it
    /// oscillate at about 10 Hz: 0.8 mm of travel at 1e-2 m/s. The rate study averages over a
    /// window of one period (1 mm) to remove that inertial oscillation; the raw peak is
    /// reported too.
    pub smoothing_window: Real,
    /// Quasi-static loading by servo ([`voussoir::loading::Servo`]): the plate advances by
    /// `increment` per step from settled states only (the default). `None`: the plate moves at
    /// `rate` (the rate study of inertia effects).
    #[serde(default)]
    pub servo: Option<ServoLoading>,
    /// Safety factor of the automatic time step (the fraction of the stability limit): 0.9
    /// under servo loading, where inertia plays no part; the model's default 0.5 for the rate
    /// study.
    #[serde(default = "default_safety")]
    pub time_step_safety: Real,
    /// How the loading plate is held ([`PlateSupport::Rolling`], the adopted baseline, by
    /// default).
    #[serde(default)]
    pub plate_support: PlateSupport,
    /// Joints of the ring with a friction angle of their own (joint index `0..=13` from the left
    /// springing → degrees, in `(0°, 90°)`, initial = residual); every other joint has
    /// `friction_deg`. Empty by default. E.g. `{5: 40, 13: 40}` keeps joints 5 and 13 from
    /// sliding, and the arch forms the test's mechanism (`docs/benchmarks/arch-static.md`, "The
    /// test's mechanism, forced"). The limit analysis takes the same angles.
    #[serde(default)]
    pub joint_friction: BTreeMap<usize, Real>,
}

/// How the loading plate is held while it is driven down.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum PlateSupport {
    /// Only its vertical velocity is prescribed: it slides horizontally and turns in the plane
    /// of the arch freely, so the load it transmits is vertical (the test's roller and bearing;
    /// the adopted baseline).
    #[default]
    Rolling,
    /// Its whole velocity is prescribed, as the paper's "fix velocity to the block" does in
    /// 3DEC: it moves straight down without turning, and holds voussoir 5 horizontally through
    /// the friction of their joint.
    Held,
}

fn default_safety() -> Real {
    0.5
}

/// Servo settings of a static case.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ServoLoading {
    /// Plate advance per advancing step (m).
    pub increment: Real,
    /// Unbalanced-force ratio at or below which the plate advances.
    pub max_unbalanced_ratio: Real,
}

impl ServoLoading {
    /// The default cases' servo: 20 µm increments from states with an unbalanced-force ratio
    /// at most 1e-3 (halving both moves every default case's peak by less than 3 %,
    /// `docs/benchmarks/arch-static.md`).
    pub const DEFAULT: Self = Self {
        increment: 2e-5,
        max_unbalanced_ratio: 1e-3,
    };
}

impl StaticCase {
    /// The paper's model: φ = 30.5°, kn = 4 GPa/m, ks = 1.6 GPa/m, large displacements, width
    /// 0.15 m (adopted), 15 sub-contacts per edge, local damping 0.8, loaded quasi-statically
    /// ([`ServoLoading::DEFAULT`], time step at 0.9 of the limit, no averaging).
    pub fn baseline() -> Self {
        Self {
            label: "baseline".into(),
            friction_deg: 30.5,
            kn: 4e9,
            ks: 1.6e9,
            rate: 1e-2,
            mode: DisplacementMode::Large,
            width: 0.15,
            per_edge: 15,
            local_damping: 0.8,
            max_displacement: 0.012,
            stop_fraction: 0.5,
            settle_ratio: 1e-5,
            plate_length: 0.10,
            plate_thickness: 0.02,
            plate_density: 7850.0,
            smoothing_window: 0.0,
            servo: Some(ServoLoading::DEFAULT),
            time_step_safety: 0.9,
            plate_support: PlateSupport::Rolling,
            joint_friction: BTreeMap::new(),
        }
    }

    /// The baseline loaded at `rate` (m/s) as the paper's study of inertia effects: the plate
    /// moves at constant speed, the time step is the model's default (0.5 of the limit) and
    /// the load is averaged over 1 mm of travel. Labelled `rate … m/s`.
    pub fn rate_study(rate: Real) -> Self {
        Self {
            label: format!("rate {rate} m/s"),
            rate,
            smoothing_window: 1e-3,
            servo: None,
            time_step_safety: default_safety(),
            ..Self::baseline()
        }
    }

    /// The same case refined, for the convergence check: half the servo's increment and
    /// threshold ([`Servo::refined`]), or half the rate.
    pub fn refined(&self) -> Self {
        let mut refined = self.clone();
        match &mut refined.servo {
            Some(s) => {
                *s = ServoLoading {
                    increment: 0.5 * s.increment,
                    max_unbalanced_ratio: 0.5 * s.max_unbalanced_ratio,
                }
            }
            None => refined.rate *= 0.5,
        }
        refined
    }

    /// Whether the case belongs to the rate study (loaded at a rate, not quasi-statically).
    pub fn is_rate_study(&self) -> bool {
        self.servo.is_none()
    }
}

/// One sample of the load–displacement curve.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Sample {
    /// Time since loading started (s).
    pub time: Real,
    /// Plate displacement (m, downwards positive).
    pub displacement: Real,
    /// Vertical load on voussoir 5 (N).
    pub load: Real,
    /// Load averaged over the last `smoothing_window` of travel (N).
    pub smoothed_load: Real,
    /// Horizontal displacement of voussoir 1 (m, at its extrados midpoint).
    pub left_support_dx: Real,
    /// Horizontal displacement of voussoir 13 (m).
    pub right_support_dx: Real,
}

/// Result of a case.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StaticResult {
    /// The case.
    pub case: StaticCase,
    /// Steps of the gravity settling.
    pub settle_steps: u64,
    /// Unbalanced-force ratio reached by the settling.
    pub settle_ratio: Real,
    /// Peak of the load averaged over `smoothing_window` (N): the quasi-static capacity.
    pub peak_load: Real,
    /// Plate displacement at that peak (m).
    pub displacement_at_peak: Real,
    /// Peak of the raw load, inertial oscillation included (N).
    pub raw_peak_load: Real,
    /// The load–displacement curve.
    pub curve: Vec<Sample>,
    /// Joint states at the peak and at the end.
    pub joints_at_peak: Vec<JointState>,
    /// Joint states at the end.
    pub joints_at_end: Vec<JointState>,
    /// Mechanism at the peak.
    pub mechanism_at_peak: Mechanism,
    /// Mechanism at the end.
    pub mechanism_at_end: Mechanism,
    /// Steps of the loading phase.
    pub steps: u64,
    /// Time step (s).
    pub dt: Real,
    /// Sub-contacts.
    pub subcontacts: usize,
    /// Wall-clock time (s).
    pub wall_s: Real,
    /// The limit analysis of the settled arch under the plate's load ([`limit_analysis`]).
    pub limit: LimitSummary,
}

/// The limit analysis of a case (`voussoir::analysis::limit`): the collapse load of the settled
/// arch, with rigid blocks, no-tension Coulomb joints of the case's friction (associative) and
/// the plate's load, beside the DEM's peak.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LimitSummary {
    /// Vertical force of the plate on voussoir 5 at collapse (N): the live load's multiplier
    /// plus the plate's weight, the quantity the DEM's load is (the plate–voussoir resultant).
    pub load: Real,
    /// The multiplier of the unit downward force on the plate (N).
    pub multiplier: Real,
    /// The plate's weight (N).
    pub plate_weight: Real,
    /// Hinges and sliding joints of the collapse mechanism.
    pub mechanism: Mechanism,
    /// How each joint of the ring moves in the mechanism.
    pub joints: Vec<JointMotion>,
    /// Wall-clock time of the analysis (s).
    pub wall_s: Real,
}

/// Relative velocity (of the largest at any contact corner) above which a joint of the limit
/// mechanism counts as hinging or sliding ([`LimitResult::classify`]).
pub const LIMIT_MECHANISM_TOLERANCE: Real = 1e-3;

/// The limit analysis of the arch as it stands in `model` (settled, before loading): the plate,
/// driven vertically in the DEM, is loaded instead by a downward force at its centroid and is
/// free vertically (it still slides and turns in the plane, as in the DEM); the joints' strength
/// is the case's Coulomb law (friction, no cohesion, no tension).
///
/// # Errors
/// The limit analysis's (`voussoir::Error::LimitInfeasible`, `LimitUnbounded`, `LimitSolver`).
pub fn limit_analysis(model: &Model, plate: BlockId, joints: &[JointRef]) -> Result<(LimitSummary, LimitResult)> {
    let started = Instant::now();
    let mut problem = LimitProblem::from_model(model)?;
    problem.set_fixity(
        plate,
        Fixity {
            translation: [Dof::Free, Dof::Free, Dof::Fixed],
            rotation: [Dof::Fixed, Dof::Fixed, Dof::Free],
        },
    )?;
    let block = &model.blocks()[plate.index()];
    let live = LiveLoad {
        block: plate,
        point: block.state().pose.translation,
        force: -Vector::Y,
    };
    let result = problem.solve(&[live], &LimitOptions::default())?;
    let plate_weight = block.mass_properties().mass * model.parameters().gravity.length();
    let (motions, mechanism) = result.classify(model, joints, LIMIT_MECHANISM_TOLERANCE);
    let summary = LimitSummary {
        load: result.multiplier + plate_weight,
        multiplier: result.multiplier,
        plate_weight,
        mechanism,
        joints: motions,
        wall_s: started.elapsed().as_secs_f64(),
    };
    Ok((summary, result))
}

/// The model of a case, with the ids of what it monitors.
#[derive(Debug)]
pub struct StaticModel {
    /// The model, settled or not.
    pub model: Model,
    /// The arch.
    pub arch: Arch,
    /// The loading plate.
    pub plate: BlockId,
    /// Voussoir 5.
    pub loaded: BlockId,
    /// Joints of the ring.
    pub joints: Vec<JointRef>,
}

const VOUSSOIR: usize = 5;

/// How far the plate travels with the load below `stop_fraction` of its peak before a case
/// stops (m): a collapse keeps the load down, where the first contact of the plate — closed by
/// one increment at the plate's approach speed, 0.13 m/s — can bounce voussoir 5 off it and
/// read zero at a settled state for a moment (φ = 25° stopped at 0.08 mm with a 95 N "peak").
pub const FALLEN_TRAVEL: Real = 1e-3;

/// Builds the model of a case (not yet settled).
///
/// # Errors
/// Invalid parameters.
pub fn build(case: &StaticCase) -> Result<StaticModel> {
    let (mut model, arch) = super::reference_arch_model(super::ArchJoints {
        width: case.width,
        per_edge: case.per_edge,
        node_rule: voussoir::geometry::NodeRule::Point,
        kn: case.kn,
        ks: case.ks,
        friction_deg: case.friction_deg,
        mode: case.mode,
        time_step: voussoir::integrate::TimeStep::Auto {
            safety: case.time_step_safety,
        },
    })?;
    model.set_damping(Damping::Local {
        alpha: case.local_damping,
    })?;
    // The plate: a box seated on the extrados of voussoir 5, turned with its slope.
    let centre = arch.extrados_midpoint(VOUSSOIR);
    let n = arch.extrados_normal(VOUSSOIR);
    let slope = (-n.x).atan2(n.y);
    let half = Vector::new(0.5 * case.plate_length, 0.5 * case.plate_thickness, 0.5 * case.width);
    let local = RigidBlock::cuboid("loading plate", -half, half, case.plate_density)?;
    let pose = Pose::from_parts(
        Vector::new(centre.x, centre.y, 0.5 * case.width) + n * (0.5 * case.plate_thickness),
        Rotation::from_rotation_z(slope),
    );
    let plate = model.add_block(
        local
            .transformed(pose)
            .with_material(super::STEEL)
            .with_fixity(plate_fixity(case.plate_support, 0.0)),
    )?;
    let joints = arch.joint_refs();
    for (&index, &friction_deg) in &case.joint_friction {
        let joint = joints
            .iter()
            .find(|j| j.index == index)
            .ok_or_else(|| voussoir::Error::InvalidParameter {
                name: "joint_friction: joint index".into(),
                value: index as Real,
                expected: "a joint of the ring, 0 (left springing) to 13 (right springing)",
            })?;
        if !(friction_deg > 0.0 && friction_deg < 90.0) {
            return Err(voussoir::Error::InvalidParameter {
                name: format!("joint_friction: friction angle of joint {index} (degrees)"),
                value: friction_deg,
                expected: "in (0, 90): a joint without friction has no capacity, and tan φ is infinite at 90°",
            });
        }
        let law = voussoir::law::CoulombSlip::dry(case.kn, case.ks, friction_deg)?;
        model.set_interface_law(joint.blocks.0, joint.blocks.1, law)?;
    }
    Ok(StaticModel {
        model,
        arch,
        plate,
        loaded: BlockId(VOUSSOIR as u32),
        joints,
    })
}

/// The plate's vertical velocity `vy` prescribed; rolling, it may slide horizontally and turn in
/// the plane of the arch; held, neither. Out-of-plane motions are fixed.
fn plate_fixity(support: PlateSupport, vy: Real) -> Fixity {
    match support {
        PlateSupport::Rolling => Fixity {
            translation: [Dof::Free, Dof::Velocity(vy), Dof::Fixed],
            rotation: [Dof::Fixed, Dof::Fixed, Dof::Free],
        },
        PlateSupport::Held => Fixity {
            translation: [Dof::Velocity(0.0), Dof::Velocity(vy), Dof::Fixed],
            rotation: [Dof::Fixed; 3],
        },
    }
}

/// The static run's observer: every `sample_every` steps, the load–displacement sample (with
/// its moving average over the smoothing window), the peak and the joints' states at it, the
/// frames; it stops the run at the maximum displacement or once the load has fallen after the
/// peak.
struct StaticRun<'a, F> {
    case: &'a StaticCase,
    plate: BlockId,
    loaded: BlockId,
    joints: &'a [JointRef],
    criteria: &'a MechanismCriteria,
    left: (BlockId, Vector),
    right: (BlockId, Vector),
    sample_every: u64,
    step0: u64,
    t0: Real,
    frame_every: Option<Real>,
    on_frame: &'a mut F,
    /// Under servo loading: the servo and the plate's height before loading (the travel is
    /// measured; samples are taken at settled states every 20 µm of travel).
    servo: Option<(Servo, Real)>,
    next_travel: Real,
    curve: Vec<Sample>,
    peak: (Real, Real),
    raw_peak: Real,
    window: std::collections::VecDeque<(Real, Real)>,
    window_sum: Real,
    at_peak: (Vec<JointState>, Mechanism),
    next_frame: Real,
    /// The travel at which the load fell below `stop_fraction` of its peak and has stayed
    /// there since.
    fallen_since: Option<Real>,
}

impl<F: FnMut(&Model) -> Result<()>> voussoir::model::Observer<voussoir::law::CoulombSlip> for StaticRun<'_, F> {
    fn after_step(&mut self, model: &Model) -> Result<ControlFlow<()>> {
        let case = self.case;
        let t = model.time() - self.t0;
        let displacement = match self.servo {
            Some((servo, y0)) => {
                let travel = y0 - model.blocks()[self.plate.index()].state().pose.translation.y;
                if !servo.settled(model) || travel < self.next_travel {
                    return Ok(ControlFlow::Continue(()));
                }
                self.next_travel = travel + SERVO_SAMPLE_TRAVEL;
                travel
            }
            None => {
                if !(model.step_count() - self.step0).is_multiple_of(self.sample_every) {
                    return Ok(ControlFlow::Continue(()));
                }
                case.rate * t
            }
        };
        // The resultant acts on the plate (the higher id); the load on the arch is its opposite
        // reaction, i.e. the upward force on the plate.
        let load = model
            .contact_between(self.plate, self.loaded)
            .map(|c| c.resultant().y)
            .unwrap_or(0.0);
        let window = &mut self.window;
        window.push_back((displacement, load));
        self.window_sum += load;
        while window
            .front()
            .is_some_and(|&(d, _)| d < displacement - case.smoothing_window)
        {
            self.window_sum -= window.pop_front().map_or(0.0, |w| w.1);
        }
        let smoothed_load = self.window_sum / window.len() as Real;
        // The smoothed value describes the middle of the window.
        let smoothed_at = displacement - 0.5 * (displacement - window.front().map_or(displacement, |w| w.0));
        self.raw_peak = self.raw_peak.max(load);
        let sample = Sample {
            time: t,
            displacement,
            load,
            smoothed_load,
            left_support_dx: model.blocks()[self.left.0.index()].displacement_of(self.left.1).x,
            right_support_dx: model.blocks()[self.right.0.index()].displacement_of(self.right.1).x,
        };
        self.curve.push(sample);
        if smoothed_load > self.peak.0 {
            self.peak = (smoothed_load, smoothed_at);
            self.at_peak = classify_joints(model, self.joints, self.criteria);
        }
        if let Some(every) = self.frame_every {
            if displacement >= self.next_frame {
                (self.on_frame)(model)?;
                self.next_frame += every;
            }
        }
        let below = self.peak.0 > 0.0 && smoothed_load < case.stop_fraction * self.peak.0 && displacement > self.peak.1;
        self.fallen_since = if below {
            Some(self.fallen_since.unwrap_or(displacement))
        } else {
            None
        };
        let fallen = self
            .fallen_since
            .is_some_and(|since| displacement - since >= FALLEN_TRAVEL);
        Ok(super::stop_when(displacement >= case.max_displacement || fallen))
    }
}

/// Runs a case; `on_frame` is called with the model every `frame_every` metres of plate travel
/// (and at the start and end of loading), for ParaView frames.
///
/// # Errors
/// Divergence or settling failure.
pub fn run(
    case: &StaticCase,
    frame_every: Option<Real>,
    mut on_frame: impl FnMut(&Model) -> Result<()>,
) -> Result<StaticResult> {
    let started = Instant::now();
    let StaticModel {
        mut model,
        arch,
        plate,
        loaded,
        joints,
    } = build(case)?;
    let settle_steps = model.run_to_equilibrium(case.settle_ratio, 200_000)?;
    let settle_ratio = model.unbalanced_force_ratio();
    // The limit analysis of the settled arch, once, before loading.
    let (limit, _) = limit_analysis(&model, plate, &joints)?;
    if case.servo.is_none() {
        model.set_fixity(plate, plate_fixity(case.plate_support, -case.rate))?;
    }
    let criteria = MechanismCriteria::default();
    let left = arch.extrados_midpoint(1);
    let right = arch.extrados_midpoint(arch.spec.voussoirs);
    let (left_id, right_id) = (arch.voussoir_id(1), arch.voussoir_id(arch.spec.voussoirs));
    let sample_every = ((2e-5 / case.rate) / model.dt()).ceil().max(1.0) as u64;
    let step0 = model.step_count();
    let mut run = StaticRun {
        case,
        plate,
        loaded,
        joints: &joints,
        criteria: &criteria,
        left: (left_id, left),
        right: (right_id, right),
        sample_every,
        step0,
        t0: model.time(),
        frame_every,
        on_frame: &mut on_frame,
        servo: None,
        next_travel: 0.0,
        curve: Vec::new(),
        peak: (0.0, 0.0),
        raw_peak: 0.0,
        window: std::collections::VecDeque::new(),
        window_sum: 0.0,
        at_peak: classify_joints(&model, &joints, &criteria),
        next_frame: 0.0,
        fallen_since: None,
    };
    // Until the observer stops the run: the maximum displacement, or the load fallen after the
    // peak.
    match case.servo {
        Some(s) => {
            let servo = Servo::new(plate, -Vector::Y, s.increment, s.max_unbalanced_ratio)?;
            run.servo = Some((servo, model.blocks()[plate.index()].state().pose.translation.y));
            servo.run(&mut model, u64::MAX, &mut run)?;
        }
        None => {
            model.run_observed(u64::MAX, &mut run)?;
        }
    }
    let StaticRun {
        curve,
        peak,
        raw_peak,
        at_peak,
        ..
    } = run;
    // A plate that never pressed on voussoir 5 with more than its own weight did not load the
    // arch: free to slide horizontally, it slid off along the sloping extrados (measured with
    // ks 0.4 GPa/m: 3 mm of travel at zero load), and its "peak" would be a capacity of zero.
    let plate_weight = plate_mass(case) * model.parameters().gravity.length();
    if raw_peak < plate_weight {
        return Err(voussoir::Error::NotConverged {
            what: "a load on voussoir 5 above the loading plate's own weight (the plate, free to slide \
                   horizontally, slid off along the extrados: its joint's shear springs, ks, did not hold it)",
            steps: model.step_count() - step0,
            last: raw_peak,
        });
    }
    if frame_every.is_some() {
        on_frame(&model)?;
    }
    let at_end = classify_joints(&model, &joints, &criteria);
    Ok(StaticResult {
        case: case.clone(),
        settle_steps,
        settle_ratio,
        peak_load: peak.0,
        displacement_at_peak: peak.1,
        raw_peak_load: raw_peak,
        curve,
        joints_at_peak: at_peak.0,
        joints_at_end: at_end.0,
        mechanism_at_peak: at_peak.1,
        mechanism_at_end: at_end.1,
        steps: model.step_count() - step0,
        dt: model.dt(),
        subcontacts: model.subcontact_count(),
        wall_s: started.elapsed().as_secs_f64(),
        limit,
    })
}

/// Runs a case and its refinement ([`StaticCase::refined`]) in parallel: the case's result
/// (with its frames) and the convergence of its peak load (N).
///
/// # Errors
/// As [`run`], for either run.
pub fn run_converged(
    case: &StaticCase,
    frame_every: Option<Real>,
    on_frame: impl FnMut(&Model) -> Result<()> + Send,
) -> Result<(StaticResult, Convergence)> {
    let refined = case.refined();
    let (result, refined) = rayon::join(|| run(case, frame_every, on_frame), || run(&refined, None, |_| Ok(())));
    let (result, refined) = (result?, refined?);
    let convergence = Convergence {
        value: result.peak_load,
        refined: refined.peak_load,
    };
    Ok((result, convergence))
}

/// Convenience for callers that want the block of the plate by name.
pub fn plate_mass(case: &StaticCase) -> Real {
    case.plate_length * case.plate_thickness * case.width * case.plate_density
}
