"""Studies on Dask (``voussoir.study``): the same numbers as a serial loop, failures as rows,
workers that die, resumed studies, exact case keys, values that survive the store, corrupt
case files, cases that hang."""

import hashlib
import json
import os
import struct
import sys
import threading
import time
import warnings

import pytest

distributed = pytest.importorskip("distributed")
pd = pytest.importorskip("pandas")

import cloudpickle  # noqa: E402 - a dependency of distributed

import numpy as np  # noqa: E402

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


def summed(a):
    return {"total": float(np.sum(a)), "dtype": str(a.dtype)}


def history_peak(h):
    return {"peak": float(np.max(h.values))}


def test_cases_that_print_alike_are_different_cases(client, tmp_path):
    """F4: two arrays (or two TimeHistory objects) with the same printout are two cases, and a
    rerun on a store never returns the other one's result."""
    a = np.zeros(2000)
    b = a.copy()
    b[1000] = 1.0
    assert repr(a) == repr(b)
    assert vs.study.case_key({"a": a}) != vs.study.case_key({"a": b})
    assert vs.study.case_key({"a": a}) == vs.study.case_key({"a": a.copy()})
    assert vs.study.case_key({"a": a}) != vs.study.case_key({"a": a.astype(np.float32)})
    table = vs.study.run(summed, [{"a": a}, {"a": b}], store=tmp_path / "both", client="serial", progress=False)
    assert table["total"].tolist() == [0.0, 1.0]
    store = tmp_path / "one"
    vs.study.run(summed, [{"a": a}], store=store, client="serial", progress=False)
    assert vs.study.run(summed, [{"a": b}], store=store, client="serial", progress=False)["total"].tolist() == [1.0]
    # The same array again is found in the store (not run: the function would fail).
    again = vs.study.run(lambda **_: 1 / 0, [{"a": a.copy()}], store=store, client="serial", progress=False)
    assert again["total"].tolist() == [0.0] and again["error"].tolist() == [""]

    h1 = vs.TimeHistory([0.0, 1.0, 2.0], [0.0, 1.0, 0.0])
    h2 = vs.TimeHistory([0.0, 1.0, 2.0], [0.0, 2.0, 0.0])
    assert repr(h1) == repr(h2)
    store = tmp_path / "histories"
    vs.study.run(history_peak, [{"h": h1}], store=store, client="serial", progress=False)
    table = vs.study.run(history_peak, [{"h": h2}], store=store, client="serial", progress=False)
    assert table["peak"].tolist() == [2.0]
    # TimeHistory parameters travel to Dask workers too.
    table = vs.study.run(history_peak, [{"h": h1}, {"h": h2}], client=client, progress=False)
    assert table["peak"].tolist() == [1.0, 2.0] and (table["error"] == "").all()

    # A parameter that can be neither written exactly nor pickled is refused, by name.
    with pytest.raises(TypeError, match=r"case 1: parameter 'lock'.*cannot be pickled"):
        vs.study.run(summed, [{"lock": 1}, {"lock": threading.Lock()}], client="serial", progress=False)


def test_plain_cases_keep_the_keys_of_stores_written_before(tmp_path):
    """The keys of plain cases are unchanged (JSON with sorted keys, hashed): a store written by
    an earlier voussoir resumes."""
    case = {"friction_deg": 30, "push": 0.2, "label": "x", "point": (0.1, 0.2), "kn": np.float64(4e9), "on": True}
    key = hashlib.sha256(json.dumps(case, sort_keys=True, default=repr).encode()).hexdigest()[:20]
    assert vs.study.case_key(case) == key
    folder = tmp_path / "s" / "cases"
    folder.mkdir(parents=True)
    entry = {"case": case, "values": {"slid_m": 0.125}, "error": "", "seconds": 1.0}
    (folder / f"{key}.json").write_text(json.dumps(entry, default=repr))
    table = vs.study.run(lambda **_: 1 / 0, [case], store=tmp_path / "s", client="serial", progress=False)
    assert table["slid_m"].tolist() == [0.125] and table["error"].tolist() == [""]


def returns_arrays(n):
    return {
        "curve": (np.arange(n * 6, dtype=np.float32) / 7).reshape(n, 6),
        "ids": np.arange(n, dtype=">i8"),
        "third": n / 3,
        "pair": (n, 0.1 + 0.2),
        "nested": {"x": [np.float64(n / 7), None, "s"]},
        "flag": np.bool_(n > 1),
    }


def test_returned_values_round_trip_a_resume(client, tmp_path):
    """F6: arrays come back from the store as arrays (dtype, shape, bytes), floats bit for bit."""
    cases = [{"n": 1}, {"n": 2}]
    store = tmp_path / "s"
    first = vs.study.run(returns_arrays, cases, store=store, client=client, progress=False)
    again = vs.study.run(lambda **_: 1 / 0, cases, store=store, client="serial", progress=False)
    for table in (first, again):
        assert (table["error"] == "").all(), table["error"].tolist()
        for k, c in enumerate(cases):
            want = returns_arrays(**c)
            for name in ("curve", "ids"):
                got = table[name][k]
                assert isinstance(got, np.ndarray), (name, got)
                assert got.dtype == want[name].dtype and got.shape == want[name].shape
                assert got.tobytes() == want[name].tobytes()
            assert struct.pack("<d", table["third"][k]) == struct.pack("<d", want["third"])
            assert table["pair"][k] == want["pair"] and isinstance(table["pair"][k], tuple)
            assert table["nested"][k] == {"x": [c["n"] / 7, None, "s"]}
            assert table["flag"][k] == (c["n"] > 1)


def clashing(push, name, **_):
    return {name: 1.0, "other": 2.0}


def test_a_value_named_like_a_parameter_or_error_is_refused():
    """F6: a value named like a parameter (of any case) or ``error`` fails its case, naming the
    key, and leaves the parameter's column alone."""
    cases = [
        {"push": 0.2, "name": "push"},
        {"push": 0.4, "name": "error"},
        {"push": 0.6, "name": "x"},  # the parameter of the next case
        {"push": 0.8, "name": "fine", "x": 1},
    ]
    table = vs.study.run(clashing, cases, client="serial", progress=False)
    assert table["push"].tolist() == [0.2, 0.4, 0.6, 0.8]
    errors = table["error"].tolist()
    assert errors[0].startswith("ValueError") and "'push'" in errors[0] and "parameter" in errors[0]
    assert errors[1].startswith("ValueError") and "'error'" in errors[1]
    assert "'x'" in errors[2] and errors[3] == ""
    assert table["fine"][3] == 1.0 and table["x"][3] == 1
    with pytest.raises(ValueError, match="parameter named 'error'"):
        vs.study.run(summed, [{"error": 0.1}], client="serial", progress=False)


def test_a_corrupt_case_file_is_named_and_its_case_run_again(tmp_path):
    """F10: a case file that is not a record (cut short) is warned about by name, its case run
    again and the file replaced; the other cases are not run again."""
    calls = []

    def counted(friction_deg, push):
        calls.append(push)
        return {"twice": 2 * push}

    cases = CASES[:3]
    store = tmp_path / "s"
    vs.study.run(counted, cases, store=store, client="serial", progress=False)
    path = store / "cases" / f"{vs.study.case_key(cases[1])}.json"
    path.write_text(path.read_text()[:25])
    calls.clear()
    with pytest.warns(RuntimeWarning, match=str(path.name) + ".*run again"):
        table = vs.study.run(counted, cases, store=store, client="serial", progress=False)
    assert calls == [cases[1]["push"]]
    assert table["twice"].tolist() == [2 * c["push"] for c in cases] and (table["error"] == "").all()
    json.loads(path.read_text())  # replaced by a whole record
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        vs.study.run(counted, cases, store=store, client="serial", progress=False)
    assert calls == [cases[1]["push"]]


def hangs_at(friction_deg, push, hang, pidfile, **_):
    """Hangs (ten minutes) at ``push == hang``, writing its process's id first."""
    if push == hang:
        with open(pidfile, "w") as f:
            f.write(str(os.getpid()))
        time.sleep(600)
    return pushed_block(friction_deg, push)


def gone(pid, within=10.0):
    until = time.monotonic() + within
    while time.monotonic() < until:
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return True
        time.sleep(0.1)
    return False


def test_a_case_that_hangs_is_killed_at_its_timeout(client, tmp_path):
    """F10: with ``timeout=`` a hung case is a ``TimeoutError`` row and its process is killed;
    the other cases give the serial loop's numbers, on Dask and serially."""
    for where, cases, limit in ((client, CASES[:4], 4), ("serial", CASES[:2], 2)):
        pidfile = str(tmp_path / f"pid-{limit}")
        cases = [dict(c, hang=0.4, pidfile=pidfile) for c in cases]
        started = time.monotonic()
        table = vs.study.run(hangs_at, cases, store=tmp_path / f"s{limit}", client=where, progress=False, timeout=limit)
        assert time.monotonic() - started < limit + 20
        errors = table["error"].tolist()
        assert errors[1].startswith("TimeoutError") and f"timeout={limit}" in errors[1], errors
        assert errors[:1] + errors[2:] == [""] * (len(cases) - 1), errors
        ok = [k for k in range(len(cases)) if k != 1]
        serial = [pushed_block(cases[k]["friction_deg"], cases[k]["push"])["slid_m"] for k in ok]
        assert [table["slid_m"][k] for k in ok] == serial
        assert gone(int(open(pidfile).read())), "the hung case's process was killed"
    with pytest.raises(ValueError, match="timeout"):
        vs.study.run(pushed_block, CASES[:1], client="serial", progress=False, timeout=0)


def test_a_case_process_that_dies_has_its_case_rerun(tmp_path):
    """With a timeout, a case whose process dies is run again in a new one (``retries``)."""
    marker = str(tmp_path / "died")
    cases = [dict(c, marker=marker) for c in CASES[4:6]]
    table = vs.study.run(dies_once, cases, client="serial", progress=False, timeout=60)
    assert os.path.exists(marker), "a case process died"
    assert (table["error"] == "").all(), table["error"].tolist()
    assert table["slid_m"].tolist() == [pushed_block(c["friction_deg"], c["push"])["slid_m"] for c in CASES[4:6]]
