//! Energy consistency of undamped contact dynamics, through the public API only.
//!
//! With no damping and a frictionless, no-tension joint, the only forces are gravity and the
//! normal springs of the sub-contacts, whose energy is a function of where the blocks are: the
//! motion must keep its energy through every kind of contact change (a face landing flat, an
//! edge, a corner, a cube tumbling from one to the other). With friction below the slope's
//! angle, a block at rest on an incline must stay at rest, and a dry-stacked wall must settle
//! without any block walking.
//!
//! What is measured, and why the tolerances hold:
//!
//! * **Mechanical energy** `kinetic + elastic − work of gravity` against the release value
//!   `m g h`, sampled whenever no sub-contact carries force (between impacts), over at least
//!   five impacts: within 2 % of `m g h`.
//! * **Balance** `input() − accounted()` at the same instants: within 1 % of `m g h`.
//! * **Friction** (what the laws dissipated): never negative and below 1 % of `m g h` for a
//!   frictionless law — it is booked only for sliding steps, whose shear force is zero here.
//!
//! During an impact resolved by a few steps the discrete kinetic energy of central difference
//! (`½ m v⁻·v⁺`) differs from the continuous one by up to `(ωΔt)²/4` of the contact's energy
//! (`ω` the impact's frequency): a property of the integrator, not of the contacts, which
//! `energy_balance_holds_at_every_step_with_a_resolving_step` checks separately with a
//! smaller step.

use crate::common;

use common::z_range;
use voussoir::build::{running_bond_wall, WallSpec};
use voussoir::prelude::*;

const RHO: Real = 2500.0;
const EDGE: Real = 0.2;

/// A frictionless, no-tension joint (kn = ks = 1 GPa/m, φ = 0).
fn frictionless() -> CoulombSlip {
    CoulombSlip::dry(1e9, 1e9, 0.0).expect("valid law")
}

/// A model with the slab and a 0.2 m cube turned by `rotation` whose lowest point is `height`
/// above the slab, undamped, with `law`.
fn drop_model(rotation: Rotation, height: Real, law: CoulombSlip, params: ModelParameters) -> (Model, BlockId) {
    let mut model = common::model_with(params, law);
    model.set_damping(Damping::None).expect("damping");
    model.add_block(common::fixed_slab("slab")).expect("slab");
    let cube = RigidBlock::cuboid("cube", Vector::splat(-EDGE / 2.0), Vector::splat(EDGE / 2.0), RHO)
        .expect("cube")
        .transformed(Pose::from_rotation(rotation));
    let lowest = z_range(&cube).0;
    let id = model
        .add_block(cube.transformed(Pose::from_translation(Vector::new(0.0, 0.0, height - lowest))))
        .expect("cube");
    (model, id)
}

/// Whether any sub-contact carries force.
fn loaded(model: &Model) -> bool {
    model
        .contacts()
        .any(|c| c.subcontacts().any(|s| s.normal_force() > 0.0))
}

/// What an undamped frictionless drop did, relative to `m g h`.
#[derive(Debug)]
struct DropRecord {
    impacts: usize,
    /// Largest |mechanical energy − released| between impacts.
    mechanical: Real,
    /// Largest |input − accounted| between impacts.
    balance: Real,
    /// Smallest and largest friction term, every step.
    friction: (Real, Real),
}

fn drop_record(rotation: Rotation, height: Real, duration: Real) -> DropRecord {
    let (mut model, _) = drop_model(rotation, height, frictionless(), ModelParameters::default());
    let mgh = RHO * EDGE.powi(3) * 9.81 * height;
    let mut r = DropRecord {
        impacts: 0,
        mechanical: 0.0,
        balance: 0.0,
        friction: (0.0, 0.0),
    };
    let mut was_loaded = false;
    while model.time() < duration {
        model.step().expect("step");
        let e = model.energies();
        r.friction = (r.friction.0.min(e.friction / mgh), r.friction.1.max(e.friction / mgh));
        let now = loaded(&model);
        if now && !was_loaded {
            r.impacts += 1;
        }
        was_loaded = now;
        if !now {
            let mechanical = e.kinetic + e.elastic - e.gravity_work - e.initial_kinetic;
            r.mechanical = r.mechanical.max(mechanical.abs() / mgh);
            r.balance = r.balance.max((e.input() - e.accounted()).abs() / mgh);
        }
    }
    r
}

fn check_drops(label: &str, rotations: &[Rotation], min_impacts: usize) {
    let mut failures = Vec::new();
    for (k, rotation) in rotations.iter().enumerate() {
        for height in [0.05_f64, 0.1, 0.2] {
            // Five impacts from a flat landing take 1.4 s from 10 cm; tumbling drops more.
            let duration = 0.5 + 8.0 * (2.0 * height / 9.81).sqrt();
            let r = drop_record(*rotation, height, duration);
            println!("{label} {k}, h = {height} m: {r:?}");
            if r.impacts < min_impacts
                || r.mechanical > 0.02
                || r.balance > 0.01
                || r.friction.0 < 0.0
                || r.friction.1 > 0.01
            {
                failures.push(format!("{label} {k}, h = {height} m: {r:?}"));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// **Flat landings keep their energy**, bounce after bounce (the cube's face lands on the
/// slab's face: every sub-contact closes and opens in the same step).
///
/// A flat impact is the stiffest mode of the cube (`ωΔt` = 0.6 at safety 0.5), and central
/// difference gains or loses up to a quarter of `(ωΔt)²` of the impact energy where the springs
/// close and open (`docs/theory.md` §4): 6–9 % of `m g h` over five or six impacts at the
/// default step alone. The impact-resolving step (`ModelParameters::impact_step`, default 0.1 of
/// the cube's critical step around each impact) brings it to 0.30–0.73 % (measured), for 4–9 %
/// more steps.
#[test]
fn frictionless_flat_drops_keep_their_energy() {
    check_drops("flat", &[Rotation::IDENTITY], 5);
}

/// **Edge landings keep their energy**: the cube, turned about a horizontal axis, lands on an
/// edge and rocks onto a face and back.
#[test]
fn frictionless_edge_drops_keep_their_energy() {
    check_drops(
        "edge",
        &[
            Rotation::from_rotation_x(0.3),
            Rotation::from_axis_angle(Vector::new(1.0, 1.0, 0.0).normalize(), 0.55),
        ],
        5,
    );
}

/// **Corner landings keep their energy**: the cube lands on a corner, tumbles onto edges and
/// faces.
#[test]
fn frictionless_corner_drops_keep_their_energy() {
    let corner_down = Rotation::from_rotation_arc(Vector::ONE.normalize(), Vector::NEG_Z);
    check_drops(
        "corner",
        &[
            Rotation::from_axis_angle(Vector::new(1.0, 2.0, 0.0).normalize(), 0.1) * corner_down,
            Rotation::from_axis_angle(Vector::new(-2.0, 1.0, 0.0).normalize(), 0.3) * corner_down,
        ],
        5,
    );
}

/// **With a step that resolves the impact, the balance holds at every step**, in contact too:
/// at a tenth of the critical step `ωΔt` of the flat impact is 0.12, so the discrete kinetic
/// energy differs from the continuous one by at most 0.4 % of the impact energy.
#[test]
fn energy_balance_holds_at_every_step_with_a_resolving_step() {
    let params = ModelParameters {
        time_step: TimeStep::Auto { safety: 0.1 },
        ..ModelParameters::default()
    };
    let corner_down = Rotation::from_rotation_arc(Vector::ONE.normalize(), Vector::NEG_Z);
    for rotation in [
        Rotation::IDENTITY,
        Rotation::from_rotation_x(0.3),
        Rotation::from_axis_angle(Vector::new(1.0, 2.0, 0.0).normalize(), 0.1) * corner_down,
    ] {
        let height = 0.1;
        let (mut model, _) = drop_model(rotation, height, frictionless(), params);
        let mgh = RHO * EDGE.powi(3) * 9.81 * height;
        let mut worst: Real = 0.0;
        while model.time() < 0.8 {
            model.step().expect("step");
            let e = model.energies();
            worst = worst.max((e.input() - e.accounted()).abs() / mgh);
        }
        println!(
            "{rotation:?}: largest |input − accounted| {:.3} % of m g h",
            100.0 * worst
        );
        assert!(worst < 0.01, "{rotation:?}: balance error {worst} of m g h");
    }
}

/// **An undamped block at rest on an incline below its friction angle stays put**: a 0.2 m
/// cube on a slab inclined at 30° (gravity vertical), joint kn = ks = 1 GPa/m with φ = 40°, first
/// brought to rest in static equilibrium (local damping, unbalanced-force ratio 1e-7), then run
/// undamped for 1 s: it moves less than 0.1 mm, and nothing slides (no dissipation).
///
/// It must start at rest in equilibrium. Released touching the slope with its joint unloaded,
/// the cube drops onto its springs with every sub-contact slipping (no normal force yet), and
/// keeps bouncing: its normal forces swing through zero at every cycle and it slips a little
/// each time. How far depends on the joint's discretisation, and the energy balance closes
/// while it does (gravity's work goes into friction): 11 mm in 1 s at 15 or 30 sub-contacts per
/// edge, 36 mm at 8, 0.22 m at 3 (measured, with this build and the one before issue 16 alike);
/// with ks = 0.4 kn, 0.26 mm. That is the response of the model to that release, which a real
/// block resting on a slope never sees; it is not what this test is about.
#[test]
fn undamped_block_at_rest_on_an_incline_stays_put() {
    let tilt = Pose::from_rotation(Rotation::from_rotation_y(-30f64.to_radians()));
    let mut model = common::model(CoulombSlip::dry(1e9, 1e9, 40.0).expect("law"));
    model.set_damping(Damping::local()).expect("damping");
    model
        .add_block(common::fixed_slab("slab").transformed(tilt))
        .expect("slab");
    let cube = model
        .add_block(common::cube("cube", Vector::ZERO).transformed(tilt))
        .expect("cube");
    model.run_to_equilibrium(1e-7, 400_000).expect("equilibrium");
    model.set_damping(Damping::None).expect("damping");
    let start = model.block(cube).expect("cube").state().pose;
    let (t0, friction0) = (model.time(), model.energies().friction);
    let mut largest: Real = 0.0;
    while model.time() < t0 + 1.0 {
        model.step().expect("step");
        let b = model.block(cube).expect("cube");
        for v in b.shape().vertices() {
            let moved = b.world_point(*v) - start.transform_point(*v);
            largest = largest.max(moved.length());
        }
    }
    let e = model.energies();
    println!(
        "incline: largest vertex displacement {largest:.3e} m in 1 s undamped; dissipated {:.3e} J",
        e.friction - friction0
    );
    assert!(largest < 1e-4, "the cube moved {largest} m");
    assert!(
        e.friction - friction0 < 1e-9,
        "the cube slid: {} J dissipated",
        e.friction - friction0
    );
}

/// **A dry-stacked wall settles undamped without walking, and its energy balance closes**: a
/// 10 × 10 running-bond wall of 0.2 × 0.1 × 0.05 m bricks (kn 1 GPa/m, ks 0.4 GPa/m, φ 30°)
/// released at rest under gravity with its joints unloaded, 1.5 s undamped.
///
/// The bricks drop onto their springs with every joint slipping (no normal force yet) and keep
/// vibrating, undamped, about their settled positions, their normal forces swinging through
/// zero: they slip by a fraction of a millimetre while they settle (each slip is dissipated,
/// booked as friction; with the joints' normal springs integrated over their cells the last
/// slips come up to about 0.7 s: 7.6 µm between the means over 0.4–0.5 s and 0.8–0.9 s) and
/// must not walk after it: the mean position of every vertex over 1.4–1.5 s (which averages
/// the vibration out) lies within 10 µm of its mean over 0.8–0.9 s (measured 3.8 µm).
///
/// The balance `|input − accounted|` is the central-difference integration's error (largest
/// while the bricks land and slip, in the first 0.2 s), and the books close as the step
/// shrinks: over the first 0.3 s at half the default step it is at most a third of what it is
/// at the default step (second order: measured 1.26 % and 0.29 % of the largest work of
/// gravity at safety 0.5 and 0.25, 0.11 % at 0.125; before the joints' cells were integrated
/// exactly, 0.87 % and 0.18 %) and within 0.5 % of the work of gravity.
#[test]
fn undamped_wall_settles_without_walking() {
    let wall = |safety: Real| {
        let params = ModelParameters {
            time_step: voussoir::integrate::TimeStep::Auto { safety },
            ..ModelParameters::default()
        };
        let mut model = common::model_with(params, CoulombSlip::dry(1e9, 4e8, 30.0).expect("law"));
        model.set_damping(Damping::None).expect("damping");
        let spec = WallSpec {
            bricks_per_course: 10,
            courses: 10,
            ..WallSpec::default()
        };
        for block in running_bond_wall(&spec).expect("wall") {
            model.add_block(block).expect("brick");
        }
        model
    };
    // The largest balance error over the first 0.3 s, relative to the largest work of gravity.
    let landing_balance = |safety: Real| {
        let mut model = wall(safety);
        let (mut worst, mut scale): (Real, Real) = (0.0, 0.0);
        while model.time() < 0.3 {
            model.step().expect("step");
            let e = model.energies();
            scale = scale.max(e.gravity_work.abs());
            worst = worst.max((e.input() - e.accounted()).abs());
        }
        worst / scale
    };
    let (coarse, fine) = (landing_balance(0.5), landing_balance(0.25));
    println!(
        "balance over the landing: {:.3} % at safety 0.5, {:.3} % at 0.25",
        100.0 * coarse,
        100.0 * fine
    );
    assert!(
        fine <= coarse / 3.0 && fine <= 0.005,
        "balance {coarse} at the default step, {fine} at half"
    );
    let mut model = wall(0.5);
    let vertices = |m: &Model| -> Vec<Vector> {
        m.blocks()
            .iter()
            .flat_map(|b| b.shape().vertices().iter().map(move |v| b.world_point(*v)))
            .collect()
    };
    let start = vertices(&model);
    let (mut worst_balance, mut scale): (Real, Real) = (0.0, 0.0);
    // Mean vertex positions over 0.8–0.9 s and over 1.4–1.5 s, which average the vibration out.
    let mut means = [
        (vec![Vector::ZERO; start.len()], 0.0),
        (vec![Vector::ZERO; start.len()], 0.0),
    ];
    let mut steps = 0;
    while model.time() < 1.5 {
        model.step().expect("step");
        steps += 1;
        if steps % 20 == 0 {
            let e = model.energies();
            scale = scale.max(e.gravity_work.abs());
            worst_balance = worst_balance.max((e.input() - e.accounted()).abs());
        }
        let window = match model.time() {
            t if (0.8..0.9).contains(&t) => Some(0),
            t if t >= 1.4 => Some(1),
            _ => None,
        };
        if let Some(w) = window {
            for (sum, p) in means[w].0.iter_mut().zip(vertices(&model)) {
                *sum += p;
            }
            means[w].1 += 1.0;
        }
    }
    let mean = |w: usize| -> Vec<Vector> { means[w].0.iter().map(|p| *p / means[w].1).collect() };
    let distance = |x: &[Vector], y: &[Vector]| x.iter().zip(y).map(|(p, q)| (*p - *q).length()).fold(0.0, Real::max);
    let moved = distance(&vertices(&model), &start);
    let drift = distance(&mean(1), &mean(0));
    let e = model.energies();
    println!(
        "wall: {steps} steps, largest vertex displacement {moved:.3e} m, mean drift from 0.8-0.9 s to 1.4-1.5 s {drift:.3e} m, \
         largest |balance| {worst_balance:.3e} J (work of gravity up to {scale:.3e} J), friction {:.3e} J",
        e.friction
    );
    assert!(drift < 1e-5, "a brick walked {drift} m after settling");
    assert!(
        worst_balance <= coarse * scale * (1.0 + 1e-9),
        "balance {worst_balance} J after the landing"
    );
    assert!(e.friction >= 0.0);
}
