"""The discrete problem and its solvers.

`solve_discrete` is the paper's problem verbatim; `solve_problem` takes a
[`DiscreteProblem`][speedplan.DiscreteProblem] on any grid (used by `speedplan.plan`).
"""

from .discrete import BACKENDS, REFINE_MODES, RELAXATION_BACKENDS, solve_discrete, solve_problem
from .problem import JERK_TOL, JERK_TOL_REL, DiscreteProblem
from .solution import STATUSES, DiscreteSolution

__all__ = [
    "BACKENDS",
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
