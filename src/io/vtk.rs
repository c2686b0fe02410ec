//! ParaView output: VTU files with real polyhedron cells (VTK cell type 42) for the blocks, a
//! point set for the sub-contacts, and `.pvd` collections for time series.
//!
//! The files are ASCII XML with `{:e}` (shortest round-trip) numbers, so they are exact and
//! readable by any VTK ≥ 8.1 reader.

use std::fmt::Write as _;
use std::fs;
use std::io::Write as _;
use std::path::{Path, PathBuf};

use crate::block::Block;
use crate::constitutive::{ConstitutiveLaw, JointStatus};
use crate::error::Result;
use crate::io::io_error;
use crate::math::Real;
use crate::model::Model;

/// VTK cell type of a polyhedron.
const VTK_POLYHEDRON: u8 = 42;
/// VTK cell type of a vertex.
const VTK_VERTEX: u8 = 1;

/// Sub-contact state codes written to the `state` array.
pub const STATE_CODES: &str = "0 elastic, 1 sliding, 2 open, 3 failed";

/// Writes the blocks as one VTU file of polyhedron cells, with cell data `block_id`, `material`,
/// `displacement` (of the centroid, m), `velocity` (m/s), `rotation` (rotation vector from the
/// initial pose, rad) and `fixed` (1 when all degrees of freedom are constrained).
///
/// # Errors
/// [`crate::Error::Io`] naming the file.
pub fn write_blocks<B: Block>(path: &Path, blocks: &[B], initial: impl Fn(usize) -> crate::math::Pose) -> Result<()> {
    let mut points = String::new();
    let mut connectivity = String::new();
    let mut offsets = String::new();
    let mut faces = String::new();
    let mut face_offsets = String::new();
    let (mut n_points, mut n_conn, mut n_faces) = (0usize, 0usize, 0usize);
    for b in blocks {
        let shape = b.shape();
        let pose = &b.state().pose;
        for v in shape.vertices() {
            let p = pose.transform_point(*v);
            let _ = write!(points, "{:e} {:e} {:e} ", p.x, p.y, p.z);
        }
        for k in 0..shape.vertices().len() {
            let _ = write!(connectivity, "{} ", n_points + k);
        }
        n_conn += shape.vertices().len();
        let _ = write!(offsets, "{n_conn} ");
        let _ = write!(faces, "{} ", shape.faces().len());
        n_faces += 1;
        for f in 0..shape.faces().len() {
            let ids = shape.face_loop(f);
            let _ = write!(faces, "{} ", ids.len());
            n_faces += 1 + ids.len();
            for &i in ids {
                let _ = write!(faces, "{} ", n_points + i as usize);
            }
        }
        let _ = write!(face_offsets, "{n_faces} ");
        n_points += shape.vertices().len();
    }
    let mut cell = CellArrays::default();
    for (i, b) in blocks.iter().enumerate() {
        let s = b.state();
        let p0 = initial(i);
        let rot = (s.pose.rotation * p0.rotation.inverse()).to_scaled_axis();
        let d = s.pose.translation - p0.translation;
        let fixed = b
            .fixity()
            .translation
            .iter()
            .chain(&b.fixity().rotation)
            .all(|d| d.prescribed().is_some());
        let _ = write!(cell.block_id, "{i} ");
        let _ = write!(cell.material, "{} ", b.material().0);
        let _ = write!(cell.displacement, "{:e} {:e} {:e} ", d.x, d.y, d.z);
        let v = s.velocity;
        let _ = write!(cell.velocity, "{:e} {:e} {:e} ", v.x, v.y, v.z);
        let _ = write!(cell.rotation, "{:e} {:e} {:e} ", rot.x, rot.y, rot.z);
        let _ = write!(cell.fixed, "{} ", u8::from(fixed));
    }
    let types = format!("{VTK_POLYHEDRON} ").repeat(blocks.len());
    let mut out = String::with_capacity(points.len() * 2);
    header(&mut out, n_points, blocks.len());
    data_array(&mut out, "Float64", "Points", 3, &points, true);
    out.push_str("</Points>\n<Cells>\n");
    data_array(&mut out, "Int64", "connectivity", 1, &connectivity, false);
    data_array(&mut out, "Int64", "offsets", 1, &offsets, false);
    data_array(&mut out, "UInt8", "types", 1, &types, false);
    data_array(&mut out, "Int64", "faces", 1, &faces, false);
    data_array(&mut out, "Int64", "faceoffsets", 1, &face_offsets, false);
    out.push_str("</Cells>\n<CellData Scalars=\"block_id\" Vectors=\"displacement\">\n");
    data_array(&mut out, "Int32", "block_id", 1, &cell.block_id, false);
    data_array(&mut out, "Int32", "material", 1, &cell.material, false);
    data_array(&mut out, "UInt8", "fixed", 1, &cell.fixed, false);
    data_array(&mut out, "Float64", "displacement", 3, &cell.displacement, false);
    data_array(&mut out, "Float64", "velocity", 3, &cell.velocity, false);
    data_array(&mut out, "Float64", "rotation", 3, &cell.rotation, false);
    out.push_str("</CellData>\n");
    footer(&mut out);
    write_file(path, &out)
}

#[derive(Default)]
struct CellArrays {
    block_id: String,
    material: String,
    fixed: String,
    displacement: String,
    velocity: String,
    rotation: String,
}

/// Writes the sub-contacts of a model as a VTU point set with point data `normal_force` (N,
/// compression positive), `normal_stress` (Pa), `shear_force` (N, vector on the second block),
/// `area` (m²), `normal_displacement` (m, positive = open), `slip` (m), `state`
/// (see [`STATE_CODES`]) and `contact` (index of the contact).
///
/// # Errors
/// [`crate::Error::Io`] naming the file.
pub fn write_subcontacts<L: ConstitutiveLaw>(path: &Path, model: &Model<L>) -> Result<()> {
    let n = model.subcontact_count();
    let mut a = SubArrays::default();
    let law = model.joints().laws();
    for (ci, c) in model.contacts().enumerate() {
        let l = &law[c.pair.law_index()];
        for s in c.subs {
            let p = s.point();
            let _ = write!(a.points, "{:e} {:e} {:e} ", p.x, p.y, p.z);
            let _ = write!(a.normal_force, "{:e} ", s.normal_force());
            let _ = write!(a.normal_stress, "{:e} ", s.normal_stress());
            let f = s.shear_force();
            let _ = write!(a.shear, "{:e} {:e} {:e} ", f.x, f.y, f.z);
            let _ = write!(a.area, "{:e} ", s.area());
            let _ = write!(a.gap, "{:e} ", s.normal_displacement());
            let _ = write!(a.slip, "{:e} ", s.slip());
            let code = if l.is_failed(s.law_state()) && s.status() != JointStatus::Sliding {
                3
            } else {
                match s.status() {
                    JointStatus::Elastic => 0,
                    JointStatus::Sliding => 1,
                    JointStatus::Open => 2,
                }
            };
            let _ = write!(a.state, "{code} ");
            let _ = write!(a.contact, "{ci} ");
        }
    }
    let mut out = String::with_capacity(a.points.len() * 4);
    header(&mut out, n, n);
    data_array(&mut out, "Float64", "Points", 3, &a.points, true);
    out.push_str("</Points>\n<Cells>\n");
    let seq: String = (0..n).map(|i| format!("{i} ")).collect();
    let ends: String = (1..=n).map(|i| format!("{i} ")).collect();
    data_array(&mut out, "Int64", "connectivity", 1, &seq, false);
    data_array(&mut out, "Int64", "offsets", 1, &ends, false);
    data_array(
        &mut out,
        "UInt8",
        "types",
        1,
        &format!("{VTK_VERTEX} ").repeat(n),
        false,
    );
    out.push_str("</Cells>\n<PointData Scalars=\"normal_stress\" Vectors=\"shear_force\">\n");
    data_array(&mut out, "Float64", "normal_force", 1, &a.normal_force, false);
    data_array(&mut out, "Float64", "normal_stress", 1, &a.normal_stress, false);
    data_array(&mut out, "Float64", "shear_force", 3, &a.shear, false);
    data_array(&mut out, "Float64", "area", 1, &a.area, false);
    data_array(&mut out, "Float64", "normal_displacement", 1, &a.gap, false);
    data_array(&mut out, "Float64", "slip", 1, &a.slip, false);
    data_array(&mut out, "UInt8", "state", 1, &a.state, false);
    data_array(&mut out, "Int32", "contact", 1, &a.contact, false);
    out.push_str("</PointData>\n");
    footer(&mut out);
    write_file(path, &out)
}

#[derive(Default)]
struct SubArrays {
    points: String,
    normal_force: String,
    normal_stress: String,
    shear: String,
    area: String,
    gap: String,
    slip: String,
    state: String,
    contact: String,
}

fn header(out: &mut String, points: usize, cells: usize) {
    out.push_str("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n<UnstructuredGrid>\n");
    let _ = writeln!(out, "<Piece NumberOfPoints=\"{points}\" NumberOfCells=\"{cells}\">");
    out.push_str("<Points>\n");
}

fn footer(out: &mut String) {
    out.push_str("</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
}

fn data_array(out: &mut String, ty: &str, name: &str, components: usize, values: &str, points: bool) {
    let name_attr = if points {
        String::new()
    } else {
        format!(" Name=\"{name}\"")
    };
    let _ = writeln!(
        out,
        "<DataArray type=\"{ty}\"{name_attr} NumberOfComponents=\"{components}\" format=\"ascii\">\n{}\n</DataArray>",
        values.trim_end()
    );
}

fn write_file(path: &Path, text: &str) -> Result<()> {
    if let Some(dir) = path.parent() {
        if !dir.as_os_str().is_empty() {
            fs::create_dir_all(dir).map_err(|e| io_error(dir, &e))?;
        }
    }
    let mut f = fs::File::create(path).map_err(|e| io_error(path, &e))?;
    f.write_all(text.as_bytes()).map_err(|e| io_error(path, &e))
}

/// A ParaView time series: each frame writes `<name>_blocks_<k>.vtu` and
/// `<name>_contacts_<k>.vtu` into the folder and rewrites `<name>_blocks.pvd` and
/// `<name>_contacts.pvd`.
///
/// ```no_run
/// # use voussoir::prelude::*;
/// # fn run(model: &mut Model) -> voussoir::Result<()> {
/// let mut series = voussoir::io::vtk::Series::new("out/demo", "wall");
/// for _ in 0..10 {
///     model.run_steps(1000)?;
///     series.write_frame(model)?; // between frames the stepping is untouched
/// }
/// # Ok(()) }
/// ```
#[derive(Debug, Clone)]
pub struct Series {
    dir: PathBuf,
    name: String,
    frames: Vec<(Real, String, String)>,
}

impl Series {
    /// A new, empty series written into `dir`.
    pub fn new(dir: impl Into<PathBuf>, name: &str) -> Self {
        Self {
            dir: dir.into(),
            name: name.to_owned(),
            frames: Vec::new(),
        }
    }

    /// Writes the model's blocks and sub-contacts as the next frame, at the model's time.
    ///
    /// # Errors
    /// [`crate::Error::Io`] naming the file.
    pub fn write_frame<L: ConstitutiveLaw>(&mut self, model: &Model<L>) -> Result<()> {
        let k = self.frames.len();
        let blocks = format!("{}_blocks_{k:05}.vtu", self.name);
        let contacts = format!("{}_contacts_{k:05}.vtu", self.name);
        let initial = |i: usize| *model.blocks()[i].initial_pose();
        write_blocks(&self.dir.join(&blocks), model.blocks(), initial)?;
        write_subcontacts(&self.dir.join(&contacts), model)?;
        self.frames.push((model.time(), blocks, contacts));
        self.write_collections()
    }

    /// Number of frames written.
    pub fn len(&self) -> usize {
        self.frames.len()
    }

    /// `true` before the first frame.
    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }

    /// Path of the blocks' `.pvd` collection.
    pub fn blocks_pvd(&self) -> PathBuf {
        self.dir.join(format!("{}_blocks.pvd", self.name))
    }

    fn write_collections(&self) -> Result<()> {
        for (suffix, pick) in [("blocks", 0), ("contacts", 1)] {
            let mut out = String::from(
                "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n<Collection>\n",
            );
            for (t, b, c) in &self.frames {
                let file = if pick == 0 { b } else { c };
                let _ = writeln!(
                    out,
                    "<DataSet timestep=\"{t:e}\" group=\"\" part=\"0\" file=\"{file}\"/>"
                );
            }
            out.push_str("</Collection>\n</VTKFile>\n");
            write_file(&self.dir.join(format!("{}_{suffix}.pvd", self.name)), &out)?;
        }
        Ok(())
    }
}
