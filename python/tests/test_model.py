"""Building, running and reading a model."""

import math
import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import voussoir as vs
from conftest import PUSH, WEIGHT, block_on_base


def test_readme_example_equilibrium(model):
    """The README's Rust example: half the friction capacity sideways, no sliding."""
    model.set_load(1, force=(PUSH, 0, 0))
    steps = model.run_to_equilibrium(1e-5, 50_000)
    assert 0 < steps < 50_000
    c = model.contacts()
    assert c["blocks"].tolist() == [[0, 1]]
    assert abs(c["normal_force"][0] - WEIGHT) < 1e-3 * WEIGHT
    # The resultant on the block balances its weight and the push.
    assert np.allclose(c["force"][0], (-PUSH, 0, WEIGHT), rtol=1e-3, atol=1e-3 * WEIGHT)
    # The support holds the base's weight and the block's, and the push.
    base_weight = 2600.0 * 2 * 2 * 0.2 * 9.81
    assert np.allclose(model.reaction(0)["force"], (-PUSH, 0.0, WEIGHT + base_weight), rtol=1e-3, atol=1e-3 * WEIGHT)
    assert model.unbalanced_force_ratio < 1e-5


def test_a_contact_resultant_acts_where_its_moment_says(model):
    """Pushed sideways at its centroid's height (0.1 m) by P, a block's base reaction moves
    towards the leading edge by e = P · 0.1 / W (moment balance about the base): the contact's
    application point, 0.2 + e along x. Its shear force is the push."""
    model.set_load(1, force=(PUSH, 0, 0))
    model.run_to_equilibrium(1e-6, 100_000)
    c = model.contacts()
    e = PUSH * 0.1 / WEIGHT
    assert c["application_point"][0] == pytest.approx([0.2 + e, 0.15, 0.0], abs=2e-4)
    assert c["shear_force"][0] == pytest.approx([-PUSH, 0, 0], rel=1e-3, abs=1e-3 * WEIGHT)
    # Without compression, no point.
    model.set_load(1, force=(0, 0, 3 * WEIGHT))
    model.run_steps(2000)
    assert np.isnan(model.contacts()["application_point"]).all() or model.contact_count == 0


def test_block_faces_and_rotations_from_initial():
    """A block's faces are its surface (outward by the right-hand rule: the polygon areas add
    up to the surface, and each normal points away from the centroid); a block turned by a
    known angle reports it since its initial pose."""
    b = vs.Block.cuboid("c", (0, 0, 0), (0.4, 0.3, 0.2), 2000.0)
    v, faces = b.vertices, b.faces
    assert len(faces) == 6 and sorted(len(f) for f in faces) == [4] * 6
    area = 0.0
    for f in faces:
        p = v[f]
        n = sum(np.cross(p[k], p[(k + 1) % len(p)]) for k in range(len(p))) / 2
        area += np.linalg.norm(n)
        assert np.dot(n, p.mean(axis=0) - b.centroid) > 0
    assert area == pytest.approx(2 * (0.4 * 0.3 + 0.4 * 0.2 + 0.3 * 0.2))
    m = vs.Model(gravity=(0, 0, 0))
    m.add_cuboid("c", (0, 0, 0), (0.4, 0.3, 0.2), 2000.0, angular_velocity=(0, 0, 1.0))
    m.run_until_time(0.3)
    assert m.rotations_from_initial()[0] == pytest.approx([0, 0, m.time], abs=1e-9)


def test_arrays(model):
    model.run_steps(20)
    n = len(model)
    assert n == model.block_count == 2
    for f, shape in [
        (model.positions, (2, 3)),
        (model.displacements, (2, 3)),
        (model.velocities, (2, 3)),
        (model.angular_velocities, (2, 3)),
        (model.rotations, (2, 4)),
        (model.rotation_matrices, (2, 3, 3)),
    ]:
        a = f()
        assert isinstance(a, np.ndarray) and a.dtype == np.float64 and a.shape == shape
    assert np.allclose(model.positions()[1], (0.2, 0.15, 0.1), atol=1e-4)
    q = model.rotations()
    assert np.allclose(np.linalg.norm(q, axis=1), 1.0)
    r = model.rotation_matrices()
    assert np.allclose(r @ np.swapaxes(r, 1, 2), np.eye(3), atol=1e-12)
    assert np.allclose(np.linalg.det(r), 1.0)
    # The matrices are the quaternions' (x, y, z, w).
    x, y, z, w = q[1]
    rq = np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )
    assert np.allclose(rq, r[1], atol=1e-12)
    sub = model.subcontacts()
    k = model.subcontact_count
    assert k == 15 * 15 and len(sub["status"]) == k
    assert sub["point"].shape == (k, 3) and sub["shear_force"].shape == (k, 3)
    assert set(sub["status"]) <= {"elastic", "sliding", "open"}
    assert np.all(sub["contact"] == 0)
    assert np.isclose(sub["area"].sum(), 0.4 * 0.3)
    assert np.isclose(sub["normal_force"].sum(), model.contacts()["normal_force"][0])
    e = model.energies()
    assert {"kinetic", "elastic", "gravity_work", "friction", "damping", "balance_error"} <= set(e)
    assert model.time > 0 and model.step_count == 20 and model.dt > 0
    assert model.critical_step is not None and model.dt <= model.critical_step


def test_blocks_and_generators():
    cube = vs.Block.from_vertices(
        "cube", [(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)], 1000.0
    )
    assert math.isclose(cube.mass, 1000.0) and math.isclose(cube.volume, 1.0)
    assert np.allclose(cube.centroid, (0.5, 0.5, 0.5))
    assert cube.vertices.shape == (8, 3)
    # A tetrahedron with explicit faces, from a numpy array.
    tet = vs.Block.from_vertices(
        "tet",
        np.array([(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1.0)]),
        2000.0,
        faces=[[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    )
    assert math.isclose(tet.volume, 1 / 6)
    fixed = cube.with_fixity("fixed").with_material(3)
    assert fixed.is_fixed and fixed.material == 3 and not cube.is_fixed
    plate = cube.with_fixity({"translation": ["free", -0.01, "free"], "rotation": ["fixed"] * 3})
    assert plate.fixity == {"translation": ["free", -0.01, "free"], "rotation": ["fixed"] * 3}

    arch = vs.build.arch()
    assert len(arch) == 15 and arch[0].is_fixed and arch[-1].is_fixed
    assert not any(b.is_fixed for b in arch[1:-1])
    assert len(vs.build.arch(voussoirs=7, width=0.2)) == 9
    wall = vs.build.running_bond_wall(bricks_per_course=4, courses=3)
    assert wall[0].is_fixed and len(wall) == 1 + 4 + 5 + 4
    assert len(vs.build.barrel_vault(rings=2, voussoirs=9)) > 18
    assert len(vs.build.dome(blocks=100)) > 50
    assert len(vs.build.multi_leaf_wall(length=1.0, height=0.4)) > 10
    w = vs.scenes.benchmark_wall(50)
    assert len(w) > 30 and isinstance(w.joint_law(0, 0), vs.CoulombSlip)


def test_rubble_wall():
    spec = dict(length=1.2, thickness=0.4, height=0.8, stone_size=0.2, through_stones=0.3, seed=7)
    wall = vs.build.rubble_wall(**spec)
    assert wall[0].is_fixed and not any(b.is_fixed for b in wall[1:])
    # The stones fill the wall's box exactly.
    volume = sum(b.volume for b in wall[1:])
    assert abs(volume - 1.2 * 0.4 * 0.8) < 1e-9
    assert any(b.name.startswith("through") for b in wall)
    # Seeded: the same wall again.
    again = vs.build.rubble_wall(**spec)
    assert [b.name for b in again] == [b.name for b in wall]
    assert [b.volume for b in again] == [b.volume for b in wall]
    # It stands under gravity.
    m = vs.Model(subcontacts_per_edge=4)
    m.set_joint_law(0, 0, vs.CoulombSlip(kn=1e10, ks=4e9, friction_deg=35.0))
    m.add_blocks(wall)
    m.run_to_equilibrium(1e-4, 50_000)
    assert np.abs(m.displacements()).max() < 1e-4
    with pytest.raises(vs.VoussoirError, match="jitter"):
        vs.build.rubble_wall(jitter=0.5)
    with pytest.raises(MemoryError, match="limit"):
        vs.build.rubble_wall(stone_size=1e-4)


def test_arch_stands_under_gravity():
    m = vs.Model(gravity=(0, -9.81, 0), subcontacts_per_edge=5)
    m.set_joint_law(0, 0, vs.CoulombSlip.dry(4e9, 1.6e9, 30.5))
    ids = m.add_blocks(vs.build.arch())
    assert ids == list(range(15))
    m.run_to_equilibrium(1e-5, 100_000)
    assert np.abs(m.displacements()).max() < 1e-3
    assert m.contact_count == 14


def test_laws():
    law = vs.CoulombSlip(4e9, 1.6e9, 35.0, residual_friction_deg=25.0, cohesion=1e5, tensile_strength=5e4)
    assert (law.kn, law.ks, law.friction_deg, law.residual_friction_deg) == (4e9, 1.6e9, 35.0, 25.0)
    assert (law.cohesion, law.tensile_strength) == (1e5, 5e4)
    assert vs.CoulombSlip.dry(1e9, 4e8, 30).residual_friction_deg == 30
    pad = vs.LinearElastic(2e8, 8e7)
    m = vs.Model()
    m.set_joint_law(0, 0, law)
    m.set_joint_law(1, 0, pad)
    assert m.joint_law(0, 0) == law and m.joint_law(0, 1) == pad and m.joint_law(1, 1) is None
    # Mixed laws in one model (AnyLaw): a stone cube (Coulomb), an elastic pad beside it.
    m.add_cuboid("base", (-1, -1, -0.2), (1, 1, 0), 2500.0, fixed=True)
    m.add_cuboid("cube", (0, 0, 0), (0.2, 0.2, 0.2), 2500.0)
    m.add_cuboid("pad", (0.5, 0, 0), (0.7, 0.2, 0.05), 1200.0, material=1)
    m.run_to_equilibrium(1e-4, 20_000)
    weight = (2500.0 * 0.008 + 1200.0 * 0.002) * 9.81
    assert abs(m.contacts()["normal_force"].sum() - weight) < 1e-3 * weight


def test_damping_and_parameters(model):
    assert model.damping == {"kind": "local", "alpha": 0.8}
    model.set_damping("none")
    assert model.damping == {"kind": "none"}
    model.set_damping("rayleigh", ratio=0.01, frequency=25.0)
    d = model.damping
    assert d["kind"] == "rayleigh" and d["mass"] > 0 and d["stiffness"] > 0
    model.set_damping("rayleigh_stiffness", ratio=0.01, frequency=25.0)
    assert model.damping["mass"] == 0
    model.gravity = (0, 0, -10.0)
    assert model.gravity.tolist() == [0, 0, -10.0]
    with pytest.raises(vs.VoussoirError, match="alpha"):
        model.set_damping("local", alpha=1.5)
    with pytest.raises(vs.VoussoirError, match="ratio= and frequency="):
        model.set_damping("rayleigh_mass")
    fixed = vs.Model(time_step=1e-6, mode="small", subcontact_spacing=0.05)
    fixed.set_joint_law(0, 0, vs.LinearElastic(1e9, 1e9))
    fixed.add_cuboid("a", (0, 0, 0), (1, 1, 1), 1000.0)
    fixed.step()
    assert fixed.dt == 1e-6


def test_fixity_velocity_load(model):
    model.set_fixity(1, {"translation": [0.02, "free", "free"], "rotation": ["fixed"] * 3})
    model.set_velocity(1, (0.0, 0.0, 0.0), (0, 0, 0))
    model.set_prescribed_velocity(1, (0.01, 0, 0))
    model.run_steps(100)
    assert math.isclose(model.velocities()[1, 0], 0.01)
    assert model.block(1).fixity == {"translation": [0.01, "free", "free"], "rotation": ["fixed"] * 3}
    model.set_fixity(1, "free")
    model.set_load(1, force=(0, 0, -1000.0), moment=None)
    assert model.block(1).fixity["translation"] == ["free"] * 3


def test_errors_are_python_exceptions():
    # ValueError subclass, the Rust message.
    with pytest.raises(vs.VoussoirError) as e:
        vs.CoulombSlip.dry(-1.0, 1e9, 30.0)
    assert isinstance(e.value, ValueError)
    assert str(e.value) == "invalid parameter `normal_stiffness` = -1: must be positive and finite"
    with pytest.raises(ValueError, match="friction"):
        vs.CoulombSlip.dry(1e9, 1e9, 95.0)
    m = vs.Model()
    with pytest.raises(vs.VoussoirError, match="the model has no blocks"):
        m.step()
    with pytest.raises(vs.VoussoirError, match=r"block #5 does not exist \(the model has 0 blocks\)"):
        m.set_load(5, force=(1, 0, 0))
    with pytest.raises(vs.VoussoirError, match="degenerate geometry"):
        m.add_polyhedron("flat", [(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0)], 1000.0)
    with pytest.raises(vs.VoussoirError, match="expected 3 numbers"):
        m.add_cuboid("a", (0, 0), (1, 1, 1), 1000.0)
    with pytest.raises(vs.VoussoirError, match="custom-law.md"):
        m.set_joint_law(0, 0, object())
    m.add_cuboid("a", (0, 0, 0), (1, 1, 1), 1000.0)
    m.add_cuboid("b", (0, 0, 0.5), (1, 1, 1.5), 1000.0)
    with pytest.raises(vs.VoussoirError, match="no joint law for materials|overlap"):
        m.step()
    m2 = block_on_base()
    with pytest.raises(vs.VoussoirError, match="not reached after 3 steps"):
        m2.run_to_equilibrium(1e-12, 3)
    with pytest.raises(vs.VoussoirError, match="end time"):
        m2.run_until_time(float("nan"))
    # I/O: an OSError subclass naming the file.
    with pytest.raises(vs.VoussoirIOError) as e:
        vs.Model.load_scene("/nonexistent/scene.json")
    assert isinstance(e.value, OSError) and "/nonexistent/scene.json" in str(e.value)


def test_progress_callback(model):
    calls = []
    assert model.run_steps(1000, callback=lambda step, t: calls.append((step, t)), every=250)
    assert [c[0] for c in calls] == [250, 500, 750, 1000]
    assert all(t > 0 for _, t in calls)
    # Returning False stops the run after that call.
    assert not model.run_steps(1000, callback=lambda step, t: step < 1500, every=100)
    assert model.step_count == 1500
    assert not model.run_until_time(10.0, callback=lambda step, t: False, every=10)
    assert model.step_count == 1510

    # Raising stops the run and propagates.
    class Stop(Exception):
        pass

    def boom(step, t):
        raise Stop(step)

    with pytest.raises(Stop):
        model.run_to_equilibrium(1e-30, 10_000, callback=boom, every=7)
    assert model.step_count == 1517
    # The equilibrium run reports its steps.
    fresh = block_on_base()
    seen = []
    n = fresh.run_to_equilibrium(1e-5, 100_000, callback=lambda s, t: seen.append(s), every=100)
    assert len(seen) == n // 100 and fresh.step_count == n


def test_monitors_and_history(model):
    model.add_monitor("uz", "displacement", block=1, point=(0.2, 0.15, 0.2), component="z")
    model.add_monitor("N", "contact_resultant", a=0, b=1, component="z")
    model.add_monitor("Ek", "energy", term="kinetic")
    model.add_monitor("ratio", "unbalanced_ratio")
    model.monitor_interval = 10
    model.run_steps(100)
    h = model.history()
    assert list(h) == ["step", "time", "uz", "N", "Ek", "ratio"]
    assert h["step"].tolist() == list(range(10, 101, 10))
    assert all(len(v) == 10 for v in h.values())
    assert h["uz"][-1] < 0  # it settles into its joint
    assert model.history_units() == {"uz": "m", "N": "N", "Ek": "J", "ratio": "-"}
    with pytest.raises(vs.VoussoirError, match="block #7 does not exist"):
        model.add_monitor("bad", "reaction", block=7)
    with pytest.raises(vs.VoussoirError, match="monitor kind"):
        model.add_monitor("bad", "temperature")
    model.clear_history()
    assert len(model.history()["time"]) == 0 and model.monitor_names() == ["uz", "N", "Ek", "ratio"]


def test_gil_released_during_run():
    """Another Python thread runs while the model steps."""
    m = vs.scenes.benchmark_wall(200)
    ticks = []
    done = threading.Event()

    def count():
        while not done.is_set():
            ticks.append(1)
            time.sleep(0.001)

    t = threading.Thread(target=count)
    t.start()
    start = time.perf_counter()
    m.run_steps(400)
    elapsed = time.perf_counter() - start
    done.set()
    t.join()
    # A thread blocked on the GIL would count (almost) nothing during the run.
    assert len(ticks) > 0.2 * elapsed / 0.001 or elapsed < 0.05, (len(ticks), elapsed)


def test_another_thread_reads_the_model_while_it_runs():
    """A second Python thread reading results during a run never finds the model borrowed
    (13 of 50 reads raised ``Already mutably borrowed`` before, and once the running thread's
    own call failed): it waits for the chunk of steps under way. Both ways round: the run in
    the main thread, then in a background thread."""
    def reader(m, done, reads, errors):
        while not done.is_set():
            try:
                t, steps = m.time, m.step_count
                d = m.displacements()
                c = m.contacts()
                assert d.shape == (m.block_count, 3) and t >= 0 and steps >= 0
                assert len(c["normal_force"]) == m.contact_count or m.step_count != steps
                reads.append(steps)
            except Exception as e:  # noqa: BLE001 - any failure is the test's
                errors.append(repr(e))
            time.sleep(0.002)

    # A run long enough for several chunks (a chunk is at most 0.1 s of steps) on any machine:
    # 2000 steps took 0.2 s on a fast one, too few chunks to see the run advance.
    probe = vs.scenes.benchmark_wall(300)
    start = time.perf_counter()
    probe.run_steps(200)
    per_step = (time.perf_counter() - start) / 200
    steps = max(2000, int(0.8 / per_step))

    m = vs.scenes.benchmark_wall(300)
    done, reads, errors = threading.Event(), [], []
    t = threading.Thread(target=reader, args=(m, done, reads, errors))
    t.start()
    try:
        assert m.run_steps(steps)
    finally:
        done.set()
        t.join()
    assert not errors, errors[:3]
    # Reads saw the run advance, not only its start or its end (a read waits for the chunk of
    # steps under way, at most 0.1 s).
    assert len(set(reads)) >= 3, sorted(set(reads))

    m = vs.scenes.benchmark_wall(300)
    result, failures = [], []

    def runner():
        try:
            result.append(m.run_steps(steps))
        except Exception as e:  # noqa: BLE001
            failures.append(repr(e))

    t = threading.Thread(target=runner)
    t.start()
    seen, errors = set(), []
    while t.is_alive():
        try:
            seen.add(m.step_count)
            m.positions()
        except Exception as e:  # noqa: BLE001
            errors.append(repr(e))
        time.sleep(0.002)
    t.join()
    assert result == [True] and not failures, failures
    assert not errors, errors[:3]
    assert len(seen) >= 3, sorted(seen)
    assert m.step_count == steps


def test_ctrl_c_stops_a_run_cleanly():
    # A process started in the background by a non-interactive shell (as CI may run pytest)
    # inherits SIGINT ignored, and Python then installs no handler for it: install Python's
    # own, as an interactive session has it, for the duration of the test.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    m = vs.scenes.benchmark_wall(200)
    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    start = time.perf_counter()
    try:
        with pytest.raises(KeyboardInterrupt):
            m.run_steps(10**9)
    finally:
        timer.join()
        signal.signal(signal.SIGINT, previous)
    assert time.perf_counter() - start < 5.0
    # Stopped between steps: the model is still usable.
    n = m.step_count
    assert n > 0
    m.run_steps(1)
    assert m.step_count == n + 1 and np.isfinite(m.positions()).all()


def test_ctrl_c_stops_a_long_first_step():
    # The first step of a large wall detects every contact (about a second at 60k blocks on
    # 2 cores): Ctrl-C is looked for between its detection batches, not only between steps.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    m = vs.scenes.benchmark_wall(60_000)
    sent = []

    def interrupt():
        sent.append(time.perf_counter())
        os.kill(os.getpid(), signal.SIGINT)

    timer = threading.Timer(0.2, interrupt)
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            m.step()
        stopped = time.perf_counter()
    finally:
        timer.join()
        signal.signal(signal.SIGINT, previous)
    assert sent and stopped - sent[0] < 0.5, f"Ctrl-C seen {stopped - sent[0]:.2f} s after it was sent"
    # The step did not happen; the next one runs.
    assert m.step_count == 0
    m.step()
    assert m.step_count == 1


_PUSH_OVER_INTERRUPTED = """
import os, signal, threading, time
import voussoir as vs
signal.signal(signal.SIGINT, signal.default_int_handler)
m = vs.Model()
m.set_joint_law(0, 0, vs.CoulombSlip.dry(1e9, 4e8, 30.0))
m.set_joint_law(0, 1, vs.CoulombSlip.dry(1e9, 4e8, 0.0))
m.add_cuboid("base", (-1, -1, -0.2), (1, 1, 0), 2500.0, fixed=True)
m.add_cuboid("cube", (0, 0, 0), (0.2, 0.2, 0.2), 2500.0)
pusher = m.add_cuboid(
    "pusher", (-0.1, 0.05, 0.05), (0.0, 0.15, 0.15), 2500.0, material=1,
    fixed={"translation": [0.0, "fixed", "fixed"], "rotation": ["fixed"] * 3},
)
m.run_steps(200)
sent = []
def interrupt():
    sent.append(time.perf_counter())
    os.kill(os.getpid(), signal.SIGINT)
threading.Timer(0.3, interrupt).start()
try:
    # A servo that never finds its balance (threshold 1e-300): it waited until max_steps.
    m.push_over(pusher, (1.0, 0.0, 0.0), 1e-6, max_unbalanced_ratio=1e-300, max_steps=50_000_000)
except KeyboardInterrupt:
    print("late", time.perf_counter() - sent[0])
    n = m.step_count
    m.run_steps(2)
    assert m.step_count == n + 2
    print("usable")
"""


def test_ctrl_c_stops_a_push_over_waiting_for_its_servo(tmp_path):
    """Ctrl-C reaches a servo that waits for a balance it never finds (it was ignored until
    ``max_steps``, minutes, then the result's first NumPy array panicked on the pending signal:
    ``PanicException: Failed to access NumPy array API capsule``). In a fresh process, where
    NumPy's API is first needed."""
    script = tmp_path / "push.py"
    script.write_text(_PUSH_OVER_INTERRUPTED)
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120)
    assert "PanicException" not in done.stderr, done.stderr
    assert done.returncode == 0, done.stderr
    lines = dict(line.split(" ", 1) if " " in line else (line, "") for line in done.stdout.split("\n") if line)
    assert "usable" in lines, done.stdout
    assert float(lines["late"]) < 1.0, done.stdout


@pytest.mark.parametrize("node_rule", ["point", "integrated"])
def test_sharp_block_keeps_its_energy(node_rule):
    """A tetrahedron dropped on its vertex, frictionless and undamped: its contacts are node
    contacts (vertices, edges and faces of both blocks pressed out of each other, a potential of
    the poses), and the mechanical energy stays within 2 % of m g h as it lands and tumbles,
    with the nodes' springs at their points or integrated over the surface they stand for."""
    m = vs.Model(node_rule=node_rule)
    m.set_joint_law(0, 0, vs.CoulombSlip.dry(1e9, 1e9, 0.0))
    m.set_damping("none")
    m.add_cuboid("slab", (-1.0, -1.0, -0.2), (1.0, 1.0, 0.0), 2500.0, fixed=True)
    s = 0.1
    turn = np.array([[0.8, -0.6, 0.0], [0.6, 0.8, 0.0], [0.0, 0.0, 1.0]]) @ np.array(
        [[1.0, 0.0, 0.0], [0.0, 0.9, -0.43589], [0.0, 0.43589, 0.9]]
    )
    tet = np.array([(s, s, s), (s, -s, -s), (-s, s, -s), (-s, -s, s)]) @ turn.T
    h = 0.05
    tet[:, 2] += h - tet[:, 2].min()
    b = m.add_polyhedron("tetrahedron", tet, 2500.0)
    mass = 2500.0 * (2 * s) ** 3 / 3.0
    mgh = mass * 9.81 * h
    worst = 0.0
    while m.time < 0.5:
        m.run_steps(200)
        e = m.energies()
        worst = max(worst, abs(e["kinetic"] + e["elastic"] - e["gravity_work"]) / mgh)
    sub = m.subcontacts()
    assert np.all(np.isfinite(sub["point"]))
    assert worst < 0.02, worst
    assert b == 1


def _cube_rocking_back_flat(node_rule, friction_deg):
    """A 0.2 m cube set rocking on the edge it shares with a fixed cube of its size, undamped:
    past 15° its loaded joint turns into a node contact, and it falls back flat (0.6 s). Returns
    whether a loaded node contact turned back into a face joint between two steps, and the
    largest |balance error| over the initial kinetic energy."""
    m = vs.Model(node_rule=node_rule)
    m.set_joint_law(0, 0, vs.CoulombSlip.dry(1e9, 1e9, friction_deg))
    m.set_damping("none")
    h, w = 0.1, 5.0
    m.add_cuboid("below", (-h, -h, -2 * h), (h, h, 0.0), 2600.0, fixed=True)
    m.add_cuboid("cube", (-h, -h, 0.0), (h, h, 2 * h), 2600.0, velocity=(0.0, w * h, w * h), angular_velocity=(-w, 0.0, 0.0))
    loaded_nodes, turned_back, worst = False, False, 0.0
    while m.time < 0.6:
        m.run_steps(1)
        c = m.contacts()
        kind = c["kind"][0] if c["kind"] else None
        turned_back |= loaded_nodes and kind == "face"
        loaded_nodes = kind == "nodes" and c["normal_force"][0] > 0.0
        worst = max(worst, abs(m.energies()["balance_error"]))
    return turned_back, worst / m.energies()["initial_kinetic"]


@pytest.mark.parametrize("friction_deg", [0.0, 30.0])
def test_integrated_node_contact_turns_back_into_a_joint(friction_deg):
    """With integrated nodes a loaded node contact whose faces come back parallel turns back into
    a face joint (``contacts()["kind"]``), its forces handed to the cells, and the books still
    close within 1 % (measured 0.26 %); point nodes keep a loaded node contact."""
    turned_back, error = _cube_rocking_back_flat("integrated", friction_deg)
    assert turned_back
    assert error < 0.01, error
    turned_back, _ = _cube_rocking_back_flat("point", friction_deg)
    assert not turned_back


def test_node_rule_is_a_model_parameter():
    """``node_rule`` reaches the model (its scene holds it) and a bad one is refused by name."""
    assert vs.Model.defaults()["node_rule"] == "point"
    assert vs.Model(node_rule="integrated").to_scene_json() != vs.Model().to_scene_json()
    assert '"node_rule":"integrated"' in vs.Model(node_rule="integrated").to_scene_json().replace(" ", "")
    with pytest.raises(vs.VoussoirError, match="node rule"):
        vs.Model(node_rule="points")


def test_hinge_tilt_is_exact_at_any_density():
    """A block whose joint opens under a moment (the resultant beyond the kern): its tilt is the
    rigid block's on a no-tension elastic joint, 2 W / (kn c² d) with c = 3 (b/2 − e) the closed
    length, already at 5 sub-contacts per edge (the joints' normal springs are integrated over
    their cells), and refining the joints does not move it."""

    def tilt(**density):
        m = block_on_base(**density)
        r0 = m.rotation_matrices()[1]
        m.set_load(1, moment=(0.0, WEIGHT * 0.12, 0.0))
        m.run_to_equilibrium(1e-7, 400_000)
        turned = m.rotation_matrices()[1] @ r0.T
        return abs(math.asin(turned[0, 2]))

    c = vs.check_density_convergence(tilt, subcontacts_per_edge=5)
    assert c["density"] == {"subcontacts_per_edge": 5}
    assert c["refined_density"] == {"subcontacts_per_edge": 9}
    expected = 2 * WEIGHT / (4e9 * (3 * (0.2 - 0.12)) ** 2 * 0.3)
    assert abs(c["value"] / expected - 1) < 0.01, (c, expected)
    assert c["relative_change"] < 0.005, c


def test_density_convergence_refuses_what_it_cannot_run():
    with pytest.raises(TypeError):
        vs.check_density_convergence(42)
    with pytest.raises(vs.VoussoirError):
        vs.check_density_convergence(lambda **d: 1.0, subcontacts_per_edge=0)
    with pytest.raises(ZeroDivisionError):
        vs.check_density_convergence(lambda **d: 1 / 0)


def test_callback_reads_and_drives_the_model():
    """The README's callback, verbatim, and more: inside the callback the model is free, to be
    read (time, step, ratios, positions, contacts, energies) and driven (a load, a prescribed
    velocity)."""
    m = block_on_base()
    seen = []

    def progress(step, t):
        assert step == m.step_count and t == m.time
        seen.append((m.unbalanced_force_ratio, m.displacements()[1, 2], len(m.contacts()["blocks"]), m.energies()["kinetic"]))
        if step == 200:
            m.set_load(1, force=(0.0, 0.0, -WEIGHT))
        # The README's test (False would stop the run), read here without stopping.
        return m.unbalanced_force_ratio > 1e-6 or True

    assert m.run_steps(1_000, callback=progress, every=100)
    assert len(seen) == 10 and all(np.isfinite(v).all() for v in map(np.array, seen))
    # The added load (its own weight again) doubled the joint's normal force.
    m.run_to_equilibrium(1e-6, 200_000)
    assert abs(m.contacts()["normal_force"][0] - 2 * WEIGHT) < 1e-3 * WEIGHT


def test_callback_false_values_stop_and_bad_callbacks_are_refused_before_the_first_step():
    m = block_on_base()
    assert not m.run_steps(1_000, callback=lambda step, t: np.False_, every=10)
    assert m.step_count == 10
    assert m.run_steps(30, callback=lambda step, t: None, every=10)
    assert m.step_count == 40
    for bad in (42, "progress", lambda: None, lambda a, b, c: None):
        with pytest.raises(TypeError):
            m.run_steps(100, callback=bad, every=10)
        with pytest.raises(TypeError):
            m.run_until_time(1.0, callback=bad)
    assert m.step_count == 40, "refused before the first step"
    # A callback with optional or variadic arguments is fine.
    assert m.run_steps(10, callback=lambda *args: True, every=5)


def test_arch_documents_its_intrados_and_density():
    """`build.arch` says that span and rise are the intrados' and shows its density default as a
    number in kg/m³ (24 kN/m³ over g), not an ellipsis."""
    import inspect

    doc = vs.build.arch.__doc__
    assert "intrados" in doc and "kg/m³" in doc
    density = inspect.signature(vs.build.arch).parameters["density"].default
    assert density == pytest.approx(24_000.0 / 9.81)
    blocks = vs.build.arch()
    assert len(blocks) == 15


def test_a_turned_slab_spins_up_as_its_inertia_tensor_says():
    """A 0.05 × 0.2 × 0.2 m slab (oblate) turned off the axes, spun from rest by a small moment
    with no gravity and no damping: ω = I⁻¹·M·t with I = R·diag(m/12·(b²+c², a²+c², a²+b²))·Rᵀ.
    parry's eigen solver gave this block the x axis as a principal axis (ω 1.9× too large about
    x in the probe)."""
    size = np.array([0.05, 0.2, 0.2])
    cz, sz = math.cos(math.radians(30)), math.sin(math.radians(30))
    cx, sx = math.cos(math.radians(20)), math.sin(math.radians(20))
    rotation = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]]) @ np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    corners = [rotation @ ((np.array([i & 1, i >> 1 & 1, i >> 2]) - 0.5) * size) for i in range(8)]
    m = vs.Model(gravity=(0, 0, 0))
    m.set_damping("none")
    m.set_joint_law(0, 0, vs.CoulombSlip.dry(1e9, 4e8, 30.0))
    slab = m.add_polyhedron("slab", corners, 2500.0)
    mass = 2500.0 * size.prod()
    a2, b2, c2 = size**2
    inertia = rotation @ np.diag([b2 + c2, a2 + c2, a2 + b2]) @ rotation.T * mass / 12
    moment = np.array([1e-4, 2e-5, -3e-5])
    m.set_load(slab, moment=tuple(moment))
    m.run_steps(4)
    expected = np.linalg.solve(inertia, moment * m.time)
    assert np.allclose(m.angular_velocities()[slab], expected, rtol=1e-6, atol=0)


def test_constructor_defaults_come_from_the_library_and_the_stub_agrees():
    """``Model``'s defaults are the library's ``ModelParameters::default()`` (written once, in
    Rust); the stub, which shows them to editors, says the same (issue 46)."""
    import ast
    import pathlib

    d = vs.Model.defaults()
    assert d["subcontacts_per_edge"] == 15 and d["contact_tolerance"] == 1e-3
    assert d["safety"] == 0.5 and d["max_speed"] == 1000.0 and d["impact_step"] == 0.1
    assert d["mode"] == "large" and tuple(d["gravity"]) == (0.0, 0.0, -9.81)
    stub = pathlib.Path(vs.__file__).with_name("_voussoir.pyi")
    tree = ast.parse(stub.read_text())
    model = next(n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == "Model")
    init = next(n for n in model.body if isinstance(n, ast.FunctionDef) and n.name == "__init__")
    stubbed = {
        a.arg: ast.literal_eval(v)
        for a, v in zip(init.args.kwonlyargs, init.args.kw_defaults)
        if v is not None and a.arg in d and a.arg != "gravity"
    }
    assert stubbed == {k: v for k, v in d.items() if k != "gravity"}, stubbed
    # A model built with the defaults is one built with them spelt out, and with other values
    # it is not (the scene holds the parameters).
    spelt = {k: v for k, v in d.items() if k != "mode"}
    assert vs.Model().to_scene_json() == vs.Model(**spelt).to_scene_json()
    assert vs.Model().to_scene_json() != vs.Model(contact_tolerance=2e-3).to_scene_json()


def test_joint_stepping_whole_or_cells(model):
    """A block resting on its base: its joint, closed and sticking, is stepped as a whole by
    default, and gives the forces of the cell-by-cell step to round-off (the sub-contacts read
    as they stand); bad names are refused.

    Pushed at a quarter of its friction limit. The joint-level step keeps a joint while the
    largest shear stress its cells hold stays within the friction strength at every corner of
    the face (docs/theory.md §3.1). Pushed at its centroid, the block's heel carries
    W/A (1 − 6 P h/(W L)), so the bound is below the limit: with h = 0.1 m over L = 0.4 m, and
    the shear uniform, it is 1/(1 + 1.5 μ) = 0.53 of it. At half the limit (PUSH) the cells'
    shear is 1.3 times its mean at the most loaded cell, and the joint is left to its cells."""
    assert model.joint_stepping == "whole"
    cells = block_on_base()
    cells.set_joint_stepping("cells")
    assert cells.joint_stepping == "cells"
    for m in (model, cells):
        m.set_load(1, force=(0.5 * PUSH, 0, 0))
        m.run_steps(3000)
    assert model.whole_joint_count() == 1 and cells.whole_joint_count() == 0
    a, b = model.contacts(), cells.contacts()
    assert np.allclose(a["force"], b["force"], rtol=1e-9, atol=1e-9 * WEIGHT)
    sa, sb = model.subcontacts(), cells.subcontacts()
    for key in ("normal_force", "shear_force"):
        assert np.allclose(sa[key], sb[key], rtol=1e-9, atol=1e-9 * WEIGHT), key
    with pytest.raises(vs.VoussoirError, match="joint stepping"):
        model.set_joint_stepping("joints")
