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
The quantities come from `speedplan.core.kinematics`, with ``κ'`` the path's exact rate
(`curvature_rate`). Each limit's outcome is a `LimitCheck`; a `Verification` holds them.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass

import numpy as np

from ..core import kinematics
from ..core.checks import FloatArray, IntArray
from ..core.forward import Forwarded
from ..core.limits import Limits
from ..core.numerics import CELL_FRACTIONS, CELL_POINTS, cell_points, cell_rows
from ..geometry import CellSamples, Path, SpeedBound
from ..geometry.bounds import bound_breakpoints
from .law import PieceExtremes, SpeedLaw, TimeLaw

__all__ = ["LIMIT_NAMES", "SAMPLES_PER_PIECE", "TOLERANCES", "LegCheck", "LimitCheck",
           "Verification", "bound_breakpoints", "check_law", "check_linear_law", "check_pieces",
           "curvature_rate"]

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
class LimitCheck:
    """How one limit fared: the realised maximum, its ratio to the limit and where.

    Attributes
    ----------
    name : str
        The quantity, one of `LIMIT_NAMES` (``"speed"``, ``"accel"``, ``"lateral_jerk"``, ...).
    ratio : float
        The largest ratio of the quantity to its limit (0 for a limit not set; ``"speed"``
        against the local bound ``sqrt(mu+(s))``, ``"grip"`` the ellipse's radius).
    maximum : float or None
        Largest realised value, SI units (see [`Verification`][speedplan.Verification]);
        ``None`` when not measured.
    limit : float or None
        The limit checked against, SI units (``inf``: not set; for ``"speed"`` the global
        ``v_max``, the ratio being against the local bound); ``None`` when not recorded.
    where_s : float or None
        Arc length [m] at which the ratio is largest; ``None`` when not recorded.
    unset : bool
        Whether the limit is not set (``inf`` or ``None``): the ratio is 0 and means nothing.

    Examples
    --------
    >>> from speedplan.timing import LimitCheck
    >>> check = LimitCheck("jerk", ratio=1.02, maximum=0.51, limit=0.5, where_s=3.0)
    >>> check.tolerance, check.exceeded
    (0.05, False)
    """

    name: str
    ratio: float
    maximum: float | None = None
    limit: float | None = None
    where_s: float | None = None
    unset: bool = False

    @property
    def tolerance(self) -> float:
        """The documented tolerance of this limit, a fraction of it (`TOLERANCES`)."""
        return TOLERANCES[self.name]

    @property
    def exceeded(self) -> bool:
        """Whether the ratio exceeds ``1 + tolerance`` (a NaN ratio does)."""
        return not self.ratio <= 1.0 + self.tolerance

    def line(self) -> str:
        """The check's line of [`Verification.summary`][speedplan.Verification.summary]."""
        if self.unset:
            return f"{self.name:12s}  not set"
        flag = "  VIOLATED" if self.exceeded else ""
        at = f" at s={self.where_s:.4g} m" if self.where_s is not None and self.ratio > 0 else ""
        return (f"{self.name:12s} {self.ratio:8.4f} of limit (tolerance "
                f"{1 + self.tolerance:.3f}){at}{flag}")


def _records(maxima: Mapping[str, float], ratios: Mapping[str, float],
             where: Mapping[str, float], unset: Iterable[str]) -> dict[str, LimitCheck]:
    """One `LimitCheck` per entry of ``ratios`` (in its order), from per-quantity maps."""
    off = frozenset(unset)
    return {k: LimitCheck(k, ratio=r, maximum=maxima.get(k), where_s=where.get(k),
                          unset=k in off) for k, r in ratios.items()}


@dataclass(frozen=True, init=False)
class Verification:
    """Realised maxima of a law and their ratios to the limits: one record per limit.

    Built from the records (``checks``), or, as the maps below, from ``maxima``, ``ratios``,
    ``where`` and ``unset`` (keyword arguments; one record per entry of ``ratios``).

    Attributes
    ----------
    checks : Mapping of str to LimitCheck
        The record of each checked quantity ([`LimitCheck`][speedplan.timing.LimitCheck]),
        in report order (`LIMIT_NAMES`).
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

    ``maxima``, ``ratios``, ``where`` and ``unset`` are read-only views of ``checks``.

    Examples
    --------
    >>> from speedplan import Limits, Path, plan
    >>> prof = plan(Path.from_waypoints([[0, 0], [10, 0]], kind="polyline"),
    ...             Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5))
    >>> check = prof.verify()
    >>> check.ok, check.ratios["jerk"] <= 1.05, check.checks["jerk"].limit
    (True, True, 0.5)
    """

    checks: Mapping[str, LimitCheck]

    def __init__(self, checks: Mapping[str, LimitCheck] | Iterable[LimitCheck] | None = None,
                 *, maxima: Mapping[str, float] | None = None,
                 ratios: Mapping[str, float] | None = None,
                 where: Mapping[str, float] | None = None,
                 unset: Iterable[str] = frozenset()) -> None:
        if checks is None:
            records = _records(maxima or {}, ratios or {}, where or {}, unset)
        elif isinstance(checks, Mapping):
            records = dict(checks)
        else:
            records = {c.name: c for c in checks}
        object.__setattr__(self, "checks", records)
        # Read after every check of a plan: computed once (the records are immutable).
        object.__setattr__(self, "_ok", not any(c.exceeded for c in records.values()))

    # Shorthands for entries of ``maxima``, documented in the class docstring.
    max_speed = Forwarded[float]("maxima", key="speed")
    max_accel = Forwarded[float]("maxima", key="accel")
    max_decel = Forwarded[float]("maxima", key="decel")
    max_jerk = Forwarded[float]("maxima", key="jerk")
    max_lateral = Forwarded[float]("maxima", key="lateral")

    @property
    def maxima(self) -> dict[str, float]:
        """Largest realised value of each quantity (see the class docstring)."""
        return {k: c.maximum for k, c in self.checks.items() if c.maximum is not None}

    @property
    def ratios(self) -> dict[str, float]:
        """Each quantity's largest ratio to its limit (see the class docstring)."""
        return {k: c.ratio for k, c in self.checks.items()}

    @property
    def where(self) -> dict[str, float]:
        """Arc length [m] at which each ratio is largest."""
        return {k: c.where_s for k, c in self.checks.items() if c.where_s is not None}

    @property
    def unset(self) -> frozenset[str]:
        """The quantities whose limit is not set."""
        return frozenset(k for k, c in self.checks.items() if c.unset)

    @property
    def violations(self) -> dict[str, float]:
        """The ratios exceeding their tolerance."""
        return {k: c.ratio for k, c in self.checks.items() if c.exceeded}

    @property
    def ok(self) -> bool:
        """Whether every ratio is within its tolerance."""
        return bool(self.__dict__["_ok"])

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
        return "\n".join(c.line() for c in self.checks.values())

    @staticmethod
    def merged(parts: list[Verification]) -> Verification:
        """The worst of several verifications (legs of one profile).

        A quantity only some parts check (``"yaw_acc"`` of turns) is merged over those; it
        counts as not set when every part has it and none sets it. One part is its own worst.
        """
        if len(parts) == 1 and tuple(parts[0].checks) == tuple(
                k for k in LIMIT_NAMES if k in parts[0].checks):
            return parts[0]
        out = []
        for k in LIMIT_NAMES:
            have = [p.checks[k] for p in parts if k in p.checks]
            if not have:
                continue
            worst = max(have, key=lambda c: c.ratio if np.isfinite(c.ratio) else np.inf)
            peaks = [c.maximum for c in have if c.maximum is not None]
            out.append(LimitCheck(k, ratio=worst.ratio, maximum=max(peaks) if peaks else None,
                                  limit=worst.limit, where_s=worst.where_s,
                                  unset=len(have) == len(parts) and all(c.unset for c in have)))
        return Verification(out)


@dataclass(frozen=True)
class LegCheck:
    """`Verification` of one leg, and which of its pieces exceed a tolerance."""

    verification: Verification
    excess: np.ndarray  # bool per law piece
    knots: FloatArray  # the law's knots, leg arc length [m]


def curvature_rate(path: Path, s: FloatArray) -> FloatArray:
    """``dκ/ds`` [1/m²]: the path's exact rate (`speedplan.Path.curvature_rate`).

    Within ``δ = 1e-7`` of the path's length of a curvature jump (a G1 path,
    `speedplan.Path.curvature_jumps`) the rate is a Dirac: there it is the jump over the
    ``2 δ`` that straddle it (one-sided at the path's ends), so lateral jerk is unbounded
    there, which is what it is physically, unless the vehicle stands.
    """
    s = np.asarray(s, dtype=np.float64)
    rate = np.array(path.curvature_rate(s), dtype=np.float64)
    joins = path.curvature_jumps()[0]
    if not joins.size:
        return rate
    length = path.length
    delta = max(1e-7 * length, 1e-9)
    k = np.searchsorted(joins, s)  # the joins either side of each position
    near = np.minimum(np.abs(s - joins[np.maximum(k - 1, 0)]),
                      np.abs(s - joins[np.minimum(k, joins.size - 1)])) <= delta
    if near.any():
        q = s[near]
        lo, hi = np.clip(q - delta, 0.0, length), np.clip(q + delta, 0.0, length)
        both = np.asarray(path.curvature(np.concatenate((hi, lo))), dtype=np.float64)
        rate[near] = (both[:hi.size] - both[hi.size:]) / (hi - lo)
    return rate


@dataclass(frozen=True, eq=False)
class _Samples:
    """The law of one leg at its sample points, and the distinct positions they lie at.

    Samples: ``SAMPLES_PER_PIECE`` per piece plus its speed maximum (``shape``, row-major),
    then the bound's breakpoints inside the leg (``n_breaks``).
    """

    w: FloatArray
    v: FloatArray
    a: FloatArray
    spots: FloatArray  # distinct positions, leg arc length [m]
    sample_spot: IntArray  # index into ``spots`` of each sample
    shape: tuple[int, int]  # the pieces' samples
    n_breaks: int
    break_pieces: IntArray  # the piece(s) each breakpoint counts for


def _law_samples(law: SpeedLaw, top: FloatArray, local: FloatArray) -> _Samples:
    """The law at its samples, and where they lie (see `_Samples`).

    Each piece's `SAMPLES_PER_PIECE` points, its speed maximum ``top``, and the
    breakpoints ``local`` [m, leg arc length].
    """
    knots = law.knots
    width = np.diff(knots)
    m = width.size
    frac = np.linspace(0.0, 1.0, SAMPLES_PER_PIECE)
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
    return _Samples(w=np.concatenate((w_p.ravel(), w_b)), v=np.concatenate((v_p.ravel(), v_b)),
                    a=np.concatenate((a_p.ravel(), a_b)), spots=spots, sample_spot=sample_spot,
                    shape=(m, SAMPLES_PER_PIECE + 1), n_breaks=int(local.size),
                    break_pieces=extra_piece)


def _path_values(spots: FloatArray, path: Path, bound: Callable[[FloatArray], FloatArray]
                 ) -> tuple[FloatArray, FloatArray]:
    """The path's curvature [1/m] and the speed bound [m²/s²] at path arc lengths ``spots``."""
    if isinstance(bound, SpeedBound) and bound.path is path and bound.offset == 0.0:
        # The curvature is the bound's own (remembered from the grid where it has a memo).
        return bound.curvature_and_bound(spots)
    return (np.asarray(path.curvature(spots), dtype=np.float64),
            np.asarray(bound(spots), dtype=np.float64))


def _sampled_loads(smp: _Samples, spot_glob: FloatArray, path: Path,
                   bound: Callable[[FloatArray], FloatArray], limits: Limits
                   ) -> dict[str, tuple[FloatArray, FloatArray, float]]:
    """``name: (load, value, limit)`` of the path-dependent quantities at the samples.

    ``load / limit`` is the ratio (``"speed"``'s load is already one), ``value`` the
    realised quantity; a quantity without a limit is one 0.
    """
    kappa_spot, wb_spot = _path_values(spot_glob, path, bound)
    kappa = kappa_spot[smp.sample_spot]
    wb = wb_spot[smp.sample_spot]
    w, v, a = smp.w, smp.v, smp.a
    with np.errstate(divide="ignore", invalid="ignore"):
        speed = np.where(wb > 0, v / np.sqrt(wb), np.where(v > 0, np.inf, 0.0))
    lateral = kinematics.lateral_acceleration(np.abs(kappa), w)
    yaw = kinematics.yaw_rate(np.abs(kappa), v)
    if np.isfinite(limits.j_lat_max):
        rate = curvature_rate(path, spot_glob)[smp.sample_spot]
        lat_jerk = np.abs(kinematics.lateral_jerk(kappa, rate, w, a, v))
    else:
        lat_jerk = np.zeros(1)  # no limit: nothing to evaluate, reported as 0
    if limits.ellipse:  # the friction ellipse's radius, 1 on the ellipse
        grip = kinematics.friction_ellipse(a, lateral, limits.a_max, limits.a_decel,
                                           limits.a_lat_max)
    else:
        grip = np.zeros(1)  # not set: reported as 0
    return {"speed": (speed, v, 1.0), "lateral": (lateral, lateral, limits.a_lat_max),
            "yaw_rate": (yaw, yaw, limits.yaw_rate_max),
            "lateral_jerk": (lat_jerk, lat_jerk, limits.j_lat_max),
            "grip": (grip, grip, 1.0 if limits.ellipse else np.inf)}


def _sampled_checks(loads: dict[str, tuple[FloatArray, FloatArray, float]], smp: _Samples,
                    glob: FloatArray, excess: np.ndarray) -> dict[str, tuple[float, float, float]]:
    """``name: (maximum, ratio, where)`` of the sampled quantities; flags ``excess`` in place."""
    out = {}
    n_b = smp.n_breaks
    for name, (load, value, limit) in loads.items():
        if not np.isfinite(limit):  # no limit: the maximum is reported, the ratio is 0
            out[name] = (float(np.max(value)), 0.0, float(glob[0]))
            continue
        ratio_s = load / limit if name != "speed" else load
        ratio_s = np.where(np.isfinite(ratio_s), ratio_s, np.inf)
        k = int(np.argmax(ratio_s))
        out[name] = (float(np.max(value)), float(ratio_s[k]), float(glob[k]))
        over = ratio_s > 1.0 + TOLERANCES[name]
        excess |= over[: over.size - n_b].reshape(smp.shape).any(axis=1)
        if n_b:
            excess[smp.break_pieces[np.tile(over[over.size - n_b:], 2)]] = True
    return out


def _piece_checks(ex: PieceExtremes, knots: FloatArray, offset: float, limits: Limits,
                  excess: np.ndarray) -> dict[str, tuple[float, float, float]]:
    """``name: (maximum, ratio, where)`` of acceleration, braking and jerk.

    From the exact extremes of every piece; flags ``excess`` in place.
    """
    j_abs = np.maximum(ex.jerk.maximum, -ex.jerk.minimum)
    out = {}
    for name, per_piece, limit in (("accel", ex.a.maximum, limits.a_max),
                                   ("decel", -ex.a.minimum, limits.a_decel),
                                   ("jerk", j_abs, limits.j_max)):
        per_piece = np.where(np.isfinite(per_piece), per_piece, np.inf)
        k = int(np.argmax(per_piece))
        ratio = max(float(per_piece[k]) / limit, 0.0) if np.isfinite(limit) else 0.0
        out[name] = (max(float(per_piece[k]), 0.0), ratio,
                     float(offset + 0.5 * (knots[k] + knots[k + 1])))
        if np.isfinite(limit):
            excess |= per_piece > limit * (1.0 + TOLERANCES[name])
    return out


def check_law(law: SpeedLaw, offset: float, path: Path,
              bound: Callable[[FloatArray], FloatArray], limits: Limits,
              breaks: FloatArray | None = None, samples: CellSamples | None = None) -> LegCheck:
    """Check the law of one leg that covers ``[offset, offset + law.length]`` of ``path``.

    ``breaks``: arc lengths of ``path`` (`bound_breakpoints`, computed here when not
    given) where the path-dependent quantities are evaluated too, besides the samples.

    A law linear in ``w`` (no jerk nor lateral-jerk limit, no friction ellipse) is checked
    cell by cell (`check_linear_law`): the same points and the same verdicts, without the
    pieces' machinery; ``samples`` (the bound at its grid's `cell_points`, read from
    ``offset``, as the model evaluated it) spares evaluating the bound there again.
    """
    if breaks is None:
        breaks = bound_breakpoints(path, bound)
    if (isinstance(law, TimeLaw) and law.linear and not limits.ellipse
            and not np.isfinite(limits.j_lat_max)):
        linear = check_linear_law(law, offset, path, bound, limits, breaks, samples)
        if linear is not None:
            return linear
    return check_pieces(law, offset, path, bound, limits, breaks)


def check_pieces(law: SpeedLaw, offset: float, path: Path,
                 bound: Callable[[FloatArray], FloatArray], limits: Limits,
                 breaks: FloatArray) -> LegCheck:
    """`check_law` of any law: exact extremes of every piece, samples of every piece."""
    ex = law.extremes()
    knots = law.knots
    local = _local_breaks(breaks, offset, law.length)
    # Each piece's speed maximum is the sixth sample of the piece.
    smp = _law_samples(law, ex.w.at, local)
    spot_glob = offset + smp.spots
    excess = np.zeros(knots.size - 1, dtype=bool)
    found = _sampled_checks(_sampled_loads(smp, spot_glob, path, bound, limits), smp,
                            spot_glob[smp.sample_spot], excess)
    found.update(_piece_checks(ex, knots, offset, limits, excess))
    return LegCheck(_verification(found, limits), excess, knots)


def _local_breaks(breaks: FloatArray, offset: float, length: float) -> FloatArray:
    """The breakpoints inside ``[offset, offset + length]``, in the leg's arc length."""
    inside = breaks[(breaks >= offset) & (breaks <= offset + length)] - offset
    out: FloatArray = np.minimum(np.maximum(inside, 0.0), length)  # np.clip, without its dispatch
    return out


def _verification(found: dict[str, tuple[float, float, float]], limits: Limits) -> Verification:
    """The `Verification` of ``name: (maximum, ratio, where)``, in `LIMIT_NAMES` order."""
    limit_of = {"speed": limits.v_max, "accel": limits.a_max, "decel": limits.a_decel,
                "lateral": limits.a_lat_max, "jerk": limits.j_max,
                "yaw_rate": limits.yaw_rate_max, "lateral_jerk": limits.j_lat_max,
                "grip": 1.0 if limits.ellipse else np.inf}
    return Verification([LimitCheck(name, ratio=found[name][1], maximum=found[name][0],
                                    limit=float(limit_of[name]), where_s=found[name][2],
                                    unset=not math.isfinite(limit_of[name]))
                         for name in LIMIT_NAMES if name in found])


def check_linear_law(law: TimeLaw, offset: float, path: Path,
                     bound: Callable[[FloatArray], FloatArray], limits: Limits,
                     breaks: FloatArray, samples: CellSamples | None = None
                     ) -> LegCheck | None:
    """`check_law` of a law linear in ``w`` on every cell, from the nodes' ``w`` alone.

    Without jerk nor lateral-jerk limit (and without the friction ellipse), on each cell
    ``w`` is the chord and the acceleration ``(w_{k+1} - w_k) / (2 h_k)`` is constant: its
    extremes are the cells' own, the jerk is 0. The speed bound, lateral acceleration and yaw
    rate are evaluated where `check_pieces` evaluates them, at each piece's
    `SAMPLES_PER_PIECE` points (two pieces per cell: the `cell_points`, nodes included,
    where the speed maxima lie) and at the breakpoints; the maxima are found on ``w / mu+``
    and ``κ² w``, whose square roots are taken at the peak only, and where they tie, the
    first along the path is reported, as there. A piece is flagged for refinement when it
    holds a point beyond a tolerance, as there. ``None`` where a value is not finite (a bound
    of 0, a NaN): `check_pieces` reports it.

    Each quantity is one array over the points followed by the breakpoints (the order in
    which ties are resolved), so that a plan of a few nodes pays few numpy calls; the scalars
    read at the peaks are Python floats (the same IEEE operations as on numpy scalars).
    """
    s, w = law.s, np.maximum(law.w, 0.0)
    local = _local_breaks(breaks, offset, law.length)
    points, kappa, wb = _linear_samples(s, local, offset, path, bound, samples)
    m = points.size  # the points come first in every array below, then the breakpoints
    dw, h = w[1:] - w[:-1], s[1:] - s[:-1]
    w_all = _chord_values(s, w, dw, h, local)
    k_abs = np.abs(kappa)
    with np.errstate(divide="ignore", invalid="ignore"):
        speed2 = w_all / wb
    lateral = k_abs * w_all
    yaw2 = k_abs * lateral
    accel = 0.5 * (dw / h)  # constant on each cell, both its pieces
    # Where a limit is not set only the maximum is reported: any of its points will do.
    k_v = _first_peak(speed2, m, points)
    k_lat = _first_peak(lateral, m, points if math.isfinite(limits.a_lat_max) else None)
    k_yaw = _first_peak(yaw2, m, points if math.isfinite(limits.yaw_rate_max) else None)
    if k_v is None or k_lat is None or k_yaw is None or not np.isfinite(accel).all():
        return None
    glob = np.concatenate((points, local)) if local.size else points
    first = offset + float(points[0])
    found = {"speed": (math.sqrt(float(w_all.max())),
                       math.sqrt(float(w_all[k_v])) / math.sqrt(float(wb[k_v])),
                       offset + float(glob[k_v]))}
    for name, top, k, limit in (
            ("lateral", float(lateral[k_lat]), k_lat, limits.a_lat_max),
            ("yaw_rate", float(k_abs[k_yaw]) * math.sqrt(float(w_all[k_yaw])), k_yaw,
             limits.yaw_rate_max)):  # |κ| v where κ² w peaks
        found[name] = ((top, top / limit, offset + float(glob[k])) if math.isfinite(limit)
                       else (top, 0.0, first))
    for name in ("lateral_jerk", "grip"):  # not set for such a law: reported as 0
        found[name] = (0.0, 0.0, first)
    knots = law.knots
    i_acc, i_dec = int(accel.argmax()), int(accel.argmin())  # the first of any ties
    for name, i, top, limit in (("accel", i_acc, float(accel[i_acc]), limits.a_max),
                                ("decel", i_dec, -float(accel[i_dec]), limits.a_decel),
                                ("jerk", 0, 0.0, limits.j_max)):  # no jerk on the chords
        found[name] = (max(top, 0.0), max(top / limit, 0.0) if math.isfinite(limit) else 0.0,
                       offset + 0.5 * (float(knots[2 * i]) + float(knots[2 * i + 1])))
    check = _verification(found, limits)
    excess = np.zeros(knots.size - 1, dtype=bool)
    if not check.ok:
        _flag_linear(excess, knots, local, accel, limits,
                     (np.sqrt(speed2[:m]), np.sqrt(speed2[m:])), (lateral[:m], lateral[m:]),
                     (yaw2[:m], yaw2[m:]))
    return LegCheck(check, excess, knots)


def _linear_samples(s: FloatArray, local: FloatArray, offset: float, path: Path,
                    bound: Callable[[FloatArray], FloatArray], samples: CellSamples | None
                    ) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The `cell_points` of ``s``, and the curvature and bound there and at ``local``.

    The curvature and the bound are one array each: the points, then the breakpoints
    ``local``. From ``samples`` where they hold them (evaluated by the model), else computed.
    """
    if (samples is not None and samples.offset == offset
            and (samples.s is s or np.array_equal(samples.s, s))):
        points, kappa, wb = samples.points, samples.curvature, samples.bound
    else:
        samples = None
        points = cell_points(s)
        kappa, wb = _path_values(offset + points, path, bound)
    if not local.size:
        return points, kappa, wb
    if samples is not None and np.array_equal(samples.extra, local):
        kappa_b, wb_b = samples.extra_curvature, samples.extra_bound
    else:
        kappa_b, wb_b = _path_values(offset + local, path, bound)
    return points, np.concatenate((kappa, kappa_b)), np.concatenate((wb, wb_b))


def _chord_values(s: FloatArray, w: FloatArray, dw: FloatArray, h: FloatArray,
                  local: FloatArray) -> FloatArray:
    """``w`` on the chords at the `cell_points` of ``s``, then at the breakpoints ``local``."""
    n, m = s.size, CELL_POINTS * (s.size - 1) + 1
    out = np.empty(m + local.size)
    w_nodes, w_inner = cell_rows(out[:m])
    w_nodes[:] = w
    np.multiply(CELL_FRACTIONS, dw, out=w_inner)
    w_inner += w[:-1]
    if local.size:
        cell = np.minimum(np.maximum(np.searchsorted(s, local, side="right") - 1, 0), n - 2)
        np.maximum(w[cell] + dw[cell] * ((local - s[cell]) / h[cell]), 0.0, out=out[m:])
    return out



def _first_peak(values: FloatArray, m: int, points: FloatArray | None) -> int | None:
    """Where the largest of ``values`` lies (points ``[:m]``, then breakpoints), or ``None``.

    Among equal values the first along the path (``points``, their positions), points
    before breakpoints (the order of `check_pieces`); any of them when ``points`` is
    ``None``. ``None`` if a value is not finite.
    """
    k = int(values.argmax())  # the first largest value (a NaN is the largest)
    top = float(values[k])
    if not math.isfinite(top):
        return None
    if k >= m or points is None:
        return k
    main = values[:m]
    ties = np.flatnonzero(main == top)
    if ties.size == 1:  # the usual case off the bound
        return k
    # The points rise along each row of `cell_points` (the nodes, then each cell's k-th
    # point, in the cells' order): the first tie at the least point is the first along the
    # path, and of equal points the one in the first row, as the rows' first ties would give.
    return int(ties[np.argmin(points[ties])])


def _flag_linear(excess: np.ndarray, knots: FloatArray, local: FloatArray, accel: FloatArray,
                 limits: Limits, speed: tuple[FloatArray, FloatArray],
                 lateral: tuple[FloatArray, FloatArray], yaw2: tuple[FloatArray, FloatArray]
                 ) -> None:
    """Flag (in place) the pieces of a linear law holding a point beyond a tolerance."""
    over, over_b = (speed[0] > 1.0 + TOLERANCES["speed"], speed[1] > 1.0 + TOLERANCES["speed"])
    for name, (load, load_b), limit in (("lateral", lateral, limits.a_lat_max),
                                        ("yaw_rate", yaw2, limits.yaw_rate_max)):
        if np.isfinite(limit):
            if name == "yaw_rate":  # |κ| v from κ² w
                load, load_b = np.sqrt(load), np.sqrt(load_b)
            over |= load / limit > 1.0 + TOLERANCES[name]
            over_b |= load_b / limit > 1.0 + TOLERANCES[name]
    nodes, inner = cell_rows(over)
    half = CELL_POINTS // 2  # the cell's middle point ends its first piece, starts its second
    excess[0::2] = nodes[:-1] | inner[:half].any(axis=0)
    excess[1::2] = inner[half - 1:].any(axis=0) | nodes[1:]
    for name, per_cell, limit in (("accel", accel, limits.a_max), ("decel", -accel,
                                                                   limits.a_decel)):
        if np.isfinite(limit):
            cell = per_cell > limit * (1.0 + TOLERANCES[name])
            excess[0::2] |= cell
            excess[1::2] |= cell
    m = knots.size - 1  # each breakpoint counts for the piece(s) it lies in
    for side in ("right", "left"):
        piece = np.clip(np.searchsorted(knots, local, side=side) - 1, 0, m - 1)
        excess[piece[over_b]] = True
