"""Independent oracles for the physics tests: ruckig and finite differences of sampled states.

Nothing here calls speedplan's own checks (``verify()``, ``TOLERANCES``): the promised
tolerances are written out, and the sampled trajectory is judged by its own numbers.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
from ruckig import InputParameter, Result, Ruckig, Trajectory

#: What the README promises at the default resolution (fractions of each limit).
PROMISED = {"speed": 0.001, "accel": 0.01, "lateral": 0.01, "jerk": 0.05}


@dataclass(frozen=True)
class RuckigAnswer:
    """ruckig's time-optimal 1-D motion, or why there is none.

    ``duration`` is ``None`` when ruckig finds no motion, or when the motion it returns
    leaves ``0 <= v <= v_max`` (ruckig's braking pre-trajectory does, for states it cannot
    keep within the limits: then no valid motion exists). ``error`` holds ruckig's own
    failure message when it raised (a numerical failure of ruckig, not a verdict).
    """

    duration: float | None
    error: str | None = None


def ruckig_move(length, lim, v0=0.0, a0=0.0, vf=0.0, af=0.0):
    """ruckig on the straight move, forward only (``min_velocity = 0``)."""
    otg = Ruckig(1)
    inp = InputParameter(1)
    inp.current_position, inp.current_velocity, inp.current_acceleration = [0.0], [v0], [a0]
    inp.target_position, inp.target_velocity, inp.target_acceleration = [length], [vf], [af]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = [lim.v_max], [lim.a_max], [lim.j_max]
    inp.min_acceleration = [-lim.a_decel]
    inp.min_velocity = [0.0]
    traj = Trajectory(1)
    try:
        result = otg.calculate(inp, traj)
    except Exception as exc:  # ruckig.RuckigError: its own numerical failure
        return RuckigAnswer(None, " ".join(str(exc).split())[:120])
    if result != Result.Working:
        return RuckigAnswer(None)
    T = traj.duration
    # Dense near both ends, where a braking pre-trajectory would leave the limits: over the
    # time a full change of acceleration and speed takes (a 48 km move's dip below 0 at
    # 6.8 s, from a0 = -0.27 at j_max = 0.04, fell between samples 8 s apart).
    a_hi, a_lo = max(lim.a_max, lim.a_decel), min(lim.a_max, lim.a_decel)
    edge = min(T, max(5.0, 3.0 * (a_hi / lim.j_max + lim.v_max / a_lo)))
    t = np.unique(np.concatenate((np.linspace(0, edge, 8001), np.linspace(0, T, 4001),
                                  np.linspace(T - edge, T, 8001))))
    vel = np.array([traj.at_time(x)[1][0] for x in t])
    if vel.min() < -1e-9 * lim.v_max or vel.max() > lim.v_max * (1 + 1e-9):
        return RuckigAnswer(None)
    return RuckigAnswer(T)


def ruckig_duration(length, lim, **states):
    """ruckig's exact optimum of a straight move (it must exist)."""
    answer = ruckig_move(length, lim, **states)
    assert answer.duration is not None, answer
    return answer.duration


@dataclass(frozen=True)
class Measured:
    """Largest ratios to the limits found by finite differences of a sampled trajectory."""

    speed: float
    accel: float
    decel: float
    jerk: float
    lateral: float
    samples: int
    #: What a rounding of the sampled speeds and times by a few ulps adds to the acceleration
    #: and jerk ratios (first and second differences over the shortest step): the finite
    #: differences of an exact trajectory stay within ``1 + rounding``.
    accel_rounding: float = 0.0
    jerk_rounding: float = 0.0


def measure(profile, samples=20_000):
    """Sample ``profile`` in time and finite-difference it.

    Three uniform stretches of ``samples / 3`` each: the first and last ``T1`` seconds
    (where a straight move changes speed; ``T1`` covers a full acceleration from rest:
    ``3 (a/j + v_max/a)``) and the whole duration; each is differenced on its own. Speed
    against the local bound ``sqrt(speed_bound(s))``; acceleration and jerk from differences
    of the sampled speed (positions only confirm the speed: at long durations their rounding
    would swamp a third difference); lateral acceleration from the sampled curvature.
    """
    lim = profile.limits
    T = profile.duration
    t1 = min(T, 3.0 * (max(lim.a_max, lim.a_decel) / lim.j_max + lim.v_max / min(lim.a_max,
                                                                               lim.a_decel)))
    per = max(samples // 3, 10)
    worst = {"speed": 0.0, "accel": 0.0, "decel": 0.0, "jerk": 0.0, "lateral": 0.0,
             "accel_rounding": 0.0, "jerk_rounding": 0.0}
    count = 0
    for lo, hi in ((0.0, t1), (max(T - t1, 0.0), T), (0.0, T)):
        t = np.linspace(lo, hi, per)
        dt = t[1] - t[0]
        if not dt > 0:
            continue
        traj = profile.at(t)
        v, s = traj.v, traj.s
        bound = np.sqrt(profile.speed_bound(s))
        with np.errstate(divide="ignore", invalid="ignore"):
            speed = np.where(bound > 0, v / bound, np.where(v > 0, np.inf, 0.0))
        a_fd = np.diff(v) / dt
        j_fd = np.diff(a_fd) / dt
        v_fd = np.diff(s) / dt
        v_mid = 0.5 * (v[1:] + v[:-1])
        # Trapezoid rule: |Δs/dt - (v0 + v1)/2| <= j dt²/12 for any motion with |jerk| <= j.
        # (plus the rounding of s(t), ~1e-15 of the duration and of the length).
        noise = 4e-15 * (T * lim.v_max + max(s[-1], 1.0)) / dt
        slack = 1.05 * lim.j_max * dt * dt / 12 + 1e-9 * lim.v_max + noise
        assert np.abs(v_fd - v_mid).max() <= slack, "positions and speeds disagree"
        lateral = np.abs(traj.curvature * v**2)
        worst["speed"] = max(worst["speed"], float(speed.max()))
        worst["accel"] = max(worst["accel"], float(max(a_fd.max(), 0.0) / lim.a_max))
        worst["decel"] = max(worst["decel"], float(max(-a_fd.min(), 0.0) / lim.a_decel))
        worst["jerk"] = max(worst["jerk"], float(np.abs(j_fd).max() / lim.j_max))
        if np.isfinite(lim.a_lat_max):
            worst["lateral"] = max(worst["lateral"], float(lateral.max() / lim.a_lat_max))
        # A few ulps of each speed, and of each sample time (times the acceleration).
        ulps = 4.0 * np.finfo(float).eps * (float(np.abs(v).max())
                                            + max(lim.a_max, lim.a_decel) * hi)
        worst["accel_rounding"] = max(worst["accel_rounding"],
                                      2.0 * ulps / dt / min(lim.a_max, lim.a_decel))
        worst["jerk_rounding"] = max(worst["jerk_rounding"], 4.0 * ulps / dt**2 / lim.j_max)
        count += t.size
    return Measured(samples=count, **worst)


def within_promise(m: Measured) -> bool:
    """Whether the measured ratios meet the README's tolerances."""
    return (m.speed <= 1 + PROMISED["speed"] and m.accel <= 1 + PROMISED["accel"]
            and m.decel <= 1 + PROMISED["accel"] and m.jerk <= 1 + PROMISED["jerk"]
            and m.lateral <= 1 + PROMISED["lateral"])


def no_jerk_lower_bound(bound, length, a_max, a_decel, v0=0.0, vf=0.0, samples=400_001):
    """A lower bound on the exact minimum time without a jerk limit [s], and its ``w``.

    The continuous problem: ``w(s) <= bound(s)``, ``-2 a_decel <= w' <= 2 a_max``,
    ``w(0) = v0²``, ``w(L) = vf²``. Its fastest law is the largest feasible ``w``, the
    inf-convolution ``min_x [bound(x) + 2 a_max (s - x)⁺ + 2 a_decel (x - s)⁺]``; taken over
    ``samples`` points only it is larger (a dip between them is missed), and between two
    samples it lies under both slope-limited lines from their values: integrating ``1 / v``
    under that tent, in closed form, gives a time that no feasible law beats.
    """
    s = np.linspace(0.0, length, samples)
    mu = np.asarray(bound(s), dtype=np.float64).copy()
    mu[0], mu[-1] = min(mu[0], v0 * v0), min(mu[-1], vf * vf)
    A, D = 2.0 * a_max, 2.0 * a_decel
    forward = A * s + np.minimum.accumulate(mu - A * s)
    backward = -D * s + np.minimum.accumulate((mu + D * s)[::-1])[::-1]
    w = np.maximum(np.minimum(forward, backward), 0.0)
    h = np.diff(s)
    wa, wb = w[:-1], w[1:]
    tc = np.clip((wb - wa + D * h) / (A + D), 0.0, h)  # where the two lines cross
    up = np.sqrt(wa + A * tc)
    down = np.sqrt(wb + D * (h - tc))
    with np.errstate(divide="ignore", invalid="ignore"):
        first = np.where(tc > 0, 2.0 * tc / (up + np.sqrt(wa)), 0.0)
        second = np.where(h - tc > 0, 2.0 * (h - tc) / (down + np.sqrt(wb)), 0.0)
    return float(np.sum(first + second)), s, w


@dataclass(frozen=True)
class IpoptAnswer:
    """CasADi + IPOPT on a discrete problem's plain formulation.

    ``w`` has the fixed end values; ``violation_price`` is the travel time IPOPT's point buys
    by violating its rows and bounds, to first order, relative to its objective
    (:func:`ipopt_plain`).
    """

    w: np.ndarray
    success: bool
    status: str
    violation_price: float


def interior_bounds(p):
    """``[max(w_min, 1e-9 max(1, max w_max)), w_max]`` on every node (as speedplan's bounds)."""
    ub = p.w_max.astype(np.float64)
    lb = np.minimum(1e-9 * max(1.0, float(np.max(p.w_max))), ub)
    if p.w_min is not None:
        lb = np.maximum(lb, p.w_min)
    return lb, ub


def ipopt_plain(p, w0, options=None):
    """IPOPT (``options`` on top of its defaults) on ``min Σ τ_i / sqrt(w_i)`` from ``w0``.

    The plain formulation, written independently of speedplan's solvers: rows
    ``w_{i+1} - w_i ∈ [-decel_i h_i, accel_i h_i]`` and ``(c · w) sqrt(w_i) ∈ [-B_i, B_i]``
    for every stencil family (rows with an infinite bound left out), bounds
    :func:`interior_bounds`.

    IPOPT stops once rows hold to ``constr_viol_tol`` and relaxes its bounds by
    ``bound_relax_factor``; near a standstill that sliver of violation buys travel time that
    no feasible point has. Relaxing row ``i`` by ``δ_i`` lowers the optimum by ``|λ_i| δ_i``
    to first order (``λ_i`` its multiplier), so ``objective (1 + violation_price)``, with
    ``violation_price = Σ |λ_i| max(violation_i, 0) / objective`` from IPOPT's own
    multipliers, is its objective at equal feasibility to first order (take the objective at
    ``w`` as returned: clipping it into the bounds would pay for their share a second time).
    """
    import casadi as ca

    x = ca.SX.sym("w", p.n - 2)
    wf = ca.vertcat(p.w_start, x, p.w_end)
    rows, lbg, ubg = [wf[1:] - wf[:-1]], [-p.decel * p.h], [p.accel * p.h]
    for fam in p.stencil_families():
        keep = np.flatnonzero(np.isfinite(fam.bound))
        if keep.size:
            stencil = ca.DM(p.stencil_matrix(fam.coef)[keep].tocsc())
            rows.append(ca.mtimes(stencil, wf) * ca.sqrt(x[keep.tolist()]))
            lbg.append(-fam.bound[keep])
            ubg.append(fam.bound[keep])
    solver = ca.nlpsol("plain", "ipopt", {"x": x, "f": ca.sum1(ca.DM(p.tau) / ca.sqrt(x)),
                                          "g": ca.vertcat(*rows)},
                       {"ipopt": {"print_level": 0, "sb": "yes", **(options or {})},
                        "print_time": False})
    lb, ub = (b[1:-1] for b in interior_bounds(p))
    lo_g, hi_g = np.concatenate(lbg), np.concatenate(ubg)
    sol = solver(x0=np.clip(w0[1:-1], lb, ub), lbx=lb, ubx=ub, lbg=lo_g, ubg=hi_g)
    stats = solver.stats()
    x_opt = np.asarray(sol["x"]).ravel()
    g_val = np.asarray(sol["g"]).ravel()
    viol_g = np.maximum(np.maximum(g_val - hi_g, lo_g - g_val), 0.0)
    viol_x = np.maximum(np.maximum(x_opt - ub, lb - x_opt), 0.0)
    bought = (np.abs(np.asarray(sol["lam_g"]).ravel()) @ viol_g
              + np.abs(np.asarray(sol["lam_x"]).ravel()) @ viol_x)
    return IpoptAnswer(w=np.concatenate(([p.w_start], x_opt, [p.w_end])),
                       success=bool(stats["success"]), status=str(stats["return_status"]),
                       violation_price=float(bought / float(sol["f"])))


def corner_reversals(traj, j_max, threshold=0.25):
    """Sign reversals of the jerk column in each corner (a run of samples with ``κ != 0``).

    Only samples with ``|j| >= threshold * j_max`` count, so a jerk that merely crosses zero
    between phases is not counted. The column, not a finite difference of ``a``, is what a
    controller that feeds the jerk forward reads: a chatter at the grid's frequency (steps of
    a few millimetres, faster than 100 Hz at walking speed) is invisible in differences of
    the sampled ``a`` but not in the column.
    """
    jerk = np.asarray(traj.j)
    curved = np.abs(np.asarray(traj.curvature)) > 1e-12
    edges = np.flatnonzero(np.diff(np.concatenate(([0], curved.astype(int), [0]))))
    counts = []
    for lo, hi in zip(edges[::2], edges[1::2], strict=True):
        j = jerk[lo:hi]
        signs = np.sign(j[np.abs(j) >= threshold * j_max])
        counts.append(int(np.count_nonzero(np.diff(signs))))
    return counts
def ruckig_turn(angle, rate_max, acc_max, jerk_max=np.inf):
    """ruckig's time-optimal rest-to-rest rotation by ``angle`` [rad] (default: no jerk limit)."""
    otg = Ruckig(1)
    inp = InputParameter(1)
    inp.current_position, inp.target_position = [0.0], [abs(angle)]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = [rate_max], [acc_max], [jerk_max]
    traj = Trajectory(1)
    assert otg.calculate(inp, traj) == Result.Working
    return traj.duration


def assert_physical(profile, length, lim, **states):
    """A straight move within the promised tolerances, never faster than ruckig beyond 1e-4."""
    m = measure(profile, samples=12_000)
    assert within_promise(m), m
    assert profile.duration >= ruckig_duration(length, lim, **states) * (1 - 1e-4)
    assert profile.status in ("optimal", "refined")


@contextlib.contextmanager
def subdivided_default_grids(k: int) -> Iterator[None]:
    """``plan()``'s default grids with every cell cut into ``k`` equal steps.

    The reference of a convergence check: the same grid family, ``k`` times finer everywhere
    (Richardson's extrapolation over ``k = 2, 4`` gives the converged duration). The planning
    strategy's coarser grids are off meanwhile: where a solver stalls on the finer grid, the
    other backend answers on that same grid, instead of a coarser grid that the reference
    would silently compare with itself.
    """
    from speedplan import strategy
    from speedplan.model import leg_grid

    original, coarser = leg_grid.default_grid, strategy.COARSER_GRIDS

    def finer(*args, **kw):
        s = original(*args, **kw)
        inner = (s[:-1, None] + np.diff(s)[:, None] * (np.arange(k) / k)[None, :]).ravel()
        return np.append(inner, s[-1])

    leg_grid.default_grid, strategy.COARSER_GRIDS = finer, ()
    try:
        yield
    finally:
        leg_grid.default_grid, strategy.COARSER_GRIDS = original, coarser
