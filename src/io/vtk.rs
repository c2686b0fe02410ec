//! ParaView output: VTU files of the blocks (as polyhedron cells, VTK type 42, or as the polygons
//! of their faces, which meshio reads too), a point set for the sub-contacts, and `.pvd`
//! collections for time series.
//!
//! The arrays are inline binary (base64, little-endian, exact), readable by any VTK ≥ 8.1 reader
//! and ParaView.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::block::Block;
use crate::error::{io_error, Error, Result};
use crate::law::{ConstitutiveLaw, JointStatus};
use crate::math::Real;
use crate::model::Model;

/// VTK cell type of a polyhedron.
const VTK_POLYHEDRON: u8 = 42;
/// VTK cell type of a vertex.
const VTK_VERTEX: u8 = 1;
/// VTK cell types of a triangle, a quad and a general polygon.
const VTK_TRIANGLE: u8 = 5;
const VTK_QUAD: u8 = 9;
const VTK_POLYGON: u8 = 7;

/// Sub-contact state codes written to the `state` array.
pub const STATE_CODES: &str = "0 elastic, 1 sliding, 2 open, 3 failed";

/// Writes the blocks as one VTU file of polyhedron cells, with cell data `block_id`, `material`,
/// `displacement` (of the centroid, m), `velocity` (m/s), `rotation` (rotation vector from the
/// initial pose, rad) and `fixed` (1 when all degrees of freedom are constrained).
///
/// ParaView reads it; meshio (5.3) does not read blocks of different vertex counts as
/// polyhedra: [`write_block_surfaces`] writes the same blocks as polygons, which both read.
///
/// # Errors
/// [`crate::Error::Io`] naming the file.
pub fn write_blocks<B: Block>(path: &Path, blocks: &[B], initial: impl Fn(usize) -> crate::math::Pose) -> Result<()> {
    let data = BlockData::of(blocks, initial);
    let mut connectivity: Vec<i64> = Vec::new();
    let mut offsets: Vec<i64> = Vec::with_capacity(blocks.len());
    let mut faces: Vec<i64> = Vec::new();
    let mut face_offsets: Vec<i64> = Vec::with_capacity(blocks.len());
    for (b, &first) in blocks.iter().zip(&data.first_point) {
        let shape = b.shape();
        connectivity.extend((0..shape.vertices().len() as i64).map(|k| first + k));
        offsets.push(connectivity.len() as i64);
        faces.push(shape.faces().len() as i64);
        for f in 0..shape.faces().len() {
            let ids = shape.face_loop(f);
            faces.push(ids.len() as i64);
            faces.extend(ids.iter().map(|&i| first + i as i64));
        }
        face_offsets.push(faces.len() as i64);
    }
    let n = blocks.len();
    let mut out = String::with_capacity(data.points.len() * 12);
    header(&mut out, data.points.len() / 3, n);
    data_array(&mut out, "Points", 3, Values::F64(&data.points), true);
    out.push_str("</Points>\n<Cells>\n");
    data_array(&mut out, "connectivity", 1, Values::I64(&connectivity), false);
    data_array(&mut out, "offsets", 1, Values::I64(&offsets), false);
    data_array(&mut out, "types", 1, Values::U8(&vec![VTK_POLYHEDRON; n]), false);
    data_array(&mut out, "faces", 1, Values::I64(&faces), false);
    data_array(&mut out, "faceoffsets", 1, Values::I64(&face_offsets), false);
    out.push_str("</Cells>\n");
    data.cell_data(&mut out, |_| 1, None);
    footer(&mut out);
    write_file(path, &out)
}

/// Writes the blocks as one VTU file of polygon cells, one per face (VTK triangles, quads and
/// polygons): the cell data of [`write_blocks`] repeated on each face of a block, and `face`
/// (the face's index in its block). ParaView draws it as [`write_blocks`]'s polyhedra, and
/// readers without polyhedra (meshio) read it; the [`Series`] writes its blocks so.
///
/// # Errors
/// [`crate::Error::Io`] naming the file.
pub fn write_block_surfaces<B: Block>(
    path: &Path,
    blocks: &[B],
    initial: impl Fn(usize) -> crate::math::Pose,
) -> Result<()> {
    let data = BlockData::of(blocks, initial);
    let mut connectivity: Vec<i64> = Vec::new();
    let (mut offsets, mut types, mut face_counts, mut face_index) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for (b, &first) in blocks.iter().zip(&data.first_point) {
        let shape = b.shape();
        face_counts.push(shape.faces().len());
        for f in 0..shape.faces().len() {
            let ids = shape.face_loop(f);
            connectivity.extend(ids.iter().map(|&i| first + i as i64));
            offsets.push(connectivity.len() as i64);
            types.push(match ids.len() {
                3 => VTK_TRIANGLE,
                4 => VTK_QUAD,
                _ => VTK_POLYGON,
            });
            face_index.push(f as i32);
        }
    }
    let mut out = String::with_capacity(data.points.len() * 12);
    header(&mut out, data.points.len() / 3, types.len());
    data_array(&mut out, "Points", 3, Values::F64(&data.points), true);
    out.push_str("</Points>\n<Cells>\n");
    data_array(&mut out, "connectivity", 1, Values::I64(&connectivity), false);
    data_array(&mut out, "offsets", 1, Values::I64(&offsets), false);
    data_array(&mut out, "types", 1, Values::U8(&types), false);
    out.push_str("</Cells>\n");
    data.cell_data(&mut out, |i| face_counts[i], Some(&face_index));
    footer(&mut out);
    write_file(path, &out)
}

/// The blocks' points (world) and per-block cell data, shared by the two block writers.
struct BlockData {
    points: Vec<f64>,
    /// Index of each block's first point.
    first_point: Vec<i64>,
    block_id: Vec<i32>,
    material: Vec<i32>,
    fixed: Vec<u8>,
    displacement: Vec<f64>,
    velocity: Vec<f64>,
    rotation: Vec<f64>,
}

impl BlockData {
    fn of<B: Block>(blocks: &[B], initial: impl Fn(usize) -> crate::math::Pose) -> Self {
        let n = blocks.len();
        let mut d = Self {
            points: Vec::new(),
            first_point: Vec::with_capacity(n),
            block_id: Vec::with_capacity(n),
            material: Vec::with_capacity(n),
            fixed: Vec::with_capacity(n),
            displacement: Vec::with_capacity(3 * n),
            velocity: Vec::with_capacity(3 * n),
            rotation: Vec::with_capacity(3 * n),
        };
        for (i, b) in blocks.iter().enumerate() {
            let s = b.state();
            d.first_point.push((d.points.len() / 3) as i64);
            for v in b.shape().vertices() {
                d.points.extend(s.pose.transform_point(*v).to_array());
            }
            let p0 = initial(i);
            d.rotation
                .extend((s.pose.rotation * p0.rotation.inverse()).to_scaled_axis().to_array());
            d.displacement.extend((s.pose.translation - p0.translation).to_array());
            d.velocity.extend(s.velocity.to_array());
            d.block_id.push(i as i32);
            d.material.push(i32::from(b.material().0));
            let all = b
                .fixity()
                .translation
                .iter()
                .chain(&b.fixity().rotation)
                .all(|d| d.prescribed().is_some());
            d.fixed.push(u8::from(all));
        }
        d
    }

    /// Writes the cell data, each block's values repeated on its `cells(block)` cells, and the
    /// `face` array when given.
    fn cell_data(&self, out: &mut String, cells: impl Fn(usize) -> usize, face: Option<&[i32]>) {
        fn repeat<T: Copy>(values: &[T], width: usize, cells: &impl Fn(usize) -> usize) -> Vec<T> {
            values
                .chunks(width)
                .enumerate()
                .flat_map(|(i, v)| std::iter::repeat_n(v, cells(i)).flatten().copied())
                .collect()
        }
        out.push_str("<CellData Scalars=\"block_id\" Vectors=\"displacement\">\n");
        data_array(
            out,
            "block_id",
            1,
            Values::I32(&repeat(&self.block_id, 1, &cells)),
            false,
        );
        data_array(
            out,
            "material",
            1,
            Values::I32(&repeat(&self.material, 1, &cells)),
            false,
        );
        data_array(out, "fixed", 1, Values::U8(&repeat(&self.fixed, 1, &cells)), false);
        data_array(
            out,
            "displacement",
            3,
            Values::F64(&repeat(&self.displacement, 3, &cells)),
            false,
        );
        data_array(
            out,
            "velocity",
            3,
            Values::F64(&repeat(&self.velocity, 3, &cells)),
            false,
        );
        data_array(
            out,
            "rotation",
            3,
            Values::F64(&repeat(&self.rotation, 3, &cells)),
            false,
        );
        if let Some(face) = face {
            data_array(out, "face", 1, Values::I32(face), false);
        }
        out.push_str("</CellData>\n");
    }
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
    let law = model.law_table().laws();
    let mut points = Vec::with_capacity(3 * n);
    let mut shear = Vec::with_capacity(3 * n);
    let (mut normal_force, mut normal_stress, mut area, mut gap, mut slip) = (
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
    );
    let (mut state, mut contact) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for (ci, c) in model.contacts().enumerate() {
        let l = &law[c.law_index()];
        // A node contact starts unbonded (`ConstitutiveLaw::unbonded_state`): failed only
        // when it has lost more.
        let unbonded = matches!(c.kind(), crate::geometry::ContactKind::Nodes).then(|| l.unbonded_state());
        for s in c.subcontacts() {
            points.extend(s.point().to_array());
            shear.extend(s.shear_force().to_array());
            normal_force.push(s.normal_force());
            normal_stress.push(s.normal_stress());
            area.push(s.area());
            gap.push(s.normal_displacement());
            slip.push(s.slip());
            let failed = l.is_failed(s.law_state()) && unbonded.as_ref() != Some(s.law_state());
            state.push(if failed && s.status() != JointStatus::Sliding {
                3u8
            } else {
                match s.status() {
                    JointStatus::Elastic => 0,
                    JointStatus::Sliding => 1,
                    JointStatus::Open => 2,
                }
            });
            contact.push(ci as i32);
        }
    }
    let mut out = String::with_capacity(n * 120);
    header(&mut out, n, n);
    data_array(&mut out, "Points", 3, Values::F64(&points), true);
    out.push_str("</Points>\n<Cells>\n");
    let seq: Vec<i64> = (0..n as i64).collect();
    let ends: Vec<i64> = (1..=n as i64).collect();
    data_array(&mut out, "connectivity", 1, Values::I64(&seq), false);
    data_array(&mut out, "offsets", 1, Values::I64(&ends), false);
    data_array(&mut out, "types", 1, Values::U8(&vec![VTK_VERTEX; n]), false);
    out.push_str("</Cells>\n<PointData Scalars=\"normal_stress\" Vectors=\"shear_force\">\n");
    data_array(&mut out, "normal_force", 1, Values::F64(&normal_force), false);
    data_array(&mut out, "normal_stress", 1, Values::F64(&normal_stress), false);
    data_array(&mut out, "shear_force", 3, Values::F64(&shear), false);
    data_array(&mut out, "area", 1, Values::F64(&area), false);
    data_array(&mut out, "normal_displacement", 1, Values::F64(&gap), false);
    data_array(&mut out, "slip", 1, Values::F64(&slip), false);
    data_array(&mut out, "state", 1, Values::U8(&state), false);
    data_array(&mut out, "contact", 1, Values::I32(&contact), false);
    out.push_str("</PointData>\n");
    footer(&mut out);
    write_file(path, &out)
}

/// A typed array for a `DataArray`.
enum Values<'a> {
    F64(&'a [f64]),
    I64(&'a [i64]),
    I32(&'a [i32]),
    U8(&'a [u8]),
}

fn header(out: &mut String, points: usize, cells: usize) {
    out.push_str("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n<UnstructuredGrid>\n");
    let _ = writeln!(out, "<Piece NumberOfPoints=\"{points}\" NumberOfCells=\"{cells}\">");
    out.push_str("<Points>\n");
}

fn footer(out: &mut String) {
    out.push_str("</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
}

/// Appends an inline binary `DataArray`: base64 of a little-endian UInt64 byte count followed by
/// the little-endian values (exact, and an order of magnitude faster than ASCII).
fn data_array(out: &mut String, name: &str, components: usize, values: Values<'_>, points: bool) {
    let (ty, bytes): (&str, Vec<u8>) = match values {
        Values::F64(v) => ("Float64", v.iter().flat_map(|x| x.to_le_bytes()).collect()),
        Values::I64(v) => ("Int64", v.iter().flat_map(|x| x.to_le_bytes()).collect()),
        Values::I32(v) => ("Int32", v.iter().flat_map(|x| x.to_le_bytes()).collect()),
        Values::U8(v) => ("UInt8", v.to_vec()),
    };
    let name_attr = if points {
        String::new()
    } else {
        format!(" Name=\"{name}\"")
    };
    // One component is VTK's default, and left out: readers that reshape every array to its
    // stated components (meshio) then read the cells' index arrays as the flat lists they are.
    let components_attr = if components == 1 {
        String::new()
    } else {
        format!(" NumberOfComponents=\"{components}\"")
    };
    let _ = writeln!(
        out,
        "<DataArray type=\"{ty}\"{name_attr}{components_attr} format=\"binary\">"
    );
    let mut block = Vec::with_capacity(8 + bytes.len());
    block.extend((bytes.len() as u64).to_le_bytes());
    block.extend(bytes);
    base64_into(out, &block);
    out.push_str("\n</DataArray>\n");
}

/// Standard base64 (RFC 4648) with padding.
fn base64_into(out: &mut String, data: &[u8]) {
    const TABLE: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut buf = Vec::with_capacity(data.len().div_ceil(3) * 4);
    for chunk in data.chunks(3) {
        let b = [chunk[0], *chunk.get(1).unwrap_or(&0), *chunk.get(2).unwrap_or(&0)];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        buf.extend_from_slice(&[
            TABLE[(n >> 18) as usize & 63],
            TABLE[(n >> 12) as usize & 63],
            if chunk.len() > 1 {
                TABLE[(n >> 6) as usize & 63]
            } else {
                b'='
            },
            if chunk.len() > 2 { TABLE[n as usize & 63] } else { b'=' },
        ]);
    }
    // The alphabet is ASCII, so the buffer is valid UTF-8.
    out.push_str(std::str::from_utf8(&buf).unwrap_or_default());
}

fn write_file(path: &Path, text: &str) -> Result<()> {
    crate::file::write_atomically(path, text.as_bytes())
}

/// A ParaView time series: each frame writes `<name>_blocks_<k>.vtu` and
/// `<name>_contacts_<k>.vtu` into the folder and rewrites `<name>_blocks.pvd` and
/// `<name>_contacts.pvd`.
///
/// The name must make portable file names inside the folder (see [`check_series_name`]):
/// [`Series::try_new`] checks it at once, [`Series::write_frame`] before writing anything. In
/// the `.pvd` collections the file names are XML-escaped (`&` is written `&amp;`).
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
///
/// One series writes a name in a folder at a time: the first frame takes a lock file
/// (`.<name>.lock`, holding the process id), which the series removes when dropped; a second
/// series (in this process or another one still running) writing the same name into the same
/// folder is refused with [`crate::Error::Io`] naming the lock file, instead of both
/// overwriting each other's frames. A lock left by a process that no longer runs (Linux:
/// checked in `/proc`) is taken over. Before each frame the earlier frames' files must still
/// be there: a folder deleted or emptied mid-run is an error naming the missing file, not a
/// collection listing frames that do not exist.
#[derive(Debug)]
pub struct Series {
    dir: PathBuf,
    name: String,
    /// Each frame's time, blocks file and sub-contacts file (none when skipped).
    frames: Vec<(Real, String, Option<String>)>,
    /// Sub-contacts are written on every this many frames (1: every frame).
    subcontacts_every: usize,
    /// Whether the collections' times count from the first frame (else the model's time).
    from_first_frame: bool,
    /// The model's time at the first frame.
    origin: Real,
    /// The lock file this series holds (from its first frame).
    lock: Option<PathBuf>,
    /// This series' number in the process, written in its lock file.
    id: u64,
}

/// Numbers the series of this process (their lock files tell them apart).
static SERIES: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

impl Clone for Series {
    /// A copy with the frames written so far, holding no lock: its next frame takes the lock,
    /// which is refused while the original holds it.
    fn clone(&self) -> Self {
        Self {
            dir: self.dir.clone(),
            name: self.name.clone(),
            frames: self.frames.clone(),
            subcontacts_every: self.subcontacts_every,
            from_first_frame: self.from_first_frame,
            origin: self.origin,
            lock: None,
            id: SERIES.fetch_add(1, std::sync::atomic::Ordering::Relaxed),
        }
    }
}

impl Drop for Series {
    fn drop(&mut self) {
        if let Some(lock) = self.lock.take() {
            let _ = std::fs::remove_file(lock);
        }
    }
}

/// Whether the process `pid` runs (Linux: its `/proc` entry; elsewhere assumed running).
fn process_runs(pid: u32) -> bool {
    if cfg!(target_os = "linux") {
        Path::new("/proc").join(pid.to_string()).exists()
    } else {
        true
    }
}

/// Longest series name accepted, in bytes: with `_contacts_00000.vtu` and the temporary file's
/// affixes the file names stay within the 255 bytes most file systems allow.
pub const MAX_SERIES_NAME_BYTES: usize = 200;

/// Checks that `name` can prefix the file names of a [`Series`] on any common file system,
/// inside the series folder: not empty, not `.` or `..`, at most [`MAX_SERIES_NAME_BYTES`]
/// bytes, and none of the path separators `/` and `\`, control characters (NUL, line breaks,
/// tabs, ...) or the characters `< > : " | ? *` that Windows refuses.
///
/// ```
/// use voussoir::io::vtk::check_series_name;
/// assert!(check_series_name("wall & arch").is_ok());
/// assert!(check_series_name("../outside").is_err());
/// ```
///
/// # Errors
/// [`Error::InvalidName`] naming the name and the offending character.
pub fn check_series_name(name: &str) -> Result<()> {
    let reject = |reason: String| {
        Err(Error::InvalidName {
            what: "series name",
            name: name.to_owned(),
            reason,
        })
    };
    if name.is_empty() {
        return reject("is empty".into());
    }
    if name == "." || name == ".." {
        return reject("is a relative folder name, not a file name".into());
    }
    if name.len() > MAX_SERIES_NAME_BYTES {
        return reject(format!(
            "is {} bytes long, more than the {MAX_SERIES_NAME_BYTES} bytes a file name leaves for it",
            name.len()
        ));
    }
    if let Some(c) = name.chars().find(|c| matches!(c, '/' | '\\')) {
        return reject(format!(
            "contains the path separator {c:?}: files would be written outside the folder"
        ));
    }
    if let Some(c) = name.chars().find(|c| c.is_control()) {
        return reject(format!("contains the control character U+{:04X}", u32::from(c)));
    }
    if let Some(c) = name
        .chars()
        .find(|c| matches!(c, '<' | '>' | ':' | '"' | '|' | '?' | '*'))
    {
        return reject(format!("contains {c:?}, which Windows does not allow in file names"));
    }
    Ok(())
}

/// Escapes text for an XML attribute value or element content.
fn xml_escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c => out.push(c),
        }
    }
    out
}

impl Series {
    /// A new, empty series written into `dir`. The name is checked by the first
    /// [`Series::write_frame`]; [`Series::try_new`] checks it at once.
    pub fn new(dir: impl Into<PathBuf>, name: &str) -> Self {
        Self {
            dir: dir.into(),
            name: name.to_owned(),
            frames: Vec::new(),
            subcontacts_every: 1,
            from_first_frame: false,
            origin: 0.0,
            lock: None,
            id: SERIES.fetch_add(1, std::sync::atomic::Ordering::Relaxed),
        }
    }

    /// Takes the series' lock file in its folder (see [`Series`]).
    fn take_lock(&mut self) -> Result<()> {
        std::fs::create_dir_all(&self.dir).map_err(|e| io_error(&self.dir, &e))?;
        let lock = self.dir.join(format!(".{}.lock", self.name));
        let me = format!("{} {}\n", std::process::id(), self.id);
        for _ in 0..2 {
            match std::fs::OpenOptions::new().write(true).create_new(true).open(&lock) {
                Ok(mut f) => {
                    use std::io::Write;
                    f.write_all(me.as_bytes()).map_err(|e| io_error(&lock, &e))?;
                    self.lock = Some(lock);
                    return Ok(());
                }
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                    let held = std::fs::read_to_string(&lock).unwrap_or_default();
                    let pid = held.split_whitespace().next().and_then(|p| p.parse::<u32>().ok());
                    match pid {
                        Some(pid) if pid == std::process::id() || process_runs(pid) => {
                            return Err(Error::Io {
                                path: lock.display().to_string(),
                                message: format!(
                                    "series {:?} in this folder is being written by another series (process {pid}): \
                                     write into another folder or under another name (remove this file if no \
                                     process writes the series)",
                                    self.name
                                ),
                            });
                        }
                        // A lock left by a process that ended (or unreadable): taken over.
                        _ => {
                            let _ = std::fs::remove_file(&lock);
                        }
                    }
                }
                Err(e) => return Err(io_error(&lock, &e)),
            }
        }
        Err(Error::Io {
            path: lock.display().to_string(),
            message: "could not take the series' lock file".into(),
        })
    }

    /// The earlier frames' files must still be there.
    fn check_frames(&self) -> Result<()> {
        for (_, b, c) in &self.frames {
            for file in std::iter::once(b).chain(c) {
                let path = self.dir.join(file);
                if !path.is_file() {
                    return Err(Error::Io {
                        path: path.display().to_string(),
                        message: "a frame this series wrote is gone (the folder was deleted or emptied \
                                  mid-run): its collection would list a missing file; start a new series"
                            .into(),
                    });
                }
            }
        }
        Ok(())
    }

    /// The same series writing its sub-contacts on every `every`-th frame only (the first,
    /// then every `every`-th; `every` is at least 1), its blocks on every frame: sub-contact
    /// files are the large ones (a 14-joint arch's are 35 times its blocks'), so a smooth
    /// animation of the blocks need not cost as many of them. The sub-contacts' `.pvd`
    /// collection lists the frames that have them.
    ///
    /// ```
    /// let series = voussoir::io::vtk::Series::new("out/demo", "wall").with_subcontacts_every(5);
    /// assert!(series.is_empty());
    /// ```
    #[must_use]
    pub fn with_subcontacts_every(mut self, every: usize) -> Self {
        self.subcontacts_every = every.max(1);
        self
    }

    /// The same series with the times of its `.pvd` collections counted from its first frame
    /// (a drop from its release, a push from its start) instead of the model's time, which
    /// includes the settling before.
    #[must_use]
    pub fn with_time_from_first_frame(mut self) -> Self {
        self.from_first_frame = true;
        self
    }

    /// A new, empty series written into `dir`, its name checked by [`check_series_name`].
    ///
    /// # Errors
    /// [`Error::InvalidName`] naming the name and what is wrong with it.
    pub fn try_new(dir: impl Into<PathBuf>, name: &str) -> Result<Self> {
        check_series_name(name)?;
        Ok(Self::new(dir, name))
    }

    /// Writes the model's blocks and sub-contacts as the next frame, at the model's time (the
    /// sub-contacts only on the frames [`Series::with_subcontacts_every`] asks for).
    ///
    /// # Errors
    /// [`Error::InvalidName`] (nothing written) if the series name is not a portable file name
    /// (see [`check_series_name`]); [`crate::Error::Io`] naming the file, the lock file held by
    /// another series, or an earlier frame's file that is gone.
    pub fn write_frame<L: ConstitutiveLaw>(&mut self, model: &Model<L>) -> Result<()> {
        check_series_name(&self.name)?;
        if self.lock.is_none() {
            self.take_lock()?;
        }
        self.check_frames()?;
        let k = self.frames.len();
        let blocks = format!("{}_blocks_{k:05}.vtu", self.name);
        let contacts = k
            .is_multiple_of(self.subcontacts_every)
            .then(|| format!("{}_contacts_{k:05}.vtu", self.name));
        let initial = |i: usize| *model.blocks()[i].initial_pose();
        write_block_surfaces(&self.dir.join(&blocks), model.blocks(), initial)?;
        if let Some(contacts) = &contacts {
            write_subcontacts(&self.dir.join(contacts), model)?;
        }
        if self.frames.is_empty() {
            self.origin = model.time();
        }
        let time = if self.from_first_frame {
            model.time() - self.origin
        } else {
            model.time()
        };
        self.frames.push((time, blocks, contacts));
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
                let Some(file) = (if pick == 0 { Some(b) } else { c.as_ref() }) else {
                    continue;
                };
                let file = xml_escape(file);
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
