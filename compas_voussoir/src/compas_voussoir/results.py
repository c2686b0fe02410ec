"""From a ``voussoir.Model`` (or a limit analysis) to ``compas_dem``'s engine-neutral ``Results``.

Per block (graph node): ``transformation``, the rigid motion from the initial pose to the
current one (``T·x`` maps a point of the block as built to where it is).

Per contact (graph edge, oriented as in the model's graph when it has the edge):

- ``face_contact`` / ``edge_contact`` / ``point_contact`` from the contact polygon (three or
  more corners / a segment / a point);
- ``contact_polygon`` (``compas.geometry.Polygon``), ``contact_points`` (its corners),
  ``contact_frame`` (``zaxis`` the contact normal from ``edge[0]`` to ``edge[1]``);
- ``resultant_global``: the force on ``edge[1]``'s block, the block the frame's ``zaxis``
  points into (as compas_dem's CRA, RBE, PRD and BLA report it; ``metadata["force_on"]`` says
  so; ``resultant_global · zaxis = F_n ≥ 0`` in compression, the rule that holds for every
  backend); ``resultant_local``: ``[F_u, F_v, F_n]`` in the frame, ``F_n`` positive in
  compression;
- ``force_point``: where the resultant acts (the centre of the normal forces), at which it
  gives the contact's moment about any axis in the joint plane; ``force_magnitude``;
- ``status`` per corner: DEM, that of the nearest sub-contact (``"elastic"``, ``"sliding"``,
  ``"open"``); limit analysis, the mechanism's (``"sliding"``, ``"open"``, ``"closed"``);
- ``force_normal``, ``force_tangent1``, ``force_tangent2`` and ``contact_data``
  (``FrictionContact``/``EdgeContact``/``VertexContact`` with ``c_np``, ``c_nn``, ``c_u``,
  ``c_v`` at the corners): corner forces that add up to the resultant and, for the normal
  forces, put it at ``force_point`` (the least-squares distribution over the corners; from a
  limit analysis, the solver's own corner forces).
"""

import numpy as np

import compas.geometry as cg
from compas_dem.interactions import EdgeContact, FrictionContact, VertexContact
from compas_dem.problem.results import Results


def _transformation(R0, c0, R1, c1):
    R = np.asarray(R1) @ np.asarray(R0).T
    t = np.asarray(c1) - R @ np.asarray(c0)
    M = np.eye(4)
    M[:3, :3], M[:3, 3] = R, t
    return cg.Transformation.from_matrix(M.tolist())


def _edge(graph, u, v):
    if graph.has_edge((u, v)):
        return (u, v), False
    if graph.has_edge((v, u)):
        return (v, u), False
    return (u, v), True


def _frame(normal):
    n = np.asarray(normal, dtype=float)
    a = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    t1 = np.cross(n, a)
    t1 /= np.linalg.norm(t1)
    t2 = np.cross(n, t1)
    return t1, t2, n


def corner_normal_forces(corners, total, point):
    """Normal forces at the corners of a polygon that add up to ``total`` and act at ``point``:
    the least-norm solution of ``Σ f_i = N``, ``Σ f_i (x_i − c) = N (p − c)`` in the polygon's
    plane (exact for three or more corners not on a line)."""
    corners = np.asarray(corners, dtype=float)
    k = len(corners)
    if k == 1 or total == 0.0 or point is None or not np.all(np.isfinite(point)):
        return np.full(k, total / k)
    c = corners.mean(axis=0)
    d = corners - c
    r = np.asarray(point, dtype=float) - c
    # Coordinates in the polygon's plane (or along its line).
    u, s, vt = np.linalg.svd(d, full_matrices=False)
    rank = int(np.sum(s > 1e-12 * max(s[0], 1e-300)))
    axes = vt[:rank]
    A = np.vstack([np.ones(k), (d @ axes.T).T])
    b = np.concatenate([[total], total * (axes @ r)])
    f, *_ = np.linalg.lstsq(A, b, rcond=None)
    return f


def _set_contact(
    results, edge, corners, normal, force_on_first, normal_force, point, fn_corners=None, ft_corners=None, status=None
):
    """One contact's entries; ``normal`` from edge[0] to edge[1], ``force_on_first`` on edge[0]."""
    t1, t2, n = _frame(normal)
    # The force on edge[1] (the block the normal points into), with F_n positive in compression.
    F = -np.asarray(force_on_first, dtype=float)
    Fu, Fv = float(F @ t1), float(F @ t2)
    corners = [list(map(float, p)) for p in corners]
    k = len(corners)
    if fn_corners is None:
        fn_corners = corner_normal_forces(corners, normal_force, point) if k else []
    if ft_corners is None:
        ft_corners = [(Fu / k, Fv / k)] * k if k else []
    origin = point if point is not None and np.all(np.isfinite(point)) else np.mean(corners, axis=0) if k else [0, 0, 0]
    frame = cg.Frame(list(map(float, origin)), list(t1), list(t2))
    forces = [
        {"c_np": max(float(fn), 0.0), "c_nn": max(-float(fn), 0.0), "c_u": float(fu), "c_v": float(fv)}
        for fn, (fu, fv) in zip(fn_corners, ft_corners)
    ]
    results.set_edge(edge, "face_contact", k >= 3)
    results.set_edge(edge, "edge_contact", k == 2)
    results.set_edge(edge, "point_contact", k == 1)
    results.set_edge(edge, "contact_points", corners)
    results.set_edge(edge, "contact_frame", frame)
    results.set_edge(edge, "resultant_global", F.tolist())
    results.set_edge(edge, "resultant_local", [Fu, Fv, float(normal_force)])
    results.set_edge(edge, "force_point", None if point is None or not np.all(np.isfinite(point)) else list(map(float, point)))
    results.set_edge(edge, "force_magnitude", float(np.linalg.norm(F)))
    results.set_edge(edge, "force_normal", [f["c_np"] - f["c_nn"] for f in forces])
    results.set_edge(edge, "force_tangent1", [f["c_u"] for f in forces])
    results.set_edge(edge, "force_tangent2", [f["c_v"] for f in forces])
    if status is not None:
        results.set_edge(edge, "status", list(status))
    if k >= 3:
        results.set_edge(edge, "contact_polygon", cg.Polygon(corners))
        fc = FrictionContact(points=corners)
        fc._frame = frame
        fc.forces = forces
        results.set_edge(edge, "contact_data", fc)
    elif k == 2:
        line = cg.Line(corners[0], corners[1])
        results.set_edge(edge, "contact_data", EdgeContact(points=corners, frame=frame, forces=forces))
        results.set_edge(edge, "contact_geometry", line)
    elif k == 1:
        results.set_edge(edge, "contact_data", VertexContact(point=cg.Point(*corners[0]), frame=frame, forces=forces))
        results.set_edge(edge, "contact_geometry", cg.Point(*corners[0]))


def from_model(problem, model, conversion, metadata=None):
    """The ``Results`` of the voussoir model as it stands."""
    m = conversion.model
    results = Results(model_id=str(model.guid), problem_id=str(problem.guid))
    positions, rotations = m.positions(), m.rotation_matrices()
    for i, n in conversion.node.items():
        results.set_node(n, "transformation", _transformation(conversion.rotations[i], conversion.centroids[i], rotations[i], positions[i]))
    c = m.contacts()
    sub = m.subcontacts()
    sub_contact, sub_point, sub_status = np.asarray(sub["contact"]), np.asarray(sub["point"]), list(sub["status"])
    for k, (a, b) in enumerate(c["blocks"]):
        u, v = conversion.node[int(a)], conversion.node[int(b)]
        edge, added = _edge(model.graph, u, v)
        if added:
            results.metadata.setdefault("added_edges", []).append(list(edge))
        # voussoir's normal and force are from a to b and on b.
        flip = edge[0] != u
        normal = -c["normal"][k] if flip else c["normal"][k]
        on_first = c["force"][k] if flip else -c["force"][k]
        point = c["application_point"][k]
        # Each corner's status: that of the sub-contact nearest to it ("elastic", "sliding",
        # "open"): at a hinge the corners on the opening side are open.
        mine = np.flatnonzero(sub_contact == k)
        status = [
            sub_status[mine[int(np.argmin(np.linalg.norm(sub_point[mine] - q, axis=1)))]] if len(mine) else "open"
            for q in np.asarray(c["polygon"][k]).reshape(-1, 3)
        ]
        _set_contact(results, edge, c["polygon"][k], normal, on_first, float(c["normal_force"][k]), point, status=status)
    results.metadata["force_on"] = "edge[1]"
    results.metadata.update(metadata or {})
    return results


def from_limit(problem, model, conversion, limit, metadata=None):
    """The ``Results`` of a ``voussoir.limit`` analysis: the contact forces at collapse (at the
    polygon corners, as the solver found them) and the mechanism as a small rigid motion of each
    block (``transformation``: the mechanism's velocities scaled to a displacement of
    ``mechanism_scale`` m at the fastest block)."""
    results = Results(model_id=str(model.guid), problem_id=str(problem.guid))
    v = np.asarray(limit["blocks"]["velocity"])
    w = np.asarray(limit["blocks"]["angular_velocity"])
    scale = (metadata or {}).get("mechanism_scale", 0.01)
    peak = max(float(np.max(np.linalg.norm(v, axis=1))) if len(v) else 0.0, 1e-300)
    for i, n in conversion.node.items():
        c0 = conversion.centroids[i]
        theta = w[i] * scale / peak
        R = cg.Rotation.from_axis_and_angle(list(theta / (np.linalg.norm(theta) or 1.0)), float(np.linalg.norm(theta))).matrix
        R = np.asarray(R)[:3, :3]
        results.set_node(n, "transformation", _transformation(np.eye(3), c0, R, c0 + v[i] * scale / peak))
    for contact in limit["contacts"]:
        a, b = contact["blocks"]
        u, v_ = conversion.node[int(a)], conversion.node[int(b)]
        edge, added = _edge(model.graph, u, v_)
        if added:
            results.metadata.setdefault("added_edges", []).append(list(edge))
        flip = edge[0] != u
        normal = -np.asarray(contact["normal"]) if flip else np.asarray(contact["normal"])
        resultant = np.asarray(contact["resultant"])  # on b
        on_first = resultant if flip else -resultant
        t1, t2, _ = _frame(normal)
        shear = np.asarray(contact["shear_force"])  # on b, per corner
        sign = 1.0  # local components are of the force on edge[1]
        if flip:
            sign = -1.0  # the force on edge[1] = a is minus the force on b
        ft = [(sign * float(s @ t1), sign * float(s @ t2)) for s in shear]
        # Each corner's status in the mechanism: sliding (which, with associative friction,
        # also opens it by tan φ of the slip), opening, or closed (rates beyond 1e-6 of the
        # largest of the whole mechanism).
        rate = max(
            (float(np.max(np.hypot(c["opening"], c["sliding"]))) for c in limit["contacts"] if len(c["opening"])),
            default=0.0,
        )
        status = [
            "sliding" if abs(sl) > 1e-6 * rate else "open" if o > 1e-6 * rate else "closed"
            for o, sl in zip(contact["opening"], contact["sliding"])
        ]
        _set_contact(
            results,
            edge,
            contact["points"],
            normal,
            on_first,
            float(np.sum(contact["normal_force"])),
            contact["application_point"],
            fn_corners=list(contact["normal_force"]),
            ft_corners=ft,
            status=status,
        )
    results.metadata["force_on"] = "edge[1]"
    results.metadata.update(metadata or {})
    return results
