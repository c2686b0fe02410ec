//! A run in one self-contained HTML file: the blocks in 3-D played over time, coloured by a
//! field, the contact polygons and forces on demand, and curves beside them. The file needs no
//! network and no plug-in to open (the renderer, a small canvas painter of this crate, is
//! inside it), so it can be mailed, attached to a report or shown inline in Jupyter
//! (`voussoir.Viewer` in Python).
//!
//! ```no_run
//! # use voussoir::Model;
//! # fn run(model: &mut Model) -> voussoir::Result<()> {
//! use voussoir::io::viewer::Viewer;
//! let mut viewer = Viewer::new("settling wall");
//! for _ in 0..50 {
//!     model.run_steps(200)?;
//!     viewer.record(model)?; // a frame: poses, fields, contacts, curves
//! }
//! viewer.write("out/wall.html".as_ref())?;
//! # Ok(()) }
//! ```
//!
//! Each frame keeps every block's pose (7 floats), its displacement, velocity and rotation
//! magnitudes and, unless [`Viewer::without_contacts`], each contact's polygon, resultant and
//! the centre of its normal forces, in single precision: about 40 bytes per block and frame,
//! plus about 100 per contact. The block shapes are stored once.

use std::path::Path;

use base64::Engine as _;
use serde::Serialize;

use crate::block::Block;
use crate::error::Error;
use crate::law::ConstitutiveLaw;
use crate::math::Real;
use crate::monitor::{EnergyTerm, Monitor};
use crate::{Model, Result};

/// The page: HTML, style and the renderer; the data goes where `/*VOUSSOIR_DATA*/` stands.
const TEMPLATE: &str = include_str!("viewer.html");
/// The mark in [`TEMPLATE`] that the data replaces.
const DATA_MARK: &str = "/*VOUSSOIR_DATA*/";

/// Records frames of a model and writes them as one HTML page (see the [module](self)).
#[derive(Debug, Clone)]
pub struct Viewer {
    title: String,
    contacts: bool,
    from_first_frame: bool,
    /// The model's time at the first frame.
    origin: Real,
    /// The block shapes, from the first frame.
    shapes: Option<Shapes>,
    frames: Vec<Frame>,
    /// Monitors sampled at every frame: name, unit, monitor, one value per frame.
    monitors: Vec<(String, &'static str, Monitor, Vec<f64>)>,
    curves: Vec<Curve>,
}

/// The blocks' shapes in their body frames, flattened (block `i`'s vertices are
/// `vertex_offset[i]..vertex_offset[i + 1]`, its faces `face_offset[i]..`, face `f`'s loop of
/// block-local vertex indices `loops[loop_offset[f]..loop_offset[f + 1]]`).
#[derive(Debug, Clone, PartialEq)]
struct Shapes {
    vertices: Vec<f32>,
    vertex_offset: Vec<u32>,
    face_offset: Vec<u32>,
    loop_offset: Vec<u32>,
    loops: Vec<u32>,
    fixed: Vec<u8>,
    up: [f64; 3],
}

#[derive(Debug, Clone)]
struct Frame {
    time: Real,
    step: u64,
    /// Kinetic energy of the blocks (J).
    kinetic: Real,
    /// Per block: x, y, z, then the rotation's quaternion x, y, z, w.
    pose: Vec<f32>,
    displacement: Vec<f32>,
    velocity: Vec<f32>,
    rotation: Vec<f32>,
    contacts: Option<Contacts>,
}

#[derive(Debug, Clone, Default)]
struct Contacts {
    /// Per contact: the centre of its normal forces (the polygon's centroid without any).
    point: Vec<f32>,
    /// Per contact: the resultant on its second block (N).
    force: Vec<f32>,
    polygon_offset: Vec<u32>,
    polygon: Vec<f32>,
}

/// A curve beside the blocks.
#[derive(Debug, Clone, Serialize)]
struct Curve {
    name: String,
    x_label: String,
    y_label: String,
    /// Whether `x` is time on the frames' clock (the page then marks the shown frame on it).
    time_axis: bool,
    x: Vec<f64>,
    y: Vec<f64>,
}

fn b64<T: Copy>(values: &[T], bytes: impl Fn(T) -> [u8; 4]) -> String {
    let raw: Vec<u8> = values.iter().flat_map(|&v| bytes(v)).collect();
    base64::engine::general_purpose::STANDARD.encode(raw)
}
fn f32s(values: &[f32]) -> String {
    b64(values, f32::to_le_bytes)
}
fn u32s(values: &[u32]) -> String {
    b64(values, u32::to_le_bytes)
}

/// A finite number as JSON, or `null` (a NaN of a monitor added late).
fn json_number(v: f64) -> serde_json::Value {
    serde_json::Number::from_f64(v).map_or(serde_json::Value::Null, serde_json::Value::Number)
}

fn index(n: usize, what: &str) -> Result<u32> {
    u32::try_from(n).map_err(|_| Error::Unsupported {
        what: format!("a viewer of more than 2^32 {what}"),
    })
}

impl Viewer {
    /// An empty viewer titled `title`, recording contacts, with the model's times.
    pub fn new(title: &str) -> Self {
        Self {
            title: title.to_owned(),
            contacts: true,
            from_first_frame: false,
            origin: 0.0,
            shapes: None,
            frames: Vec::new(),
            monitors: Vec::new(),
            curves: Vec::new(),
        }
    }

    /// The same viewer recording no contacts (for large models: a 10,000-block wall has about
    /// 20,000 contacts, 2 MB a frame).
    #[must_use]
    pub fn without_contacts(mut self) -> Self {
        self.contacts = false;
        self
    }

    /// The same viewer with its times counted from its first frame (a drop from its release)
    /// instead of the model's time, as [`super::vtk::Series::with_time_from_first_frame`].
    #[must_use]
    pub fn with_time_from_first_frame(mut self) -> Self {
        self.from_first_frame = true;
        self
    }

    /// Samples `monitor` at every frame and shows it as a curve against time, named `name`
    /// (with its unit). Frames recorded before have no value (a gap in the curve).
    ///
    /// # Errors
    /// [`Error::InvalidName`] if a monitor or curve of this name exists already.
    pub fn add_monitor(&mut self, name: &str, monitor: Monitor) -> Result<()> {
        self.check_new_name(name)?;
        let values = vec![f64::NAN; self.frames.len()];
        self.monitors.push((name.to_owned(), monitor.unit(), monitor, values));
        Ok(())
    }

    /// Whether a monitor named `name` is sampled.
    pub fn has_monitor(&self, name: &str) -> bool {
        self.monitors.iter().any(|m| m.0 == name)
    }

    /// Adds a curve of given points beside the blocks (a load–displacement curve, a
    /// history). With `time_axis`, `x` is time on the frames' clock, and the page marks the
    /// frame shown on it.
    ///
    /// # Errors
    /// [`Error::InvalidName`] if a monitor or curve of this name exists already;
    /// [`Error::Unsupported`] if `x` and `y` differ in length.
    pub fn add_curve(
        &mut self,
        name: &str,
        (x_label, y_label): (&str, &str),
        x: &[f64],
        y: &[f64],
        time_axis: bool,
    ) -> Result<()> {
        self.check_new_name(name)?;
        if x.len() != y.len() {
            return Err(Error::Unsupported {
                what: format!("curve {name:?} with {} x values and {} y values", x.len(), y.len()),
            });
        }
        self.curves.push(Curve {
            name: name.to_owned(),
            x_label: x_label.to_owned(),
            y_label: y_label.to_owned(),
            time_axis,
            x: x.to_vec(),
            y: y.to_vec(),
        });
        Ok(())
    }

    fn check_new_name(&self, name: &str) -> Result<()> {
        let built_in = ["kinetic energy", "largest displacement"];
        if built_in.contains(&name) || self.has_monitor(name) || self.curves.iter().any(|c| c.name == name) {
            return Err(Error::InvalidName {
                what: "viewer curve",
                name: name.to_owned(),
                reason: "is taken by another curve of this viewer".into(),
            });
        }
        Ok(())
    }

    /// Number of frames recorded.
    pub fn len(&self) -> usize {
        self.frames.len()
    }

    /// `true` before the first frame.
    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }

    /// The frames' times (s), on the viewer's clock.
    pub fn times(&self) -> Vec<Real> {
        self.frames.iter().map(|f| f.time).collect()
    }

    /// Records the model's current state as the next frame.
    ///
    /// # Errors
    /// [`Error::Unsupported`] if the model's blocks are not those of the first frame (another
    /// model, or blocks added since), or for more than 2^32 vertices.
    pub fn record<L: ConstitutiveLaw>(&mut self, model: &Model<L>) -> Result<()> {
        let blocks = model.blocks();
        match &self.shapes {
            None => {
                self.shapes = Some(Shapes::of(model)?);
                self.origin = model.time();
            }
            Some(shapes) if shapes.fixed.len() != blocks.len() => {
                return Err(Error::Unsupported {
                    what: format!(
                        "a viewer frame of {} blocks after frames of {} (one viewer shows one model)",
                        blocks.len(),
                        shapes.fixed.len()
                    ),
                })
            }
            Some(shapes) => {
                if let Some(i) = shapes.first_other_shape(blocks) {
                    return Err(Error::Unsupported {
                        what: format!(
                            "a viewer frame whose block {i} ({:?}) has another shape than in the first frames \
                             (one viewer shows one model)",
                            blocks[i].name()
                        ),
                    });
                }
            }
        }
        let n = blocks.len();
        let mut frame = Frame {
            time: if self.from_first_frame {
                model.time() - self.origin
            } else {
                model.time()
            },
            step: model.step_count(),
            kinetic: Monitor::Energy(EnergyTerm::Kinetic).evaluate(model),
            pose: Vec::with_capacity(7 * n),
            displacement: Vec::with_capacity(n),
            velocity: Vec::with_capacity(n),
            rotation: Vec::with_capacity(n),
            contacts: None,
        };
        for b in blocks {
            let s = b.state();
            let (t, q) = (s.pose.translation, s.pose.rotation);
            frame.pose.extend([t.x, t.y, t.z, q.x, q.y, q.z, q.w].map(|v| v as f32));
            let p0 = b.initial_pose();
            frame.displacement.push((t - p0.translation).length() as f32);
            frame.velocity.push(s.velocity.length() as f32);
            let turned = (q * p0.rotation.inverse()).to_scaled_axis().length();
            frame.rotation.push(turned.to_degrees() as f32);
        }
        if self.contacts {
            let mut c = Contacts {
                polygon_offset: vec![0],
                ..Contacts::default()
            };
            for view in model.contacts() {
                let polygon = model.contact_polygon(&view);
                let centre = view.application_point().unwrap_or_else(|| {
                    polygon.iter().copied().sum::<crate::math::Vector>() / polygon.len().max(1) as f64
                });
                c.point.extend(centre.to_array().map(|v| v as f32));
                c.force.extend(view.resultant().to_array().map(|v| v as f32));
                for p in &polygon {
                    c.polygon.extend(p.to_array().map(|v| v as f32));
                }
                c.polygon_offset
                    .push(index(c.polygon.len() / 3, "contact polygon corners")?);
            }
            frame.contacts = Some(c);
        }
        for (_, _, monitor, values) in &mut self.monitors {
            values.push(monitor.evaluate(model));
        }
        self.frames.push(frame);
        Ok(())
    }

    /// The page, as a string.
    ///
    /// # Errors
    /// [`Error::Unsupported`] before the first frame (there is nothing to show).
    pub fn to_html(&self) -> Result<String> {
        let (Some(shapes), false) = (&self.shapes, self.frames.is_empty()) else {
            return Err(Error::Unsupported {
                what: "a viewer page without frames (record a frame first)".into(),
            });
        };
        let frames: Vec<serde_json::Value> = self
            .frames
            .iter()
            .map(|f| {
                let mut v = serde_json::json!({
                    "time": f.time,
                    "step": f.step,
                    "pose": f32s(&f.pose),
                    "fields": {
                        "displacement": f32s(&f.displacement),
                        "velocity": f32s(&f.velocity),
                        "rotation": f32s(&f.rotation),
                    },
                });
                if let Some(c) = &f.contacts {
                    v["contacts"] = serde_json::json!({
                        "count": c.polygon_offset.len() - 1,
                        "point": f32s(&c.point),
                        "force": f32s(&c.force),
                        "polygon_offset": u32s(&c.polygon_offset),
                        "polygon": f32s(&c.polygon),
                    });
                }
                v
            })
            .collect();
        let times: Vec<f64> = self.times();
        let mut curves: Vec<serde_json::Value> = Vec::new();
        let mut built_in = |name: &str, y_label: &str, y: Vec<f64>| {
            curves.push(serde_json::json!({
                "name": name, "x_label": "time (s)", "y_label": y_label, "time_axis": true,
                "x": times, "y": y,
            }));
        };
        let largest = |f: &Frame| f.displacement.iter().fold(0.0f64, |m, &d| m.max(f64::from(d)));
        built_in("largest displacement", "m", self.frames.iter().map(largest).collect());
        built_in("kinetic energy", "J", self.frames.iter().map(|f| f.kinetic).collect());
        for (name, unit, _, values) in &self.monitors {
            let y: Vec<serde_json::Value> = values.iter().map(|&v| json_number(v)).collect();
            curves.push(serde_json::json!({
                "name": name, "x_label": "time (s)", "y_label": unit, "time_axis": true,
                "x": times, "y": y,
            }));
        }
        for c in &self.curves {
            let mut v = serde_json::to_value(c).map_err(|e| Error::Unsupported { what: e.to_string() })?;
            v["x"] = c.x.iter().map(|&x| json_number(x)).collect();
            v["y"] = c.y.iter().map(|&y| json_number(y)).collect();
            curves.push(v);
        }
        let data = serde_json::json!({
            "format": "voussoir-viewer 1",
            "title": self.title,
            "up": shapes.up,
            "blocks": {
                "count": shapes.fixed.len(),
                "vertices": f32s(&shapes.vertices),
                "vertex_offset": u32s(&shapes.vertex_offset),
                "face_offset": u32s(&shapes.face_offset),
                "loop_offset": u32s(&shapes.loop_offset),
                "loops": u32s(&shapes.loops),
                "fixed": base64::engine::general_purpose::STANDARD.encode(&shapes.fixed),
            },
            "fields": [
                {"name": "displacement", "label": "displacement (m)"},
                {"name": "velocity", "label": "speed (m/s)"},
                {"name": "rotation", "label": "rotation (°)"},
            ],
            "frames": frames,
            "curves": curves,
        });
        // Inside <script>, "</" would end the element and "<!--" start an escaped section that
        // swallows the rest of the page: every "<" (only ever inside a JSON string) is written
        // as the escape "\u003c", the same character to the parser.
        let json = data.to_string().replace('<', "\\u003c");
        let mut title = String::new();
        for c in self.title.chars() {
            match c {
                '&' => title.push_str("&amp;"),
                '<' => title.push_str("&lt;"),
                '>' => title.push_str("&gt;"),
                c => title.push(c),
            }
        }
        let page = TEMPLATE.replacen(
            "<title>voussoir</title>",
            &format!("<title>{title} — voussoir</title>"),
            1,
        );
        Ok(page.replacen(DATA_MARK, &json, 1))
    }

    /// Writes the page to `path` (a `.html` file), atomically, creating the folder.
    ///
    /// # Errors
    /// [`Error::Unsupported`] before the first frame; [`Error::Io`] naming the file.
    pub fn write(&self, path: &Path) -> Result<()> {
        let page = self.to_html()?;
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|e| Error::Io {
                path: dir.display().to_string(),
                message: e.to_string(),
            })?;
        }
        crate::file::write_atomically(path, page.as_bytes())
    }
}

impl Shapes {
    /// The first of `blocks` (as many as recorded) whose body-frame vertices are not those
    /// recorded: a frame of another model.
    fn first_other_shape(&self, blocks: &[crate::block::RigidBlock]) -> Option<usize> {
        blocks.iter().enumerate().position(|(i, b)| {
            let (start, end) = (
                3 * self.vertex_offset[i] as usize,
                3 * self.vertex_offset[i + 1] as usize,
            );
            let stored = &self.vertices[start..end];
            let vertices = b.shape().vertices();
            vertices.len() * 3 != stored.len()
                || vertices
                    .iter()
                    .zip(stored.chunks_exact(3))
                    .any(|(v, s)| v.to_array().map(|x| (x as f32).to_bits()) != [s[0], s[1], s[2]].map(f32::to_bits))
        })
    }

    fn of<L: ConstitutiveLaw>(model: &Model<L>) -> Result<Self> {
        let blocks = model.blocks();
        let mut s = Self {
            vertices: Vec::new(),
            vertex_offset: vec![0],
            face_offset: vec![0],
            loop_offset: vec![0],
            loops: Vec::new(),
            fixed: Vec::with_capacity(blocks.len()),
            up: [0.0, 0.0, 1.0],
        };
        for b in blocks {
            let shape = b.shape();
            for v in shape.vertices() {
                s.vertices.extend(v.to_array().map(|x| x as f32));
            }
            s.vertex_offset.push(index(s.vertices.len() / 3, "vertices")?);
            for f in 0..shape.faces().len() {
                s.loops.extend(shape.face_loop(f));
                s.loop_offset.push(index(s.loops.len(), "face corners")?);
            }
            s.face_offset.push(index(s.loop_offset.len() - 1, "faces")?);
            let fixity = b.fixity();
            let all = fixity
                .translation
                .iter()
                .chain(&fixity.rotation)
                .all(|d| d.prescribed().is_some());
            s.fixed.push(u8::from(all));
        }
        let g = model.parameters().gravity;
        if g.length() > 0.0 {
            s.up = (-g.normalize()).to_array();
        }
        Ok(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_of_floats_is_little_endian() {
        assert_eq!(f32s(&[1.0]), "AACAPw==");
        assert_eq!(u32s(&[1, 2]), "AQAAAAIAAAA=");
    }
}
