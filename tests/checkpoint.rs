//! Checkpoint and restart: a restarted run continues bit-identically; corrupt or truncated
//! checkpoints give errors, never panics.

mod common;

use voussoir::build::{running_bond_wall, WallSpec};
use voussoir::monitor::Recorder;
use voussoir::prelude::*;

use common::fingerprint;
use voussoir::model::reseal_checkpoint;

/// An edited checkpoint document as text, its checksum recomputed: what an edit on purpose
/// looks like, so that the checks behind the checksum are reached.
fn sealed(json: &serde_json::Value) -> Result<String> {
    reseal_checkpoint(&json.to_string())
}

/// A small wall under a lateral load, so that blocks slide, rock and get re-detected.
fn moving_wall() -> Result<Model> {
    let params = ModelParameters {
        gravity: Vector::new(6.0, 0.0, -9.81), // beyond tan 25° × g: the courses slide
        contact: ContactParameters {
            density: SubcontactDensity::PerEdge(4),
            ..ContactParameters::default()
        },
        ..ModelParameters::default()
    };
    let mut model = common::model_with(params, CoulombSlip::new(1e9, 4e8, 25.0, 20.0, 2e3, 1e3)?);
    model.set_damping(Damping::rayleigh_stiffness(0.02, 50.0)?)?;
    for b in running_bond_wall(&WallSpec {
        bricks_per_course: 4,
        courses: 5,
        ..WallSpec::default()
    })? {
        model.add_block(b)?;
    }
    Ok(model)
}

/// A recorder of the wall's kinetic energy and top displacement every tenth step.
fn wall_recorder(model: &Model) -> Result<Recorder<CoulombSlip>> {
    let mut recorder = Recorder::new(10);
    recorder.add_monitor(model, "kinetic", Monitor::Energy(EnergyTerm::Kinetic))?;
    recorder.add_monitor(
        model,
        "top x",
        Monitor::Displacement {
            block: BlockId(20),
            point: Vector::new(0.5, 0.05, 0.225),
            component: Component::X,
        },
    )?;
    Ok(recorder)
}

#[test]
fn restarted_run_is_bit_identical() -> Result<()> {
    let mut model = moving_wall()?;
    model.run_steps(2000)?;
    let dir = std::env::temp_dir().join(format!("voussoir-checkpoint-{}", std::process::id()));
    let path = dir.join("wall.json");
    model.save_checkpoint(&path)?;
    let mut restarted: Model = Model::load_checkpoint(&path)?;
    // The contacts' resultants and the blocks' contact wrenches read the same before a step.
    let resultants = |m: &Model| m.contacts().map(|c| c.wrench()).collect::<Vec<_>>();
    assert_eq!(resultants(&model), resultants(&restarted));
    assert!(resultants(&model).iter().any(|w| w.force != Vector::ZERO));
    for i in 0..model.blocks().len() {
        let id = BlockId(i as u32);
        assert_eq!(model.contact_wrench(id)?, restarted.contact_wrench(id)?);
    }
    let detections = model.detection_count();
    // Recorders are the caller's: both runs, observed alike, record the same histories.
    let (mut recorded, mut recorded_again) = (wall_recorder(&model)?, wall_recorder(&restarted)?);
    model.run_steps_observed(3000, &mut recorded)?;
    restarted.run_steps_observed(3000, &mut recorded_again)?;
    assert!(
        model.detection_count() > detections,
        "the test must cross re-detections"
    );
    assert!(
        model.contacts().flat_map(|c| c.subcontacts()).any(|s| s.slip() > 0.0),
        "the test must include slip"
    );
    assert_eq!(fingerprint(&model), fingerprint(&restarted));
    assert_eq!(recorded.history(), recorded_again.history());
    assert_eq!(recorded.history().len(), 300);
    std::fs::remove_dir_all(&dir).ok();
    Ok(())
}

#[test]
fn truncated_or_corrupt_checkpoints_are_errors() -> Result<()> {
    let mut model = moving_wall()?;
    model.run_steps(50)?;
    let text = model.to_checkpoint_string()?;
    // Truncated anywhere: an error naming where, never a panic.
    for cut in (0..text.len()).step_by(text.len() / 97 + 1) {
        let err = Model::<CoulombSlip>::from_checkpoint_str(&text[..cut]).expect_err("truncated");
        assert!(matches!(err, Error::Checkpoint { .. }), "{err}");
    }
    // Inconsistent indices that parse fine: a block or a law that does not exist.
    for (field, value) in [("blocks", serde_json::json!([0, 7777])), ("law", serde_json::json!(7))] {
        let mut json: serde_json::Value = serde_json::from_str(&text).expect("json");
        json["contacts"][0][field] = value;
        let err = Model::<CoulombSlip>::from_checkpoint_str(&sealed(&json)?).expect_err(field);
        assert!(err.to_string().contains("contacts[0]"), "{err}");
    }
    // A bad law parameter is caught by the law's own validation, with its path.
    let bad_law = text.replacen("\"friction_deg\":25.0", "\"friction_deg\":95.0", 1);
    assert_ne!(bad_law, text);
    let err = Model::<CoulombSlip>::from_checkpoint_str(&reseal_checkpoint(&bad_law)?).expect_err("bad friction");
    assert!(
        err.to_string().contains("joints.laws[0]") && err.to_string().contains("friction"),
        "{err}"
    );
    // Spring moments that do not belong to the stored forces (they feed the joint work).
    let mut json: serde_json::Value = serde_json::from_str(&text).expect("json");
    let force = &mut json["contacts"][0]["springs"][0][2];
    let fz = force.as_f64().expect("a number");
    assert!(fz.abs() > 1.0, "the first contact is loaded: {fz}");
    *force = serde_json::json!(fz * 1.5);
    let err = Model::<CoulombSlip>::from_checkpoint_str(&sealed(&json)?).expect_err("bad springs");
    assert!(err.to_string().contains("contacts[0].springs"), "{err}");
    // Joint axes or anchor plane axes that are not orthonormal.
    for (field, path) in [("tangent", "contacts[0].tangent"), ("anchors", "contacts[0].anchors")] {
        let mut json: serde_json::Value = serde_json::from_str(&text).expect("json");
        let axis = if field == "tangent" {
            &mut json["contacts"][0]["tangent"]
        } else {
            &mut json["contacts"][0]["anchors"]["v"]
        };
        let scaled: Vec<f64> = axis
            .as_array()
            .expect("a vector")
            .iter()
            .map(|c| 1.01 * c.as_f64().expect("a number"))
            .collect();
        *axis = serde_json::json!(scaled);
        let err = Model::<CoulombSlip>::from_checkpoint_str(&sealed(&json)?).expect_err(field);
        assert!(err.to_string().contains(path), "{err}");
    }
    // Another version is named as such, whatever else changed between the versions.
    let mut json: serde_json::Value = serde_json::from_str(&text).expect("json");
    json["version"] = serde_json::json!(6);
    json.as_object_mut().expect("an object").remove("contacts");
    let err = Model::<CoulombSlip>::from_checkpoint_str(&json.to_string()).expect_err("version 6");
    assert!(
        err.to_string().contains("version 6") && err.to_string().contains("reads version 10"),
        "{err}"
    );
    // Every contact has its wrench.
    let mut json: serde_json::Value = serde_json::from_str(&text).expect("json");
    json["contacts"][0].as_object_mut().expect("a contact").remove("wrench");
    let err = Model::<CoulombSlip>::from_checkpoint_str(&sealed(&json)?).expect_err("wrench");
    assert!(
        err.to_string().contains("contacts[0]") && err.to_string().contains("wrench"),
        "{err}"
    );
    json["format"] = serde_json::json!("something-else");
    let err = Model::<CoulombSlip>::from_checkpoint_str(&json.to_string()).expect_err("format");
    assert!(err.to_string().contains("something-else"), "{err}");
    // A missing file.
    let err = Model::<CoulombSlip>::load_checkpoint(std::path::Path::new("/nonexistent/x.json")).expect_err("missing");
    assert!(matches!(err, Error::Io { .. }), "{err}");
    Ok(())
}

/// A change that asks for a full re-detection (here a ten times stiffer joint law, which needs a
/// shorter step) is not lost when the model is saved before its next step.
#[test]
fn pending_redetection_survives_a_checkpoint() -> Result<()> {
    let mut model = moving_wall()?;
    model.run_steps(30)?;
    let dt_before = model.dt();
    model.set_joint_law(
        MaterialId(0),
        MaterialId(0),
        CoulombSlip::new(1e11, 4e10, 25.0, 20.0, 2e3, 1e3)?,
    )?;
    let mut restored: Model = Model::from_checkpoint_str(&model.to_checkpoint_string()?)?;
    model.step()?;
    restored.step()?;
    assert!(model.dt() < 0.5 * dt_before, "the stiffer law shortens the step");
    assert_eq!(restored.dt(), model.dt());
    model.run_steps(20)?;
    restored.run_steps(20)?;
    assert_eq!(fingerprint(&model), fingerprint(&restored));
    Ok(())
}

/// The checkpoint format is the transfer structs' fields, nothing of the step's storage: these
/// key sets change only with the format version.
#[test]
fn checkpoint_format_is_the_transfer_structs() -> Result<()> {
    let mut model = moving_wall()?;
    model.run_steps(20)?;
    let json: serde_json::Value = serde_json::from_str(&model.to_checkpoint_string()?).expect("json");
    let keys = |v: &serde_json::Value| -> Vec<String> {
        let mut k: Vec<String> = v.as_object().expect("an object").keys().cloned().collect();
        k.sort();
        k
    };
    assert_eq!(json["version"], 10);
    assert_eq!(json["law_type"], "CoulombSlip");
    assert!(json["checksum"].as_str().expect("a checksum").starts_with("crc32:"));
    assert_eq!(
        keys(&json),
        [
            "blocks",
            "checksum",
            "contacts",
            "critical",
            "damping",
            "detections",
            "drift",
            "dt",
            "energy",
            "format",
            "joints",
            "last_forces",
            "law_type",
            "params",
            "pending_detection",
            "ref_poses",
            "refine_omega2",
            "refine_until",
            "refining",
            "started",
            "step",
            "time",
            "unbalanced_ratio",
            "version",
        ]
    );
    let contact = &json["contacts"][0];
    assert_eq!(
        keys(contact),
        [
            "anchors",
            "area",
            "blocks",
            "bound_area",
            "dashpots",
            "host_is_a",
            "kind",
            "law",
            "normal",
            "normal_force",
            "reference_centroids",
            "reference_host_rotation",
            "springs",
            "subcontacts",
            "tangent",
            "wrench",
        ]
    );
    assert_eq!(
        keys(&contact["subcontacts"][0]),
        ["area", "dashpot", "force", "gap", "key", "plane", "slip", "state", "status"]
    );
    Ok(())
}

/// A checkpoint is never written in place: the text goes to a temporary file beside the
/// target, which then replaces it. Here the target is a link to `/dev/full` (a disk that is
/// always full): writing in place fails with "no space left" (and on a real full disk would
/// have truncated the previous checkpoint); writing beside and renaming replaces the link.
#[cfg(target_os = "linux")]
#[test]
fn checkpoints_are_written_beside_and_renamed_over_the_target() -> Result<()> {
    let dir = std::env::temp_dir().join(format!("voussoir_atomic_{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let path = dir.join("state.json");
    let _ = std::fs::remove_file(&path);
    std::os::unix::fs::symlink("/dev/full", &path).expect("symlink");
    let mut model = moving_wall()?;
    model.run_steps(10)?;
    model.save_checkpoint(&path)?;
    assert!(!std::fs::symlink_metadata(&path).expect("file").file_type().is_symlink());
    let restored: Model = Model::load_checkpoint(&path)?;
    assert_eq!(restored.step_count(), 10);
    // No temporary file is left behind.
    let names: Vec<String> = std::fs::read_dir(&dir)
        .expect("list")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["state.json"]);
    std::fs::remove_dir_all(&dir).ok();
    Ok(())
}
