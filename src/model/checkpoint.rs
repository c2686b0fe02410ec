//! Checkpoint and restart: the full state of a model (blocks, contacts, sub-contact history, law
//! state, energies, monitors) as JSON, restored so that the run continues bit-identically.
//! Compiled with the `serde` feature.

use std::path::Path;

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

use super::{Model, ModelParameters};
use crate::block::{Block, RigidBlock, Wrench};
use crate::constitutive::{ConstitutiveLaw, JointTable};
use crate::contact::{ContactPair, ContactReference, ContactWrench, ForceMoments, SubContact, SubContactRecord};
use crate::error::{io_error, Error, Result};
use crate::integrate::{CentralDifference, CriticalStep, Damping};
use crate::math::{is_finite_vector, Pose, Real, Vector};
use crate::model::Energies;
use crate::monitor::{History, Monitor};

const FORMAT: &str = "voussoir-checkpoint";
const VERSION: u32 = 8;

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
    joints: JointTable<L>,
    pairs: Vec<ContactPair>,
    /// The contacts' reference geometry and areas, index for index.
    references: Vec<ContactReference>,
    /// The contacts' wrenches as of the last step, index for index (what `contact_wrench` and
    /// the contacts' resultants report before the next step).
    wrenches: Vec<ContactWrench>,
    subs: Vec<SubContact<L::State>>,
    /// The sub-contacts' records, index for index.
    sub_records: Vec<SubContactRecord>,
    ref_poses: Vec<Pose>,
    dt: Real,
    critical: Option<CriticalStep>,
    step: u64,
    time: Real,
    energy: Energies,
    started: bool,
    unbalanced_ratio: Option<Real>,
    detections: u64,
    monitors: Vec<(String, Monitor)>,
    history: History,
    monitor_interval: u64,
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

/// Checkpoints need the `serde` feature (on by default).
#[cfg_attr(docsrs, doc(cfg(feature = "serde")))]
impl<L> Model<L>
where
    L: ConstitutiveLaw + Serialize + DeserializeOwned,
    L::State: Serialize + DeserializeOwned,
{
    /// The full state as JSON text (numbers round-trip exactly).
    ///
    /// The integrator is stored as its damping model and restored as [`CentralDifference`]; a
    /// custom integrator must be set again after [`Model::from_checkpoint_str`].
    ///
    /// # Errors
    /// [`Error::Io`] if serialisation fails (it does not for the shipped laws).
    pub fn to_checkpoint_string(&self) -> Result<String> {
        let snap = Snapshot::<L> {
            format: FORMAT.into(),
            version: VERSION,
            params: self.params,
            damping: self.integrator.damping(),
            blocks: self.blocks.clone(),
            joints: self.joints.clone(),
            pairs: self.pairs.clone(),
            references: self.references.clone(),
            wrenches: self.wrenches.clone(),
            subs: self.subs.clone(),
            sub_records: self.sub_records.clone(),
            ref_poses: self.ref_poses.clone(),
            dt: self.dt,
            critical: self.critical,
            step: self.step,
            time: self.time,
            energy: self.energies(),
            started: self.started,
            unbalanced_ratio: self.unbalanced_ratio.is_finite().then_some(self.unbalanced_ratio),
            detections: self.detections,
            monitors: self.monitors.clone(),
            history: self.history.clone(),
            monitor_interval: self.monitor_interval,
            last_forces: self.records.iter().map(|r| (r.reaction, r.damping)).collect(),
            drift: self.drift,
            refine_until: self.refine_until,
            refine_omega2: self.refine_omega2,
            refining: self.refining.clone(),
            pending_detection: self.scratch.force_full_detection,
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
        if snap.ref_poses.len() != n {
            return Err(corrupt("ref_poses", "one pose per block expected"));
        }
        if snap.references.len() != snap.pairs.len() {
            return Err(corrupt("references", "one reference per contact expected"));
        }
        if snap.wrenches.len() != snap.pairs.len() {
            return Err(corrupt("wrenches", "one wrench per contact expected"));
        }
        if let Some(k) = snap
            .wrenches
            .iter()
            .position(|w| !(is_finite_vector(w.force) && is_finite_vector(w.moment_a) && is_finite_vector(w.moment_b)))
        {
            return Err(corrupt(&format!("wrenches[{k}]"), "non-finite force or moment"));
        }
        let mut next = 0usize;
        for (k, p) in snap.pairs.iter().enumerate() {
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
                return Err(corrupt(&format!("pairs[{k}].tangent"), "joint axes not orthonormal"));
            }
            if !orthonormal(p.anchors.u, p.anchors.v) {
                return Err(corrupt(
                    &format!("pairs[{k}].anchors"),
                    "anchor plane axes not orthonormal",
                ));
            }
            let sorted = k == 0 || (snap.pairs[k - 1].a, snap.pairs[k - 1].b) < (p.a, p.b);
            let (start, end) = (p.first as usize, p.first as usize + p.count as usize);
            let ok = faces_ok
                && sorted
                && (p.a as usize) < n
                && (p.b as usize) < n
                && p.a < p.b
                && (p.law as usize) < snap.joints.laws().len()
                && start == next
                && end <= snap.subs.len();
            if !ok {
                return Err(corrupt(
                    &format!("pairs[{k}]"),
                    "inconsistent block, law or sub-contact indices",
                ));
            }
            next = end;
        }
        if next != snap.subs.len() {
            return Err(corrupt("subs", "sub-contacts not covered by the contacts"));
        }
        if let Some(i) = snap.subs.iter().position(|s| s.area < 0.0) {
            return Err(corrupt(&format!("subs[{i}].area"), "negative area"));
        }
        if snap.sub_records.len() != snap.subs.len() {
            return Err(corrupt("sub_records", "one record per sub-contact expected"));
        }
        for (name, m) in &snap.monitors {
            if m.blocks().iter().any(|b| b.index() >= n) {
                return Err(corrupt(&format!("monitors.{name}"), "refers to a missing block"));
            }
        }
        let mut model = Model::new(snap.params)?;
        for (i, mut b) in snap.blocks.into_iter().enumerate() {
            b.restore()
                .map_err(|e| corrupt(&format!("blocks[{i}]"), &e.to_string()))?;
            model.add_block(b)?;
        }
        model.joints = snap.joints;
        model.integrator = Box::new(CentralDifference::new(snap.damping));
        model.pairs = snap.pairs;
        model.references = snap.references;
        model.wrenches = snap.wrenches;
        model.subs = snap.subs;
        model.sub_records = snap.sub_records;
        for (k, p) in model.pairs.iter_mut().enumerate() {
            let (a, b) = (&model.blocks[p.a as usize], &model.blocks[p.b as usize]);
            p.cache_local_faces(Block::shape(a), Block::shape(b));
            // Dashpot forces still held must be seen (and their work booked) by the next step.
            p.dashpots |= model.sub_records[p.range()].iter().any(|r| r.dashpot != Vector::ZERO);
            // The stored spring moments are those of the stored forces, up to summation order.
            if !p
                .springs
                .matches(&ForceMoments::of_springs(&p.axes(), &model.subs[p.range()]))
            {
                return Err(corrupt(
                    &format!("pairs[{k}].springs"),
                    "inconsistent with the sub-contact forces",
                ));
            }
        }
        model.ref_poses = snap.ref_poses;
        model.dt = snap.dt;
        model.drift = if snap.drift > 0.0 && snap.started {
            snap.drift
        } else {
            0.0
        };
        model.refine_until = snap.refine_until;
        model.refine_omega2 = snap.refine_omega2;
        model.refining = snap.refining;
        model.refining.sort_unstable();
        model.refining.dedup();
        model.critical = snap.critical;
        model.step = snap.step;
        model.time = snap.time;
        model.energy = snap.energy;
        model.started = snap.started;
        model.unbalanced_ratio = snap.unbalanced_ratio.unwrap_or(Real::INFINITY);
        model.detections = snap.detections;
        model.monitors = snap.monitors;
        model.history = snap.history;
        model.monitor_interval = snap.monitor_interval.max(1);
        for (r, &(reaction, damping)) in model.records.iter_mut().zip(&snap.last_forces) {
            r.reaction = reaction;
            r.damping = damping;
        }
        model.scratch.force_full_detection = !model.started || snap.pending_detection;
        model.rebuild_block_index();
        Ok(model)
    }

    /// Writes [`Model::to_checkpoint_string`] to a file.
    ///
    /// # Errors
    /// [`Error::Io`] naming the file.
    pub fn save_checkpoint(&self, path: &Path) -> Result<()> {
        let text = self.to_checkpoint_string()?;
        if let Some(dir) = path.parent() {
            if !dir.as_os_str().is_empty() {
                std::fs::create_dir_all(dir).map_err(|e| io_error(dir, &e))?;
            }
        }
        std::fs::write(path, text).map_err(|e| io_error(path, &e))
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
