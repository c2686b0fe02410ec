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

Per support block (graph node of an ``is_support`` element), node attribute ``"reaction"``
(read with :func:`reactions`): ``{"force", "moment", "point"}``, the force (N) and moment (N·m,
about ``point``, the support's centroid) **on the support from the blocks in contact with it**,
global frame (a support under an arch of weight W: ``force[2] = −W`` summed over the
supports; the reaction on the structure is its negative). ``metadata["reaction_on"]`` says so.

Limit analysis, per hinged joint, edge attribute ``"hinge"`` and ``metadata["hinges"]`` (see
:func:`hinges`): the corners about which the joint turns (``pivot``), the relative rotation
(``axis``), the opening, and ``side`` (``"intrados"``/``"extrados"``, where the pivot is)
when the structure has a centre that the hinged joints face.
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


def _support_nodes(model, conversion):
    return [e.graphnode for e in model.elements() if e.is_support and e.graphnode in conversion.index]


def _set_reaction(results, node, force, moment, point):
    results.set_node(
        node,
        "reaction",
        {"force": [float(x) for x in force], "moment": [float(x) for x in moment], "point": [float(x) for x in point]},
    )


REACTION_ON = (
    "support: force (N) and moment (N·m, about 'point', the support's centroid) on the support block "
    "from the blocks in contact with it, global frame; the reaction on the structure is its negative"
)


def reactions(results, about=None):
    """The support reactions of ``results`` (from :func:`compas_voussoir.solve`):
    ``{graph node: {"force", "moment", "point"}}`` (numpy arrays), the force (N) and moment
    (N·m) **on the support block from the blocks in contact with it**, global frame, the moment
    about ``point`` (the support's centroid) or, with ``about=(x, y, z)``, about that point
    (``point`` is then ``about``: moments about one point add up). Under gravity alone, the
    supports' forces add up to the structure's weight, pointing down (−z); the force the
    supports exert on the structure is the negative. ``{}`` for results without reactions."""
    out = {}
    for node in results.nodes():
        r = results.node_attribute(node, "reaction")
        if r is None:
            continue
        f, m, p = (np.asarray(r[k], dtype=float) for k in ("force", "moment", "point"))
        if about is not None:
            q = np.asarray(about, dtype=float)
            m = m + np.cross(p - q, f)
            p = q.copy()
        out[node] = {"force": f, "moment": m, "point": p}
    return out


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
    # The supports' reactions: the contacts' force and moment on each (about its centroid).
    for n in _support_nodes(model, conversion):
        i = conversion.index[n]
        w = m.contact_wrench(i)
        _set_reaction(results, n, w["force"], w["moment"], positions[i])
    results.metadata["force_on"] = "edge[1]"
    results.metadata["reaction_on"] = REACTION_ON
    results.metadata.update(metadata or {})
    return results


def _identity_results(problem, model, conversion):
    results = Results(model_id=str(model.guid), problem_id=str(problem.guid))
    for i, n in conversion.node.items():
        c0 = conversion.centroids[i]
        results.set_node(n, "transformation", _transformation(np.eye(3), c0, np.eye(3), c0))
    return results


def without_forces(problem, model, conversion, metadata=None):
    """``Results`` of a limit analysis that found no state of collapse (the dead load not
    carried, or only the dead load checked): the blocks where they stand, no contact forces,
    ``metadata`` saying why."""
    results = _identity_results(problem, model, conversion)
    results.metadata.update(metadata or {})
    return results


def _plane_fit(planes):
    """The point nearest (least squares) to the planes ``[(point, normal), ...]``, its distance
    to each, and the number of directions the normals span; ``None`` when that says nothing:
    fewer than two directions, or no more planes than directions (two planes always meet in a
    line, three of independent normals in a point)."""
    if not planes:
        return None
    q = np.asarray([p for p, _ in planes], dtype=float)
    n = np.asarray([d for _, d in planes], dtype=float)
    A = n.T @ n
    rhs = n.T @ np.einsum("ij,ij->i", n, q)
    s = np.linalg.svd(A, compute_uv=False)
    rank = int(np.sum(s > 1e-6 * s[0]))
    if rank < 2 or len(planes) <= rank:
        return None
    x, *_ = np.linalg.lstsq(A, rhs, rcond=1e-6)
    return x, np.abs(np.einsum("ij,ij->i", n, x - q)), rank


def _centre(planes, hinged, tolerance):
    """The point that the joints' planes meet at (an arch's or a dome's centre: its radial
    joints all pass through it), within ``tolerance`` (m): the planes that miss it (a loading
    plate's, a wall's head joints) are dropped one by one, the worst first, up to half of
    them; every hinged joint's plane must pass through it. ``None`` when there is none."""
    planes = list(planes)
    keep = len(planes) - len(planes) // 2
    while len(planes) >= keep:
        fit = _plane_fit(planes)
        if fit is None:
            return None
        x, distance, _ = fit
        worst = int(np.argmax(distance))
        if distance[worst] <= tolerance:
            break
        del planes[worst]
    else:
        return None
    for q, n in hinged:
        if abs(float(np.asarray(n) @ (x - np.asarray(q)))) > tolerance:
            return None
    return x


def hinges(limit, conversion, model, *, tolerance=1e-3, centre=None):
    """The hinged joints of a ``voussoir.limit`` mechanism: the contacts whose blocks turn
    about one another (the opening rate varies over the contact polygon's corners by more than
    ``tolerance`` of the mechanism's largest corner rate). One dict per hinge, JSON-ready:

    - ``edge``: the graph edge ``[u, v]`` (oriented as in the model's graph);
    - ``pivot``: the corners about which the joint turns (the closed ones: two for an edge of
      the polygon, one for a corner), ``pivot_point`` their mean;
    - ``axis``: unit vector of the relative rotation of ``edge[1]``'s block with respect to
      ``edge[0]``'s (the right-hand rule), in the joint's plane; ``rotation``: its rate
      (rad per unit of the mechanism's velocities);
    - ``opening``: the largest opening rate at the corners (> 0: the joint opens on the side
      away from the pivot), ``opens``: those corners; ``towards``: unit vector in the joint's
      plane from the polygon's centre towards the pivot;
    - ``side``: ``"intrados"`` when the pivot is the end of the joint nearer ``centre`` (an
      arch's or vault's centre of curvature), ``"extrados"`` when it is the farther;
      ``opens_on``: the other. Without ``centre``, the point where the joints' planes meet
      (least squares; the radial joints of an arch or a dome all pass through its centre)
      within 5 % of the joints' median size (centre to corner), the planes that miss it (a
      loading plate's) dropped, up to half of them, and the hinged joints' passing through
      it; ``side`` is ``None`` when there is no such point (e.g. a block rocking on its base:
      ``pivot`` and ``towards`` say which edge; or give ``centre``).
    """
    w = np.asarray(limit["blocks"]["angular_velocity"], dtype=float)
    rate = max(
        (float(np.max(np.hypot(c["opening"], c["sliding"]))) for c in limit["contacts"] if len(c["opening"])),
        default=0.0,
    )
    if rate <= 0.0:
        return []
    found = []
    for contact in limit["contacts"]:
        pts = np.asarray(contact["points"], dtype=float).reshape(-1, 3)
        o = np.asarray(contact["opening"], dtype=float)
        if len(pts) < 2:
            continue
        spread = float(np.max(o) - np.min(o))
        if spread <= tolerance * rate:
            continue
        a, b = (int(x) for x in contact["blocks"])
        u, v_ = conversion.node[a], conversion.node[b]
        edge, _ = _edge(model.graph, u, v_)
        flip = edge[0] != u
        normal = np.asarray(contact["normal"], dtype=float)
        omega = w[b] - w[a]
        if flip:
            normal, omega = -normal, -omega
        in_plane = omega - (omega @ normal) * normal
        closed = o - np.min(o) <= max(1e-2 * spread, tolerance * rate)
        pivot = pts[closed]
        centroid = pts.mean(axis=0)
        towards = pivot.mean(axis=0) - centroid
        towards -= (towards @ normal) * normal
        found.append(
            {
                "edge": [int(edge[0]), int(edge[1])],
                "pivot": pivot.tolist(),
                "pivot_point": pivot.mean(axis=0).tolist(),
                "axis": (in_plane / (np.linalg.norm(in_plane) or 1.0)).tolist(),
                "rotation": float(np.linalg.norm(in_plane)),
                "opening": float(np.max(o)),
                "opens": pts[o >= np.max(o) - 1e-2 * spread].tolist(),
                "towards": (towards / (np.linalg.norm(towards) or 1.0)).tolist(),
                "side": None,
                "opens_on": None,
                "_plane": (centroid, normal),
            }
        )
    if found:
        if centre is not None:
            c = np.asarray(centre, dtype=float)
        else:
            planes, sizes = [], []
            for contact in limit["contacts"]:
                pts = np.asarray(contact["points"], dtype=float).reshape(-1, 3)
                if len(pts) >= 2:
                    planes.append((pts.mean(axis=0), np.asarray(contact["normal"], dtype=float)))
                    sizes.append(float(np.max(np.linalg.norm(pts - pts.mean(axis=0), axis=1))))
            c = _centre(planes, [h["_plane"] for h in found], 0.05 * float(np.median(sizes)))
        for h in found:
            if c is not None:
                near = np.linalg.norm(np.asarray(h["pivot_point"]) - c)
                far = np.linalg.norm(np.mean(h["opens"], axis=0) - c)
                if abs(near - far) > 1e-9 * max(near, far):
                    h["side"] = "intrados" if near < far else "extrados"
                    h["opens_on"] = "extrados" if near < far else "intrados"
            del h["_plane"]
    return found


def from_limit(problem, model, conversion, limit, metadata=None, *, centre=None):
    """The ``Results`` of a ``voussoir.limit`` analysis: the contact forces at collapse (at the
    polygon corners, as the solver found them), the supports' reactions (exact: the solver's
    corner forces), the hinges (:func:`hinges`, ``centre`` as it takes it) and the mechanism as
    a small rigid motion of each block (``transformation``: the mechanism's velocities scaled
    to a displacement of ``mechanism_scale`` m at the fastest block)."""
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
    supports = {conversion.index[n]: n for n in _support_nodes(model, conversion)}
    wrench = {i: [np.zeros(3), np.zeros(3)] for i in supports}
    # Each corner's status in the mechanism: sliding (which, with associative friction, also
    # opens it by tan φ of the slip), opening, or closed (rates beyond 1e-6 of the largest of
    # the whole mechanism).
    rate = max(
        (float(np.max(np.hypot(c["opening"], c["sliding"]))) for c in limit["contacts"] if len(c["opening"])),
        default=0.0,
    )
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
        # The corner forces on b (normal from a to b, compression positive; shear on b), and
        # their negatives on a: the supports' reactions.
        pts = np.asarray(contact["points"], dtype=float).reshape(-1, 3)
        on_b = np.asarray(contact["normal_force"], dtype=float)[:, None] * np.asarray(contact["normal"], dtype=float) + shear
        for block, sgn in ((int(b), 1.0), (int(a), -1.0)):
            if block in wrench:
                c = conversion.centroids[block]
                wrench[block][0] += sgn * on_b.sum(axis=0)
                wrench[block][1] += sgn * np.cross(pts - c, on_b).sum(axis=0)
    for i, n in supports.items():
        _set_reaction(results, n, wrench[i][0], wrench[i][1], conversion.centroids[i])
    found = hinges(limit, conversion, model, centre=centre)
    for h in found:
        results.set_edge(tuple(h["edge"]), "hinge", h)
    results.metadata["hinges"] = found
    results.metadata["force_on"] = "edge[1]"
    results.metadata["reaction_on"] = REACTION_ON
    results.metadata.update(metadata or {})
    return results
