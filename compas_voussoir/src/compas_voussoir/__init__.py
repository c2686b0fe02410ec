"""compas_voussoir: voussoir as an engine of COMPAS's masonry framework.

A ``compas_dem`` block model and its ``Problem`` (supports, Mohr–Coulomb joints, joint
stiffnesses, point/surface/body loads, prescribed motions) become a ``voussoir.Model``; a DEM
analysis (settling, time history, base shaking, push-over to capacity) or a limit analysis
runs; the answer comes back as ``compas_dem``'s engine-neutral ``Results``. Changing engine is
one line::

    results = problem.solve()                                   # the engine compas_dem knows
    results = compas_voussoir.solve(problem, analysis="static")   # voussoir
"""

from .convert import Conversion, to_voussoir
from .results import corner_normal_forces, from_limit, from_model
from .solve import ANALYSES, Voussoir, run, solve

__version__ = "0.1.0"

__all__ = [
    "ANALYSES",
    "Conversion",
    "Voussoir",
    "corner_normal_forces",
    "from_limit",
    "from_model",
    "run",
    "solve",
    "to_voussoir",
]
