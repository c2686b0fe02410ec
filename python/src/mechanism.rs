//! The mechanism classifier from Python (`voussoir::analysis::classify_joints`): which joints
//! hinge, about which edge, and which slide.

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PySequence};
use voussoir::analysis::{classify_joints as classify, HingeSide, JointRef, MechanismCriteria};
use voussoir::build::arch::Arch;

use crate::blocks::arch_spec;
use crate::convert::{array1, array_n3, vec3, Int};
use crate::errors::{bad, OrPy};
use crate::model::PyModel;

/// classify_joints(model, joints, *, open_fraction=0.5, edge_band=0.25, slip=0.0005)
/// --
///
/// Measures the given joints of the model as it stands and names the mechanism (Rust:
/// ``voussoir::analysis::classify_joints``). A joint is a dict ``{"blocks": (a, b),
/// "intrados": (x, y, z), "extrados": (x, y, z)}`` with an optional ``"index"`` (its label;
/// default: its place in the list): its two blocks and the two edge points across it at the
/// blocks' initial pose (m, world; they move with block ``a``). ``voussoir.build.arch_joints``
/// gives an arch's.
///
/// Per joint: the **open fraction** (the share of its area without compression; 1 when the
/// blocks do not touch), the **compression position** (the centre of the normal forces from
/// the intrados, 0, to the extrados, 1; NaN when nothing is compressed), the area-weighted
/// mean accumulated **slip** (m) and the total **normal force** (N). A joint **hinges** when
/// at least ``open_fraction`` of it is open and its compression centre lies within
/// ``edge_band`` of an edge (about that edge); it **slides** when its mean slip exceeds
/// ``slip`` (m).
///
/// Returns a dict: ``joint`` (n,) labels, ``open_fraction``, ``compression_position``,
/// ``slip``, ``normal_force`` (n,) arrays, ``hinge`` a list of ``None``, ``"intrados"`` or
/// ``"extrados"``, ``sliding`` (n,) bools, ``hinges`` a list of ``(joint, side)``,
/// ``sliding_joints`` a list of labels, and ``description``, e.g. ``"hinges 2e 5i 9i 13e"``.
///
/// >>> import voussoir as vs
/// >>> m = vs.Model(gravity=(0, -9.81, 0))
/// >>> m.set_joint_law(0, 0, vs.CoulombSlip.dry(4e9, 1.6e9, 35.0))
/// >>> _ = m.add_blocks(vs.build.arch())
/// >>> m.run_steps(10)  # built exactly touching: the joints close under the weight
/// True
/// >>> r = vs.classify_joints(m, vs.build.arch_joints())
/// >>> len(r["joint"]), r["description"]  # the 14 joints of 13 voussoirs, none hinged
/// (14, 'no hinges')
#[pyfunction]
#[pyo3(signature = (model, joints, *, open_fraction=0.5, edge_band=0.25, slip=5e-4))]
pub fn classify_joints<'py>(
    py: Python<'py>,
    model: PyRef<'py, PyModel>,
    joints: &Bound<'py, PyAny>,
    open_fraction: f64,
    edge_band: f64,
    slip: f64,
) -> PyResult<Bound<'py, PyAny>> {
    if !(0.0..=1.0).contains(&open_fraction) {
        return Err(bad(format!("open_fraction = {open_fraction}: must lie in [0, 1]")));
    }
    if !(0.0..=0.5).contains(&edge_band) {
        return Err(bad(format!("edge_band = {edge_band}: must lie in [0, 0.5]")));
    }
    if !(slip.is_finite() && slip >= 0.0) {
        return Err(bad(format!("slip = {slip} m: must be finite and not negative")));
    }
    let criteria = MechanismCriteria {
        open_fraction,
        edge_band,
        slip,
    };
    let (states, mechanism) = {
        let this = model.lock(py);
        let refs = joint_refs(joints, this.model.blocks().len())?;
        classify(&this.model, &refs, &criteria)
    };
    let side = |s: HingeSide| match s {
        HingeSide::Intrados => "intrados",
        HingeSide::Extrados => "extrados",
    };
    let d = PyDict::new(py);
    d.set_item("joint", array1(py, states.iter().map(|s| s.joint as i64).collect()))?;
    d.set_item(
        "open_fraction",
        array1(py, states.iter().map(|s| s.open_fraction).collect()),
    )?;
    d.set_item(
        "compression_position",
        array1(py, states.iter().map(|s| s.compression_position).collect()),
    )?;
    d.set_item("slip", array1(py, states.iter().map(|s| s.slip).collect()))?;
    d.set_item(
        "normal_force",
        array1(py, states.iter().map(|s| s.normal_force).collect()),
    )?;
    d.set_item("hinge", states.iter().map(|s| s.hinge.map(side)).collect::<Vec<_>>())?;
    d.set_item("sliding", array1(py, states.iter().map(|s| s.sliding).collect()))?;
    d.set_item(
        "hinges",
        mechanism
            .hinges
            .iter()
            .map(|h| (h.joint, side(h.side)))
            .collect::<Vec<_>>(),
    )?;
    d.set_item("sliding_joints", mechanism.sliding_joints.clone())?;
    d.set_item("description", mechanism.describe())?;
    crate::convert::result(py, "Mechanism", d)
}

/// The joints from Python: a list of dicts `{"blocks", "intrados", "extrados", "index"?}`.
pub(crate) fn joint_refs(obj: &Bound<'_, PyAny>, count: usize) -> PyResult<Vec<JointRef>> {
    let list = obj.cast::<PySequence>().map_err(|_| {
        bad("joints: expected a list of {\"blocks\": (a, b), \"intrados\": (x, y, z), \"extrados\": (x, y, z)} dicts")
    })?;
    let mut refs = Vec::with_capacity(list.len()?);
    for (k, item) in list.try_iter()?.enumerate() {
        let item = item?;
        let d = item
            .cast::<PyDict>()
            .map_err(|_| bad(format!("joints[{k}]: expected a dict with blocks, intrados, extrados")))?;
        let get = |key: &str| -> PyResult<Bound<'_, PyAny>> {
            d.get_item(key)?.ok_or_else(|| {
                bad(format!(
                    "joints[{k}]: missing {key:?} (expected blocks, intrados, extrados)"
                ))
            })
        };
        let blocks = get("blocks")?;
        let pair = blocks
            .cast::<PySequence>()
            .map_err(|_| bad(format!("joints[{k}].blocks: expected two block indices (a, b)")))?;
        if pair.len()? != 2 {
            return Err(bad(format!("joints[{k}].blocks: expected two block indices (a, b)")));
        }
        let a = pair
            .get_item(0)?
            .extract::<Int>()?
            .block(&format!("joints[{k}].blocks[0]"), count)?;
        let b = pair
            .get_item(1)?
            .extract::<Int>()?
            .block(&format!("joints[{k}].blocks[1]"), count)?;
        if a == b {
            return Err(bad(format!(
                "joints[{k}].blocks: a joint needs two different blocks, got {} twice",
                a.0
            )));
        }
        let index = match d.get_item("index")? {
            Some(i) => i
                .extract::<Int>()?
                .at_most(&format!("joints[{k}].index"), u32::MAX.into())? as usize,
            None => k,
        };
        let intrados = vec3(&get("intrados")?, &format!("joints[{k}].intrados"))?;
        let extrados = vec3(&get("extrados")?, &format!("joints[{k}].extrados"))?;
        if !(intrados.is_finite() && extrados.is_finite()) || (extrados - intrados).length() == 0.0 {
            return Err(bad(format!(
                "joints[{k}]: intrados and extrados must be two distinct finite points"
            )));
        }
        refs.push(JointRef {
            index,
            blocks: (a, b),
            intrados,
            extrados,
        });
    }
    Ok(refs)
}

/// arch_joints(*, span=1.2, rise=0.4, thickness=0.2, width=0.15, voussoirs=13, density=2446.48, abutment_outer_width=0.2, abutment_depth=0.3, voussoir_material=0, abutment_material=0, first_block=0)
/// --
///
/// The joints of the arch that ``voussoir.build.arch`` builds with the same arguments, for
/// ``classify_joints``: one dict per joint, from the left springing to the right, with
/// ``index`` (0 at the left springing), ``blocks`` (the block on its left and on its right,
/// counted from ``first_block``, the index the arch's first block got in the model),
/// ``intrados`` and ``extrados`` (its edge points at mid-width, m). Also ``points``: the four
/// corners of the joint face (m × 3), intrados first.
///
/// >>> import voussoir as vs
/// >>> j = vs.build.arch_joints()
/// >>> len(j), j[0]["blocks"], j[-1]["blocks"]
/// (14, (0, 1), (13, 14))
#[pyfunction]
#[pyo3(signature = (*, span=1.2, rise=0.4, thickness=0.2, width=0.15, voussoirs=13, density=2446.4831804281343,
    abutment_outer_width=0.20, abutment_depth=0.30, voussoir_material=0, abutment_material=0, first_block=0))]
#[allow(clippy::too_many_arguments)]
pub fn arch_joints<'py>(
    py: Python<'py>,
    span: f64,
    rise: f64,
    thickness: f64,
    width: f64,
    voussoirs: i64,
    density: f64,
    abutment_outer_width: f64,
    abutment_depth: f64,
    voussoir_material: i64,
    abutment_material: i64,
    first_block: i64,
) -> PyResult<Bound<'py, PyList>> {
    let voussoirs = crate::convert::whole(voussoirs, "voussoirs", usize::MAX as u64)? as usize;
    let voussoir_material = crate::convert::whole(voussoir_material, "voussoir_material", u64::from(u16::MAX))? as u16;
    let abutment_material = crate::convert::whole(abutment_material, "abutment_material", u64::from(u16::MAX))? as u16;
    let first_block = crate::convert::whole(first_block, "first_block", u64::from(u32::MAX))? as u32;
    let spec = arch_spec(
        span,
        rise,
        thickness,
        width,
        voussoirs,
        density,
        abutment_outer_width,
        abutment_depth,
        voussoir_material,
        abutment_material,
    );
    let arch = Arch::new(&spec).py()?;
    let out = PyList::empty(py);
    for j in arch.joint_refs() {
        let d = PyDict::new(py);
        d.set_item("index", j.index)?;
        d.set_item(
            "blocks",
            (
                first_block as u64 + u64::from(j.blocks.0 .0),
                first_block as u64 + u64::from(j.blocks.1 .0),
            ),
        )?;
        d.set_item("intrados", crate::convert::vector(py, j.intrados))?;
        d.set_item("extrados", crate::convert::vector(py, j.extrados))?;
        let half = voussoir::math::Vector::new(0.0, 0.0, 0.5 * width);
        d.set_item(
            "points",
            array_n3(
                py,
                [
                    j.intrados - half,
                    j.intrados + half,
                    j.extrados + half,
                    j.extrados - half,
                ]
                .into_iter(),
            ),
        )?;
        out.append(d)?;
    }
    Ok(out)
}
