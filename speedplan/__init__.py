"""speedplan: minimum-time speed laws along a path, with a certificate of optimality.

Speed, tangential-acceleration, lateral-acceleration and true jerk limits; see `plan`.
"""

import importlib
from types import ModuleType

from ._version import __version__
from .batch import BatchResult, plan_many
from .core import (
    InfeasibleError,
    InvalidInputError,
    Limits,
    LimitWarning,
    PlanTimeout,
    SolverError,
    SpeedplanError,
    SpeedplanWarning,
)
from .geometry import Path, SpanLimit, SpeedZone, speed_bounds
from .plan import plan
from .route import Route, RouteProfile
from .route_plan import plan_route, plan_route_update
from .solve import DiscreteProblem, DiscreteSolution, solve_discrete
from .timing import SpeedProfile, Trajectory, Verification
from .waypoints import profile_from_waypoints

__all__ = [
    "BatchResult",
    "DiscreteProblem",
    "DiscreteSolution",
    "InfeasibleError",
    "InvalidInputError",
    "LimitWarning",
    "Limits",
    "Path",
    "PlanTimeout",
    "Route",
    "RouteProfile",
    "SolverError",
    "SpanLimit",
    "SpeedProfile",
    "SpeedZone",
    "SpeedplanError",
    "SpeedplanWarning",
    "Trajectory",
    "Verification",
    "__version__",
    "plan",
    "plan_many",
    "plan_route",
    "plan_route_update",
    "profile_from_waypoints",
    "solve_discrete",
    "speed_bounds",
]

#: Submodules imported on first attribute access (``speedplan.io.read_path`` after a plain
#: ``import speedplan``), so that the import itself stays light.
_LAZY_SUBMODULES = ("cli", "io", "plot")


def __getattr__(name: str) -> ModuleType:
    if name in _LAZY_SUBMODULES:
        return importlib.import_module(f".{name}", __name__)
    raise AttributeError(f"module 'speedplan' has no attribute {name!r}")
