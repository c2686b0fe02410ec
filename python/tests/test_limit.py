"""Limit analysis from Python (``voussoir.limit``) against closed forms."""

import math

import numpy as np
import pytest

import voussoir as vs
from conftest import WEIGHT, block_on_base

MU = math.tan(math.radians(30.5))


@pytest.fixture
def stepped():
    m = block_on_base()
    m.run_steps(1)
    return m


def test_a_block_pushed_low_slides_at_mu_w(stepped):
    """Pushed along x at mid-height: sliding (tan 30.5° W) comes before tipping (2 W)."""
    r = vs.limit(stepped, [{"block": 1, "point": (0.2, 0.15, 0.1), "force": (1.0, 0.0, 0.0)}])
    assert r["multiplier"] == pytest.approx(MU * WEIGHT, rel=1e-6)
    assert r["carries_dead_load"] is True and r["status"] in ("Solved", "AlmostSolved")
    # The mechanism: the block translates along +x, without turning.
    v, w = r["blocks"]["velocity"], r["blocks"]["angular_velocity"]
    assert v.shape == (2, 3) and np.allclose(v[0], 0) and np.allclose(w[0], 0)
    assert v[1][0] > 0 and abs(v[1][1]) < 1e-6 * v[1][0] and np.allclose(w[1], 0, atol=1e-6 * v[1][0])
    (c,) = r["contacts"]
    assert c["blocks"] == (0, 1)
    # The joint carries the weight and the push: N = W, friction = μ W.
    assert c["normal_force"].sum() == pytest.approx(WEIGHT, rel=1e-6)
    assert c["resultant"] == pytest.approx([-MU * WEIGHT, 0.0, WEIGHT], rel=1e-6, abs=1e-6 * WEIGHT)
    assert c["points"].shape == (len(c["normal_force"]), 3)
    assert (c["sliding"] > 0).all()


def test_a_block_pushed_high_tips_about_its_edge(stepped):
    """Pushed along y at 0.5 m through a lever: tipping about the edge y = 0.3 m,
    λ·0.5 = W·0.15, before sliding (tan 30.5° W)."""
    r = vs.limit(stepped, [(1, (0.2, 0.15, 0.5), (0.0, 1.0, 0.0))])
    # 1e-5: the interior-point solver's tolerance (measured 1.2e-6).
    assert r["multiplier"] == pytest.approx(0.3 * WEIGHT, rel=1e-5)
    # It turns about x (positive: +y at the top), its far edge opening.
    w = r["blocks"]["angular_velocity"][1]
    assert w[0] < 0 and abs(w[1]) < 1e-6 * abs(w[0]) and abs(w[2]) < 1e-6 * abs(w[0])
    (c,) = r["contacts"]
    # All the compression at the edge it turns about: the application point is on it.
    assert c["application_point"][1] == pytest.approx(0.3, abs=1e-6)
    # On the joint plane (the blocks overlap by their springs after a step: 0.6 µm).
    assert c["application_point"][2] == pytest.approx(0.0, abs=1e-5)
    # The resultant applied there gives the corners' moment about the edge's line.
    corners = np.cross(c["points"] - c["application_point"], c["normal_force"][:, None] * c["normal"])
    assert np.abs(corners.sum(axis=0)[:2]).max() < 1e-6 * WEIGHT


def test_the_pyramid_is_a_lower_bound_and_fixity_overrides(stepped):
    load = [{"block": 1, "point": (0.2, 0.15, 0.1), "force": (1.0, 0.0, 0.0)}]
    cone = vs.limit(stepped, load)["multiplier"]
    pyramid = vs.limit(stepped, load, friction="pyramid", facets=16)["multiplier"]
    assert pyramid <= cone * (1 + 1e-9)
    assert pyramid >= cone * math.cos(math.pi / 16) * (1 - 1e-9)
    # The block's rotations fixed for the analysis: pushed high, it can no longer tip and
    # slides at tan 30.5° W instead of tipping at 0.3 W.
    high = [(1, (0.2, 0.15, 0.5), (0.0, 1.0, 0.0))]
    assert vs.limit(stepped, high)["multiplier"] == pytest.approx(0.3 * WEIGHT, rel=1e-5)
    held = vs.limit(stepped, high, fixity={1: {"rotation": ["fixed", "fixed", "fixed"]}})
    assert held["multiplier"] == pytest.approx(MU * WEIGHT, rel=1e-5)
    assert np.allclose(held["blocks"]["angular_velocity"], 0)


def test_bad_input_is_refused_with_its_place(stepped):
    with pytest.raises(ValueError, match=r"live_loads\[0\].block"):
        vs.limit(stepped, [{"block": 5, "point": (0, 0, 0), "force": (1, 0, 0)}])
    with pytest.raises(ValueError, match=r'live_loads\[0\]: missing "force"'):
        vs.limit(stepped, [{"block": 1, "point": (0, 0, 0)}])
    with pytest.raises(ValueError, match="friction"):
        vs.limit(stepped, [(1, (0, 0, 0), (1, 0, 0))], friction="sphere")
    fresh = block_on_base()
    with pytest.raises(vs.VoussoirError, match="never stepped"):
        vs.limit(fresh, [(1, (0, 0, 0), (1, 0, 0))])


def test_a_thread_may_read_the_model_while_the_solver_runs(stepped):
    """The solve lets the GIL go and does not hold the model."""
    import threading

    out = []
    t = threading.Thread(target=lambda: out.append(vs.limit(stepped, [(1, (0.2, 0.15, 0.1), (1, 0, 0))])))
    t.start()
    assert stepped.block_count == 2
    t.join()
    assert out and out[0]["multiplier"] > 0


def test_the_docstring_examples_run():
    """The ``>>>`` examples of the package's functions and classes give what they show."""
    import doctest

    finder, runner = doctest.DocTestFinder(), doctest.DocTestRunner(optionflags=doctest.ELLIPSIS)
    tested = 0
    for name in vs.__all__:
        obj = getattr(vs, name)
        for test in finder.find(obj, name, globs={"vs": vs}):
            if test.examples:
                tested += 1
                runner.run(test)
    assert tested >= 2
    assert runner.failures == 0, runner.summarize()


def on_incline(psi_deg):
    """The block of ``block_on_base`` on a slope of ``psi_deg`` (gravity tilted: down-slope is
    +x), stepped once."""
    psi = math.radians(psi_deg)
    m = block_on_base(gravity=(9.81 * math.sin(psi), 0.0, -9.81 * math.cos(psi)))
    m.run_steps(1)
    return m


@pytest.mark.parametrize("psi_deg", [0.0, 20.0, 30.0])
def test_the_dead_load_alone_is_carried_below_the_friction_angle(psi_deg):
    """No live load: the dead-load question. On a slope shallower than φ = 30.5° the block
    stands (it would tip only at tan ψ = 2): carries_dead_load True, no multiplier, and the
    contact forces of an admissible state that balance its weight (to round-off: 1e-14 W
    measured) with compression only and shear within μ n."""
    m = on_incline(psi_deg)
    r = vs.limit(m, [])
    assert r["multiplier"] is None and r["carries_dead_load"] is True and r["reason"] is None
    assert r["status"] in ("Solved", "AlmostSolved")
    (c,) = r["contacts"]
    weight = m.block(1).mass * np.asarray(m.gravity)
    assert np.abs(c["resultant"] + weight).max() < 1e-10 * WEIGHT
    assert (c["normal_force"] >= -1e-10 * WEIGHT).all()
    assert (np.linalg.norm(c["shear_force"], axis=1) <= MU * c["normal_force"] + 1e-10 * WEIGHT).all()
    # The moment too: about the block's centroid the corner forces balance (gravity acts there).
    corners = c["normal_force"][:, None] * c["normal"] + c["shear_force"]
    moment = np.cross(c["points"] - m.positions()[1], corners).sum(axis=0)
    assert np.abs(moment).max() < 1e-10 * WEIGHT
    # No mechanism; joints are not classified.
    assert not r["blocks"]["velocity"].any() and not r["blocks"]["angular_velocity"].any()
    assert vs.limit(m, [], joints=[{"blocks": (0, 1), "intrados": (0, 0.15, 0), "extrados": (0.4, 0.15, 0)}])["mechanism"] is None
    # The same answer from live loads of zero force, and from carries_dead_load.
    zero = vs.limit(m, [(1, (0.2, 0.15, 0.1), (0.0, 0.0, 0.0))])
    assert zero["multiplier"] is None and zero["carries_dead_load"] is True
    assert vs.carries_dead_load(m) is True
    assert vs.carries_dead_load(m, friction="pyramid", facets=8) is (psi_deg < 29.0)


def test_the_dead_load_not_carried_is_an_answer():
    """Steeper than φ the block slides: carries_dead_load False, not an error, with the
    solver's status and a reason naming the block; no forces; the certificate moves the block
    down the slope, its joint opening by at least tan φ of its slip (associative)."""
    m = on_incline(32.0)
    r = vs.limit(m, [])
    assert r["multiplier"] is None and r["carries_dead_load"] is False
    assert r["status"] in ("PrimalInfeasible", "AlmostPrimalInfeasible")
    assert 'block #1 ("block") moves' in r["reason"]
    (c,) = r["contacts"]
    assert not c["normal_force"].any() and c["application_point"] is None
    v = r["blocks"]["velocity"][1]
    assert v[0] > 0 and np.allclose(r["blocks"]["velocity"][0], 0)
    scale = np.hypot(c["opening"], c["sliding"]).max()
    assert (c["opening"] >= MU * c["sliding"] - 1e-6 * scale).all()
    # The dead load's power is the weight.
    assert m.block(1).mass * float(np.dot(m.gravity, v)) == pytest.approx(WEIGHT, rel=1e-6)
    assert vs.carries_dead_load(m) is False
    # With a live load the question is the collapse load, and an arch of blocks that cannot
    # stand raises (below).
    with pytest.raises(vs.LimitInfeasibleError, match="cannot carry its own weight"):
        vs.limit(m, [(1, (0.2, 0.15, 0.1), (0.0, 1.0, 0.0))])


def test_limit_errors_have_their_own_classes(stepped):
    """Infeasible, unbounded and solver failures are subclasses of VoussoirError (and so of
    ValueError): callers catch them by class, not by message; VoussoirError still catches them."""
    for cls in (vs.LimitInfeasibleError, vs.LimitUnboundedError, vs.LimitSolverError):
        assert issubclass(cls, vs.VoussoirError) and issubclass(cls, ValueError)
        assert cls.__module__ == "voussoir" and cls.__doc__
    # A slab overhanging its support by three quarters: it cannot stand; pushed, that raises.
    m = vs.Model()
    m.set_joint_law(0, 0, vs.CoulombSlip.dry(4e9, 1.6e9, 30.0))
    m.add_cuboid("base", (-1, -1, -0.2), (0, 1, 0), 2600.0, fixed=True)
    m.add_cuboid("slab", (-0.1, 0, 0), (0.3, 0.2, 0.1), 2600.0)
    m.run_steps(1)
    with pytest.raises(vs.LimitInfeasibleError, match="cannot carry its own weight") as caught:
        vs.limit(m, [(1, (0.1, 0.1, 0.05), (-1.0, 0.0, 0.0))])
    assert isinstance(caught.value, vs.VoussoirError)
    # Lifted at its tip it stands only with the live load's help: refused when checked.
    lift = [(1, (0.3, 0.1, 0.1), (0.0, 0.0, 1.0))]
    with pytest.raises(vs.LimitInfeasibleError, match="dead loads alone are not carried"):
        vs.limit(m, lift)
    weight = 2600.0 * 0.008 * 9.81
    assert vs.limit(m, lift, check_dead_load=False)["multiplier"] == pytest.approx(0.5 * weight, rel=1e-6)
    dead = vs.limit(m, [])
    assert dead["carries_dead_load"] is False and 'block #1 ("slab") moves' in dead["reason"]
    # It tips about the support's edge x = 0: its far end falls.
    assert dead["blocks"]["angular_velocity"][1][1] > 0
    # A live load on the support: unbounded.
    with pytest.raises(vs.LimitUnboundedError, match="unbounded"):
        vs.limit(stepped, [(0, (0, 0, 0), (1, 0, 0))])
    # The solver stopped at its iteration limit.
    with pytest.raises(vs.LimitSolverError, match="MaxIterations"):
        vs.limit(stepped, [(1, (0.2, 0.15, 0.1), (1, 0, 0))], max_iterations=1)
    with pytest.raises(vs.LimitSolverError):
        vs.carries_dead_load(stepped, max_iterations=1)
    # Bad input is still a plain VoussoirError.
    with pytest.raises(vs.VoussoirError) as bad:
        vs.limit(stepped, [(1, (0, 0, 0), (1, 0, 0))], friction="pyramid", facets=2)
    assert not isinstance(bad.value, (vs.LimitInfeasibleError, vs.LimitUnboundedError, vs.LimitSolverError))
