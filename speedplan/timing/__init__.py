"""Time mapping: from the discrete speed law ``w(s)`` to a trajectory in time."""

from .law import TimeLaw
from .profile import SpeedProfile
from .trajectory import COLUMNS, Trajectory
from .verify import TOLERANCES, Verification

__all__ = ["COLUMNS", "TOLERANCES", "SpeedProfile", "TimeLaw", "Trajectory", "Verification"]
