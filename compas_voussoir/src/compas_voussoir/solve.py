"""The analyses: a ``compas_dem`` problem solved by voussoir, ``compas_dem`` ``Results`` back."""

import inspect
import math
from typing import Dict, Optional, Sequence

import numpy as np

import voussoir as vs

from .convert import MODEL_OPTIONS, centroidal_loads, live_loads, to_voussoir, warn
from .results import from_limit, from_model, without_forces

ANALYSES = ("static", "dynamic", "shaking", "capacity", "limit")

#: The name of the ``compas_dem`` ``Solver`` that :func:`Voussoir` makes.
SOLVER_NAME = "voussoir"


class NotSettledWarning(UserWarning):
    """A DEM run did not reach its unbalanced-force ratio within ``max_steps``: the Results are
    of the model as it stands, ``metadata["settled"]`` is False and ``metadata["history"]``
    says how the ratio and the kinetic energy went."""


def Voussoir(**parameters):
    """A ``compas_dem`` ``Solver`` named ``"voussoir"`` holding the parameters of
    :func:`run`: with it, ``problem.set_solver(compas_voussoir.Voussoir(analysis="limit",
    live="Live"))`` then ``problem.solve()`` runs voussoir (``compas_voussoir`` installs that
    dispatch when imported: :func:`compas_voussoir.install`), as ``compas_voussoir.solve(problem)``
    does. A plain ``Solver`` (JSON round trips need no compas_voussoir); parameters that
    :func:`run` does not take are refused here (``TypeError`` naming them)."""
    from compas_dem.problem import Solver

    unknown = sorted(set(parameters) - set(_RUN_PARAMETERS) - set(MODEL_OPTIONS))
    if unknown:
        raise TypeError(
            f"Voussoir() got unexpected parameter{'s' if len(unknown) > 1 else ''} {', '.join(map(repr, unknown))}; "
            f"it takes {', '.join(_RUN_PARAMETERS)} and the voussoir.Model options {', '.join(MODEL_OPTIONS)}"
        )
    s = Solver()
    s.name = SOLVER_NAME
    s.parameters = dict(parameters)
    return s


def _apply_loads_and_motions(problem, model, conv, ramp_time):
    """The problem's loads (``"ramp"`` over ``ramp_time``, ``"instantaneous"`` from the start)
    and prescribed displacements (at a constant rate over ``ramp_time``)."""
    from compas_dem.analysis.resolve import resolve_centroidal_displacements

    m = conv.model
    ramp = vs.TimeHistory([0.0, ramp_time], [0.0, 1.0])
    for i, kinds in centroidal_loads(problem, model, conv).items():
        if "ramp" in kinds and "instantaneous" in kinds:
            raise ValueError(
                f"block {conv.node[i]} carries both ramped and instantaneous loads; voussoir gives a block one load history"
            )
        if "ramp" in kinds:
            f, mo = kinds["ramp"]
            m.set_load_history(i, ramp, force=f, moment=mo)
        else:
            f, mo = kinds["instantaneous"]
            m.set_load(i, force=f, moment=mo)
    prescribed = resolve_centroidal_displacements(problem.boundary_conditions)
    for n, disp in prescribed.items():
        i = conv.index[n]
        fixity = {"translation": ["free"] * 3, "rotation": ["free"] * 3}
        for key in ("translation", "rotation"):
            for k, value in enumerate(disp[key] or [None] * 3):
                if value is not None:
                    fixity[key][k] = float(value) / ramp_time
        m.set_fixity(i, fixity)
    return [conv.index[n] for n in prescribed]


def _stop_prescribed(conv, blocks):
    """Fixes the axes whose displacements were prescribed, once reached."""
    m = conv.model
    for i in blocks:
        f = m.block(i).fixity
        fixed = {key: ["fixed" if not isinstance(d, str) else d for d in f[key]] for key in ("translation", "rotation")}
        m.set_fixity(i, fixed)


def solve(problem, model=None, **options):
    """Solves ``problem`` over ``model`` (default: the problem's) with voussoir and returns
    ``compas_dem.problem.Results``; the options are :func:`run`'s, taken from the problem's
    ``Voussoir`` solver (``problem.set_solver(compas_voussoir.Voussoir(...))``) where not given
    here (its ``None`` values left out, as ``compas_dem`` does). ``problem.solve()`` calls this
    for a ``Voussoir`` solver."""
    configured = getattr(problem, "_solver", None)
    if configured is not None and getattr(configured, "name", None) == SOLVER_NAME:
        options = {**{k: v for k, v in configured.parameters.items() if v is not None}, **options}
    return run(problem, model, **options)


def run(
    problem,
    model=None,
    *,
    analysis: Optional[str] = None,
    density: Optional[float] = None,
    densities: Optional[Dict[int, float]] = None,
    kn: Optional[float] = None,
    ks: Optional[float] = None,
    interfaces: Optional[Dict[tuple, dict]] = None,
    fracture: Optional[dict] = None,
    subcontacts_per_edge: Optional[int] = None,
    contact_tolerance: Optional[float] = None,
    ramp_time: float = 0.5,
    ratio: float = 1e-5,
    max_steps: int = 2_000_000,
    history_every: Optional[int] = None,
    duration: float = 1.0,
    damping: Optional[dict] = None,
    ground_motion: Optional[dict] = None,
    capacity: Optional[dict] = None,
    live: Optional[Sequence[str]] = None,
    fixity: Optional[Dict[int, object]] = None,
    friction: str = "cone",
    facets: int = 16,
    check_dead_load: bool = True,
    max_iterations: int = 200,
    mechanism_scale: float = 0.01,
    centre=None,
    progress: bool = False,
    **model_options,
):
    """Solves ``problem`` over ``model`` (default: the problem's) with voussoir; returns
    ``compas_dem.problem.Results`` (see ``compas_voussoir.results`` for what each entry holds
    and its signs) with ``metadata`` saying what was run, and the supports' reactions
    (:func:`compas_voussoir.reactions`: force and moment on each support from the structure).

    ``analysis`` (default ``"static"``):

    - ``"static"``: gravity and the loads (ramped over ``ramp_time`` s) with local damping,
      run to an unbalanced-force ratio below ``ratio`` or ``max_steps`` steps;
      ``metadata["settled"]`` says whether it got there (if not, the Results are of the model
      as it stands and a :class:`NotSettledWarning` is issued); ``metadata["history"]``
      samples, every ``history_every`` steps (default: 1000 or fewer, about 200 samples over
      ``max_steps``), the step, time, unbalanced-force ratio and kinetic energy (J). A model
      without a support (no fixed block, no prescribed motion) is refused: under gravity its
      blocks fall and never settle;
    - ``"dynamic"``: the same loads for ``duration`` s of model time with ``damping``
      (``{"kind": "rayleigh", "ratio": 0.05, "frequency": 5.0}`` by default, as
      ``voussoir.Model.set_damping`` takes it); ``metadata["history"]`` samples the blocks;
    - ``"shaking"``: settled statically, then the supports move with ``ground_motion``
      (``{"x": TimeHistory or (times, values), "y": ..., "z": ..., "kind": "acceleration"}``,
      accelerations in m/s²) for the record's length, Rayleigh damping (or ``damping``);
    - ``"capacity"``: settled, then ``capacity["block"]`` (a graph node) is pushed along
      ``capacity["direction"]`` under servo control to the peak of the load it carries (as
      3DEC's ``add_load_capacity``; ``voussoir.Model.push_over``; keys ``increment`` (m,
      default 2e-5), ``max_travel`` (default 0.012), ``fixity`` of the pushed block during
      the push (default: the pushed axis prescribed, the others free));
      ``metadata["peak_load"]`` (N) and ``metadata["curve"]``. Push a loading device (a
      plate seated on the structure, as 3DEC and the laboratory do, and as the tests push the
      reference arch's): the servo advances only once the free blocks have settled (their
      unbalanced-force ratio), and a block with a prescribed axis is not one of them, so a model
      whose only moving block is the pushed one is refused (its samples would catch its joint
      ringing: a 0.2 m cube pushed along its own joint at φ 30° peaked at 0.79 W while sliding
      at 0.577 W). A shaking or capacity analysis whose settling does not settle stops there
      (``metadata["settled"]`` False, ``["stage"]`` ``"settle"``);
    - ``"limit"``: limit analysis of the loads of the boundary conditions named ``live``
      (scaled by the multiplier) with the others and gravity as dead loads (``facets``,
      ``max_iterations``, ``check_dead_load`` as ``voussoir.limit`` takes them);
      ``metadata["multiplier"]``, ``["status"]``, ``["carries_dead_load"]`` (True, False, or
      None when not checked), ``["mechanism"]`` (block velocities), ``["hinges"]`` (per hinged
      joint the corners it turns about and its side, intrados or extrados, about ``centre``
      or the centre the hinged joints face: :func:`compas_voussoir.results.hinges`); ``fixity``
      overrides per graph node (e.g. a loading plate's out-of-plane motions fixed). A dead load
      that is not carried is an answer, not an error: ``carries_dead_load`` False,
      ``multiplier`` None, ``status`` ``"infeasible"`` and ``reason`` (voussoir's
      ``LimitInfeasibleError``), Results without forces. ``live=[]`` (or live loads of zero
      force) asks only whether the dead load is carried (``voussoir.limit`` with no live load;
      ``multiplier`` None, ``dead_load_only`` True, ``status`` the solver's): when it is, the
      Results hold the contact forces of an admissible state that carries it (they balance the
      weight and the dead loads; the supports' reactions with them) and no mechanism; when it
      is not, ``status`` ``"PrimalInfeasible"``, ``reason`` naming the blocks that fall,
      ``mechanism`` the solver's certificate (a motion on which the dead load does work: which
      blocks fall and which way, not a collapse mechanism to read hinges from) and Results
      without forces.

    Model options: ``density`` (kg/m³, for blocks without a material) and ``densities`` per
    graph node; ``kn``, ``ks`` (**Pa/m, stiffness per unit joint area**; compas_dem's
    ``set_joint_model`` docstring says N/m: a value outside 1e8–1e14 Pa/m is warned about,
    :class:`compas_voussoir.StiffnessUnitsWarning`) over the problem's joint model;
    ``interfaces`` ``{(u, v): {"phi", "c", "t_c", "kn", "kt", "gf_i", "gf_ii", "phi_r",
    "softening"}}`` per pair of graph nodes; ``fracture`` ``{"gf_i", "gf_ii", "phi_r",
    "softening"}`` (J/m², degrees): mortared joints (``voussoir.MortarJoint``) that soften on
    these fracture energies instead of the brittle Mohr–Coulomb joints;
    ``subcontacts_per_edge``, ``contact_tolerance`` (None: voussoir's defaults,
    ``voussoir.Model.defaults()``); the ``voussoir.Model`` keywords of
    ``compas_voussoir.convert.MODEL_OPTIONS``. Any other keyword is refused (``TypeError``
    naming it).
    """
    model = model if model is not None else problem.model
    analysis = "static" if analysis is None else analysis
    if analysis not in ANALYSES:
        raise ValueError(f"analysis {analysis!r}: expected one of {ANALYSES}")
    unknown = sorted(set(model_options) - set(MODEL_OPTIONS))
    if unknown:
        raise TypeError(
            f"unexpected keyword argument{'s' if len(unknown) > 1 else ''} {', '.join(map(repr, unknown))}; "
            f"compas_voussoir.run takes {', '.join(_RUN_PARAMETERS)} and the voussoir.Model options "
            f"{', '.join(MODEL_OPTIONS)}"
            + (" (gravity is the boundary conditions' g, along -z)" if "gravity" in unknown else "")
        )
    _check_run_arguments(
        duration=duration,
        ramp_time=ramp_time,
        ratio=ratio,
        max_steps=max_steps,
        history_every=history_every,
        subcontacts_per_edge=subcontacts_per_edge,
        contact_tolerance=contact_tolerance,
        density=density,
        densities=densities,
        facets=facets,
        max_iterations=max_iterations,
        check_dead_load=check_dead_load,
        mechanism_scale=mechanism_scale,
        centre=centre,
        progress=progress,
        friction=friction,
    )
    conv = to_voussoir(
        problem,
        model,
        density=density,
        densities=densities,
        kn=kn,
        ks=ks,
        interfaces=interfaces,
        fracture=fracture,
        subcontacts_per_edge=subcontacts_per_edge,
        contact_tolerance=contact_tolerance,
        **model_options,
    )
    m = conv.model
    meta = {
        "engine": "voussoir",
        "version": vs.__version__,
        "analysis": analysis,
        "joint_law": conv.law,
        "units": dict(UNITS),
    }

    if analysis == "limit":
        return _limit(
            problem,
            model,
            conv,
            meta,
            live=live,
            fixity=fixity,
            friction=friction,
            facets=facets,
            check_dead_load=check_dead_load,
            max_iterations=max_iterations,
            mechanism_scale=mechanism_scale,
            centre=centre,
        )

    # The shaking's and the push's own arguments, checked before the settling.
    axes = _ground_motion(ground_motion) if analysis == "shaking" else None
    if analysis == "shaking" and not any(e.is_support for e in model.elements()):
        raise ValueError("shaking: the model has no support blocks to move (model.add_support(node))")
    shaking_damping = _damping(damping) if analysis in ("shaking", "dynamic") else None
    push = _capacity_plan(m, conv, capacity) if analysis == "capacity" else None

    every = history_every or max(1, min(1000, max_steps // 200))
    if analysis in ("static", "capacity", "shaking"):
        m.set_damping("local", alpha=0.8)
        prescribed = _apply_loads_and_motions(problem, model, conv, ramp_time)
        _check_supported(conv, prescribed)
        settle = _settle(m, ramp_time, ratio, max_steps, every, progress)
        _stop_prescribed(conv, prescribed)
        meta.update(settle)
        if not settle["settled"]:
            stage = " (the settling before the " + analysis + " stage, which was not run)" if analysis != "static" else ""
            warn(
                NotSettledWarning(
                    f"the {analysis} analysis did not settle{stage}: the unbalanced-force ratio is "
                    f"{settle['unbalanced_ratio']:.3g} after {settle['settle_steps']} steps (target {ratio:g}, "
                    f"max_steps {max_steps}); the Results are of the model as it stands, metadata['history'] "
                    "has the ratio and kinetic energy over the steps"
                )
            )
            if analysis != "static":
                meta["stage"] = "settle"
                meta.update({"time": m.time, "steps": m.step_count, "energies": dict(m.energies())})
                return from_model(problem, model, conv, meta)

    if analysis == "dynamic":
        d = shaking_damping
        m.set_damping(d.pop("kind"), **d)
        prescribed = _apply_loads_and_motions(problem, model, conv, ramp_time)
        times, positions = [], []
        step = max(duration / 200.0, 1e-9)
        while m.time < duration - 1e-12:
            m.run_until_time(min(m.time + step, duration), progress=False)
            times.append(m.time)
            positions.append(m.positions().tolist())
        meta["history"] = {"time": times, "nodes": [conv.node[i] for i in range(len(conv.node))], "positions": positions}

    if analysis == "shaking":
        d = shaking_damping
        m.set_damping(d.pop("kind"), **d)
        supports = [conv.index[e.graphnode] for e in model.elements() if e.is_support]
        for i in supports:
            m.set_base_motion(i, axes["x"], axes["y"], axes["z"], kind=axes["kind"])
        end = max(h.end for key, h in axes.items() if key != "kind" and h is not None)
        t0 = m.time
        m.run_until_time(t0 + end, progress=progress)
        meta["shaking_duration"] = m.time - t0

    if analysis == "capacity":
        meta.update(_push(m, push, progress))

    meta.update({"time": m.time, "steps": m.step_count, "energies": dict(m.energies())})
    return from_model(problem, model, conv, meta)


#: The units of what the Results and their metadata hold.
UNITS = {
    "length": "m",
    "force": "N",
    "moment": "N·m",
    "stress": "Pa",
    "kn": "Pa/m (normal stiffness per unit joint area; compas_dem's docstring says N/m)",
    "ks": "Pa/m (shear stiffness per unit joint area)",
    "density": "kg/m³",
    "time": "s",
    "energy": "J",
}


def _damping(damping):
    if damping is None:
        return {"kind": "rayleigh", "ratio": 0.05, "frequency": 5.0}
    if not isinstance(damping, dict) or "kind" not in damping:
        raise ValueError(f"damping = {damping!r}: a dict with 'kind' (as voussoir.Model.set_damping takes it) expected")
    d = dict(damping)
    # Checked on a model of its own, before any run.
    try:
        vs.Model().set_damping(d["kind"], **{k: v for k, v in d.items() if k != "kind"})
    except (ValueError, TypeError) as e:
        raise type(e)(f"damping = {damping!r}: {e}") from None
    return d


def _check_supported(conv, prescribed):
    """Refuses a settling run of a model without any support: no block fixed in any degree of
    freedom and none with a prescribed motion (its blocks fall for ever; voussoir's
    unbalanced-force ratio, the unbalanced force over the mean support reaction, is then
    ``inf`` and its error said only "last value inf")."""
    m = conv.model
    if prescribed:
        return
    for i in range(len(m)):
        f = m.block(i).fixity
        if any(d != "free" for key in ("translation", "rotation") for d in f[key]):
            return
    if not np.any(np.asarray(m.gravity) != 0.0) and all(
        not np.any(m.load(i)["force"]) and not np.any(m.load(i)["moment"]) for i in range(len(m))
    ):
        return
    raise ValueError(
        "the model has no support: no block is fixed and none has a prescribed motion, so under gravity every "
        "block falls and the run cannot settle. Flag the support blocks before solving: model.add_support(node) "
        "or model.add_supports([...]) (compas_dem's is_support)"
    )


def _settle(m, ramp_time, ratio, max_steps, every, progress):
    """The loads' ramp (``ramp_time`` s), then a run to an unbalanced-force ratio below
    ``ratio`` or ``max_steps`` steps; the ratio and kinetic energy every ``every`` steps."""
    history = {"step": [], "time": [], "unbalanced_ratio": [], "kinetic_energy": []}

    def sample(step, time):
        history["step"].append(int(step))
        history["time"].append(float(time))
        history["unbalanced_ratio"].append(float(m.unbalanced_force_ratio))
        history["kinetic_energy"].append(float(dict(m.energies())["kinetic"]))

    m.run_until_time(ramp_time, sample, every, progress=progress)
    start = m.step_count

    def settle(step, time):
        sample(step, time)
        return step - start < max_steps

    # The callback stops the run at max_steps (voussoir's own limit, a little beyond, would
    # raise and lose the run).
    m.run_to_equilibrium(ratio, max_steps + every + 1, settle, every, progress=progress)
    if not history["step"] or history["step"][-1] != m.step_count:
        sample(m.step_count, m.time)
    last = float(m.unbalanced_force_ratio)
    return {
        "settled": bool(last < ratio),
        "settle_steps": int(m.step_count - start),
        "unbalanced_ratio": last,
        "target_ratio": ratio,
        "history": history,
    }


def _limit(problem, model, conv, meta, *, live, fixity, friction, facets, check_dead_load, max_iterations, mechanism_scale, centre):
    m = conv.model
    if live is None:
        raise ValueError(
            'analysis="limit" needs live=["name of the boundary condition with the live loads"] '
            "(live=[] checks only whether the dead load is carried)"
        )
    names = [live] if isinstance(live, str) else list(live)
    for name in names:
        if not isinstance(name, str):
            raise ValueError(f"live: {name!r} is not the name of a boundary condition")
    if any(bc.displacements for bc in problem.boundary_conditions):
        raise ValueError("limit analysis of a problem with prescribed displacements is not supported")
    dead = [bc for bc in problem.boundary_conditions if bc.name not in names]
    overrides = {}
    for n, f in (fixity or {}).items():
        if n not in conv.index:
            raise ValueError(f"fixity: block {n!r} is not a node of the model's graph")
        overrides[conv.index[n]] = f
    # The dead loads as constant loads; the contacts found by one step.
    from compas_dem.analysis.resolve import resolve_centroidal_loads

    for n, entry in resolve_centroidal_loads(model, dead).items():
        i = conv.index[n]
        shift = conv.centroids[i] - np.asarray(list(model.graph.node_element(n).point))
        f = np.asarray(list(entry["force"]), dtype=float)
        mo = np.asarray(list(entry["moment"]), dtype=float) - np.cross(shift, f)
        if np.any(f) or np.any(mo):
            m.set_load(i, force=f, moment=mo)
    m.step()
    loads = live_loads(problem, model, conv, names)
    options = {"fixity": overrides, "friction": friction, "facets": facets, "max_iterations": max_iterations}
    meta.update({"live": names, "mechanism_scale": mechanism_scale, "check_dead_load": bool(check_dead_load)})

    if not loads:
        # Only the dead load: is it carried? voussoir.limit answers that with no live load:
        # the forces of an admissible state when it is, the blocks that fall when not.
        r = vs.limit(m, [], **options)
        meta.update(
            {
                "multiplier": None,
                "status": r["status"],
                "iterations": r["iterations"],
                "carries_dead_load": r["carries_dead_load"],
                "dead_load_only": True,
            }
        )
        if r["carries_dead_load"]:
            meta["mechanism"] = None
            return from_limit(problem, model, conv, r, meta, centre=centre)
        meta.update({"reason": r["reason"], "mechanism": _mechanism(conv, r), "hinges": []})
        return without_forces(problem, model, conv, meta)

    try:
        r = vs.limit(m, loads, check_dead_load=bool(check_dead_load), **options)
    except vs.LimitInfeasibleError as e:
        meta.update(
            {
                "multiplier": None,
                "status": "infeasible",
                "carries_dead_load": False,
                "reason": str(e),
                "mechanism": None,
                "hinges": [],
            }
        )
        return without_forces(problem, model, conv, meta)
    meta.update(
        {
            "multiplier": r["multiplier"],
            "status": r["status"],
            "iterations": r["iterations"],
            "carries_dead_load": r["carries_dead_load"],
            "mechanism": _mechanism(conv, r),
        }
    )
    return from_limit(problem, model, conv, r, meta, centre=centre)


def _mechanism(conv, r):
    """Per graph node, the block's ``velocity`` and ``angular_velocity`` in a
    ``voussoir.limit`` answer's mechanism."""
    return {
        conv.node[i]: {
            "velocity": r["blocks"]["velocity"][i].tolist(),
            "angular_velocity": r["blocks"]["angular_velocity"][i].tolist(),
        }
        for i in conv.node
    }


def _ground_motion(ground_motion):
    """``{"x", "y", "z": TimeHistory or None, "kind"}`` of the shaking's ``ground_motion``."""
    if not ground_motion:
        raise ValueError('analysis="shaking" needs ground_motion={"x": TimeHistory or (times, accelerations)}')
    if not isinstance(ground_motion, dict):
        raise ValueError(f"ground_motion = {ground_motion!r}: a dict {{'x': ..., 'y': ..., 'z': ..., 'kind': ...}} expected")
    gm = dict(ground_motion)
    axes = {"kind": gm.pop("kind", "acceleration")}
    if axes["kind"] not in ("acceleration", "velocity", "displacement"):
        raise ValueError(f"ground_motion['kind'] = {axes['kind']!r}: expected 'acceleration', 'velocity' or 'displacement'")
    for axis in ("x", "y", "z"):
        h = gm.pop(axis, None)
        if h is not None and not isinstance(h, vs.TimeHistory):
            try:
                h = vs.TimeHistory(list(h[0]), list(h[1]))
            except (TypeError, IndexError, ValueError) as e:
                raise ValueError(f"ground_motion[{axis!r}]: a voussoir.TimeHistory or (times, values) expected ({e})") from None
        axes[axis] = h
    if gm:
        raise ValueError(f"ground_motion: unknown keys {sorted(gm)}; expected x, y, z, kind")
    if all(axes[axis] is None for axis in ("x", "y", "z")):
        raise ValueError("ground_motion: no record for any of x, y, z")
    return axes


def _capacity_plan(m, conv, capacity):
    """The push of a capacity analysis, its arguments checked: ``(block, direction, fixity,
    increment, max_travel, push_over options)``."""
    if not capacity or not isinstance(capacity, dict) or "block" not in capacity:
        raise ValueError('analysis="capacity" needs capacity={"block": graph node, "direction": (x, y, z)}')
    c = dict(capacity)
    node = c.pop("block")
    if node not in conv.index:
        raise ValueError(
            f"capacity: block {node!r} is not a node of the model's graph (its nodes: {sorted(conv.index)[:20]}"
            f"{' ...' if len(conv.index) > 20 else ''})"
        )
    allowed = {"direction", "fixity", "increment", "max_travel"} | set(_PUSH_OVER_OPTIONS)
    extra = sorted(set(c) - allowed)
    if extra:
        raise ValueError(f"capacity: unknown keys {extra}; expected block, {', '.join(sorted(allowed))}")
    i = conv.index[node]
    others = [j for j in range(len(m)) if j != i and not m.block(j).is_fixed]
    if not others:
        raise ValueError(
            "capacity: the pushed block is the only one that moves; push a loading device (a plate seated on "
            "the structure) so that the servo has free blocks to wait for"
        )
    try:
        direction = np.asarray(c.pop("direction", (0.0, 0.0, -1.0)), dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"capacity: direction = {capacity['direction']!r}: a non-zero, finite (x, y, z) expected") from None
    if direction.shape != (3,) or not np.all(np.isfinite(direction)) or not np.any(direction):
        raise ValueError(f"capacity: direction = {direction.tolist()!r}: a non-zero, finite (x, y, z) expected")
    fix = c.pop("fixity", None)
    if fix is None:
        axis = int(np.argmax(np.abs(direction)))
        if np.count_nonzero(direction) != 1:
            raise ValueError("capacity: give fixity= for a direction that is not along an axis")
        fix = {"translation": ["free"] * 3, "rotation": ["free"] * 3}
        fix["translation"][axis] = 0.0
    for name, default in (("increment", 2e-5), ("max_travel", 0.012)):
        v = c.pop(name, default)
        if isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)) or not math.isfinite(v) or v <= 0:
            raise ValueError(f"capacity: {name} = {v!r}: a positive, finite length (m) expected")
        c[name] = float(v)
    return {"block": i, "direction": direction, "fixity": fix, "options": c}


def _push(m, plan, progress):
    m.set_fixity(plan["block"], plan["fixity"])
    c = dict(plan["options"])
    r = m.push_over(plan["block"], plan["direction"], c.pop("increment"), progress=progress, **c)
    return {
        "peak_load": r["peak_load"],
        "travel_at_peak": r["travel_at_peak"],
        "stop": r["stop"],
        "curve": {k: np.asarray(v).tolist() for k, v in r["curve"].items()},
    }


_PUSH_OVER_OPTIONS = ("max_unbalanced_ratio", "stop_fraction", "fallen_travel", "sample_travel", "smoothing_window", "max_steps")


def _check_run_arguments(**values):
    """The run's arguments, each named in the error (probe 3, F13: ``duration=-1`` or NaN was
    accepted): ``duration``, ``ratio``, ``ramp_time`` (the loads' ramp: a time history from 0
    needs a positive one; ``loading_type="instantaneous"`` acts from the start),
    ``contact_tolerance``, ``mechanism_scale``, ``density`` positive and finite;
    ``max_steps``, ``subcontacts_per_edge``, ``history_every``, ``max_iterations`` positive
    integers; ``facets`` an integer of at least 3; ``densities`` positive per node;
    ``friction`` ``"cone"`` or ``"pyramid"``;
    ``check_dead_load``, ``progress`` booleans; ``centre`` a finite point."""

    def number(v):
        return not isinstance(v, bool) and isinstance(v, (int, float, np.integer, np.floating)) and math.isfinite(v)

    def integer(v):
        return not isinstance(v, bool) and isinstance(v, (int, np.integer))

    for name in ("duration", "ratio", "ramp_time", "contact_tolerance", "mechanism_scale"):
        v = values[name]
        if v is None and name == "contact_tolerance":
            continue  # voussoir's default
        if not number(v) or v <= 0:
            raise ValueError(f"{name} = {v!r}: a positive, finite number expected")
    for name in ("max_steps", "subcontacts_per_edge", "max_iterations", "history_every"):
        v = values[name]
        if v is None and name in ("history_every", "subcontacts_per_edge"):
            continue  # every step / voussoir's default
        if not integer(v) or v <= 0:
            raise ValueError(f"{name} = {v!r}: a positive integer expected")
    v = values["facets"]
    if not integer(v) or v < 3:
        raise ValueError(f"facets = {v!r}: an integer of at least 3 expected (the friction pyramid's planes)")
    v = values["density"]
    if v is not None and (not number(v) or v <= 0):
        raise ValueError(f"density = {v!r}: a positive, finite density (kg/m³) expected")
    d = values["densities"]
    if d is not None:
        if not isinstance(d, dict):
            raise ValueError(f"densities = {d!r}: a dict {{graph node: density (kg/m³)}} expected")
        for node, v in d.items():
            if not number(v) or v <= 0:
                raise ValueError(f"densities[{node!r}] = {v!r}: a positive, finite density (kg/m³) expected")
    for name in ("check_dead_load", "progress"):
        v = values[name]
        if not isinstance(v, (bool, np.bool_)):
            raise ValueError(f"{name} = {v!r}: True or False expected")
    if values["friction"] not in ("cone", "pyramid"):
        raise ValueError(f"friction = {values['friction']!r}: expected 'cone' or 'pyramid'")
    c = values["centre"]
    if c is not None:
        try:
            ok = np.asarray(c, dtype=float).shape == (3,) and bool(np.all(np.isfinite(np.asarray(c, dtype=float))))
        except (TypeError, ValueError):
            ok = False
        if not ok:
            raise ValueError(f"centre = {c!r}: a finite point (x, y, z) expected")


#: The keyword arguments of :func:`run` (besides the ``voussoir.Model`` options).
_RUN_PARAMETERS = tuple(p for p in inspect.signature(run).parameters if p not in ("problem", "model", "model_options"))
