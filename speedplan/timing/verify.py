"""Measure a planned law against its limits, piece by piece.

The law is a chain of quadratic pieces (`speedplan.timing.law`), so the extremes of
acceleration and jerk over each piece are exact closed forms (`TimeLaw.extremes`):
nothing between samples can escape. What depends on the path — the speed bound (curvature,
zones, ``v_limit``), lateral acceleration ``κ v²``, yaw rate ``κ v`` and lateral jerk
``v (κ' w + 2 κ a)`` — is evaluated at `SAMPLES_PER_PIECE` points of every piece
(both ends included: 8 per grid cell, as dense as the discrete problem's own bound sampling),
at the piece's speed maximum, and at every breakpoint of the speed bound inside the leg
(`bound_breakpoints`: knots of ``v_limit``, ends of spans, zone entries and exits, joins
of path pieces), where a narrow dip or a step of the bound can fall between two samples.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..core.checks import FloatArray
from ..core.forward import Forwarded
from ..core.limits import Limits
from ..geometry import Path, SpeedBound
from ..geometry.bounds import bound_breakpoints
from .law import TimeLaw

__all__ = ["LIMIT_NAMES", "SAMPLES_PER_PIECE", "TOLERANCES", "LegCheck", "Verification",
           "bound_breakpoints", "check_law", "curvature_rate"]

#: Points per law piece where path-dependent quantities are evaluated (ends included).
SAMPLES_PER_PIECE = 5
#: Documented tolerances at the default resolution, as fractions of each limit; all shrink
#: as the grid is refined (docs/convergence.md, docs/failure-modes.md).
TOLERANCES: dict[str, float] = {
    "speed": 0.001,
    "accel": 0.01,
    "decel": 0.01,
    "lateral": 0.01,
    "jerk": 0.05,
    "yaw_rate": 0.001,
    "lateral_jerk": 0.05,
    "grip": 0.01,
    "yaw_acc": 0.001,
    "yaw_jerk": 0.001,
}
#: Every checked limit, in report order.
LIMIT_NAMES = tuple(TOLERANCES)



@dataclass(frozen=True)
class Verification:
    """Realised maxima of a law and their ratios to the limits.

    Attributes
    ----------
    maxima : dict
        Largest realised value of each quantity, SI units (``"speed"`` [m/s], ``"accel"``
        and ``"decel"`` [m/s²], ``"lateral"`` [m/s²], ``"jerk"`` and ``"lateral_jerk"``
        [m/s³], ``"yaw_rate"`` [rad/s]; ``"grip"``, with ``grip="ellipse"``, the friction
        ellipse's radius ``sqrt((a / a_max)² + (a_lat / a_lat_max)²)``, 1 on the ellipse).
    ratios : dict
        Each maximum divided by its limit (``"speed"`` against the local bound
        ``sqrt(mu+(s))``, which includes ``v_max``, lateral limits and zones); limits that are
        ``inf`` give 0, and so does the grip without ``grip="ellipse"``. A ratio above
        ``1 + TOLERANCES[name]`` is a violation. ``"yaw_acc"`` [rad/s²] and ``"yaw_jerk"``
        [rad/s³] of turns on the spot appear in the checks of routes that turn
        ([`speedplan.RouteProfile.verify`][speedplan.RouteProfile.verify]).
    where : dict
        Arc length [m] at which each ratio is largest.
    unset : frozenset of str
        The quantities whose limit is not set (``inf`` or ``None``): their ratio is 0 and
        [`summary`][speedplan.Verification.summary] says "not set".
    max_speed, max_accel, max_decel, max_jerk, max_lateral : float
        Largest speed [m/s], acceleration, braking deceleration [m/s²], absolute jerk [m/s³]
        and absolute lateral acceleration [m/s²]: the entries of ``maxima``.

    Examples
    --------
    >>> from speedplan import Limits, Path, plan
    >>> prof = plan(Path.from_waypoints([[0, 0], [10, 0]], kind="polyline"),
    ...             Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5))
    >>> check = prof.verify()
    >>> check.ok, check.ratios["jerk"] <= 1.05
    (True, True)
    """

    maxima: dict[str, float]
    ratios: dict[str, float]
    where: dict[str, float] = field(default_factory=dict)
    unset: frozenset[str] = frozenset()

    # Shorthands for entries of ``maxima``, documented in the class docstring.
    max_speed = Forwarded[float]("maxima", key="speed")
    max_accel = Forwarded[float]("maxima", key="accel")
    max_decel = Forwarded[float]("maxima", key="decel")
    max_jerk = Forwarded[float]("maxima", key="jerk")
    max_lateral = Forwarded[float]("maxima", key="lateral")

    @property
    def violations(self) -> dict[str, float]:
        """The ratios exceeding their tolerance."""
        return {k: r for k, r in self.ratios.items() if not r <= 1.0 + TOLERANCES[k]}

    @property
    def ok(self) -> bool:
        """Whether every ratio is within its tolerance."""
        return not self.violations

    def summary(self) -> str:
        """One line per limit: realised ratio, tolerance and where.

        A limit that is not set says "not set" (its ratio is 0 and means nothing).

        Examples
        --------
        >>> from speedplan import Limits, Path, plan
        >>> prof = plan(Path.from_waypoints([[0, 0], [10, 0]], kind="polyline"),
        ...             Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5))
        >>> prof.verify().summary().splitlines()[-2:]
        ['lateral_jerk  not set', 'grip          not set']
        """
        lines = []
        for k, r in self.ratios.items():
            if k in self.unset:
                lines.append(f"{k:12s}  not set")
                continue
            flag = "  VIOLATED" if not r <= 1 + TOLERANCES[k] else ""
            at = f" at s={self.where[k]:.4g} m" if k in self.where and r > 0 else ""
            lines.append(f"{k:12s} {r:8.4f} of limit (tolerance {1 + TOLERANCES[k]:.3f}){at}"
                         f"{flag}")
        return "\n".join(lines)

    @staticmethod
    def merged(parts: list[Verification]) -> Verification:
        """The worst of several verifications (legs of one profile).

        A quantity only some parts check (``"yaw_acc"`` of turns) is merged over those.
        """
        keys = [k for k in LIMIT_NAMES if any(k in p.ratios for p in parts)]
        maxima = {k: max(p.maxima[k] for p in parts if k in p.maxima) for k in keys}
        ratios, where = {}, {}
        for k in keys:
            worst = max((p for p in parts if k in p.ratios),
                        key=lambda p: (p.ratios[k] if np.isfinite(p.ratios[k]) else np.inf))
            ratios[k] = worst.ratios[k]
            if k in worst.where:
                where[k] = worst.where[k]
        unset = frozenset.intersection(*(p.unset for p in parts)) if parts else frozenset()
        return Verification(maxima=maxima, ratios=ratios, where=where, unset=unset)


@dataclass(frozen=True)
class LegCheck:
    """`Verification` of one leg, and which of its pieces exceed a tolerance."""

    verification: Verification
    excess: np.ndarray  # bool per law piece
    knots: FloatArray  # the law's knots, leg arc length [m]


def curvature_rate(path: Path, s: FloatArray) -> FloatArray:
    """``dκ/ds`` [1/m²] by a central difference (one-sided at the path's ends).

    Where the curvature jumps (a G1 path) the result is of order ``jump / (2 δ)``: lateral
    jerk is then unbounded, which is what it is physically.
    """
    length = path.length
    delta = max(1e-7 * length, 1e-9)
    lo = np.clip(s - delta, 0.0, length)
    hi = np.clip(s + delta, 0.0, length)
    both = np.asarray(path.curvature(np.concatenate((hi.ravel(), lo.ravel()))))  # one pass
    out: FloatArray = (both[:hi.size].reshape(hi.shape) - both[hi.size:].reshape(lo.shape)) / (
        hi - lo)
    return out


def check_law(law: TimeLaw, offset: float, path: Path,
              bound: Callable[[FloatArray], FloatArray], limits: Limits,
              breaks: FloatArray | None = None) -> LegCheck:
    """Check the law of one leg that covers ``[offset, offset + law.length]`` of ``path``.

    ``breaks``: arc lengths of ``path`` (`bound_breakpoints`, computed here when not
    given) where the path-dependent quantities are evaluated too, besides the samples.
    """
    ex = law.extremes()
    knots = law.knots
    width = np.diff(knots)
    m = width.size
    frac = np.linspace(0.0, 1.0, SAMPLES_PER_PIECE)
    top = ex["w"][0]  # each piece's speed maximum, the sixth sample of the piece
    if breaks is None:
        breaks = bound_breakpoints(path, bound)
    local = np.clip(breaks[(breaks >= offset) & (breaks <= offset + law.length)] - offset,
                    0.0, law.length)
    # Each breakpoint counts for the piece(s) it lies in (both, on a knot).
    at = np.searchsorted(knots, local, side="right") - 1
    left = np.searchsorted(knots, local, side="left") - 1
    extra_piece = np.clip(np.concatenate((at, left)), 0, m - 1)
    # The law on each piece at its own offsets (both sides of a knot: the acceleration may
    # jump there); the path once per distinct position: neighbouring pieces share a knot,
    # and a maximum at a knot is that knot.
    dx = np.concatenate((width[:, None] * frac[None, :], (top - knots[:-1])[:, None]), axis=1)
    piece = np.arange(m)[:, None]
    w_p, v_p, a_p, _ = law._kinematics(piece, dx, width[:, None] - dx)
    w_b, v_b, a_b, _ = law.kinematics(local)
    w = np.concatenate((w_p.ravel(), w_b))
    v = np.concatenate((v_p.ravel(), v_b))
    a = np.concatenate((a_p.ravel(), a_b))
    inner = knots[:-1, None] + width[:, None] * frac[None, 1:-1]
    own = (top != knots[:-1]) & (top != knots[1:])
    n_inner = inner.size
    where_at = np.empty((m, SAMPLES_PER_PIECE + 1), dtype=np.intp)  # index into `spots`
    where_at[:, 0] = np.arange(m)
    where_at[:, SAMPLES_PER_PIECE - 1] = np.arange(1, m + 1)
    where_at[:, 1:-2] = m + 1 + np.arange(n_inner).reshape(inner.shape)
    at_top = np.where(top == knots[1:], np.arange(1, m + 1), np.arange(m))
    where_at[:, -1] = np.where(own, m + 1 + n_inner + np.cumsum(own) - 1, at_top)
    spots = np.concatenate((knots, inner.ravel(), top[own], local))
    sample_spot = np.concatenate((where_at.ravel(), spots.size - local.size
                                  + np.arange(local.size)))
    shape = where_at.shape
    spot_glob = offset + spots
    if isinstance(bound, SpeedBound) and bound.path is path and bound.offset == 0.0:
        # The curvature is the bound's own (remembered from the grid where it has a memo).
        kappa_spot, wb_spot = bound.curvature_and_bound(spot_glob)
    else:
        kappa_spot = np.asarray(path.curvature(spot_glob), dtype=np.float64)
        wb_spot = np.asarray(bound(spot_glob), dtype=np.float64)
    glob = spot_glob[sample_spot]
    kappa = kappa_spot[sample_spot]
    wb = wb_spot[sample_spot]
    with np.errstate(divide="ignore", invalid="ignore"):
        speed = np.where(wb > 0, v / np.sqrt(wb), np.where(v > 0, np.inf, 0.0))
    lateral = np.abs(kappa) * w
    yaw = np.abs(kappa) * v
    if np.isfinite(limits.j_lat_max):
        rate = curvature_rate(path, spot_glob)[sample_spot]
        lat_jerk = np.abs(v * (rate * w + 2.0 * kappa * a))
    else:
        lat_jerk = np.zeros(1)  # no limit: nothing to evaluate, reported as 0
    if limits.ellipse:  # the friction ellipse's radius, 1 on the ellipse
        grip = np.hypot(a / np.where(a >= 0.0, limits.a_max, limits.a_decel),
                        lateral / limits.a_lat_max)
    else:
        grip = np.zeros(1)  # not set: reported as 0
    per_sample = {"speed": (speed, v, 1.0), "lateral": (lateral, lateral, limits.a_lat_max),
                  "yaw_rate": (yaw, yaw, limits.yaw_rate_max),
                  "lateral_jerk": (lat_jerk, lat_jerk, limits.j_lat_max),
                  "grip": (grip, grip, 1.0 if limits.ellipse else np.inf)}
    maxima: dict[str, float] = {}
    ratios: dict[str, float] = {}
    where: dict[str, float] = {}
    excess = np.zeros(width.size, dtype=bool)
    for name, (load, value, limit) in per_sample.items():
        if not np.isfinite(limit):  # no limit: the maximum is reported, the ratio is 0
            maxima[name] = float(np.max(value))
            ratios[name], where[name] = 0.0, float(glob[0])
            continue
        ratio_s = load / limit if name != "speed" else load
        ratio_s = np.where(np.isfinite(ratio_s), ratio_s, np.inf)
        k = int(np.argmax(ratio_s))
        maxima[name] = float(np.max(value))
        ratios[name] = float(ratio_s[k])
        where[name] = float(glob[k])
        over = ratio_s > 1.0 + TOLERANCES[name]
        excess |= over[: over.size - local.size].reshape(shape).any(axis=1)
        if local.size:
            excess[extra_piece[np.tile(over[over.size - local.size:], 2)]] = True
    a_top, a_bottom = ex["a"][1], ex["a"][2]
    j_top, j_bottom = ex["jerk"][1], ex["jerk"][2]
    j_abs = np.maximum(j_top, -j_bottom)
    for name, per_piece, limit in (("accel", a_top, limits.a_max),
                                   ("decel", -a_bottom, limits.a_decel),
                                   ("jerk", j_abs, limits.j_max)):
        per_piece = np.where(np.isfinite(per_piece), per_piece, np.inf)
        k = int(np.argmax(per_piece))
        maxima[name] = max(float(per_piece[k]), 0.0)
        ratios[name] = max(float(per_piece[k]) / limit, 0.0) if np.isfinite(limit) else 0.0
        where[name] = float(offset + 0.5 * (knots[k] + knots[k + 1]))
        if np.isfinite(limit):
            excess |= per_piece > limit * (1.0 + TOLERANCES[name])
    order = {k: i for i, k in enumerate(LIMIT_NAMES)}
    ratios = dict(sorted(ratios.items(), key=lambda kv: order[kv[0]]))
    limit_of = {"speed": limits.v_max, "accel": limits.a_max, "decel": limits.a_decel,
                "lateral": limits.a_lat_max, "jerk": limits.j_max,
                "yaw_rate": limits.yaw_rate_max, "lateral_jerk": limits.j_lat_max,
                "grip": 1.0 if limits.ellipse else np.inf}
    unset = frozenset(k for k, lim in limit_of.items() if not np.isfinite(lim))
    return LegCheck(Verification(maxima=maxima, ratios=ratios, where=where, unset=unset),
                    excess, knots)
