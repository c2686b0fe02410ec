//! The command lines of the core crate's examples (`block_on_incline`, `scaling`,
//! `shear_wall`) against hostile input (issue 18), and the argument checks they share with
//! `voussoir-arch` (`examples/common/args.rs`). The runs of the built examples need
//! `cargo build --release --examples`, which `cargo test --release` does.

#[path = "../examples/common/args.rs"]
mod args;

#[path = "support/example_binary.rs"]
mod example_binary;

use example_binary::example;
use std::ops::Bound::{Excluded, Included, Unbounded};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

#[test]
fn real_values_are_finite_and_in_range() {
    let angle = args::real(Included(0.0), Excluded(90.0));
    assert_eq!(angle("0"), Ok(0.0));
    assert_eq!(angle(" 35.5 "), Ok(35.5));
    for bad in ["90", "180", "-35", "nan", "inf", "-inf", "abc", ""] {
        let e = angle(bad).expect_err(bad);
        assert!(e.contains("[0, 90)"), "{bad}: {e}");
    }
    assert_eq!(args::positive("1e-9"), Ok(1e-9));
    for bad in ["0", "-1", "NaN", "infinity"] {
        assert!(args::positive(bad).is_err(), "{bad}");
    }
    let any = args::real(Unbounded, Unbounded);
    assert_eq!(any("-1e300"), Ok(-1e300));
    assert!(any("inf").is_err() && any("nan").is_err());
    assert!(args::finite("1e400").is_err(), "overflows to inf");
}

#[test]
fn intervals_print_as_read() {
    let i = |lo, hi| args::Interval { lo, hi }.to_string();
    assert_eq!(i(Included(0.0), Included(0.2)), "[0, 0.2]");
    assert_eq!(i(Excluded(0.0), Excluded(90.0)), "(0, 90)");
    assert_eq!(i(Included(1e7), Included(1e12)), "[1e7, 1e12]");
    assert_eq!(i(Excluded(0.0), Included(1e-6)), "(0, 1e-6]");
    assert_eq!(i(Excluded(0.0), Unbounded), "(0, ∞)");
}

#[test]
fn whole_numbers_and_duplicates() {
    let at_least_one = args::whole::<u64>(1);
    assert_eq!(at_least_one("50"), Ok(50));
    for bad in ["0", "-1", "1.5", "abc", ""] {
        let e = at_least_one(bad).expect_err(bad);
        assert!(e.contains("≥ 1"), "{bad}: {e}");
    }
    assert_eq!(args::unique("--setup", &["a", "b"]), Ok(()));
    let e = args::unique("--setup", &["a", "b", "a"]).expect_err("twice");
    assert!(
        e.contains("--setup") && e.contains("\"a\"") && e.contains("twice"),
        "{e}"
    );
}

/// A fresh, empty folder for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("voussoir-examples-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch folder");
    dir
}

#[test]
fn the_output_folder_is_probed() {
    let dir = scratch("probe");
    let file = dir.join("a_file");
    std::fs::write(&file, "x").expect("write");
    let summary = ["summary.json".to_owned()];
    let e = args::prepare_output_dir(&file, &[], &summary).expect_err("file in the way");
    assert!(
        matches!(&e, voussoir::Error::Io { path, .. } if path == &file.display().to_string()),
        "{e}"
    );
    let e = args::prepare_output_dir(&file.join("below"), &[], &summary).expect_err("below a file");
    assert!(e.to_string().contains("a_file"), "{e}");
    std::fs::create_dir_all(dir.join("out/summary.json")).expect("mkdir");
    let e = args::prepare_output_dir(&dir.join("out"), &[], &summary).expect_err("folder in the way");
    assert!(
        e.to_string().contains("summary.json") && e.to_string().contains("is a folder"),
        "{e}"
    );
    args::prepare_output_dir(&dir.join("new/deeper"), &["paraview"], &summary).expect("fresh");
    assert!(dir.join("new/deeper/paraview").is_dir());
    let _ = std::fs::remove_dir_all(&dir);
}

/// Runs an example in `cwd`: exit code, stdout, stderr, wall time.
fn run(name: &str, args: &[&str], cwd: &Path) -> (Option<i32>, String, String, Duration) {
    let started = Instant::now();
    let o = Command::new(example(name))
        .args(args)
        .current_dir(cwd)
        .output()
        .expect("runs");
    (
        o.status.code(),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
        started.elapsed(),
    )
}

#[test]
fn block_on_incline_refuses_what_it_ignored() {
    let dir = scratch("incline");
    let (code, stdout, _, _) = run("block_on_incline", &["--help"], &dir);
    assert_eq!(code, Some(0));
    assert!(stdout.contains("[0, 90)") && stdout.contains("SLOPE_DEG"), "{stdout}");
    // Each used to run (ignored, or a ramp at 180° or −35°, or an error about the ramp block).
    for (args, expected) in [
        (&["180"][..], "SLOPE_DEG"),
        (&["-35"], "SLOPE_DEG"),
        (&["nan"], "SLOPE_DEG"),
        (&["35", "90"], "FRICTION_DEG"),
        (&["35", "-1"], "FRICTION_DEG"),
        (&["--slope", "35"], "--slope"),
        (&["35", "30", "5"], "5"),
    ] {
        let (code, _, stderr, _) = run("block_on_incline", args, &dir);
        assert_eq!(code, Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(expected), "{args:?}: {stderr}");
    }
    let (code, stdout, stderr, _) = run("block_on_incline", &["20", "30"], &dir);
    assert_eq!(code, Some(0), "{stderr}");
    assert!(stdout.contains("slope 20°, friction 30°"), "{stdout}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn scaling_checks_its_counts_and_folder_first() {
    let dir = scratch("scaling");
    for (args, expected) in [
        (&["--blocks", "0"][..], "--blocks"),
        (&["--blocks", "100,abc"], "--blocks"),
        (&["--steps", "0"], "--steps"),
        (&["--spacing", "0"], "--spacing"),
        (&["--spacing", "nan"], "--spacing"),
        (&["--frobnicate"], "--frobnicate"),
    ] {
        let (code, _, stderr, _) = run("scaling", args, &dir);
        assert_eq!(code, Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(expected), "{args:?}: {stderr}");
    }
    // A file in place of the output folder: refused before the first wall is built.
    std::fs::write(dir.join("a_file"), "x").expect("write");
    let (code, _, stderr, wall) = run("scaling", &["--out", "a_file", "--blocks", "100000"], &dir);
    assert_eq!(code, Some(1), "{stderr}");
    assert!(stderr.contains("a_file"), "{stderr}");
    assert!(wall < Duration::from_secs(2), "took {wall:?}");
    // A small run writes its summary.
    let (code, _, stderr, _) = run("scaling", &["--blocks", "20", "--steps", "1", "--out", "s"], &dir);
    assert_eq!(code, Some(0), "{stderr}");
    assert!(dir.join("s/summary.json").is_file());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn scaling_shakes_the_wall_on_request() {
    let dir = scratch("scaling-shake");
    for (args, expected) in [(&["--scene", "quake"][..], "--scene"), (&["--warmup", "0"], "--warmup")] {
        let (code, _, stderr, _) = run("scaling", args, &dir);
        assert_eq!(code, Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(expected), "{args:?}: {stderr}");
    }
    // The base moves about 0.8 mm by the end: beyond the 0.25 mm re-detection trigger.
    let args = [
        "--scene", "shake", "--blocks", "20", "--warmup", "100", "--steps", "100", "--out", "s",
    ];
    let (code, stdout, stderr, _) = run("scaling", &args, &dir);
    assert_eq!(code, Some(0), "{stderr}");
    assert!(stdout.contains("shaking"), "{stdout}");
    let summary = std::fs::read_to_string(dir.join("s/summary.json")).expect("summary");
    let runs: serde_json::Value = serde_json::from_str(&summary).expect("json");
    let first = &runs["runs"][0];
    assert_eq!(first["scene"], "shake", "{summary}");
    assert!(
        first["redetections_per_step"].as_f64().expect("redetections") > 0.0,
        "{summary}"
    );
    assert!(first["peak_rss_bytes"].as_u64().expect("memory") > 0, "{summary}");
    // The default is the resting wall.
    let (code, stdout, stderr, _) = run("scaling", &["--blocks", "20", "--steps", "1", "--out", "r"], &dir);
    assert_eq!(code, Some(0), "{stderr}");
    assert!(stdout.contains("settling"), "{stdout}");
    let summary = std::fs::read_to_string(dir.join("r/summary.json")).expect("summary");
    assert!(summary.contains("\"scene\": \"rest\""), "{summary}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn shear_wall_refuses_bad_options_before_it_runs() {
    let dir = scratch("shear_wall");
    let out = dir.join("out");
    let out_arg = out.to_str().expect("utf-8 path");
    for (args, expected) in [
        (&["--ensemble", "1"][..], "--ensemble"),
        (&["--ensemble", "two"], "--ensemble"),
        (&["--masonry-strength-mpa", "0"], "--masonry-strength-mpa"),
        (&["--masonry-strength-mpa", "nan"], "--masonry-strength-mpa"),
        (&["--cap", "soft"], "--cap"),
        (&["--stiffness", "elastic"], "--stiffness"),
        (&["--top", "free"], "--top"),
    ] {
        let mut all = args.to_vec();
        all.extend(["--out", out_arg]);
        let (code, _, stderr, _) = run("shear_wall", &all, &dir);
        assert_eq!(code, Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(expected), "{args:?}: {stderr}");
        assert!(!out.exists(), "{args:?} wrote {}", out.display());
    }
    let _ = std::fs::remove_dir_all(&dir);
}
