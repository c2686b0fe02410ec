"""Progress bars of long runs and the short ``repr`` of results."""

import pickle
import sys

import numpy as np
import pytest

import voussoir as vs


def block_on_base():
    m = vs.Model()
    m.set_joint_law(0, 0, vs.CoulombSlip.dry(1e9, 4e8, 30.0))
    m.set_damping("local", alpha=0.8)
    m.add_cuboid("base", (-1, -1, -0.2), (1, 1, 0), 2500.0, fixed=True)
    m.add_cuboid("block", (0, 0, 0), (0.2, 0.2, 0.2), 2500.0)
    return m


@pytest.mark.parametrize("tqdm", [True, False], ids=["tqdm", "plain"])
def test_runs_show_progress_to_their_goal(tqdm, capsys, monkeypatch):
    if tqdm:
        pytest.importorskip("tqdm")
    else:
        monkeypatch.setitem(sys.modules, "tqdm.auto", None)  # import fails: the plain line
    m = block_on_base()
    assert m.run_steps(300, progress=True)
    err = capsys.readouterr().err
    assert "voussoir run" in err and "100%" in err and "300/300" in err, err
    assert m.run_until_time(m.time + 0.01, progress=True)
    err = capsys.readouterr().err
    assert "100%" in err and " s" in err, err
    m.run_to_equilibrium(1e-4, 100_000, progress=True)
    err = capsys.readouterr().err
    assert "voussoir equilibrium" in err and "ratio" in err, err
    # Without progress=True, nothing is written.
    m.run_steps(10)
    assert capsys.readouterr().err == ""


def test_a_failing_run_closes_its_bar(capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "tqdm.auto", None)
    m = block_on_base()
    with pytest.raises(vs.VoussoirError):
        m.run_to_equilibrium(1e-30, 50, progress=True)
    err = capsys.readouterr().err
    assert "voussoir equilibrium" in err and err.endswith("\n"), err


def test_push_over_shows_its_travel(capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "tqdm.auto", None)
    m = vs.Model()
    m.set_joint_law(0, 0, vs.CoulombSlip.dry(1e9, 4e8, 30.0))
    m.set_joint_law(0, 1, vs.CoulombSlip.dry(1e9, 4e8, 0.0))
    m.set_damping("local", alpha=0.8)
    m.add_cuboid("base", (-1, -1, -0.2), (1, 1, 0), 2500.0, fixed=True)
    m.add_cuboid("cube", (0, 0, 0), (0.2, 0.2, 0.2), 2500.0)
    pusher = m.add_cuboid(
        "pusher", (-0.1, 0.05, 0.05), (0.0, 0.15, 0.15), 2500.0, material=1,
        fixed={"translation": [0.0, "fixed", "fixed"], "rotation": ["fixed"] * 3},
    )
    m.run_to_equilibrium(1e-5, 100_000)
    r = m.push_over(pusher, (1, 0, 0), 5e-6, max_travel=2e-4, progress=True)
    err = capsys.readouterr().err
    assert "voussoir push-over" in err and " m " in err and "load" in err, err
    # The result: a dict with a short repr.
    assert isinstance(r, dict) and r["stop"] == "max_travel"
    text = repr(r)
    assert text.startswith("PushOverResult(") and "peak_load=" in text and "curve={time, step" in text
    assert len(text.splitlines()) <= 10


def test_results_are_dicts_with_a_short_repr():
    m = block_on_base()
    m.run_to_equilibrium(1e-5, 100_000)
    r = vs.limit(m, [{"block": 1, "point": (0.1, 0.1, 0.1), "force": (1, 0, 0)}])
    assert isinstance(r, dict) and r["multiplier"] > 0
    text = repr(r)
    assert text.startswith("LimitResult(") and "multiplier=" in text and "contacts=[1 items]" in text
    assert len(text.splitlines()) <= 12
    c = m.contacts()
    assert isinstance(c["normal"], np.ndarray)
    assert "normal=array(1×3, float64)" in repr(c)
    assert repr(m.energies()).startswith("Energies(")
    assert repr(m.subcontacts()).startswith("SubContacts(")
    # Pickled (as Dask does) it comes back the same.
    back = pickle.loads(pickle.dumps(r))
    assert back.kind == "LimitResult" and back["multiplier"] == r["multiplier"]
