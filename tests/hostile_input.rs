//! Issue 33, input silently ignored or misread: unknown fields in scene files, motions without
//! an axis, base-motion CSV files (decimal commas, quotes, UTF-16, CR-only lines), displacement
//! records that jump or snap back, generators asked for more blocks than memory holds, files
//! read without end.

use std::path::Path;

use voussoir::io::scene::Scene;
use voussoir::loading::{BaseMotion, MotionKind, TimeHistory};
use voussoir::prelude::*;

fn example() -> serde_json::Value {
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/examples/block-on-base.json"))
        .expect("example file");
    serde_json::from_str(&text).expect("json")
}

fn load(doc: &serde_json::Value) -> Result<Model> {
    Scene::<CoulombSlip>::from_json(&doc.to_string())?.build()
}

fn motion() -> serde_json::Value {
    serde_json::json!({
        "kind": "Acceleration",
        "axes": [{"times": [0.0, 1.0], "values": [0.0, 1.0]}, null, null]
    })
}

/// An edit of a scene document.
type Edit = Box<dyn Fn(&mut serde_json::Value)>;

/// Each documented object refuses a field it does not know, naming it and its path (they all
/// loaded without a word: a record meant in g ran 9.81 times too weak).
#[test]
fn unknown_fields_are_refused_everywhere() {
    let mut base = example();
    base["blocks"][0]["motion"] = motion();
    load(&base).expect("the example with a motion loads");
    let edits: Vec<(&str, Edit)> = vec![
        (
            "unit",
            Box::new(|d| d["blocks"][0]["motion"]["axes"][0]["unit"] = "g".into()),
        ),
        (
            "scale",
            Box::new(|d| d["blocks"][0]["motion"]["axes"][0]["scale"] = 9.81.into()),
        ),
        ("start", Box::new(|d| d["blocks"][0]["motion"]["start"] = 0.5.into())),
        (
            "translations",
            Box::new(|d| d["blocks"][0]["fixity"]["translations"] = serde_json::json!(["Free", "Free", "Free"])),
        ),
        (
            "torque",
            Box::new(|d| d["blocks"][1]["load"]["torque"] = serde_json::json!([0, 0, 1])),
        ),
        ("beta", Box::new(|d| d["damping"]["Local"]["beta"] = 0.1.into())),
        (
            "dt",
            Box::new(|d| d["parameters"]["time_step"] = serde_json::json!({"Auto": {"safety": 0.5, "dt": 1e-4}})),
        ),
        (
            "offset",
            Box::new(|d| d["monitors"][1]["monitor"]["Reaction"]["offset"] = 1.0.into()),
        ),
    ];
    for (field, edit) in edits {
        let mut doc = base.clone();
        edit(&mut doc);
        let e = load(&doc).err().unwrap_or_else(|| panic!("`{field}` was accepted"));
        let message = e.to_string();
        assert!(
            message.contains("unknown field") && message.contains(field),
            "{field}: {message}"
        );
    }
}

/// A key given twice anywhere in a scene is refused, naming it and where (it loaded the last
/// value: a file edited by hand ran with the value further down); `monitor_interval: 0` is
/// refused (it loaded as 1).
#[test]
fn keys_given_twice_and_a_zero_monitor_interval_are_refused() {
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/examples/block-on-base.json"))
        .expect("example file");
    Scene::<CoulombSlip>::from_json(&text).expect("the example loads");
    let twice = [
        (
            "\"monitor_interval\": 10",
            "\"monitor_interval\": 10, \"monitor_interval\": 3",
            "monitor_interval",
            "",
        ),
        (
            "\"friction_deg\": 30.5,",
            "\"friction_deg\": 30.5, \"friction_deg\": 45,",
            "friction_deg",
            "joints[0].law",
        ),
        (
            "\"density\": 2446.5,\n      \"load\"",
            "\"density\": 2446.5, \"density\": 1.0,\n      \"load\"",
            "density",
            "blocks[1]",
        ),
        (
            "{ \"alpha\": 0.8 }",
            "{ \"alpha\": 0.8, \"alpha\": 0.0 }",
            "alpha",
            "damping",
        ),
        (
            "\"tolerance\": 0.001,",
            "\"tolerance\": 0.001, \"tolerance\": 0.5,",
            "tolerance",
            "parameters.contact",
        ),
        (
            "\"component\": \"Z\"",
            "\"component\": \"Z\", \"component\": \"X\"",
            "component",
            "monitors[1]",
        ),
        (
            "{ \"PerEdge\": 10 }",
            "{ \"PerEdge\": 10, \"PerEdge\": 30 }",
            "PerEdge",
            "parameters.contact.density",
        ),
        (
            "{ \"Local\": { \"alpha\": 0.8 } }",
            "{ \"Local\": { \"alpha\": 0.8 }, \"Local\": { \"alpha\": 0.1 } }",
            "Local",
            "damping",
        ),
    ];
    for (from, to, key, path) in twice {
        assert!(text.contains(from), "{from}");
        let e = Scene::<CoulombSlip>::from_json(&text.replacen(from, to, 1))
            .err()
            .unwrap_or_else(|| panic!("`{key}` given twice was accepted"));
        let message = e.to_string();
        assert!(message.contains(&format!("duplicate key `{key}`")), "{key}: {message}");
        assert!(message.contains(path), "{key}: {message} does not say where ({path})");
    }
    let e = Scene::<CoulombSlip>::from_json(&text.replace("\"monitor_interval\": 10", "\"monitor_interval\": 0"))
        .unwrap_err();
    assert!(
        e.to_string().contains("monitor_interval") && e.to_string().contains("at least 1"),
        "{e}"
    );
    // serde's derived objects refused a duplicate field before (a variant given twice with
    // "expected value"); the probe's case was Python's, whose reader went through a `Value`
    // (test_hostile.py). A checkpoint goes through a `Value` too.
    let mut model = voussoir::scenes::benchmark_wall(20).unwrap();
    model.run_steps(2).unwrap();
    let checkpoint = model.to_checkpoint_string().unwrap();
    let at = checkpoint.find("\"step\":").expect("a step field");
    let edited = format!("{}\"step\": 0, {}", &checkpoint[..at], &checkpoint[at..]);
    let e = Model::<CoulombSlip>::from_checkpoint_str(&edited).unwrap_err();
    assert!(e.to_string().contains("duplicate key `step`"), "{e}");
}

/// A motion with three null axes is refused on load as `BaseMotion::new` refuses it.
#[test]
fn a_motion_without_an_axis_is_refused_on_load() {
    let mut doc = example();
    doc["blocks"][0]["motion"] = serde_json::json!({"kind": "Velocity", "axes": [null, null, null]});
    let e = load(&doc).unwrap_err().to_string();
    assert!(e.contains("at least one axis") && e.contains("blocks[0].motion"), "{e}");
}

/// Displacement records: one starting at a value other than 0 is refused (the block would jump
/// by it in one step); one ending at 10 mm holds 10 mm after its end (it used to snap back to 0
/// in one step).
#[test]
fn displacement_records_neither_jump_nor_snap_back() {
    let late = TimeHistory::new(vec![0.5, 1.0], vec![0.01, 0.02]).expect("history");
    let e = BaseMotion::new(MotionKind::Displacement, [Some(late), None, None]).unwrap_err();
    assert!(e.to_string().contains("starts at the block's position"), "{e}");
    let ramp = TimeHistory::new(vec![0.0, 1.0], vec![0.0, 0.01]).expect("history");
    let m = BaseMotion::new(MotionKind::Displacement, [Some(ramp), None, None]).expect("motion");
    assert_eq!(m.displacement(0.5).x, 0.005);
    assert_eq!(m.displacement(1.0).x, 0.01);
    assert_eq!(m.displacement(5.0).x, 0.01);
    assert_eq!(m.mean_velocity(1.0, 0.1).x, 0.0);
    // Velocity records are zero outside: the displacement reached is kept.
    let v = TimeHistory::new(vec![0.0, 1.0], vec![1.0, 1.0]).expect("history");
    let m = BaseMotion::new(MotionKind::Velocity, [Some(v), None, None]).expect("motion");
    assert_eq!(m.displacement(3.0).x, 1.0);
}

/// Base-motion CSV: decimal commas are refused (they read as other numbers); quoted numbers
/// and CR-only line ends are read; a text with no numeric row says how many lines were read and
/// skipped and shows the first; UTF-16 files are refused saying so.
#[test]
fn time_history_csv_says_what_it_read() {
    let e = TimeHistory::from_csv("t;a\n0;0\n1,5;0,3\n", 0, 1, 1.0).unwrap_err();
    assert!(e.to_string().contains("decimal commas"), "{e}");
    let quoted = TimeHistory::from_csv("\"t\",\"a\"\n\"0.0\",\"0.5\"\n\"1.0\",\"1.5\"\n", 0, 1, 1.0).expect("quoted");
    assert_eq!(quoted.values(), [0.5, 1.5]);
    let cr = TimeHistory::from_csv("t,a\r0,1\r1,2\r2,3\r", 0, 1, 1.0).expect("CR only");
    assert_eq!(cr.times(), [0.0, 1.0, 2.0]);
    let e = TimeHistory::from_csv("time,acc\nzero,one\n", 0, 1, 1.0)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("0 numeric rows") && e.contains("2 lines read") && e.contains("line 1: `time,acc`"),
        "{e}"
    );
    let e = TimeHistory::from_csv("\0t\0,\0a\0\n", 0, 1, 1.0)
        .unwrap_err()
        .to_string();
    assert!(e.contains("UTF-16"), "{e}");
    let dir = std::env::temp_dir().join(format!("voussoir-hostile-input-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let path = dir.join("utf16.csv");
    let mut bytes = vec![0xFF, 0xFE];
    for u in "t,a\n0,0\n1,1\n".encode_utf16() {
        bytes.extend_from_slice(&u.to_le_bytes());
    }
    std::fs::write(&path, bytes).expect("write");
    let e = TimeHistory::from_csv_file(&path, 0, 1, 1.0).unwrap_err().to_string();
    assert!(e.contains("UTF-16") && e.contains("utf16.csv"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Reading `/dev/zero` as a checkpoint or a scene is refused at once (a device, not a regular
/// file) instead of reading without end; a regular file holding a NUL byte stops there.
#[cfg(unix)]
#[test]
fn endless_files_are_refused_at_once() {
    let started = std::time::Instant::now();
    let e = Model::<CoulombSlip>::load_checkpoint(Path::new("/dev/zero")).unwrap_err();
    assert!(e.to_string().contains("a device: only a regular file is read"), "{e}");
    let e = Scene::<CoulombSlip>::load(Path::new("/dev/zero")).unwrap_err();
    assert!(e.to_string().contains("a device"), "{e}");
    assert!(started.elapsed().as_secs_f64() < 1.0);
    let dir = std::env::temp_dir().join(format!("voussoir-nul-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let nul = dir.join("nul.json");
    std::fs::write(&nul, b"{\"blocks\": \0}").unwrap();
    let e = Scene::<CoulombSlip>::load(&nul).unwrap_err();
    assert!(e.to_string().contains("a NUL byte at byte 11"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A named pipe, a folder or a socket given as a checkpoint, a scene or a base-motion CSV is
/// refused at once, naming what it is (a pipe blocked the load for ever, deaf to Ctrl-C).
#[cfg(unix)]
#[test]
fn named_pipes_folders_and_sockets_are_refused_on_load() {
    use voussoir::loading::TimeHistory;
    let dir = std::env::temp_dir().join(format!("voussoir-fifo-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let fifo = dir.join("pipe.json");
    let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    // SAFETY: a valid NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0, "mkfifo");
    let socket = dir.join("socket.json");
    let _listener = std::os::unix::net::UnixListener::bind(&socket).unwrap();
    let started = std::time::Instant::now();
    for (path, what) in [(&fifo, "a named pipe"), (&dir, "a folder"), (&socket, "a socket")] {
        let e = Model::<CoulombSlip>::load_checkpoint(path).unwrap_err();
        assert!(
            e.to_string().contains(what) && e.to_string().contains(&*path.to_string_lossy()),
            "{e}"
        );
        let e = Scene::<CoulombSlip>::load(path).unwrap_err();
        assert!(e.to_string().contains(what), "{e}");
        let e = TimeHistory::from_csv_file(path, 0, 1, 1.0).unwrap_err();
        assert!(e.to_string().contains(what), "{e}");
    }
    assert!(started.elapsed().as_secs_f64() < 1.0);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Generators asked for more blocks than memory holds are `Error::TooLarge` before they
/// allocate (they used to abort the process).
#[test]
fn huge_generators_are_refused() {
    use voussoir::build::arch::ArchSpec;
    use voussoir::build::{running_bond_wall, WallSpec, MAX_GENERATED_BLOCKS};
    let e = voussoir::scenes::benchmark_wall(1_000_000_000).unwrap_err();
    assert!(
        matches!(e, Error::TooLarge { limit, .. } if limit == MAX_GENERATED_BLOCKS),
        "{e:?}"
    );
    let spec = WallSpec {
        courses: 1_000_000,
        bricks_per_course: 1_000_000,
        ..WallSpec::default()
    };
    let e = running_bond_wall(&spec).unwrap_err();
    assert!(
        matches!(e, Error::TooLarge { requested, .. } if requested == 1_000_001_000_000),
        "{e:?}"
    );
    let spec = WallSpec {
        courses: usize::MAX,
        bricks_per_course: usize::MAX,
        ..WallSpec::default()
    };
    assert!(matches!(running_bond_wall(&spec), Err(Error::TooLarge { .. })));
    let spec = ArchSpec {
        voussoirs: 1_000_000_000,
        ..ArchSpec::reference(0.2)
    };
    let e = voussoir::build::arch::Arch::new(&spec).unwrap_err();
    assert!(matches!(e, Error::TooLarge { .. }), "{e:?}");
}

/// A joint stiffness near f64's limit (1.7e308 Pa/m, found by the fuzzer) overflows the
/// stability bound: the step is an error naming the critical step, not a NaN `dt` after a
/// step reported as successful.
#[test]
fn a_stiffness_that_overflows_the_step_is_an_error() {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz/corpus/scene/overflow-stiffness.json"),
    )
    .expect("seed");
    let mut model = Scene::<CoulombSlip>::from_json(&text)
        .expect("scene")
        .build()
        .expect("model");
    let e = model.step().unwrap_err();
    assert!(e.to_string().contains("critical time step"), "{e}");
}

/// Found by the fuzzers of issue 33: samples 1e-323 s apart (their slope overflows) are
/// refused; a velocity whose kinetic energy overflows is refused, so that the model still
/// saves a checkpoint that loads (its energy used to be written as null).
#[test]
fn overflowing_histories_and_velocities_are_refused() {
    let e = TimeHistory::new(vec![0.0, 1e-323], vec![0.0, -49.05]).unwrap_err();
    assert!(e.to_string().contains("overflow"), "{e}");
    let mut model: Model = Model::new(ModelParameters::default()).expect("model");
    let cube = model
        .add_block(RigidBlock::cuboid("c", Vector::ZERO, Vector::splat(0.2), 2500.0).expect("cube"))
        .expect("cube");
    let e = model
        .set_velocity(cube, Vector::new(1e308, 0.0, 0.0), Vector::ZERO)
        .unwrap_err();
    assert!(matches!(e, Error::NonFinite { .. }), "{e:?}");
    assert_eq!(model.block(cube).expect("cube").state().velocity, Vector::ZERO);
    let text = model.to_checkpoint_string().expect("saves");
    Model::<CoulombSlip>::from_checkpoint_str(&text).expect("loads");
}
