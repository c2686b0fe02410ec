//! Scene files: a model's definition (blocks, materials, joint laws, fixities, loads, damping,
//! monitors, parameters) as JSON, validated on load with the path of the first bad field.
//!
//! The format is documented in `docs/scene-format.md`.

use std::path::Path;

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

use crate::block::{Block, BlockId, Fixity, RigidBlock, Wrench};
use crate::error::{Error, Result};
use crate::integrate::Damping;
use crate::law::{ConstitutiveLaw, MaterialId};
use crate::math::Vector;
use crate::model::{Model, ModelParameters};
use crate::monitor::{Monitor, Recorder};

/// A block as written in a scene: world vertices (convex hull) or vertices and faces.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BlockSpec {
    /// Name used in messages and outputs.
    pub name: String,
    /// Vertices in world coordinates (m).
    pub vertices: Vec<Vector>,
    /// Optional explicit faces (vertex index loops, counter-clockwise seen from outside); the
    /// convex hull of the vertices otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub faces: Option<Vec<Vec<usize>>>,
    /// Density (kg/m³).
    pub density: f64,
    /// Material id (selects joint laws).
    #[serde(default)]
    pub material: MaterialId,
    /// Fixity; free when omitted.
    #[serde(default)]
    pub fixity: Fixity,
    /// Initial velocity (m/s).
    #[serde(default)]
    pub velocity: Vector,
    /// Initial angular velocity (rad/s).
    #[serde(default)]
    pub angular_velocity: Vector,
    /// Constant applied load (force and moment about the centroid).
    #[serde(default)]
    pub load: Wrench,
    /// Base motion of the block's translations from time 0 (a shaking table), see
    /// [`Model::set_base_motion`]: `{"kind": "Acceleration", "axes": [{"times": [..], "values":
    /// [..]}, null, null]}`; the driven axes must be fixed or prescribed in `fixity`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motion: Option<crate::signal::BaseMotion>,
    /// Time-varying load from time 0, replacing `load` (see [`Model::set_load_history`]):
    /// `{"load": {"force": [..], "moment": [..]}, "history": {"times": [..], "values": [..]}}`,
    /// the wrench scaled by the history's factor.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub load_history: Option<crate::signal::LoadHistory>,
}

/// The joint law between two materials.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointSpec<L> {
    /// The two materials (either order).
    pub materials: [MaterialId; 2],
    /// The law and its parameters.
    pub law: L,
}

/// The joint law of one interface: the joint between two blocks, whatever their materials.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InterfaceSpec<L> {
    /// The two blocks (indices into `blocks`, either order).
    pub blocks: [BlockId; 2],
    /// The law and its parameters.
    pub law: L,
}

/// A named monitor.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MonitorSpec {
    /// Column name.
    pub name: String,
    /// What is monitored.
    pub monitor: Monitor,
}

/// A model's definition, without its run state (see [`Model::to_checkpoint_string`] for that).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene<L> {
    /// Global parameters; defaults for omitted fields.
    #[serde(default)]
    pub parameters: ModelParameters,
    /// Damping; local 0.8 when omitted.
    #[serde(default)]
    pub damping: Damping,
    /// Joint laws per pair of materials.
    pub joints: Vec<JointSpec<L>>,
    /// Joint laws of single interfaces (pairs of blocks), which take precedence over their
    /// materials'; optional.
    #[serde(default = "Vec::new", skip_serializing_if = "Vec::is_empty")]
    pub interfaces: Vec<InterfaceSpec<L>>,
    /// The blocks, in id order.
    pub blocks: Vec<BlockSpec>,
    /// Monitors.
    #[serde(default)]
    pub monitors: Vec<MonitorSpec>,
    /// Sample the monitors every this many steps (default 1; 0 is refused on load).
    #[serde(default = "one")]
    pub monitor_interval: u64,
}

fn one() -> u64 {
    1
}

/// The fields of a scene file, for messages.
const SCENE_FIELDS: &str = "with the fields \"joints\" and \"blocks\" (required) and \"parameters\", \
                            \"damping\", \"interfaces\", \"monitors\", \"monitor_interval\" (optional)";

/// serde's message for a struct given as an array (`invalid length 2, expected struct
/// BlockSpec with 5 elements`) rephrased: the value must be a JSON object with named fields.
fn struct_as_array_message(message: &str) -> String {
    match message.split_once("expected struct ") {
        Some((head, tail)) if head.starts_with("invalid length") && tail.contains(" elements") => {
            let name = tail.split_whitespace().next().unwrap_or("value");
            format!("must be a JSON object {{ ... }} with named fields ({name}), not an array ({message})")
        }
        _ => message.to_owned(),
    }
}

impl<L: ConstitutiveLaw + Serialize + DeserializeOwned> Scene<L> {
    /// Parses a scene from JSON text: a JSON object with the fields `joints` and `blocks`
    /// (required) and `parameters`, `damping`, `interfaces`, `monitors`, `monitor_interval` (optional), see
    /// `docs/scene-format.md`. Syntax and type errors name the path of the field; a file that is
    /// not a JSON object (`[]`, a number, nothing) says so.
    ///
    /// # Errors
    /// [`Error::Checkpoint`] with the path (for example `blocks[2].density`).
    pub fn from_json(text: &str) -> Result<Self> {
        // A byte-order mark, as some editors write, is not part of the JSON.
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        // serde accepts a struct written as an array of its fields in order, so `[]` or
        // `[1, 2]` got "invalid length 2, expected struct Scene with 6 elements": say what a scene
        // file is instead.
        let found = match text.trim_start().chars().next() {
            None => Some("nothing (the file is empty)"),
            Some('{') => None,
            Some('[') => Some("an array"),
            Some('"') => Some("a string"),
            Some('t' | 'f') => Some("a boolean"),
            Some('n') => Some("null"),
            Some(c) if c == '-' || c.is_ascii_digit() => Some("a number"),
            Some(_) => None, // not JSON: serde's syntax error says where
        };
        if let Some(found) = found {
            return Err(Error::Checkpoint {
                path: "(the whole file)".into(),
                message: format!("a scene file must be a JSON object {{ ... }} {SCENE_FIELDS}; found {found}"),
            });
        }
        // serde's derived objects refuse a field given twice; this says so for every object
        // (a map would keep the last value) with the same message.
        crate::json_keys::refuse_duplicate_keys(text)?;
        let de = &mut serde_json::Deserializer::from_str(text);
        let scene: Self = serde_path_to_error::deserialize(de).map_err(|e| Error::Checkpoint {
            path: e.path().to_string(),
            message: struct_as_array_message(&e.inner().to_string()),
        })?;
        if scene.monitor_interval == 0 {
            return Err(Error::Checkpoint {
                path: "monitor_interval".into(),
                message: "0: the monitors are sampled every this many steps, at least 1".into(),
            });
        }
        Ok(scene)
    }

    /// Reads a scene file.
    ///
    /// # Errors
    /// [`Error::Io`] naming the file; otherwise as [`Scene::from_json`].
    pub fn load(path: &Path) -> Result<Self> {
        let text = crate::file::read_text(path)?;
        Self::from_json(&text)
    }

    /// Pretty JSON text.
    ///
    /// # Errors
    /// [`Error::Io`] if serialisation fails.
    pub fn to_json(&self) -> Result<String> {
        serde_json::to_string_pretty(self).map_err(|e| Error::Io {
            path: "(scene)".into(),
            message: e.to_string(),
        })
    }

    /// Writes the scene as pretty JSON.
    ///
    /// # Errors
    /// [`Error::Io`] naming the file.
    pub fn save(&self, path: &Path) -> Result<()> {
        let text = self.to_json()?;
        crate::file::write_atomically(path, text.as_bytes())
    }

    /// The definition of a model in its current pose (velocities and loads included), without
    /// monitors (see [`Scene::with_recorder`]).
    pub fn from_model(model: &Model<L>) -> Self {
        let blocks = model
            .blocks()
            .iter()
            .enumerate()
            .map(|(i, b)| {
                let s = b.state();
                BlockSpec {
                    name: b.name().to_owned(),
                    vertices: b
                        .shape()
                        .vertices()
                        .iter()
                        .map(|v| s.pose.transform_point(*v))
                        .collect(),
                    faces: Some(
                        (0..b.shape().faces().len())
                            .map(|f| b.shape().face_loop(f).iter().map(|&i| i as usize).collect())
                            .collect(),
                    ),
                    density: b.density(),
                    material: b.material(),
                    fixity: *b.fixity(),
                    velocity: s.velocity,
                    angular_velocity: s.angular_velocity,
                    load: b.load(),
                    // A scene starts at time 0: the motion from the start of its history.
                    motion: model.base_motions().find(|m| m.0.index() == i).map(|m| m.1.clone()),
                    load_history: model.load_histories().find(|h| h.0.index() == i).map(|h| h.1.clone()),
                }
            })
            .collect();
        Self {
            parameters: *model.parameters(),
            damping: model.damping(),
            joints: model
                .law_table()
                .entries()
                .map(|(a, b, law)| JointSpec {
                    materials: [a, b],
                    law: law.clone(),
                })
                .collect(),
            interfaces: model
                .law_table()
                .interface_entries()
                .map(|(a, b, law)| InterfaceSpec {
                    blocks: [a, b],
                    law: law.clone(),
                })
                .collect(),
            blocks,
            monitors: Vec::new(),
            monitor_interval: 1,
        }
    }

    /// This scene with the built-in monitors of `recorder` and its interval (probes of one's
    /// own cannot be written to a file and are left out).
    pub fn with_recorder(mut self, recorder: &Recorder<L>) -> Self {
        self.monitors = recorder
            .monitors()
            .map(|(name, m)| MonitorSpec {
                name: name.to_owned(),
                monitor: *m,
            })
            .collect();
        self.monitor_interval = recorder.interval();
        self
    }

    /// A recorder of the scene's monitors for `model` (built by [`Scene::build`]).
    ///
    /// # Errors
    /// [`Error::Checkpoint`] with the path (`monitors[k]`) of a monitor naming a missing block.
    pub fn recorder(&self, model: &Model<L>) -> Result<Recorder<L>> {
        let mut recorder = Recorder::new(self.monitor_interval);
        for (k, m) in self.monitors.iter().enumerate() {
            recorder
                .add_monitor(model, &m.name, m.monitor)
                .map_err(|e| Error::Checkpoint {
                    path: format!("monitors[{k}]"),
                    message: e.to_string(),
                })?;
        }
        Ok(recorder)
    }

    /// Builds the model, validating everything but the monitors (see [`Scene::recorder`]);
    /// errors name the path of the bad entry.
    ///
    /// # Errors
    /// [`Error::Checkpoint`] with the path (for example `blocks[3]`) and the underlying error.
    pub fn build(&self) -> Result<Model<L>> {
        let at = |path: String| {
            move |e: Error| Error::Checkpoint {
                path,
                message: e.to_string(),
            }
        };
        let mut model = Model::new(self.parameters).map_err(at("parameters".into()))?;
        model.set_damping(self.damping).map_err(at("damping".into()))?;
        for (k, j) in self.joints.iter().enumerate() {
            let pair = (j.materials[0].min(j.materials[1]), j.materials[0].max(j.materials[1]));
            if let Some(first) = self.joints[..k]
                .iter()
                .position(|o| (o.materials[0].min(o.materials[1]), o.materials[0].max(o.materials[1])) == pair)
            {
                return Err(Error::Checkpoint {
                    path: format!("joints[{k}].materials"),
                    message: format!(
                        "the pair of materials {} and {} already has a law at joints[{first}]",
                        pair.0, pair.1
                    ),
                });
            }
            model
                .set_joint_law(j.materials[0], j.materials[1], j.law.clone())
                .map_err(at(format!("joints[{k}].law")))?;
        }
        for (i, b) in self.blocks.iter().enumerate() {
            let path = format!("blocks[{i}]");
            let block = match &b.faces {
                Some(faces) => RigidBlock::from_faces(&b.name, &b.vertices, faces, b.density),
                None => RigidBlock::from_vertices(&b.name, &b.vertices, b.density),
            }
            .map_err(at(path.clone()))?;
            let block = block
                .with_material(b.material)
                .with_fixity(b.fixity)
                .with_velocity(b.velocity, b.angular_velocity);
            let id = model.add_block(block).map_err(at(path.clone()))?;
            model.set_load(id, b.load).map_err(at(path.clone()))?;
            if let Some(motion) = &b.motion {
                model
                    .set_base_motion(id, Some(motion.clone()))
                    .map_err(at(format!("{path}.motion")))?;
            }
            if let Some(load) = &b.load_history {
                model
                    .set_load_history(id, Some(load.clone()))
                    .map_err(at(format!("{path}.load_history")))?;
            }
        }
        for (k, j) in self.interfaces.iter().enumerate() {
            let pair = (j.blocks[0].min(j.blocks[1]), j.blocks[0].max(j.blocks[1]));
            if let Some(first) = self.interfaces[..k]
                .iter()
                .position(|o| (o.blocks[0].min(o.blocks[1]), o.blocks[0].max(o.blocks[1])) == pair)
            {
                return Err(Error::Checkpoint {
                    path: format!("interfaces[{k}].blocks"),
                    message: format!(
                        "the interface of blocks {} and {} already has a law at interfaces[{first}]",
                        pair.0 .0, pair.1 .0
                    ),
                });
            }
            model
                .set_interface_law(j.blocks[0], j.blocks[1], j.law.clone())
                .map_err(at(format!("interfaces[{k}]")))?;
        }
        Ok(model)
    }
}
