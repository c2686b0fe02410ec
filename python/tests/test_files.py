"""ParaView, CSV, scenes and checkpoints."""

import json
import pathlib
import xml.etree.ElementTree as ET

import numpy as np
import pytest

import voussoir as vs
from conftest import PUSH, block_on_base

REPO = pathlib.Path(__file__).resolve().parents[2]


def test_paraview(tmp_path, model):
    model.run_steps(10)
    model.write_vtk_blocks(tmp_path / "blocks.vtu")
    model.write_vtk_subcontacts(tmp_path / "sub.vtu")
    for f in ("blocks.vtu", "sub.vtu"):
        assert ET.parse(tmp_path / f).getroot().tag == "VTKFile"
    series = vs.ParaviewSeries(tmp_path / "series", "demo")
    for _ in range(3):
        model.run_steps(5)
        series.write_frame(model)
    assert len(series) == 3
    pvd = pathlib.Path(series.blocks_pvd)
    assert pvd.exists() and len(ET.parse(pvd).getroot().findall(".//DataSet")) == 3
    # Sub-contacts on every second frame: frames 0, 2 and 4 of five.
    sparse = vs.ParaviewSeries(tmp_path / "sparse", "demo", subcontacts_every=2)
    for _ in range(5):
        model.run_steps(1)
        sparse.write_frame(model)
    contacts = tmp_path / "sparse" / "demo_contacts.pvd"
    files = [d.get("file") for d in ET.parse(contacts).getroot().findall(".//DataSet")]
    assert files == [f"demo_contacts_{k:05}.vtu" for k in (0, 2, 4)]
    assert not (tmp_path / "sparse" / "demo_contacts_00001.vtu").exists()
    assert len(ET.parse(sparse.blocks_pvd).getroot().findall(".//DataSet")) == 5
    with pytest.raises(ValueError, match="at least 1"):
        vs.ParaviewSeries(tmp_path / "x", "demo", subcontacts_every=0)
    # Times from the first frame: 0 and the time between the frames.
    relative = vs.ParaviewSeries(tmp_path / "rel", "demo", time_from_first_frame=True)
    t0 = model.time
    relative.write_frame(model)
    model.run_steps(10)
    relative.write_frame(model)
    times = [float(d.get("timestep")) for d in ET.parse(relative.blocks_pvd).getroot().findall(".//DataSet")]
    assert times == [0.0, pytest.approx(model.time - t0, rel=1e-12)] and t0 > 0


def test_paraview_files_read_by_meshio(tmp_path, model):
    """The blocks and sub-contacts a series writes, and both kinds of block file, read back by
    meshio (the usual Python mesh reader) with the model's numbers."""
    meshio = pytest.importorskip("meshio")
    model.run_steps(50)
    series = vs.ParaviewSeries(tmp_path, "demo")
    series.write_frame(model)
    blocks = meshio.read(tmp_path / "demo_blocks_00000.vtu")
    faces = sum(len(b) for b in blocks.cells)
    ids = np.concatenate(blocks.cell_data["block_id"])
    assert sorted(set(ids.tolist())) == list(range(model.block_count))
    # Six quadrilateral faces a cuboid, each face carrying its block's displacement.
    assert faces == 6 * model.block_count
    displacement = np.concatenate(blocks.cell_data["displacement"])
    for i in range(model.block_count):
        want = model.displacements()[i]
        assert np.allclose(displacement[ids == i], want, rtol=0, atol=1e-15)
    subs = meshio.read(tmp_path / "demo_contacts_00000.vtu")
    assert len(subs.points) == model.subcontact_count
    assert subs.point_data["area"].sum() == pytest.approx(model.subcontacts()["area"].sum(), rel=1e-12)
    model.write_vtk_blocks(tmp_path / "surfaces.vtu")
    assert sum(len(b) for b in meshio.read(tmp_path / "surfaces.vtu").cells) == faces
    # Polyhedra: ParaView's; meshio reads cuboids (all of one vertex count) as such.
    model.write_vtk_blocks(tmp_path / "poly.vtu", cells="polyhedra")
    poly = meshio.read(tmp_path / "poly.vtu")
    assert sum(len(b) for b in poly.cells) == model.block_count
    with pytest.raises(ValueError, match="surfaces"):
        model.write_vtk_blocks(tmp_path / "x.vtu", cells="solids")


def test_history_csv(tmp_path, model):
    model.add_monitor("ux", "displacement", block=1, point=(0.2, 0.15, 0.1), component="x")
    model.add_monitor("Ek", "energy", term="kinetic")
    model.run_steps(3)
    model.write_history_csv(tmp_path / "out" / "h.csv")
    lines = (tmp_path / "out" / "h.csv").read_text().splitlines()
    assert lines[0] == "time [s],step,ux [m],Ek [J]"
    assert len(lines) == 4
    assert [float(x) for x in lines[-1].split(",")][:2] == pytest.approx([model.time, 3])


def test_scene_round_trip(tmp_path, model):
    model.set_load(1, force=(PUSH, 0, 0))
    model.add_monitor("ux", "displacement", block=1, point=(0.2, 0.15, 0.1), component="x")
    model.monitor_interval = 5
    path = tmp_path / "scene.json"
    model.save_scene(path)
    doc = json.loads(path.read_text())
    # Coulomb laws only: written as a Rust Scene<CoulombSlip> reads them.
    assert "friction_deg" in doc["joints"][0]["law"]
    loaded = vs.Model.load_scene(path)
    assert loaded.monitor_names() == ["ux"] and loaded.monitor_interval == 5
    assert np.array_equal(loaded.positions(), model.positions())
    model.run_steps(50)
    loaded.run_steps(50)
    assert np.array_equal(loaded.positions(), model.positions())
    assert np.array_equal(loaded.history()["ux"], model.history()["ux"])
    # Mixed laws: written with their kind.
    model.set_joint_law(0, 1, vs.LinearElastic(1e8, 1e8))
    doc = json.loads(model.to_scene_json())
    assert {next(iter(j["law"])) for j in doc["joints"]} == {"Coulomb", "Elastic"}
    assert vs.Model.from_scene_json(model.to_scene_json()).joint_law(1, 0) == vs.LinearElastic(1e8, 1e8)


def test_repository_scene_example():
    m = vs.Model.load_scene(REPO / "docs" / "examples" / "block-on-base.json")
    assert len(m) >= 2
    m.run_steps(10)


def test_bad_scene():
    with pytest.raises(vs.VoussoirError, match="density"):
        vs.Model.from_scene_json(
            '{"joints": [], "blocks": [{"name": "a", "vertices": [[0,0,0],[1,0,0],[0,1,0],[0,0,1]], "density": "heavy"}]}'
        )
    with pytest.raises(vs.VoussoirError):
        vs.Model.from_scene_json("{not json")


def test_checkpoint_bit_identical(tmp_path):
    m = block_on_base()
    m.set_load(1, force=(PUSH, 0, 0))
    m.run_steps(50)
    m.save_checkpoint(tmp_path / "c.json")
    restarted = vs.Model.load_checkpoint(tmp_path / "c.json")
    assert restarted.step_count == 50 and restarted.time == m.time
    m.run_steps(50)
    restarted.run_steps(50)
    assert np.array_equal(m.positions(), restarted.positions())
    assert np.array_equal(m.velocities(), restarted.velocities())
    assert np.array_equal(m.subcontacts()["normal_force"], restarted.subcontacts()["normal_force"])
    again = vs.Model.from_checkpoint_string(m.to_checkpoint_string())
    assert np.array_equal(again.rotations(), m.rotations())
    with pytest.raises(vs.VoussoirError, match="checkpoint"):
        vs.Model.from_checkpoint_string('{"format": 3')
    with pytest.raises(vs.VoussoirIOError):
        m.save_checkpoint(tmp_path / "missing-dir" / "x" / "c.json" / "\0")
