//! Checkpoint and restart: the full state of a model (blocks, contacts, sub-contact history, law
//! state, energies) as JSON, restored so that the run continues bit-identically. Recorders are
//! the caller's: their [`crate::monitor::History`] serialises on its own.
//! Compiled with the `serde` feature.

use std::path::Path;

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

use super::{Model, ModelParameters};
use crate::block::{Block, RigidBlock, Wrench};
use crate::contact::{
    AnchorPlane, ContactPair, ContactReference, ContactWrench, ForceMoments, SubContact, SubContactRecord,
};
use crate::error::{io_error, Error, Result};
use crate::geometry::{ContactKind, SubKey};
use crate::integrate::{CentralDifference, CriticalStep, Damping};
use crate::law::{ConstitutiveLaw, LawTable};
use crate::law::{JointForce, JointStatus};
use crate::math::{is_finite_vector, Pose, Real, Rotation, Vector, Vector2};
use crate::model::Energies;

const FORMAT: &str = "voussoir-checkpoint";
/// Version 9 stores joints through [`ContactEntry`], apart from the step's storage layout, so
/// that a layout change no longer changes the format.
const VERSION: u32 = 9;

/// The fields every version has, read before the rest (other fields are skipped).
#[derive(Deserialize)]
struct Header {
    format: String,
    version: u32,
}

#[derive(Serialize, Deserialize)]
#[serde(bound(
    serialize = "L: Serialize, L::State: Serialize",
    deserialize = "L: DeserializeOwned, L::State: DeserializeOwned"
))]
struct Snapshot<L: ConstitutiveLaw> {
    format: String,
    version: u32,
    params: ModelParameters,
    damping: Damping,
    blocks: Vec<RigidBlock>,
    joints: LawTable<L>,
    /// The contacts, sorted by block pair, each with its sub-contacts.
    contacts: Vec<ContactEntry<L::State>>,
    ref_poses: Vec<Pose>,
    dt: Real,
    critical: Option<CriticalStep>,
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
    /// The contacts under impact refinement (sorted block pairs).
    #[serde(default)]
    refining: Vec<(u32, u32)>,
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
    /// Centroids and host rotation at detection (small-displacement mode).
    reference_centroids: (Vector, Vector),
    reference_host_rotation: Rotation,
    area: Real,
    bound_area: Real,
    /// Resultant and moments as of the last step.
    wrench: ContactWrench,
    subcontacts: Vec<SubContactEntry<S>>,
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
    status: JointStatus,
    state: S,
    dashpot: Vector,
}

impl<L: ConstitutiveLaw> Model<L> {
    /// Contact `k` as a checkpoint stores it.
    fn contact_entry(&self, k: usize) -> ContactEntry<L::State> {
        let (p, r) = (&self.state.pairs[k], &self.state.references[k]);
        let range = p.range();
        ContactEntry {
            blocks: (p.a, p.b),
            kind: p.kind,
            host_is_a: p.host_is_a,
            law: p.law,
            normal: p.normal,
            tangent: p.tangent,
            anchors: p.anchors,
            dashpots: p.dashpots,
            normal_force: p.normal_force,
            springs: [p.springs.force, p.springs.per_x, p.springs.per_y],
            reference_centroids: (r.ref_a, r.ref_b),
            reference_host_rotation: r.ref_host_rotation,
            area: r.area,
            bound_area: r.bound_area,
            wrench: self.state.wrenches[k],
            subcontacts: self.state.subs[range.clone()]
                .iter()
                .zip(&self.state.sub_records[range])
                .map(|(s, rec)| SubContactEntry {
                    key: rec.key,
                    plane: s.plane,
                    area: s.area,
                    gap: s.gap,
                    force: s.force,
                    slip: s.slip,
                    status: s.status,
                    state: s.state.clone(),
                    dashpot: rec.dashpot,
                })
                .collect(),
        }
    }
}

/// The step's storage rebuilt from checkpointed joints: contacts, their references and
/// wrenches, the sub-contacts and their records (each contact's range in order).
#[allow(clippy::type_complexity)]
fn into_storage<S>(
    entries: Vec<ContactEntry<S>>,
) -> (
    Vec<ContactPair>,
    Vec<ContactReference>,
    Vec<ContactWrench>,
    Vec<SubContact<S>>,
    Vec<SubContactRecord>,
) {
    let total = entries.iter().map(|e| e.subcontacts.len()).sum();
    let (mut pairs, mut references, mut wrenches) = (
        Vec::with_capacity(entries.len()),
        Vec::with_capacity(entries.len()),
        Vec::with_capacity(entries.len()),
    );
    let (mut subs, mut records) = (Vec::with_capacity(total), Vec::with_capacity(total));
    for e in entries {
        let first = subs.len() as u32;
        let count = e.subcontacts.len() as u32;
        for s in e.subcontacts {
            subs.push(SubContact {
                plane: s.plane,
                area: s.area,
                gap: s.gap,
                force: s.force,
                slip: s.slip,
                status: s.status,
                state: s.state,
            });
            records.push(SubContactRecord {
                key: s.key,
                dashpot: s.dashpot,
            });
        }
        pairs.push(ContactPair {
            a: e.blocks.0,
            b: e.blocks.1,
            kind: e.kind,
            host_is_a: e.host_is_a,
            law: e.law,
            first,
            count,
            normal: e.normal,
            tangent: e.tangent,
            anchors: e.anchors,
            plane_normal: Vector::ZERO,
            plane_offset: 0.0,
            dashpots: e.dashpots,
            normal_force: e.normal_force,
            springs: ForceMoments {
                force: e.springs[0],
                per_x: e.springs[1],
                per_y: e.springs[2],
            },
        });
        references.push(ContactReference {
            ref_a: e.reference_centroids.0,
            ref_b: e.reference_centroids.1,
            ref_host_rotation: e.reference_host_rotation,
            area: e.area,
            bound_area: e.bound_area,
        });
        wrenches.push(e.wrench);
    }
    (pairs, references, wrenches, subs, records)
}

impl<L> Model<L>
where
    L: ConstitutiveLaw + Serialize + DeserializeOwned,
    L::State: Serialize + DeserializeOwned,
{
    /// The full state as JSON text (numbers round-trip exactly).
    ///
    /// The integrator is stored as its damping model and restored as [`CentralDifference`];
    /// a model with a custom integrator (one whose
    /// [`Integrator::checkpoint_damping`](crate::Integrator::checkpoint_damping) is `None`)
    /// is refused rather than restored with another.
    ///
    /// # Errors
    /// [`Error::Unsupported`] for a custom integrator; [`Error::Io`] if serialisation fails (it
    /// does not for the shipped laws).
    pub fn to_checkpoint_string(&self) -> Result<String> {
        let Some(damping) = self.state.integrator.checkpoint_damping() else {
            return Err(Error::Unsupported {
                what: format!(
                    "checkpoint of a model with a custom integrator ({:?}), which a checkpoint cannot restore",
                    self.state.integrator
                ),
            });
        };
        let snap = Snapshot::<L> {
            format: FORMAT.into(),
            version: VERSION,
            params: self.state.params,
            damping,
            blocks: self.state.blocks.clone(),
            joints: self.state.laws.clone(),
            contacts: (0..self.state.pairs.len()).map(|k| self.contact_entry(k)).collect(),
            ref_poses: self.state.ref_poses.clone(),
            dt: self.state.dt,
            critical: self.state.critical,
            step: self.state.step,
            time: self.state.time,
            energy: self.energies(),
            started: self.state.started,
            unbalanced_ratio: self
                .state
                .unbalanced_ratio
                .is_finite()
                .then_some(self.state.unbalanced_ratio),
            detections: self.state.detections,
            last_forces: self.state.records.iter().map(|r| (r.reaction, r.damping)).collect(),
            drift: self.state.drift,
            refine_until: self.state.refine_until,
            refine_omega2: self.state.refine_omega2,
            refining: self.state.refining.clone(),
            pending_detection: self.state.changes.need_full_detection(),
        };
        serde_json::to_string(&snap).map_err(|e| Error::Io {
            path: "(checkpoint)".into(),
            message: e.to_string(),
        })
    }

    /// Restores a model from [`Model::to_checkpoint_string`] text.
    ///
    /// ```
    /// use voussoir::prelude::*;
    /// let mut model: Model = Model::new(ModelParameters::default())?;
    /// model.set_joint_law(MaterialId(0), MaterialId(0), CoulombSlip::dry(1e9, 4e8, 30.0)?)?;
    /// model.add_block(RigidBlock::cuboid("base", Vector::splat(-1.0), Vector::new(1.0, 1.0, 0.0), 2000.0)?
    ///     .with_fixity(Fixity::FIXED))?;
    /// let b = model.add_block(RigidBlock::cuboid("b", Vector::ZERO, Vector::splat(0.1), 2000.0)?)?;
    /// model.run_steps(50)?;
    /// let mut restarted: Model = Model::from_checkpoint_str(&model.to_checkpoint_string()?)?;
    /// model.run_steps(50)?;
    /// restarted.run_steps(50)?;
    /// assert_eq!(model.block(b)?.state(), restarted.block(b)?.state()); // bit-identical
    /// assert!(Model::<CoulombSlip>::from_checkpoint_str("{\"format\": 3").is_err());
    /// # Ok::<(), voussoir::Error>(())
    /// ```
    ///
    /// # Errors
    /// [`Error::Checkpoint`] for truncated, corrupt or inconsistent text, naming where.
    pub fn from_checkpoint_str(text: &str) -> Result<Self> {
        // The format and version first, so that a file of another version is named as such
        // rather than failing on the first field that changed.
        if let Ok(header) = serde_json::from_str::<Header>(text) {
            if header.format != FORMAT {
                return Err(Error::Checkpoint {
                    path: "format".into(),
                    message: format!("\"{}\" is not a {FORMAT}", header.format),
                });
            }
            if header.version != VERSION {
                return Err(Error::Checkpoint {
                    path: "version".into(),
                    message: format!(
                        "{FORMAT} version {}; this build reads version {VERSION}",
                        header.version
                    ),
                });
            }
        }
        let de = &mut serde_json::Deserializer::from_str(text);
        let snap: Snapshot<L> = serde_path_to_error::deserialize(de).map_err(|e| Error::Checkpoint {
            path: e.path().to_string(),
            message: e.inner().to_string(),
        })?;
        let corrupt = |path: &str, message: &str| Error::Checkpoint {
            path: path.into(),
            message: message.into(),
        };
        if snap.format != FORMAT || snap.version != VERSION {
            return Err(corrupt("format", &format!("not a {FORMAT} version {VERSION}")));
        }
        snap.params.validate()?;
        snap.damping.validate()?;
        let n = snap.blocks.len();
        if !snap.joints.check() {
            return Err(corrupt("joints", "law index out of range"));
        }
        // Laws are validated as on `set_joint_law` (serde only checks their shape).
        for (k, law) in snap.joints.laws().iter().enumerate() {
            crate::law::check_law(law).map_err(|e| corrupt(&format!("joints.laws[{k}]"), &e.to_string()))?;
        }
        if snap.ref_poses.len() != n {
            return Err(corrupt("ref_poses", "one pose per block expected"));
        }
        let (pairs, references, wrenches, subs, sub_records) = into_storage(snap.contacts);
        if let Some(k) = wrenches
            .iter()
            .position(|w| !(is_finite_vector(w.force) && is_finite_vector(w.moment_a) && is_finite_vector(w.moment_b)))
        {
            return Err(corrupt(&format!("contacts[{k}].wrench"), "non-finite force or moment"));
        }
        let mut next = 0usize;
        for (k, p) in pairs.iter().enumerate() {
            let faces_ok = match p.kind {
                crate::geometry::ContactKind::FaceFace { face_a, face_b } => {
                    (p.a as usize) < n
                        && (p.b as usize) < n
                        && (face_a as usize) < snap.blocks[p.a as usize].shape_face_count()
                        && (face_b as usize) < snap.blocks[p.b as usize].shape_face_count()
                }
                crate::geometry::ContactKind::Point { .. } => true,
            };
            if !orthonormal(p.normal, p.tangent) {
                return Err(corrupt(&format!("contacts[{k}].tangent"), "joint axes not orthonormal"));
            }
            if !orthonormal(p.anchors.u, p.anchors.v) {
                return Err(corrupt(
                    &format!("contacts[{k}].anchors"),
                    "anchor plane axes not orthonormal",
                ));
            }
            let sorted = k == 0 || (pairs[k - 1].a, pairs[k - 1].b) < (p.a, p.b);
            let (start, end) = (p.first as usize, p.first as usize + p.count as usize);
            let ok = faces_ok
                && sorted
                && (p.a as usize) < n
                && (p.b as usize) < n
                && p.a < p.b
                && (p.law as usize) < snap.joints.laws().len()
                && start == next
                && end <= subs.len();
            if !ok {
                return Err(corrupt(
                    &format!("contacts[{k}]"),
                    "inconsistent block, law or sub-contact indices",
                ));
            }
            next = end;
        }
        if let Some(i) = subs.iter().position(|s| s.area < 0.0) {
            let k = pairs.partition_point(|p| p.first as usize + p.count as usize <= i);
            let j = i - pairs[k].first as usize;
            return Err(corrupt(
                &format!("contacts[{k}].subcontacts[{j}].area"),
                "negative area",
            ));
        }
        let mut model = Model::new(snap.params)?;
        for (i, mut b) in snap.blocks.into_iter().enumerate() {
            b.restore()
                .map_err(|e| corrupt(&format!("blocks[{i}]"), &e.to_string()))?;
            model.add_block(b)?;
        }
        model.state.laws = snap.joints;
        model.state.integrator = Box::new(CentralDifference::new(snap.damping));
        model.state.pairs = pairs;
        model.state.references = references;
        model.state.wrenches = wrenches;
        model.state.subs = subs;
        model.state.sub_records = sub_records;
        for (k, p) in model.state.pairs.iter_mut().enumerate() {
            let (a, b) = (&model.state.blocks[p.a as usize], &model.state.blocks[p.b as usize]);
            p.cache_local_faces(Block::shape(a), Block::shape(b));
            // Dashpot forces still held must be seen (and their work booked) by the next step.
            p.dashpots |= model.state.sub_records[p.range()]
                .iter()
                .any(|r| r.dashpot != Vector::ZERO);
            // The stored spring moments are those of the stored forces, up to summation order.
            if !p
                .springs
                .matches(&ForceMoments::of_springs(&p.axes(), &model.state.subs[p.range()]))
            {
                return Err(corrupt(
                    &format!("contacts[{k}].springs"),
                    "inconsistent with the sub-contact forces",
                ));
            }
        }
        model.state.ref_poses = snap.ref_poses;
        model.state.dt = snap.dt;
        model.state.drift = if snap.drift > 0.0 && snap.started {
            snap.drift
        } else {
            0.0
        };
        model.state.refine_until = snap.refine_until;
        model.state.refine_omega2 = snap.refine_omega2;
        model.state.refining = snap.refining;
        model.state.refining.sort_unstable();
        model.state.refining.dedup();
        model.state.critical = snap.critical;
        model.state.step = snap.step;
        model.state.time = snap.time;
        model.state.energy = snap.energy;
        model.state.started = snap.started;
        model.state.unbalanced_ratio = snap.unbalanced_ratio.unwrap_or(Real::INFINITY);
        model.state.detections = snap.detections;
        for (r, &(reaction, damping)) in model.state.records.iter_mut().zip(&snap.last_forces) {
            r.reaction = reaction;
            r.damping = damping;
        }
        model.state.changes.clear();
        if !model.state.started || snap.pending_detection {
            model.state.changes.insert(super::changes::Changes::DETECTION);
        }
        model.state.rebuild_block_index(&mut model.pipeline);
        Ok(model)
    }

    /// Writes [`Model::to_checkpoint_string`] to a file.
    ///
    /// # Errors
    /// [`Error::Io`] naming the file.
    pub fn save_checkpoint(&self, path: &Path) -> Result<()> {
        let text = self.to_checkpoint_string()?;
        crate::file::write_atomically(path, text.as_bytes())
    }

    /// Reads a checkpoint file.
    ///
    /// # Errors
    /// [`Error::Io`] naming the file; [`Error::Checkpoint`] for corrupt content.
    pub fn load_checkpoint(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| io_error(path, &e))?;
        Self::from_checkpoint_str(&text)
    }
}

/// Whether `a` and `b` are unit vectors normal to each other, to round-off (1e-9).
fn orthonormal(a: Vector, b: Vector) -> bool {
    let tolerance = 1e-9;
    (a.length_squared() - 1.0).abs() <= tolerance
        && (b.length_squared() - 1.0).abs() <= tolerance
        && a.dot(b).abs() <= tolerance
}
