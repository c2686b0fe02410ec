//! Checkpoint and restart: a restarted run continues bit-identically; corrupt or truncated
//! checkpoints give errors, never panics.

use crate::common;

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
            density: SubContactDensity::PerEdge(4),
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

/// Adds a regular tetrahedron (the one inscribed in a 0.2 m cube, 2,500 kg/m³), turned so that
/// it meets the slab of `common::fixed_slab` (top at z = 0) on a vertex, its lowest point `lift`
/// above it.
fn add_tilted_tetrahedron<L: ConstitutiveLaw>(model: &mut Model<L>, lift: Real) -> Result<BlockId> {
    let s = 0.1;
    let v = Vector::new;
    let tetrahedron = RigidBlock::from_vertices(
        "tetrahedron",
        &[v(s, s, s), v(s, -s, -s), v(-s, s, -s), v(-s, -s, s)],
        2500.0,
    )?
    .transformed(Pose::from_rotation(Rotation::from_scaled_axis(v(0.3, -0.5, 0.2))));
    let low = common::z_range(&tetrahedron).0;
    model.add_block(tetrahedron.transformed(Pose::from_translation(v(0.0, 0.0, lift - low))))
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
    // A loaded sub-contact whose area is tiny (subnormal): its springs' elastic energy is
    // infinite, and a model loaded with it would save a file that does not load (found by the
    // fuzzer: the energy was written as `null`).
    let mut json: serde_json::Value = serde_json::from_str(&text).expect("json");
    let sub = json["contacts"][0]["subcontacts"]
        .as_array()
        .expect("sub-contacts")
        .iter()
        .position(|s| s["force"]["normal"].as_f64().is_some_and(|f| f.abs() > 0.0))
        .expect("a loaded sub-contact");
    json["contacts"][0]["subcontacts"][sub]["area"] = serde_json::json!(1e-320);
    let err = Model::<CoulombSlip>::from_checkpoint_str(&sealed(&json)?).expect_err("infinite energy");
    assert!(
        err.to_string().contains(&format!("contacts[0].subcontacts[{sub}]"))
            && err.to_string().contains("elastic energy"),
        "{err}"
    );
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
    // A face-face cell's key that names other faces than its joint's (a cell keeps only its
    // grid indices, its joint the faces): either face, the other block's or the host's.
    for face_bit in [32, 48] {
        let mut json: serde_json::Value = serde_json::from_str(&text).expect("json");
        assert!(json["contacts"][0]["kind"].get("FaceFace").is_some(), "a joint first");
        let key = &mut json["contacts"][0]["subcontacts"][1]["key"];
        *key = serde_json::json!(key.as_u64().expect("a key") ^ (1u64 << face_bit));
        let err = Model::<CoulombSlip>::from_checkpoint_str(&sealed(&json)?).expect_err("a cell of other faces");
        assert!(
            matches!(err, Error::Checkpoint { .. }) && err.to_string().contains("contacts[0].subcontacts[1].key"),
            "{err}"
        );
    }
    // Another version is named as such, whatever else changed between the versions.
    let mut json: serde_json::Value = serde_json::from_str(&text).expect("json");
    json["version"] = serde_json::json!(6);
    json.as_object_mut().expect("an object").remove("contacts");
    let err = Model::<CoulombSlip>::from_checkpoint_str(&json.to_string()).expect_err("version 6");
    assert!(
        err.to_string().contains("version 6") && err.to_string().contains("reads versions 13 to 16"),
        "{err}"
    );
    // The tested pairs: in order, with finite unit poses and slacks, one for every contact.
    let tested = |edit: &dyn Fn(&mut serde_json::Value)| -> Result<String> {
        let mut json: serde_json::Value = serde_json::from_str(&text).expect("json");
        edit(&mut json);
        Ok(Model::<CoulombSlip>::from_checkpoint_str(&sealed(&json)?)
            .expect_err("a bad tested pair")
            .to_string())
    };
    let err = tested(&|j| j["tested"].as_array_mut().expect("a list").swap(0, 1))?;
    assert!(err.contains("tested[1].blocks"), "{err}");
    let err = tested(&|j| j["tested"][0]["blocks"] = serde_json::json!([3, 2]))?;
    assert!(err.contains("tested[0].blocks"), "{err}");
    let err = tested(&|j| j["tested"][2]["relative"]["rotation"] = serde_json::json!([0.0, 0.0, 0.0, 2.0]))?;
    assert!(err.contains("tested[2].relative"), "{err}");
    let err = tested(&|j| j["tested"][2]["slack"] = serde_json::json!(-1e-3))?;
    assert!(err.contains("tested[2].slack"), "{err}");
    let err = tested(&|j| {
        let first = j["contacts"][0]["blocks"].clone();
        j["tested"]
            .as_array_mut()
            .expect("a list")
            .retain(|t| t["blocks"] != first);
    })?;
    assert!(
        err.contains("contacts[0].blocks") && err.contains("did not test"),
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

/// A velocity set between steps reaches the next step's contacts: the step after
/// `set_velocity` is the one a restarted model takes from the same state (the contact pass
/// reads the blocks' motions from a list the block pass prepares; a setter must not leave it
/// stale).
#[test]
fn a_velocity_set_between_steps_reaches_the_contacts() -> Result<()> {
    let mut model = moving_wall()?;
    model.run_steps(30)?;
    let id = model
        .contacts()
        .find(|c| c.normal_force() > 0.0 && !model.blocks()[c.blocks().1.index()].fixity().is_fixed())
        .map(|c| c.blocks().1)
        .expect("a loaded contact of a free block");
    model.set_velocity(id, Vector::new(0.05, 0.0, -0.02), Vector::new(0.0, 0.3, 0.0))?;
    let mut restored: Model = Model::from_checkpoint_str(&model.to_checkpoint_string()?)?;
    model.step()?;
    restored.step()?;
    assert_eq!(fingerprint(&model), fingerprint(&restored));
    model.run_steps(5)?;
    restored.run_steps(5)?;
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
    assert_eq!(json["version"], 16);
    assert_eq!(json["law_type"], "CoulombSlip");
    assert!(json["checksum"].as_str().expect("a checksum").starts_with("crc32:"));
    assert_eq!(
        keys(&json),
        [
            "blocks",
            "bounds",
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
            "motions",
            "params",
            "pending_detection",
            "ref_poses",
            "refine_omega2",
            "refine_travel",
            "refine_until",
            "refining",
            "started",
            "step",
            "tested",
            "time",
            "unbalanced_ratio",
            "version",
        ]
    );
    assert_eq!(keys(&json["tested"][0]), ["blocks", "relative", "slack"]);
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
            "spread_energy",
            "springs",
            "subcontacts",
            "tangent",
            "wrench",
        ]
    );
    assert_eq!(
        keys(&contact["subcontacts"][0]),
        ["area", "dashpot", "force", "gap", "half", "key", "plane", "slip", "state", "status"]
    );
    // A joint stepped as a whole (a wall at rest) adds its record and its cells' held shear.
    let mut wall = voussoir::scenes::benchmark_wall(300)?;
    wall.run_steps(400)?;
    let json: serde_json::Value = serde_json::from_str(&wall.to_checkpoint_string()?).expect("json");
    let whole: Vec<&serde_json::Value> = json["contacts"]
        .as_array()
        .expect("contacts")
        .iter()
        .filter(|c| c.get("joint").is_some())
        .collect();
    assert_eq!(whole.len(), wall.whole_joint_count());
    assert_eq!(keys(&whole[0]["joint"]), ["held_shear", "level"]);
    assert_eq!(
        keys(&whole[0]["joint"]["level"]),
        [
            "active",
            "ends",
            "field",
            "gap",
            "held",
            "held_stress",
            "open",
            "span",
            "stiffness"
        ]
    );
    Ok(())
}

/// A joint stepped as a whole whose stored forces are not those its record gives (an edited
/// held shear, a record without its cells) is refused, naming the contact.
#[test]
fn an_edited_whole_joint_is_refused() -> Result<()> {
    let mut wall = voussoir::scenes::benchmark_wall(300)?;
    wall.run_steps(400)?;
    let text = wall.to_checkpoint_string()?;
    let json: serde_json::Value = serde_json::from_str(&text).expect("json");
    let k = json["contacts"]
        .as_array()
        .expect("contacts")
        .iter()
        .position(|c| c.get("joint").is_some())
        .expect("a joint stepped as a whole");
    let mut edited = json.clone();
    let held = &mut edited["contacts"][k]["joint"]["held_shear"][0][0];
    *held = serde_json::json!(held.as_f64().expect("a number") * 1.5 + 1.0);
    let err = Model::<CoulombSlip>::from_checkpoint_str(&sealed(&edited)?).expect_err("edited held shear");
    assert!(
        err.to_string().contains(&format!("contacts[{k}].subcontacts[0]")),
        "{err}"
    );
    let mut edited = json.clone();
    edited["contacts"][k]["joint"]["held_shear"]
        .as_array_mut()
        .expect("held shear")
        .pop();
    let err = Model::<CoulombSlip>::from_checkpoint_str(&sealed(&edited)?).expect_err("one short");
    assert!(err.to_string().contains(&format!("contacts[{k}].joint")), "{err}");
    // A node contact is not stepped as a whole: a record on one is refused.
    let mut edited = json.clone();
    edited["contacts"][k]["kind"] = serde_json::json!("Nodes");
    let err = Model::<CoulombSlip>::from_checkpoint_str(&sealed(&edited)?).expect_err("a node contact's record");
    assert!(err.to_string().contains(&format!("contacts[{k}].joint")), "{err}");
    // A span beyond the joint's cells (a joint open in part stepped as a whole but for them),
    // beyond what a span holds, over all of them, on a joint open all over, or without its
    // hinge record, is refused; so is a hinge record on a joint without a span, and open cells
    // stepped as a whole at an end the span reaches, or on a joint without a span.
    let hinge = serde_json::json!({
        "closed_box": [[0.0, 0.0], [0.1, 0.1]],
        "entry_gap": [-1e-6, 0.0, 0.0],
        "room": 1.0
    });
    let cells = json["contacts"][k]["subcontacts"].as_array().expect("cells").len();
    for (span, open, with_hinge, ends) in [
        ((0, 60_000), false, true, "closed"),
        ((1, 100_000), false, true, "closed"),
        ((0, cells), false, true, "closed"),
        ((0, 1), true, true, "closed"),
        ((0, 1), false, false, "closed"),
        ((0, 0), false, true, "closed"),
        ((0, 1), false, true, "open_before"),
        ((1, cells), false, true, "open_after"),
        ((0, 0), false, false, "open_after"),
    ] {
        let mut edited = json.clone();
        edited["contacts"][k]["joint"]["level"]["span"] = serde_json::json!([span.0, span.1]);
        edited["contacts"][k]["joint"]["level"]["open"] = serde_json::json!(open);
        edited["contacts"][k]["joint"]["level"]["ends"] = serde_json::json!(ends);
        if with_hinge {
            edited["contacts"][k]["joint"]["hinge"] = hinge.clone();
        }
        let err = Model::<CoulombSlip>::from_checkpoint_str(&sealed(&edited)?).expect_err("a span out of range");
        assert!(
            err.to_string().contains(&format!("contacts[{k}].joint")),
            "{span:?} {open} {with_hinge} {ends}: {err}"
        );
    }
    // A cell stepped as a whole that is not in its law's initial state is refused, naming it.
    let mut edited = json.clone();
    edited["contacts"][k]["subcontacts"][0]["state"] = serde_json::json!({ "failed": true });
    let err = Model::<CoulombSlip>::from_checkpoint_str(&sealed(&edited)?).expect_err("a failed cell held whole");
    assert!(
        err.to_string().contains(&format!("contacts[{k}].subcontacts[0]")) && err.to_string().contains("initial state"),
        "{err}"
    );
    // A cell said to be open and stepped as a whole that carries a force is refused, naming it.
    let mut edited = json.clone();
    edited["contacts"][k]["joint"]["level"]["span"] = serde_json::json!([1, 2]);
    edited["contacts"][k]["joint"]["level"]["ends"] = serde_json::json!("open_before");
    edited["contacts"][k]["joint"]["hinge"] = hinge.clone();
    let err = Model::<CoulombSlip>::from_checkpoint_str(&sealed(&edited)?).expect_err("an open cell with a force");
    assert!(
        err.to_string().contains(&format!("contacts[{k}].subcontacts[0]")) && err.to_string().contains("open"),
        "{err}"
    );
    // What a file's version did not have is refused, naming the joint and the version: open
    // cells stepped as a whole in a version 15 file, a span and a hinge record in a version 14
    // one (no build of those versions wrote them).
    for (version, what) in [(15, "`ends`"), (14, "a span or a hinge record")] {
        let mut older = edited.clone();
        older["version"] = serde_json::json!(version);
        if version == 14 {
            older["contacts"][k]["joint"]["level"]["ends"] = serde_json::json!("closed");
        }
        let err = Model::<CoulombSlip>::from_checkpoint_str(&sealed(&older)?).expect_err("newer than its version");
        assert!(
            err.to_string().contains(&format!("contacts[{k}].joint"))
                && err.to_string().contains(what)
                && err.to_string().contains(&format!("version {version} file")),
            "{version}: {err}"
        );
    }
    // Unedited, it loads; as version 13 wrote it (no joints stepped as a whole: the cells as
    // they stand), it loads too, its joints stepped cell by cell until they enter again.
    assert_eq!(
        Model::<CoulombSlip>::from_checkpoint_str(&text)?.whole_joint_count(),
        wall.whole_joint_count()
    );
    let mut old = json.clone();
    old["version"] = serde_json::json!(13);
    for c in old["contacts"].as_array_mut().expect("contacts") {
        c.as_object_mut().expect("an object").remove("joint");
    }
    let mut restored = Model::<CoulombSlip>::from_checkpoint_str(&sealed(&old)?)?;
    assert_eq!(restored.whole_joint_count(), 0);
    restored.run_steps(1)?;
    assert!(restored.whole_joint_count() > 0);
    Ok(())
}

/// A checkpoint is never written in place: the text goes to a temporary file beside the
/// target, which then replaces it. Here the target is a hard link of another file: writing in
/// place would change both names' content (and on a full disk would have truncated the
/// previous checkpoint); writing beside and renaming leaves the other name's content as it was.
/// (This test used a link to `/dev/full`, which the writer now follows to its target:
/// `tests/hostile_files.rs`.)
#[cfg(unix)]
#[test]
fn checkpoints_are_written_beside_and_renamed_over_the_target() -> Result<()> {
    let dir = std::env::temp_dir().join(format!("voussoir_atomic_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("dir");
    let path = dir.join("state.json");
    let other = dir.join("other-name.json");
    std::fs::write(&other, "previous").expect("file");
    std::fs::hard_link(&other, &path).expect("hard link");
    let mut model = moving_wall()?;
    model.run_steps(10)?;
    model.save_checkpoint(&path)?;
    assert_eq!(std::fs::read_to_string(&other).expect("other"), "previous");
    let restored: Model = Model::load_checkpoint(&path)?;
    assert_eq!(restored.step_count(), 10);
    // No temporary file is left behind.
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .expect("list")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["other-name.json", "state.json"]);
    std::fs::remove_dir_all(&dir).ok();
    Ok(())
}

/// Edits of a checkpoint's derived data, resealed (so that the checksum passes, as after an edit
/// on purpose), are refused with a typed error naming the block and the field: the stored value
/// is compared with what the geometry, the density and the velocities give. Before format 10
/// every one of them loaded and ran (an outside probe's list).
#[test]
fn edited_derived_data_is_refused() -> Result<()> {
    let mut model = moving_wall()?;
    model.run_steps(300)?;
    let text = model.to_checkpoint_string()?;
    let original: serde_json::Value = serde_json::from_str(&text).expect("json");
    // A free block that moves and turns: its angular velocity and momentum are not zero.
    let i = (0..model.blocks().len())
        .find(|&i| model.blocks()[i].is_free() && model.blocks()[i].state().angular_velocity.length() > 1e-6)
        .expect("a turning block");
    let scale = |v: &serde_json::Value, f: f64| -> serde_json::Value {
        match v {
            serde_json::Value::Array(items) => items
                .iter()
                .map(|x| serde_json::json!(x.as_f64().expect("n") * f))
                .collect(),
            x => serde_json::json!(x.as_f64().expect("a number") * f),
        }
    };
    type Edit = Box<dyn Fn(&mut serde_json::Value)>;
    let b = format!("blocks[{i}]");
    let cases: Vec<(&str, Edit, &str)> = vec![
        (
            "mass ×1000",
            Box::new(move |j| j["blocks"][i]["mass"]["mass"] = scale(&j["blocks"][i]["mass"]["mass"], 1000.0)),
            "mass.mass",
        ),
        (
            "negative mass",
            Box::new(move |j| j["blocks"][i]["mass"]["mass"] = scale(&j["blocks"][i]["mass"]["mass"], -1.0)),
            "mass.mass",
        ),
        (
            "negative inertia",
            Box::new(move |j| {
                j["blocks"][i]["mass"]["principal_inertia"][1] =
                    scale(&j["blocks"][i]["mass"]["principal_inertia"][1], -1.0)
            }),
            "mass.principal_inertia",
        ),
        (
            "negative unit inertia of the shape",
            Box::new(move |j| {
                j["blocks"][i]["shape"]["unit_inertia"] = scale(&j["blocks"][i]["shape"]["unit_inertia"], -1.0)
            }),
            "shape.unit_inertia",
        ),
        (
            "negative volume",
            Box::new(move |j| j["blocks"][i]["mass"]["volume"] = scale(&j["blocks"][i]["mass"]["volume"], -1.0)),
            "mass.volume",
        ),
        (
            "negative shape volume",
            Box::new(move |j| j["blocks"][i]["shape"]["volume"] = scale(&j["blocks"][i]["shape"]["volume"], -1.0)),
            "shape.volume",
        ),
        (
            "negative density",
            Box::new(move |j| j["blocks"][i]["density"] = scale(&j["blocks"][i]["density"], -1.0)),
            "density",
        ),
        (
            "density ×1000 (mass no longer that of the density)",
            Box::new(move |j| j["blocks"][i]["density"] = scale(&j["blocks"][i]["density"], 1000.0)),
            "mass.mass",
        ),
        (
            "angular momentum inconsistent with ω",
            Box::new(move |j| {
                j["blocks"][i]["state"]["angular_momentum"] = scale(&j["blocks"][i]["state"]["angular_momentum"], 3.0)
            }),
            "state.angular_velocity",
        ),
        (
            "ω inconsistent with the angular momentum",
            Box::new(move |j| {
                j["blocks"][i]["state"]["angular_velocity"] = scale(&j["blocks"][i]["state"]["angular_velocity"], -1.0)
            }),
            "state.angular_velocity",
        ),
        (
            "face normal zeroed",
            Box::new(move |j| j["blocks"][i]["shape"]["faces"][2]["normal"] = serde_json::json!([0.0, 0.0, 0.0])),
            "shape.faces[2].normal",
        ),
        (
            "face normal flipped",
            Box::new(move |j| {
                j["blocks"][i]["shape"]["faces"][0]["normal"] =
                    scale(&j["blocks"][i]["shape"]["faces"][0]["normal"], -1.0)
            }),
            "shape.faces[0].normal",
        ),
        (
            "face offset moved",
            Box::new(move |j| {
                j["blocks"][i]["shape"]["faces"][1]["offset"] =
                    scale(&j["blocks"][i]["shape"]["faces"][1]["offset"], 1.01)
            }),
            "shape.faces[1].offset",
        ),
        (
            "moved vertex",
            Box::new(move |j| {
                j["blocks"][i]["shape"]["vertices"][3] = scale(&j["blocks"][i]["shape"]["vertices"][3], 1.05)
            }),
            "shape.faces[",
        ),
        (
            "shape radius",
            Box::new(move |j| j["blocks"][i]["shape"]["radius"] = scale(&j["blocks"][i]["shape"]["radius"], 0.5)),
            "shape.radius",
        ),
        (
            // Construction refuses hulls beyond geometry::MAX_HULL_VERTICES (their detection
            // costs seconds); a file must not bring one in.
            "300 more vertices",
            Box::new(move |j| {
                let v = j["blocks"][i]["shape"]["vertices"][0].clone();
                if let Some(list) = j["blocks"][i]["shape"]["vertices"].as_array_mut() {
                    list.extend(std::iter::repeat_n(v, 300));
                }
            }),
            "shape.vertices",
        ),
    ];
    for (what, edit, field) in &cases {
        let mut json = original.clone();
        edit(&mut json);
        let err = Model::<CoulombSlip>::from_checkpoint_str(&sealed(&json)?).expect_err(what);
        let Error::CheckpointBlock { block, field: f, .. } = &err else {
            panic!("{what}: expected CheckpointBlock, got {err:?}")
        };
        assert_eq!(block.index(), i, "{what}: {err}");
        assert!(f.starts_with(field), "{what}: {err}");
        assert!(
            err.to_string().contains(&b[7..b.len() - 1]),
            "{what} names the block: {err}"
        );
    }
    // The original, resealed, still loads: the checks hold for what a run writes.
    Model::<CoulombSlip>::from_checkpoint_str(&sealed(&original)?)?;
    Ok(())
}

/// A negative, zero or doubled time step, a critical step that is not that of the blocks and
/// contacts, and counters near overflow are refused (a negative `dt` used to run backwards,
/// `step: u64::MAX` to wrap at the next step).
#[test]
fn edited_time_step_and_counters_are_refused() -> Result<()> {
    let mut model = moving_wall()?;
    model.run_steps(300)?;
    let original: serde_json::Value = serde_json::from_str(&model.to_checkpoint_string()?).expect("json");
    let dt = original["dt"].as_f64().expect("dt");
    let critical = original["critical"]["dt"].as_f64().expect("critical dt");
    let cases: Vec<(&str, &str, serde_json::Value)> = vec![
        ("dt", "dt", serde_json::json!(-1e-4)),
        ("dt", "dt", serde_json::json!(0.0)),
        ("dt", "dt", serde_json::json!(2.0 * dt)),
        ("step", "step", serde_json::json!(u64::MAX)),
        ("detections", "detections", serde_json::json!(u64::MAX)),
        ("time", "time", serde_json::json!(-1.0)),
        ("drift", "drift", serde_json::json!(-1e-4)),
    ];
    for (field, path, value) in cases {
        let mut json = original.clone();
        json[field] = value.clone();
        let err = Model::<CoulombSlip>::from_checkpoint_str(&sealed(&json)?).expect_err(field);
        let Error::Checkpoint { path: p, .. } = &err else {
            panic!("{field} = {value}: expected Checkpoint, got {err:?}")
        };
        assert_eq!(p, path, "{field} = {value}: {err}");
    }
    // dt and the critical step edited together (dt still safety × critical): the critical step
    // the stored bounds give gives it away.
    let mut json = original.clone();
    json["critical"]["dt"] = serde_json::json!(10.0 * critical);
    json["dt"] = serde_json::json!(10.0 * dt);
    let err = Model::<CoulombSlip>::from_checkpoint_str(&sealed(&json)?).expect_err("critical");
    assert!(
        matches!(&err, Error::Checkpoint { path, .. } if path == "critical.dt"),
        "{err}"
    );
    // The bounds, the critical step and dt edited together: the bounds the blocks and contacts
    // give now give it away.
    let mut json = original.clone();
    let bounds: Vec<f64> = json["bounds"]
        .as_array()
        .expect("bounds")
        .iter()
        .map(|w| w.as_f64().expect("a number") / 100.0)
        .collect();
    json["bounds"] = serde_json::json!(bounds);
    json["critical"]["dt"] = serde_json::json!(10.0 * critical);
    json["dt"] = serde_json::json!(10.0 * dt);
    let err = Model::<CoulombSlip>::from_checkpoint_str(&sealed(&json)?).expect_err("bounds");
    assert!(
        matches!(&err, Error::Checkpoint { path, .. } if path.starts_with("bounds[")),
        "{err}"
    );
    // A step count far beyond any run but short of 2^53 loads and steps.
    let mut json = original.clone();
    json["step"] = serde_json::json!(1u64 << 52);
    let mut restored: Model = Model::from_checkpoint_str(&sealed(&json)?)?;
    restored.run_steps(3)?;
    assert_eq!(restored.step_count(), (1u64 << 52) + 3);
    Ok(())
}

/// A slab of material 1 under two stacked cubes of material 0, with a law for each pair of
/// materials (laws 0 and 1).
fn two_cubes_on_a_slab_of_another_material() -> Result<Model> {
    let mut model: Model = Model::new(ModelParameters::default())?;
    model.set_joint_law(MaterialId(0), MaterialId(0), CoulombSlip::dry(1e9, 4e8, 30.0)?)?;
    model.set_joint_law(MaterialId(0), MaterialId(1), CoulombSlip::dry(2e9, 8e8, 35.0)?)?;
    model.add_block(common::fixed_slab("base").with_material(MaterialId(1)))?;
    model.add_block(common::cube("low", Vector::ZERO))?;
    model.add_block(common::cube("high", Vector::new(0.0, 0.0, common::CUBE_EDGE)))?;
    Ok(model)
}

/// Two materials with two laws: a contact whose law index is the other pair's law is refused,
/// naming the contact and its blocks.
#[test]
fn contact_law_index_must_be_its_materials_law() -> Result<()> {
    let mut model = two_cubes_on_a_slab_of_another_material()?;
    model.run_steps(50)?;
    let text = model.to_checkpoint_string()?;
    let json: serde_json::Value = serde_json::from_str(&text).expect("json");
    let contacts = json["contacts"].as_array().expect("contacts");
    assert_eq!(contacts.len(), 2);
    for (k, contact) in contacts.iter().enumerate() {
        let law = contact["law"].as_u64().expect("a law index");
        let mut edited = json.clone();
        edited["contacts"][k]["law"] = serde_json::json!(1 - law);
        let err = Model::<CoulombSlip>::from_checkpoint_str(&sealed(&edited)?).expect_err("another law");
        let Error::CheckpointContactLaw {
            contact: c,
            a,
            b,
            law: l,
            ..
        } = &err
        else {
            panic!("expected CheckpointContactLaw, got {err:?}")
        };
        assert_eq!((*c, *l), (k, 1 - law as u32), "{err}");
        let blocks = contact["blocks"].as_array().expect("blocks");
        assert_eq!(
            (a.0 as u64, b.0 as u64),
            (blocks[0].as_u64().expect("a"), blocks[1].as_u64().expect("b"))
        );
        assert!(err.to_string().contains(&format!("contact {k}")), "{err}");
    }
    Model::<CoulombSlip>::from_checkpoint_str(&text)?;
    Ok(())
}

/// Any change to a checkpoint's content, corruption or edit, is refused as such unless the
/// checksum is recomputed; formatting is not content. Random single-byte mutations are either
/// refused (never a panic) or load the very model that was saved.
#[test]
fn corrupted_checkpoints_are_refused() -> Result<()> {
    let mut model = moving_wall()?;
    model.run_steps(200)?;
    let text = model.to_checkpoint_string()?;
    // An edit of one value, not resealed.
    let edited = text.replacen("\"step\":200", "\"step\":201", 1);
    assert_ne!(edited, text);
    let err = Model::<CoulombSlip>::from_checkpoint_str(&edited).expect_err("edited");
    assert!(matches!(err, Error::CheckpointChecksum { .. }), "{err}");
    assert!(err.to_string().contains("corrupted or edited"), "{err}");
    // No checksum, or a mangled one.
    let mut json: serde_json::Value = serde_json::from_str(&text).expect("json");
    json.as_object_mut().expect("an object").remove("checksum");
    let err = Model::<CoulombSlip>::from_checkpoint_str(&json.to_string()).expect_err("no checksum");
    assert!(
        matches!(&err, Error::Checkpoint { path, .. } if path == "checksum"),
        "{err}"
    );
    // Re-indented with its keys in another order: the same content, the same model.
    let pretty = serde_json::to_string_pretty(&json).expect("json");
    let mut json: serde_json::Value = serde_json::from_str(&text).expect("json");
    let checksum = json
        .as_object_mut()
        .expect("an object")
        .remove("checksum")
        .expect("checksum");
    let pretty = format!("{{\"checksum\": {checksum},\n{}", &pretty[1..]);
    let restored: Model = Model::from_checkpoint_str(&pretty)?;
    assert_eq!(restored.to_checkpoint_string()?, text);
    // Random single-byte mutations (a fixed pseudo-random sequence, printable bytes only so that
    // the text stays UTF-8): every one refused or harmless.
    let bytes = text.as_bytes();
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let (mut refused, mut same) = (0, 0);
    for _ in 0..3000 {
        let at = (next() % bytes.len() as u64) as usize;
        let byte = b' ' + (next() % 95) as u8;
        if bytes[at] == byte {
            continue;
        }
        let mut mutated = bytes.to_vec();
        mutated[at] = byte;
        let mutated = String::from_utf8(mutated).expect("ascii");
        match Model::<CoulombSlip>::from_checkpoint_str(&mutated) {
            Err(_) => refused += 1,
            Ok(m) => {
                assert_eq!(
                    m.to_checkpoint_string()?,
                    text,
                    "byte {at} set to {:?} loaded another model",
                    byte as char
                );
                same += 1;
            }
        }
    }
    assert!(refused > 2900, "{refused} refused, {same} harmless");
    Ok(())
}

/// A checkpoint written by a model of one law type names both law types when loaded as another
/// (it used to fail on the first field the laws do not share: "missing field `friction_deg`").
#[test]
fn checkpoint_of_another_law_type_is_named() -> Result<()> {
    let elastic = LinearElastic {
        normal_stiffness: 1e9,
        shear_stiffness: 4e8,
    };
    let mut model = common::model(elastic);
    model.add_block(common::fixed_slab("base"))?;
    model.add_block(common::cube("cube", Vector::ZERO))?;
    model.run_steps(20)?;
    let text = model.to_checkpoint_string()?;
    let err = Model::<CoulombSlip>::from_checkpoint_str(&text).expect_err("another law type");
    assert_eq!(
        err,
        Error::CheckpointLawType {
            written: "LinearElastic".into(),
            loading: "CoulombSlip".into()
        }
    );
    assert!(
        err.to_string().contains("LinearElastic") && err.to_string().contains("CoulombSlip"),
        "{err}"
    );
    let err = Model::<AnyLaw>::from_checkpoint_str(&text).expect_err("AnyLaw");
    assert!(
        matches!(&err, Error::CheckpointLawType { loading, .. } if loading == "AnyLaw"),
        "{err}"
    );
    // The same law type loads.
    Model::<LinearElastic>::from_checkpoint_str(&text)?;
    // And a Coulomb checkpoint as linear elastic.
    let mut wall = moving_wall()?;
    wall.run_steps(5)?;
    let err = Model::<LinearElastic>::from_checkpoint_str(&wall.to_checkpoint_string()?).expect_err("elastic");
    assert!(
        matches!(&err, Error::CheckpointLawType { written, .. } if written == "CoulombSlip"),
        "{err}"
    );
    Ok(())
}

/// A recorded history whose columns do not fit together (a monitor removed, a column
/// shortened, a byte of `steps` mutated) is refused as it is read, naming what does not fit;
/// it used to load and make `history_to_csv` panic.
#[test]
fn inconsistent_histories_are_refused() -> Result<()> {
    let mut model = moving_wall()?;
    let mut recorder = wall_recorder(&model)?;
    model.run_steps_observed(100, &mut recorder)?;
    let text = serde_json::to_string(recorder.history()).expect("json");
    let back: voussoir::monitor::History = serde_json::from_str(&text).expect("a consistent history");
    assert_eq!(&back, recorder.history());
    let original: serde_json::Value = serde_json::from_str(&text).expect("json");
    type Edit = Box<dyn Fn(&mut serde_json::Value)>;
    let cases: Vec<(&str, Edit)> = vec![
        (
            "a monitor's name removed",
            Box::new(|j| {
                j["names"].as_array_mut().expect("names").pop();
            }),
        ),
        (
            "a monitor's column removed",
            Box::new(|j| {
                j["columns"].as_array_mut().expect("columns").remove(0);
            }),
        ),
        (
            "a unit removed",
            Box::new(|j| {
                j["units"].as_array_mut().expect("units").pop();
            }),
        ),
        (
            "a column shortened",
            Box::new(|j| {
                j["columns"][1].as_array_mut().expect("column").pop();
            }),
        ),
        (
            "a sample added to a column",
            Box::new(|j| {
                j["columns"][0]
                    .as_array_mut()
                    .expect("column")
                    .push(serde_json::json!(1.0));
            }),
        ),
        (
            "a step removed",
            Box::new(|j| {
                j["steps"].as_array_mut().expect("steps").pop();
            }),
        ),
        (
            "a time removed",
            Box::new(|j| {
                j["times"].as_array_mut().expect("times").pop();
            }),
        ),
    ];
    for (what, edit) in &cases {
        let mut json = original.clone();
        edit(&mut json);
        let err = serde_json::from_str::<voussoir::monitor::History>(&json.to_string()).expect_err(what);
        assert!(err.to_string().contains("inconsistent history"), "{what}: {err}");
    }
    // A byte of `steps` mutated: the separator in "20,30" made a digit, "20530".
    let steps_at = text.find("\"steps\":[").expect("steps");
    let comma = steps_at + text[steps_at..].find("20,30").expect("steps 20 and 30") + 2;
    let mutated = format!("{}5{}", &text[..comma], &text[comma + 1..]);
    let err = serde_json::from_str::<voussoir::monitor::History>(&mutated).expect_err("mutated steps");
    assert!(err.to_string().contains("10 times for 9 steps"), "{err}");
    Ok(())
}

/// A running-bond wall's bricks are copies of two bricks (whole and half) sharing their shapes,
/// placed where the spec puts them (corners to round-off), and they share them again once read
/// back from a checkpoint: a wall's memory per block does not grow on restart.
#[test]
fn a_walls_bricks_share_their_shapes_also_after_a_checkpoint() -> Result<()> {
    let spec = WallSpec {
        bricks_per_course: 4,
        courses: 5,
        ..WallSpec::default()
    };
    let bricks = running_bond_wall(&spec)?;
    let distinct = |blocks: &[RigidBlock]| {
        let mut shapes: Vec<*const voussoir::geometry::Polyhedron> = Vec::new();
        for b in blocks {
            let p = std::ptr::from_ref(b.shape());
            if !shapes.contains(&p) {
                shapes.push(p);
            }
        }
        shapes.len()
    };
    // The base, a whole brick, a half brick.
    assert_eq!(distinct(&bricks), 3);
    // Course 1 starts with a half brick: x from 0 to l/2.
    let (l, w, h) = (spec.brick.x, spec.brick.y, spec.brick.z);
    let half = &bricks[1 + spec.bricks_per_course];
    let pose = half.state().pose;
    let corners: Vec<Vector> = half
        .shape()
        .vertices()
        .iter()
        .map(|v| pose.transform_point(*v))
        .collect();
    let lo = corners.iter().fold(Vector::splat(Real::INFINITY), |m, c| m.min(*c));
    let hi = corners.iter().fold(Vector::splat(Real::NEG_INFINITY), |m, c| m.max(*c));
    assert!((lo - Vector::new(0.0, 0.0, h)).length() < 1e-12, "{lo}");
    assert!((hi - Vector::new(0.5 * l, w, 2.0 * h)).length() < 1e-12, "{hi}");

    let mut model = moving_wall()?;
    model.run_steps(5)?;
    assert_eq!(distinct(model.blocks()), 3);
    let dir = std::env::temp_dir().join(format!("voussoir-shared-shapes-{}", std::process::id()));
    let path = dir.join("wall.json");
    model.save_checkpoint(&path)?;
    let restored: Model = Model::load_checkpoint(&path)?;
    assert_eq!(distinct(restored.blocks()), 3);
    assert_eq!(fingerprint(&restored), fingerprint(&model));
    std::fs::remove_dir_all(&dir).ok();
    Ok(())
}

/// Every way a law reaches a contact survives a checkpoint and the run goes on bit for bit: a
/// pair of materials, an interface's own law set before the first step, one set while the
/// contact exists, an interface law replaced, and a law set after the last step (the contact
/// still holds its old law until the next step's detection, which the checkpoint owes).
#[test]
fn every_way_a_law_reaches_a_contact_reloads_bit_identically() -> Result<()> {
    let build = two_cubes_on_a_slab_of_another_material;
    let weak = || CoulombSlip::dry(5e8, 2e8, 20.0);
    type Setup = fn(&mut Model, &dyn Fn() -> Result<CoulombSlip>) -> Result<()>;
    let cases: [(&str, Setup); 5] = [
        ("materials only", |m, _| m.run_steps(60)),
        ("interface before the first step", |m, weak| {
            m.set_interface_law(BlockId(1), BlockId(2), weak()?)?;
            m.run_steps(60)
        }),
        ("interface set while in contact", |m, weak| {
            m.run_steps(30)?;
            m.set_interface_law(BlockId(0), BlockId(1), weak()?)?;
            m.run_steps(30)
        }),
        ("interface replaced", |m, weak| {
            m.set_interface_law(BlockId(2), BlockId(1), weak()?)?;
            m.run_steps(30)?;
            m.set_interface_law(BlockId(1), BlockId(2), CoulombSlip::dry(7e8, 3e8, 25.0)?)?;
            m.run_steps(30)
        }),
        ("laws set after the last step", |m, weak| {
            m.run_steps(60)?;
            m.set_interface_law(BlockId(1), BlockId(2), weak()?)?;
            m.set_joint_law(MaterialId(0), MaterialId(1), CoulombSlip::dry(3e9, 1.2e9, 40.0)?)
        }),
    ];
    for (name, setup) in cases {
        let mut model = build()?;
        setup(&mut model, &weak)?;
        assert_eq!(model.contacts().len(), 2, "{name}");
        let text = model.to_checkpoint_string()?;
        let mut restarted = Model::<CoulombSlip>::from_checkpoint_str(&text)
            .unwrap_or_else(|e| panic!("{name}: the checkpoint does not load: {e}"));
        assert_eq!(fingerprint(&model), fingerprint(&restarted), "{name}: as loaded");
        // Saved again, the same document; but for the stability bounds of a checkpoint that owes a
        // detection, which the next step re-evaluates and the loader does not restore.
        let document = |text: &str| {
            let mut json: serde_json::Value = serde_json::from_str(text).expect("json");
            if json["pending_detection"] == serde_json::json!(true) {
                json["bounds"] = serde_json::Value::Null;
                json["checksum"] = serde_json::Value::Null;
            }
            json
        };
        assert!(
            document(&restarted.to_checkpoint_string()?) == document(&text),
            "{name}: saved again, another document"
        );
        model.run_steps(200)?;
        restarted.run_steps(200)?;
        assert_eq!(fingerprint(&model), fingerprint(&restarted), "{name}: 200 steps on");
        // The contacts hold the laws detection gives them.
        for c in model.contacts() {
            let (a, b) = c.blocks();
            let (ma, mb) = (model.block(a)?.material(), model.block(b)?.material());
            let expected = model.law_table().index_for((a, ma), (b, mb));
            assert_eq!(Some(c.law_index() as u32), expected, "{name}: contact {a}–{b}");
        }
    }
    Ok(())
}

/// **A run with integrated node contacts restarts bit for bit** ([`NodeRule::Integrated`]): the
/// pieces each node stands for are not written (they depend on the shapes alone and are built
/// again at the first step after reading), and the plane a pressed node's shear is kept in is
/// the sub-contact's own. A tetrahedron tumbling on a slab with friction, checkpointed while a
/// node contact is pressed, then 2,000 steps on both.
#[test]
fn a_run_with_integrated_nodes_restarts_bit_for_bit() -> Result<()> {
    let mut params = ModelParameters::default();
    params.contact.node_rule = NodeRule::Integrated;
    let mut model = common::model_with(params, CoulombSlip::dry(1e9, 1e9, 30.0)?);
    model.add_block(common::fixed_slab("slab"))?;
    add_tilted_tetrahedron(&mut model, 0.03)?;
    // Until a node contact carries load.
    let pressed = |m: &Model| {
        m.contacts().any(|c| {
            matches!(c.kind(), voussoir::geometry::ContactKind::Nodes)
                && c.subcontacts().any(|x| x.normal_force() > 0.0)
        })
    };
    while !pressed(&model) || model.time() < 0.15 {
        model.step()?;
        assert!(model.time() < 1.0, "no pressed node contact");
    }
    let mut restarted: Model = Model::from_checkpoint_str(&model.to_checkpoint_string()?)?;
    model.run_steps(2000)?;
    restarted.run_steps(2000)?;
    assert!(
        model.energies().friction > 0.0,
        "the test must include slip at the nodes"
    );
    assert_eq!(fingerprint(&model), fingerprint(&restarted));
    Ok(())
}

/// **A block tossed off its last contact checkpoints and restarts bit for bit.** A tetrahedron
/// resting on a vertex (a node contact, point rule) is thrown up off the slab: the step keeps
/// the stability bound of its last contact (2.7e5 1/s² in the run that found this), while the
/// whole evaluation the checkpoint reader checks against gives a block in flight the bound of
/// a contact over its largest face (1.3e8 1/s²). The reader refused such a checkpoint as edited;
/// it checks blocks in contact only. Saved in flight, reloaded, and both runs on through the
/// landing, the same bits.
#[test]
fn a_block_tossed_off_its_last_contact_restarts_bit_for_bit() -> Result<()> {
    let mut model = common::model_with(ModelParameters::default(), CoulombSlip::dry(1e9, 1e9, 30.0)?);
    model.set_damping(Damping::local())?;
    model.add_block(common::fixed_slab("slab"))?;
    let id = add_tilted_tetrahedron(&mut model, 0.002)?;
    let pressed = |m: &Model| m.contacts().any(|c| c.subcontacts().any(|x| x.normal_force() > 0.0));
    while !pressed(&model) {
        model.step()?;
        assert!(model.time() < 0.5, "no pressed contact");
    }
    model.set_velocity(id, Vector::new(0.0, 0.0, 1.5), Vector::ZERO)?;
    while model.contacts().len() > 0 {
        model.step()?;
        assert!(model.time() < 1.0, "still in contact");
    }
    let mut restarted: Model = Model::from_checkpoint_str(&model.to_checkpoint_string()?)?;
    // Up 0.11 m and down again (about 0.3 s), then on for 2,000 steps from the landing.
    for m in [&mut model, &mut restarted] {
        while m.contacts().len() == 0 {
            m.step()?;
            assert!(m.time() < 2.0, "the tetrahedron must land");
        }
        m.run_steps(2000)?;
    }
    assert_eq!(fingerprint(&model), fingerprint(&restarted));
    Ok(())
}

/// **Every checkpoint of a tumbling scene loads, and restarts bit for bit.** A tetrahedron
/// dropped on a vertex onto a slab, bouncing, rocking and settling, beside a cube that lands
/// on the slab: contacts appear, vanish, change kind between nodes and faces, and blocks lose
/// their last contact and land again. With point nodes and local damping, with integrated nodes
/// and Rayleigh damping, and in small displacements (the tetrahedron set down within the
/// contact tolerance, contacts being found once), a checkpoint every 25 steps over 3,000
/// must load (the bug above was a refused one at step 2,871 of the first), and every 500 steps
/// the reloaded model and the original step on 100 steps to the same bits.
#[test]
fn every_checkpoint_of_a_tumbling_scene_loads() -> Result<()> {
    let v = Vector::new;
    let scene = |params: ModelParameters, damping: Damping, lift: Real| -> Result<Model> {
        let mut model = common::model_with(params, CoulombSlip::dry(1e9, 1e9, 30.0)?);
        model.set_damping(damping)?;
        model.add_block(common::fixed_slab("slab"))?;
        add_tilted_tetrahedron(&mut model, lift)?;
        let gap = lift.min(1e-3);
        model.add_block(RigidBlock::cuboid(
            "cube",
            v(0.4, 0.4, gap),
            v(0.6, 0.6, gap + 0.2),
            2500.0,
        )?)?;
        Ok(model)
    };
    let integrated = ModelParameters {
        contact: ContactParameters {
            node_rule: NodeRule::Integrated,
            ..ContactParameters::default()
        },
        ..ModelParameters::default()
    };
    let small = ModelParameters {
        mode: DisplacementMode::Small,
        ..ModelParameters::default()
    };
    let rayleigh = Damping::Rayleigh {
        mass: 0.5,
        stiffness: 1e-5,
    };
    for (name, mut model) in [
        (
            "point nodes, local damping",
            scene(ModelParameters::default(), Damping::local(), 0.03)?,
        ),
        ("integrated nodes, Rayleigh", scene(integrated, rayleigh, 0.03)?),
        // Contacts found once: the tetrahedron starts within the contact tolerance.
        ("small displacements, Rayleigh", scene(small, rayleigh, 2e-4)?),
    ] {
        let mut kinds = std::collections::BTreeSet::new();
        for k in 1..=120 {
            model.run_steps(25)?;
            kinds.extend(
                model
                    .contacts()
                    .map(|c| format!("{:?}", c.kind()).chars().take(4).collect::<String>()),
            );
            let text = model.to_checkpoint_string()?;
            let mut again: Model = Model::from_checkpoint_str(&text).map_err(|e| Error::Unsupported {
                what: format!("{name}, step {}: {e}", model.step_count()),
            })?;
            if k % 20 == 0 {
                model.run_steps(100)?;
                again.run_steps(100)?;
                assert_eq!(
                    fingerprint(&model),
                    fingerprint(&again),
                    "{name}, step {}",
                    model.step_count()
                );
            }
        }
        assert!(kinds.len() == 2, "{name}: node and face contacts both met, {kinds:?}");
    }
    Ok(())
}

/// **A node contact turning back into a joint restarts bit for bit** ([`NodeRule::Integrated`],
/// `docs/theory.md` §6): a 0.2 m cube set rocking on the edge it shares with a fixed cube of its
/// size tips past 15° (its loaded joint turns into a node contact), is checkpointed there, and
/// falls back flat, where its loaded node contact turns back into a face joint and hands its
/// forces to the cells; both runs to 0.6 s, with friction.
#[test]
fn a_node_contact_turning_back_into_a_joint_restarts_bit_for_bit() -> Result<()> {
    let mut params = ModelParameters::default();
    params.contact.node_rule = NodeRule::Integrated;
    let mut model = common::model_with(params, CoulombSlip::dry(1e9, 1e9, 30.0)?);
    model.set_damping(Damping::None)?;
    let (h, w) = (0.1, 5.0);
    let v = Vector::new;
    model.add_block(
        RigidBlock::cuboid("below", v(-h, -h, -2.0 * h), v(h, h, 0.0), 2600.0)?.with_fixity(Fixity::FIXED),
    )?;
    model.add_block(
        RigidBlock::cuboid("cube", v(-h, -h, 0.0), v(h, h, 2.0 * h), 2600.0)?
            .with_velocity(v(0.0, w * h, w * h), v(-w, 0.0, 0.0)),
    )?;
    let loaded_nodes = |m: &Model| {
        m.contacts()
            .any(|c| matches!(c.kind(), voussoir::geometry::ContactKind::Nodes) && c.normal_force() > 0.0)
    };
    while !loaded_nodes(&model) {
        model.step()?;
        assert!(model.time() < 0.3, "the joint turns into a node contact under load");
    }
    let mut restarted: Model = Model::from_checkpoint_str(&model.to_checkpoint_string()?)?;
    let (mut was_loaded_nodes, mut turned_back) = (true, false);
    while model.time() < 0.6 {
        model.step()?;
        restarted.step()?;
        let face = model
            .contacts()
            .any(|c| matches!(c.kind(), voussoir::geometry::ContactKind::FaceFace { .. }));
        turned_back |= was_loaded_nodes && face;
        was_loaded_nodes = loaded_nodes(&model);
    }
    assert!(turned_back, "the loaded node contact turns back into a joint");
    assert!(model.energies().friction > 0.0, "the test must include slip");
    assert_eq!(fingerprint(&model), fingerprint(&restarted));
    Ok(())
}
