"""Studies on Dask (``voussoir.study``): the same numbers as a serial loop, failures as rows,
workers that die, resumed studies."""

import os
import sys

import pytest

distributed = pytest.importorskip("distributed")
pd = pytest.importorskip("pandas")

import cloudpickle  # noqa: E402 - a dependency of distributed

import voussoir as vs  # noqa: E402

# The case functions below travel to the workers by value (they cannot import this module).
cloudpickle.register_pickle_by_value(sys.modules[__name__])


def pushed_block(friction_deg, push):
    """A block on a base pushed sideways by ``push`` times its weight for 300 steps: how far it
    slid and its kinetic energy (a few hundredths of a second a case)."""
    m = vs.Model()
    m.set_joint_law(0, 0, vs.CoulombSlip.dry(4e9, 1.6e9, friction_deg))
    m.add_cuboid("base", (-1, -1, -0.2), (1, 1, 0), 2600.0, fixed=True)
    m.add_cuboid("block", (0, 0, 0), (0.4, 0.3, 0.2), 2600.0)
    weight = 2600.0 * 0.024 * 9.81
    m.run_steps(20)
    m.set_load(1, force=(push * weight, 0, 0))
    m.run_steps(300)
    return {"slid_m": float(m.displacements()[1][0]), "kinetic_j": m.energies()["kinetic"]}


def sometimes_fails(friction_deg, push):
    if push > 0.7:
        raise ValueError(f"no such push: {push}")
    return pushed_block(friction_deg, push)


def dies_once(friction_deg, push, marker):
    """Kills its worker the first time it runs (a crash, an out-of-memory kill)."""
    if push == 0.4 and friction_deg == 30 and not os.path.exists(marker):
        open(marker, "w").close()
        os._exit(1)
    return pushed_block(friction_deg, push)


CASES = vs.study.grid(friction_deg=[25, 30, 35], push=[0.2, 0.4, 0.6, 0.8])


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None, env={"RAYON_NUM_THREADS": "1"}
    )
    c = distributed.Client(cluster)
    yield c
    c.close()
    cluster.close()


def test_a_study_on_two_workers_equals_the_serial_loop_bit_for_bit(client, tmp_path):
    table = vs.study.run(pushed_block, CASES, store=tmp_path / "s", client=client, progress=False)
    serial = [pushed_block(**c) for c in CASES]
    assert len(table) == 12 and list(table.columns) == ["friction_deg", "push", "slid_m", "kinetic_j", "error"]
    assert (table["error"] == "").all()
    assert table["slid_m"].tolist() == [r["slid_m"] for r in serial]
    assert table["kinetic_j"].tolist() == [r["kinetic_j"] for r in serial]
    # Physics, not only bookkeeping: pushed beyond tan φ the block slides, below it does not.
    for row in table.itertuples():
        sliding = row.push > __import__("math").tan(__import__("math").radians(row.friction_deg))
        assert (row.slid_m > 1e-4) == sliding, row
    # The table on disk is the same.
    on_disk = pd.read_csv(tmp_path / "s" / "table.csv", keep_default_na=False)
    assert on_disk["slid_m"].tolist() == table["slid_m"].tolist()
    # A rerun runs nothing: every case is in the store.
    again = vs.study.run(lambda **_: 1 / 0, CASES, store=tmp_path / "s", client=client, progress=False)
    pd.testing.assert_frame_equal(again, table)


def test_a_raising_case_is_a_row_with_its_message(client):
    table = vs.study.run(sometimes_fails, CASES, client=client, progress=False)
    failed = table[table["error"] != ""]
    assert failed["push"].tolist() == [0.8, 0.8, 0.8]
    assert failed["error"].str.contains("ValueError: no such push: 0.8").all()
    assert table[table["error"] == ""]["slid_m"].notna().all()


def test_a_worker_that_dies_has_its_case_rerun(client, tmp_path):
    marker = str(tmp_path / "died")
    cases = [dict(c, marker=marker) for c in CASES]
    table = vs.study.run(dies_once, cases, client=client, progress=False, retries=2)
    assert os.path.exists(marker), "a worker died"
    assert (table["error"] == "").all(), table["error"].tolist()
    assert table["slid_m"].tolist() == [pushed_block(c["friction_deg"], c["push"])["slid_m"] for c in CASES]


def test_serial_runs_and_bad_cases():
    table = vs.study.run(pushed_block, CASES[:2], client="serial", progress=False)
    assert table["slid_m"].tolist() == [pushed_block(**c)["slid_m"] for c in CASES[:2]]
    with pytest.raises(ValueError, match="same case"):
        vs.study.run(pushed_block, [CASES[0], CASES[0]], client="serial")
    with pytest.raises(TypeError, match="list of values"):
        vs.study.grid(phi=30)


def test_the_static_sensitivity_cases_are_the_command_lines():
    """The 24 cases of ``cargo run --example arch_static`` (its summary.json labels), and one of
    them run through the study gives what ``scenarios.arch_static`` gives."""
    cases = vs.study.arch_static_cases()
    labels = [c["label"] for c in cases]
    assert len(cases) == 24 and labels[0] == "baseline" and labels[-1] == "rate 0.005 m/s"
    assert labels[1:4] == ["friction 25°", "friction 26°", "friction 27°"]
    assert "kn 2 GPa/m" in labels and "small displacements" in labels and "width 0.20 m" in labels
    quick = {"per_edge": 5, "max_displacement": 0.002}
    table = vs.study.arch_static_sensitivity(client="serial", progress=False, **quick)
    assert len(table) == 24 and (table["error"] == "").all(), table[table["error"] != ""]
    direct = vs.scenarios.arch_static(**dict(cases[0], **quick))
    assert table["peak_load_kn"][0] == direct["peak_load_kn"]
