"""From a ``compas_dem`` block model and its ``Problem`` to a ``voussoir.Model``.

Conventions (those of ``compas_dem`` and its other engines):

- SI units: m, kg, N, Pa; gravity along ``-z`` with the boundary conditions' ``g`` (9.81 m/s²);
- a block is an element of the model's graph, named by its graph node; ``is_support`` blocks
  are fixed;
- the contact model is Mohr–Coulomb (``phi`` in degrees, ``c`` cohesion in Pa, ``t_c``
  tensile strength in Pa); the joint model's ``kn``, ``kt`` are stiffnesses per unit area
  (Pa/m, 3DEC's ``jkn``, ``jks``);
- loads are resolved to the block centroids by ``compas_dem``'s own
  ``resolve_centroidal_loads`` (point, surface and body loads), as for LMGC90; a ``"ramp"``
  load rises from zero over ``ramp_time`` and holds, an ``"instantaneous"`` one acts from the
  start; prescribed translations and rotations (``Translation``, ``Rotation``) are reached at a
  constant rate over ``ramp_time``.
"""

from dataclasses import dataclass, field
from typing import Dict, Optional

import numpy as np

import voussoir as vs

#: Joint stiffnesses used when the problem has no joint model (Pa/m): the reference arch's
#: (Pulatsu et al. 2021); ``docs/theory.md`` §4.1 says how to choose them.
DEFAULT_KN = 4e9
DEFAULT_KS = 1.6e9


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


def joint_law(problem, kn=None, ks=None):
    """The ``voussoir.CoulombSlip`` of the problem's contact and joint models, and its parameters."""
    props = problem.contact_properties
    cm = props.contact_model
    if cm is None:
        raise ValueError('the problem has no contact model: problem.set_contact_model("MohrCoulomb", phi=...)')
    phi = float(getattr(cm, "_phi", None) if getattr(cm, "_phi", None) is not None else np.degrees(np.arctan(cm.mu)))
    cohesion = float(cm.c or 0.0)
    tension = float(cm.t_c or 0.0)
    jm = props.joint_model
    default = jm is None or jm.kn is None
    kn = float(kn if kn is not None else (jm.kn if not default else DEFAULT_KN))
    if ks is None:
        ks = jm.kt if (jm is not None and jm.kt is not None) else (DEFAULT_KS if default else 0.4 * kn)
    ks = float(ks)
    law = vs.CoulombSlip(kn, ks, phi, residual_friction_deg=phi, cohesion=cohesion, tensile_strength=tension)
    return law, {"kn": kn, "ks": ks, "phi": phi, "cohesion": cohesion, "tensile_strength": tension, "default_stiffness": default}


def to_voussoir(
    problem,
    model=None,
    *,
    density: Optional[float] = None,
    densities: Optional[Dict[int, float]] = None,
    kn: Optional[float] = None,
    ks: Optional[float] = None,
    interfaces: Optional[Dict[tuple, dict]] = None,
    subcontacts_per_edge: int = 15,
    contact_tolerance: float = 1e-3,
    **model_options,
) -> Conversion:
    """Builds the ``voussoir.Model`` of a problem (its model's blocks, supports and joints);
    loads and motions are applied by the analyses (``compas_voussoir.solve``).

    ``density`` (kg/m³) fills in blocks without a material; ``densities`` overrides it per
    graph node. ``kn``, ``ks`` (Pa/m) override the joint model. ``interfaces`` maps a pair of
    graph nodes to the Mohr–Coulomb and stiffness values of that interface only
    (``{"phi", "c", "t_c", "kn", "kt"}``, missing ones taken from the problem), as
    ``compas_3dec``'s per-interface properties.
    """
    model = model if model is not None else problem.model
    law, params = joint_law(problem, kn, ks)
    g = _gravity(problem)
    m = vs.Model(
        gravity=(0.0, 0.0, -g),
        subcontacts_per_edge=subcontacts_per_edge,
        contact_tolerance=contact_tolerance,
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
    for (a, b), values in (interfaces or {}).items():
        if a not in index or b not in index:
            raise ValueError(f"interfaces: no block {a if a not in index else b} in the model")
        kn_i = float(values.get("kn", params["kn"]))
        ks_i = float(values.get("kt", params["ks"] if "kn" not in values else 0.4 * kn_i))
        phi_i = float(values.get("phi", params["phi"]))
        m.set_interface_law(
            index[a],
            index[b],
            vs.CoulombSlip(
                kn_i,
                ks_i,
                phi_i,
                residual_friction_deg=phi_i,
                cohesion=float(values.get("c", params["cohesion"]) or 0.0),
                tensile_strength=float(values.get("t_c", params["tensile_strength"]) or 0.0),
            ),
        )
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
    ``voussoir.limit`` live loads (a force at a point, N per unit multiplier)."""
    groups = [bc for bc in problem.boundary_conditions if bc.name in names]
    missing = set(names) - {bc.name for bc in groups}
    if missing:
        raise ValueError(f"no boundary condition named {sorted(missing)}; the problem has {[bc.name for bc in problem.boundary_conditions]}")
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
    if not loads:
        raise ValueError(f"the boundary conditions {sorted(names)} hold no loads")
    return loads
