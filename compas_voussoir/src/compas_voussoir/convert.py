"""From a ``compas_dem`` block model and its ``Problem`` to a ``voussoir.Model``.

Conventions (those of ``compas_dem`` and its other engines):

- SI units: m, kg, N, Pa; gravity along ``-z`` with the boundary conditions' ``g`` (9.81 m/s²);
- a block is an element of the model's graph, named by its graph node; ``is_support`` blocks
  are fixed;
- the contact model is Mohr–Coulomb (``phi`` in degrees, ``c`` cohesion in Pa, ``t_c``
  tensile strength in Pa); the joint model's ``kn``, ``kt`` are stiffnesses **per unit
  area** (Pa/m, 3DEC's ``jkn``, ``jks``), not the N/m of ``compas_dem``'s
  ``Problem.set_joint_model`` docstring: a joint of area ``A`` with ``kn`` Pa/m is a spring of
  ``kn·A`` N/m. A value outside ``PLAUSIBLE_STIFFNESS`` (1e8–1e14 Pa/m) is used as given but
  warned about (:class:`StiffnessUnitsWarning`), with the Pa/m it would be if it were a
  whole joint's N/m;
- loads are resolved to the block centroids by ``compas_dem``'s own
  ``resolve_centroidal_loads`` (point, surface and body loads), as for LMGC90; a ``"ramp"``
  load rises from zero over ``ramp_time`` and holds, an ``"instantaneous"`` one acts from the
  start; prescribed translations and rotations (``Translation``, ``Rotation``) are reached at a
  constant rate over ``ramp_time``.
"""

import math
import os
import sys
import warnings
from dataclasses import dataclass, field
from typing import Dict, Optional

import numpy as np

import voussoir as vs

#: Joint stiffnesses used when the problem has no joint model (Pa/m): the reference arch's
#: (Pulatsu et al. 2021); ``docs/theory.md`` §4.1 says how to choose them.
DEFAULT_KN = 4e9
DEFAULT_KS = 1.6e9

#: The joint stiffnesses per unit area (Pa/m) of masonry joints, from a soft lime-mortar bed
#: (E ≈ 0.1–1 GPa over 10–20 mm: 5e9–1e11) or a dry joint (measured 1e9–1e11) down to a very
#: soft one with a decade to spare (1e8), up to stone on stone (E ≈ 50 GPa over a 1 mm
#: asperity layer: 5e13) with a factor to spare (1e14). A whole-joint stiffness in N/m is the
#: per-area one times the joint's area (0.01–0.5 m² for stones and bricks): a value given in
#: N/m is one to two decades smaller, and a value below 1e8 "Pa/m" is most likely N/m (or a
#: slip of the exponent); above 1e14 Pa/m the DEM's time step (∝ 1/√kn) becomes tiny for no
#: gain in accuracy (the rigid limit is reached long before; docs/theory.md §4.1).
PLAUSIBLE_STIFFNESS = (1e8, 1e14)

#: The ``voussoir.Model`` keywords that ``to_voussoir`` and the analyses pass on (gravity comes
#: from the problem; ``contact_tolerance`` and ``subcontacts_per_edge`` have their own).
MODEL_OPTIONS = ("subcontact_spacing", "time_step", "safety", "mode", "max_speed", "impact_step")

_SOURCE_NAMES = {
    "kn=": "kn",
    "ks=": "ks",
    "joint model kn": "the joint model's kn (problem.set_joint_model)",
    "joint model kt": "the joint model's kt (problem.set_joint_model)",
}


class StiffnessUnitsWarning(UserWarning):
    """A joint stiffness outside :data:`PLAUSIBLE_STIFFNESS` (1e8–1e14 Pa/m): compas_voussoir
    reads ``kn``, ``kt`` per unit area (Pa/m); ``compas_dem``'s ``set_joint_model`` docstring
    says N/m (a whole joint's spring). The value is used as given."""


@dataclass
class Conversion:
    """A ``voussoir.Model`` built from a ``compas_dem`` model, and how its blocks map back."""

    model: "vs.Model"
    #: voussoir block index of each graph node.
    index: Dict[int, int]
    #: graph node of each voussoir block index.
    node: Dict[int, int]
    #: the joint law's parameters and whether the stiffnesses were defaults.
    law: Dict[str, object] = field(default_factory=dict)
    #: initial centroids (n × 3) and rotation matrices (n × 3 × 3) of the blocks.
    centroids: Optional[np.ndarray] = None
    rotations: Optional[np.ndarray] = None


def _gravity(problem) -> float:
    gs = {float(bc.g) for bc in problem.boundary_conditions}
    if len(gs) > 1:
        raise ValueError(f"the boundary conditions disagree on g: {sorted(gs)} m/s²; voussoir has one gravity")
    return gs.pop() if gs else 9.81


def _density(block, node, density, densities):
    if densities and node in densities:
        return float(densities[node])
    material = getattr(block, "material", None)
    if material is not None and getattr(material, "density", None):
        return float(material.density)
    if density is not None:
        return float(density)
    raise ValueError(
        f"block {node} has no material with a density; give density= (kg/m³) or densities={{{node}: ...}}"
    )


def _stiffness(value, name):
    """A joint stiffness (Pa/m) as a float; ``name`` says where it came from."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
        raise ValueError(f"{name} = {value!r}: a joint stiffness per unit area (Pa/m) expected, a number")
    v = float(value)
    if not math.isfinite(v) or v <= 0.0:
        raise ValueError(f"{name} = {value!r}: a joint stiffness per unit area (Pa/m) must be positive and finite")
    return v


#: The keys of a fracture specification (``fracture=`` and an interface's entries): the
#: fracture energies (J/m²) of mode I (with the tensile strength ``t_c``) and mode II (with the
#: cohesion ``c``), the residual friction angle (degrees) and the softening curve.
FRACTURE_KEYS = ("gf_i", "gf_ii", "phi_r", "softening")


def _law(kn, ks, phi, cohesion, tension, fracture, where):
    """``voussoir.MortarJoint`` when ``fracture`` gives a fracture energy (softening on it),
    else ``voussoir.CoulombSlip`` (brittle, as before)."""
    fracture = fracture or {}
    extra = sorted(set(fracture) - set(FRACTURE_KEYS))
    if extra:
        raise ValueError(f"{where}: unknown keys {extra}; the fracture keys are {', '.join(FRACTURE_KEYS)}")
    gf_i, gf_ii = fracture.get("gf_i"), fracture.get("gf_ii")
    phi_r = float(fracture.get("phi_r", phi))
    if gf_i is None and gf_ii is None:
        if "phi_r" in fracture or "softening" in fracture:
            raise ValueError(f"{where}: phi_r and softening need a fracture energy (gf_i or gf_ii)")
        return vs.CoulombSlip(kn, ks, phi, residual_friction_deg=phi, cohesion=cohesion, tensile_strength=tension)
    for name, g, strength, strength_name in (("gf_i", gf_i, tension, "t_c"), ("gf_ii", gf_ii, cohesion, "c")):
        if g is not None and strength <= 0.0:
            raise ValueError(f"{where}: {name} = {g!r} softens the {strength_name}, which is {strength}: give {strength_name} > 0")
    return vs.MortarJoint(
        kn,
        ks,
        phi,
        residual_friction_deg=phi_r,
        tensile_strength=tension,
        # A strength without its fracture energy stays brittle (0); no strength, no energy.
        mode_i_fracture_energy=float(gf_i) if gf_i is not None else (0.0 if tension > 0.0 else None),
        cohesion=cohesion,
        mode_ii_fracture_energy=float(gf_ii) if gf_ii is not None else (0.0 if cohesion > 0.0 else None),
        softening=fracture.get("softening", "exponential"),
    )


def joint_law(problem, kn=None, ks=None, fracture=None):
    """The joint law of the problem's contact and joint models, and its parameters (``kn``,
    ``ks`` in Pa/m: per unit joint area; ``sources`` says where each came from):
    ``voussoir.CoulombSlip`` (brittle tension cut-off and cohesion, as compas_dem's Mohr–Coulomb
    model), or ``voussoir.MortarJoint`` when ``fracture`` gives fracture energies
    (:data:`FRACTURE_KEYS`; compas_dem's model has none): the tensile strength and cohesion then
    soften on them, friction going to ``phi_r``."""
    props = problem.contact_properties
    cm = props.contact_model
    if cm is None:
        raise ValueError('the problem has no contact model: problem.set_contact_model("MohrCoulomb", phi=...)')
    phi = float(getattr(cm, "_phi", None) if getattr(cm, "_phi", None) is not None else np.degrees(np.arctan(cm.mu)))
    cohesion = float(cm.c or 0.0)
    tension = float(cm.t_c or 0.0)
    jm = props.joint_model
    if kn is not None:
        kn, kn_from = _stiffness(kn, "kn"), "kn="
    elif jm is not None and jm.kn is not None:
        kn, kn_from = _stiffness(jm.kn, "the joint model's kn (problem.set_joint_model)"), "joint model kn"
    else:
        kn, kn_from = DEFAULT_KN, "default"
    if ks is not None:
        ks, ks_from = _stiffness(ks, "ks"), "ks="
    elif jm is not None and jm.kt is not None:
        ks, ks_from = _stiffness(jm.kt, "the joint model's kt (problem.set_joint_model)"), "joint model kt"
    elif kn_from == "default":
        ks, ks_from = DEFAULT_KS, "default"
    else:
        ks, ks_from = 0.4 * kn, "0.4 kn"
    default = kn_from == "default"
    law = _law(kn, ks, phi, cohesion, tension, fracture, "fracture")
    return law, {
        "law": type(law).__name__,
        "fracture": dict(fracture or {}),
        "kn": kn,
        "ks": ks,
        "units": "Pa/m",
        "phi": phi,
        "cohesion": cohesion,
        "tensile_strength": tension,
        "default_stiffness": default,
        "sources": {"kn": kn_from, "ks": ks_from},
    }


def _polygon_area(points):
    p = np.asarray(points, dtype=float).reshape(-1, 3)
    if len(p) < 3:
        return 0.0
    return 0.5 * float(np.linalg.norm(np.cross(p - p[0], np.roll(p, -1, axis=0) - p[0]).sum(axis=0)))


def joint_areas(m):
    """The areas (m²) of the contacts of the ``voussoir.Model`` ``m`` as one step finds them
    (on a copy: ``m`` is not stepped); ``None`` when they cannot be found."""
    try:
        copy = vs.Model.from_checkpoint_string(m.to_checkpoint_string())
        copy.step()
        areas = [_polygon_area(p) for p in copy.contacts()["polygon"]]
    except (ValueError, MemoryError, OSError):
        return None
    areas = [a for a in areas if a > 0.0]
    return np.asarray(areas) if areas else None


def warn(warning):
    """``warnings.warn`` pointing at the first caller outside compas_voussoir (the user's line,
    whichever way the call came: ``solve``, ``run``, ``problem.solve()``)."""
    here = os.path.dirname(os.path.abspath(__file__))
    level, frame = 2, sys._getframe(1)
    while frame is not None and os.path.dirname(os.path.abspath(frame.f_code.co_filename)) == here:
        frame, level = frame.f_back, level + 1
    warnings.warn(warning, stacklevel=level)


def check_stiffnesses(values, m=None):
    """Warns (:class:`StiffnessUnitsWarning`) for each ``{name: stiffness}`` outside
    :data:`PLAUSIBLE_STIFFNESS`, with what it would be in Pa/m if it were a whole joint's N/m
    (divided by the median area of the joints of ``m``, when given). Returns the names warned
    about."""
    lo, hi = PLAUSIBLE_STIFFNESS
    odd = {name: v for name, v in values.items() if not lo <= v <= hi}
    if not odd:
        return []
    areas = joint_areas(m) if m is not None else None
    area = float(np.median(areas)) if areas is not None else None
    for name, v in odd.items():
        where = "below" if v < lo else "above"
        text = (
            f"{name} = {v:.4g} Pa/m is {where} the {lo:.0e}–{hi:.0e} Pa/m of masonry joints. compas_voussoir reads "
            "joint stiffnesses per unit area (Pa/m, 3DEC's jkn/jks), not the N/m of compas_dem's "
            "set_joint_model docstring"
        )
        if area is not None:
            per_area = v / area
            plausible = lo <= per_area <= hi
            text += (
                f"; if {v:.4g} is a whole joint's stiffness in N/m, divide it by the joint's area: these joints' "
                f"median area is {area:.4g} m², which gives {per_area:.4g} Pa/m"
                + ("" if plausible else " (still outside the range)")
            )
        else:
            text += "; if it is a whole joint's stiffness in N/m, divide it by the joint's area (m²)"
        warn(StiffnessUnitsWarning(text + ". The value is used as given."))
    return list(odd)


def to_voussoir(
    problem,
    model=None,
    *,
    density: Optional[float] = None,
    densities: Optional[Dict[int, float]] = None,
    kn: Optional[float] = None,
    ks: Optional[float] = None,
    interfaces: Optional[Dict[tuple, dict]] = None,
    fracture: Optional[dict] = None,
    subcontacts_per_edge: Optional[int] = None,
    contact_tolerance: Optional[float] = None,
    **model_options,
) -> Conversion:
    """Builds the ``voussoir.Model`` of a problem (its model's blocks, supports and joints);
    loads and motions are applied by the analyses (``compas_voussoir.solve``).

    ``density`` (kg/m³) fills in blocks without a material; ``densities`` overrides it per
    graph node. ``kn``, ``ks`` (Pa/m) override the joint model. ``interfaces`` maps a pair of
    graph nodes to the Mohr–Coulomb and stiffness values of that interface only
    (``{"phi", "c", "t_c", "kn", "kt"}``, missing ones taken from the problem), as
    ``compas_3dec``'s per-interface properties, and its fracture energies
    (:data:`FRACTURE_KEYS`). ``fracture`` (``{"gf_i", "gf_ii", "phi_r", "softening"}``, J/m² and
    degrees) makes every joint a ``voussoir.MortarJoint`` softening on those fracture energies
    (compas_dem's Mohr–Coulomb model has none; without them the joints are brittle
    ``voussoir.CoulombSlip``, as before). Stiffnesses are per unit joint area (Pa/m);
    one outside :data:`PLAUSIBLE_STIFFNESS` is warned about (:class:`StiffnessUnitsWarning`).
    ``model_options``: the ``voussoir.Model`` keywords in :data:`MODEL_OPTIONS`.
    """
    model = model if model is not None else problem.model
    unknown = sorted(set(model_options) - set(MODEL_OPTIONS))
    if unknown:
        raise TypeError(
            f"unexpected keyword argument{'s' if len(unknown) > 1 else ''} {', '.join(map(repr, unknown))}; "
            f"voussoir.Model options are {', '.join(MODEL_OPTIONS)}"
        )
    law, params = joint_law(problem, kn, ks, fracture)
    g = _gravity(problem)
    # None: voussoir's own default (``voussoir.Model.defaults()``), not restated here.
    given = {"subcontacts_per_edge": subcontacts_per_edge, "contact_tolerance": contact_tolerance}
    m = vs.Model(
        gravity=(0.0, 0.0, -g),
        **{k: v for k, v in given.items() if v is not None},
        **model_options,
    )
    m.set_joint_law(0, 0, law)
    index, node = {}, {}
    for element in model.elements():
        n = element.graphnode
        vertices, faces = element.modelgeometry.to_vertices_and_faces()
        rho = _density(element, n, density, densities)
        i = m.add_polyhedron(f"block {n}", vertices, rho, faces=faces, fixed=bool(element.is_support))
        index[n], node[i] = i, n
    for n in densities or {}:
        if n not in index:
            raise ValueError(f"densities: block {n!r} is not a node of the model's graph")
    stiffnesses = {} if params["default_stiffness"] else {_SOURCE_NAMES[params["sources"]["kn"]]: params["kn"]}
    if params["sources"]["ks"] in ("ks=", "joint model kt"):
        stiffnesses[_SOURCE_NAMES[params["sources"]["ks"]]] = params["ks"]
    if interfaces is not None and not isinstance(interfaces, dict):
        raise ValueError(f"interfaces = {interfaces!r}: a dict {{(u, v): {{'phi', 'c', 't_c', 'kn', 'kt'}}}} expected")
    for key, values in (interfaces or {}).items():
        if not (isinstance(key, tuple) and len(key) == 2):
            raise ValueError(f"interfaces: key {key!r} is not a pair of graph nodes (u, v)")
        a, b = key
        if a not in index or b not in index:
            raise ValueError(f"interfaces: no block {a if a not in index else b} in the model")
        extra = sorted(set(values) - {"phi", "c", "t_c", "kn", "kt", *FRACTURE_KEYS})
        if extra:
            raise ValueError(
                f"interfaces[{key!r}]: unknown keys {extra}; expected phi, c, t_c, kn, kt, {', '.join(FRACTURE_KEYS)}"
            )
        kn_i = _stiffness(values["kn"], f"interfaces[{key!r}]['kn']") if "kn" in values else params["kn"]
        if "kt" in values:
            ks_i = _stiffness(values["kt"], f"interfaces[{key!r}]['kt']")
        else:
            ks_i = params["ks"] if "kn" not in values else 0.4 * kn_i
        for name in ("kn", "kt"):
            if name in values:
                stiffnesses[f"interfaces[{key!r}]['{name}']"] = kn_i if name == "kn" else ks_i
        phi_i = float(values.get("phi", params["phi"]))
        # An interface's fracture energies, else the problem's (``fracture=``).
        own = {k: values[k] for k in FRACTURE_KEYS if k in values}
        m.set_interface_law(
            index[a],
            index[b],
            _law(
                kn_i,
                ks_i,
                phi_i,
                float(values.get("c", params["cohesion"]) or 0.0),
                float(values.get("t_c", params["tensile_strength"]) or 0.0),
                own or fracture,
                f"interfaces[{key!r}]",
            ),
        )
    params["units_warning"] = check_stiffnesses(stiffnesses, m)
    return Conversion(
        model=m,
        index=index,
        node=node,
        law=params,
        centroids=m.positions().copy(),
        rotations=m.rotation_matrices().copy(),
    )


def centroidal_loads(problem, model, conversion):
    """``{voussoir index: {"ramp": (force, moment), "instantaneous": (force, moment)}}`` of the
    problem's loads, resolved to the centroids by ``compas_dem`` (moments about compas_dem's
    block point are moved to voussoir's centroid)."""
    from compas_dem.analysis.resolve import resolve_centroidal_loads

    resolved = resolve_centroidal_loads(model, problem.boundary_conditions)
    out = {}
    for n, entry in resolved.items():
        i = conversion.index[n]
        block = model.graph.node_element(n)
        shift = np.asarray(conversion.centroids[i]) - np.asarray(list(block.point))
        kinds = {}
        for kind, bucket in entry["by_loading_type"].items():
            f = np.asarray(list(bucket["force"]), dtype=float)
            mo = np.asarray(list(bucket["moment"]), dtype=float)
            # M about the centroid c = M about p + (p − c) × F.
            mo = mo - np.cross(shift, f)
            if np.any(f != 0.0) or np.any(mo != 0.0):
                kinds[kind] = (f, mo)
        if kinds:
            out[i] = kinds
    return out


def live_loads(problem, model, conversion, names):
    """The point, surface and body loads of the boundary conditions named ``names`` as
    ``voussoir.limit`` live loads (a force at a point, N per unit multiplier); loads of zero
    force are left out (none left: only the dead load is to be checked)."""
    groups = [bc for bc in problem.boundary_conditions if bc.name in names]
    missing = set(names) - {bc.name for bc in groups}
    if missing:
        raise ValueError(f"live: no boundary condition named {sorted(missing)}; the problem has {[bc.name for bc in problem.boundary_conditions]}")
    loads = []
    for bc in groups:
        for e in bc.point_loads:
            if e.moment is not None and e.point is None and np.any(np.asarray(e.moment) != 0.0):
                raise ValueError(f"live load on block {e.block_index}: a moment cannot be a live load of the limit analysis")
            i = conversion.index[e.block_index]
            point = list(e.point) if e.point is not None else list(conversion.centroids[i])
            loads.append({"block": i, "point": point, "force": list(e.force or [0.0, 0.0, 0.0])})
        for e in bc.surface_loads:
            block = model.graph.node_element(e.block_index)
            area = block.modelgeometry.face_area(e.face_index)
            loads.append(
                {
                    "block": conversion.index[e.block_index],
                    "point": list(block.modelgeometry.face_center(e.face_index)),
                    "force": list(np.asarray(e.load, dtype=float) * area),
                }
            )
        for e in bc.body_forces:
            for element in model.elements():
                i = conversion.index[element.graphnode]
                mass = conversion.model.block(i).mass
                loads.append(
                    {"block": i, "point": list(conversion.centroids[i]), "force": list(np.asarray(e.acceleration) * mass)}
                )
    # A zero live load asks only whether the dead load is carried: dropped here (the limit
    # analysis then checks the dead load alone).
    return [load for load in loads if np.any(np.asarray(load["force"], dtype=float) != 0.0)]
