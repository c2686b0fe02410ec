//! Checkpoint and restart: the full state of a model (blocks, contacts, sub-contact history, law
//! state, energies) as JSON, restored so that the run continues bit-identically. Recorders are
//! the caller's: their [`crate::monitor::History`] serialises on its own (and is checked for
//! consistency as it is read).
//! Compiled with the `serde` feature.
//!
//! A checkpoint carries a checksum of its content and the name of its law type; loading one
//! checks everything it can against everything else (see
//! [`Model::from_checkpoint_str`](super::Model::from_checkpoint_str)), so that a corrupted or
//! edited file is refused with a typed error rather than run.
//!
//! This file holds the format (its version, the snapshot and the transfer records of contacts
//! and sub-contacts), the checksum and the law type's name; `write.rs` writes a checkpoint and
//! `read.rs` reads and checks one.

mod checks;
mod read;
mod tested;
mod write;

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

use super::ModelParameters;
use crate::block::{RigidBlock, Wrench};
use crate::contact::{AnchorPlane, ContactWrench};
use crate::error::{Error, Result};
use crate::geometry::{ContactKind, SubKey};
use crate::integrate::{CriticalStep, Damping};
use crate::law::{ConstitutiveLaw, LawTable};
use crate::law::{JointForce, JointStatus};
use crate::math::{Pose, Real, Rotation, Vector, Vector2};
use crate::model::Energies;
use tested::TestedEntry;

const FORMAT: &str = "voussoir-checkpoint";
/// Version 9 stores joints through [`ContactEntry`], apart from the step's storage layout, so
/// that a layout change no longer changes the format. Version 10 adds the checksum and the law
/// type; version 9 files (which have neither, so that corruption could not be told) are refused.
/// Version 11 adds the pairs the narrow phase tested, with their relative poses, on which
/// re-detection depends, and the blocks' stability bounds, which are re-evaluated block by block.
/// Version 12 has node contacts (`"Nodes"`) where 11 had point contacts (`"Point"`, with a
/// plane), and the refinement's travel cap (`refine_travel`).
/// Version 15 adds joints open in part (hinges) stepped as a whole but for a range of their
/// cells: the joint record's `span` and the joint's `hinge` (its cells' box, gap and room at
/// entry), absent (a joint closed or open all over) in the files of version 14, which this
/// build reads. Version 16 adds a hinge's open cells stepped as a whole: the joint record's
/// `ends` (`"closed"` in the files of version 15, which this build reads); the hinge record's
/// `closed_box` is no longer written, but measured from the cells when a file is read. A
/// joint record holding what its file's version did not have is refused.
const VERSION: u32 = 16;
/// The oldest version this build reads: 13 differs from 14 only in having no joints stepped
/// as a whole ([`JointEntry`]).
const OLDEST_VERSION: u32 = 13;
/// The checksum's field: `"crc32:"` and eight hexadecimal digits.
const CHECKSUM: &str = "checksum";
/// The largest step count (or detection count) a checkpoint may hold: 2⁵³, where `f64` stops
/// counting exactly; far beyond any run (years at a microsecond a step), far below where the
/// counter would overflow.
const MAX_COUNT: u64 = 1 << 53;
/// A stored stability bound below this fraction of the one the blocks and contacts give on
/// load is refused: it would allow a step the contacts cannot take.
const MIN_STORED_BOUND: Real = 0.8;

/// The fields every version has, read before the rest (other fields are skipped).
#[derive(Deserialize)]
struct Header {
    format: String,
    version: u32,
    #[serde(default)]
    law_type: Option<String>,
}

#[derive(Serialize, Deserialize)]
#[serde(bound(
    serialize = "L: Serialize, L::State: Serialize",
    deserialize = "L: DeserializeOwned, L::State: DeserializeOwned"
))]
struct Snapshot<L: ConstitutiveLaw> {
    format: String,
    version: u32,
    /// The law type's serde name ([`law_type_name`]), `None` when it has none.
    law_type: Option<String>,
    params: ModelParameters,
    damping: Damping,
    blocks: Vec<RigidBlock>,
    joints: LawTable<L>,
    /// The contacts, sorted by block pair, each with its sub-contacts.
    contacts: Vec<ContactEntry<L::State>>,
    ref_poses: Vec<Pose>,
    /// The pairs the narrow phase tested, sorted, with the relative pose of each at its test.
    tested: Vec<TestedEntry>,
    dt: Real,
    critical: Option<CriticalStep>,
    /// Each block's bound of its squared natural frequency (1/s²) as last evaluated: the
    /// critical step and the impact probe read them.
    bounds: Vec<Real>,
    step: u64,
    time: Real,
    energy: Energies,
    started: bool,
    unbalanced_ratio: Option<Real>,
    detections: u64,
    /// Last step's reaction and damping wrench per block: the energy bookkeeping books each of
    /// them half in the next step.
    #[serde(default)]
    last_forces: Vec<(Wrench, Wrench)>,
    /// A full re-detection (and step re-evaluation) requested by a change of laws, parameters,
    /// fixity or blocks before the save and not yet done.
    #[serde(default)]
    pending_detection: bool,
    /// The last step's duration and the impact refinement's state (absent: a constant step).
    #[serde(default)]
    drift: Real,
    #[serde(default)]
    refine_until: Real,
    #[serde(default)]
    refine_omega2: Real,
    /// Whether the refinement also caps the travel per step (a node contact asked for it).
    #[serde(default)]
    refine_travel: bool,
    /// The contacts under impact refinement (sorted block pairs).
    #[serde(default)]
    refining: Vec<(u32, u32)>,
    /// Base motions ([`Model::set_base_motion`](super::Model::set_base_motion)), with the model
    /// time each started at.
    #[serde(default)]
    motions: Vec<super::excitation::AppliedMotion>,
    /// Load histories ([`Model::set_load_history`](super::Model::set_load_history)), with the
    /// model time each started at.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    load_histories: Vec<super::excitation::AppliedLoad>,
}

/// A joint as checkpoints store it: its geometry, law, the step's running sums and its
/// sub-contacts, independent of how the step lays them out in memory.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ContactEntry<S> {
    blocks: (u32, u32),
    kind: ContactKind,
    host_is_a: bool,
    law: u32,
    normal: Vector,
    tangent: Vector,
    anchors: AnchorPlane,
    /// Whether the sub-contacts may hold dashpot forces: it selects the sub-contact loop, and
    /// with it the order of the sums.
    dashpots: bool,
    normal_force: Real,
    /// Force and first moments of the spring forces as the step summed them (a recomputation
    /// could sum in another order): `[F, F_x, F_y]`.
    springs: [Vector; 3],
    spread_energy: Real,
    /// Centroids and host rotation at detection, which small-displacement mode steps with.
    /// Large displacements keep none (they step with the current poses): their files hold
    /// placeholders here, the blocks' centroids and the host block's rotation as they stand,
    /// which a load checks as numbers and does not keep.
    reference_centroids: (Vector, Vector),
    reference_host_rotation: Rotation,
    area: Real,
    bound_area: Real,
    /// Resultant and moments as of the last step.
    wrench: ContactWrench,
    /// The sub-contacts, with their forces as they stand (also those of a joint stepped as a
    /// whole).
    subcontacts: Vec<SubContactEntry<S>>,
    /// A joint stepped as a whole (`contact/joint_level/`): what the step continues from.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    joint: Option<JointEntry>,
}

/// A joint stepped as a whole, as checkpoints store it: the joint's record and the shear
/// forces its cells hold (`F⁰ᵢ`, in sub-contact order), from which the forces stored in the
/// sub-contacts follow, to the bit, as the step would write them.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct JointEntry {
    level: crate::contact::JointLevel,
    held_shear: Vec<Vector2>,
    /// Of a joint open in part (its `level.span` not empty): its cells' gap and room at entry
    /// (version 15; also their box, which version 16 measures from the cells instead).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    hinge: Option<crate::contact::HingeRecord>,
}

/// A sub-contact as checkpoints store it.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct SubContactEntry<S> {
    key: SubKey,
    plane: Vector2,
    area: Real,
    gap: Real,
    force: JointForce,
    slip: Real,
    half: [f32; 2],
    status: JointStatus,
    state: S,
    dashpot: Vector,
}

/// The checksum of a checkpoint document (without its checksum field): CRC-32 (IEEE) of its
/// compact JSON with every object's keys sorted, as `crc32:` and eight hexadecimal digits.
fn checksum_of(value: &serde_json::Value) -> String {
    let mut text = String::new();
    canonical(value, &mut text);
    format!("crc32:{:08x}", crc32fast::hash(text.as_bytes()))
}

/// Compact JSON with sorted keys, whatever order the map keeps them in.
fn canonical(value: &serde_json::Value, out: &mut String) {
    use serde_json::Value;
    match value {
        Value::Object(map) => {
            let mut keys: Vec<&String> = map.keys().collect();
            keys.sort_unstable();
            out.push('{');
            for (i, k) in keys.into_iter().enumerate() {
                if i > 0 {
                    out.push(',');
                }
                out.push_str(&Value::String(k.clone()).to_string());
                out.push(':');
                canonical(&map[k], out);
            }
            out.push('}');
        }
        Value::Array(items) => {
            out.push('[');
            for (i, v) in items.iter().enumerate() {
                if i > 0 {
                    out.push(',');
                }
                canonical(v, out);
            }
            out.push(']');
        }
        scalar => out.push_str(&scalar.to_string()),
    }
}

/// Recomputes the checksum of a checkpoint edited on purpose, so that it loads again (its content
/// is then checked as any checkpoint's is).
///
/// ```
/// use voussoir::prelude::*;
/// let mut model: Model = Model::new(ModelParameters::default())?;
/// model.add_block(RigidBlock::cuboid("b", Vector::ZERO, Vector::splat(0.1), 2000.0)?)?;
/// let text = model.to_checkpoint_string()?;
/// let edited = text.replace("\"name\":\"b\"", "\"name\":\"stone\"");
/// assert!(matches!(Model::<CoulombSlip>::from_checkpoint_str(&edited), Err(Error::CheckpointChecksum { .. })));
/// let resealed = voussoir::model::reseal_checkpoint(&edited)?;
/// assert_eq!(Model::<CoulombSlip>::from_checkpoint_str(&resealed)?.blocks()[0].name(), "stone");
/// # Ok::<(), voussoir::Error>(())
/// ```
///
/// # Errors
/// [`Error::Checkpoint`] for text that is not a JSON object.
pub fn reseal_checkpoint(text: &str) -> Result<String> {
    let corrupt = |message: String| Error::Checkpoint {
        path: "(document)".into(),
        message,
    };
    let mut value: serde_json::Value =
        serde_json::from_str(text).map_err(|e| corrupt(format!("not a complete JSON document: {e}")))?;
    let Some(map) = value.as_object_mut() else {
        return Err(corrupt("not a JSON object".into()));
    };
    map.remove(CHECKSUM);
    let checksum = checksum_of(&value);
    if let serde_json::Value::Object(map) = &mut value {
        map.insert(CHECKSUM.into(), checksum.into());
    }
    serde_json::to_string(&value).map_err(|e| corrupt(e.to_string()))
}

/// The law type's name as its serde derive gives it (the struct or enum name, or its
/// `#[serde(rename)]`): stable across builds, unlike `std::any::type_name`. `None` for a
/// `Deserialize` that does not name its type.
fn law_type_name<L: DeserializeOwned>() -> Option<&'static str> {
    match L::deserialize(NameOnly) {
        Err(NameFound(name)) => name,
        Ok(_) => None,
    }
}

/// A deserializer with no data, which stops at the first type name serde hands it.
struct NameOnly;

/// The name [`NameOnly`] found (the "error" that stops the deserialisation).
#[derive(Debug)]
struct NameFound(Option<&'static str>);

impl std::fmt::Display for NameFound {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "type name {:?}", self.0)
    }
}

impl std::error::Error for NameFound {}

impl serde::de::Error for NameFound {
    fn custom<T: std::fmt::Display>(_: T) -> Self {
        NameFound(None)
    }
}

impl<'de> serde::Deserializer<'de> for NameOnly {
    type Error = NameFound;

    fn deserialize_any<V: serde::de::Visitor<'de>>(self, _: V) -> std::result::Result<V::Value, NameFound> {
        Err(NameFound(None))
    }

    fn deserialize_struct<V: serde::de::Visitor<'de>>(
        self,
        name: &'static str,
        _: &'static [&'static str],
        _: V,
    ) -> std::result::Result<V::Value, NameFound> {
        Err(NameFound(Some(name)))
    }

    fn deserialize_enum<V: serde::de::Visitor<'de>>(
        self,
        name: &'static str,
        _: &'static [&'static str],
        _: V,
    ) -> std::result::Result<V::Value, NameFound> {
        Err(NameFound(Some(name)))
    }

    fn deserialize_newtype_struct<V: serde::de::Visitor<'de>>(
        self,
        name: &'static str,
        _: V,
    ) -> std::result::Result<V::Value, NameFound> {
        Err(NameFound(Some(name)))
    }

    fn deserialize_unit_struct<V: serde::de::Visitor<'de>>(
        self,
        name: &'static str,
        _: V,
    ) -> std::result::Result<V::Value, NameFound> {
        Err(NameFound(Some(name)))
    }

    fn deserialize_tuple_struct<V: serde::de::Visitor<'de>>(
        self,
        name: &'static str,
        _: usize,
        _: V,
    ) -> std::result::Result<V::Value, NameFound> {
        Err(NameFound(Some(name)))
    }

    serde::forward_to_deserialize_any! {
        bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string bytes byte_buf option
        unit seq tuple map identifier ignored_any
    }
}
