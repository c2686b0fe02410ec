"""``problem.solve()`` for a ``compas_voussoir.Voussoir(...)`` solver.

``compas_dem`` 0.6 (the version on the package index) dispatches ``Problem.solve`` on the
solver's name through a fixed list (``"LMGC90"``, ``"3DEC"``, ``"CRA"``, ``"RBE"``, ``"PRD"``,
``"BLA"``) and raises ``Solver '<name>' is not recognised`` for any other; it offers no
plugin (``compas.plugins`` pluggable) or registry for a solver, and ``Problem.solve`` calls
nothing on the solver object that could run it. So the one way for ``problem.solve()`` to run
voussoir is to wrap ``Problem.solve``: :func:`install` (called when ``compas_voussoir`` is
imported) replaces it with a function that runs :func:`compas_voussoir.solve` when the
problem's solver is named ``"voussoir"`` and calls the original ``Problem.solve`` unchanged
otherwise. :func:`uninstall` puts the original back (should a later ``compas_dem``
dispatch ``"voussoir"`` itself, or through a plugin, that is the one to use). The wrapper is
marked (``Problem.solve.__compas_voussoir__``) so that installing twice (a reload of the
module) does not wrap the wrapper.
"""

import functools

from .solve import SOLVER_NAME, solve


def _problem_class():
    from compas_dem.problem import Problem

    return Problem


def installed():
    """Whether ``Problem.solve`` runs voussoir for a ``Voussoir`` solver."""
    return getattr(_problem_class().solve, "__compas_voussoir__", False)


def install():
    """Makes ``Problem.solve()`` run voussoir when the problem's solver is
    ``compas_voussoir.Voussoir(...)`` (any ``compas_dem`` ``Solver`` named ``"voussoir"``, e.g.
    one read back from JSON); every other solver goes to ``compas_dem``'s own ``Problem.solve``
    as before. Runtime options given to ``problem.solve(**options)`` override the solver's
    parameters, as in ``compas_dem``. Idempotent; returns True if it installed the wrapper."""
    Problem = _problem_class()
    if installed():
        return False
    original = Problem.solve

    @functools.wraps(original)
    def solve_with_voussoir(self, **runtime_options):
        solver = getattr(self, "_solver", None)
        if solver is not None and getattr(solver, "name", None) == SOLVER_NAME:
            return solve(self, **runtime_options)
        return original(self, **runtime_options)

    solve_with_voussoir.__compas_voussoir__ = True
    solve_with_voussoir.__compas_voussoir_original__ = original
    solve_with_voussoir.__doc__ = (original.__doc__ or "") + (
        "\n\n        (compas_voussoir: a solver named 'voussoir', compas_voussoir.Voussoir(...), runs "
        "compas_voussoir.solve(problem, **runtime_options).)\n"
    )
    Problem.solve = solve_with_voussoir
    return True


def uninstall():
    """Puts ``compas_dem``'s own ``Problem.solve`` back (a ``Voussoir`` solver is then "not
    recognised" by ``problem.solve()``; ``compas_voussoir.solve(problem)`` still works).
    Returns True if it removed the wrapper."""
    Problem = _problem_class()
    current = Problem.solve
    if not getattr(current, "__compas_voussoir__", False):
        return False
    Problem.solve = current.__compas_voussoir_original__
    return True
