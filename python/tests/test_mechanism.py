"""The mechanism classifier from Python (``voussoir.classify_joints``, ``build.arch_joints``)."""

import numpy as np
import pytest

import voussoir as vs

WEIGHT = 2500.0 * 0.016 * 9.81
JOINT = [{"blocks": (0, 1), "intrados": (0, 0.1, 0), "extrados": (0.2, 0.1, 0)}]


def standing_block(friction_deg):
    """A 0.2 × 0.2 × 0.4 m block settled on a fixed base."""
    m = vs.Model()
    m.set_joint_law(0, 0, vs.CoulombSlip.dry(1e9, 4e8, friction_deg))
    m.set_damping("local", alpha=0.8)
    m.add_cuboid("base", (-1, -1, -0.2), (1, 1, 0), 2500.0, fixed=True)
    block = m.add_cuboid("block", (0, 0, 0), (0.2, 0.2, 0.4), 2500.0)
    m.run_to_equilibrium(1e-5, 100_000)
    return m, block


def test_a_block_at_rest_has_a_closed_joint_centred_under_it():
    m, _ = standing_block(40.0)
    r = vs.classify_joints(m, JOINT)
    assert r["open_fraction"][0] == 0.0
    # Uniform pressure: the centre of the normal forces under the centroid, the weight carried.
    assert r["compression_position"][0] == pytest.approx(0.5, abs=1e-6)
    assert r["normal_force"][0] == pytest.approx(WEIGHT, rel=1e-4)
    assert r["hinge"] == [None] and r["description"] == "no hinges"


def test_a_block_tipped_over_hinges_about_the_far_edge():
    """0.6 W at the centroid: it tips (0.5 W would) before it slides (tan 40° W = 0.84 W)."""
    m, block = standing_block(40.0)
    m.set_damping("none")
    m.set_load(block, force=(0.6 * WEIGHT, 0, 0))
    m.run_until_time(m.time + 0.1)
    r = vs.classify_joints(m, JOINT)
    assert r["open_fraction"][0] > 0.5
    assert r["compression_position"][0] > 0.9
    assert r["hinge"] == ["extrados"] and r["hinges"] == [(0, "extrados")]
    assert not r["sliding"][0] and r["description"] == "hinges 0e"
    # Pushed the other way, about the other edge; a label of one's own is kept.
    m, block = standing_block(40.0)
    m.set_damping("none")
    m.set_load(block, force=(-0.6 * WEIGHT, 0, 0))
    m.run_until_time(m.time + 0.1)
    r = vs.classify_joints(m, [dict(JOINT[0], index=7)])
    assert r["hinges"] == [(7, "intrados")] and r["description"] == "hinges 7i"


def test_a_block_pushed_beyond_friction_slides():
    """φ 10°: 0.6 W slides it (tan 10° W = 0.18 W) by centimetres in 0.1 s."""
    m, block = standing_block(10.0)
    m.set_damping("none")
    m.set_load(block, force=(0.6 * WEIGHT, 0, 0))
    m.run_until_time(m.time + 0.1)
    r = vs.classify_joints(m, JOINT, slip=5e-4)
    assert r["slip"][0] > 5e-3
    assert r["sliding"][0] and r["sliding_joints"] == [0]
    assert "sliding 0" in r["description"]


def test_arch_joints_match_the_arch():
    blocks = vs.build.arch()
    joints = vs.build.arch_joints()
    assert len(joints) == len(blocks) - 1 == 14
    for k, j in enumerate(joints):
        assert j["index"] == k and j["blocks"] == (k, k + 1)
        assert j["points"].shape == (4, 3)
        # The joint's corners are vertices of both blocks it separates.
        for b in j["blocks"]:
            v = blocks[b].vertices
            for p in j["points"]:
                assert np.min(np.linalg.norm(v - p, axis=1)) < 1e-9
    shifted = vs.build.arch_joints(first_block=3)
    assert shifted[0]["blocks"] == (3, 4)


def test_bad_joints_are_refused_with_their_place():
    m, _ = standing_block(40.0)
    with pytest.raises(vs.VoussoirError, match=r"joints\[0\]: missing \"extrados\""):
        vs.classify_joints(m, [{"blocks": (0, 1), "intrados": (0, 0, 0)}])
    with pytest.raises(vs.VoussoirError, match=r"joints\[0\].blocks\[1\] 5"):
        vs.classify_joints(m, [{"blocks": (0, 5), "intrados": (0, 0, 0), "extrados": (1, 0, 0)}])
    with pytest.raises(vs.VoussoirError, match="two different blocks"):
        vs.classify_joints(m, [{"blocks": (1, 1), "intrados": (0, 0, 0), "extrados": (1, 0, 0)}])
    with pytest.raises(vs.VoussoirError, match="distinct finite"):
        vs.classify_joints(m, [{"blocks": (0, 1), "intrados": (0, 0, 0), "extrados": (0, 0, 0)}])
    with pytest.raises(vs.VoussoirError, match="open_fraction"):
        vs.classify_joints(m, JOINT, open_fraction=1.5)
    with pytest.raises(vs.VoussoirError, match="edge_band"):
        vs.classify_joints(m, JOINT, edge_band=float("nan"))
    with pytest.raises(vs.VoussoirError, match="slip"):
        vs.classify_joints(m, JOINT, slip=-1.0)


def test_docstring_examples_run():
    import doctest

    runner = doctest.DocTestRunner()
    for name, obj in (("classify_joints", vs.classify_joints), ("arch_joints", vs.build.arch_joints)):
        tests = doctest.DocTestFinder().find(obj, name, globs={"vs": vs})
        assert tests and tests[0].examples, name
        for t in tests:
            runner.run(t)
    assert runner.failures == 0, runner.summarize()


def test_the_limit_analysis_names_its_mechanism():
    """The reference arch (φ 30.5°) under a point load on voussoir 5's extrados: the limit
    analysis's mechanism, classified at the arch's joints, slides at joints 4, 5 and 13 as
    arch_static's table reports it ("no hinges; sliding 4 5 13")."""
    m = vs.Model(gravity=(0, -9.81, 0))
    m.set_joint_law(0, 0, vs.CoulombSlip.dry(4e9, 1.6e9, 30.5))
    m.add_blocks(vs.build.arch())
    m.run_steps(1)
    joints = vs.build.arch_joints()
    e4, e5 = joints[4]["extrados"], joints[5]["extrados"]
    point = 0.5 * (e4 + e5)
    r = vs.limit(m, [{"block": 5, "point": point, "force": (0, -1, 0)}], joints=joints)
    assert len(r["joints"]) == 14
    assert r["multiplier"] == pytest.approx(2755.0, rel=0.005)  # arch_static's limit load
    assert r["mechanism"] == "no hinges; sliding 4 5 13"
    sliding = [j["joint"] for j in r["joints"] if j["is_sliding"]]
    assert sliding == [4, 5, 13] and all(j["hinge"] is None for j in r["joints"])
    with pytest.raises(vs.VoussoirError, match="mechanism_tolerance"):
        vs.limit(m, [{"block": 5, "point": point, "force": (0, -1, 0)}], joints=joints, mechanism_tolerance=0.0)


def test_contact_tangent_components():
    m, _ = standing_block(40.0)
    m.set_load(1, force=(0.2 * WEIGHT, 0, 0))
    m.run_to_equilibrium(1e-6, 200_000)
    c = m.contacts()
    n, t1, t2 = c["normal"][0], c["tangent1"][0], c["tangent2"][0]
    assert np.allclose(np.cross(n, t1), t2)
    f = c["force"][0]
    assert np.allclose(c["tangent_force"][0], [f @ t1, f @ t2])
    # The block's base carries the push: the tangential force on the block is the load.
    assert np.hypot(*c["tangent_force"][0]) == pytest.approx(0.2 * WEIGHT, rel=1e-4)
