"""voussoir: discrete element modelling of masonry built from rigid blocks.

The Python face of the Rust library of the same name (PyO3): build models from blocks and
generators, run them (the GIL released; Ctrl-C and a progress callback between steps), read the
results as numpy arrays, write ParaView and CSV files and self-contained HTML viewers of a run (``Viewer``), save and load scenes and checkpoints, and
run the reference arch's benchmarks (``voussoir.scenarios``), and find collapse loads by
limit analysis (``voussoir.limit``; whether the dead load is carried at all:
``voussoir.carries_dead_load``).

Joint laws are the shipped ones (``CoulombSlip``, ``MortarJoint``, ``LinearElastic``); a law of
your own is written in Rust (``docs/custom-law.md``), not in Python.
"""

from ._voussoir import (
    Block,
    CoulombSlip,
    LimitInfeasibleError,
    LimitSolverError,
    LimitUnboundedError,
    LinearElastic,
    Model,
    MortarJoint,
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


def carries_dead_load(model, *, fixity=None, friction="cone", facets=16, max_iterations=200):
    """Whether the model's blocks as they stand carry the dead loads (gravity and the blocks'
    constant loads): whether contact forces within the joints' strength (no tension, Coulomb)
    hold every free block in equilibrium. The dead-load question of ``limit`` (``limit(model,
    [])``, which also gives the contact forces of an admissible state, or the blocks that fall);
    Rust ``LimitProblem::carries_dead_load``. The model must have been stepped once; ``fixity``,
    ``friction``, ``facets``, ``max_iterations`` as ``limit`` takes them. Returns True or False
    (an answer either way); raises ``LimitSolverError`` when the solver stops without one.

    >>> import voussoir as vs
    >>> m = vs.Model()
    >>> m.set_joint_law(0, 0, vs.CoulombSlip.dry(4e9, 1.6e9, 30.0))
    >>> _ = m.add_cuboid("base", (-1, -1, -0.2), (0, 1, 0), 2600.0, fixed=True)
    >>> _ = m.add_cuboid("slab", (-0.1, 0, 0), (0.3, 0.2, 0.1), 2600.0)  # 3/4 of it overhangs
    >>> m.run_steps(1)
    True
    >>> vs.carries_dead_load(m)
    False
    """
    answer = limit(model, [], fixity=fixity, friction=friction, facets=facets, max_iterations=max_iterations)
    return bool(answer["carries_dead_load"])


__all__ = [
    "Block",
    "CoulombSlip",
    "LinearElastic",
    "Model",
    "MortarJoint",
    "ParaviewSeries",
    "TimeHistory",
    "Viewer",
    "VoussoirError",
    "VoussoirIOError",
    "LimitInfeasibleError",
    "LimitSolverError",
    "LimitUnboundedError",
    "__version__",
    "build",
    "carries_dead_load",
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
