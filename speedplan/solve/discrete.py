"""Solve the discrete problem to certified optimality: pass, relaxation, refinement.

The algorithm is the paper's (Section "Solution algorithm"):

1. without jerk rows, the exact forward/backward pass (no solver);
2. otherwise the SOCP relaxation, whose dual objective is a certified lower bound;
3. if its ``w`` meets every jerk row (violation <= 1e-5) it is globally optimal
   (Observation 1); otherwise IPOPT refines from it and the optimum lies in
   ``[lower_bound, objective]``.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Callable
from dataclasses import replace
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from ..core.checks import FloatArray, as_array, as_scalar, broadcast_positive, grid_size
from ..core.deadline import passed
from ..core.errors import InfeasibleError, InvalidInputError, SolverError, SpeedplanWarning
from ..core.options import BACKENDS, REFINE_MODES, Backend, Refine, RelaxationBackend, check_option
from .banded import (
    _lagrangian_bound,
    check_grid_resolvable,
    kernel_for_auto,
    solve_unit_relaxation,
    unit_scales,
)
from .clarabel_ import RelaxationResult, row_multipliers, solve_relaxation
from .cuts import secant_cuts
from .nojerk import check_reachable, max_feasible_w, positive_feasible_w
from .problem import GRIP_TOL, ROW_TOL_REL, DiscreteProblem
from .refine import refine as refine_nlp
from .solution import DiscreteSolution, RefinementInfo, RelaxationInfo, Status

__all__ = ["BACKENDS", "CUT_GAP", "CUT_MAX_NODES", "CUT_PAD", "CUT_SECONDS", "POLISH_GAP",
           "REFINE_MODES", "RELAXATION_BACKENDS", "solve_discrete", "solve_problem"]

#: Relaxation backends by name (the names of `speedplan.core.options.RelaxationBackend`);
#: each maps a problem in the units of `unit_scales`, boundary values checked, to a
#: RelaxationResult.
RELAXATION_BACKENDS: dict[str, Callable[[DiscreteProblem], RelaxationResult]] = {
    "clarabel": solve_relaxation,
    "banded": solve_unit_relaxation,
}
#: ``backend="auto"`` uses the banded interior-point method from this many nodes on (it is
#: 5-8x faster than Clarabel from 100 to 500 nodes, measured); below, both take a few
#: milliseconds and Clarabel, the reference, is used.
AUTO_BANDED_FROM = 100
#: A relaxation that is not exact and leaves a certified gap above this (relative) is solved
#: again with the secant cuts of its stencil rows (`speedplan.solve.cuts`), by Clarabel, for
#: a tighter lower bound.
CUT_GAP = 5e-3
#: The cuts are added at the nodes where the relaxed ``w`` exceeds a stencil row and this many
#: nodes on either side (every cut at once made the relaxation of a 1 172-node road curve
#: stall in Clarabel; the nodes where the relaxation pays for an excess carry the bound).
CUT_PAD = 3
#: The least time [s] Clarabel gets for the relaxation with cuts; it gets as long as the solve
#: before it took, if longer. The cuts only tighten the certificate (the plan is the same), and
#: Clarabel is the only backend that holds them: solved to the end, a cubic spline through 300
#: waypoints with comfort limits (18 248 nodes) took 19.5 s there after a 1.2 s solve. Stopped
#: earlier, its last iterate's multipliers still bound the travel time (weak duality): on a
#: spline through 100 waypoints (5 353 nodes) that bound passes the relaxation's own after
#: about 1 s (gap 1.10 % -> 0.55 %; 0.26 % at the end of the solve, 2.3 s).
CUT_SECONDS = 1.0
#: Above this many nodes the relaxation is not solved again with cuts: Clarabel's iterations
#: grow with the grid (31 ms at 5 353 nodes with 5 601 cuts, about 0.2 s at 18 248), and on
#: the 300-waypoint spline 1.2 s of them gave a bound far below the relaxation's, after 0.9 s
#: of building the cuts.
CUT_MAX_NODES = 10_000
#: An exact relaxation whose own certified gap (objective against lower bound, relative) is
#: above this was stopped short of its optimum (Clarabel's reduced accuracy, "AlmostSolved":
#: 2.3e-6 slower than the optimum on a 27 m straight grid, with a gap of 1.5e-5); the
#: refinement then polishes its point, so that both backends agree to this (the banded
#: kernel accepts no stop above it, `speedplan.solve._banded_ipm.ALMOST_GAP`).
POLISH_GAP = 1e-6
#: A refined point slower than the relaxed one by more than this (relative), where the
#: relaxed point meets every row within the acceptance tolerance, went astray (`_refined`).
ASTRAY_GAP = 1e-3
#: Until the banded kernel is compiled (first use after installation, 20-30 s; see
#: `kernel_ready`), ``"auto"`` answers with Clarabel below this
#: many nodes while a background process compiles it; from this size on Clarabel would take
#: about as long as the compilation (16 s at 10^5 nodes), so ``"auto"`` waits for it.
AUTO_WAIT_FROM = 100_000


def _linear_tol(problem: DiscreteProblem) -> float:
    return 1e-7 * max(1.0, float(np.max(problem.w_max)))


def _scale_into_jerk_bounds(problem: DiscreteProblem, w: FloatArray) -> FloatArray | None:
    """Shrink ``w`` uniformly until every jerk row holds (only when both ends are at rest).

    ``c w`` keeps every linear row and scales ``w'' sqrt(w)`` by ``c^1.5``.
    """
    if problem.w_start != 0.0 or problem.w_end != 0.0 or problem.has_lower_bounds:
        return None
    wpp = np.abs(problem.stencil_apply(problem.second_difference_weights, w))
    load = wpp * np.sqrt(np.maximum(w[1:-1], 0.0))
    finite = np.isfinite(problem.jerk) & (load > 0)
    if not finite.any():
        return w
    c = float(min(1.0, np.min(problem.jerk[finite] / load[finite]) ** (2.0 / 3.0)))
    return w * (c * (1.0 - 1e-12))


def _auto_backend(problem: DiscreteProblem) -> RelaxationBackend:
    """``backend="auto"``: banded from `AUTO_BANDED_FROM` nodes on, once it is compiled.

    Friction-ellipse rows are Clarabel's alone (the banded kernel holds no cone of them).
    """
    if problem.n < AUTO_BANDED_FROM or problem.has_grip:
        return "clarabel"
    return "banded" if kernel_for_auto(wait=problem.n >= AUTO_WAIT_FROM) else "clarabel"


def _arriving(relax: RelaxationResult, unit: DiscreteProblem, backend: str) -> RelaxationResult:
    """``relax``, unless its ``w`` reaches 0 at an interior node (the law would not arrive).

    An optimum of the relaxation never stops inside a leg (its travel time would be
    infinite); a ``w`` that does is a stall reported as solved to reduced accuracy
    (Clarabel on a 7 km grid whose steps span 1e-8..72 m: ``AlmostSolved``, ``w = 0`` next to
    the end).
    """
    w = np.clip(relax.w, 0.0, unit.w_max)
    w[0], w[-1] = unit.w_start, unit.w_end
    if not np.isfinite(unit.travel_time(w)):
        raise SolverError(
            f"{backend} stopped ({relax.status}) at a speed law that comes to rest inside the "
            "leg", backend=backend, status=relax.status)
    return relax


def _relax_with_fallback(
    unit: DiscreteProblem, backend: str, fallback: bool = True
) -> tuple[RelaxationResult, str, str | None]:
    """Solve the relaxation; if the backend stalls, retry once with the other backend.

    Both are interior-point methods on the same SOCP, but they fail on different instances
    (Clarabel can stall at ``InsufficientProgress``, or stop ``AlmostSolved`` at a law that
    does not arrive, on long, strongly graded grids). ``fallback=False``: no retry.
    """
    try:
        return _arriving(RELAXATION_BACKENDS[backend](unit), unit, backend), backend, None
    except SolverError as first:
        if not fallback or unit.has_grip:  # the other backend holds no friction ellipse
            raise
        other = "banded" if backend == "clarabel" else "clarabel"
        try:
            return (_arriving(RELAXATION_BACKENDS[other](unit), unit, other), other,
                    f"{backend}: {first}")
        except SolverError as second:
            raise SolverError(
                f"both relaxation backends failed ({backend}: {first}; {other}: {second})",
                backend=f"{backend},{other}", status=second.status,
            ) from second


def solve_problem(
    problem: DiscreteProblem, *, refine: Refine = "auto", backend: Backend = "clarabel",
    fallback: bool = True, ipopt_fallback: bool = True,
) -> DiscreteSolution:
    """Solve a validated `DiscreteProblem` (any grid) and certify the result.

    If the relaxation backend fails, the other one is tried, unless ``fallback`` is False
    ([`speedplan.plan`][speedplan.plan] first tries a coarser default grid with the same backend).
    ``ipopt_fallback`` False keeps the refinement to the banded method's starts (no IPOPT
    run of up to 5 s when none is accepted).

    Raises
    ------
    InvalidInputError
        If the grid is finer than the relaxation can resolve for these jerk bounds
        (`check_grid_resolvable`).
    InfeasibleError
        If the boundary values cannot be met.
    SolverError
        If a backend fails and no feasible point can be produced.
    """
    t_start = time.perf_counter()
    refine = check_option("refine", refine, REFINE_MODES)
    backend = check_option("backend", backend, BACKENDS)
    if not (problem.has_jerk or problem.has_grip):
        return _passed(problem, t_start)
    check_reachable(problem)
    if problem.has_grip and backend == "banded":
        raise InvalidInputError(
            "`backend`='banded' holds no friction-ellipse rows (Limits grip='ellipse'); use "
            "backend='auto' or 'clarabel'")
    if problem.n < 3:
        return _passed(problem, t_start)

    check_grid_resolvable(problem)  # before any solver spends a minute on it
    positive_feasible_w(problem)  # before scaling: its error names s in the problem's units
    if backend == "auto":  # only now: the pass above needs no solver (and no compilation)
        backend = _auto_backend(problem)
    relaxed = _relaxed(problem, backend, fallback)
    w = relaxed.w
    status: Status = "optimal" if relaxed.exact else "relaxed"
    refinement: RefinementInfo | None = None
    loose = relaxed.exact and problem.travel_time(w) > relaxed.lower * (1.0 + POLISH_GAP)
    refined = refine == "always" or (refine == "auto" and (not relaxed.exact or loose))
    if refined:
        w, status, refinement = _refined(problem, relaxed, w, status, ipopt_fallback)
    elif not relaxed.exact:
        warnings.warn(
            f"refine='never' and the relaxation is not exact: w violates jerk rows by up to "
            f"{relaxed.info.jerk_violation:.3g} (status 'relaxed')",
            SpeedplanWarning, stacklevel=3,
        )

    objective = problem.travel_time(w)
    if (not relaxed.exact and objective > relaxed.lower * (1.0 + CUT_GAP) and not passed()
            and problem.n <= CUT_MAX_NODES):
        seconds = max(CUT_SECONDS, time.perf_counter() - t_start)
        relaxed = _with_cuts(problem, relaxed, objective, seconds)
    return DiscreteSolution(
        w=w,
        objective=objective,
        lower_bound=relaxed.lower,
        gap=(objective - relaxed.lower) / relaxed.lower,
        exact=relaxed.exact,
        exact_a_priori=problem.satisfies_a_priori_exactness(),
        jerk_violation=problem.jerk_violation(w),
        refined=refined,
        status=status,
        solve_time=time.perf_counter() - t_start,
        backend=relaxed.info.backend,
        relaxation=relaxed.info,
        refinement=refinement,
    )


def _passed(problem: DiscreteProblem, t_start: float) -> DiscreteSolution:
    """The exact optimum without jerk rows (the O(n) pass), its boundary values checked.

    The pass meets ``w_start`` and ``w_end`` exactly when they are reachable (see
    `max_feasible_w`); only when it does not does `check_reachable` run, to raise the
    error that names the constraint and where (or pass, for values within its tolerance).
    """
    w = max_feasible_w(problem)
    if problem.has_lower_bounds or not (w[0] == problem.w_start and w[-1] == problem.w_end):
        check_reachable(problem)
    obj = problem.travel_time(w)
    return DiscreteSolution(
        w=w, objective=obj, lower_bound=obj, gap=0.0, exact=True, exact_a_priori=True,
        jerk_violation=0.0, refined=False, status="optimal",
        solve_time=time.perf_counter() - t_start, backend="pass",
    )


def _with_cuts(problem: DiscreteProblem, relaxed: _Relaxed, objective: float,
               seconds: float) -> _Relaxed:
    """``relaxed`` with the lower bound of the relaxation plus the secant cuts, if higher.

    The cuts (`secant_cuts`) remove no feasible point of the discrete problem, so the bound
    stays valid; Clarabel solves it (the banded kernel holds no such rows) for at most
    ``seconds`` (`CUT_SECONDS`), and the bound comes from the multipliers of its last iterate.
    A failed solve, or a bound above the travel time of the feasible ``objective`` beyond
    the solvers' tolerance (which a valid bound never is), leaves the relaxation's own bound.
    """
    t0 = time.perf_counter()
    s_scale, w_scale = unit_scales(problem)
    unit = relaxed.unit
    cuts = secant_cuts(unit).near(_violating_nodes(unit, relaxed.w_unit), CUT_PAD)
    if cuts.size == 0:
        return relaxed
    try:
        res = solve_relaxation(unit, cuts=cuts, time_limit=seconds)
    except (SolverError, InfeasibleError):
        return relaxed
    assert res.z is not None
    mu_acc, mu_dec, nu, pi = row_multipliers(unit, res.z, cuts)
    pi = np.maximum(pi, 0.0)
    g = np.zeros(unit.n)
    for j in range(3):
        np.add.at(g, cuts.node - 1 + j, pi * cuts.coef[:, j])
    # Weak duality with the solver's multipliers: valid whatever its accuracy.
    bound = _lagrangian_bound(unit, mu_acc, mu_dec, nu, linear=(g, float(pi @ cuts.rhs)))
    bound *= s_scale / np.sqrt(w_scale)
    info = replace(relaxed.info, cut_bound=bound, cut_time=time.perf_counter() - t0)
    lower = bound if relaxed.lower < bound <= objective * (1.0 + 1e-7) else relaxed.lower
    return relaxed._replace(lower=lower, info=info)


def _violating_nodes(unit: DiscreteProblem, w: FloatArray) -> np.ndarray:
    """Interior nodes (``1 .. n-2``) where ``w`` exceeds a stencil row beyond its tolerance."""
    w = np.clip(w, 0.0, unit.w_max)
    over = np.zeros(unit.n - 2, dtype=bool)
    for family in unit.stencil_families():
        load = np.abs(unit.stencil_apply(family.coef, w)) * np.sqrt(w[1:-1])
        over |= load > family.bound * (1.0 + 1e-6)
    out: np.ndarray = np.flatnonzero(over) + 1
    return out


class _Relaxed(NamedTuple):
    """The relaxation's answer, in the problem's units and in the solver's."""

    unit: DiscreteProblem  # the problem in the solver's units (`unit_scales`)
    w_unit: FloatArray  # the relaxation's w in those units
    w_scale: float
    w: FloatArray  # clipped into the bounds, in the problem's units, ends fixed
    lower: float  # certified lower bound on the travel time [s]
    exact: bool
    info: RelaxationInfo
    time_scale: float  # seconds per unit of the travel time in the solver's units


def _relaxed(problem: DiscreteProblem, backend: str, fallback: bool) -> _Relaxed:
    """Solve the relaxation in units where the mean step and the largest bound are 1."""
    s_scale, w_scale = unit_scales(problem)  # well-scaled cones
    time_scale = s_scale / np.sqrt(w_scale)
    unit = problem.scaled(s_scale, w_scale)
    relax, backend, fallback_reason = _relax_with_fallback(unit, backend, fallback)
    w_relaxed = np.clip(relax.w * w_scale, 0.0, problem.w_max)
    w_relaxed[0], w_relaxed[-1] = problem.w_start, problem.w_end
    lower = min(relax.dual_objective, relax.primal_objective) * time_scale
    relaxed_violation = problem.jerk_violation(w_relaxed)
    # An interior-point answer meets the convex rows to its own tolerance: a friction
    # ellipse met to GRIP_TOL is exact (the convex rows are not relaxed). A point faster than
    # the relaxation's own bound beyond POLISH_GAP is not: it uses the rows' tolerance
    # (measured: a comfort plan 1.2e-5 under its bound, rows 0.2 % over), and the
    # refinement brings it to a feasible one.
    exact = (relaxed_violation <= problem.jerk_tol
             and problem.relative_row_excess(w_relaxed) <= ROW_TOL_REL
             and problem.grip_violation(w_relaxed) <= GRIP_TOL
             and bool(problem.travel_time(w_relaxed) >= lower * (1.0 - POLISH_GAP)))
    info = RelaxationInfo(
        backend=backend, status=relax.status, iterations=relax.iterations,
        time=relax.solve_time + relax.setup_time, w=w_relaxed,
        jerk_violation=relaxed_violation, fallback=fallback_reason,
    )
    return _Relaxed(unit, relax.w, w_scale, w_relaxed, lower, exact, info, time_scale)


def _refined(problem: DiscreteProblem, relaxed: _Relaxed, w: FloatArray, status: Status,
             ipopt: bool = True) -> tuple[FloatArray, Status, RefinementInfo]:
    """The nonconvex refinement from the relaxation's point: ``w`` and status it leaves.

    An exact relaxation keeps its own ``w`` unless the refined point is feasible and faster
    (a relaxation stopped short of its optimum, `POLISH_GAP`); otherwise the refined point if
    it is feasible, else the relaxed one scaled into the jerk bounds.
    """

    def feasible(w_unit: FloatArray) -> bool:
        w_ref = np.clip(w_unit * relaxed.w_scale, 0.0, problem.w_max)
        return bool(problem.linear_violation(w_ref) <= _linear_tol(problem)
                    and problem.jerk_violation(w_ref) <= problem.jerk_tol
                    and problem.grip_violation(w_ref) <= GRIP_TOL)

    # A polish of an exact relaxation runs every start: it is there to reach POLISH_GAP.
    lower = None if relaxed.exact else relaxed.lower / relaxed.time_scale
    ref = refine_nlp(relaxed.unit, relaxed.w_unit, accept=feasible, lower_bound=lower,
                     ipopt=ipopt)
    w_ref = np.clip(ref.w * relaxed.w_scale, 0.0, problem.w_max)
    ref_ok = ref.success and feasible(ref.w)
    refinement = RefinementInfo(
        status=ref.status, accepted=ref_ok, iterations=ref.iterations, time=ref.solve_time,
        objective=problem.travel_time(w_ref) if ref_ok else None,
    )
    if relaxed.exact:
        faster = ref_ok and problem.travel_time(w_ref) < problem.travel_time(w)
        return (w_ref if faster else w), status, refinement
    # The relaxed point may meet every row within the tolerance the refined points are
    # accepted with, yet fail exactness only by lying under its own bound (rows a hair over
    # next to a standstill, where the time grows as w^-1/2): there the refinement can stall
    # and its fallback start end in a far optimum (states read off a stop's approach: 8-50 %
    # slower, and a law with 7x the jerk). Such a refined point does not replace it.
    held = (feasible(relaxed.w_unit)
            and problem.relative_row_excess(relaxed.w) <= ROW_TOL_REL)
    if ref_ok and not (held and problem.travel_time(w_ref)
                       > problem.travel_time(relaxed.w) * (1.0 + ASTRAY_GAP)):
        return w_ref, "refined", refinement
    if held:
        kept = RefinementInfo(
            status=f"{ref.status}; the relaxed point kept (within the rows' tolerance)",
            accepted=False, iterations=ref.iterations, time=ref.solve_time,
            objective=refinement.objective)
        return relaxed.w, "refined", kept
    scaled = _scale_into_jerk_bounds(problem, relaxed.w)
    if scaled is None:
        raise SolverError(
            f"the relaxation is not exact (jerk violation {relaxed.info.jerk_violation:.3g}) "
            f"and the refinement did not return a feasible point ({ref.status})",
            backend="ipopt", status=ref.status,
        )
    warnings.warn(
        f"the refinement failed ({ref.status}); returning the relaxed "
        "solution scaled into the jerk bounds (status 'scaled')",
        SpeedplanWarning, stacklevel=4,
    )
    return scaled, "scaled", refinement


def _accel_pair(A: ArrayLike | tuple[ArrayLike, ArrayLike], n: int
                ) -> tuple[FloatArray, FloatArray]:
    if isinstance(A, tuple):
        if len(A) != 2:
            raise InvalidInputError(
                f"`A` as a tuple must be (accel, decel); got a tuple of length {len(A)}"
            )
        return (broadcast_positive("A[0] (accel)", A[0], n - 1),
                broadcast_positive("A[1] (decel)", A[1], n - 1))
    acc = broadcast_positive("A", A, n - 1)
    return acc, acc


def solve_discrete(
    w_max: ArrayLike,
    A: ArrayLike | tuple[ArrayLike, ArrayLike],
    J: ArrayLike,
    h: float = 1.0,
    *,
    w_start: float = 0.0,
    w_end: float = 0.0,
    refine: Refine = "auto",
    backend: Backend = "auto",
) -> DiscreteSolution:
    """Solve the paper's discrete speed-planning problem with a certificate of optimality.

    minimise ``Σ_{i=2}^{n-1} h / sqrt(w_i)`` subject to ``|w_{i+1} - w_i| <= A_i h``,
    ``0 <= w_i <= w_max_i``, ``|w_{i-1} - 2 w_i + w_{i+1}| sqrt(w_i) <= h² J_i`` and
    ``w_1 = w_start``, ``w_n = w_end``.

    Parameters
    ----------
    w_max : array_like, shape (n,)
        Upper bounds on ``w = v²``; ``> 0`` at interior nodes.
    A : float, array_like of shape (n-1,), or tuple (accel, decel)
        Bound on ``|w_{i+1} - w_i| / h``. A *tuple* of two entries gives separate
        acceleration and braking bounds (each scalar or length n-1).
    J : float or array_like, shape (n-2,)
        Jerk bound of each interior node; ``inf`` drops the row (``J=inf``: no jerk rows, solved
        exactly by an O(n) pass without any solver).
    h : float
        Grid step.
    w_start, w_end : float
        Boundary values ``w_1`` and ``w_n`` (the paper: 0).
    refine : {"auto", "always", "never"}
        When to run the IPOPT refinement: when the relaxation is not exact, always (its result
        is then in ``refinement``), or never (a non-exact result has status ``"relaxed"`` and
        warns).
    backend : {"auto", "clarabel", "banded"}
        Relaxation backend: Clarabel (reference), the structure-exploiting banded
        interior-point method, or ``"auto"`` (banded from `AUTO_BANDED_FROM` nodes on;
        Clarabel while the banded kernel is being compiled on first use, see
        `kernel_ready`).

    Returns
    -------
    DiscreteSolution

    Raises
    ------
    InvalidInputError
        Wrong shapes, NaN/inf, non-positive ``h``/``A``/``J``, negative ``w_max``.
    InfeasibleError
        The boundary values cannot be met (the message says which and where).

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan import solve_discrete
    >>> sol = solve_discrete(np.full(50, 4.0), A=0.5, J=0.2)
    >>> sol.status, sol.exact, bool(sol.gap < 1e-6)
    ('optimal', True, True)
    >>> bool(sol.w.max() <= 4.0)
    True
    """
    wm = as_array("w_max", w_max, ndim=1)
    n = grid_size("w_max", wm.shape[0])
    if n < 3:
        raise InvalidInputError(f"`w_max` must have at least 3 entries; got {n}")
    if (wm < 0).any():
        i = int(np.flatnonzero(wm < 0)[0])
        raise InvalidInputError(f"`w_max` must be >= 0; got {wm[i]!r} at index {i}")
    if (wm[1:-1] <= 0).any():
        i = int(np.flatnonzero(wm[1:-1] <= 0)[0]) + 1
        raise InvalidInputError(
            f"`w_max` must be > 0 at interior nodes (a stop inside the path makes the travel "
            f"time infinite; split the problem there); got {wm[i]!r} at index {i}"
        )
    hh = as_scalar("h", h, positive=True)
    accel, decel = _accel_pair(A, n)
    jerk = broadcast_positive("J", J, n - 2, allow_inf=True)
    problem = DiscreteProblem(
        s=np.arange(n, dtype=np.float64) * hh,
        w_max=wm,
        accel=accel,
        decel=decel,
        jerk=jerk,
        w_start=as_scalar("w_start", w_start, nonnegative=True),
        w_end=as_scalar("w_end", w_end, nonnegative=True),
    )
    return solve_problem(problem, refine=refine, backend=backend)
