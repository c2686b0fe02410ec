//! Fuzzing of the command lines (issue 18): argument vectors of `arch_impact`, `arch_static`
//! and `limit_arch`, mutated from the seeds in `arch/tests/fuzz/corpus/cli/` (JSON arrays of
//! arguments, the program first) by the engine of `tests/fuzz/engine.rs` for a time budget
//! (`VOUSSOIR_FUZZ_SECONDS`, default 1 s; `.ci/run` gives 20 s).
//!
//! The property: parsing returns the options or a clap error with a message, never panics; the
//! options it returns plan their output files inside the output folder, and every value the
//! parsers range-check is in its range.

#[path = "../../tests/fuzz/engine.rs"]
mod engine;

use serde_json::Value;
use voussoir_arch::cli::arch_impact::ImpactOptions;
use voussoir_arch::cli::arch_limit::{LimitArgs, AMPLITUDE_RANGE};
use voussoir_arch::cli::arch_static::{StaticOptions, FRICTION_RANGE, SERVO_INCREMENT_RANGE, SERVO_RATIO_RANGE};
use voussoir_arch::cli::{parse, CommonOptions, Run};

/// The arguments of an input: a JSON array (non-strings as their JSON text), or else the text
/// split at white space.
fn arguments(text: &str) -> Vec<String> {
    match serde_json::from_str::<Value>(text) {
        Ok(Value::Array(items)) => items
            .into_iter()
            .map(|v| match v {
                Value::String(s) => s,
                other => other.to_string(),
            })
            .collect(),
        _ => text.split_whitespace().map(str::to_owned).collect(),
    }
}

/// The planned outputs are relative file names that stay in the folder.
fn outputs_stay_inside<R: Run>(run: &R) -> Result<(), String> {
    for f in run.outputs() {
        let p = std::path::Path::new(&f);
        if p.is_absolute() || p.components().any(|c| matches!(c, std::path::Component::ParentDir)) || f.is_empty() {
            return Err(format!("planned output `{f}` leaves the output folder"));
        }
    }
    Ok(())
}

fn parsed<R: Run>(args: &[String]) -> Result<Option<(CommonOptions, R)>, String> {
    match parse::<R>(args.iter().cloned()) {
        Ok(x) => {
            outputs_stay_inside(&x.1)?;
            Ok(Some(x))
        }
        Err(e) if e.to_string().trim().is_empty() => Err(format!("an error without a message: {e:?}")),
        Err(_) => Ok(None),
    }
}

fn check(text: &str) -> Result<bool, String> {
    let args = arguments(text);
    let in_range = |name: &str, ok: bool| {
        if ok {
            Ok(())
        } else {
            Err(format!("{name} out of range: {args:?}"))
        }
    };
    match args.first().map(String::as_str) {
        Some("arch_impact") => Ok(parsed::<ImpactOptions>(&args)?.is_some()),
        Some("arch_static") => match parsed::<StaticOptions>(&args)? {
            Some((_, o)) => {
                in_range("--friction", o.friction.iter().all(|&f| FRICTION_RANGE.contains(f)))?;
                in_range("--servo-increment", SERVO_INCREMENT_RANGE.contains(o.servo_increment))?;
                in_range("--servo-ratio", SERVO_RATIO_RANGE.contains(o.servo_ratio))?;
                in_range(
                    "--joint-friction",
                    o.joint_friction.iter().all(|&(_, f)| FRICTION_RANGE.contains(f)),
                )?;
                Ok(true)
            }
            None => Ok(false),
        },
        Some("limit_arch") => match parsed::<LimitArgs>(&args)? {
            Some((_, o)) => {
                in_range("--friction", FRICTION_RANGE.contains(o.friction))?;
                in_range("--amplitude", AMPLITUDE_RANGE.contains(o.amplitude))?;
                in_range("--frames", o.frames >= 2)?;
                Ok(true)
            }
            None => Ok(false),
        },
        // Another program name: parse it as each, none may panic.
        _ => {
            parsed::<ImpactOptions>(&args)?;
            parsed::<StaticOptions>(&args)?;
            parsed::<LimitArgs>(&args)?;
            Ok(false)
        }
    }
}

#[test]
fn fuzz_command_lines() {
    let seeds = engine::corpus("cli");
    let outcome = engine::fuzz("cli", &seeds, check);
    assert!(outcome.inputs > seeds.len() as u64);
}
