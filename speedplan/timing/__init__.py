"""Time mapping: from the discrete speed law ``w(s)`` to a trajectory in time, and its checks."""

from .law import LawChain, TimeLaw
from .profile import PROFILE_STATUSES, LegResult, SpeedProfile, law_for
from .trajectory import COLUMNS, Trajectory
from .verify import TOLERANCES, Verification

__all__ = ["COLUMNS", "PROFILE_STATUSES", "TOLERANCES", "LawChain", "LegResult", "SpeedProfile",
           "TimeLaw", "Trajectory", "Verification", "law_for"]
