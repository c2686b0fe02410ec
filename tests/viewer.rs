//! The HTML viewer: what the page carries (the frames' poses, times, fields, contacts and
//! curves, read back from the page's data), and its refusals. The page itself is opened in
//! headless Chromium by the Python tests (`python/tests/test_viewer.py`, which `.ci/run` runs
//! with Chromium installed): pixels, the page's own checks of frame count and time range, no
//! console errors.

use crate::common;

use base64::Engine as _;
use voussoir::io::viewer::Viewer;
use voussoir::monitor::{Component, Monitor};
use voussoir::prelude::*;

/// The JSON data inside a page.
fn data(page: &str) -> serde_json::Value {
    let open = "<script type=\"application/json\" id=\"voussoir-data\">";
    let start = page.find(open).expect("data element") + open.len();
    let end = start + page[start..].find("</script>").expect("end of the data element");
    serde_json::from_str(&page[start..end]).expect("the data is JSON")
}

fn floats(text: &serde_json::Value) -> Vec<f32> {
    let bytes = base64::engine::general_purpose::STANDARD
        .decode(text.as_str().expect("base64 text"))
        .expect("base64");
    bytes
        .chunks(4)
        .map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes")))
        .collect()
}

/// A cube dropped 1 cm onto a slab, recorded every 200 steps.
fn dropped_cube() -> Result<(Model<CoulombSlip>, Viewer)> {
    let mut model = common::model(CoulombSlip::dry(1e9, 4e8, 30.0)?);
    model.add_block(common::fixed_slab("slab"))?;
    let cube = model.add_block(common::cube("cube", Vector::new(0.0, 0.0, 0.01)))?;
    let mut viewer = Viewer::new("a cube </script> & a slab").with_time_from_first_frame();
    viewer.add_monitor(
        "cube height",
        Monitor::Displacement {
            block: cube,
            point: Vector::new(0.0, 0.0, 0.11),
            component: Component::Z,
        },
    )?;
    model.run_steps(10)?;
    for _ in 0..6 {
        viewer.record(&model)?;
        model.run_steps(200)?;
    }
    Ok((model, viewer))
}

#[test]
fn the_page_carries_every_frame_pose_field_contact_and_curve() -> Result<()> {
    let (model, mut viewer) = dropped_cube()?;
    viewer.add_curve("a line", ("x (m)", "y (N)"), &[0.0, 1.0], &[2.0, f64::NAN], false)?;
    let page = viewer.to_html()?;
    // The title is escaped in the page's title; the data cannot end its script element.
    assert!(page.contains("<title>a cube &lt;/script&gt; &amp; a slab — voussoir</title>"));
    let d = data(&page);
    assert_eq!(d["title"], "a cube </script> & a slab");
    assert_eq!(d["up"], serde_json::json!([0.0, 0.0, 1.0]));
    assert_eq!(d["blocks"]["count"], 2);
    let frames = d["frames"].as_array().expect("frames");
    assert_eq!(frames.len(), 6);
    // Times from the first frame, 200 steps apart (the step may shorten at impacts).
    let times: Vec<f64> = frames.iter().map(|f| f["time"].as_f64().expect("time")).collect();
    assert_eq!(times[0], 0.0);
    assert_eq!(times, viewer.times());
    assert!(times.windows(2).all(|w| w[1] > w[0]));
    let steps: Vec<u64> = frames.iter().map(|f| f["step"].as_u64().expect("step")).collect();
    assert_eq!(steps, [10, 210, 410, 610, 810, 1010]);
    assert!(times[5] <= 1000.0 * model.dt() * (1.0 + 1e-12) && times[5] > 0.0);
    // The last frame's pose of the cube is the model's, in single precision.
    let last = &frames[5];
    let pose = floats(&last["pose"]);
    assert_eq!(pose.len(), 14, "7 floats per block");
    let q = &pose[10..14];
    let norm = q.iter().map(|v| v * v).sum::<f32>().sqrt();
    assert!((norm - 1.0).abs() < 1e-6, "a unit quaternion: {q:?}");
    // The displacement field is the one the cube's height monitor sampled at the same instant.
    let shown = floats(&last["fields"]["displacement"]);
    let curves = d["curves"].as_array().expect("curves");
    let names: Vec<&str> = curves.iter().map(|c| c["name"].as_str().expect("name")).collect();
    assert_eq!(
        names,
        ["largest displacement", "kinetic energy", "cube height", "a line"]
    );
    let height = curves[2]["y"][5].as_f64().expect("sampled");
    assert!(
        (f64::from(shown[1]) - height.abs()).abs() < 1e-6,
        "{shown:?} vs {height}"
    );
    assert_eq!(f64::from(shown[0]), 0.0, "the slab does not move");
    // The cube fell 1 cm and rests on the slab: the frames show it.
    assert!((height + 0.01).abs() < 5e-4, "cube height change {height}");
    // Contacts: one joint at rest carrying the cube's weight, its polygon the 0.2 m square.
    let c = &last["contacts"];
    assert_eq!(c["count"], 1);
    let force = floats(&c["force"]);
    let weight = common::STONE_DENSITY * common::CUBE_EDGE.powi(3) * 9.81;
    assert!(
        (f64::from(force[2]).abs() - weight).abs() < 0.02 * weight,
        "{force:?} vs {weight}"
    );
    let polygon = floats(&c["polygon"]);
    assert_eq!(polygon.len(), 12, "four corners");
    // A NaN in a curve is null (a gap), not invalid JSON.
    assert_eq!(curves[3]["y"][1], serde_json::Value::Null);
    Ok(())
}

#[test]
fn a_viewer_refuses_what_it_cannot_show() -> Result<()> {
    let (mut model, mut viewer) = dropped_cube()?;
    // Names are unique, the built-in curves' included.
    assert!(matches!(
        viewer.add_monitor("cube height", Monitor::UnbalancedRatio),
        Err(Error::InvalidName { .. })
    ));
    assert!(viewer.add_curve("kinetic energy", ("t", "J"), &[], &[], true).is_err());
    assert!(matches!(
        viewer.add_curve("mismatch", ("t", "J"), &[1.0], &[], true),
        Err(Error::Unsupported { .. })
    ));
    // One viewer, one model.
    model.add_block(common::cube("another", Vector::new(0.5, 0.5, 0.0)))?;
    let err = viewer.record(&model).expect_err("other blocks");
    assert!(err.to_string().contains("3 blocks after frames of 2"), "{err}");
    // Another model of as many blocks but other shapes (probe 3, F8: it was taken).
    let mut other = common::model(CoulombSlip::dry(1e9, 4e8, 30.0)?);
    other.add_block(common::fixed_slab("slab"))?;
    other.add_block(RigidBlock::cuboid(
        "brick",
        Vector::new(0.0, 0.0, 0.0),
        Vector::new(0.2, 0.1, 0.05),
        2000.0,
    )?)?;
    let err = viewer.record(&other).expect_err("another model");
    assert!(
        err.to_string().contains("block 1 (\"brick\") has another shape"),
        "{err}"
    );
    // Nothing to show before a frame; nothing written then.
    let empty = Viewer::new("empty");
    assert!(empty.is_empty());
    let path = std::env::temp_dir().join(format!("voussoir-viewer-empty-{}.html", std::process::id()));
    assert!(matches!(empty.write(&path), Err(Error::Unsupported { .. })));
    assert!(!path.exists());
    Ok(())
}

#[test]
fn a_large_model_can_be_recorded_without_contacts() -> Result<()> {
    let (model, _) = dropped_cube()?;
    let mut viewer = Viewer::new("no contacts").without_contacts();
    viewer.record(&model)?;
    let d = data(&viewer.to_html()?);
    assert!(d["frames"][0].get("contacts").is_none());
    let dir = std::env::temp_dir().join(format!("voussoir-viewer-{}", std::process::id()));
    let path = dir.join("sub").join("cube.html");
    viewer.write(&path)?;
    assert!(std::fs::read_to_string(&path)
        .expect("written")
        .starts_with("<!DOCTYPE html>"));
    std::fs::remove_dir_all(&dir).expect("cleaned up");
    Ok(())
}

/// Names that HTML would read as markup inside the data element (probe 3, F8): `<!--<script>`
/// opened an escaped section that swallowed the renderer. Every `<` in the data is written as
/// `\u003c`, and the names read back unchanged.
#[test]
fn markup_in_names_cannot_break_the_page() -> Result<()> {
    let (_, mut viewer) = dropped_cube()?;
    let name = "<!--<script> </script><b>";
    viewer.add_curve(name, ("x <i>", "y"), &[0.0, 1.0], &[1.0, 2.0], false)?;
    let page = viewer.to_html()?;
    let open = "<script type=\"application/json\" id=\"voussoir-data\">";
    let start = page.find(open).expect("data element") + open.len();
    let end = start + page[start..].find("</script>").expect("end of the data element");
    assert!(!page[start..end].contains('<'), "markup in the data element");
    let json = data(&page);
    let curves = json["curves"].as_array().expect("curves");
    assert!(
        curves.iter().any(|c| c["name"] == name && c["x_label"] == "x <i>"),
        "{curves:?}"
    );
    Ok(())
}
