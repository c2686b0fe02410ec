//! Whole-engine checks through the public API: the energy balance of damped collapses and of an
//! undamped elastic system, and bit-identical determinism across runs and thread counts.

use crate::common;

use voussoir::build::{running_bond_wall, WallSpec};
use voussoir::prelude::*;

use common::fingerprint;

/// Friction angle of the collapse joints (degrees).
const PHI: f64 = 30.0;

/// A column of `n` 0.2 m stone cubes on a fixed slab, under gravity tilted by `tilt_deg` about
/// y. With the tilt steeper than the column's slenderness (tan 20° = 0.36 > 0.2 / 0.8) the
/// column topples: blocks rock, slide (tan 20° < tan 30°, so sliding comes from the dynamics)
/// and hit the slab and each other.
fn column(damping: Damping, tilt_deg: f64, n: usize) -> Model {
    let t = tilt_deg.to_radians();
    let params = ModelParameters {
        gravity: 9.81 * Vector::new(t.sin(), 0.0, -t.cos()),
        ..ModelParameters::default()
    };
    let mut model = common::model_with(params, CoulombSlip::dry(1e8, 4e7, PHI).unwrap());
    model.set_damping(damping).unwrap();
    model
        .add_block(
            RigidBlock::cuboid(
                "slab",
                Vector::new(-2.0, -1.0, -0.2),
                Vector::new(2.0, 1.0, 0.0),
                2500.0,
            )
            .unwrap()
            .with_fixity(Fixity::FIXED),
        )
        .unwrap();
    for k in 0..n {
        let z = 0.2 * k as f64;
        model
            .add_block(common::cube(&format!("cube {k}"), Vector::new(0.0, 0.0, z)))
            .unwrap();
    }
    model
}

/// The largest magnitude among all terms of the balance (J).
fn largest_term(e: &Energies) -> f64 {
    [
        e.kinetic,
        e.initial_kinetic,
        e.elastic,
        e.friction,
        e.damping,
        e.gravity_work,
        e.load_work,
        e.boundary_work,
        e.input(),
    ]
    .into_iter()
    .fold(0.0, |a, b| a.max(b.abs()))
}

/// Energies below this (J) are not compared: a micro-joule is nine orders of magnitude below the
/// energies of these runs and at the level of the round-off of the initial contact geometry
/// (blocks built touching have gaps of ~1e-17 m, hence spring energies of ~1e-20 J in the very
/// first step, which must not count as "100 % of the scale").
const SCALE_FLOOR: f64 = 1e-6;

/// The worst violations seen over a run, each relative to the energy scale of the run so far.
#[derive(Debug, Default)]
struct EnergyWatch {
    /// Running maximum of [`largest_term`] (J).
    scale: f64,
    /// Worst |accounted − input| / scale, with the step where it happened.
    worst_balance: (f64, u64),
    /// Most negative friction / scale (dissipation must not create energy), with its step.
    worst_negative_friction: (f64, u64),
    /// Most negative damping / scale, with its step.
    worst_negative_damping: (f64, u64),
}

impl EnergyWatch {
    fn observe<L: ConstitutiveLaw>(&mut self, model: &Model<L>) {
        let e = model.energies();
        let step = model.step_count();
        self.scale = self.scale.max(largest_term(&e));
        if self.scale < SCALE_FLOOR {
            return;
        }
        let balance = e.balance_error().abs() / self.scale;
        if balance > self.worst_balance.0 {
            self.worst_balance = (balance, step);
        }
        let friction = (-e.friction / self.scale).max(0.0);
        if friction > self.worst_negative_friction.0 {
            self.worst_negative_friction = (friction, step);
        }
        let damping = (-e.damping / self.scale).max(0.0);
        if damping > self.worst_negative_damping.0 {
            self.worst_negative_damping = (damping, step);
        }
    }
}

/// Runs `model` to `t_end`, checking the energies after every step.
fn run_watched(model: &mut Model, t_end: f64) -> EnergyWatch {
    let mut watch = EnergyWatch::default();
    while model.time() < t_end {
        model.step().unwrap();
        watch.observe(model);
    }
    watch
}

/// 1 % of the energy scale: the budget for the balance. Consistent bookkeeping meets it more than
/// ten times over (the works telescope exactly for translation; rotation and moving contact
/// geometry add O(Δt²) terms: 0.08 % measured in the collapses with trapezoidal bookkeeping), so a
/// breach means energy is booked inconsistently or created by the contact model.
const BALANCE_TOLERANCE: f64 = 0.01;

/// Checks a collapse run: balance at every step within 1 % of the running energy scale, and the
/// dissipated energies (friction, damping) never negative by more than the same 1 %.
fn check_collapse(name: &str, mut model: Model) {
    let top = BlockId(model.blocks().len() as u32 - 1);
    let start = model.block(top).unwrap().state().pose.translation;
    let watch = run_watched(&mut model, 1.0);
    let e = model.energies();
    let moved = (model.block(top).unwrap().state().pose.translation - start).length();
    println!(
        "{name}: steps {} detections {} moved {moved:.3} m; end {e:?}; balance error {:.3e} J; {watch:?}",
        model.step_count(),
        model.detection_count(),
        e.balance_error()
    );
    // It really is a collapse: the top block fell over by more than its width.
    assert!(moved > 0.2, "{name}: the top block moved only {moved} m");
    assert!(e.gravity_work > 10.0 && e.damping > 0.0, "{name}: {e:?}");
    // At the end.
    assert!(
        e.balance_error().abs() <= BALANCE_TOLERANCE * largest_term(&e),
        "{name}: final balance error {} J vs largest term {} J ({e:?})",
        e.balance_error(),
        largest_term(&e)
    );
    // During the run.
    assert!(
        watch.worst_balance.0 <= BALANCE_TOLERANCE,
        "{name}: balance error reached {:.2} % of the energy scale at step {}",
        100.0 * watch.worst_balance.0,
        watch.worst_balance.1
    );
    assert!(
        watch.worst_negative_damping.0 <= BALANCE_TOLERANCE,
        "{name}: damping dissipation went negative: {:.2} % of the energy scale at step {}",
        100.0 * watch.worst_negative_damping.0,
        watch.worst_negative_damping.1
    );
    assert!(
        watch.worst_negative_friction.0 <= BALANCE_TOLERANCE,
        "{name}: friction dissipation went negative (energy created at the joints): {:.2} % of \
         the energy scale at step {}",
        100.0 * watch.worst_negative_friction.0,
        watch.worst_negative_friction.1
    );
    assert!(
        e.friction > 0.0,
        "{name}: blocks slid, yet no friction dissipation: {e:?}"
    );
}

/// A four-cube column topples under gravity tilted by 20° with Cundall local damping (α = 0.8):
/// rocking, slip at φ = 30° and impacts. After every step, and at the end (t = 1 s),
/// `kinetic + elastic + friction + damping` equals `initial kinetic + works` within 1 % of the
/// largest energy term so far, and neither dissipation term is negative beyond that 1 %.
#[test]
fn collapse_with_local_damping_balances_energy() {
    check_collapse("local damping", column(Damping::local(), 20.0, 4));
}

/// The same collapse with Rayleigh damping (5 % at 20 Hz, mass and stiffness parts), which
/// adds contact dashpots: the same 1 % balance and non-negative dissipation.
#[test]
fn collapse_with_rayleigh_damping_balances_energy() {
    check_collapse("rayleigh", column(Damping::rayleigh(0.05, 20.0).unwrap(), 20.0, 4));
}

/// An undamped elastic system: three cubes stacked on a slab with linear elastic joints (no slip,
/// no opening: [`LinearElastic`]), released at rest in contact with small horizontal velocities
/// (2, 4, 6 mm/s). They bounce on the normal springs and sway and rock on the shear springs.
/// Damping must stay exactly zero; the friction term (work on the joints minus stored energy)
/// must stay ~0 — below 0.1 % of the energy scale, which leaves room only for the O(Δt²)
/// mismatch between the geometric gap and the kinematic increments of a rotating joint — and
/// the balance must hold within 1 % at every step over 0.2 s (tens of contact oscillations).
#[test]
fn undamped_elastic_stack_conserves_energy() {
    let mut model = common::model(LinearElastic {
        normal_stiffness: 1e8,
        shear_stiffness: 4e7,
    });
    model.set_damping(Damping::None).unwrap();
    model.add_block(common::fixed_slab("slab")).unwrap();
    for k in 0..3 {
        let z = 0.2 * k as f64;
        let cube = common::cube(&format!("cube {k}"), Vector::new(0.0, 0.0, z))
            .with_velocity(Vector::new(0.002 * (k + 1) as f64, 0.0, 0.0), Vector::ZERO);
        model.add_block(cube).unwrap();
    }
    let mut max_friction: f64 = 0.0;
    let mut watch = EnergyWatch::default();
    while model.time() < 0.2 {
        model.step().unwrap();
        watch.observe(&model);
        max_friction = max_friction.max(model.energies().friction.abs());
        assert_eq!(model.energies().damping, 0.0, "no damping model, no damping");
    }
    let e = model.energies();
    println!(
        "undamped: {e:?}; balance error {:.3e} J; max |friction| {max_friction:.3e} J; {watch:?}",
        e.balance_error()
    );
    assert!(e.elastic > 0.0 && e.kinetic > 0.0 && e.gravity_work > 0.0, "{e:?}");
    assert!(
        e.balance_error().abs() <= BALANCE_TOLERANCE * largest_term(&e),
        "final balance error {} J vs largest term {} J",
        e.balance_error(),
        largest_term(&e)
    );
    assert!(
        watch.worst_balance.0 <= BALANCE_TOLERANCE,
        "balance error reached {:.2} % of the energy scale at step {}",
        100.0 * watch.worst_balance.0,
        watch.worst_balance.1
    );
    assert!(
        max_friction <= 1e-3 * watch.scale,
        "friction term {max_friction} J in an elastic system (scale {} J)",
        watch.scale
    );
}

/// A 5-course, 5-brick running-bond wall under gravity tilted by 30° out of its plane (so that
/// it rocks and its bricks slide at φ = 25°), with the default local damping.
fn tilted_wall() -> Model {
    let t = 30f64.to_radians();
    let params = ModelParameters {
        gravity: 9.81 * Vector::new(0.0, t.sin(), -t.cos()),
        ..ModelParameters::default()
    };
    let mut model = common::model_with(params, CoulombSlip::dry(1e8, 4e7, 25.0).unwrap());
    let spec = WallSpec {
        bricks_per_course: 5,
        courses: 5,
        ..WallSpec::default()
    };
    for block in running_bond_wall(&spec).unwrap() {
        model.add_block(block).unwrap();
    }
    model
}

/// Steps of the determinism runs: enough for the wall to move by millimetres and for several
/// re-detections, within a second or two in release.
const DETERMINISM_STEPS: u64 = 600;

fn run_wall() -> (Vec<u64>, Model) {
    let mut model = tilted_wall();
    model.run_steps(DETERMINISM_STEPS).unwrap();
    (fingerprint(&model), model)
}

/// Two runs of the same model give bit-identical block states, energies and contact forces, and
/// the run really moved (so the comparison is not trivially of resting blocks).
#[test]
fn same_model_twice_is_bit_identical() {
    let (a, model) = run_wall();
    let (b, _) = run_wall();
    let moved = model
        .blocks()
        .iter()
        .map(|b| (b.state().pose.translation - b.initial_pose().translation).length())
        .fold(0.0, f64::max);
    println!(
        "wall: {} blocks, {} sub-contacts, {} detections, largest displacement {moved:.3e} m",
        model.blocks().len(),
        model.subcontact_count(),
        model.detection_count()
    );
    assert!(moved > 1e-3, "the wall barely moved: {moved} m");
    assert!(model.detection_count() > 2, "no re-detection happened");
    assert_eq!(a.len(), b.len());
    let first = a.iter().zip(&b).position(|(x, y)| x != y);
    assert_eq!(first, None, "runs differ at fingerprint word {first:?}");
}

/// The same model run in a 1-thread and a 2-thread rayon pool gives bit-identical results: the
/// contact loops are parallel (thousands of sub-contacts, several rayon tasks) but every sum is
/// gathered in a fixed order.
#[test]
fn one_and_two_threads_are_bit_identical() {
    let pool = |n| rayon::ThreadPoolBuilder::new().num_threads(n).build().unwrap();
    let (one, model) = pool(1).install(run_wall);
    let (two, _) = pool(2).install(run_wall);
    assert!(
        model.subcontact_count() > 4 * 512,
        "too few sub-contacts ({}) to split the contact loops between threads",
        model.subcontact_count()
    );
    assert_eq!(one.len(), two.len());
    let first = one.iter().zip(&two).position(|(x, y)| x != y);
    assert_eq!(first, None, "1 and 2 threads differ at fingerprint word {first:?}");
}
