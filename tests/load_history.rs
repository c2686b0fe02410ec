//! Time-varying loads (`loading::LoadHistory`, `Model::set_load_history`) against closed forms,
//! the energy books, checkpoints and scenes.

use crate::common;

use std::f64::consts::PI;

use common::{cube, fingerprint, fixed_slab, model, model_with};
use voussoir::io::scene::Scene;
use voussoir::loading::{LoadHistory, TimeHistory};
use voussoir::prelude::*;

const F0: f64 = 50.0;
const FREQUENCY: f64 = 2.0;

fn wrench(force: Vector, moment: Vector) -> Wrench {
    Wrench { force, moment }
}

/// A free 0.2 m cube without gravity under `F0 sin(2π f t)` along x and `M0 sin(2π f t)`
/// about z, from rest: `x = F0/m (t/ω − sin ωt/ω²)` and `θ = M0/I (t/ω − sin ωt/ω²)`. The
/// history is sampled 400 times per period (linear between samples: 2e-5 of the amplitude).
/// The load's work, booked with the trapezoidal rule, equals the kinetic energy: the balance
/// is an identity of central difference for translation, and within 1e-6 with the rotation.
#[test]
fn a_free_block_follows_a_sine_load() {
    let params = ModelParameters {
        gravity: Vector::ZERO,
        ..ModelParameters::default()
    };
    let mut model: Model = model_with(params, CoulombSlip::dry(1e9, 4e8, 30.0).unwrap());
    model.set_damping(Damping::None).unwrap();
    let id = model.add_block(cube("free", Vector::ZERO)).unwrap();
    let (m, inertia) = {
        let mp = model.block(id).unwrap().mass_properties();
        (mp.mass, mp.mass * (0.04 + 0.04) / 12.0)
    };
    let m0 = 0.05;
    let sine = TimeHistory::sine(1.0, FREQUENCY, 1.0, 400).unwrap();
    let load = LoadHistory::new(wrench(Vector::new(F0, 0.0, 0.0), Vector::new(0.0, 0.0, m0)), sine).unwrap();
    model.set_load_history(id, Some(load)).unwrap();
    let initial = model.block(id).unwrap().state().pose.rotation;
    let x0 = model.block(id).unwrap().state().pose.translation.x;
    model.run_until_time(0.75).unwrap();
    let t = model.time();
    let w = 2.0 * PI * FREQUENCY;
    let shape = t / w - (w * t).sin() / (w * w);
    let state = model.block(id).unwrap().state();
    let x = state.pose.translation.x - x0;
    assert!((x / (F0 / m * shape) - 1.0).abs() < 1e-3, "x {x} vs {}", F0 / m * shape);
    // Poses turn the principal frame into the world's: the turn since the start.
    let theta = (state.pose.rotation * initial.inverse()).to_scaled_axis().z;
    assert!((theta / (m0 / inertia * shape) - 1.0).abs() < 1e-3, "θ {theta}");
    let e = model.energies();
    assert!(e.load_work > 0.0);
    assert!(
        e.balance_error().abs() < 1e-6 * e.load_work,
        "balance error {} of load work {}",
        e.balance_error(),
        e.load_work
    );
    // Past the end of the history (1 s), the factor holds its last value, sin 2π = 0.
    model.run_until_time(1.2).unwrap();
    let v = model.block(id).unwrap().state().velocity.x;
    model.run_until_time(1.3).unwrap();
    assert!((model.block(id).unwrap().state().velocity.x - v).abs() < 1e-9 * v.abs().max(1.0));
}

/// A cube on a slab (φ 20°) pushed by a pulse of 0.6 W, ramped up in 20 ms, held 80 ms, ramped
/// down in 20 ms: it slides and friction stops it. With every other term booked, the balance
/// closes within 0.1 % of the load's work, friction's work never decreases, and once the block
/// has stopped (its kinetic energy below 0.1 % of the load's work) friction has dissipated the
/// load's work within 1 % (the rest is stored in the joint springs).
#[test]
fn a_load_pulse_slides_a_block_and_the_energy_closes() {
    let mut model = model(CoulombSlip::dry(1e9, 4e8, 20.0).unwrap());
    model.add_block(fixed_slab("slab")).unwrap();
    let id = model.add_block(cube("cube", Vector::ZERO)).unwrap();
    model.run_to_equilibrium(1e-6, 200_000).unwrap();
    model.set_damping(Damping::None).unwrap();
    let before = model.energies();
    let weight = model.block(id).unwrap().mass_properties().mass * 9.81;
    let pulse = TimeHistory::new(vec![0.0, 0.02, 0.1, 0.12], vec![0.0, 1.0, 1.0, 0.0]).unwrap();
    let load = wrench(Vector::new(0.6 * weight, 0.0, 0.0), Vector::ZERO);
    model
        .set_load_history(id, Some(LoadHistory::new(load, pulse).unwrap()))
        .unwrap();
    let x0 = model.block(id).unwrap().state().pose.translation.x;
    let mut friction = before.friction;
    while model.time() < 0.5 {
        model.run_steps(50).unwrap();
        let e = model.energies();
        // Once the block has stopped, its joint rings with shear reversals, at which a step
        // may book a few nJ below zero (docs/theory.md §6): far below a µJ.
        assert!(
            e.friction >= friction - 1e-6,
            "friction booked {} J",
            e.friction - friction
        );
        friction = e.friction;
    }
    let e = model.energies();
    let load_work = e.load_work - before.load_work;
    assert!(load_work > 0.0);
    assert!(
        (e.balance_error() - before.balance_error()).abs() < 1e-3 * load_work,
        "balance error {} of load work {load_work}",
        e.balance_error() - before.balance_error()
    );
    let slid = model.block(id).unwrap().state().pose.translation.x - x0;
    assert!(slid > 1e-3, "slid {slid}");
    // Stopped: what moves is the block ringing on its undamped joint springs.
    assert!(e.kinetic < 1e-3 * load_work, "kinetic energy {} J left", e.kinetic);
    let dissipated = e.friction - before.friction;
    assert!(
        (dissipated - load_work).abs() < 0.01 * load_work,
        "friction {dissipated} vs load work {load_work}"
    );
}

/// A checkpoint taken mid-history resumes bit for bit; a scene keeps the history (from its
/// own time 0); `set_load` replaces the history with a constant load; removing the history
/// leaves the last load.
#[test]
fn load_histories_survive_checkpoints_and_scenes() {
    let mut model = model(CoulombSlip::dry(1e9, 4e8, 20.0).unwrap());
    model.add_block(fixed_slab("slab")).unwrap();
    let id = model.add_block(cube("cube", Vector::ZERO)).unwrap();
    let ramp = TimeHistory::new(vec![0.0, 0.05], vec![0.0, 1.0]).unwrap();
    let load = LoadHistory::new(wrench(Vector::new(30.0, 0.0, 0.0), Vector::ZERO), ramp).unwrap();
    model.set_load_history(id, Some(load.clone())).unwrap();
    assert!(model.set_load_history(BlockId(7), Some(load.clone())).is_err());

    let scene = Scene::from_model(&model);
    assert_eq!(scene.blocks[1].load_history.as_ref(), Some(&load));
    let rebuilt: Model = Scene::from_json(&scene.to_json().unwrap()).unwrap().build().unwrap();
    assert_eq!(rebuilt.load_histories().count(), 1);

    model.run_until_time(0.02).unwrap();
    let text = model.to_checkpoint_string().unwrap();
    let mut resumed: Model = Model::from_checkpoint_str(&text).unwrap();
    assert_eq!(resumed.load_histories().next().unwrap().2, 0.0);
    model.run_until_time(0.08).unwrap();
    resumed.run_until_time(0.08).unwrap();
    assert_eq!(fingerprint(&model), fingerprint(&resumed));
    assert_eq!(model.block(id).unwrap().load().force.x, 30.0);

    model.set_load_history(id, None).unwrap();
    model.step().unwrap();
    assert_eq!(model.block(id).unwrap().load().force.x, 30.0, "the last load stays");
    model.set_load_history(id, Some(load)).unwrap();
    model
        .set_load(id, wrench(Vector::new(5.0, 0.0, 0.0), Vector::ZERO))
        .unwrap();
    assert_eq!(model.load_histories().count(), 0);
    model.step().unwrap();
    assert_eq!(model.block(id).unwrap().load().force.x, 5.0);
}
