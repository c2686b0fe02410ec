//! ParaView output read back by a real reader.
//!
//! The structure of the files is checked here in Rust. With `VOUSSOIR_VTK_CHECK=1` (set by
//! `.ci/run`, which installs VTK's Python package) the files are also read by VTK itself, which
//! checks cell counts, cell types, the total volume of the polyhedra and the sub-contact areas.

mod common;

use std::path::Path;
use std::process::Command;

use voussoir::io::vtk::Series;
use voussoir::prelude::*;

#[test]
fn vtu_frames_are_read_back_by_vtk() -> Result<()> {
    let mut model = common::model(CoulombSlip::dry(1e9, 4e8, 30.0)?);
    model.add_block(
        RigidBlock::cuboid(
            "base",
            Vector::new(-1.0, -1.0, -0.2),
            Vector::new(1.0, 1.0, 0.0),
            2000.0,
        )?
        .with_fixity(Fixity::FIXED),
    )?;
    // A hexagonal prism (8 faces, hexagons with 6 vertices) and a wedge.
    let hex: Vec<Vector> = (0..12)
        .map(|k| {
            let a = std::f64::consts::PI / 3.0 * (k % 6) as f64;
            Vector::new(0.1 * a.cos(), 0.1 * a.sin(), if k < 6 { 0.0 } else { 0.15 })
        })
        .collect();
    model.add_block(RigidBlock::from_vertices("hexagon", &hex, 2000.0)?)?;
    let wedge = [
        Vector::new(0.3, 0.0, 0.0),
        Vector::new(0.6, 0.0, 0.0),
        Vector::new(0.3, 0.2, 0.0),
        Vector::new(0.6, 0.2, 0.0),
        Vector::new(0.3, 0.0, 0.2),
        Vector::new(0.3, 0.2, 0.2),
    ];
    model.add_block(RigidBlock::from_vertices("wedge", &wedge, 2000.0)?)?;
    let dir = std::env::temp_dir().join(format!("voussoir-vtk-{}", std::process::id()));
    let mut series = Series::new(&dir, "demo");
    series.write_frame(&model)?;
    model.run_steps(200)?;
    series.write_frame(&model)?;
    assert_eq!(series.len(), 2);

    let blocks = dir.join("demo_blocks_00001.vtu");
    let contacts = dir.join("demo_contacts_00001.vtu");
    let text = std::fs::read_to_string(&blocks).expect("blocks file");
    assert!(text.contains("NumberOfCells=\"3\"") && text.contains("Name=\"faces\""));
    let pvd = std::fs::read_to_string(series.blocks_pvd()).expect("pvd");
    assert_eq!(pvd.matches("<DataSet").count(), 2);

    let volume: f64 = model.blocks().iter().map(|b| b.shape().volume()).sum();
    let area: f64 = model.contacts().flat_map(|c| c.subcontacts()).map(|s| s.area()).sum();
    // Hexagon on the base (area 1.5·√3·r²) and the wedge's 0.3 × 0.2 face.
    let expected_area = 1.5 * 3f64.sqrt() * 0.01 + 0.06;
    assert!((area - expected_area).abs() < 1e-12, "{area} vs {expected_area}");

    if std::env::var("VOUSSOIR_VTK_CHECK").as_deref() == Ok("1") {
        let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/vtk_check.py");
        let out = Command::new("python3")
            .arg(script)
            .args([&blocks, &contacts, &series.blocks_pvd()])
            .args([
                model.blocks().len().to_string(),
                volume.to_string(),
                model.subcontact_count().to_string(),
                area.to_string(),
            ])
            .output()
            .expect("python3 runs");
        let stdout = String::from_utf8_lossy(&out.stdout);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "VTK check failed:\n{stdout}\n{stderr}");
        println!("{stdout}");
    } else {
        eprintln!("VOUSSOIR_VTK_CHECK is not 1: skipping the read-back with VTK (.ci/run does it)");
    }
    std::fs::remove_dir_all(&dir).ok();
    Ok(())
}
