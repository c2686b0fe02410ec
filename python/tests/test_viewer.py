"""The HTML viewer (``voussoir.Viewer``): the page written, shown inline in Jupyter, and opened
in headless Chromium: its own checks of frame count and time range, no console errors, and
a screenshot whose pixels show the blocks.

Chromium is Debian's (``/usr/bin/chromium``); ``.ci/run`` installs it and sets
``VOUSSOIR_REQUIRE_CHROMIUM=1``, so that there the browser tests cannot be skipped.
"""

import html
import json
import os
import re
import shutil
import subprocess

import numpy as np
import pytest

import voussoir as vs

CHROMIUM = next((shutil.which(n) for n in ("chromium", "chromium-browser", "google-chrome") if shutil.which(n)), None)
needs_chromium = pytest.mark.skipif(
    CHROMIUM is None and os.environ.get("VOUSSOIR_REQUIRE_CHROMIUM") != "1",
    reason="no Chromium on this machine (.ci/run installs it)",
)


def toppling_block(viewer):
    """A tall block on a fixed base set turning about its +x bottom edge at 2 rad/s (its
    kinetic energy 3.5 times what lifting its centroid over that edge takes): it falls."""
    m = vs.Model()
    m.set_joint_law(0, 0, vs.CoulombSlip.dry(1e9, 4e8, 35.0))
    m.add_cuboid("base", (-1, -1, -0.2), (1, 1, 0), 2600.0, fixed=True)
    m.add_cuboid("pillar", (0, 0, 0), (0.1, 0.2, 0.5), 2600.0, velocity=(0.5, 0, 0.1), angular_velocity=(0, 2.0, 0))
    m.add_monitor("pillar top x", "displacement", block=1, point=(0.05, 0.1, 0.5), component="x")
    m.run_steps(20)
    for _ in range(12):
        viewer.record(m)
        m.run_until_time(m.time + 0.05)
    return m


def chromium(url, *extra, timeout=120):
    """Runs headless Chromium on ``url`` with the flags this machine's closed network needs;
    returns (stdout, stderr)."""
    flags = [
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-quic",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--hide-scrollbars",
        "--enable-logging=stderr",
        "--v=0",
    ]
    run = subprocess.run([CHROMIUM, *flags, *extra, url], capture_output=True, text=True, timeout=timeout)
    return run.stdout, run.stderr


def console_messages(stderr):
    """The page's console output (errors included), as Chromium logs it."""
    return [line for line in stderr.splitlines() if ":CONSOLE" in line]


def test_the_page_holds_every_frame_and_curve(tmp_path):
    v = vs.Viewer("a toppling pillar", time_from_first_frame=True)
    m = toppling_block(v)
    assert len(v) == 12 and repr(v) == "Viewer(12 frames)"
    # From the first frame, 0.05 s apart (``run_until_time`` ends on the step that reaches it).
    assert v.times[0] == 0.0
    assert all(0.05 <= b - a < 0.05 + 2 * m.dt for a, b in zip(v.times, v.times[1:])), v.times
    v.add_curve("line", [0.0, 1.0], [1.0, float("nan")], x_label="x", y_label="y", time_axis=False)
    path = v.write(tmp_path / "pages" / "pillar.html")
    page = path.read_text()
    data = json.loads(re.search(r'id="voussoir-data">(.*?)</script>', page, re.S).group(1))
    assert data["blocks"]["count"] == len(m) == 2
    assert [f["time"] for f in data["frames"]] == v.times
    names = [c["name"] for c in data["curves"]]
    assert names == ["largest displacement", "kinetic energy", "pillar top x", "line"]
    # The monitor's curve is the model's history at the frames' instants.
    top, history = data["curves"][2]["y"], m.history()
    for frame, value in zip(data["frames"], top):
        (at,) = np.nonzero(history["step"] == frame["step"])[0]
        assert value == history["pillar top x"][at]
    assert top[-1] > 0.05, "the pillar's top moved along +x as it fell"
    # Inline in Jupyter: the page inside an iframe, escaped.
    inline = v._repr_html_()
    assert inline.startswith("<iframe srcdoc=\"<!DOCTYPE html>")
    assert html.unescape(inline.split('srcdoc="', 1)[1].split('" style=', 1)[0]) == page
    # Errors are typed, before anything is written.
    with pytest.raises(vs.VoussoirError, match="taken"):
        v.add_curve("kinetic energy", [0.0], [1.0])
    with pytest.raises(vs.VoussoirError, match="before|frame"):
        vs.Viewer().write(tmp_path / "empty.html")
    assert not (tmp_path / "empty.html").exists()
    other = vs.Model()
    other.add_cuboid("one", (0, 0, 0), (1, 1, 1), 2000.0)
    with pytest.raises(vs.VoussoirError, match="1 blocks after frames of 2"):
        v.record(other)


@needs_chromium
def test_chromium_plays_the_page_without_errors(tmp_path):
    v = vs.Viewer("a toppling pillar")
    toppling_block(v)
    path = v.write(tmp_path / "pillar.html")
    # The page's own checks, after its first drawing, at the last frame with joints and forces.
    out, err = chromium(path.as_uri() + "#frame=last&joints=1&forces=1", "--dump-dom", f"--user-data-dir={tmp_path / 'profile1'}")
    found = re.search(r'<pre id="voussoir-checks" hidden="">(.*?)</pre>', out, re.S)
    assert found, out[-2000:]
    checks = json.loads(html.unescape(found.group(1)))
    assert checks["errors"] == []
    assert checks["frames"] == len(v) == 12
    assert checks["frame_shown"] == 11
    assert checks["time_start"] == v.times[0] and checks["time_end"] == v.times[-1]
    assert checks["blocks"] == 2
    # Of the 12 faces, those facing the camera are drawn (3 of a box in general position).
    assert 3 <= checks["faces_drawn"] <= 8, checks
    assert checks["contacts_drawn"] >= 1 and checks["forces_drawn"] >= 1, checks
    assert console_messages(err) == [], console_messages(err)


@needs_chromium
def test_chromium_screenshot_shows_the_blocks(tmp_path):
    v = vs.Viewer("a toppling pillar")
    toppling_block(v)
    path = v.write(tmp_path / "pillar.html")
    plt = pytest.importorskip("matplotlib.pyplot")
    shots = {}
    for k, frame in enumerate(["0", "last"]):
        png = tmp_path / f"frame_{frame}.png"
        _, err = chromium(
            path.as_uri() + f"#frame={frame}&field=displacement",
            f"--screenshot={png}",
            "--window-size=1000,640",
            f"--user-data-dir={tmp_path / f'profile{k}'}",
        )
        assert png.exists(), err[-2000:]
        assert console_messages(err) == [], console_messages(err)
        shots[frame] = plt.imread(png)[..., :3]
    for frame, rgb in shots.items():
        # The 3-D view: left of the 300 px curve panel, between the top and bottom bars. Its
        # background is #f4f5f7; the blocks cover a good share of it.
        view = rgb[60:580, 20:680]
        background = np.array([0xF4, 0xF5, 0xF7]) / 255.0
        covered = np.mean(np.any(np.abs(view - background) > 0.04, axis=-1))
        assert 0.05 < covered < 0.95, (frame, covered)
        # The fixed base is grey; at the last frame the moving pillar is coloured by its
        # displacement (the colour map's bright end: a strongly green or yellow pixel).
        grey = np.all(np.abs(view - view.mean(axis=-1, keepdims=True)) < 0.02, axis=-1) & (view.mean(axis=-1) < 0.75)
        assert np.mean(grey) > 0.01, (frame, np.mean(grey))
    last = shots["last"][60:580, 20:680]
    bright = (last[..., 1] > 0.6) & (last[..., 2] < 0.5)
    assert bright.sum() > 50, bright.sum()
    # The pillar fell between the two frames: the pictures differ.
    assert np.mean(np.any(np.abs(shots["0"] - shots["last"]) > 0.1, axis=-1)) > 0.005


@needs_chromium
@pytest.mark.parametrize("case", ["no blocks", "one block, no contacts recorded", "<!--<script> in the names"])
def test_chromium_opens_edge_cases_without_errors(tmp_path, case):
    m = vs.Model()
    v = vs.Viewer(case, contacts=case == "no blocks")
    if case != "no blocks":
        m.add_cuboid("block", (0, 0, 0), (1, 1, 1), 2000.0)
    if "script" in case:
        # Probe 3, F8: markup in a title or curve name broke the page (the data swallowed the
        # renderer); every "<" in the data is written as an escape.
        v.add_curve("<!--<script>", [0.0, 1.0], [1.0, 2.0], time_axis=False)
    v.record(m)
    v.record(m)
    path = v.write(tmp_path / "edge.html")
    out, err = chromium(path.as_uri() + "#joints=1&forces=1&frame=last", "--dump-dom", f"--user-data-dir={tmp_path / 'profile'}")
    found = re.search(r'<pre id="voussoir-checks" hidden="">(.*?)</pre>', out, re.S)
    assert found, out[-2000:]
    checks = json.loads(html.unescape(found.group(1)))
    assert checks["errors"] == [] and console_messages(err) == []
    assert checks["frames"] == 2 and checks["blocks"] == len(m)
    # A box seen from above and aside shows three faces; nothing is drawn without blocks.
    assert checks["faces_drawn"] == (0 if case == "no blocks" else 3)


def test_a_viewer_refuses_another_models_frames():
    """One viewer shows one model (its docstring): a model of as many blocks but other shapes
    is refused (probe 3, F8: it was taken)."""
    v = vs.Viewer("one model")
    a = vs.Model()
    a.add_cuboid("cube", (0, 0, 0), (1, 1, 1), 2000.0)
    v.record(a)
    b = vs.Model()
    b.add_cuboid("brick", (0, 0, 0), (0.2, 0.1, 0.05), 2000.0)
    with pytest.raises(vs.VoussoirError, match="another shape"):
        v.record(b)
    v.record(a)
