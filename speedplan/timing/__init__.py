"""Time mapping: from the discrete speed law ``w(s)`` to a trajectory in time, and its checks."""

from .law import Extreme, LawChain, PieceExtremes, SpeedLaw, TimeLaw
from .motion_law import MotionLaw
from .profile import PROFILE_STATUSES, LegResult, SpeedProfile, law_for
from .trajectory import COLUMNS, Trajectory
from .verify import TOLERANCES, LimitCheck, Verification

__all__ = ["COLUMNS", "PROFILE_STATUSES", "TOLERANCES", "Extreme", "LawChain", "LegResult",
           "LimitCheck", "MotionLaw", "PieceExtremes", "SpeedLaw", "SpeedProfile", "TimeLaw",
           "Trajectory", "Verification", "law_for"]
