"""Geometry: arc-length parametrised paths, their constructors and speed bounds."""

from .bounds import SpeedZone, speed_bounds, zone_intervals
from .path import Arc, Clothoid, Line, Path, PathSamples

__all__ = [
    "Arc",
    "Clothoid",
    "Line",
    "Path",
    "PathSamples",
    "SpeedZone",
    "speed_bounds",
    "zone_intervals",
]
