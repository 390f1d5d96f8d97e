"""The discrete problem and its solvers.

:func:`solve_discrete` is the paper's problem verbatim; :func:`solve_problem` takes a
:class:`DiscreteProblem` on any grid (used by :func:`speedplan.plan`).
"""

from .discrete import RELAXATION_BACKENDS, REFINE_MODES, solve_discrete, solve_problem
from .problem import JERK_TOL, JERK_TOL_REL, DiscreteProblem
from .solution import STATUSES, DiscreteSolution

__all__ = [
    "JERK_TOL",
    "JERK_TOL_REL",
    "REFINE_MODES",
    "RELAXATION_BACKENDS",
    "STATUSES",
    "DiscreteProblem",
    "DiscreteSolution",
    "solve_discrete",
    "solve_problem",
]
