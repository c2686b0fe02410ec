"""Time-varying loads (``Model.set_load_history``), per-interface joint laws
(``Model.set_interface_law``) and contact polygons (``Model.contacts()["polygon"]``)."""

import math

import numpy as np
import pytest

import voussoir as vs


def test_a_ramped_load_moves_a_free_block_as_the_closed_form():
    """No gravity, no damping: a force ramped from 0 to F over T moves a block of mass m by
    F t³ / (6 m T) (0.2 % for the step), then, held, at the constant acceleration F/m."""
    m = vs.Model(gravity=(0, 0, 0))
    m.set_damping("none")
    b = m.add_cuboid("block", (0, 0, 0), (0.2, 0.2, 0.2), 2500.0)
    ramp = vs.TimeHistory([0.0, 0.1], [0.0, 1.0])
    m.set_load_history(b, ramp, force=(100, 0, 0))
    m.run_until_time(0.1)
    t = m.time
    assert m.displacements()[b, 0] == pytest.approx(100 * t**3 / (6 * 20 * 0.1), rel=2e-3)
    v = m.velocities()[b, 0]
    m.run_until_time(0.2)
    assert m.load(b)["force"][0] == 100.0  # held after the ramp
    assert m.velocities()[b, 0] - v == pytest.approx(100 / 20 * (m.time - t), rel=1e-6)
    e = m.energies()
    assert abs(e["balance_error"]) < 1e-9 * e["load_work"]
    # set_load replaces the history; None removes it, keeping the last load.
    m.set_load(b, force=(1, 0, 0))
    m.step()
    assert m.load(b)["force"][0] == 1.0
    m.set_load_history(b, ramp, force=(10, 0, 0))
    m.run_until_time(m.time + 0.05)
    m.set_load_history(b, None)
    last = m.load(b)["force"][0]
    m.step()
    assert 0 < last < 10 and m.load(b)["force"][0] == last


def test_load_histories_are_kept_by_scenes_and_checkpoints():
    m = vs.Model()
    m.set_joint_law(0, 0, vs.CoulombSlip.dry(1e9, 4e8, 30.0))
    m.add_cuboid("base", (-1, -1, -0.2), (1, 1, 0), 2500.0, fixed=True)
    b = m.add_cuboid("block", (0, 0, 0), (0.2, 0.2, 0.2), 2500.0)
    m.set_load_history(b, vs.TimeHistory.sine(1.0, 5.0, 1.0), force=(20, 0, 0))
    assert "load_history" in m.to_scene_json()
    m.run_until_time(0.03)
    resumed = vs.Model.from_checkpoint_string(m.to_checkpoint_string())
    m.run_until_time(0.06)
    resumed.run_until_time(0.06)
    assert np.array_equal(m.positions(), resumed.positions())
    assert np.array_equal(m.load(b)["force"], resumed.load(b)["force"])


def test_load_history_errors_name_the_argument():
    m = vs.Model()
    with pytest.raises(vs.VoussoirError, match="block index 3"):
        m.set_load_history(3, vs.TimeHistory([0, 1], [0, 1]), force=(1, 0, 0))
    m.add_cuboid("block", (0, 0, 0), (0.2, 0.2, 0.2), 2500.0)
    with pytest.raises(vs.VoussoirError, match="force"):
        m.set_load_history(0, vs.TimeHistory([0, 1], [0, 1]), force=(math.nan, 0, 0))
    with pytest.raises(TypeError):
        m.set_load_history(0, [0, 1], force=(1, 0, 0))


def test_an_interface_law_overrides_the_materials_law():
    """Two equal blocks on one slab (φ 30°) pushed by 0.5 W: the one whose interface with the
    slab has φ 20° slides, the other stands."""
    m = vs.Model()
    m.set_joint_law(0, 0, vs.CoulombSlip.dry(1e9, 4e8, 30.0))
    slab = m.add_cuboid("slab", (-1, -0.5, -0.2), (1, 0.5, 0), 2500.0, fixed=True)
    held = m.add_cuboid("held", (-0.6, -0.1, 0), (-0.4, 0.1, 0.2), 2500.0)
    weak = m.add_cuboid("weak", (0.4, -0.1, 0), (0.6, 0.1, 0.2), 2500.0)
    m.run_to_equilibrium(1e-6, 200_000)
    m.set_interface_law(weak, slab, vs.CoulombSlip.dry(1e9, 4e8, 20.0))
    assert m.interface_law(slab, weak).friction_deg == 20.0
    assert m.interface_law(slab, held) is None
    assert '"interfaces"' in m.to_scene_json()
    with pytest.raises(vs.VoussoirError, match="itself"):
        m.set_interface_law(weak, weak, vs.CoulombSlip.dry(1e9, 4e8, 20.0))
    with pytest.raises(vs.VoussoirError, match="block b 7"):
        m.set_interface_law(weak, 7, vs.CoulombSlip.dry(1e9, 4e8, 20.0))
    weight = 2500 * 0.008 * 9.81
    m.set_damping("none")
    for b in (held, weak):
        m.set_load(b, force=(0.5 * weight, 0, 0))
    x0 = m.positions()[:, 0].copy()
    m.run_until_time(m.time + 0.1)
    moved = m.positions()[:, 0] - x0
    assert moved[weak] > 5e-3 and abs(moved[held]) < 1e-4
    back = vs.Model.from_scene_json(m.to_scene_json())
    assert back.interface_law(weak, slab).friction_deg == 20.0
    # A checkpoint with the interface law in use loads and goes on bit for bit (it was refused:
    # "uses law 1, but their materials map to law 0").
    resumed = vs.Model.from_checkpoint_string(m.to_checkpoint_string())
    assert resumed.interface_law(weak, slab).friction_deg == 20.0
    for model in (m, resumed):
        model.run_steps(100)
    assert resumed.to_checkpoint_string() == m.to_checkpoint_string()
    assert np.array_equal(resumed.positions(), m.positions())


def test_contact_polygons_are_the_touching_faces():
    """A 0.4 × 0.3 m block on a larger slab: one contact whose polygon is the block's bottom
    face; a block on its edge: a segment along the edge."""
    m = vs.Model()
    m.set_joint_law(0, 0, vs.CoulombSlip.dry(1e9, 4e8, 30.0))
    m.add_cuboid("base", (-1, -1, -0.2), (1, 1, 0), 2500.0, fixed=True)
    m.add_cuboid("block", (0, 0, 0), (0.4, 0.3, 0.2), 2500.0)
    m.step()
    c = m.contacts()
    (poly,) = c["polygon"]
    assert poly.shape == (4, 3)
    # The block's bottom face, where it stands (sunk by 2 µm under its weight after a step).
    corners = sorted(map(tuple, np.round(poly[:, :2], 9)))
    assert np.allclose(corners, [(0, 0), (0, 0.3), (0.4, 0), (0.4, 0.3)], atol=1e-12)
    assert np.all(np.abs(poly[:, 2]) < 1e-5)
    # The polygon's area is the joint's, and the application point lies in it.
    x, y = poly[:, 0], poly[:, 1]
    area = 0.5 * abs(np.dot(x, np.roll(y, 1)) - np.dot(y, np.roll(x, 1)))
    assert area == pytest.approx(0.12, rel=1e-12)
    # A prism standing on its edge (a triangle's corner down): the polygon is a segment.
    m = vs.Model()
    m.set_joint_law(0, 0, vs.CoulombSlip.dry(1e9, 4e8, 30.0))
    m.add_cuboid("base", (-1, -1, -0.2), (1, 1, 0), 2500.0, fixed=True)
    m.add_polyhedron(
        "wedge",
        [(0, 0, 0), (-0.1, 0, 0.2), (0.1, 0, 0.2), (0, 0.3, 0), (-0.1, 0.3, 0.2), (0.1, 0.3, 0.2)],
        2500.0,
    )
    m.step()
    (poly,) = m.contacts()["polygon"]
    length = np.ptp(poly[:, 1])
    assert length == pytest.approx(0.3, rel=1e-9) and np.ptp(poly[:, 0]) < 1e-9
