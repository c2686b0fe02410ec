//! Scene files: the documented example loads and runs; a model round-trips through a scene;
//! bad fields are reported with their path.

use std::path::Path;

use voussoir::io::scene::Scene;
use voussoir::prelude::*;

fn example() -> Result<Scene<CoulombSlip>> {
    Scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/examples/block-on-base.json"))
}

#[test]
fn documented_example_builds_and_reaches_equilibrium() -> Result<()> {
    let scene = example()?;
    let mut model = scene.build()?;
    let mut recorder = scene.recorder(&model)?;
    assert_eq!(model.blocks().len(), 2);
    model.run_steps_observed(100, &mut recorder)?;
    model.run_to_equilibrium(1e-6, 50_000)?;
    // The 50 N push is below μW = tan 30.5° × 2446.5 × 0.008 × 9.81 = 113 N: the stone sticks,
    // and the support carries its weight.
    let weight = 2446.5 * 0.008 * 9.81;
    // (The base's own reaction also carries the base's weight: use the joint force instead.)
    let support = -model.contact_wrench(BlockId(0))?.force.z;
    assert!(
        (support - weight).abs() < 1e-4 * weight,
        "support {support} vs weight {weight}"
    );
    assert_eq!(recorder.history().names(), ["stone x", "support z"]);
    assert_eq!(recorder.history().len(), 100 / recorder.interval() as usize);
    Ok(())
}

#[test]
fn model_round_trips_through_a_scene() -> Result<()> {
    let scene = example()?;
    let model = scene.build()?;
    let recorder = scene.recorder(&model)?;
    let text = Scene::from_model(&model).with_recorder(&recorder).to_json()?;
    let scene_again = Scene::<CoulombSlip>::from_json(&text)?;
    let again = scene_again.build()?;
    let recorder_again = scene_again.recorder(&again)?;
    for (a, b) in model.blocks().iter().zip(again.blocks()) {
        assert_eq!(a.name(), b.name());
        assert!((a.mass_properties().mass - b.mass_properties().mass).abs() < 1e-12 * a.mass_properties().mass);
        assert!((a.state().pose.translation - b.state().pose.translation).length() < 1e-12);
        assert_eq!(a.fixity(), b.fixity());
        assert_eq!(a.load(), b.load());
    }
    assert_eq!(model.law_table().laws(), again.law_table().laws());
    assert!(recorder.monitors().eq(recorder_again.monitors()));
    assert_eq!(recorder.interval(), recorder_again.interval());
    Ok(())
}

#[test]
fn bad_fields_are_reported_with_their_path() -> Result<()> {
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/examples/block-on-base.json"))
        .expect("example file");
    let cases = [
        // (replace, with, expected fragment of the message)
        (
            "\"density\": 2446.5,\n      \"load\"",
            "\"density\": \"heavy\",\n      \"load\"",
            "blocks[1].density",
        ),
        (
            "\"density\": 2446.5,\n      \"load\"",
            "\"density\": -1.0,\n      \"load\"",
            "blocks[1]",
        ),
        ("\"friction_deg\": 30.5", "\"friction_deg\": 95.0", "joints[0].law"),
        ("\"tolerance\": 0.001", "\"tolerance\": -0.001", "parameters"),
        ("\"alpha\": 0.8", "\"alpha\": 1.5", "damping"),
        ("\"block\": 1,", "\"block\": 7,", "monitors[0]"),
        (
            "\"monitor_interval\": 10",
            "\"monitor_interval\": 10, \"colour\": 3",
            "colour",
        ),
        (
            "[-0.1, -0.1, 0.2], [0.1, -0.1, 0.2], [0.1, 0.1, 0.2], [-0.1, 0.1, 0.2]",
            "[-0.1, -0.1, 0.0], [0.1, -0.1, 0.0], [0.1, 0.1, 0.0], [-0.1, 0.1, 0.0]",
            "blocks[1]",
        ),
    ];
    for (from, to, expected) in cases {
        let bad = text.replacen(from, to, 1);
        assert_ne!(bad, text, "test case {from:?} does not apply");
        // The model and its recorder (whose monitors name blocks of the model).
        let err = Scene::<CoulombSlip>::from_json(&bad)
            .and_then(|s| s.build().and_then(|m| s.recorder(&m)))
            .expect_err(expected);
        assert!(err.to_string().contains(expected), "{expected:?} not in {err}");
    }
    Ok(())
}

/// A scene file saved with a UTF-8 byte-order mark (as some editors write) reads as without
/// (it used to fail with "expected value at line 1 column 1").
#[test]
fn a_byte_order_mark_is_accepted() -> Result<()> {
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/examples/block-on-base.json"))
        .expect("example file");
    let scene = Scene::<CoulombSlip>::from_json(&format!("\u{feff}{text}"))?;
    assert_eq!(scene.build()?.blocks().len(), 2);
    Ok(())
}

/// A file that is not a JSON object (`[]`, `[1, 2]`, a number, a string, `null`, nothing) is
/// refused with a message saying what a scene file is; it used to say "invalid length 2, expected
/// struct Scene with 6 elements" (serde's message for a struct written as an array). A block
/// written as an array gets the same hint, with its path.
#[test]
fn a_scene_that_is_not_a_json_object_says_what_a_scene_is() {
    for (text, found) in [
        ("[]", "an array"),
        ("[1, 2]", "an array"),
        ("\u{feff} [ ]", "an array"),
        ("3.5", "a number"),
        ("-1", "a number"),
        ("\"scene\"", "a string"),
        ("true", "a boolean"),
        ("null", "null"),
        ("", "empty"),
        ("  \n", "empty"),
    ] {
        let e = Scene::<CoulombSlip>::from_json(text).unwrap_err();
        assert!(matches!(e, Error::Checkpoint { .. }), "{text:?}: {e:?}");
        let message = e.to_string();
        for part in ["scene file must be a JSON object", "\"joints\"", "\"blocks\"", found] {
            assert!(message.contains(part), "{text:?}: {part:?} not in {message}");
        }
        assert!(!message.contains("invalid length"), "{message}");
    }
    let e = Scene::<CoulombSlip>::from_json(r#"{"joints": [], "blocks": [[]]}"#).unwrap_err();
    let Error::Checkpoint { path, message } = &e else {
        panic!("expected Checkpoint, got {e:?}")
    };
    assert_eq!(path, "blocks[0]");
    assert!(
        message.contains("must be a JSON object") && message.contains("BlockSpec"),
        "{message}"
    );
    // Not JSON at all: serde's syntax error, with its line and column.
    let e = Scene::<CoulombSlip>::from_json("scene: 1").unwrap_err();
    assert!(e.to_string().contains("line 1"), "{e}");
}
