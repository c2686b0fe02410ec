//! The checks of a checkpoint's snapshot before a model is rebuilt from it: the snapshot apart
//! from its contacts (phase 2), the contacts against the blocks, laws and tested pairs (phase
//! 3), the run's counters and clock, and the stored step against the stored bounds (see
//! `read.rs`).

use super::tested::tested_pairs;
use super::{Snapshot, MAX_COUNT};
use crate::block::Block;
use crate::contact::{ContactStore, SubContact};
use crate::error::{Error, Result};
use crate::geometry::SubKey;
use crate::ids::BlockId;
use crate::integrate::{CriticalStep, TimeStep};
use crate::law::ConstitutiveLaw;
use crate::math::{is_finite_vector, is_unit_pose, Real, Vector};
use crate::model::ModelParameters;

/// `Error::Checkpoint` at `path`.
pub(super) fn corrupt(path: &str, message: &str) -> Error {
    Error::Checkpoint {
        path: path.into(),
        message: message.into(),
    }
}

/// Phase 2, the snapshot apart from its contacts: parameters, damping and laws validated as
/// `Model::new`, `set_damping` and `set_joint_law` do (serde only checks their shape); the
/// reference poses; the tested pairs (returned, checked); one pair of last forces per block;
/// the run's counters and clock.
pub(super) fn check_snapshot<L: ConstitutiveLaw>(
    snap: &Snapshot<L>,
) -> Result<Vec<crate::model::detection::TestedPair>> {
    snap.params.validate()?;
    snap.damping.validate()?;
    let n = snap.blocks.len();
    if !snap.joints.check() {
        return Err(corrupt("joints", "law index out of range"));
    }
    for (k, law) in snap.joints.laws().iter().enumerate() {
        crate::law::check_law(law).map_err(|e| corrupt(&format!("joints.laws[{k}]"), &e.to_string()))?;
    }
    if snap.ref_poses.len() != n {
        return Err(corrupt("ref_poses", "one pose per block expected"));
    }
    if let Some(i) = snap.ref_poses.iter().position(|p| !is_unit_pose(p)) {
        return Err(corrupt(
            &format!("ref_poses[{i}]"),
            "not a finite pose with a unit rotation",
        ));
    }
    let tested = tested_pairs(&snap.tested, n)?;
    if snap.last_forces.len() != n {
        return Err(corrupt("last_forces", "one pair of wrenches per block expected"));
    }
    check_run_state(snap)?;
    Ok(tested)
}

/// Phase 3, the contacts against the blocks, the laws and the tested pairs: every contact
/// between blocks the narrow phase tested, finite wrenches, faces and nodes that exist, axes
/// orthonormal, contacts sorted with contiguous sub-contact ranges covering every sub-contact,
/// each contact's law the one detection gives its pair, areas not negative.
pub(super) fn check_contacts<L: ConstitutiveLaw>(
    snap: &Snapshot<L>,
    storage: &ContactStore<L::State>,
    tested: &[crate::model::detection::TestedPair],
) -> Result<()> {
    let ContactStore {
        pairs,
        references,
        wrenches,
        subs,
        ..
    } = storage;
    let n = snap.blocks.len();
    if let Some(k) = pairs
        .iter()
        .position(|p| tested.binary_search_by_key(&(p.a, p.b), |t| (t.a, t.b)).is_err())
    {
        return Err(corrupt(
            &format!("contacts[{k}].blocks"),
            "a contact between blocks the narrow phase did not test",
        ));
    }
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
            crate::geometry::ContactKind::Nodes => {
                (p.a as usize) < n
                    && (p.b as usize) < n
                    && (p.first as usize + p.count as usize) <= subs.len()
                    && references[k].node_keys().len() == p.count as usize
                    && nodes_fit(
                        (snap.blocks[p.a as usize].shape(), snap.blocks[p.b as usize].shape()),
                        &subs[p.range()],
                        references[k].node_keys(),
                    )
            }
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
        // The law is the one detection gives the pair: the interface's own, else the one
        // its materials map to. A law set since the last detection takes effect at the next
        // step's full detection (`pending_detection`), so the contact may still hold the
        // law it was detected with (any law of the table).
        let (material_a, material_b) = (
            snap.blocks[p.a as usize].material(),
            snap.blocks[p.b as usize].material(),
        );
        let expected = snap
            .joints
            .index_for((BlockId(p.a), material_a), (BlockId(p.b), material_b));
        if expected != Some(p.law) && !snap.pending_detection {
            return Err(Error::CheckpointContactLaw {
                contact: k,
                a: BlockId(p.a),
                b: BlockId(p.b),
                material_a,
                material_b,
                law: p.law,
                expected: expected.map_or_else(|| "no law".into(), |e| format!("law {e}")),
            });
        }
        next = end;
    }
    if next != subs.len() {
        return Err(corrupt("contacts", "sub-contacts outside every contact"));
    }
    if let Some(i) = subs.iter().position(|s| s.area < 0.0) {
        let k = pairs.partition_point(|p| p.first as usize + p.count as usize <= i);
        let j = i - pairs[k].first as usize;
        return Err(corrupt(
            &format!("contacts[{k}].subcontacts[{j}].area"),
            "negative area",
        ));
    }
    Ok(())
}

/// Whether `a` and `b` are unit vectors normal to each other, to round-off (1e-9).
pub(super) fn orthonormal(a: Vector, b: Vector) -> bool {
    let tolerance = 1e-9;
    (a.length_squared() - 1.0).abs() <= tolerance
        && (b.length_squared() - 1.0).abs() <= tolerance
        && a.dot(b).abs() <= tolerance
}

/// The run's counters, clock and step: finite, not negative, and counters far from overflow.
pub(super) fn check_run_state<L: ConstitutiveLaw>(snap: &Snapshot<L>) -> Result<()> {
    let bad = |path: &str, message: String| {
        Err(Error::Checkpoint {
            path: path.into(),
            message,
        })
    };
    for (path, count) in [("step", snap.step), ("detections", snap.detections)] {
        if count > MAX_COUNT {
            return bad(path, format!("{count} is beyond any run (at most 2^53 = {MAX_COUNT})"));
        }
    }
    let positive_dt = snap.dt.is_finite() && (snap.dt > 0.0 || (!snap.started && snap.dt == 0.0));
    if !positive_dt {
        return bad("dt", format!("{} s is not a positive, finite time step", snap.dt));
    }
    for (path, v) in [
        ("time", snap.time),
        ("drift", snap.drift),
        ("refine_until", snap.refine_until),
        ("refine_omega2", snap.refine_omega2),
    ] {
        if !(v.is_finite() && v >= 0.0) {
            return bad(path, format!("{v} is not finite and not negative"));
        }
    }
    if let Some(c) = snap.critical {
        if !(c.dt.is_finite() && c.dt > 0.0 && c.omega_max.is_finite() && c.omega_max >= 0.0) {
            return bad("critical", format!("{c:?} is not a positive, finite step"));
        }
        if c.block.index() >= snap.blocks.len() {
            return bad("critical.block", format!("{} does not exist", c.block));
        }
    }
    if let Some(&(a, b)) = snap
        .refining
        .iter()
        .find(|&&(a, b)| a >= b || b as usize >= snap.blocks.len())
    {
        return bad("refining", format!("({a}, {b}) is not a pair of blocks"));
    }
    Ok(())
}

/// The stored step against the parameters and the critical step the stored bounds give
/// (`fresh`): the stored critical step equal to it, the step what the parameters make of the
/// stored critical step, bit for bit.
pub(super) fn check_time_step(
    params: &ModelParameters,
    dt: Real,
    critical: Option<CriticalStep>,
    fresh: Option<CriticalStep>,
) -> Result<()> {
    let bad = |path: &str, message: String| {
        Err(Error::Checkpoint {
            path: path.into(),
            message,
        })
    };
    let expected = match (critical, fresh) {
        (Some(c), Some(f)) => {
            if c != f {
                return bad(
                    "critical.dt",
                    format!("{} s in the file, the stored bounds give {} s", c.dt, f.dt),
                );
            }
            match params.time_step {
                TimeStep::Auto { safety } => safety * c.dt,
                TimeStep::Fixed(fixed) => fixed,
            }
        }
        (None, None) => match params.time_step {
            TimeStep::Auto { .. } => dt,
            TimeStep::Fixed(fixed) => fixed,
        },
        (Some(_), None) => return bad("critical", "in the file, but nothing in the model is stiff".into()),
        (None, Some(f)) => return bad("critical", format!("missing, the blocks and contacts give {} s", f.dt)),
    };
    if dt.to_bits() != expected.to_bits() {
        return bad(
            "dt",
            format!("{dt} s in the file, the parameters and the critical step give {expected} s"),
        );
    }
    Ok(())
}

/// Whether the sub-contacts of a node contact between blocks of shapes `shapes` name nodes of
/// those shapes (their `keys`) and faces of the other block (the face each was last pressed out
/// of, `plane.x`).
pub(super) fn nodes_fit<S>(
    shapes: (&crate::geometry::Polyhedron, &crate::geometry::Polyhedron),
    subs: &[SubContact<S>],
    keys: &[SubKey],
) -> bool {
    subs.iter().zip(keys).all(|(s, key)| {
        let id = crate::geometry::NodeId::from_key(*key);
        let (host, other) = if id.on_b { (shapes.1, shapes.0) } else { shapes };
        let face = s.plane.x;
        id.fits(host) && face >= 0.0 && face.fract() == 0.0 && (face as usize) < other.faces().len() && s.plane.y == 0.0
    })
}
