"""Paths through waypoints: polyline with rounded corners, arc-length cubic spline, G1 clothoids."""

from __future__ import annotations

from typing import Any

import numpy as np
from scipy.interpolate import CubicSpline

from .._checks import FloatArray, as_array, as_scalar, choice
from ..errors import InvalidInputError
from .pieces import ClothoidPiece, CurvePiece, Piece

__all__ = ["KINDS", "fit_clothoid", "fit_waypoints"]

KINDS = ("clothoid", "spline", "polyline")
#: Default corner rounding of polylines: each corner arc starts this fraction of the shorter
#: adjacent leg before the corner (scale-free, so millimetres and metres give the same path).
CORNER_FRACTION = 0.25

_GX, _GW = np.polynomial.legendre.leggauss(64)
_GX, _GW = 0.5 * (_GX + 1.0), 0.5 * _GW


def _wrap(a: FloatArray | float) -> Any:
    return (np.asarray(a) + np.pi) % (2 * np.pi) - np.pi


def check_waypoints(xy: Any, name: str = "xy") -> FloatArray:
    """Validate waypoints: shape (n, 2), n >= 2, finite, no consecutive duplicates."""
    pts = as_array(name, xy)
    if pts.ndim != 2 or pts.shape[1] != 2 or pts.shape[0] < 2:
        raise InvalidInputError(
            f"`{name}` must have shape (n, 2) with n >= 2; got {pts.shape}"
        )
    legs = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    scale = max(float(np.ptp(pts, axis=0).max()), 1e-300)
    if (legs <= 1e-12 * scale).any():
        i = int(np.flatnonzero(legs <= 1e-12 * scale)[0])
        if scale <= 1e-300 or np.all(legs <= 1e-12 * scale):
            raise InvalidInputError(f"`{name}` needs at least two distinct points")
        raise InvalidInputError(
            f"`{name}` has repeated consecutive points at rows {i} and {i + 1}; remove duplicates"
        )
    return pts


def fit_clothoid(p0: FloatArray, theta0: float, p1: FloatArray, theta1: float) -> ClothoidPiece:
    """The clothoid from ``(p0, theta0)`` to ``(p1, theta1)`` (G1 Hermite interpolation).

    Bertolazzi & Frego's formulation: in the frame of the chord the heading is
    ``θ(t) = A t² + (δ - A) t + φ0`` for ``t ∈ [0, 1]``; ``A`` solves ``∫ sin θ = 0`` (Newton),
    then ``L = |p1 - p0| / ∫ cos θ``.
    """
    d = np.asarray(p1, dtype=np.float64) - np.asarray(p0, dtype=np.float64)
    r = float(np.hypot(*d))
    phi = float(np.arctan2(d[1], d[0]))
    phi0 = float(_wrap(theta0 - phi))
    phi1 = float(_wrap(theta1 - phi))
    delta = phi1 - phi0
    t = _GX

    def theta(A: float) -> FloatArray:
        out: FloatArray = A * t * t + (delta - A) * t + phi0
        return out

    A = 3.0 * (phi0 + phi1)
    for _ in range(100):
        th = theta(A)
        g = float(np.sin(th) @ _GW)
        dg = float(((t * t - t) * np.cos(th)) @ _GW)
        step = g / dg if dg != 0 else 0.0
        A -= step
        if abs(step) <= 1e-15 * max(1.0, abs(A)):
            break
    th = theta(A)
    if abs(float(np.sin(th) @ _GW)) > 1e-12 or float(np.cos(th) @ _GW) <= 0:
        raise InvalidInputError(
            f"no clothoid joins ({p0[0]:.6g}, {p0[1]:.6g}) to ({p1[0]:.6g}, {p1[1]:.6g}) with the "
            "requested headings; add an intermediate waypoint"
        )
    L = r / float(np.cos(th) @ _GW)
    return ClothoidPiece((float(p0[0]), float(p0[1])), float(theta0), L, (delta - A) / L,
                         (delta + A) / L)


def _estimate_headings(pts: FloatArray) -> FloatArray:
    """Tangent directions of a chord-parametrised cubic spline through the points."""
    if pts.shape[0] == 2:
        d = pts[1] - pts[0]
        return np.full(2, np.arctan2(d[1], d[0]))
    tau = np.concatenate(([0.0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))))
    closed = np.allclose(pts[0], pts[-1])
    cs = CubicSpline(tau, pts, bc_type="periodic" if closed else "not-a-knot")
    d1 = cs(tau, 1)
    out: FloatArray = np.arctan2(d1[:, 1], d1[:, 0])
    return out


def _clothoid_chain(pts: FloatArray, headings: Any) -> list[Piece]:
    if headings is None:
        th = _estimate_headings(pts)
    else:
        th = as_array("headings", headings, ndim=1, length=pts.shape[0])
    return [fit_clothoid(pts[i], float(th[i]), pts[i + 1], float(th[i + 1]))
            for i in range(pts.shape[0] - 1)]


def _spline(pts: FloatArray) -> list[Piece]:
    tau = np.concatenate(([0.0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))))
    if pts.shape[0] == 2:
        cs = CubicSpline(tau, pts, bc_type="natural")
    else:
        closed = np.allclose(pts[0], pts[-1])
        cs = CubicSpline(tau, pts, bc_type="periodic" if closed else "not-a-knot")

    def curve(t: FloatArray, nu: int) -> FloatArray:
        out: FloatArray = cs(np.asarray(t), nu).reshape(-1, 2)
        return out

    return [CurvePiece(curve, tau)]


def _polyline(pts: FloatArray, max_deviation: float | None) -> list[Piece]:
    d = np.diff(pts, axis=0)
    legs = np.linalg.norm(d, axis=1)
    head = np.arctan2(d[:, 1], d[:, 0])
    turn = _wrap(np.diff(head))
    if (np.abs(turn) > np.pi - 1e-9).any():
        i = int(np.flatnonzero(np.abs(turn) > np.pi - 1e-9)[0]) + 1
        raise InvalidInputError(
            f"`xy` reverses direction at row {i} (a cusp); a path cannot turn by 180°"
        )
    # Tangent length of each corner arc, capped at half of each adjacent leg.
    half_tan = np.tan(0.5 * np.abs(turn))
    cap = 0.5 * np.minimum(legs[:-1], legs[1:])
    if max_deviation is None:
        tangent = CORNER_FRACTION * np.minimum(legs[:-1], legs[1:])
    else:
        dev = as_scalar("max_deviation", max_deviation, nonnegative=True)
        with np.errstate(divide="ignore", invalid="ignore"):
            radius = dev / (1.0 / np.cos(0.5 * turn) - 1.0)
        tangent = np.minimum(np.where(np.isfinite(radius), radius * half_tan, cap), cap)
    tangent = np.where(np.abs(turn) < 1e-12, 0.0, tangent)
    if max_deviation is not None and (tangent == 0).any() and (np.abs(turn) >= 1e-12).any():
        sharp = np.flatnonzero((tangent == 0) & (np.abs(turn) >= 1e-12))
        if sharp.size:
            raise InvalidInputError(
                "`max_deviation`=0 leaves sharp corners (infinite curvature) at rows "
                f"{(sharp + 1).tolist()}; a vehicle must stop there — pass max_deviation > 0 "
                "or split the path at the corners"
            )
    pieces: list[Piece] = []
    start = pts[0]
    before = np.concatenate(([0.0], tangent))
    after = np.concatenate((tangent, [0.0]))
    for i in range(legs.size):
        straight = legs[i] - before[i] - after[i]
        p = pts[i] + d[i] / legs[i] * before[i]
        if straight > 1e-12 * legs[i]:
            pieces.append(ClothoidPiece((float(p[0]), float(p[1])), float(head[i]), float(straight),
                                        0.0, 0.0))
        if i < turn.size and tangent[i] > 0:
            radius = tangent[i] / half_tan[i]
            p = pts[i + 1] - d[i] / legs[i] * tangent[i]
            k = float(np.sign(turn[i]) / radius)
            pieces.append(ClothoidPiece((float(p[0]), float(p[1])), float(head[i]),
                                        float(radius * abs(turn[i])), k, k))
    del start
    return pieces


def fit_waypoints(
    xy: Any,
    kind: str = "clothoid",
    *,
    headings: Any = None,
    max_deviation: float | None = None,
) -> tuple[Piece, ...]:
    """Pieces of a path through the waypoints ``xy`` (shape (n, 2), metres).

    Parameters
    ----------
    xy : array_like, shape (n, 2)
        Waypoints [m]; n >= 2, finite, no consecutive duplicates.
    kind : {"clothoid", "spline", "polyline"}
        ``"clothoid"`` (default): one clothoid per leg (curvature linear in s), tangent-continuous
        (G1) at every waypoint, passing through every waypoint exactly; headings from ``headings``
        or, by default, from a cubic spline through the points. ``"spline"``: a cubic spline,
        reparametrised by true arc length (C², curvature continuous). ``"polyline"``: straight
        legs whose corners are rounded by circular arcs.
    headings : array_like, optional
        Headings [rad] at the waypoints (``"clothoid"`` only).
    max_deviation : float, optional
        ``"polyline"`` only: largest distance [m] between a corner and its rounding arc. By
        default each arc starts a quarter of the shorter adjacent leg before the corner (a
        corner of zero radius would force the vehicle to stop; rounding keeps the path
        drivable and is independent of the unit of length). ``0`` keeps sharp corners and is
        rejected, because the speed bound there is zero.
    """
    choice("kind", kind, KINDS)
    pts = check_waypoints(xy)
    if headings is not None and kind != "clothoid":
        raise InvalidInputError("`headings` applies to kind='clothoid' only")
    if max_deviation is not None and kind != "polyline":
        raise InvalidInputError("`max_deviation` applies to kind='polyline' only")
    if kind == "clothoid":
        return tuple(_clothoid_chain(pts, headings))
    if kind == "spline":
        return tuple(_spline(pts))
    return tuple(_polyline(pts, max_deviation))
