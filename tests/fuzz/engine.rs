//! A small time-bounded fuzzing engine on proptest strategies, shared by the fuzz targets
//! (`tests/fuzz.rs` for the loaders, `arch/tests/fuzz_cli.rs` for the command lines).
//!
//! Each target mutates the seeds of its corpus (`tests/fuzz/corpus/<target>/`) with a drawn
//! [`Plan`]: structural edits of the JSON (numbers replaced by hostile values, keys deleted,
//! nodes replaced, array items duplicated) and then byte edits (flips, insertions, deletions,
//! truncation). The property is the target's `check`: it returns `Err` for a wrong answer
//! (a model that loads and then goes non-finite, a round trip that fails); a panic is a failure
//! too. A failing input is shrunk with proptest's value trees and written to
//! `target/tmp/fuzz-artifacts/`. An input that runs longer than 30 s aborts the run after
//! writing its artifact: a hang is a failure.
//!
//! The budget per target is `VOUSSOIR_FUZZ_SECONDS` (default 1 s, so that `cargo test` stays
//! quick; `.ci/run` gives each target 20 s); the draws follow `VOUSSOIR_FUZZ_SEED` (default
//! fixed), so a run is reproducible up to how many inputs fit in the budget.

#![allow(dead_code)]

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use proptest::prelude::*;
use proptest::strategy::ValueTree;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use serde_json::Value;

/// Numbers a loader must survive: zero, negatives, denormal-small and huge magnitudes, the
/// edges of the integer types, angles at and past their ranges.
const HOSTILE_NUMBERS: &[f64] = &[
    0.0,
    -0.0,
    -1.0,
    1e-300,
    1e-12,
    0.5,
    2.0,
    90.0,
    180.0,
    1e12,
    1e300,
    1.7e308,
    -1e308,
    65535.0,
    4294967297.0,
];

/// One structural edit of a JSON document (indices are taken modulo what exists).
#[derive(Debug, Clone)]
pub enum JsonEdit {
    /// Replace the n-th number with a hostile one.
    Number(usize, usize),
    /// Replace the n-th number with a hostile integer (u64::MAX, i64::MIN, 2⁵³ + 1).
    Integer(usize, usize),
    /// Delete the n-th object key.
    DeleteKey(usize),
    /// Replace the n-th node with null, [], {}, "", true, a long string or a deep array.
    Replace(usize, usize),
    /// Duplicate an item of the n-th array.
    Duplicate(usize),
}

/// One byte edit of the text.
#[derive(Debug, Clone)]
pub enum ByteEdit {
    /// Flip a bit.
    Flip(usize, u8),
    /// Insert a byte (JSON punctuation, a digit, a letter or any byte).
    Insert(usize, u8),
    /// Delete up to 8 bytes.
    Delete(usize, usize),
    /// Cut the text.
    Truncate(usize),
}

/// What is done to one seed.
#[derive(Debug, Clone)]
pub struct Plan {
    /// Which seed.
    pub seed: usize,
    /// Structural edits, applied first (when the seed is JSON).
    pub json: Vec<JsonEdit>,
    /// Byte edits, applied after.
    pub bytes: Vec<ByteEdit>,
}

fn json_edit() -> impl Strategy<Value = JsonEdit> {
    prop_oneof![
        4 => (any::<usize>(), 0..HOSTILE_NUMBERS.len()).prop_map(|(n, v)| JsonEdit::Number(n, v)),
        1 => (any::<usize>(), 0..3usize).prop_map(|(n, v)| JsonEdit::Integer(n, v)),
        2 => any::<usize>().prop_map(JsonEdit::DeleteKey),
        2 => (any::<usize>(), 0..7usize).prop_map(|(n, k)| JsonEdit::Replace(n, k)),
        1 => any::<usize>().prop_map(JsonEdit::Duplicate),
    ]
}

fn byte_edit() -> impl Strategy<Value = ByteEdit> {
    let interesting = prop_oneof![
        Just(b'{'),
        Just(b'}'),
        Just(b'['),
        Just(b']'),
        Just(b'"'),
        Just(b','),
        Just(b':'),
        Just(b'-'),
        Just(b'e'),
        Just(b'.'),
        Just(b'\\'),
        Just(b'\n'),
        b'0'..=b'9',
        any::<u8>(),
    ];
    prop_oneof![
        3 => (any::<usize>(), 0..8u8).prop_map(|(p, b)| ByteEdit::Flip(p, b)),
        3 => (any::<usize>(), interesting).prop_map(|(p, b)| ByteEdit::Insert(p, b)),
        2 => (any::<usize>(), 1..8usize).prop_map(|(p, n)| ByteEdit::Delete(p, n)),
        1 => any::<usize>().prop_map(ByteEdit::Truncate),
    ]
}

/// Plans over `seeds` seeds: mostly structural (they reach the validation behind the parser),
/// some byte-level (they reach the parser's own errors).
pub fn plan(seeds: usize) -> impl Strategy<Value = Plan> {
    (
        0..seeds,
        prop::collection::vec(json_edit(), 0..4),
        prop_oneof![3 => Just(0usize), 1 => 1..4usize],
    )
        .prop_flat_map(|(seed, json, n_bytes)| {
            prop::collection::vec(byte_edit(), n_bytes).prop_map(move |bytes| Plan {
                seed,
                json: json.clone(),
                bytes,
            })
        })
}

/// Visits the nodes of `v` in document order, calling `f` with the running index.
fn visit<'a>(v: &'a mut Value, f: &mut dyn FnMut(&mut Value) -> bool) -> bool {
    if f(v) {
        return true;
    }
    match v {
        Value::Array(items) => items.iter_mut().any(|x| visit(x, f)),
        Value::Object(map) => map.values_mut().any(|x| visit(x, f)),
        _ => false,
    }
}

fn apply_json(doc: &mut Value, edit: &JsonEdit) {
    let count = |doc: &mut Value, pick: &dyn Fn(&Value) -> bool| {
        let mut n = 0usize;
        visit(doc, &mut |v| {
            n += usize::from(pick(v));
            false
        });
        n
    };
    let nth_mut = |doc: &mut Value, pick: &dyn Fn(&Value) -> bool, n: usize, change: &mut dyn FnMut(&mut Value)| {
        let mut i = 0usize;
        visit(doc, &mut |v| {
            if pick(v) {
                if i == n {
                    change(v);
                    return true;
                }
                i += 1;
            }
            false
        });
    };
    match *edit {
        JsonEdit::Number(n, k) | JsonEdit::Integer(n, k) => {
            let total = count(doc, &|v| v.is_number());
            if total == 0 {
                return;
            }
            let value = match edit {
                JsonEdit::Number(..) => serde_json::Number::from_f64(HOSTILE_NUMBERS[k]).map(Value::Number),
                _ => Some(match k {
                    0 => Value::from(u64::MAX),
                    1 => Value::from(i64::MIN),
                    _ => Value::from((1u64 << 53) + 1),
                }),
            };
            if let Some(value) = value {
                nth_mut(doc, &|v| v.is_number(), n % total, &mut |v| *v = value.clone());
            }
        }
        JsonEdit::DeleteKey(n) => {
            let total = count(doc, &|v| v.as_object().is_some_and(|m| !m.is_empty()));
            if total == 0 {
                return;
            }
            nth_mut(
                doc,
                &|v| v.as_object().is_some_and(|m| !m.is_empty()),
                n % total,
                &mut |v| {
                    if let Value::Object(m) = v {
                        let key = m.keys().nth(n % m.len()).cloned();
                        if let Some(key) = key {
                            m.remove(&key);
                        }
                    }
                },
            );
        }
        JsonEdit::Replace(n, k) => {
            let total = count(doc, &|_| true);
            let with = match k {
                0 => Value::Null,
                1 => Value::Array(Vec::new()),
                2 => Value::Object(Default::default()),
                3 => Value::String(String::new()),
                4 => Value::Bool(true),
                5 => Value::String("x".repeat(100_000)),
                _ => (0..200).fold(Value::Null, |inner, _| Value::Array(vec![inner])),
            };
            nth_mut(doc, &|_| true, n % total.max(1), &mut |v| *v = with.clone());
        }
        JsonEdit::Duplicate(n) => {
            let total = count(doc, &|v| v.as_array().is_some_and(|a| !a.is_empty()));
            if total == 0 {
                return;
            }
            nth_mut(
                doc,
                &|v| v.as_array().is_some_and(|a| !a.is_empty()),
                n % total,
                &mut |v| {
                    if let Value::Array(a) = v {
                        let item = a[n % a.len()].clone();
                        a.push(item);
                    }
                },
            );
        }
    }
}

fn apply_bytes(text: &mut Vec<u8>, edit: &ByteEdit) {
    let len = text.len();
    match *edit {
        ByteEdit::Flip(p, bit) if len > 0 => text[p % len] ^= 1 << bit,
        ByteEdit::Insert(p, b) => text.insert(p % (len + 1), b),
        ByteEdit::Delete(p, n) if len > 0 => {
            let start = p % len;
            text.drain(start..(start + n).min(len));
        }
        ByteEdit::Truncate(p) => text.truncate(p % (len + 1)),
        _ => {}
    }
}

/// The input a plan makes of the seeds (lossy UTF-8: the loaders take `&str`).
pub fn apply(seeds: &[String], plan: &Plan) -> String {
    let seed = &seeds[plan.seed % seeds.len()];
    let mut text = match serde_json::from_str::<Value>(seed) {
        Ok(mut doc) if !plan.json.is_empty() => {
            for e in &plan.json {
                apply_json(&mut doc, e);
            }
            serde_json::to_string_pretty(&doc).unwrap_or_else(|_| seed.clone())
        }
        _ => seed.clone(),
    }
    .into_bytes();
    for e in &plan.bytes {
        apply_bytes(&mut text, e);
    }
    String::from_utf8_lossy(&text).into_owned()
}

/// The seeds of a corpus folder under `tests/fuzz/corpus/`, sorted by name.
pub fn corpus(target: &str) -> Vec<String> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fuzz/corpus")
        .join(target);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("corpus {}: {e}", dir.display()))
        .map(|e| e.expect("corpus entry").path())
        .collect();
    files.sort();
    files
        .iter()
        .map(|f| std::fs::read_to_string(f).unwrap_or_else(|e| panic!("{}: {e}", f.display())))
        .collect()
}

/// What a fuzz run did.
#[derive(Debug, Clone, Copy)]
pub struct Outcome {
    /// Inputs tried.
    pub inputs: u64,
    /// Inputs the target accepted (its `check` returned `Ok(true)`).
    pub accepted: u64,
}

fn budget() -> (Duration, u64) {
    let seconds = std::env::var("VOUSSOIR_FUZZ_SECONDS")
        .ok()
        .and_then(|s| s.parse::<f64>().ok())
        .filter(|s| s.is_finite() && *s >= 0.0)
        .unwrap_or(1.0);
    let seed = std::env::var("VOUSSOIR_FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse::<u64>().ok())
        .unwrap_or(0x766f_7573_736f_6972);
    (Duration::from_secs_f64(seconds), seed)
}

fn artifact(target: &str, kind: &str, input: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("fuzz-artifacts");
    let _ = std::fs::create_dir_all(&dir);
    let path = dir.join(format!("{target}-{kind}.txt"));
    let _ = std::fs::write(&path, input);
    path
}

/// Runs `check` on inputs mutated from `seeds` for the budget. `check` returns `Ok(true)`
/// when the input was accepted (loaded), `Ok(false)` when it was refused with a typed error,
/// `Err(why)` for a wrong answer. Panics (after shrinking and writing the artifact) on the
/// first failure; aborts on an input that runs for 30 s.
pub fn fuzz(target: &str, seeds: &[String], check: impl Fn(&str) -> Result<bool, String>) -> Outcome {
    assert!(!seeds.is_empty(), "{target}: empty corpus");
    let (limit, seed) = budget();
    let mut bytes = [0u8; 32];
    bytes[..8].copy_from_slice(&seed.to_le_bytes());
    let mut runner = TestRunner::new_with_rng(Config::default(), TestRng::from_seed(RngAlgorithm::ChaCha, &bytes));
    let strategy = plan(seeds.len());

    // The watchdog: an input running for 30 s is a hang.
    let current: Arc<Mutex<(Instant, String)>> = Arc::new(Mutex::new((Instant::now(), String::new())));
    let done = Arc::new(AtomicBool::new(false));
    let watchdog = {
        let (current, done, target) = (Arc::clone(&current), Arc::clone(&done), target.to_owned());
        std::thread::spawn(move || {
            while !done.load(Ordering::Relaxed) {
                std::thread::sleep(Duration::from_millis(100));
                let guard = current.lock().unwrap_or_else(|e| e.into_inner());
                if guard.0.elapsed() > Duration::from_secs(30) {
                    let path = artifact(&target, "hang", &guard.1);
                    eprintln!(
                        "{target}: an input ran for 30 s (a hang); written to {}",
                        path.display()
                    );
                    std::process::abort();
                }
            }
        })
    };
    let run = |input: &str| -> Result<bool, String> {
        *current.lock().unwrap_or_else(|e| e.into_inner()) = (Instant::now(), input.to_owned());
        catch_unwind(AssertUnwindSafe(|| check(input))).unwrap_or_else(|p| {
            let msg = p
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            Err(format!("panic: {msg}"))
        })
    };

    let started = Instant::now();
    let mut outcome = Outcome { inputs: 0, accepted: 0 };
    // Every seed as it is first: each must be accepted.
    for (i, s) in seeds.iter().enumerate() {
        match run(s) {
            Ok(true) => outcome.accepted += 1,
            Ok(false) => panic!("{target}: seed {i} is refused"),
            Err(e) => panic!("{target}: seed {i}: {e}"),
        }
        outcome.inputs += 1;
    }
    while started.elapsed() < limit {
        let mut tree = strategy.new_tree(&mut runner).expect("plan");
        let input = apply(seeds, &tree.current());
        outcome.inputs += 1;
        match run(&input) {
            Ok(accepted) => outcome.accepted += u64::from(accepted),
            Err(first) => {
                // Shrink: keep simplifying while the input still fails.
                let (mut failing, mut why, mut failing_plan) = (input, first, tree.current());
                for _ in 0..500 {
                    if !tree.simplify() {
                        break;
                    }
                    let smaller = apply(seeds, &tree.current());
                    match run(&smaller) {
                        Err(e) => (failing, why, failing_plan) = (smaller, e, tree.current()),
                        Ok(_) => {
                            if !tree.complicate() {
                                break;
                            }
                        }
                    }
                }
                done.store(true, Ordering::Relaxed);
                let path = artifact(target, "failure", &failing);
                panic!(
                    "{target}: {why}\n(plan {failing_plan:?}; input written to {}; reproduce with VOUSSOIR_FUZZ_SEED={seed})",
                    path.display()
                );
            }
        }
    }
    done.store(true, Ordering::Relaxed);
    let _ = watchdog.join();
    println!(
        "{target}: {} inputs in {:.1} s ({} accepted, {} refused with an error), seed {seed}",
        outcome.inputs,
        started.elapsed().as_secs_f64(),
        outcome.accepted,
        outcome.inputs - outcome.accepted
    );
    outcome
}
