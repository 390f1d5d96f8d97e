"""Measure a planned trajectory against its limits on a fine time sampling."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["TOLERANCES", "Verification"]

#: Documented tolerances of the time law at the default resolution, as fractions of each
#: limit; all shrink as the grid is refined (see the convergence table in the docs).
TOLERANCES: dict[str, float] = {
    "speed": 0.005,
    "accel": 0.02,
    "decel": 0.02,
    "lateral": 0.02,
    "jerk": 0.10,
}


@dataclass(frozen=True)
class Verification:
    """Realised maxima of a trajectory and their ratios to the limits.

    ``ratios[name]`` is the realised maximum divided by its limit (``speed`` against the local
    bound ``sqrt(mu+(s))``, which includes ``v_max``, lateral limits and zones); a ratio above
    ``1 + TOLERANCES[name]`` is a violation. Limits that are ``inf`` give a ratio of 0.
    """

    max_speed: float
    max_accel: float
    max_decel: float
    max_jerk: float
    max_lateral: float
    ratios: dict[str, float]
    dt: float

    @property
    def violations(self) -> dict[str, float]:
        """The ratios exceeding their tolerance."""
        return {k: r for k, r in self.ratios.items() if r > 1.0 + TOLERANCES[k]}

    @property
    def ok(self) -> bool:
        """Whether every ratio is within its tolerance."""
        return not self.violations

    def summary(self) -> str:
        """One line per limit: realised ratio and tolerance."""
        return "\n".join(
            f"{k:8s} {r:8.4f} of limit (tolerance {1 + TOLERANCES[k]:.3f})"
            f"{'  VIOLATED' if r > 1 + TOLERANCES[k] else ''}"
            for k, r in self.ratios.items()
        )
