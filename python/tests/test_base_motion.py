"""Base motions from Python (``Model.set_base_motion``, ``TimeHistory``) against closed forms."""

import math

import numpy as np
import pytest

import voussoir as vs


def table_model():
    m = vs.Model()
    m.set_joint_law(0, 0, vs.CoulombSlip.dry(1e9, 4e8, 30.0))
    table = m.add_cuboid("table", (-1, -1, -0.1), (1, 1, 0), 2500.0, fixed=True)
    return m, table


def test_a_table_shaken_by_an_accelerogram_moves_as_its_double_integral():
    """0.1 g at 2 Hz along x from rest: u(t) = a0/ω² (ωt − sin ωt)."""
    m, table = table_model()
    a0, f = 0.1 * 9.81, 2.0
    m.set_base_motion(table, x=vs.TimeHistory.sine(a0, f, 1.0, 100))
    m.run_until_time(0.25)
    w = 2 * math.pi * f
    exact = a0 / w**2 * (w * 0.25 - math.sin(w * 0.25))
    x = m.positions()[table][0]
    # The record is sampled 100 times a period and integrated exactly between samples; the
    # model lands on 0.25 s to within a step (1e-3 of the displacement, as the Rust example).
    assert x == pytest.approx(exact, rel=1e-3)
    assert m.positions()[table][1] == pytest.approx(0.0, abs=1e-15)


def test_a_record_in_g_from_csv_and_a_displacement_history(tmp_path):
    path = tmp_path / "record.csv"
    path.write_text("time [s],acc [g]\n0,0\n0.5,0.1\n1.0,0\n")
    h = vs.TimeHistory.from_csv(path, scale=9.81)
    assert h.times.tolist() == [0.0, 0.5, 1.0]
    assert h.values == pytest.approx([0.0, 0.981, 0.0])
    assert h.value_at(0.25) == pytest.approx(0.4905) and h.end == 1.0 and len(h) == 3
    # A displacement ramp along y: the table is where the record says.
    m, table = table_model()
    m.set_base_motion(table, y=vs.TimeHistory([0.0, 1.0], [0.0, 0.02]), kind="displacement")
    m.run_until_time(0.5)
    assert m.positions()[table][1] == pytest.approx(0.02 * m.time, rel=1e-9)
    # Removed: the table stops and its axes are fixed.
    m.set_base_motion(table)
    y = m.positions()[table][1]
    m.run_steps(50)
    assert m.positions()[table][1] == y


def test_bad_motions_are_refused():
    m, table = table_model()
    block = m.add_cuboid("block", (0, 0, 0), (0.2, 0.2, 0.2), 2500.0)
    with pytest.raises(vs.VoussoirError, match="fixed or prescribed"):
        m.set_base_motion(block, x=vs.TimeHistory.sine(1.0, 1.0, 1.0))
    with pytest.raises(vs.VoussoirError, match="0"):
        m.set_base_motion(table, x=vs.TimeHistory([0.0, 1.0], [0.01, 0.02]), kind="displacement")
    with pytest.raises(ValueError, match="kind"):
        m.set_base_motion(table, x=vs.TimeHistory.sine(1.0, 1.0, 1.0), kind="jerk")
    with pytest.raises(vs.VoussoirError, match="increase"):
        vs.TimeHistory([0.0, 0.0], [1.0, 2.0])
    with pytest.raises(vs.VoussoirError):
        vs.TimeHistory([0.0], [1.0])
    assert np.isfinite(vs.TimeHistory.sine(1.0, 1.0, 1.0).values).all()
