"""compas_voussoir against the voussoir library's own reference arch, closed forms and the
Results conventions of compas_dem."""

import math

import numpy as np
import pytest

compas_dem = pytest.importorskip("compas_dem")

from compas.datastructures import Mesh  # noqa: E402
from compas_dem.models import BlockModel  # noqa: E402
from compas_dem.problem import Problem  # noqa: E402
from compas_dem.templates import ArchTemplate  # noqa: E402

import compas_voussoir as cv  # noqa: E402
import voussoir as vs  # noqa: E402

DENSITY = 2446.4831804281343  # 24 kN/m³, the reference arch's
STEEL = 7850.0
WIDTH = 0.15


def to_compas(points):
    """voussoir's arch frame (x span, y up, z across) to compas_dem's (x span, y across, z up)."""
    p = np.asarray(points, dtype=float)
    return p[:, [0, 2, 1]]


def mesh_of(block):
    # The swap of y and z is a reflection: the face loops turn the other way.
    return Mesh.from_vertices_and_faces(to_compas(block.vertices).tolist(), [f[::-1] for f in block.faces])


def reference_arch():
    """The reference arch of ``cargo run --example arch_static`` as a compas_dem model: the 13
    voussoirs of compas_dem's ``ArchTemplate``, the two abutments of ``voussoir.build.arch``
    (supports) and the steel loading plate on voussoir 5's extrados. Returns the model, the
    plate's graph node and the stones' graph nodes."""
    model = BlockModel.from_template(ArchTemplate(rise=0.4, span=1.2, thickness=0.2, depth=WIDTH, n=13))
    blocks = vs.build.arch(width=WIDTH)
    # ArchTemplate's voussoirs are build.arch's, vertex for vertex (numbered from the right).
    for element, block in zip(model.elements(), reversed(blocks[1:-1])):
        mine = np.asarray(element.modelgeometry.to_vertices_and_faces()[0])
        theirs = to_compas(block.vertices)
        assert max(np.min(np.linalg.norm(theirs - p, axis=1)) for p in mine) < 1e-12
    for abutment in (blocks[0], blocks[-1]):
        model.add_support_from_mesh(mesh_of(abutment))
    # The plate: 0.10 × 0.02 m, seated on the middle of voussoir 5's extrados, turned with it.
    joints = vs.build.arch_joints(width=WIDTH)
    e4, e5 = np.asarray(joints[4]["extrados"]), np.asarray(joints[5]["extrados"])
    mid, chord = 0.5 * (e4 + e5), e5 - e4
    n = np.array([-chord[1], chord[0], 0.0]) / np.hypot(chord[0], chord[1])
    t = chord / np.linalg.norm(chord)
    corners = []
    for a in (-0.05, 0.05):
        for b in (0.0, 0.02):
            for z in (0.0, WIDTH):
                p = mid + a * t + b * n
                corners.append([p[0], p[1], z])
    plate = vs.Block.from_vertices("plate", corners, STEEL)
    plate_node = model.add_block_from_mesh(mesh_of(plate))
    return model, plate_node


def reference_problem(phi=30.5):
    model, plate = reference_arch()
    problem = Problem(model)
    problem.set_contact_model("MohrCoulomb", phi=phi)
    problem.set_joint_model(kn=4e9, kt=1.6e9)
    live = problem.add_boundary_condition("Live")
    centroid = np.mean(np.asarray(model.graph.node_element(plate).modelgeometry.to_vertices_and_faces()[0]), axis=0)
    problem.add_point_load_at_point(plate, list(centroid), [0.0, 0.0, -1.0], boundary_condition=live)
    return model, plate, problem


def block_on_support():
    """A 0.2 m block (graph node 1) on a 2 × 1 m support (node 0)."""
    from compas.geometry import Box

    boxes = [
        Box.from_corner_corner_height([-1, -0.5, -0.2], [1, 0.5, -0.2], 0.2),
        Box.from_corner_corner_height([-0.1, -0.1, 0.0], [0.1, 0.1, 0.0], 0.2),
    ]
    model = BlockModel.from_boxes(boxes)
    model.add_support(0)
    return model


# The plate moves in the arch's plane only (as in arch_static's limit analysis).
PLATE_IN_PLANE = {"translation": ["free", "fixed", "free"], "rotation": ["fixed", "free", "fixed"]}


def test_limit_load_of_the_reference_arch():
    """Through compas_dem, the limit load (multiplier + the plate's weight) is arch_static's
    2.755 kN at φ 30.5° (the library and LMGC90 agree on it to four digits)."""
    model, plate, problem = reference_problem()
    r = cv.solve(problem, analysis="limit", live="Live", density=DENSITY, densities={plate: STEEL}, fixity={plate: PLATE_IN_PLANE})
    weight = STEEL * 0.1 * 0.02 * WIDTH * 9.81
    load = r.metadata["multiplier"] + weight
    assert load == pytest.approx(2755.0, rel=0.005), load
    assert r.metadata["carries_dead_load"] is True
    # The same through compas_dem's own API: the solver set on the problem, problem.solve().
    problem.set_solver(cv.Voussoir(analysis="limit", live="Live", density=DENSITY, densities={plate: STEEL}, fixity={plate: PLATE_IN_PLANE}))
    assert problem.solve().metadata["multiplier"] == r.metadata["multiplier"]
    assert cv.solve(problem).metadata["multiplier"] == r.metadata["multiplier"]
    # Every contact at collapse: a polygon whose corner forces add up to the resultant.
    for edge in r.edges():
        fn = np.asarray(r.force_normal(edge))
        assert fn.sum() == pytest.approx(r.resultant_local(edge)[2], rel=1e-9, abs=1e-9)
        assert r.face_contact(edge) or r.edge_contact(edge) or r.point_contact(edge)
        assert len(r.status(edge)) == len(r.contact_point(edge))
    # The mechanism slides at three joints (arch_static: "sliding 4 5 13"): some corners slide.
    assert any(s == "sliding" for e in r.edges() for s in r.status(e))


def test_dem_capacity_of_the_reference_arch():
    """A push-over of the plate through compas_dem: the capacity is arch_static's baseline,
    2.798 kN, within 3 %."""
    model, plate, problem = reference_problem()
    push = {"block": plate, "direction": (0.0, 0.0, -1.0), "increment": 2e-5, "max_travel": 0.004,
            "fixity": {"translation": ["free", "fixed", 0.0], "rotation": ["fixed", "free", "fixed"]}}
    r = cv.solve(problem, analysis="capacity", capacity=push, density=DENSITY, densities={plate: STEEL})
    assert r.metadata["peak_load"] == pytest.approx(2798.0, rel=0.03), r.metadata["peak_load"]


def test_static_results_follow_compas_dem_conventions():
    """Settled under its weight: the abutments carry the arch's weight, each contact's
    force_point reproduces the contact's moment, transformations are rigid motions."""
    model, plate, problem = reference_problem()
    r = cv.solve(problem, analysis="static", density=DENSITY, densities={plate: STEEL})
    assert r.metadata["unbalanced_ratio"] < 1e-5
    conv = cv.to_voussoir(problem, density=DENSITY, densities={plate: STEEL})
    weight = sum(conv.model.block(i).mass for i in range(len(conv.model)) if not conv.model.block(i).is_fixed) * 9.81
    supports = {e.graphnode for e in model.elements() if e.is_support}
    vertical = 0.0
    for edge in r.edges():
        u, v = edge
        if (u in supports) != (v in supports):
            F = np.asarray(r.resultant_global(edge))  # on edge[1], the block the frame's z points into
            vertical += F[2] if v in supports else -F[2]  # the force on the support, downward negative
            assert F @ np.asarray(r.contact_frame(edge).zaxis) > 0  # compression
        # Moment about the frame's origin: the corner normal forces give the resultant's.
        frame = r.contact_frame(edge)
        pts = np.asarray(r.contact_point(edge))
        fn = np.asarray(r.force_normal(edge))
        n = np.asarray(frame.zaxis)
        if r.face_contact(edge) and fn.sum() > 0:
            p = np.asarray(r.force_point(edge))
            moment_corners = np.cross(pts - p, np.outer(fn, n)).sum(axis=0)
            assert np.linalg.norm(moment_corners) < 1e-6 * fn.sum(), moment_corners
    assert -vertical == pytest.approx(weight, rel=1e-3)
    assert r.metadata["force_on"] == "edge[1]"
    statuses = {s for e in r.edges() for s in r.status(e)}
    assert statuses <= {"elastic", "sliding", "open"} and "elastic" in statuses
    T = np.asarray(r.transformation(plate).matrix)
    assert np.allclose(T[:3, :3] @ T[:3, :3].T, np.eye(3), atol=1e-12)


def test_a_shaken_wall_round_trips_its_results():
    """A two-block wall on a support shaken at 0.3 g for 0.2 s: Results with every block and
    contact, which survive compas's JSON round trip."""
    import compas
    from compas.geometry import Box

    boxes = [Box.from_corner_corner_height([-1, -0.5, -0.2], [1, 0.5, -0.2], 0.2)]
    boxes += [Box.from_corner_corner_height([-0.4 + 0.4 * k, -0.1, 0.0], [0.0 + 0.4 * k, 0.1, 0.0], 0.3) for k in range(2)]
    model = BlockModel.from_boxes(boxes)
    model.add_support(0)
    problem = Problem(model)
    problem.set_contact_model("MohrCoulomb", phi=35.0)
    problem.add_boundary_condition("Gravity")
    record = vs.TimeHistory.sine(0.3 * 9.81, 5.0, 0.2, 400)
    r = cv.solve(problem, analysis="shaking", ground_motion={"x": record}, density=2000.0)
    assert r.metadata["shaking_duration"] == pytest.approx(0.2, abs=1e-3)
    assert set(r.nodes()) == {0, 1, 2}
    back = compas.json_loads(compas.json_dumps(r))
    for node in r.nodes():
        assert np.allclose(back.transformation(node).matrix, r.transformation(node).matrix)
    for edge in r.edges():
        assert back.resultant_global(edge) == r.resultant_global(edge)
    # The support moved with the ground: x(0.2 s) of a sine acceleration from rest.
    w = 2 * math.pi * 5.0
    exact = 0.3 * 9.81 / w**2 * (w * 0.2 - math.sin(w * 0.2))
    assert r.displacement(0)[0] == pytest.approx(exact, rel=1e-3)


def test_corner_forces_put_the_resultant_at_its_point():
    corners = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
    f = cv.corner_normal_forces(corners, 10.0, [0.8, 0.3, 0.0])
    assert f.sum() == pytest.approx(10.0)
    assert (f[:, None] * np.asarray(corners)).sum(axis=0) / 10.0 == pytest.approx([0.8, 0.3, 0.0])


def test_bad_problems_are_refused_with_what_is_missing():
    model = BlockModel.from_template(ArchTemplate(rise=0.4, span=1.2, thickness=0.2, depth=0.15, n=5))
    problem = Problem(model)
    with pytest.raises(ValueError, match="contact model"):
        cv.solve(problem, density=2000.0)
    problem.set_contact_model("MohrCoulomb", phi=30.0)
    with pytest.raises(ValueError, match="density"):
        cv.solve(problem)
    with pytest.raises(ValueError, match="analysis"):
        cv.solve(problem, analysis="quasi", density=2000.0)
    with pytest.raises(ValueError, match="live"):
        cv.solve(problem, analysis="limit", density=2000.0)
    single = block_on_support()
    lonely = Problem(single)
    lonely.set_contact_model("MohrCoulomb", phi=30.0)
    with pytest.raises(ValueError, match="loading device"):
        cv.solve(lonely, analysis="capacity", capacity={"block": 1, "direction": (1, 0, 0)}, density=2000.0)
    # Probe 3, F13: run arguments named (duration=-1 and NaN were accepted), an unknown block
    # named (it was a bare KeyError: 99).
    for bad in (-1.0, math.nan, 0.0):
        with pytest.raises(ValueError, match="duration"):
            cv.solve(problem, analysis="dynamic", duration=bad, density=2000.0)
    with pytest.raises(ValueError, match="max_steps"):
        cv.solve(problem, max_steps=0, density=2000.0)
    with pytest.raises(ValueError, match="block 99 is not a node"):
        cv.solve(lonely, analysis="capacity", capacity={"block": 99, "direction": (1, 0, 0)}, density=2000.0)
    # Every argument checked before the run, named in the error.
    problem.add_boundary_condition("Live")
    model.add_supports([0, 4])
    bad_values = {
        "ramp_time": 0.0,  # (a zero ramp was a time history error: "time of sample 1 = 0")
        "ratio": math.nan,
        "max_steps": 1.5,
        "history_every": 0,
        "subcontacts_per_edge": 0,
        "contact_tolerance": -1.0,
        "densities": {7: 2000.0},
        "kn": "4e9",
        "ks": 0.0,
        "progress": "yes",
        "interfaces": {(0, 1): {"mu": 0.3}},
    }
    for name, value in bad_values.items():
        with pytest.raises(ValueError, match=name):
            cv.solve(problem, density=2000.0, **{name: value})
    with pytest.raises(ValueError, match="density"):
        cv.solve(problem, density=-5.0)
    limit_values = {"facets": 2, "check_dead_load": "no", "fixity": {9: "fixed"}, "centre": (0, 0), "max_iterations": 0, "mechanism_scale": 0.0}
    for name, value in limit_values.items():
        with pytest.raises(ValueError, match=name):
            cv.solve(problem, analysis="limit", live="Live", density=2000.0, **{name: value})
    with pytest.raises(ValueError, match="live: no boundary condition named"):
        cv.solve(problem, analysis="limit", live="Nope", density=2000.0)
    with pytest.raises(ValueError, match=r"capacity: direction"):
        cv.solve(problem, analysis="capacity", capacity={"block": 2, "direction": (0, 0, 0)}, density=2000.0)
    with pytest.raises(ValueError, match=r"capacity: unknown keys \['incremnt'\]"):
        cv.solve(problem, analysis="capacity", capacity={"block": 2, "incremnt": 1e-5}, density=2000.0)
    with pytest.raises(ValueError, match="ground_motion"):
        cv.solve(problem, analysis="shaking", ground_motion={"x": (1, 2)}, density=2000.0)
    with pytest.raises(ValueError, match="damping"):
        cv.solve(problem, analysis="dynamic", damping={"ratio": 0.05}, density=2000.0)
    # An unknown keyword is named (check_dead_load was "Model.__new__() got an unexpected
    # keyword argument" before it was plumbed to voussoir.limit).
    with pytest.raises(TypeError, match="'duration_s'"):
        cv.solve(problem, duration_s=1.0, density=2000.0)


def test_self_weight_reactions_against_compas_cra():
    """compas_dem's own ArchTemplate arch on its end voussoirs (supports), ρ 2000 kg/m³, μ 0.6:
    the springing reactions of the settled DEM against compas_cra's coupled rigid-block
    equilibrium (its own IPOPT, called directly: compas_dem's Solver.CRA needs pyomo). The
    vertical reactions are statically determinate (symmetry) and agree to 1e-5; the horizontal
    thrust is not: voussoir's elastic joints give 299.3 N whatever their stiffness (the same
    within 0.1 % at kn 4 and 400 GPa/m), compas_cra's equilibrium 337.5 N, its RBE 219.1 N —
    three admissible states of a statically indeterminate arch (docs/compas.md)."""
    pytest.importorskip("compas_cra")
    import contextlib
    import io

    from compas_assembly.datastructures import Assembly
    from compas_assembly.datastructures import Block as AsmBlock
    from compas_cra.equilibrium import cra_solve
    from compas_dem.interactions.contact import local_resultant

    rho, g = 2000.0, 9.81
    model = BlockModel.from_template(ArchTemplate(rise=0.4, span=1.2, thickness=0.2, depth=0.15, n=13))
    model.add_supports([0, 12])
    model.compute_contacts()
    assembly, node_of = Assembly(), {}
    for el in model.elements():
        x, y, z = el.point
        node_of[el.graphnode] = assembly.add_block(el.modelgeometry.copy(cls=AsmBlock), x=x, y=y, z=z, is_support=el.is_support)
    for u, v in model.graph.edges():
        assembly.graph.add_edge(node_of[u], node_of[v], interfaces=model.graph.edge_attribute((u, v), "contacts"))
    with contextlib.redirect_stdout(io.StringIO()):
        cra_solve(assembly, mu=0.6, density=1.0, d_bnd=1e-3, eps=1e-4, verbose=False)
    cra = {}
    for u, v in model.graph.edges():
        for c in assembly.graph.edge_attribute((node_of[u], node_of[v]), "interfaces"):
            fu, fv, fn = local_resultant([{k: val * rho * g for k, val in f.items()} for f in c.forces])
            f = c.frame
            cra[(u, v)] = cra.get((u, v), 0) + np.array([fu * f.xaxis[k] + fv * f.yaxis[k] + fn * f.zaxis[k] for k in range(3)])
    cra_reaction = -cra[(11, 12)]  # on the arch from support 12 (the force on edge[1] = 12, reversed)

    thrusts = []
    for kn in (4e9, 4e11):
        problem = Problem(model)
        problem.set_contact_model("MohrCoulomb", mu=0.6)
        problem.set_joint_model(kn=kn, kt=0.4 * kn)
        r = cv.solve(problem, analysis="static", density=rho)
        reaction = -np.asarray(r.resultant_global((11, 12)))
        assert reaction[2] == pytest.approx(cra_reaction[2], rel=1e-5)
        thrusts.append(reaction[0])
    assert thrusts[1] == pytest.approx(thrusts[0], rel=1e-3)
    assert abs(thrusts[0]) == pytest.approx(299.3, rel=2e-3)
    assert abs(cra_reaction[0]) == pytest.approx(337.5, rel=2e-3)


def test_a_dynamic_run_slides_a_pushed_block_as_coulomb_says():
    """A 0.2 m block on a support (μ 0.2), pushed by an instantaneous 0.5 W from rest, undamped:
    it slides x = ½ (0.5 − μ) g t² (0.2 % measured: the shear springs' pre-slip and the
    weight's first bounce)."""
    model = block_on_support()
    problem = Problem(model)
    problem.set_contact_model("MohrCoulomb", mu=0.2)
    push = problem.add_boundary_condition("Push")
    weight = 2000.0 * 0.008 * 9.81
    problem.add_point_load_at_centroid(1, [0.5 * weight, 0, 0], loading_type="instantaneous", boundary_condition=push)
    r = cv.solve(problem, analysis="dynamic", duration=0.2, damping={"kind": "none"}, density=2000.0)
    t = r.metadata["time"]
    assert t == pytest.approx(0.2, abs=1e-3)
    assert r.displacement(1)[0] == pytest.approx(0.5 * (0.5 - 0.2) * 9.81 * t**2, rel=0.01)
    assert len(r.metadata["history"]["time"]) >= 100


def test_a_prescribed_translation_is_reached():
    """compas_dem's prescribed displacement of a block (2 mm along x), reached at a constant rate
    over ramp_time and then held: the block ends 2 mm along (measured −0.12 %, one step at the
    prescribed velocity; asserted 1 %), its other axes free (it stays on its support)."""
    model = block_on_support()
    problem = Problem(model)
    problem.set_contact_model("MohrCoulomb", phi=30.0)
    move = problem.add_boundary_condition("Move")
    problem.add_displacement(1, [0.002, None, None], boundary_condition=move)
    r = cv.solve(problem, analysis="static", density=2000.0)
    dx, dy, dz = r.displacement(1)
    assert dx == pytest.approx(0.002, rel=0.01)
    assert abs(dy) < 1e-9 and abs(dz) < 1e-5


def semicircular_arch(thickness=0.2, n=16, mu=1.0, load_on=None, load=1.0):
    """compas_dem's ArchTemplate as a semicircle (intrados radius 1 m about the origin, span 2 m,
    0.2 m deep) of ``n`` voussoirs, the end ones supports; μ 1 (hinges, not sliding); a
    downward live load of ``load`` N at voussoir ``load_on``'s centroid."""
    model = BlockModel.from_template(ArchTemplate(rise=1.0, span=2.0, thickness=thickness, depth=0.2, n=n))
    model.add_supports([0, n - 1])
    problem = Problem(model)
    problem.set_contact_model("MohrCoulomb", mu=mu)
    live = problem.add_boundary_condition("Live")
    if load_on is not None:
        problem.add_point_load_at_centroid(load_on, [0.0, 0.0, -load], boundary_condition=live)
    return model, problem


def sliding_block_problem(mu=0.2, push=0.5, loading_type="ramp"):
    """block_on_support (ρ 2000 kg/m³, μ ``mu``) pushed sideways by ``push`` times its weight."""
    model = block_on_support()
    problem = Problem(model)
    problem.set_contact_model("MohrCoulomb", mu=mu)
    bc = problem.add_boundary_condition("Push")
    weight = 2000.0 * 0.008 * 9.81
    problem.add_point_load_at_centroid(1, [push * weight, 0, 0], loading_type=loading_type, boundary_condition=bc)
    return model, problem


def test_problem_solve_runs_voussoir():
    """Issue: problem.set_solver(compas_voussoir.Voussoir(...)); problem.solve() said "Solver
    'voussoir' is not recognised" (compas_dem 0.6 dispatches on a fixed list of names).
    Importing compas_voussoir wraps Problem.solve (compas_voussoir.install): a Voussoir solver
    runs voussoir, with problem.solve()'s runtime options over the solver's parameters; any
    other solver reaches compas_dem's own code; the problem with its solver survives compas's
    JSON round trip; uninstall() puts compas_dem's Problem.solve back."""
    import compas
    from compas_dem.problem import Solver

    model, problem = sliding_block_problem(mu=0.6, push=0.1)
    problem.set_solver(cv.Voussoir(analysis="limit", live="Push", density=2000.0))
    assert cv.installed()
    r = problem.solve()
    weight = 2000.0 * 0.008 * 9.81
    # The block slides at μ W: the multiplier of the 0.1 W push is 6 (measured 6 to 1e-8).
    assert r.metadata["multiplier"] == pytest.approx(6.0, rel=1e-6)
    assert r.metadata["multiplier"] * 0.1 * weight == pytest.approx(0.6 * weight, rel=1e-6)
    assert cv.solve(problem).metadata["multiplier"] == r.metadata["multiplier"]
    # Runtime options win over the solver's parameters, as in compas_dem.
    assert problem.solve(check_dead_load=False).metadata["carries_dead_load"] is None
    # JSON round trip: a plain compas_dem Solver named "voussoir".
    back = compas.json_loads(compas.json_dumps(problem))
    back.load_model(model)
    assert back._solver.name == "voussoir"
    assert back.solve().metadata["multiplier"] == pytest.approx(6.0, rel=1e-6)
    # Other solvers still go to compas_dem (its own error for a model without materials).
    problem.set_solver(Solver.RBE())
    with pytest.raises(Exception) as other:
        problem.solve()
    assert "not recognised" not in str(other.value)
    problem.set_solver(cv.Voussoir(analysis="limit", live="Push", density=2000.0))
    try:
        assert cv.uninstall() is True
        assert not cv.installed()
        with pytest.raises(ValueError, match="not recognised"):
            problem.solve()
    finally:
        cv.install()
    assert cv.install() is False  # idempotent
    assert problem.solve().metadata["multiplier"] == pytest.approx(6.0, rel=1e-6)
    # A misspelt parameter is refused when the solver is made, not at the solve.
    with pytest.raises(TypeError, match="'lve'"):
        cv.Voussoir(analysis="limit", lve="Push")


def test_stiffnesses_are_per_unit_area_and_odd_ones_warned():
    """compas_dem's set_joint_model docstring gives kn, kt in N/m; compas_voussoir reads Pa/m
    (per unit joint area, 3DEC's jkn/jks). A value outside 1e8–1e14 Pa/m (masonry joints) is
    warned about (StiffnessUnitsWarning, pointing at the caller's line), with what it would be
    in Pa/m as a whole joint's N/m over the joints' median area (the 13-voussoir arch's joints:
    0.2 × 0.15 = 0.03 m²). The units are in the Results' metadata."""
    model = BlockModel.from_template(ArchTemplate(rise=0.4, span=1.2, thickness=0.2, depth=0.15, n=13))
    model.add_supports([0, 12])
    problem = Problem(model)
    problem.set_contact_model("MohrCoulomb", phi=35.0)
    # 4 GPa/m over a 0.03 m² joint is 1.2e8 N/m: inside the Pa/m range, no way to tell. A
    # softer joint's 3e7 N/m (1e9 Pa/m) is below it.
    problem.set_joint_model(kn=3e7, kt=1.2e7)
    with pytest.warns(cv.StiffnessUnitsWarning) as caught:
        r = cv.solve(problem, analysis="limit", live=[], density=2000.0)
    texts = [str(w.message) for w in caught if issubclass(w.category, cv.StiffnessUnitsWarning)]
    assert len(texts) == 2
    kn_text = next(t for t in texts if "kn" in t)
    assert "3e+07 Pa/m is below" in kn_text and "N/m" in kn_text
    assert "median area is 0.03 m²" in kn_text and "1e+09 Pa/m" in kn_text
    assert all(w.filename == __file__ for w in caught)
    assert r.metadata["joint_law"]["units"] == "Pa/m"
    assert r.metadata["joint_law"]["units_warning"] and "Pa/m" in r.metadata["units"]["kn"]
    # Within the range: no warning (4e9 Pa/m, the reference arch's), the default neither.
    import warnings

    problem.set_joint_model(kn=4e9, kt=1.6e9)
    with warnings.catch_warnings():
        warnings.simplefilter("error", cv.StiffnessUnitsWarning)
        cv.to_voussoir(problem, density=2000.0)
        cv.to_voussoir(problem, density=2000.0, kn=1e14, ks=4e13)
    # An interface's own stiffness, named as given.
    with pytest.warns(cv.StiffnessUnitsWarning, match=r"interfaces\[\(5, 6\)\]\['kn'\] = 5e\+15"):
        cv.to_voussoir(problem, density=2000.0, interfaces={(5, 6): {"kn": 5e15}})
    # Not a stiffness at all: refused, named.
    with pytest.raises(ValueError, match="kn = -1"):
        cv.to_voussoir(problem, density=2000.0, kn=-1.0)
    problem.set_joint_model(kn=math.nan, kt=1e9)
    with pytest.raises(ValueError, match="joint model's kn"):
        cv.to_voussoir(problem, density=2000.0)


def test_limit_analysis_answers_whether_the_dead_load_is_carried():
    """A zero live load (or live=[]) asks whether the dead load alone is carried (voussoir.limit
    with no live load). Carried, the Results hold the contact forces of an admissible state:
    every voussoir in equilibrium under its weight and its contacts' forces (force and moment,
    to round-off), the supports' reactions adding up to the arch's weight. An arch that cannot
    stand is an answer, carries_dead_load False with the solver's status and a reason naming
    the blocks that fall, not an error. The semicircular arch of 16 voussoirs (intrados radius
    1 m, end voussoirs fixed, μ 1) stands down to a thickness of 0.0654 m (bisected: carried
    at 0.06540, not at 0.06539); check_dead_load=False passes through (it was a TypeError from
    voussoir.Model) and gives the same multiplier unchecked."""
    for live, load in (("Live", 0.0), ([], 1.0)):  # a zero live load; no live load (1 N dead)
        model, problem = semicircular_arch(load_on=4, load=load)
        r = cv.solve(problem, analysis="limit", live=live, density=2000.0)
        assert r.metadata["carries_dead_load"] is True and r.metadata["multiplier"] is None
        assert r.metadata["status"] == "Solved" and r.metadata["dead_load_only"] is True
        assert r.metadata["mechanism"] is None and r.metadata["hinges"] == [] and "reason" not in r.metadata
        assert set(r.nodes()) == set(range(16))
        # The blocks stay where they stand (no mechanism).
        for n in r.nodes():
            assert np.allclose(np.asarray(r.transformation(n).matrix), np.eye(4), atol=1e-12)
        # Every contact of the ring, with forces; each voussoir in equilibrium.
        edges = list(r.edges())
        assert len(edges) == 15
        conv = cv.to_voussoir(problem, density=2000.0)
        masses = {conv.node[i]: conv.model.block(i).mass for i in conv.node}
        centroids = {conv.node[i]: np.asarray(conv.centroids[i]) for i in conv.node}
        g = np.asarray(conv.model.gravity, dtype=float)
        weight = sum(masses[n] for n in range(1, 15)) * float(np.linalg.norm(g))
        force = {n: masses[n] * g for n in range(16)}
        moment = {n: np.zeros(3) for n in range(16)}
        # live=[]: the "Live" load is a dead load, at compas_dem's centroid of the element.
        at = np.asarray(list(model.graph.node_element(4).point), dtype=float)
        force[4] += [0.0, 0.0, -load]
        moment[4] += np.cross(at - centroids[4], [0.0, 0.0, -load])
        for u, v in edges:
            f = np.asarray(r.resultant_global((u, v)), dtype=float)  # on v
            p = np.asarray(list(r.force_point((u, v))), dtype=float)
            for node, sign in ((v, 1.0), (u, -1.0)):
                force[node] += sign * f
                moment[node] += sign * np.cross(p - centroids[node], f)
            assert r.resultant_local((u, v))[2] > 0.0  # compression
        for n in range(1, 15):
            assert np.linalg.norm(force[n]) < 1e-9 * weight, (n, force[n])
            assert np.linalg.norm(moment[n]) < 1e-9 * weight, (n, moment[n])
        total = sum(np.asarray(x["force"]) for x in cv.reactions(r).values())
        assert total == pytest.approx([0.0, 0.0, -weight - load], abs=1e-9 * weight)
    for thickness, stands in ((0.0655, True), (0.0653, False)):
        model, problem = semicircular_arch(thickness=thickness, load_on=4)
        r = cv.solve(problem, analysis="limit", live=[], density=2000.0)
        assert r.metadata["carries_dead_load"] is stands, thickness
        if stands:
            assert r.metadata["status"] == "Solved" and len(list(r.edges())) == 15
        else:
            assert r.metadata["status"] in ("PrimalInfeasible", "AlmostPrimalInfeasible")
            assert "move" in r.metadata["reason"] and not list(r.edges())
            # The solver's certificate: a motion on which the dead loads (the weight and the
            # 1 N at voussoir 4's centroid) do work, scaled to a power of the weight (so near
            # the limit thickness, where the work nearly vanishes, the speeds are large).
            conv = cv.to_voussoir(problem, density=2000.0)
            g = np.asarray(conv.model.gravity, dtype=float)
            mech = r.metadata["mechanism"]
            power = sum(conv.model.block(i).mass * float(g @ mech[conv.node[i]]["velocity"]) for i in conv.node)
            at = np.asarray(list(model.graph.node_element(4).point), dtype=float)
            i4 = conv.index[4]
            v4 = np.asarray(mech[4]["velocity"]) + np.cross(mech[4]["angular_velocity"], at - conv.centroids[i4])
            power += float(np.dot([0.0, 0.0, -1.0], v4))
            weight = sum(conv.model.block(conv.index[n]).mass for n in range(1, 15)) * float(np.linalg.norm(g))
            assert power == pytest.approx(weight + 1.0, rel=1e-6)
    # With a live load: the thin arch's answer is False (voussoir raised LimitInfeasibleError),
    # checked or not.
    model, problem = semicircular_arch(thickness=0.05, load_on=4)
    for check in (True, False):
        r = cv.solve(problem, analysis="limit", live="Live", density=2000.0, check_dead_load=check)
        assert r.metadata["carries_dead_load"] is False
        assert r.metadata["multiplier"] is None and r.metadata["status"] == "infeasible"
        assert "cannot carry its own weight" in r.metadata["reason"]
    # The 0.2 m arch: 2271.6 N at voussoir 4, checked or not.
    model, problem = semicircular_arch(load_on=4)
    checked = cv.solve(problem, analysis="limit", live="Live", density=2000.0)
    unchecked = cv.solve(problem, analysis="limit", live="Live", density=2000.0, check_dead_load=False)
    assert checked.metadata["carries_dead_load"] is True and unchecked.metadata["carries_dead_load"] is None
    assert checked.metadata["multiplier"] == pytest.approx(2271.6, rel=1e-4)
    assert unchecked.metadata["multiplier"] == pytest.approx(checked.metadata["multiplier"], rel=1e-9)
    # The other options of voussoir.limit pass through too: a 16-plane pyramid is a lower bound
    # within 1 − cos(π/16) = 1.9 %.
    pyramid = cv.solve(problem, analysis="limit", live="Live", density=2000.0, friction="pyramid", facets=16)
    assert 0.98 * checked.metadata["multiplier"] <= pyramid.metadata["multiplier"] <= checked.metadata["multiplier"] * (1 + 1e-6)


def test_a_static_run_that_does_not_settle_returns_flagged_results():
    """The block on its support (μ 0.2) pushed by 0.5 W never settles: it slides on. Results
    come back all the same with settled False, a NotSettledWarning, and the history of the
    unbalanced-force ratio (it stays at 0.29, the net force over the load) and the kinetic
    energy (growing as the block speeds up). A model without supports is refused, naming the
    cause (it was "unbalanced-force ratio target not reached ... (last value inf)")."""
    model, problem = sliding_block_problem()
    with pytest.warns(cv.NotSettledWarning, match="did not settle"):
        r = cv.solve(problem, analysis="static", density=2000.0, max_steps=5000)
    md = r.metadata
    assert md["settled"] is False and md["settle_steps"] == 5000
    h = md["history"]
    assert len(h["step"]) == len(h["unbalanced_ratio"]) == len(h["kinetic_energy"]) == len(h["time"]) > 100
    assert h["step"] == sorted(h["step"]) and h["step"][-1] == md["steps"]
    assert min(h["unbalanced_ratio"][len(h["step"]) // 2 :]) > 0.2  # far above the 1e-5 target
    assert h["kinetic_energy"][-1] > h["kinetic_energy"][len(h["step"]) // 2] > 0.0
    assert r.displacement(1)[0] > 0.1  # it slid
    # A settled run has the same flag and history.
    model, problem = sliding_block_problem(mu=0.6, push=0.1)
    r = cv.solve(problem, analysis="static", density=2000.0)
    assert r.metadata["settled"] is True and r.metadata["history"]["unbalanced_ratio"][-1] < 1e-5
    # An arch too thin to stand (the semicircle at 0.05 m; the limit analysis says it stands
    # down to 0.0654 m) collapses in the DEM: not settled after 10 000 steps, the ratio and
    # the kinetic energy high (measured at 20 000 steps: 0.72, 92 J, the blocks 1.9 m down);
    # at 0.08 m it settles (3479 steps).
    model, problem = semicircular_arch(thickness=0.05)
    with pytest.warns(cv.NotSettledWarning):
        r = cv.solve(problem, analysis="static", density=2000.0, max_steps=10000)
    assert r.metadata["settled"] is False and r.metadata["unbalanced_ratio"] > 0.1
    assert r.metadata["history"]["kinetic_energy"][-1] > 1.0
    assert max(np.linalg.norm(r.displacement(n)) for n in r.nodes()) > 0.1
    model, problem = semicircular_arch(thickness=0.08)
    assert cv.solve(problem, analysis="static", density=2000.0, max_steps=10000).metadata["settled"] is True
    # No support at all.
    free = BlockModel.from_template(ArchTemplate(rise=0.4, span=1.2, thickness=0.2, depth=0.15, n=5))
    problem = Problem(free)
    problem.set_contact_model("MohrCoulomb", phi=30.0)
    with pytest.raises(ValueError, match="no support"):
        cv.solve(problem, analysis="static", density=2000.0)
    with pytest.raises(ValueError, match="no support"):
        cv.solve(problem, analysis="capacity", capacity={"block": 1}, density=2000.0)
    # The limit analysis answers instead: not carried.
    assert cv.solve(problem, analysis="limit", live=[], density=2000.0).metadata["carries_dead_load"] is False


def test_support_reactions_balance_the_loads():
    """compas_voussoir.reactions(results): per support, the force and moment on it from the
    structure (global frame). Summed over the supports they are the weight of the free blocks
    plus the applied loads: the settled DEM of the reference arch (1 N on the plate), force to
    2e-8 (measured) within the 1e-5 settle ratio, moments about the origin (at the settled
    positions) to 1e-6 relative; the limit analysis at collapse (weight + multiplier × live)
    to 5e-13 measured (asserted 1e-9). The reactions survive compas's JSON round trip."""
    import compas

    model, plate, problem = reference_problem()
    conv = cv.to_voussoir(problem, density=DENSITY, densities={plate: STEEL})
    m = conv.model
    free = [i for i in range(len(m)) if not m.block(i).is_fixed]
    weight = sum(m.block(i).mass for i in free) * 9.81
    plate_point = np.mean(np.asarray(model.graph.node_element(plate).modelgeometry.to_vertices_and_faces()[0]), axis=0)
    supports = {e.graphnode for e in model.elements() if e.is_support}

    r = cv.solve(problem, analysis="static", density=DENSITY, densities={plate: STEEL})
    assert r.metadata["settled"] and "on the support" in r.metadata["reaction_on"]
    reactions = cv.reactions(r, about=(0, 0, 0))
    assert set(reactions) == supports
    F = sum(x["force"] for x in reactions.values())
    M = sum(x["moment"] for x in reactions.values())
    assert F[2] == pytest.approx(-(weight + 1.0), rel=1e-6)
    assert abs(F[0]) < 1e-5 * weight and abs(F[1]) < 1e-9 * weight
    # The loads' moment about the origin at the settled positions (the live load's point
    # moves with the plate).
    def moved(node, p):
        T = np.asarray(r.transformation(node).matrix)
        return T[:3, :3] @ p + T[:3, 3]

    expected = sum(np.cross(moved(conv.node[i], conv.centroids[i]), [0, 0, -m.block(i).mass * 9.81]) for i in free)
    expected = expected + np.cross(moved(plate, plate_point), [0, 0, -1.0])
    assert np.allclose(M, expected, rtol=0, atol=1e-6 * weight)
    # Each support's thrust is inward (the force on the support pushes it outward).
    for node, x in cv.reactions(r).items():
        assert x["force"][2] < 0 and np.sign(x["force"][0]) == np.sign(x["point"][0])
    back = compas.json_loads(compas.json_dumps(r))
    assert all(np.allclose(cv.reactions(back)[n]["force"], x["force"]) for n, x in cv.reactions(r).items())

    lim = cv.solve(problem, analysis="limit", live="Live", density=DENSITY, densities={plate: STEEL}, fixity={plate: PLATE_IN_PLANE})
    lam = lim.metadata["multiplier"]
    reactions = cv.reactions(lim, about=(0, 0, 0))
    F = sum(x["force"] for x in reactions.values())
    M = sum(x["moment"] for x in reactions.values())
    assert np.allclose(F, [0, 0, -(weight + lam)], rtol=0, atol=1e-9 * (weight + lam))
    expected = sum(np.cross(conv.centroids[i], [0, 0, -m.block(i).mass * 9.81]) for i in free)
    expected = expected + np.cross(plate_point, [0, 0, -lam])
    assert np.allclose(M, expected, rtol=0, atol=1e-9 * (weight + lam))


def test_hinge_sides_of_the_four_hinge_mechanism():
    """The semicircular arch (intrados radius 1 m, 0.2 m thick, 16 voussoirs, μ 1) under a
    point load on voussoir 4 (at 56° from the right springing): the classic four-hinge
    mechanism, 2271.6 N. Per hinged joint the Results say which side the pivot is on:
    from the right, intrados (joint 1–2, 22.5°), extrados under the load (4–5, 56.2°),
    intrados (10–11, 123.8°), extrados (14–15, 168.8°): the sides alternate, the joint under
    the load opening at the intrados. Checked against the geometry: the pivot corners lie on
    the intrados (radius 1) or the extrados (1.2), the opening ones on the other. The centre
    is found from the hinged joints' planes; given explicitly, the same."""
    model, problem = semicircular_arch(load_on=4)
    r = cv.solve(problem, analysis="limit", live="Live", density=2000.0)
    hinges = sorted(r.metadata["hinges"], key=lambda h: math.atan2(h["pivot_point"][2], h["pivot_point"][0]))
    assert [tuple(h["edge"]) for h in hinges] == [(1, 2), (4, 5), (10, 11), (14, 15)]
    assert [h["side"] for h in hinges] == ["intrados", "extrados", "intrados", "extrados"]
    assert [h["opens_on"] for h in hinges] == ["extrados", "intrados", "extrados", "intrados"]
    for h in hinges:
        radius = {"intrados": 1.0, "extrados": 1.2}
        pivot = np.asarray(h["pivot"])
        opens = np.asarray(h["opens"])
        assert len(pivot) == 2 and len(opens) == 2  # an edge across the arch's depth
        assert np.allclose(np.hypot(pivot[:, 0], pivot[:, 2]), radius[h["side"]], atol=1e-9)
        assert np.allclose(np.hypot(opens[:, 0], opens[:, 2]), radius[h["opens_on"]], atol=1e-9)
        assert h["opening"] > 0 and abs(abs(h["axis"][1]) - 1.0) < 1e-9  # turning about the depth
        assert r.edge_attribute(tuple(h["edge"]), "hinge")["side"] == h["side"]
        # Its corners: the pivot closed, the others open.
        status = dict(zip(map(tuple, np.round(r.contact_point(tuple(h["edge"])), 12)), r.status(tuple(h["edge"]))))
        assert {status[tuple(np.round(p, 12))] for p in pivot} == {"closed"}
        assert {status[tuple(np.round(p, 12))] for p in opens} == {"open"}
    given = cv.solve(problem, analysis="limit", live="Live", density=2000.0, centre=(0.0, 0.1, 0.0))
    assert [h["side"] for h in given.metadata["hinges"]] == [h["side"] for h in r.metadata["hinges"]]
    # A block rocking on its base has no intrados: the pivot edge is given, no side. The cube
    # pushed at its centroid (μ 2: it tips before it slides) turns about its far edge (x = 0.1)
    # at a push of W (b/h = 1): the multiplier of 0.1 W is 10 (measured 9.99996).
    model, problem = sliding_block_problem(mu=2.0, push=0.1)
    r = cv.solve(problem, analysis="limit", live="Push", density=2000.0)
    (h,) = r.metadata["hinges"]
    assert h["side"] is None and np.allclose(np.asarray(h["pivot"])[:, 0], 0.1)
    assert np.allclose(h["towards"], [1.0, 0.0, 0.0], atol=1e-9)
    assert r.metadata["multiplier"] == pytest.approx(10.0, rel=1e-5)


def test_model_defaults_are_voussoirs_own():
    """The sub-contact density and contact tolerance are not restated here: None takes
    ``voussoir.Model.defaults()`` (issue 46: 15 per edge and 1e-3 were written again)."""
    import inspect

    for fn in (cv.run, cv.to_voussoir):
        params = inspect.signature(fn).parameters
        assert params["subcontacts_per_edge"].default is None
        assert params["contact_tolerance"].default is None


def test_fracture_energies_make_mortared_joints():
    """compas_dem's Mohr–Coulomb model has strengths but no fracture energies: with
    ``fracture=`` (or an interface's ``gf_i``, ``gf_ii``) the joints are voussoir.MortarJoint,
    softening on them; without, brittle CoulombSlip as before (issue 44, item 4). What the law
    then dissipates is tested with the law (python/tests/test_mortar.py, tests/mortar.rs)."""
    model = block_on_support()
    problem = Problem(model)
    problem.set_contact_model("MohrCoulomb", phi=30.0, c=2e5, t_c=1e5)
    conv = cv.to_voussoir(problem, density=2000.0)
    assert isinstance(conv.model.joint_law(0, 0), vs.CoulombSlip) and conv.law["law"] == "CoulombSlip"
    conv = cv.to_voussoir(problem, density=2000.0, fracture={"gf_i": 10.0, "gf_ii": 50.0, "phi_r": 25.0})
    law = conv.model.joint_law(0, 0)
    assert isinstance(law, vs.MortarJoint) and conv.law["law"] == "MortarJoint"
    assert law.mode_i_fracture_energy == 10.0 and law.mode_ii_fracture_energy == 50.0
    assert law.tensile_strength == 1e5 and law.cohesion == 2e5 and law.residual_friction_deg == 25.0
    # Per interface: its own fracture energies; the others keep the problem's law.
    a, b = sorted(conv.index)[:2]
    conv = cv.to_voussoir(problem, density=2000.0, interfaces={(a, b): {"gf_i": 5.0}})
    il = conv.model.interface_law(conv.index[a], conv.index[b])
    assert isinstance(il, vs.MortarJoint) and il.mode_i_fracture_energy == 5.0
    assert isinstance(conv.model.joint_law(0, 0), vs.CoulombSlip)
    # A fracture energy needs its strength; unknown keys are named.
    problem.set_contact_model("MohrCoulomb", phi=30.0)
    with pytest.raises(ValueError, match="gf_i = 10.0 softens the t_c"):
        cv.to_voussoir(problem, density=2000.0, fracture={"gf_i": 10.0})
    with pytest.raises(ValueError, match="unknown keys \\['gfi'\\]"):
        cv.to_voussoir(problem, density=2000.0, fracture={"gfi": 10.0})
    with pytest.raises(ValueError, match="need a fracture energy"):
        cv.to_voussoir(problem, density=2000.0, fracture={"phi_r": 20.0})
