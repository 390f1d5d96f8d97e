"""Base layer: errors and warnings, vehicle limits, option types, input checks, shared numerics.

Every other layer imports from here; this layer imports nothing else from speedplan.
"""

from .errors import (
    InfeasibleError,
    InvalidInputError,
    LimitWarning,
    PlanTimeout,
    SolverError,
    SpeedplanError,
    SpeedplanWarning,
)
from .limits import Limits

__all__ = [
    "InfeasibleError",
    "InvalidInputError",
    "LimitWarning",
    "Limits",
    "PlanTimeout",
    "SolverError",
    "SpeedplanError",
    "SpeedplanWarning",
]
