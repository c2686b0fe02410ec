"""compas_voussoir: voussoir as an engine of COMPAS's masonry framework.

A ``compas_dem`` block model and its ``Problem`` (supports, Mohr–Coulomb joints, joint
stiffnesses per unit area (Pa/m), point/surface/body loads, prescribed motions) become a
``voussoir.Model``; a DEM analysis (settling, time history, base shaking, push-over to
capacity) or a limit analysis runs; the answer comes back as ``compas_dem``'s engine-neutral
``Results`` (with the supports' reactions: :func:`reactions`). Changing engine is one line::

    problem.set_solver(compas_voussoir.Voussoir(analysis="static", density=2400.0))
    results = problem.solve()                                     # runs voussoir
    results = compas_voussoir.solve(problem, analysis="static")   # the same, directly

Importing ``compas_voussoir`` lets ``Problem.solve`` run a ``Voussoir`` solver
(:func:`install`; ``compas_dem`` dispatches on a fixed list of solver names and has no plugin
for a solver); :func:`uninstall` undoes it.
"""

from .convert import MODEL_OPTIONS, PLAUSIBLE_STIFFNESS, Conversion, StiffnessUnitsWarning, to_voussoir
from .dispatch import install, installed, uninstall
from .results import corner_normal_forces, from_limit, from_model, hinges, reactions
from .solve import ANALYSES, SOLVER_NAME, UNITS, NotSettledWarning, Voussoir, run, solve

__version__ = "0.1.0"

__all__ = [
    "ANALYSES",
    "MODEL_OPTIONS",
    "PLAUSIBLE_STIFFNESS",
    "SOLVER_NAME",
    "UNITS",
    "Conversion",
    "NotSettledWarning",
    "StiffnessUnitsWarning",
    "Voussoir",
    "corner_normal_forces",
    "from_limit",
    "from_model",
    "hinges",
    "install",
    "installed",
    "reactions",
    "run",
    "solve",
    "to_voussoir",
    "uninstall",
]

install()
