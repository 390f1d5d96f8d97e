"""speedplan: minimum-time speed laws along a path under speed, acceleration, lateral
acceleration and true jerk limits, with a certificate of optimality.
"""

from .errors import InfeasibleError, InvalidInputError, SolverError, SpeedplanError
from .limits import Limits
from .solve import DiscreteProblem, DiscreteSolution, solve_discrete

__version__ = "0.1.0"

__all__ = [
    "DiscreteProblem",
    "DiscreteSolution",
    "InfeasibleError",
    "InvalidInputError",
    "Limits",
    "SolverError",
    "SpeedplanError",
    "__version__",
    "solve_discrete",
]
