"""Pictures without ParaView (``voussoir.draw``, matplotlib)."""

import numpy as np
import pytest

import voussoir as vs

plt = pytest.importorskip("matplotlib.pyplot")


def settled_arch():
    m = vs.Model(gravity=(0, -9.81, 0))
    m.set_joint_law(0, 0, vs.CoulombSlip.dry(4e9, 1.6e9, 35.0))
    m.add_blocks(vs.build.arch())
    m.run_steps(200)
    return m


@pytest.mark.parametrize("view", ["3d", "xy"])
def test_an_arch_is_drawn_to_a_png(tmp_path, view):
    m = settled_arch()
    path = vs.draw.save(m, tmp_path / "frames" / f"arch_{view}.png", view=view, contacts=True, displacement_scale=100.0)
    assert path.exists() and not (tmp_path / "frames" / f"arch_{view}.png.partial").exists()
    image = plt.imread(path)
    # Something was drawn: not a blank page (a sizeable share of pixels is neither white nor
    # transparent).
    rgb = image[..., :3]
    drawn = np.mean(np.any(rgb < 0.9, axis=-1))
    assert drawn > 0.02, drawn


def test_draw_returns_axes_holding_every_face():
    m = settled_arch()
    ax = vs.draw.draw(m, view="xy", colorbar=False)
    faces = sum(len(m.block(i).faces) for i in range(len(m)))
    (polys,) = [c for c in ax.collections if len(c.get_paths()) == faces]
    assert len(polys.get_paths()) == faces
    plt.close(ax.figure)
    with pytest.raises(ValueError, match="view"):
        vs.draw.draw(m, view="side")
