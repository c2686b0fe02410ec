"""voussoir: discrete element modelling of masonry built from rigid blocks.

The Python face of the Rust library of the same name (PyO3): build models from blocks and
generators, run them (the GIL released; Ctrl-C and a progress callback between steps), read the
results as numpy arrays, write ParaView and CSV files and self-contained HTML viewers of a run (``Viewer``), save and load scenes and checkpoints, and
run the reference arch's benchmarks (``voussoir.scenarios``), and find collapse loads by
limit analysis (``voussoir.limit``).

Joint laws are the shipped ones (``CoulombSlip``, ``LinearElastic``); a law of your own is
written in Rust (``docs/custom-law.md``), not in Python.
"""

from ._voussoir import (
    Block,
    CoulombSlip,
    LinearElastic,
    Model,
    ParaviewSeries,
    TimeHistory,
    Viewer,
    VoussoirError,
    VoussoirIOError,
    __version__,
    check_density_convergence,
    check_servo_convergence,
    classify_joints,
    limit,
)
from . import build, draw, fragility, scenarios, scenes, study

__all__ = [
    "Block",
    "CoulombSlip",
    "LinearElastic",
    "Model",
    "ParaviewSeries",
    "TimeHistory",
    "Viewer",
    "VoussoirError",
    "VoussoirIOError",
    "__version__",
    "build",
    "draw",
    "fragility",
    "check_density_convergence",
    "check_servo_convergence",
    "classify_joints",
    "limit",
    "scenarios",
    "scenes",
    "study",
]
