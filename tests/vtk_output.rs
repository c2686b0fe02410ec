//! ParaView output read back by a real reader, and names that must not break the files they
//! name (series names in `.pvd` collections and file names, monitor names in CSV histories).
//!
//! The structure of the files is checked here in Rust. With `VOUSSOIR_VTK_CHECK=1` (set by
//! `.ci/run`, which installs VTK's Python package) the files are also read by VTK itself, which
//! checks cell counts, cell types, the total volume of the polyhedra, the total area of the
//! face polygons the series writes and the sub-contact areas.

use crate::common;

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

    // The series writes the blocks as the polygons of their faces (meshio reads them too);
    // `write_blocks` writes them as polyhedra.
    let surfaces = dir.join("demo_blocks_00001.vtu");
    let contacts = dir.join("demo_contacts_00001.vtu");
    let blocks = dir.join("polyhedra.vtu");
    voussoir::io::vtk::write_blocks(&blocks, model.blocks(), |i| *model.blocks()[i].initial_pose())?;
    let text = std::fs::read_to_string(&blocks).expect("blocks file");
    assert!(text.contains("NumberOfCells=\"3\"") && text.contains("Name=\"faces\""));
    let faces: usize = model.blocks().iter().map(|b| b.shape().faces().len()).sum();
    let surface: f64 = model
        .blocks()
        .iter()
        .flat_map(|b| b.shape().faces().iter().map(|f| f.area))
        .sum();
    let text = std::fs::read_to_string(&surfaces).expect("surfaces file");
    assert!(text.contains(&format!("NumberOfCells=\"{faces}\"")) && text.contains("Name=\"face\""));
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
            .args([&blocks, &contacts, &series.blocks_pvd(), &surfaces])
            .args([
                model.blocks().len().to_string(),
                volume.to_string(),
                model.subcontact_count().to_string(),
                area.to_string(),
                faces.to_string(),
                surface.to_string(),
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

/// Checks that `text` is well-formed XML as far as voussoir writes it (a prolog, nested
/// elements, attributes in double quotes, text; no comments, CDATA or DTD) and returns the
/// unescaped values of every attribute named `attribute`, in document order.
fn well_formed_xml(text: &str, attribute: &str) -> std::result::Result<Vec<String>, String> {
    fn unescape(raw: &str) -> std::result::Result<String, String> {
        let mut out = String::new();
        let mut rest = raw;
        while let Some(i) = rest.find('&') {
            out.push_str(&rest[..i]);
            let end = rest[i..]
                .find(';')
                .ok_or_else(|| format!("unterminated entity in {raw:?}"))?;
            out.push(match &rest[i + 1..i + end] {
                "amp" => '&',
                "lt" => '<',
                "gt" => '>',
                "quot" => '"',
                "apos" => '\'',
                e => return Err(format!("unknown entity &{e}; in {raw:?}")),
            });
            rest = &rest[i + end + 1..];
        }
        out.push_str(rest);
        Ok(out)
    }
    let name_ok = |n: &str| !n.is_empty() && n.chars().all(|c| c.is_alphanumeric() || "_-:.".contains(c));
    let mut values = Vec::new();
    let mut stack: Vec<String> = Vec::new();
    let mut roots = 0;
    let mut rest = text
        .strip_prefix("<?xml version=\"1.0\"?>")
        .ok_or("no XML declaration")?;
    while !rest.is_empty() {
        let lt = rest.find('<').unwrap_or(rest.len());
        unescape(&rest[..lt])?;
        if stack.is_empty() && !rest[..lt].trim().is_empty() {
            return Err(format!("text outside the root element: {:?}", &rest[..lt]));
        }
        rest = &rest[lt..];
        if rest.is_empty() {
            break;
        }
        let gt = rest.find('>').ok_or("unterminated tag")?;
        let tag = &rest[1..gt];
        rest = &rest[gt + 1..];
        if let Some(name) = tag.strip_prefix('/') {
            if stack.pop().as_deref() != Some(name.trim()) {
                return Err(format!("closing tag </{name}> does not match"));
            }
            continue;
        }
        let (tag, empty) = match tag.strip_suffix('/') {
            Some(t) => (t, true),
            None => (tag, false),
        };
        let mut parts = tag.trim_end();
        let name_end = parts.find(char::is_whitespace).unwrap_or(parts.len());
        let name = &parts[..name_end];
        if !name_ok(name) {
            return Err(format!("bad element name {name:?}"));
        }
        parts = parts[name_end..].trim_start();
        while !parts.is_empty() {
            let eq = parts
                .find('=')
                .ok_or_else(|| format!("attribute without value in <{tag}>"))?;
            let key = parts[..eq].trim();
            if !name_ok(key) {
                return Err(format!("bad attribute name {key:?} in <{tag}>"));
            }
            let value = parts[eq + 1..].strip_prefix('"').ok_or("attribute value not quoted")?;
            let close = value.find('"').ok_or("unterminated attribute value")?;
            let raw = &value[..close];
            if raw.contains('<') {
                return Err(format!("'<' in attribute value {raw:?}"));
            }
            let unescaped = unescape(raw)?;
            if key == attribute {
                values.push(unescaped);
            }
            let after = &value[close + 1..];
            if !(after.is_empty() || after.starts_with(char::is_whitespace)) {
                return Err(format!("no space after attribute {key}"));
            }
            parts = after.trim_start();
        }
        if stack.is_empty() {
            roots += 1;
            if roots > 1 {
                return Err(format!("second root element <{name}>"));
            }
        }
        if !empty {
            stack.push(name.to_owned());
        }
    }
    if stack.is_empty() && roots == 1 {
        Ok(values)
    } else {
        Err(format!("unclosed elements {stack:?}"))
    }
}

fn one_block_model() -> Result<Model> {
    let mut model = common::model(CoulombSlip::dry(1e9, 4e8, 30.0)?);
    model.add_block(common::fixed_slab("slab"))?;
    model.add_block(common::cube("cube", Vector::ZERO))?;
    Ok(model)
}

/// A series name with XML's special characters still gives well-formed `.pvd` collections
/// whose `file` attributes name the files written; names that are not portable file names —
/// path separators that would write outside the folder, `..`, NUL and other control
/// characters, Windows' reserved characters, the empty name — are refused with
/// `Error::InvalidName` naming them, and nothing is written.
#[test]
fn series_names_stay_in_the_folder_and_collections_stay_well_formed() -> Result<()> {
    let mut model = one_block_model()?;
    let root = std::env::temp_dir().join(format!("voussoir-series-names-{}", std::process::id()));
    let dir = root.join("series");
    std::fs::create_dir_all(&dir).expect("temporary folder");

    let name = "wall & arch 'v2'";
    let mut series = Series::try_new(&dir, name)?;
    series.write_frame(&model)?;
    model.run_steps(5)?;
    series.write_frame(&model)?;
    for pvd in ["blocks", "contacts"] {
        let path = dir.join(format!("{name}_{pvd}.pvd"));
        let text = std::fs::read_to_string(&path).expect("collection written");
        let files = well_formed_xml(&text, "file").unwrap_or_else(|e| panic!("{}: {e}\n{text}", path.display()));
        assert_eq!(files.len(), 2, "{text}");
        for f in files {
            assert!(f.starts_with(name), "{f}");
            assert!(
                dir.join(&f).is_file(),
                "{f} named in {} was not written",
                path.display()
            );
        }
    }

    let long = "x".repeat(201);
    for bad in [
        "../escape",
        "..\\escape",
        "sub/dir",
        "/absolute",
        "..",
        ".",
        "",
        "nul\0byte",
        "new\nline",
        "<tag>",
        "say \"hi\"",
        "a:b",
        "what?",
        long.as_str(),
    ] {
        let before: Vec<_> = walk(&root);
        let e = Series::new(&dir, bad).write_frame(&model).unwrap_err();
        let Error::InvalidName { what, name, reason } = &e else {
            panic!("{bad:?}: expected InvalidName, got {e:?}")
        };
        assert_eq!((*what, name.as_str()), ("series name", bad));
        assert!(!reason.is_empty());
        assert!(e.to_string().contains(&format!("{bad:?}")), "{e}");
        assert!(Series::try_new(&dir, bad).is_err(), "{bad:?}");
        assert_eq!(walk(&root), before, "{bad:?} wrote files");
    }
    std::fs::remove_dir_all(&root).ok();
    Ok(())
}

/// Every file and folder under `root`, sorted.
fn walk(root: &Path) -> Vec<std::path::PathBuf> {
    let mut out = Vec::new();
    let mut todo = vec![root.to_path_buf()];
    while let Some(d) = todo.pop() {
        for entry in std::fs::read_dir(&d).expect("readable folder").flatten() {
            let p = entry.path();
            if p.is_dir() {
                todo.push(p.clone());
            }
            out.push(p);
        }
    }
    out.sort();
    out
}

/// Splits CSV text into records of fields as RFC 4180 says (quoted fields may hold commas,
/// doubled quotes and line breaks).
fn parse_csv(text: &str) -> std::result::Result<Vec<Vec<String>>, String> {
    let mut records = Vec::new();
    let mut record = Vec::new();
    let mut field = String::new();
    let mut chars = text.chars().peekable();
    let mut quoted = false;
    let mut at_start = true;
    while let Some(c) = chars.next() {
        if quoted {
            match c {
                '"' if chars.peek() == Some(&'"') => {
                    chars.next();
                    field.push('"');
                }
                '"' => {
                    quoted = false;
                    if !matches!(chars.peek(), None | Some(',' | '\n' | '\r')) {
                        return Err(format!("text after a closing quote in {field:?}"));
                    }
                }
                c => field.push(c),
            }
            continue;
        }
        match c {
            '"' if at_start => {
                quoted = true;
                at_start = false;
            }
            '"' => return Err(format!("quote inside an unquoted field {field:?}")),
            ',' => {
                record.push(std::mem::take(&mut field));
                at_start = true;
            }
            '\r' if chars.peek() == Some(&'\n') => {}
            '\n' => {
                record.push(std::mem::take(&mut field));
                records.push(std::mem::take(&mut record));
                at_start = true;
            }
            c => {
                field.push(c);
                at_start = false;
            }
        }
    }
    if quoted {
        return Err("unterminated quoted field".into());
    }
    if !field.is_empty() || !record.is_empty() {
        record.push(field);
        records.push(record);
    }
    Ok(records)
}

/// Monitor names with commas, double quotes and line breaks: the CSV history parses back (RFC
/// 4180) into one header and one record per sample, each with one field per column, and the
/// header gives the names exactly.
#[test]
fn csv_histories_quote_monitor_names() -> Result<()> {
    let mut model = one_block_model()?;
    let names = ["plain", "a, b", "say \"hi\"", "two\nlines", "crlf\r\nend", "\"quoted\""];
    let mut recorder = voussoir::monitor::Recorder::new(2);
    for name in names {
        recorder.add_monitor(&model, name, Monitor::Energy(EnergyTerm::Kinetic))?;
    }
    model.run_steps_observed(10, &mut recorder)?;
    let dir = std::env::temp_dir().join(format!("voussoir-csv-names-{}", std::process::id()));
    let path = dir.join("history.csv");
    voussoir::io::csv::write_history(&path, recorder.history())?;
    let text = std::fs::read_to_string(&path).expect("history written");
    let records = parse_csv(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
    assert_eq!(records.len(), 1 + recorder.history().len(), "{text}");
    for r in &records {
        assert_eq!(r.len(), 2 + names.len(), "{r:?}");
    }
    let header: Vec<String> = ["time [s]".to_owned(), "step".to_owned()]
        .into_iter()
        .chain(names.iter().map(|n| format!("{n} [J]")))
        .collect();
    assert_eq!(records[0], header);
    for r in &records[1..] {
        assert!(r.iter().all(|f| f.parse::<f64>().is_ok()), "{r:?}");
    }
    std::fs::remove_dir_all(&dir).ok();
    Ok(())
}

/// A series whose times count from its first frame: 0, then the model time elapsed since; the
/// default counts the model's time (which includes any settling before the first frame).
#[test]
fn a_series_may_count_time_from_its_first_frame() -> Result<()> {
    let mut model = common::model(CoulombSlip::dry(1e9, 4e8, 30.0)?);
    model.add_block(common::fixed_slab("slab"))?;
    model.add_block(common::cube("cube", Vector::ZERO))?;
    model.run_steps(50)?;
    let t0 = model.time();
    let dir = std::env::temp_dir().join(format!("voussoir-vtk-origin-{}", std::process::id()));
    let mut relative = Series::new(&dir, "relative").with_time_from_first_frame();
    let mut absolute = Series::new(&dir, "absolute");
    for _ in 0..2 {
        relative.write_frame(&model)?;
        absolute.write_frame(&model)?;
        model.run_steps(10)?;
    }
    let times = |pvd: std::path::PathBuf| -> Vec<f64> {
        let text = std::fs::read_to_string(pvd).expect("pvd");
        text.split("timestep=\"")
            .skip(1)
            .map(|rest| rest.split('"').next().expect("value").parse().expect("number"))
            .collect()
    };
    let (r, a) = (times(relative.blocks_pvd()), times(absolute.blocks_pvd()));
    assert!(t0 > 0.0 && r[0] == 0.0 && a[0] == t0, "{r:?} {a:?}");
    assert!((r[1] - (a[1] - t0)).abs() < 1e-15, "{r:?} {a:?}");
    drop((relative, absolute));
    std::fs::remove_dir_all(&dir).ok();
    Ok(())
}
