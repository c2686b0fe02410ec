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
