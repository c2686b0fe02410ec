//! The drop-weight impact tests of the reference arch (Pulatsu, Gonen & Lourenço 2021; `docs/benchmarks/arch-impact.md`).
//!
//! Default model ([`ImpactorGuide::Frame`], as the paper's §4.2: "new rigid blocks are added to
//! simulate the frame and the free-falling object … noncohesive bonds between the falling object
//! and frame-blocks"): the arch of [`voussoir::build::arch::ArchSpec::reference`]; a rigid impactor
//! of the test's mass, 0.10 m along the span × the arch width, that is a **free** block (no
//! constrained degree of freedom); four **fixed frame blocks** around it, two along the span and
//! two across the width, each [`ImpactCase::guide_clearance`] away from its faces, in contact
//! with it through a noncohesive, by default frictionless, joint (material pair
//! [`super::STEEL`]–[`super::FRAME`]). The impactor strikes the **extrados of voussoir 5
//! directly**; its bottom face is parallel to that extrados ([`ImpactorBase::Sloped`], the
//! default) or horizontal ([`ImpactorBase::Flat`]).
//!
//! The other variant ([`ImpactorGuide::SeatConstrained`]): a steel seat resting on the extrados of
//! voussoir 5 with a horizontal top, and an impactor guided by constrained degrees of freedom
//! (only its vertical translation free).
//!
//! In both, the arch (and seat) are first settled under gravity with local damping while the
//! impactor is held; then the impactor is released and the run continues with stiffness-
//! proportional Rayleigh damping for `duration` seconds, or until the arch collapses. Release
//! ([`Release`]): just above the point of contact ([`ImpactCase::release_gap`]) with the speed
//! of the fall at that point, `√(2g(H − gap))`, so that it strikes at `√(2gH)` (the default), or
//! at rest from the full drop height `H` above the point of contact.
//!
//! Collapse rule ([`collapsed_voussoir`]): a voussoir's centroid has dropped by more than half
//! the ring thickness below its settled position. First-impact peak: the largest downward
//! quarter-span displacement until the impactor first moves up (its first rebound).

use std::ops::ControlFlow;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::stop_when;
use voussoir::block::{Block, BlockId, Dof, Fixity, RigidBlock};
use voussoir::build::arch::Arch;
use voussoir::error::Result;
use voussoir::integrate::Damping;
use voussoir::law::CoulombSlip;
use voussoir::math::{Real, Vector};
use voussoir::model::Model;
use voussoir::model::ModelParameters;

/// Gravitational acceleration of the scenario (m/s², along −y).
pub const GRAVITY: Real = 9.81;

pub use super::impact_case::{setups, ImpactCase, ImpactSetup, ImpactorBase, ImpactorGuide, Release};

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
    /// Vertical force of the struck blocks (voussoirs, or seat) on the impactor (N, up positive).
    pub impact_force: Real,
    /// Impactor velocity (m/s, up positive).
    pub impactor_velocity: Real,
    /// Horizontal displacement of the impactor's centroid since release (m): along the span.
    pub impactor_drift_x: Real,
    /// Across the width (m).
    pub impactor_drift_z: Real,
    /// Kinetic energy of every block (J).
    pub kinetic: Real,
    /// Kinetic energy of the impactor (J).
    pub impactor_kinetic: Real,
    /// Potential energy of the ring (voussoirs, and the seat) relative to its settled position,
    /// `Σ m·g·Δy` (J).
    pub arch_potential: Real,
    /// Elastic energy in the joint springs, change since release (J).
    pub elastic: Real,
    /// Energy dissipated by slip since release (J).
    pub friction: Real,
    /// Energy dissipated by damping since release (J).
    pub damping: Real,
    /// Work of gravity since release (J).
    pub gravity_work: Real,
    /// Energy input since just before release: the kinetic energy given to the impactor + works
    /// of gravity, loads and supports (J).
    pub input: Real,
    /// Change of kinetic + elastic + dissipated energy since just before release (J).
    pub accounted: Real,
}

/// The outcome of a case.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ImpactResult {
    /// The case.
    pub case: ImpactCase,
    /// Nominal impact velocity `√(2gH)` (m/s, downwards positive).
    pub v0: Real,
    /// Vertical gap between impactor and target measured after settling, at release (m).
    pub release_gap: Real,
    /// Impactor speed given at release (m/s, downwards).
    pub release_velocity: Real,
    /// Impactor speed at the last step before first contact (m/s, downwards).
    pub contact_speed: Real,
    /// Time of the first contact force (s after release).
    pub contact_time: Real,
    /// Time step of the step that brought the first contact force (s).
    pub contact_dt: Real,
    /// Impactor momentum at contact, nominal (kg·m/s).
    pub momentum: Real,
    /// Impactor kinetic energy at contact, nominal (J).
    pub kinetic_energy: Real,
    /// Largest downward quarter-span displacement during the first impact, until the impactor
    /// first moves up (m).
    pub first_peak_disp: Real,
    /// Largest downward quarter-span displacement over the run (m).
    pub max_disp: Real,
    /// Largest upward quarter-span displacement above its settled position after first contact
    /// (m), and when (s after release).
    pub max_rise: Real,
    /// Time of [`ImpactResult::max_rise`] (s).
    pub max_rise_time: Real,
    /// Largest quarter-span speed (m/s).
    pub max_velocity: Real,
    /// Largest quarter-span acceleration (m/s²).
    pub max_accel: Real,
    /// Largest impact force (N).
    pub max_impact_force: Real,
    /// Largest horizontal displacement of the impactor's centroid (m), along the span and
    /// across, sampled.
    pub max_impactor_drift: [Real; 2],
    /// Largest rotation of the impactor (rad), sampled.
    pub max_impactor_rotation: Real,
    /// Whether the collapse rule fired.
    pub collapsed: bool,
    /// Time of collapse (s after release).
    pub collapse_time: Option<Real>,
    /// Largest excess of energy over input during the run (J).
    pub max_energy_excess: Real,
    /// Largest `|accounted − input|` during the run (J).
    pub max_energy_error: Real,
    /// Excess of energy over input at the end of the run (J).
    pub final_energy_excess: Real,
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
    /// The seat on voussoir 5 ([`ImpactorGuide::SeatConstrained`]).
    pub seat: Option<BlockId>,
    /// The impactor.
    pub impactor: BlockId,
    /// The fixed frame blocks ([`ImpactorGuide::Frame`]): along the span (left, right), then
    /// across the width (front, back).
    pub frame: Vec<BlockId>,
    /// The blocks the impactor can strike: every voussoir, or the seat.
    pub targets: Vec<BlockId>,
    /// The impactor's two lowest corners along the span at mid-width, as built (world, m).
    pub impactor_bottom: [Vector; 2],
    /// The surface it strikes, as two points of the target block at mid-width (world, as built):
    /// the extrados chord of voussoir 5, or the seat's top.
    pub struck: (BlockId, [Vector; 2]),
}

const VOUSSOIR: usize = 5;

/// Builds the model (not settled; impactor held).
///
/// # Errors
/// [`voussoir::Error::InvalidParameter`] for bad parameters.
pub fn build(case: &ImpactCase) -> Result<ImpactModel> {
    case.validate()?;
    let (mut model, arch) = super::reference_arch_model(super::ArchJoints {
        width: case.width,
        per_edge: case.per_edge,
        node_rule: case.node_rule,
        kn: case.kn,
        ks: case.ks,
        friction_deg: case.friction_deg,
        mode: voussoir::contact::DisplacementMode::Large,
        time_step: voussoir::integrate::TimeStep::default(),
    })?;
    let (steel, frame) = (super::STEEL, super::FRAME);
    let stone_law = CoulombSlip::dry(case.kn, case.ks, case.friction_deg)?;
    let guide_law = CoulombSlip::dry(case.kn, case.ks, case.guide_friction_deg)?;
    model.set_joint_law(steel, frame, guide_law)?;
    // The frame is not meant to touch the arch; should a stone reach it, it is a stone joint.
    model.set_joint_law(super::STONE, frame, stone_law)?;
    model.set_joint_law(frame, frame, stone_law)?;

    let b = case.width;
    let e0 = arch.joints[VOUSSOIR - 1].extrados;
    let e1 = arch.joints[VOUSSOIR].extrados;
    let xc = arch.extrados_midpoint(VOUSSOIR).x;
    let (l, h) = (case.impactor_length, case.impactor_height);
    let (xl, xr) = (xc - 0.5 * l, xc + 0.5 * l);
    let slope = (e1.y - e0.y) / (e1.x - e0.x);
    let extrados_y = |x: Real| e0.y + slope * (x - e0.x);
    // Height above the point of contact at which the impactor starts.
    let lift = match case.release {
        Release::JustAbove => case.release_gap,
        Release::FullHeight => case.drop_height(),
    };
    let mid = 0.5 * b;
    let extrude = |outline: &[(Real, Real)], z0: Real, z1: Real| -> Vec<Vector> {
        outline
            .iter()
            .flat_map(|&(x, y)| [Vector::new(x, y, z0), Vector::new(x, y, z1)])
            .collect()
    };
    let density = case.setup.mass / (l * h * b);
    match case.guide {
        ImpactorGuide::SeatConstrained => {
            let top = e0.y.max(e1.y) + case.seat_thickness;
            let seat_pts = extrude(&[(e0.x, e0.y), (e1.x, e1.y), (e1.x, top), (e0.x, top)], 0.0, b);
            let seat = model.add_block(RigidBlock::from_vertices("seat", &seat_pts, 7850.0)?.with_material(steel))?;
            let y0 = top + lift;
            let lo = Vector::new(xl, y0, 0.0);
            let impactor = RigidBlock::cuboid("impactor", lo, lo + Vector::new(l, h, b), density)?
                .with_material(steel)
                .with_fixity(Fixity::FIXED);
            let impactor = model.add_block(impactor)?;
            Ok(ImpactModel {
                model,
                arch,
                seat: Some(seat),
                impactor,
                frame: Vec::new(),
                targets: vec![seat],
                impactor_bottom: [Vector::new(xl, y0, mid), Vector::new(xr, y0, mid)],
                struck: (seat, [Vector::new(e0.x, top, mid), Vector::new(e1.x, top, mid)]),
            })
        }
        ImpactorGuide::Frame => {
            // The impactor at the point of contact: bottom corners and top.
            let (bl, br, top) = match case.base {
                ImpactorBase::Sloped => (extrados_y(xl), extrados_y(xr), extrados_y(xc) + h),
                ImpactorBase::Flat => {
                    let y = extrados_y(xl).max(extrados_y(xr));
                    (y, y, y + h)
                }
            };
            let outline = [(xl, bl + lift), (xr, br + lift), (xr, top + lift), (xl, top + lift)];
            let impactor = RigidBlock::from_vertices("impactor", &extrude(&outline, 0.0, b), density)?
                .with_material(steel)
                .with_fixity(Fixity::FIXED);
            let impactor = model.add_block(impactor)?;
            // The frame spans the whole fall (as the test's did), whatever the release, from
            // `guide_standoff` above the extrados below it to above the impactor at full height.
            let frame_top = top + case.drop_height().max(lift) + case.guide_standoff;
            let (c, t) = (case.guide_clearance, case.guide_thickness);
            let extrados_max = |x0: Real, x1: Real| -> Real {
                let mut y = Real::NEG_INFINITY;
                let polyline: Vec<Vector> = arch.joints.iter().map(|j| j.extrados).collect();
                for w in polyline.windows(2) {
                    let (p, q) = (w[0], w[1]);
                    let (a, z) = (p.x.max(x0), q.x.min(x1));
                    if a <= z {
                        let at = |x: Real| p.y + (q.y - p.y) * (x - p.x) / (q.x - p.x);
                        y = y.max(at(a)).max(at(z));
                    }
                }
                y
            };
            let mut frame_ids = Vec::new();
            for (name, x0, x1) in [("frame left", xl - c - t, xl - c), ("frame right", xr + c, xr + c + t)] {
                let bottom = extrados_max(x0, x1) + case.guide_standoff;
                let pts = extrude(&[(x0, bottom), (x1, bottom), (x1, frame_top), (x0, frame_top)], 0.0, b);
                let block = RigidBlock::from_vertices(name, &pts, 7850.0)?
                    .with_material(frame)
                    .with_fixity(Fixity::FIXED);
                frame_ids.push(model.add_block(block)?);
            }
            // Across the width the frame lies outside the arch (z < 0, z > b): it reaches down
            // to the springing line without touching a stone.
            for (name, z0, z1) in [("frame front", -c - t, -c), ("frame back", b + c, b + c + t)] {
                let pts = extrude(&[(xl, 0.0), (xr, 0.0), (xr, frame_top), (xl, frame_top)], z0, z1);
                let block = RigidBlock::from_vertices(name, &pts, 7850.0)?
                    .with_material(frame)
                    .with_fixity(Fixity::FIXED);
                frame_ids.push(model.add_block(block)?);
            }
            let targets = (1..=arch.spec.voussoirs).map(|k| arch.voussoir_id(k)).collect();
            let struck = (
                arch.voussoir_id(VOUSSOIR),
                [Vector::new(e0.x, e0.y, mid), Vector::new(e1.x, e1.y, mid)],
            );
            Ok(ImpactModel {
                model,
                arch,
                seat: None,
                impactor,
                frame: frame_ids,
                targets,
                impactor_bottom: [Vector::new(xl, bl + lift, mid), Vector::new(xr, br + lift, mid)],
                struck,
            })
        }
    }
}

/// The guide of the seat variant: only the vertical translation is free.
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

/// The current position of a point given in the world frame of the block's initial pose.
fn moved(model: &Model, id: BlockId, initial_world: Vector) -> Vector {
    let b = &model.blocks()[id.index()];
    b.world_point(b.initial_pose().inverse_transform_point(initial_world))
}

/// Smallest vertical gap between the impactor's bottom corners and the struck surface (m).
fn vertical_gap(model: &Model, m: &ImpactModel) -> Real {
    let (id, [p, q]) = m.struck;
    let (p, q) = (moved(model, id, p), moved(model, id, q));
    m.impactor_bottom
        .iter()
        .map(|&c| {
            let c = moved(model, m.impactor, c);
            c.y - (p.y + (q.y - p.y) * (c.x - p.x) / (q.x - p.x))
        })
        .fold(Real::INFINITY, Real::min)
}

/// Vertical force of the targets on the impactor (N, up positive): the impactor is added after
/// them, so it is the `b` block of each contact.
fn impact_force(model: &Model, targets: &[BlockId], impactor: BlockId) -> Real {
    targets
        .iter()
        .filter_map(|&t| model.contact_between(t, impactor))
        .map(|c| c.resultant().y)
        .sum()
}

/// The impact run's observer: after every step, the contact check until the impactor first
/// touches the arch, and every `sample_interval` of simulated time the histories, maxima and the
/// collapse check; it stops the run at the case's duration, or 0.1 s after a collapse.
struct ImpactRun<'a, F> {
    case: &'a ImpactCase,
    targets: &'a [BlockId],
    /// Ring blocks whose potential energy is tracked: id, mass, settled height.
    ring: &'a [(BlockId, Real, Real)],
    arch: &'a Arch,
    settled: &'a [Vector],
    impactor: BlockId,
    quarter: Vector,
    q_block: BlockId,
    q_settled: Vector,
    /// Energies just before release.
    e0: voussoir::model::Energies,
    impactor_start: voussoir::math::Pose,
    t0: Real,
    frame_every: Option<Real>,
    on_frame: &'a mut F,
    /// The impactor's downward speed before the step just taken.
    before: Real,
    samples: Vec<ImpactSample>,
    last_v: Real,
    next_sample: Real,
    next_frame: Real,
    first_peak: Real,
    first_done: bool,
    impact_started: bool,
    contact_speed: Real,
    contact_time: Real,
    contact_dt: Real,
    max_disp: Real,
    max_v: Real,
    max_a: Real,
    max_f: Real,
    max_excess: Real,
    max_rise: Real,
    max_rise_time: Real,
    max_drift: [Real; 2],
    max_rot: Real,
    max_error: Real,
    collapse_time: Option<Real>,
    last_sample_t: Real,
}

impl<F: FnMut(&Model) -> Result<()>> voussoir::model::Observer<CoulombSlip> for ImpactRun<'_, F> {
    fn after_step(&mut self, model: &Model) -> Result<ControlFlow<()>> {
        let before = self.before;
        self.before = -model.blocks()[self.impactor.index()].state().velocity.y;
        let case = self.case;
        let t = model.time() - self.t0;
        if !self.impact_started {
            // Checked every step until the first contact, so the speed at contact is exact.
            let force = impact_force(model, self.targets, self.impactor);
            if force > 0.0 {
                self.impact_started = true;
                self.contact_speed = before;
                self.contact_time = t;
                self.contact_dt = model.dt();
            }
        }
        if t + 1e-12 < self.next_sample && t < case.duration {
            return Ok(ControlFlow::Continue(()));
        }
        self.next_sample += case.sample_interval;
        let qb = &model.blocks()[self.q_block.index()];
        let p = moved(model, self.q_block, self.quarter);
        let disp = p.y - self.q_settled.y;
        let velocity = qb.point_velocity(p).y;
        let accel = if t > self.last_sample_t {
            (velocity - self.last_v) / (t - self.last_sample_t)
        } else {
            0.0
        };
        self.last_v = velocity;
        self.last_sample_t = t;
        let force = impact_force(model, self.targets, self.impactor);
        let e = model.energies();
        let e0 = &self.e0;
        let ib = &model.blocks()[self.impactor.index()];
        let pose = ib.state().pose;
        let drift = pose.translation - self.impactor_start.translation;
        let rotation = (pose.rotation * self.impactor_start.rotation.inverse())
            .to_axis_angle()
            .1;
        let arch_potential: Real = self
            .ring
            .iter()
            .map(|&(id, m, y0)| m * GRAVITY * (model.blocks()[id.index()].state().pose.translation.y - y0))
            .sum();
        let sample = ImpactSample {
            time: t,
            disp,
            velocity,
            accel,
            impact_force: force,
            impactor_velocity: ib.state().velocity.y,
            impactor_drift_x: drift.x,
            impactor_drift_z: drift.z,
            kinetic: e.kinetic,
            impactor_kinetic: ib.kinetic_energy(),
            arch_potential,
            elastic: e.elastic - e0.elastic,
            friction: e.friction - e0.friction,
            damping: e.damping - e0.damping,
            gravity_work: e.gravity_work - e0.gravity_work,
            input: e.input() - e0.input(),
            accounted: e.accounted() - e0.accounted(),
        };
        if self.impact_started && !self.first_done {
            self.first_peak = self.first_peak.max(-disp);
            // The first impact ends when the impactor first moves up (its rebound); if it rides
            // the arch down, the first peak is the overall maximum. (The contact force is no
            // measure of it: the impactor chatters on the arch within the first milliseconds.)
            if sample.impactor_velocity > 0.0 {
                self.first_done = true;
            }
        }
        if self.impact_started && disp > self.max_rise {
            self.max_rise = disp;
            self.max_rise_time = t;
        }
        self.max_disp = self.max_disp.max(-disp);
        self.max_v = self.max_v.max(velocity.abs());
        self.max_a = self.max_a.max(accel.abs());
        self.max_f = self.max_f.max(force);
        self.max_drift = [
            self.max_drift[0].max(drift.x.abs()),
            self.max_drift[1].max(drift.z.abs()),
        ];
        self.max_rot = self.max_rot.max(rotation.abs());
        self.max_excess = self.max_excess.max(sample.accounted - sample.input);
        self.max_error = self.max_error.max((sample.accounted - sample.input).abs());
        self.samples.push(sample);
        if let Some(every) = self.frame_every {
            if t >= self.next_frame {
                (self.on_frame)(model)?;
                self.next_frame += every;
            }
        }
        if self.collapse_time.is_none() && collapsed_voussoir(model, self.arch, self.settled).is_some() {
            self.collapse_time = Some(t);
        }
        // After a collapse, keep 0.1 s for the record, then stop.
        Ok(stop_when(
            t >= case.duration || self.collapse_time.is_some_and(|tc| t > tc + 0.1),
        ))
    }
}

/// Runs a case.
///
/// # Errors
/// Invalid parameters, divergence or settling failure.
pub fn run(
    case: &ImpactCase,
    frame_every: Option<Real>,
    mut on_frame: impl FnMut(&Model) -> Result<()>,
) -> Result<ImpactResult> {
    let started = Instant::now();
    let mut im = build(case)?;
    if case.settle_perturbation == 0.0 {
        im.model.run_to_equilibrium(1e-5, 200_000)?;
    } else {
        // Settled under gravity changed at round-off level, then released under the test's.
        let params = *im.model.parameters();
        im.model.set_parameters(ModelParameters {
            gravity: params.gravity * (1.0 + case.settle_perturbation),
            ..params
        })?;
        im.model.run_to_equilibrium(1e-5, 200_000)?;
        im.model.set_parameters(params)?;
    }
    let arch = im.arch.clone();
    let impactor = im.impactor;
    let settled: Vec<Vector> = (1..=arch.spec.voussoirs)
        .map(|k| im.model.blocks()[arch.voussoir(k)].state().pose.translation)
        .collect();
    // Blocks of the ring whose potential energy is tracked: voussoirs and seat.
    let ring: Vec<(BlockId, Real, Real)> = (1..=arch.spec.voussoirs)
        .map(|k| arch.voussoir_id(k))
        .chain(im.seat)
        .map(|id| {
            let b = &im.model.blocks()[id.index()];
            (id, b.mass_properties().mass, b.state().pose.translation.y)
        })
        .collect();
    let quarter = arch.extrados_midpoint(VOUSSOIR);
    let q_block = arch.voussoir_id(VOUSSOIR);
    let q_settled = moved(&im.model, q_block, quarter);

    // Release: the speed of the fall at the measured gap, so that the impactor strikes at √(2gH).
    let gap = vertical_gap(&im.model, &im);
    let v0 = case.impact_velocity();
    let v_release = (2.0 * GRAVITY * (case.drop_height() - gap).max(0.0)).sqrt();
    let fixity = match case.guide {
        ImpactorGuide::Frame => Fixity::FREE,
        ImpactorGuide::SeatConstrained => guided(),
    };
    let targets = im.targets.clone();
    let model = &mut im.model;
    // Energies from just before release: the kinetic energy given to the impactor counts as input.
    let e0 = model.energies();
    model.set_fixity(impactor, fixity)?;
    model.set_velocity(impactor, Vector::new(0.0, -v_release, 0.0), Vector::ZERO)?;
    model.set_damping(Damping::rayleigh_stiffness(case.damping_ratio, case.damping_frequency)?)?;
    let step0 = model.step_count();
    let mut run = ImpactRun {
        case,
        targets: &targets,
        ring: &ring,
        arch: &arch,
        settled: &settled,
        impactor,
        quarter,
        q_block,
        q_settled,
        e0,
        impactor_start: model.blocks()[impactor.index()].state().pose,
        t0: model.time(),
        frame_every,
        on_frame: &mut on_frame,
        before: -model.blocks()[impactor.index()].state().velocity.y,
        samples: Vec::new(),
        last_v: 0.0,
        next_sample: 0.0,
        next_frame: 0.0,
        first_peak: 0.0,
        first_done: false,
        impact_started: false,
        contact_speed: v_release,
        contact_time: Real::NAN,
        contact_dt: Real::NAN,
        max_disp: 0.0,
        max_v: 0.0,
        max_a: 0.0,
        max_f: 0.0,
        max_excess: 0.0,
        max_rise: 0.0,
        max_rise_time: 0.0,
        max_drift: [0.0; 2],
        max_rot: 0.0,
        max_error: 0.0,
        collapse_time: None,
        last_sample_t: 0.0,
    };
    // Until the observer stops the run: the duration, or 0.1 s after a collapse.
    model.run_observed(u64::MAX, &mut run)?;
    let ImpactRun {
        samples,
        first_peak,
        contact_speed,
        contact_time,
        contact_dt,
        max_disp,
        max_v,
        max_a,
        max_f,
        max_excess,
        max_rise,
        max_rise_time,
        max_drift,
        max_rot,
        max_error,
        collapse_time,
        ..
    } = run;
    let mass = case.setup.mass;
    Ok(ImpactResult {
        case: case.clone(),
        v0,
        release_gap: gap,
        release_velocity: v_release,
        contact_speed,
        contact_dt,
        contact_time,
        momentum: mass * v0,
        kinetic_energy: 0.5 * mass * v0 * v0,
        first_peak_disp: first_peak,
        max_disp,
        max_rise,
        max_rise_time,
        max_velocity: max_v,
        max_accel: max_a,
        max_impact_force: max_f,
        max_impactor_drift: max_drift,
        max_impactor_rotation: max_rot,
        collapsed: collapse_time.is_some(),
        collapse_time,
        max_energy_excess: max_excess,
        max_energy_error: max_error,
        final_energy_excess: samples.last().map_or(0.0, |s| s.accounted - s.input),
        samples,
        steps: model.step_count() - step0,
        dt: model.dt(),
        wall_s: started.elapsed().as_secs_f64(),
    })
}
