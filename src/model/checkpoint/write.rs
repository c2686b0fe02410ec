//! Writing a checkpoint: each contact as its transfer record, the snapshot of the whole state,
//! its checksum, and the file.

use std::path::Path;

use serde::de::DeserializeOwned;
use serde::Serialize;

use super::tested::TestedEntry;
use super::{
    checksum_of, law_type_name, ContactEntry, JointEntry, Snapshot, SubContactEntry, CHECKSUM, FORMAT, VERSION,
};
use crate::contact::SmallReference;
use crate::error::{Error, Result};
use crate::law::ConstitutiveLaw;
use crate::model::Model;

impl<L: ConstitutiveLaw> Model<L> {
    /// Contact `k` as a checkpoint stores it.
    ///
    /// Its geometry at detection (`reference_centroids`, `reference_host_rotation`) as kept in
    /// small-displacement mode; where the contacts keep none (large displacements, which never
    /// read it: a switch to small displacements detects every contact afresh), placeholders in
    /// the same fields, so that the format stays as it was: the blocks' current centroids and
    /// the host block's current rotation.
    fn contact_entry(&self, k: usize) -> ContactEntry<L::State> {
        let (p, r) = (&self.state.contacts.pairs[k], &self.state.contacts.references[k]);
        let range = p.range();
        let small = match self.state.contacts.small_refs.get(k) {
            Some(s) => *s,
            None => {
                let (pa, pb) = (
                    &self.state.blocks[p.a as usize].state.pose,
                    &self.state.blocks[p.b as usize].state.pose,
                );
                SmallReference {
                    ref_a: pa.translation,
                    ref_b: pb.translation,
                    ref_host_rotation: if p.host_is_a { pa.rotation } else { pb.rotation },
                }
            }
        };
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
            spread_energy: p.spread_energy,
            reference_centroids: (small.ref_a, small.ref_b),
            reference_host_rotation: small.ref_host_rotation,
            area: r.area,
            bound_area: r.bound_area,
            wrench: self.state.contacts.wrenches[k],
            subcontacts: self.state.contacts.subs[range.clone()]
                .iter()
                .zip(range.clone())
                .map(|(s, i)| {
                    let (force, gap, status) = p.joint.live(i - range.start, s);
                    SubContactEntry {
                        key: p.key(r, i - range.start, s),
                        plane: s.plane,
                        area: s.area,
                        gap,
                        force,
                        slip: s.slip,
                        half: s.half,
                        status,
                        state: s.state.clone(),
                        dashpot: self.state.contacts.dashpot(i),
                    }
                })
                .collect(),
            joint: p.joint.active.then(|| JointEntry {
                level: p.joint,
                held_shear: self.state.contacts.subs[range].iter().map(|s| s.force.shear).collect(),
                hinge: r.hinge().copied().filter(|_| p.joint.is_partial()),
            }),
        }
    }
}

impl<L> Model<L>
where
    L: ConstitutiveLaw + Serialize + DeserializeOwned,
    L::State: Serialize + DeserializeOwned,
{
    /// The full state as JSON text (numbers round-trip exactly).
    ///
    /// The integrator is stored as its damping model and restored as
    /// [`CentralDifference`](crate::integrate::CentralDifference); a model with a custom
    /// integrator (one whose
    /// [`Integrator::checkpoint_damping`](crate::Integrator::checkpoint_damping) is `None`) is
    /// refused rather than restored with another.
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
            law_type: law_type_name::<L>().map(str::to_owned),
            params: self.state.params,
            damping,
            blocks: self.state.blocks.clone(),
            joints: self.state.laws.clone(),
            contacts: (0..self.state.contacts.pairs.len())
                .map(|k| self.contact_entry(k))
                .collect(),
            ref_poses: self.state.found.ref_poses.clone(),
            tested: self
                .state
                .found
                .tested
                .iter()
                .map(|t| TestedEntry {
                    blocks: (t.a, t.b),
                    relative: t.relative,
                    slack: t.slack,
                })
                .collect(),
            dt: self.state.clock.dt,
            critical: self.state.clock.critical,
            bounds: self.pipeline.bounds.iter().map(|b| b.omega_squared).collect(),
            step: self.state.clock.step,
            time: self.state.clock.time,
            energy: self.energies(),
            started: self.state.clock.started,
            unbalanced_ratio: self
                .state
                .unbalanced_ratio
                .is_finite()
                .then_some(self.state.unbalanced_ratio),
            detections: self.state.found.detections,
            last_forces: self.state.records.iter().map(|r| (r.reaction, r.damping)).collect(),
            drift: self.state.clock.drift,
            refine_until: self.state.clock.refine_until,
            refine_omega2: self.state.clock.refine_omega2,
            refine_travel: self.state.clock.refine_travel,
            refining: self.state.clock.refining.clone(),
            motions: self.state.excitations.motions.clone(),
            load_histories: self.state.excitations.load_histories.clone(),
            pending_detection: self.state.changes.need_full_detection() || !self.state.refixed.is_empty(),
        };
        let io = |e: serde_json::Error| Error::Io {
            path: "(checkpoint)".into(),
            message: e.to_string(),
        };
        let mut value = serde_json::to_value(&snap).map_err(io)?;
        // A non-finite energy is written as null, which would not load: what saves must load.
        if let Some((term, _)) = value["energy"]
            .as_object()
            .and_then(|m| m.iter().find(|(_, v)| v.is_null()))
        {
            return Err(Error::NonFinite {
                what: format!(
                    "energy term `{term}` of the model (a velocity, load or force beyond f64's range): a checkpoint \
                     of it would not load"
                ),
            });
        }
        let checksum = checksum_of(&value);
        if let serde_json::Value::Object(map) = &mut value {
            map.insert(CHECKSUM.into(), checksum.into());
        }
        serde_json::to_string(&value).map_err(io)
    }

    /// Writes [`Model::to_checkpoint_string`] to a file.
    ///
    /// # Errors
    /// [`Error::Io`] naming the file.
    pub fn save_checkpoint(&self, path: &Path) -> Result<()> {
        let text = self.to_checkpoint_string()?;
        crate::file::write_atomically(path, text.as_bytes())
    }
}
