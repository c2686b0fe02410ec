//! Limit analysis from Python (`voussoir::analysis::limit`).

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PySequence};
use voussoir::analysis::limit::{FrictionModel, LimitAnswer, LimitOptions, LimitProblem, LiveLoad};
use voussoir::math::Vector;

use crate::convert::{array1, array_n3, vec3, vector, Int};
use crate::errors::bad;
use crate::errors::OrPy;
use crate::model::PyModel;

/// limit(model, live_loads, *, fixity=None, friction="cone", facets=16, check_dead_load=True, max_iterations=200, joints=None, mechanism_tolerance=0.001)
/// --
///
/// The collapse load of the model's blocks as they stand, by limit analysis (Rust:
/// ``voussoir::analysis::limit``): rigid blocks, no-tension joints with the Coulomb strength of
/// their laws (friction angle and cohesion; associative flow), the dead loads (gravity and the
/// blocks' constant loads) fixed, the live loads scaled by the multiplier. Second-order cone
/// programme solved by Clarabel; the model must have been stepped once (its contacts found).
///
/// ``live_loads``: a list of ``{"block": i, "point": (x, y, z), "force": (fx, fy, fz)}`` (or
/// ``(block, point, force)`` tuples): the force ``multiplier * force`` on ``block`` at ``point``
/// (world, m; N per unit multiplier: with a unit force the multiplier is in newtons). An empty
/// list, or live loads whose forces are all zero, asks the dead-load question alone
/// (``voussoir.carries_dead_load``): whether the dead loads are carried, an answer either way
/// (``multiplier`` None, ``carries_dead_load`` True or False), not an error.
/// ``fixity``: ``{block: fixity}`` overrides for the analysis (as ``Model.add_cuboid`` takes
/// them), e.g. a loading plate left free. ``friction``: ``"cone"`` (exact) or ``"pyramid"``
/// (``facets`` planes inscribed, a linear programme, a lower bound by at most
/// ``1 - cos(pi / facets)``). ``check_dead_load``: also check that the dead loads alone are
/// carried (a second solve); a structure that stands only when pushed raises
/// ``LimitInfeasibleError``.
/// ``joints``: joints to classify in the mechanism, as ``classify_joints`` takes them (e.g.
/// ``voussoir.build.arch_joints()``); a joint hinges or slides where its relative motion at
/// collapse exceeds ``mechanism_tolerance`` of the largest.
///
/// Raises, with a live load, ``LimitInfeasibleError`` when the dead loads are not carried
/// (the structure cannot carry its own weight, or only with the live load's help),
/// ``LimitUnboundedError`` when the multiplier has no bound (the live load goes straight into
/// the supports, or wedges blocks that friction locks), ``LimitSolverError`` when the solver
/// stops without an answer (e.g. at ``max_iterations``): subclasses of ``VoussoirError``, with
/// the library's messages; ``VoussoirError`` for bad input.
///
/// Returns a dict:
///
/// - ``multiplier``: the collapse multiplier (None for the dead-load question); ``status``,
///   ``iterations``: the solver's (``"Solved"`` or ``"AlmostSolved"``; for a dead load not
///   carried ``"PrimalInfeasible"`` or ``"AlmostPrimalInfeasible"``); ``carries_dead_load``:
///   True when checked (always with a live load unless ``check_dead_load=False``, then None),
///   the answer for the dead-load question; ``reason``: why a dead load is not carried (naming
///   the blocks that fall), None otherwise;
/// - ``blocks``: ``centroid``, ``velocity``, ``angular_velocity`` (n × 3 arrays): each block's
///   motion in the mechanism, scaled so that the live loads' power is the sum of their
///   forces' magnitudes; for a dead load not carried, the solver's certificate (a motion on
///   which the dead loads do work: which blocks fall and which way, a blend where several
///   mechanisms exist), scaled so that the dead loads' power is the free blocks' weight; zero
///   for a dead load carried;
/// - ``contacts``: a list, one dict per contact at collapse (for the dead-load question, of the
///   admissible state that carries it, or with zero forces when it is not carried):
///   ``blocks`` (a, b), ``normal``
///   (a to b), ``points`` (the polygon's corners, m × 3), ``normal_force`` (m, N, compression
///   positive), ``shear_force`` (m × 3, on b), ``opening`` and ``sliding`` (m: the mechanism's
///   relative motion at each corner), ``resultant`` (the force on b) and
///   ``application_point`` (the centre of the normal forces, where the resultant gives the
///   corners' moment about any axis in the joint plane; None for a contact without
///   compression);
/// - with ``joints``: ``joints``, one dict per joint (``joint``, ``opening_intrados``,
///   ``opening_extrados``, ``sliding``: the mechanism's rates; ``hinge``: None,
///   ``"intrados"`` or ``"extrados"``; ``is_sliding``), and ``mechanism``, e.g.
///   ``"hinges 4e 8i; sliding 13"`` (both None for the dead-load question: it has no collapse
///   mechanism to read).
///
/// >>> import voussoir as vs
/// >>> m = vs.Model()
/// >>> m.set_joint_law(0, 0, vs.CoulombSlip.dry(4e9, 1.6e9, 30.0))
/// >>> _ = m.add_cuboid("base", (-1, -1, -0.2), (1, 1, 0), 2600.0, fixed=True)
/// >>> block = m.add_cuboid("block", (0, 0, 0), (0.4, 0.3, 0.2), 2600.0)
/// >>> m.run_steps(1)
/// True
/// >>> r = vs.limit(m, [{"block": block, "point": (0.2, 0.15, 0.1), "force": (1, 0, 0)}])
/// >>> round(r["multiplier"] / (2600 * 0.024 * 9.81), 4)  # slides: tan 30°
/// 0.5774
/// >>> d = vs.limit(m, [])  # the dead load alone: carried, the base holds the block up
/// >>> d["multiplier"] is None, d["carries_dead_load"]
/// (True, True)
/// >>> round(float(d["contacts"][0]["resultant"][2]) / (2600 * 0.024 * 9.81), 9)
/// 1.0
#[pyfunction]
#[pyo3(signature = (model, live_loads, *, fixity=None, friction="cone", facets=16, check_dead_load=true, max_iterations=200, joints=None, mechanism_tolerance=1e-3))]
#[allow(clippy::too_many_arguments)]
pub fn limit<'py>(
    py: Python<'py>,
    model: PyRef<'py, PyModel>,
    live_loads: &Bound<'py, PyAny>,
    fixity: Option<&Bound<'py, PyDict>>,
    friction: &str,
    facets: i64,
    check_dead_load: bool,
    max_iterations: i64,
    joints: Option<&Bound<'py, PyAny>>,
    mechanism_tolerance: f64,
) -> PyResult<Bound<'py, PyAny>> {
    let facets = crate::convert::whole(facets, "facets", usize::MAX as u64)? as usize;
    let max_iterations = crate::convert::whole(max_iterations, "max_iterations", u64::from(u32::MAX))? as u32;
    if !(mechanism_tolerance.is_finite() && mechanism_tolerance > 0.0) {
        return Err(bad(format!(
            "mechanism_tolerance = {mechanism_tolerance}: must be positive and finite"
        )));
    }
    let friction = match friction {
        "cone" => FrictionModel::Cone,
        "pyramid" => FrictionModel::Pyramid { facets },
        other => return Err(bad(format!("friction {other:?}: expected \"cone\" or \"pyramid\""))),
    };
    let options = LimitOptions {
        friction,
        check_dead_load,
        max_iterations,
    };
    let (problem, live, refs) = {
        let this = model.lock(py);
        let count = this.model.blocks().len();
        let refs = joints.map(|j| crate::mechanism::joint_refs(j, count)).transpose()?;
        let mut problem = LimitProblem::from_model(&this.model).py()?;
        if let Some(overrides) = fixity {
            for (block, spec) in overrides.iter() {
                let id = block.extract::<Int>()?.block("fixity: block", count)?;
                problem.set_fixity(id, crate::convert::fixity(Some(&spec))?).py()?;
            }
        }
        (problem, live_loads_of(live_loads, count)?, refs)
    };
    // The model is free again; the solve lets the GIL go.
    let answer = py.detach(|| problem.analyse(&live, &options)).py()?;
    let d = result_to_py(py, &answer, check_dead_load)?;
    if let Some(refs) = refs {
        let LimitAnswer::Collapse(result) = &answer else {
            d.set_item("joints", py.None())?;
            d.set_item("mechanism", py.None())?;
            return crate::convert::result(py, "LimitResult", d);
        };
        let (motions, mechanism) = {
            let this = model.lock(py);
            result.classify(&this.model, &refs, mechanism_tolerance)
        };
        let list = PyList::empty(py);
        for m in motions {
            let e = PyDict::new(py);
            e.set_item("joint", m.joint)?;
            e.set_item("opening_intrados", m.opening_intrados)?;
            e.set_item("opening_extrados", m.opening_extrados)?;
            e.set_item("sliding", m.sliding)?;
            e.set_item(
                "hinge",
                m.hinge.map(|h| match h {
                    voussoir::analysis::HingeSide::Intrados => "intrados",
                    voussoir::analysis::HingeSide::Extrados => "extrados",
                }),
            )?;
            e.set_item("is_sliding", m.is_sliding)?;
            list.append(e)?;
        }
        d.set_item("joints", list)?;
        d.set_item("mechanism", mechanism.describe())?;
    }
    crate::convert::result(py, "LimitResult", d)
}

/// The live loads from Python: dicts or `(block, point, force)` sequences.
fn live_loads_of(obj: &Bound<'_, PyAny>, count: usize) -> PyResult<Vec<LiveLoad>> {
    let list = obj
        .cast::<PySequence>()
        .map_err(|_| bad("live_loads: expected a list of {\"block\", \"point\", \"force\"} dicts"))?;
    let mut live = Vec::with_capacity(list.len()?);
    for (k, item) in list.try_iter()?.enumerate() {
        let item = item?;
        let what = |field: &str| format!("live_loads[{k}].{field}");
        let (block, point, force) = if let Ok(d) = item.cast::<PyDict>() {
            let get = |key: &str| -> PyResult<Bound<'_, PyAny>> {
                d.get_item(key)?.ok_or_else(|| {
                    bad(format!(
                        "live_loads[{k}]: missing {key:?} (expected block, point, force)"
                    ))
                })
            };
            (get("block")?, get("point")?, get("force")?)
        } else {
            let seq = item.cast::<PySequence>().map_err(|_| {
                bad(format!(
                    "live_loads[{k}]: expected a dict or a (block, point, force) tuple"
                ))
            })?;
            if seq.len()? != 3 {
                return Err(bad(format!("live_loads[{k}]: expected (block, point, force)")));
            }
            (seq.get_item(0)?, seq.get_item(1)?, seq.get_item(2)?)
        };
        live.push(LiveLoad {
            block: block.extract::<Int>()?.block(&what("block"), count)?,
            point: vec3(&point, &what("point"))?,
            force: vec3(&force, &what("force"))?,
        });
    }
    Ok(live)
}

/// A [`LimitAnswer`] as Python data (see [`limit`]); `checked`: whether a collapse answer
/// checked the dead loads.
fn result_to_py<'py>(py: Python<'py>, r: &LimitAnswer, checked: bool) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let (carries_dead_load, reason) = match r {
        LimitAnswer::Collapse(_) => (checked.then_some(true), None),
        LimitAnswer::DeadLoad(dead) => (Some(dead.carried), dead.reason.as_deref()),
    };
    d.set_item("multiplier", r.multiplier())?;
    d.set_item("status", r.status())?;
    d.set_item("iterations", r.iterations())?;
    d.set_item("carries_dead_load", carries_dead_load)?;
    d.set_item("reason", reason)?;
    let blocks = PyDict::new(py);
    blocks.set_item("centroid", array_n3(py, r.blocks().iter().map(|b| b.centroid)))?;
    blocks.set_item("velocity", array_n3(py, r.blocks().iter().map(|b| b.velocity)))?;
    blocks.set_item(
        "angular_velocity",
        array_n3(py, r.blocks().iter().map(|b| b.angular_velocity)),
    )?;
    d.set_item("blocks", blocks)?;
    let contacts = PyList::empty(py);
    for c in r.contacts() {
        let e = PyDict::new(py);
        e.set_item("blocks", (c.blocks.0 .0, c.blocks.1 .0))?;
        e.set_item("normal", vector(py, c.normal))?;
        e.set_item("points", array_n3(py, c.vertices.iter().map(|v| v.point)))?;
        e.set_item(
            "normal_force",
            array1(py, c.vertices.iter().map(|v| v.normal_force).collect()),
        )?;
        e.set_item("shear_force", array_n3(py, c.vertices.iter().map(|v| v.shear_force)))?;
        e.set_item("opening", array1(py, c.vertices.iter().map(|v| v.opening).collect()))?;
        e.set_item("sliding", array1(py, c.vertices.iter().map(|v| v.sliding).collect()))?;
        e.set_item("resultant", vector(py, c.resultant()))?;
        let total: f64 = c.vertices.iter().map(|v| v.normal_force).sum();
        let centre = (total > 0.0).then(|| c.vertices.iter().map(|v| v.point * v.normal_force).sum::<Vector>() / total);
        e.set_item("application_point", centre.map(|p| vector(py, p)))?;
        contacts.append(e)?;
    }
    d.set_item("contacts", contacts)?;
    Ok(d)
}
