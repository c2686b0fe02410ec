"""The analyses: a ``compas_dem`` problem solved by voussoir, ``compas_dem`` ``Results`` back."""

import math
from typing import Dict, Optional, Sequence

import numpy as np

import voussoir as vs

from .convert import centroidal_loads, live_loads, to_voussoir
from .results import from_limit, from_model

ANALYSES = ("static", "dynamic", "shaking", "capacity", "limit")


def Voussoir(**parameters):
    """A ``compas_dem`` ``Solver`` named ``"voussoir"`` holding the parameters of
    :func:`solve`, so that ``problem.set_solver(compas_voussoir.Voussoir(analysis="limit",
    live="Live"))`` and then ``compas_voussoir.solve(problem)`` work as ``problem.solve()``
    does for the engines ``compas_dem`` knows."""
    from compas_dem.problem import Solver

    s = Solver()
    s.name = "voussoir"
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
    here. This is the one line that changes from ``problem.solve()``."""
    configured = getattr(problem, "_solver", None)
    if configured is not None and getattr(configured, "name", None) == "voussoir":
        options = {**configured.parameters, **options}
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
    subcontacts_per_edge: int = 15,
    ramp_time: float = 0.5,
    ratio: float = 1e-5,
    max_steps: int = 2_000_000,
    duration: float = 1.0,
    damping: Optional[dict] = None,
    ground_motion: Optional[dict] = None,
    capacity: Optional[dict] = None,
    live: Optional[Sequence[str]] = None,
    fixity: Optional[Dict[int, object]] = None,
    friction: str = "cone",
    progress: bool = False,
    **model_options,
):
    """Solves ``problem`` over ``model`` (default: the problem's) with voussoir; returns
    ``compas_dem.problem.Results`` (see ``compas_voussoir.results`` for what each entry holds
    and its signs) with ``metadata`` saying what was run.

    ``analysis`` (default ``"static"``):

    - ``"static"``: gravity and the loads (ramped over ``ramp_time`` s) with local damping,
      run to an unbalanced-force ratio below ``ratio``;
    - ``"dynamic"``: the same loads for ``duration`` s of model time with ``damping``
      (``{"kind": "rayleigh", "ratio": 0.05, "frequency": 5.0}`` by default, as
      ``voussoir.Model.set_damping`` takes it); ``metadata["history"]`` samples the blocks;
    - ``"shaking"``: settled statically, then the supports move with ``ground_motion``
      (``{"x": TimeHistory or (times, values), "y": ..., "z": ..., "kind": "acceleration"}``,
      accelerations in m/s²) for the record's length (or ``duration``), Rayleigh damping;
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
      at 0.577 W);
    - ``"limit"``: limit analysis of the loads of the boundary conditions named ``live``
      (scaled by the multiplier) with the others and gravity as dead loads;
      ``metadata["multiplier"]``, ``["carries_dead_load"]``, ``["mechanism"]`` (block
      velocities), ``fixity`` overrides per graph node (e.g. a loading plate's
      out-of-plane motions fixed).

    Model options: ``density`` (kg/m³, for blocks without a material) and ``densities`` per
    graph node; ``kn``, ``ks`` (Pa/m) over the problem's joint model; ``interfaces``
    ``{(u, v): {"phi", "c", "t_c", "kn", "kt"}}`` per pair of graph nodes;
    ``subcontacts_per_edge``; any other ``voussoir.Model`` keyword.
    """
    model = model if model is not None else problem.model
    analysis = analysis or "static"
    if analysis not in ANALYSES:
        raise ValueError(f"analysis {analysis!r}: expected one of {ANALYSES}")
    _check_run_arguments(duration=duration, ramp_time=ramp_time, ratio=ratio, max_steps=max_steps)
    conv = to_voussoir(
        problem,
        model,
        density=density,
        densities=densities,
        kn=kn,
        ks=ks,
        interfaces=interfaces,
        subcontacts_per_edge=subcontacts_per_edge,
        **model_options,
    )
    m = conv.model
    meta = {"engine": "voussoir", "version": vs.__version__, "analysis": analysis, "joint_law": conv.law}

    if analysis == "limit":
        if not live:
            raise ValueError('analysis="limit" needs live=["name of the boundary condition with the live loads"]')
        names = [live] if isinstance(live, str) else list(live)
        dead = [bc for bc in problem.boundary_conditions if bc.name not in names]
        if any(bc.displacements for bc in problem.boundary_conditions):
            raise ValueError("limit analysis of a problem with prescribed displacements is not supported")
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
        overrides = {conv.index[n]: f for n, f in (fixity or {}).items()}
        r = vs.limit(m, loads, fixity=overrides, friction=friction)
        meta.update(
            {
                "multiplier": r["multiplier"],
                "status": r["status"],
                "carries_dead_load": r["carries_dead_load"],
                "live": names,
                "mechanism": {
                    conv.node[i]: {
                        "velocity": r["blocks"]["velocity"][i].tolist(),
                        "angular_velocity": r["blocks"]["angular_velocity"][i].tolist(),
                    }
                    for i in conv.node
                },
            }
        )
        return from_limit(problem, model, conv, r, meta)

    if analysis in ("static", "capacity", "shaking"):
        m.set_damping("local", alpha=0.8)
        prescribed = _apply_loads_and_motions(problem, model, conv, ramp_time)
        m.run_until_time(ramp_time, progress=progress)
        _stop_prescribed(conv, prescribed)
        steps = m.run_to_equilibrium(ratio, max_steps, progress=progress)
        meta.update({"settle_steps": int(steps), "unbalanced_ratio": m.unbalanced_force_ratio})

    if analysis == "dynamic":
        d = dict(damping or {"kind": "rayleigh", "ratio": 0.05, "frequency": 5.0})
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
        if not ground_motion:
            raise ValueError('analysis="shaking" needs ground_motion={"x": TimeHistory or (times, accelerations)}')
        gm = dict(ground_motion)
        kind = gm.pop("kind", "acceleration")
        axes = {}
        for axis in ("x", "y", "z"):
            h = gm.pop(axis, None)
            if h is not None and not isinstance(h, vs.TimeHistory):
                h = vs.TimeHistory(list(h[0]), list(h[1]))
            axes[axis] = h
        if gm:
            raise ValueError(f"ground_motion: unknown keys {sorted(gm)}")
        d = dict(damping or {"kind": "rayleigh", "ratio": 0.05, "frequency": 5.0})
        m.set_damping(d.pop("kind"), **d)
        supports = [conv.index[e.graphnode] for e in model.elements() if e.is_support]
        if not supports:
            raise ValueError("shaking: the model has no support blocks to move")
        for i in supports:
            m.set_base_motion(i, axes["x"], axes["y"], axes["z"], kind=kind)
        end = max(h.end for h in axes.values() if h is not None)
        t0 = m.time
        m.run_until_time(t0 + end, progress=progress)
        meta["shaking_duration"] = m.time - t0

    if analysis == "capacity":
        if not capacity or "block" not in capacity:
            raise ValueError('analysis="capacity" needs capacity={"block": graph node, "direction": (x, y, z)}')
        c = dict(capacity)
        node = c.pop("block")
        if node not in conv.index:
            raise ValueError(
                f"capacity: block {node!r} is not a node of the model's graph (its nodes: {sorted(conv.index)[:20]}"
                f"{' ...' if len(conv.index) > 20 else ''})"
            )
        i = conv.index[node]
        others = [j for j in range(len(m)) if j != i and not m.block(j).is_fixed]
        if not others:
            raise ValueError(
                "capacity: the pushed block is the only one that moves; push a loading device (a plate seated on "
                "the structure) so that the servo has free blocks to wait for"
            )
        direction = np.asarray(c.pop("direction", (0.0, 0.0, -1.0)), dtype=float)
        fix = c.pop("fixity", None)
        if fix is None:
            axis = int(np.argmax(np.abs(direction)))
            if np.count_nonzero(direction) != 1:
                raise ValueError("capacity: give fixity= for a direction that is not along an axis")
            fix = {"translation": ["free"] * 3, "rotation": ["free"] * 3}
            fix["translation"][axis] = 0.0
        m.set_fixity(i, fix)
        r = m.push_over(
            i,
            direction,
            c.pop("increment", 2e-5),
            max_travel=c.pop("max_travel", 0.012),
            progress=progress,
            **c,
        )
        meta.update(
            {
                "peak_load": r["peak_load"],
                "travel_at_peak": r["travel_at_peak"],
                "stop": r["stop"],
                "curve": {k: np.asarray(v).tolist() for k, v in r["curve"].items()},
            }
        )

    meta.update({"time": m.time, "steps": m.step_count, "energies": dict(m.energies())})
    return from_model(problem, model, conv, meta)


def _check_run_arguments(**values):
    """The run's numeric arguments, each named in the error: ``duration`` and ``ratio``
    positive and finite, ``ramp_time`` finite and not negative, ``max_steps`` a positive
    integer (probe 3, F13: ``duration=-1`` or NaN was accepted)."""
    for name in ("duration", "ratio"):
        v = values[name]
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v <= 0:
            raise ValueError(f"{name} = {v!r}: a positive, finite number expected")
    v = values["ramp_time"]
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v < 0:
        raise ValueError(f"ramp_time = {v!r}: a finite number not below 0 expected")
    v = values["max_steps"]
    if isinstance(v, bool) or not isinstance(v, int) or v <= 0:
        raise ValueError(f"max_steps = {v!r}: a positive integer expected")
