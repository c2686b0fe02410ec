"""Issue 33, hostile input round 2: atomic scenes, all-or-nothing block lists, monitor names,
index arguments, sizes that would abort, endless inputs, series written twice."""

import itertools
import json
import os
import pathlib
import subprocess
import sys
import threading
import time

import pytest

import voussoir as vs
from conftest import block_on_base


def test_save_scene_is_atomic_under_a_file_size_limit(tmp_path):
    """A save that fails half-way (a file-size limit, as a full disk) leaves the previous scene
    whole; it used to leave a fragment that no longer loaded."""
    path = tmp_path / "scene.json"
    block_on_base().save_scene(path)
    before = path.read_bytes()
    script = f"""
import resource, signal, sys
sys.path = {sys.path!r}
import voussoir as vs
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
m = vs.Model()
m.set_joint_law(0, 0, vs.CoulombSlip.dry(4e9, 1.6e9, 30.5))
m.add_blocks(vs.build.running_bond_wall(bricks_per_course=20, courses=20))
resource.setrlimit(resource.RLIMIT_FSIZE, (4096, 4096))
try:
    m.save_scene({str(path)!r})
except OSError as e:
    print("refused:", e)
"""
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert "refused:" in out.stdout, out.stdout + out.stderr
    assert path.read_bytes() == before
    vs.Model.load_scene(path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scene.json"], "no temporary file left"


def test_add_blocks_is_all_or_nothing():
    m = vs.Model(subcontact_spacing=0.01)
    ok = vs.Block.cuboid("ok", (0, 0, 0), (0.2, 0.2, 0.2), 2000.0)
    too_big = vs.Block.cuboid("too big", (0, 0, 0), (100, 1, 1), 2000.0)
    with pytest.raises(vs.VoussoirError, match=r"blocks\[1\].*too big.*no block was added"):
        m.add_blocks([ok, too_big])
    assert m.block_count == 0
    assert m.add_blocks([ok, ok]) == [0, 1]


def test_monitor_names_are_unique_and_not_time_or_step(model):
    for name in ("time", "step"):
        with pytest.raises(vs.VoussoirError, match="history's own"):
            model.add_monitor(name, "energy", term="kinetic")
    model.add_monitor("Ek", "energy", term="kinetic")
    with pytest.raises(vs.VoussoirError, match="exists already"):
        model.add_monitor("Ek", "unbalanced_ratio")
    model.run_steps(2)
    assert list(model.history()) == ["step", "time", "Ek"]
    assert list(model.history()["step"]) == [1, 2]


def test_index_arguments_say_which_and_why(model):
    """Out-of-range indices raise VoussoirError (a ValueError) naming the argument and the
    value; they used to raise PyO3's OverflowError naming neither."""
    for bad, why in ((-1, "negative"), (2, "does not exist"), (10**30, "out of range"), (-(10**30), "out of range")):
        with pytest.raises(vs.VoussoirError, match=f"block index {bad}.*{why}"):
            model.block(bad)
        with pytest.raises(vs.VoussoirError, match=f"block index {bad}"):
            model.set_velocity(bad, (0, 0, 0))
    with pytest.raises(vs.VoussoirError, match="block index a -1 is negative"):
        model.add_monitor("r", "contact_resultant", a=-1, b=1)
    with pytest.raises(ValueError, match="material a = -1"):
        model.set_joint_law(-1, 0, vs.LinearElastic(1e8, 1e8))
    with pytest.raises(ValueError, match="material b = 70000"):
        model.joint_law(0, 70000)
    with pytest.raises(TypeError):
        model.block(1.5)
    assert model.block(1).name == "block"


def test_sizes_beyond_memory_are_memory_errors():
    with pytest.raises(MemoryError, match="limit"):
        vs.scenes.benchmark_wall(10**9)
    with pytest.raises(MemoryError, match="limit"):
        vs.build.running_bond_wall(courses=10**6, bricks_per_course=10**6)
    with pytest.raises(MemoryError, match="voussoirs"):
        vs.build.arch(voussoirs=10**9)


def test_endless_iterables_are_refused():
    m = vs.Model()
    with pytest.raises(vs.VoussoirError, match="got more"):
        m.gravity = itertools.count()
    start = time.monotonic()
    with pytest.raises(MemoryError, match="endless"):
        m.add_polyhedron("endless", itertools.repeat((0.0, 0.0, 0.0)), 2000.0)
    assert time.monotonic() - start < 30


def test_load_checkpoint_of_an_endless_file_is_refused_at_once():
    start = time.monotonic()
    with pytest.raises(vs.VoussoirIOError, match="a device: only a regular file is read"):
        vs.Model.load_checkpoint("/dev/zero")
    assert time.monotonic() - start < 1


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="named pipes are POSIX")
def test_named_pipes_are_refused_on_load(tmp_path):
    """A scene, checkpoint or CSV given as a named pipe is refused at once, naming it (the load
    blocked for ever, holding the GIL, deaf to Ctrl-C). Should it block again, a writer opened
    after 5 s unblocks it, and the test fails on its time."""
    fifo = tmp_path / "pipe.json"
    os.mkfifo(fifo)

    def unblock():
        try:
            os.close(os.open(fifo, os.O_WRONLY | os.O_NONBLOCK))
        except OSError:
            pass

    for load in (vs.Model.load_scene, vs.Model.load_checkpoint, vs.TimeHistory.from_csv):
        timer = threading.Timer(5.0, unblock)
        timer.start()
        start = time.monotonic()
        try:
            with pytest.raises(vs.VoussoirIOError, match="a named pipe: only a regular file is read") as e:
                load(fifo)
        finally:
            timer.cancel()
        assert time.monotonic() - start < 1, load
        assert str(fifo) in str(e.value)


def test_two_series_of_one_name_in_one_folder(tmp_path, model):
    model.run_steps(2)
    first = vs.ParaviewSeries(tmp_path, "demo")
    first.write_frame(model)
    second = vs.ParaviewSeries(tmp_path, "demo")
    with pytest.raises(vs.VoussoirIOError, match="another series"):
        second.write_frame(model)
    del first
    second.write_frame(model)


def test_two_processes_writing_one_series_folder(tmp_path):
    """A series held by another running process is refused (the lock file names its process);
    once that process has ended, its lock is taken over."""
    script = f"""
import sys, time
sys.path = {sys.path!r}
sys.path.insert(0, {str(pathlib.Path(__file__).parent)!r})
import voussoir as vs
from conftest import block_on_base
m = block_on_base()
m.run_steps(1)
s = vs.ParaviewSeries({str(tmp_path)!r}, "shared")
s.write_frame(m)
print("holding", flush=True)
time.sleep(30)
"""
    other = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True)
    try:
        assert other.stdout.readline().strip() == "holding"
        m = block_on_base()
        m.run_steps(1)
        mine = vs.ParaviewSeries(tmp_path, "shared")
        with pytest.raises(vs.VoussoirIOError, match=f"process {other.pid}"):
            mine.write_frame(m)
    finally:
        other.kill()
        other.wait()
    # The other process was killed holding its lock: the lock is stale and taken over.
    mine.write_frame(m)
    assert len(mine) == 1


def test_a_block_added_into_another_after_the_first_step_is_refused():
    """Probe 3, F5: a cube added 5 mm into the slab after the first step was launched; it is
    refused as the same layout is at the start, and the model is left as it was."""
    m = vs.Model()
    m.set_joint_law(0, 0, vs.CoulombSlip.dry(1e9, 4e8, 30.0))
    m.add_cuboid("slab", (-1, -1, -0.2), (1, 1, 0), 2500.0, fixed=True)
    m.add_cuboid("cube", (-0.1, -0.1, 0), (0.1, 0.1, 0.2), 2500.0)
    m.run_steps(20)
    with pytest.raises(vs.VoussoirError, match="overlaps block #0 by 5.000e-3 m"):
        m.add_cuboid("late", (0.3, -0.1, -0.005), (0.5, 0.1, 0.195), 2500.0)
    assert m.block_count == 2
    m.run_steps(5)
    assert m.velocities()[1, 2] > -1e-2


def test_round3_arguments_and_files_say_what_is_wrong(tmp_path):
    """Probe 3, F14: a negative material names the argument (PyO3's OverflowError named
    nothing), ``add_blocks`` takes any iterable as its stub says (a generator raised TypeError),
    ``draw.save`` of an empty model says so (numpy's message), a scene key given twice and
    ``monitor_interval: 0`` are refused on load (they loaded the last value, and as 1)."""
    m = vs.Model()
    with pytest.raises(ValueError, match="material = -1"):
        m.add_cuboid("a", (0, 0, 0), (1, 1, 1), 2000.0, material=-1)
    with pytest.raises(ValueError, match="material = 70000"):
        vs.Block.cuboid("a", (0, 0, 0), (1, 1, 1), 2000.0, material=70000)
    with pytest.raises(ValueError, match="voussoir_material = -2"):
        vs.build.arch(voussoir_material=-2)
    with pytest.raises(ValueError, match="n = -1"):
        m.run_steps(-1)
    with pytest.raises(ValueError, match="max_steps = -5"):
        m.run_to_equilibrium(1e-5, -5)

    blocks = vs.build.arch()
    indices = m.add_blocks(b for b in blocks)
    assert indices == list(range(len(blocks)))
    with pytest.raises(TypeError, match=r"blocks\[1\]: expected a Block, got str; no block was added"):
        vs.Model().add_blocks(iter([blocks[0], "stone"]))
    with pytest.raises(TypeError, match="expected an iterable of Block, got int"):
        m.add_blocks(3)

    pytest.importorskip("matplotlib")
    with pytest.raises(vs.VoussoirError, match="no blocks"):
        vs.draw.save(vs.Model(), tmp_path / "empty.png")
    assert not list(tmp_path.iterdir())

    scene = block_on_base()
    path = tmp_path / "scene.json"
    scene.save_scene(path)
    text = path.read_text()
    assert '"density":' in text
    with pytest.raises(vs.VoussoirError, match=r"blocks\[0\]\.density.*duplicate key `density`"):
        vs.Model.from_scene_json(text.replace('"density":', '"density": 1.0, "density":', 1))
    checkpoint = scene.to_checkpoint_string()
    with pytest.raises(vs.VoussoirError, match="duplicate key `step`"):
        vs.Model.from_checkpoint_string(checkpoint.replace('"step":', '"step": 0, "step":', 1))
    doc = json.loads(text)
    doc["monitor_interval"] = 0
    with pytest.raises(vs.VoussoirError, match="monitor_interval.*at least 1"):
        vs.Model.from_scene_json(json.dumps(doc))


def test_equilibrium_without_a_support_says_why():
    """Probe 3, F12: a model with nothing fixed falls, and ``run_to_equilibrium`` says that no
    contact carries a force (it said only "last value inf")."""
    m = vs.Model()
    m.set_joint_law(0, 0, vs.CoulombSlip.dry(1e9, 4e8, 30.0))
    m.add_cuboid("stone", (0, 0, 0), (0.2, 0.2, 0.2), 2500.0)
    with pytest.raises(vs.VoussoirError, match="no contact carries a force.*fixed"):
        m.run_to_equilibrium(1e-5, 200)
