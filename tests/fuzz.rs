//! Fuzzing of the loaders (issues 18 and 33): scene files (with base motions) and checkpoints,
//! and base-motion CSV records (`TimeHistory::from_csv`), mutated from the seeds in
//! `tests/fuzz/corpus/` by the engine of `tests/fuzz/engine.rs` for a time budget
//! (`VOUSSOIR_FUZZ_SECONDS` per target, default 1 s; `.ci/run` gives 20 s).
//!
//! The property: a loader returns the model or a typed error with a message, never panics or
//! hangs; a model it returns builds, records and steps without panicking, and whatever it
//! reports after a successful step is finite.

#[path = "fuzz/engine.rs"]
mod engine;

use voussoir::io::scene::Scene;
use voussoir::loading::{BaseMotion, MotionKind, TimeHistory};
use voussoir::prelude::*;

/// Steps a loaded model a few times: `Err` only for a wrong answer (a panic is caught by the
/// engine). A typed error from a step is a fine answer to a hostile model.
fn exercise(model: &mut Model) -> Result<(), String> {
    for _ in 0..5 {
        if model.step().is_err() {
            return Ok(());
        }
        let finite = |v: Vector| v.is_finite();
        for (i, b) in model.blocks().iter().enumerate() {
            let s = b.state();
            if !(finite(s.pose.translation) && finite(s.velocity) && finite(s.angular_velocity)) {
                return Err(format!("block {i} is not finite after a successful step: {s:?}"));
            }
        }
        if !model.dt().is_finite() || model.dt() <= 0.0 {
            return Err(format!("dt {} after a successful step", model.dt()));
        }
    }
    Ok(())
}

fn check_scene(text: &str) -> Result<bool, String> {
    let scene = match Scene::<CoulombSlip>::from_json(text) {
        Ok(s) => s,
        Err(e) => return message(e),
    };
    let mut model = match scene.build() {
        Ok(m) => m,
        Err(e) => return message(e),
    };
    let mut recorder = match scene.recorder(&model) {
        Ok(r) => r,
        Err(e) => return message(e),
    };
    exercise(&mut model)?;
    recorder.record(&model);
    let _ = voussoir::io::csv::history_to_csv(recorder.history());
    Ok(true)
}

/// A refusal must say something.
fn message(e: voussoir::Error) -> Result<bool, String> {
    if e.to_string().trim().is_empty() {
        return Err(format!("an error without a message: {e:?}"));
    }
    Ok(false)
}

#[test]
fn fuzz_scene_files() {
    let seeds = engine::corpus("scene");
    let outcome = engine::fuzz("scene", &seeds, check_scene);
    assert!(outcome.inputs > seeds.len() as u64);
}

/// Checkpoints of the scene seeds after 20 steps: the checkpoint seeds (generated from the
/// scene corpus, so that they follow the format of the build under test). Seeds kept for the
/// errors they give (e.g. `overflow-stiffness.json`) make no checkpoint.
fn checkpoint_seeds() -> Vec<String> {
    engine::corpus("scene")
        .iter()
        .filter_map(|text| {
            let scene = Scene::<CoulombSlip>::from_json(text).expect("scene seed");
            let mut model = scene.build().expect("build");
            model.run_steps(20).ok()?;
            Some(model.to_checkpoint_string().expect("checkpoint"))
        })
        .collect()
}

/// A mutated checkpoint is refused by its checksum unless the mutation left the content as it
/// was; resealed (`reseal_checkpoint`, as a user who edits a file on purpose does), it reaches
/// the validation behind the checksum, and what loads there saves, loads again and steps.
fn check_checkpoint(text: &str) -> Result<bool, String> {
    if let Ok(model) = Model::<CoulombSlip>::from_checkpoint_str(text) {
        // Only an unchanged content passes the checksum: it saves as a seed does.
        let again = model
            .to_checkpoint_string()
            .map_err(|e| format!("a loaded checkpoint does not save: {e}"))?;
        Model::<CoulombSlip>::from_checkpoint_str(&again)
            .map_err(|e| format!("a re-saved checkpoint does not load: {e}"))?;
    }
    let sealed = match voussoir::model::reseal_checkpoint(text) {
        Ok(s) => s,
        Err(e) => return message(e),
    };
    let mut model = match Model::<CoulombSlip>::from_checkpoint_str(&sealed) {
        Ok(m) => m,
        Err(e) => return message(e),
    };
    let again = model
        .to_checkpoint_string()
        .map_err(|e| format!("a loaded checkpoint does not save: {e}"))?;
    Model::<CoulombSlip>::from_checkpoint_str(&again)
        .map_err(|e| format!("a re-saved checkpoint does not load: {e}"))?;
    exercise(&mut model)?;
    Ok(true)
}

#[test]
fn fuzz_checkpoints() {
    let seeds = checkpoint_seeds();
    let outcome = engine::fuzz("checkpoint", &seeds, check_checkpoint);
    assert!(outcome.inputs > seeds.len() as u64);
}

/// A base-motion record read from CSV text (columns 0 and 1, and 1 and 2, scaled as a record
/// in g): a history with finite values at strictly increasing finite times, whose motions of
/// every kind give finite displacements and velocities, or a typed error with a message.
fn check_csv(text: &str) -> Result<bool, String> {
    let mut accepted = false;
    for (t, v) in [(0, 1), (1, 2)] {
        let h = match TimeHistory::from_csv(text, t, v, 9.81) {
            Ok(h) => h,
            Err(e) => {
                message(e)?;
                continue;
            }
        };
        let (times, values) = (h.times(), h.values());
        if times.len() < 2 || times.len() != values.len() {
            return Err(format!("{} times and {} values", times.len(), values.len()));
        }
        if !times.windows(2).all(|w| w[0] < w[1]) || !times.iter().chain(values).all(|x| x.is_finite()) {
            return Err(format!(
                "times not increasing or values not finite: {times:?} {values:?}"
            ));
        }
        for kind in [MotionKind::Acceleration, MotionKind::Velocity, MotionKind::Displacement] {
            let motion = match BaseMotion::new(kind, [Some(h.clone()), None, None]) {
                Ok(m) => m,
                Err(e) => {
                    message(e)?;
                    continue;
                }
            };
            let end = h.end();
            for at in [times[0], 0.5 * (times[0] + end), end, end + 1.0] {
                let (u, v) = (motion.displacement(at), motion.mean_velocity(at, 1e-3));
                // Finite unless the record's own integral overflows (values near f64::MAX).
                if !(u.is_finite() && v.is_finite()) && values.iter().all(|x| x.abs() < 1e150) {
                    return Err(format!("{kind:?} at {at}: displacement {u}, velocity {v}"));
                }
            }
        }
        accepted = true;
    }
    Ok(accepted)
}

#[test]
fn fuzz_time_history_csv() {
    let seeds = engine::corpus("csv");
    let outcome = engine::fuzz("csv", &seeds, check_csv);
    assert!(outcome.inputs > seeds.len() as u64);
    assert!(outcome.accepted > 0, "some records are read");
}
