//! Reading a checkpoint: the header, the checksum and the law type first, then the snapshot,
//! checked against everything it can be checked against before a model is rebuilt from it
//! (see [`Model::from_checkpoint_str`]), and the file.

use std::path::Path;

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

use super::checks::{check_contacts, check_snapshot, check_time_step, corrupt};
use super::tested::check_slacks;
use super::{
    checksum_of, law_type_name, ContactEntry, Header, Snapshot, CHECKSUM, FORMAT, MIN_STORED_BOUND, OLDEST_VERSION,
    VERSION,
};
use crate::block::Block;
use crate::contact::{
    ContactPair, ContactReference, ContactStore, DisplacementMode, ForceMoments, SideRecord, SmallReference, SpanEnds,
    SubContact,
};
use crate::error::{Error, Result};
use crate::geometry::ContactKind;
use crate::ids::BlockId;
use crate::integrate::CentralDifference;
use crate::law::{ConstitutiveLaw, JointForce};
use crate::math::is_unit_pose;
use crate::math::{Real, Vector};
use crate::model::{Model, ModelParameters};

/// The step's storage rebuilt from checkpointed joints. A joint stepped as a whole gets its
/// cells' held shear forces back; its stored forces must be those its record gives them, to the
/// bit (else the error names it). A face-face cell keeps the grid indices of its key, whose
/// faces must be its joint's (as detection writes them; else the error names it), a node
/// contact its nodes' keys.
/// A joint record holding what its file's `version` did not have (a span or a hinge record
/// before version 15, open cells at one end before 16) is refused: no build of that version
/// wrote it.
///
/// The contacts' geometry at detection (`reference_centroids`, `reference_host_rotation`) is
/// kept when `small` (the file's model steps with small displacements); otherwise it is read
/// (as numbers) but not kept: large displacements never read it, and the files of this version
/// hold placeholders there (those of earlier ones, each contact's last detection).
fn into_storage<S: PartialEq + Default>(
    entries: Vec<ContactEntry<S>>,
    version: u32,
    small: bool,
) -> Result<ContactStore<S>> {
    let total = entries.iter().map(|e| e.subcontacts.len()).sum();
    let (mut pairs, mut references, mut wrenches) = (
        Vec::with_capacity(entries.len()),
        Vec::with_capacity(entries.len()),
        Vec::with_capacity(entries.len()),
    );
    let mut small_refs = Vec::with_capacity(if small { entries.len() } else { 0 });
    let mut subs = Vec::with_capacity(total);
    // Kept only when some sub-contact holds a dashpot force (a model without Rayleigh damping
    // keeps none; one with it fills them at its next step).
    let kept = entries
        .iter()
        .any(|e| e.subcontacts.iter().any(|s| s.dashpot != Vector::ZERO));
    let mut dashpots = Vec::with_capacity(if kept { total } else { 0 });
    for (k, e) in entries.into_iter().enumerate() {
        let first = subs.len() as u32;
        let count = e.subcontacts.len() as u32;
        if let Some(j) = &e.joint {
            let newer = if version < 15 && (j.level.span != (0, 0) || j.hinge.is_some()) {
                Some("a span or a hinge record, which version 15 added")
            } else if version < 16 && j.level.ends != SpanEnds::Closed {
                Some("open cells stepped as a whole (`ends`), which version 16 added")
            } else {
                None
            };
            if let Some(what) = newer {
                return Err(corrupt(
                    &format!("contacts[{k}].joint"),
                    &format!("holds {what}, in a version {version} file"),
                ));
            }
        }
        let (joint, hinge) = match &e.joint {
            None => Default::default(),
            Some(j)
                if j.level.active
                    && j.held_shear.len() == e.subcontacts.len()
                    && ((j.level.span == (0, 0) && j.level.ends == SpanEnds::Closed && j.hinge.is_none())
                        || (!j.level.open
                            && j.level.span.0 < j.level.span.1
                            && usize::from(j.level.span.1) <= e.subcontacts.len()
                            && (j.level.span.0 > 0 || usize::from(j.level.span.1) < e.subcontacts.len())
                            && (j.level.ends == SpanEnds::Closed
                                || (j.level.span.0 > 0 && usize::from(j.level.span.1) < e.subcontacts.len()))
                            && j.hinge.is_some()))
                    && matches!(e.kind, crate::geometry::ContactKind::FaceFace { .. }) =>
            {
                (j.level, j.hinge.map(|h| Box::new(SideRecord::Hinge(h))))
            }
            Some(_) => {
                return Err(corrupt(
                    &format!("contacts[{k}].joint"),
                    "must be a face-face joint's, active, with one shear force per sub-contact, and, when \
                     its span is not empty, a joint not open all over, its span within its sub-contacts with \
                     cells outside it (at both ends when one end is open) and its hinge record",
                ))
            }
        };
        let mut node_keys = Vec::new();
        for (j, s) in e.subcontacts.into_iter().enumerate() {
            let cell = match e.kind {
                ContactKind::FaceFace { face_a, face_b } if s.key.is_cell_of(face_a, face_b) => s.key.cell_indices(),
                ContactKind::FaceFace { .. } => {
                    return Err(corrupt(
                        &format!("contacts[{k}].subcontacts[{j}].key"),
                        "is not the key of a cell of its joint's faces",
                    ))
                }
                ContactKind::Nodes => {
                    node_keys.push(s.key);
                    [0; 2]
                }
            };
            let mut sub = SubContact {
                plane: s.plane,
                area: s.area,
                gap: s.gap,
                force: s.force,
                slip: s.slip,
                half: s.half,
                status: s.status,
                cell,
                state: s.state,
            };
            if let Some(entry) = &e.joint {
                sub.force.shear = entry.held_shear[j];
                // A cell stepped as a whole is virgin, and carries nothing if open, as the joint
                // entered with it (`JointLevel::enter`, `enter_open`, `enter_partial`).
                let whole = joint.active && !joint.span_range().contains(&j);
                if whole && (sub.state != S::default() || (joint.holds_open(j) && sub.force != JointForce::default())) {
                    return Err(corrupt(
                        &format!("contacts[{k}].subcontacts[{j}]"),
                        "is stepped as a whole with its joint, so must be in its law's initial state and, \
                         open, carry no force",
                    ));
                }
                let (force, gap, status) = joint.live(j, &sub);
                let same = |a: Real, b: Real| a.to_bits() == b.to_bits();
                let matches = same(force.normal, s.force.normal)
                    && same(force.shear.x, s.force.shear.x)
                    && same(force.shear.y, s.force.shear.y)
                    && same(gap, s.gap)
                    && status == s.status;
                if !matches {
                    return Err(corrupt(
                        &format!("contacts[{k}].subcontacts[{j}]"),
                        "forces differ from those of the joint stepped as a whole",
                    ));
                }
            }
            subs.push(sub);
            if kept {
                dashpots.push(s.dashpot);
            }
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
            spread_energy: e.spread_energy,
            cells: Default::default(),
            joint,
        });
        if small {
            small_refs.push(SmallReference {
                ref_a: e.reference_centroids.0,
                ref_b: e.reference_centroids.1,
                ref_host_rotation: e.reference_host_rotation,
            });
        }
        references.push(ContactReference {
            area: e.area,
            bound_area: e.bound_area,
            side: match e.kind {
                ContactKind::FaceFace { .. } => hinge,
                ContactKind::Nodes => ContactReference::nodes(node_keys),
            },
        });
        wrenches.push(e.wrench);
    }
    Ok(ContactStore {
        pairs,
        references,
        wrenches,
        small_refs,
        small_kept: small,
        subs,
        sub_dashpots: dashpots,
        dashpots_kept: kept,
    })
}

impl<L> Model<L>
where
    L: ConstitutiveLaw + Serialize + DeserializeOwned,
    L::State: Serialize + DeserializeOwned,
{
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
    /// // A checkpoint of one law type does not load as another.
    /// let err = Model::<LinearElastic>::from_checkpoint_str(&model.to_checkpoint_string()?).unwrap_err();
    /// assert!(matches!(err, Error::CheckpointLawType { .. }));
    /// # Ok::<(), voussoir::Error>(())
    /// ```
    ///
    /// # What is checked
    ///
    /// A checkpoint is trusted only as far as it can be checked; what can be recomputed is
    /// compared with what construction computes:
    ///
    /// - **Checksum**: the file stores the CRC-32 of its content (`"checksum": "crc32:…"`; the
    ///   compact JSON of the document without that field, keys sorted). Any change to a value,
    ///   by corruption or by hand, gives [`Error::CheckpointChecksum`]; formatting (spaces, key
    ///   order) does not count. Edit a checkpoint on purpose, then
    ///   [`reseal_checkpoint`](super::reseal_checkpoint) it.
    /// - **Version and law type**: another format version is refused naming both versions (files
    ///   of version 9, which have no checksum, included); a file written by a model of another
    ///   law type gives [`Error::CheckpointLawType`] naming both (a law type is named by its
    ///   serde name: `CoulombSlip`, `LinearElastic`, `AnyLaw`, or a custom law's struct or enum
    ///   name; a law whose `Deserialize` gives no name is not checked).
    /// - **Blocks** ([`Error::CheckpointBlock`]): each face's normal, offset and area, the edges
    ///   and the radius are recomputed from the vertices and face loops as construction does and
    ///   must match bit for bit; every vertex lies inside every face (convexity); the volume, the
    ///   centroid (the body frame's origin) and the principal inertia per unit density must be
    ///   those of the vertices (to round-off, 10⁻⁹ of the volume, 10⁻⁶ of the inertia); the
    ///   mass, volume and principal inertia must be those of the shape and the (positive)
    ///   density, bit for bit. The angular momentum `L` is the state the integrator advances;
    ///   the angular velocity must be `I⁻¹L` in the world frame to within the rotation of one
    ///   step (relative `10⁻⁹ + 2|ω|Δt`).
    /// - **Time step and counters** ([`Error::Checkpoint`] at `dt`, `critical`, `step`, …): `dt`
    ///   must be positive and what the parameters make of the stored critical step (`safety ×
    ///   critical`, or the fixed step); the critical step is re-evaluated from the blocks and
    ///   contacts and must agree with the stored one within 10 %; the step and detection counts
    ///   must not exceed 2⁵³ (so they never overflow); time and the impact refinement's state
    ///   must be finite and not negative.
    /// - **Contacts**: block, face, law and sub-contact indices in range and sorted; each
    ///   contact's law must be the one the law table gives its blocks' materials
    ///   ([`Error::CheckpointContactLaw`]); axes orthonormal; spring moments those of the
    ///   sub-contact forces; areas not negative.
    /// - **Laws and parameters**: validated as [`Model::set_joint_law`] and [`Model::new`] do.
    ///
    /// Everything else (positions, velocities, forces, law states, energies) is state, restored
    /// as stored, so that a valid checkpoint continues bit for bit.
    ///
    /// # Errors
    /// [`Error::Checkpoint`] for truncated, corrupt or inconsistent text, naming where;
    /// [`Error::CheckpointChecksum`], [`Error::CheckpointLawType`],
    /// [`Error::CheckpointContactLaw`] and [`Error::CheckpointBlock`] as above; never a panic.
    pub fn from_checkpoint_str(text: &str) -> Result<Self> {
        let mut snap = parse_snapshot::<L>(text)?;
        let tested = check_snapshot(&snap)?;
        let small = snap.params.mode == DisplacementMode::Small;
        let storage = into_storage(std::mem::take(&mut snap.contacts), snap.version, small)?;
        check_contacts(&snap, &storage, &tested)?;
        let pending_detection = snap.pending_detection;
        let mut model = restore_blocks(snap.params, std::mem::take(&mut snap.blocks), snap.dt.max(snap.drift))?;
        restore_contacts(&mut model, std::mem::take(&mut snap.joints), snap.damping, storage)?;
        check_slacks(&model.state.blocks, &tested, &model.state.params.contact)?;
        model.state.found.tested = tested;
        restore_excitations(&mut model, &mut snap)?;
        restore_run(&mut model, &snap);
        let redetect = !model.state.clock.started || pending_detection;
        if redetect {
            model.state.changes.insert(crate::model::changes::Changes::DETECTION);
        }
        model.state.rebuild_block_index(&mut model.pipeline);
        if !redetect {
            restore_bounds(&mut model, &snap.bounds)?;
            let from_bounds = model.state.integrator.critical_step(&model.pipeline.bounds);
            check_time_step(&snap.params, snap.dt, snap.critical, from_bounds)?;
        }
        model.state.clock.dt = snap.dt;
        model.state.clock.critical = snap.critical;
        Ok(model)
    }

    /// Reads a checkpoint file.
    ///
    /// # Errors
    /// [`Error::Io`] naming the file; [`Error::Checkpoint`] for corrupt content.
    pub fn load_checkpoint(path: &Path) -> Result<Self> {
        let text = crate::file::read_text(path)?;
        Self::from_checkpoint_str(&text)
    }
}

/// serde's error at its path.
fn typed_error(e: serde_path_to_error::Error<serde_json::Error>) -> Error {
    Error::Checkpoint {
        path: e.path().to_string(),
        message: e.inner().to_string(),
    }
}

/// Phase 1, the document: JSON without a key given twice, the format and version (first, so
/// that a file of another version is named as such rather than failing on the first field that
/// changed), the checksum, the law type (before the laws, which would fail on the first field
/// that differs), then the typed snapshot.
fn parse_snapshot<L>(text: &str) -> Result<Snapshot<L>>
where
    L: ConstitutiveLaw + DeserializeOwned,
    L::State: DeserializeOwned,
{
    // A key given twice would be read as its last value by `Value`.
    crate::json_keys::refuse_duplicate_keys(text)?;
    let mut value: serde_json::Value =
        serde_json::from_str(text).map_err(|e| corrupt("(document)", &format!("not a complete JSON document: {e}")))?;
    let Ok(header) = Header::deserialize(&value) else {
        // Let the typed reading say which field is wrong.
        return Err(match serde_path_to_error::deserialize::<_, Snapshot<L>>(value) {
            Err(e) => typed_error(e),
            Ok(_) => corrupt("format", &format!("not a {FORMAT}")),
        });
    };
    if header.format != FORMAT {
        return Err(corrupt("format", &format!("\"{}\" is not a {FORMAT}", header.format)));
    }
    if !(OLDEST_VERSION..=VERSION).contains(&header.version) {
        return Err(corrupt(
            "version",
            &format!(
                "{FORMAT} version {}; this build reads versions {OLDEST_VERSION} to {VERSION}",
                header.version
            ),
        ));
    }
    // The checksum over the rest: any value changed since the save is refused here.
    let stored = match value.as_object_mut().and_then(|m| m.remove(CHECKSUM)) {
        Some(serde_json::Value::String(s)) => s,
        Some(_) => return Err(corrupt(CHECKSUM, "not a string")),
        None => return Err(corrupt(CHECKSUM, "missing: the file is truncated or was edited")),
    };
    let computed = checksum_of(&value);
    if stored != computed {
        return Err(Error::CheckpointChecksum { stored, computed });
    }
    if let (Some(written), Some(loading)) = (header.law_type.as_deref(), law_type_name::<L>()) {
        if written != loading {
            return Err(Error::CheckpointLawType {
                written: written.into(),
                loading: loading.into(),
            });
        }
    }
    let snap: Snapshot<L> = serde_path_to_error::deserialize(value).map_err(typed_error)?;
    if snap.format != FORMAT || !(OLDEST_VERSION..=VERSION).contains(&snap.version) {
        return Err(corrupt("format", &format!("not a {FORMAT} version {VERSION}")));
    }
    Ok(snap)
}

/// Phase 4, the blocks: each restored (its shape rebuilt) and its derived data checked against
/// its vertices and density, its initial pose a finite unit pose, its angular velocity the
/// inertia's image of its angular momentum to within the rotation of one `step`; added to a
/// new model of `params`, blocks of one shape sharing it again (a wall's bricks).
fn restore_blocks<L: ConstitutiveLaw>(
    params: ModelParameters,
    blocks: Vec<crate::block::RigidBlock>,
    step: Real,
) -> Result<Model<L>> {
    let mut model = Model::new(params)?;
    for (i, mut b) in blocks.into_iter().enumerate() {
        b.restore()
            .map_err(|e| corrupt(&format!("blocks[{i}]"), &e.to_string()))?;
        let block_error = |field: String, message: String| Error::CheckpointBlock {
            block: BlockId(i as u32),
            name: b.name().to_owned(),
            field,
            message,
        };
        b.check_derived()
            .map_err(|(field, message)| block_error(field, message))?;
        if !is_unit_pose(b.initial_pose()) {
            return Err(block_error(
                "initial_pose".into(),
                "is not a finite pose with a unit rotation".into(),
            ));
        }
        let s = *b.state();
        let from_w = b.world_inertia_times(s.angular_velocity);
        let tolerance =
            (1e-9 + 2.0 * s.angular_velocity.length() * step) * s.angular_momentum.length().max(from_w.length());
        // (Written so that a NaN is refused too.)
        let consistent = (from_w - s.angular_momentum).length() <= tolerance;
        if !consistent {
            return Err(block_error(
                "state.angular_velocity".into(),
                format!(
                    "{:?} disagrees with the angular momentum {:?} (the inertia gives {:?} for it)",
                    s.angular_velocity, s.angular_momentum, from_w
                ),
            ));
        }
        model.add_block(b)?;
    }
    crate::block::share_shapes(&mut model.state.blocks);
    Ok(model)
}

/// Phase 5, the contacts into the model with the laws and the integrator: each contact's
/// local faces and cell summary re-derived, its stored spring moments checked against its
/// sub-contact forces (each normal force within its cell's rectangle), its cells' half sizes
/// finite lengths, and every sub-contact's elastic energy (and their sum) finite.
fn restore_contacts<L: ConstitutiveLaw>(
    model: &mut Model<L>,
    laws: crate::law::LawTable<L>,
    damping: crate::integrate::Damping,
    storage: ContactStore<L::State>,
) -> Result<()> {
    model.state.laws = laws;
    model.state.integrator = Box::new(CentralDifference::new(damping));
    model.state.contacts = storage;
    for (k, p) in model.state.contacts.pairs.iter_mut().enumerate() {
        let (a, b) = (&model.state.blocks[p.a as usize], &model.state.blocks[p.b as usize]);
        p.cache_local_faces(Block::shape(a), Block::shape(b));
        p.cells = crate::contact::CellSummary::of(&model.state.contacts.subs[p.range()]);
        if p.joint.is_partial() {
            let subs = &model.state.contacts.subs[p.range()];
            // A hinge's record was read with it (checked above).
            let Some(hinge) = model.state.contacts.references[k].hinge_mut() else {
                return Err(corrupt(
                    &format!("contacts[{k}].joint"),
                    "a joint open in part without its hinge record",
                ));
            };
            hinge.measure(subs, &p.cells, &p.joint);
            // Its open cells stepped as a whole are open over their box at the joint's gap.
            if p.joint.ends != SpanEnds::Closed && !crate::contact::JointLevel::open_over(hinge.open_box, p.joint.gap) {
                return Err(corrupt(
                    &format!("contacts[{k}].joint"),
                    "steps open cells as a whole where its gap closes them",
                ));
            }
        }
        // Dashpot forces still held must be seen (and their work booked) by the next step.
        p.dashpots |= model.state.contacts.dashpots_kept
            && model.state.contacts.sub_dashpots[p.range()]
                .iter()
                .any(|d| *d != Vector::ZERO);
        // A cell's half sizes are lengths: finite (a huge number read into an `f32` is
        // infinite, and would be saved as `null`) and not negative.
        if let Some(j) = model.state.contacts.subs[p.range()]
            .iter()
            .position(|s| !s.half.iter().all(|h| h.is_finite() && *h >= 0.0))
        {
            return Err(corrupt(
                &format!("contacts[{k}].subcontacts[{j}].half"),
                "must be finite lengths, not negative",
            ));
        }
        // The stored spring moments are those of the stored forces, up to summation order,
        // with each normal force placed within its cell's rectangle (where the step put it,
        // `contact/spread.rs`, at the poses before the step's advance).
        let law = &model.state.laws.laws()[p.law as usize];
        let subs = &model.state.contacts.subs[p.range()];
        // A joint stepped as a whole: its cells as they stand.
        let live: Vec<SubContact<L::State>>;
        let subs = if p.joint.active {
            live = subs
                .iter()
                .enumerate()
                .map(|(i, s)| {
                    let mut cell = s.clone();
                    (cell.force, cell.gap, cell.status) = p.joint.live(i, s);
                    cell
                })
                .collect();
            &live[..]
        } else {
            subs
        };
        let (anchored, _) = p.springs_of(subs, law, None);
        let reach = |k: usize| subs.iter().map(|s| s.force.normal.max(0.0) * s.half()[k]).sum::<Real>();
        let scale = 1e-9 * (anchored.force.length() + anchored.per_x.length() + anchored.per_y.length());
        let placed = ForceMoments {
            force: p.springs.force,
            per_x: anchored.per_x,
            per_y: anchored.per_y,
        };
        let within = |offset: Vector, reach: Real| offset.length() <= reach * (1.0 + 1e-9) + scale;
        let consistent = p.springs.force.is_finite()
            && placed.matches(&anchored)
            && within(p.springs.per_x - anchored.per_x, reach(0))
            && within(p.springs.per_y - anchored.per_y, reach(1))
            && p.spread_energy >= 0.0
            && p.spread_energy.is_finite();
        if !consistent {
            return Err(corrupt(
                &format!("contacts[{k}].springs"),
                "inconsistent with the sub-contact forces",
            ));
        }
    }
    // The joints' elastic energy is saved with the model: it must be a number (a sub-contact
    // of a tiny area, or a huge force, would make it infinite and the saved file unreadable).
    for (k, p) in model.state.contacts.pairs.iter().enumerate() {
        let law = &model.state.laws.laws()[p.law as usize];
        let subs = &model.state.contacts.subs[p.range()];
        if let Some(j) = subs
            .iter()
            .enumerate()
            .position(|(i, s)| !law.elastic_energy(s.area, &p.joint.live(i, s).0, &s.state).is_finite())
        {
            return Err(corrupt(
                &format!("contacts[{k}].subcontacts[{j}]"),
                "forces and area whose elastic energy is not finite",
            ));
        }
    }
    if !model.elastic_energy().is_finite() {
        return Err(corrupt("contacts", "the joints' elastic energy is not finite"));
    }
    Ok(())
}

/// Phase 6, the base motions and load histories, each started at a finite time before the
/// checkpoint's and set as `set_base_motion` and `set_load_history` set them (against the
/// blocks' fixity).
fn restore_excitations<L: ConstitutiveLaw>(model: &mut Model<L>, snap: &mut Snapshot<L>) -> Result<()> {
    for (k, m) in std::mem::take(&mut snap.motions).into_iter().enumerate() {
        let block = BlockId(m.block);
        if !(m.start.is_finite() && m.start <= snap.time) {
            return Err(corrupt(
                &format!("motions[{k}].start"),
                "not a finite time before the checkpoint's",
            ));
        }
        let start = m.start;
        model
            .set_base_motion(block, Some(m.motion))
            .map_err(|e| corrupt(&format!("motions[{k}]"), &e.to_string()))?;
        if let Some(last) = model.state.excitations.motions.iter_mut().find(|a| a.block == block.0) {
            last.start = start;
        }
    }
    for (k, h) in std::mem::take(&mut snap.load_histories).into_iter().enumerate() {
        if !(h.start.is_finite() && h.start <= snap.time) {
            return Err(corrupt(
                &format!("load_histories[{k}].start"),
                "not a finite time before the checkpoint's",
            ));
        }
        let (block, start) = (BlockId(h.block), h.start);
        model
            .set_load_history(block, Some(h.load))
            .map_err(|e| corrupt(&format!("load_histories[{k}]"), &e.to_string()))?;
        if let Some(last) = model
            .state
            .excitations
            .load_histories
            .iter_mut()
            .find(|a| a.block == block.0)
        {
            last.start = start;
        }
    }
    Ok(())
}

/// Phase 7, the run's state as stored: reference poses, drift and impact refinement, counters,
/// clock, energies, the last reactions and damping forces; no change owed.
fn restore_run<L: ConstitutiveLaw>(model: &mut Model<L>, snap: &Snapshot<L>) {
    let state = &mut model.state;
    state.found.ref_poses.clone_from(&snap.ref_poses);
    state.clock.drift = if snap.drift > 0.0 && snap.started {
        snap.drift
    } else {
        0.0
    };
    state.clock.refine_until = snap.refine_until;
    state.clock.refine_omega2 = snap.refine_omega2;
    state.clock.refine_travel = snap.refine_travel;
    state.clock.refining.clone_from(&snap.refining);
    state.clock.refining.sort_unstable();
    state.clock.refining.dedup();
    state.clock.step = snap.step;
    state.clock.time = snap.time;
    state.energy = snap.energy;
    state.clock.started = snap.started;
    state.unbalanced_ratio = snap.unbalanced_ratio.unwrap_or(Real::INFINITY);
    state.found.detections = snap.detections;
    for (r, &(reaction, damping)) in state.records.iter_mut().zip(&snap.last_forces) {
        r.reaction = reaction;
        r.damping = damping;
    }
    state.changes.clear();
}

/// Phase 8, the stability bounds (when no detection is owed): one finite bound per block, none
/// of a block in contact far below what the blocks and contacts give now (the stored ones are
/// as of their last evaluation: contacts that shrank since leave them higher, a contact grows
/// by up to 5 % before they are re-evaluated); the stored ones are then taken, bit for bit.
///
/// A block without contacts is not checked. The whole evaluation gives it the bound of a
/// contact over its largest face, a placeholder for its landing
/// (`integrate/stability.rs`), while a step that loses its last contact keeps the bound
/// it had: a lost contact only makes the step safer, no spring acts on a block in flight, and
/// the contact it lands on is new, so its bound is evaluated then. A tetrahedron that bounced
/// off a slab on a vertex kept 2.7e5 1/s² where the placeholder is 1.3e8, and its checkpoint
/// was refused.
fn restore_bounds<L: ConstitutiveLaw>(model: &mut Model<L>, bounds: &[Real]) -> Result<()> {
    if bounds.len() != model.state.blocks.len() {
        return Err(corrupt("bounds", "one bound per block expected"));
    }
    if let Some(i) = bounds.iter().position(|w| !(w.is_finite() && *w >= 0.0)) {
        return Err(corrupt(&format!("bounds[{i}]"), "a finite value ≥ 0 expected"));
    }
    let bound_areas: Vec<Real> = model.state.contacts.references.iter().map(|r| r.bound_area).collect();
    // An error here is a fixed step above the re-evaluated limit: checked by the caller.
    let _ = model.state.refresh_time_step(&mut model.pipeline);
    for (r, area) in model.state.contacts.references.iter_mut().zip(bound_areas) {
        r.bound_area = area;
    }
    let offsets = &model.pipeline.block_offsets;
    for (i, (stored, fresh)) in bounds.iter().zip(&model.pipeline.bounds).enumerate() {
        let in_contact = offsets[i + 1] > offsets[i];
        if in_contact && *stored < MIN_STORED_BOUND * fresh.omega_squared {
            return Err(corrupt(
                &format!("bounds[{i}]"),
                &format!(
                    "{stored} 1/s² in the file, the blocks and contacts give {} 1/s²",
                    fresh.omega_squared
                ),
            ));
        }
    }
    for (bound, stored) in model.pipeline.bounds.iter_mut().zip(bounds) {
        bound.omega_squared = *stored;
    }
    Ok(())
}
