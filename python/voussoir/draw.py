"""Pictures of a model without ParaView: its blocks (and contact polygons) drawn with matplotlib.

``draw(model)`` draws into a matplotlib axes (3-D, or projected on a plane) and returns it;
``save(model, "frame.png")`` writes a picture (PNG, SVG, PDF: matplotlib's formats, by the
file's extension). Blocks are coloured by how far they have moved (or one colour), fixed blocks
grey; displacements may be magnified for the picture (``displacement_scale``: the blocks'
translations only, rotations as they are). For a run, call ``save`` from a callback::

    m.run_until_time(1.0, callback=lambda step, t: vs.draw.save(m, f"out/frame_{step:07d}.png"), every=2000)

matplotlib is needed (``pip install matplotlib``); the rest of voussoir does not need it.
"""

from typing import Optional, Sequence

import numpy as np

from ._voussoir import VoussoirError

__all__ = ["draw", "save"]

_PLANES = {"xy": (0, 1), "xz": (0, 2), "yz": (1, 2)}


def _faces(model, displacement_scale):
    """Every face polygon (world, m), the block of each, and each block's displacement (m)."""
    moved = np.linalg.norm(model.displacements(), axis=1)
    shift = (displacement_scale - 1.0) * model.displacements()
    polygons, owners = [], []
    for i in range(len(model)):
        block = model.block(i)
        v = block.vertices + shift[i]
        for f in block.faces:
            polygons.append(v[f])
            owners.append(i)
    return polygons, np.asarray(owners), moved


def draw(
    model,
    ax=None,
    *,
    view: str = "3d",
    displacement_scale: float = 1.0,
    color: Optional[str] = None,
    cmap: str = "viridis",
    edgecolor: str = "#333333",
    linewidth: float = 0.3,
    contacts: bool = False,
    colorbar: bool = True,
    elevation: float = 20.0,
    azimuth: float = -60.0,
):
    """Draws ``model``'s blocks into ``ax`` (a new figure when None) and returns the axes
    (``VoussoirError`` for a model without blocks).

    ``view``: ``"3d"`` (a perspective of the faces, the axis against gravity up, seen from
    ``elevation`` and ``azimuth`` in degrees) or ``"xy"``, ``"xz"``, ``"yz"`` (the faces
    projected on that plane: an arch built in the x–y plane reads best in ``"xy"``). Blocks
    are coloured by their displacement with ``cmap`` (a colour bar in mm when ``colorbar``),
    or all ``color``; fixed blocks are grey. ``contacts=True`` outlines the contact polygons
    in red.
    """
    import matplotlib.pyplot as plt
    from matplotlib import cm, colors

    if len(model) == 0:
        raise VoussoirError("draw: the model has no blocks, nothing to draw; add blocks first")
    if view != "3d" and view not in _PLANES:
        raise ValueError(f"view {view!r}: expected '3d', 'xy', 'xz' or 'yz'")
    if not np.isfinite(displacement_scale):
        raise ValueError(f"displacement_scale = {displacement_scale}: must be finite")
    polygons, owners, moved = _faces(model, displacement_scale)
    fixed = np.array([model.block(i).is_fixed for i in range(len(model))], dtype=bool)
    top = float(moved[~fixed].max()) if np.any(~fixed) else 0.0
    norm = colors.Normalize(vmin=0.0, vmax=top * 1e3 if top > 0 else 1.0)
    mapper = cm.ScalarMappable(norm=norm, cmap=cmap)
    faces_colour = [
        "#b0b0b0" if fixed[i] else (color if color is not None else mapper.to_rgba(moved[i] * 1e3)) for i in owners
    ]
    if ax is None:
        fig = plt.figure(figsize=(7, 5))
        ax = fig.add_subplot(projection="3d") if view == "3d" else fig.add_subplot()
    if view == "3d":
        from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

        ax.add_collection3d(Poly3DCollection(polygons, facecolors=faces_colour, edgecolors=edgecolor, linewidths=linewidth))
        points = np.concatenate(polygons)
        lo, hi = points.min(axis=0), points.max(axis=0)
        centre, half = 0.5 * (lo + hi), 0.5 * float(np.max(hi - lo)) or 1.0
        ax.set_xlim(centre[0] - half, centre[0] + half)
        ax.set_ylim(centre[1] - half, centre[1] + half)
        ax.set_zlim(centre[2] - half, centre[2] + half)
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_zlabel("z [m]")
        # Up is against gravity (an arch built in the x–y plane stands up in y).
        g = np.asarray(model.gravity, dtype=float)
        up = "xyz"[int(np.argmax(np.abs(g)))] if np.any(g) else "z"
        ax.view_init(elev=elevation, azim=azimuth, vertical_axis=up)
        if contacts:
            loops = [np.vstack([p, p[:1]]) for p in model.contacts()["polygon"] if len(p) >= 2]
            if loops:
                ax.add_collection3d(Line3DCollection(loops, colors="red", linewidths=1.0))
    else:
        from matplotlib.collections import LineCollection, PolyCollection

        a, b = _PLANES[view]
        ax.add_collection(
            PolyCollection([p[:, [a, b]] for p in polygons], facecolors=faces_colour, edgecolors=edgecolor, linewidths=linewidth)
        )
        if contacts:
            loops = [np.vstack([p, p[:1]])[:, [a, b]] for p in model.contacts()["polygon"] if len(p) >= 2]
            if loops:
                ax.add_collection(LineCollection(loops, colors="red", linewidths=1.0))
        ax.autoscale_view()
        ax.set_aspect("equal")
        ax.set_xlabel(f"{'xyz'[a]} [m]")
        ax.set_ylabel(f"{'xyz'[b]} [m]")
    if colorbar and color is None:
        mapper.set_array([])
        ax.figure.colorbar(mapper, ax=ax, shrink=0.7, label="displacement [mm]")
    ax.set_title(f"t = {model.time:.4g} s, step {model.step_count}")
    return ax


def save(model, path, *, dpi: int = 120, **options):
    """Draws ``model`` (``draw``'s options) into a new figure and writes it to ``path`` (the
    format by its extension: ``.png``, ``.svg``, ``.pdf``), creating the folder; the figure is
    closed. Returns the path."""
    import os

    import matplotlib

    if matplotlib.get_backend().lower() not in ("agg", "module://matplotlib_inline.backend_inline"):
        try:
            import matplotlib.pyplot as plt

            plt.switch_backend("Agg")
        except Exception:  # an interactive session keeps its backend
            pass
    import matplotlib.pyplot as plt

    if len(model) == 0:
        raise VoussoirError(f"draw.save({os.fspath(path)!r}): the model has no blocks, nothing to draw; no file written")
    folder = os.path.dirname(os.fspath(path))
    if folder:
        os.makedirs(folder, exist_ok=True)
    ax = draw(model, **options)
    # Written beside and renamed: an interrupted save leaves no half-written picture.
    tmp = f"{os.fspath(path)}.partial"
    fmt = os.path.splitext(os.fspath(path))[1].lstrip(".") or "png"
    ax.figure.savefig(tmp, dpi=dpi, format=fmt, bbox_inches="tight")
    plt.close(ax.figure)
    os.replace(tmp, path)
    return path
