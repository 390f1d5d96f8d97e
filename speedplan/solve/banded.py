"""Structure-exploiting interior-point solver for the SOCP relaxation (O(n) per iteration).

The relaxation (paper eq. ``relax``, our `build_socp`) is

    minimise   Σ t_i
    subject to (w_{i+1} - w_i) <= A_i h_i,   (w_i - w_{i+1}) <= D_i h_i,   w_i <= w_max_i,
               w_i >= w_min_i                           (where ``w_min`` is given),
               ±τ_i (c_fi · w_{i-1:i+2}) / B_fi - t_i <= 0   (every finite row of every
                                        stencil family f: jerk rows, lateral-jerk rows),
               z_i² <= w_i,   t_i z_i >= τ_i            (two 3-D second-order cones),
               w_0 = w_start,   w_{n-1} = w_end,

over ``x = (w, t, z)`` restricted to the ``m = n - 2`` interior nodes: the fixed end values are
eliminated and move to the right-hand side. We solve it with a Mehrotra predictor–corrector
primal–dual method with Nesterov–Todd scaling, in the form (and with the notation) of
CVXOPT's ``coneqp``: ``G x + s = b``, ``s ∈ K``, ``G' y + c = 0``, ``y ∈ K``.

Every Newton step reduces to the normal equations ``G' W⁻² G Δx = r``. Their matrix couples
node ``i`` only with ``i ± 1`` through the acceleration rows and with ``i ± 2`` through the
three-point stencils; ``t_i`` and ``z_i`` appear only in rows of node ``i``. So we eliminate
the 2×2 block of ``(t_i, z_i)`` per node (a closed-form Schur complement) and are left with a
pentadiagonal symmetric positive-definite system in ``w``, factored once per iteration as
``L D L'`` and solved twice (predictor and corrector); ``docs/banded-ipm.md`` derives it.
The iteration itself is compiled (`speedplan.solve._banded_ipm`, numba): an iteration
costs O(n) time and memory with no per-operation interpreter overhead.

The problem is solved in the units of `unit_scales` (``w_max <= 1``, unit mean step),
with every variable further scaled per node from the O(n) no-jerk profile ``w_ref``
(``w = w_ref ŵ``, ``z = sqrt(w_ref) ẑ``, ``t = τ / sqrt(w_ref) t̂``) so that every node's cones
become the same unit cones ``ẑ² <= ŵ`` and ``t̂ ẑ >= 1``. The
primal start is the midpoint of the slowest and fastest feasible profiles (see
`_start`), the dual start CVXOPT's default (least-norm, shifted into the cones);
each Newton solve gets one round of iterative refinement once the gap is small and the
solve's own residual could matter.

Near the optimum the NT scaling becomes ill-conditioned and rounding can stop progress a
little short of ``tol`` (seen with strongly varying ``J``, at ``tol`` = 1e-9 on some of
the paper's families, and on fine grids, where the reduced matrix inherits the conditioning
of the fourth difference ``D̂'D̂``). Whatever stopped the iteration (a stall, a matrix that
no longer factors, the iteration limit), the method reports ``status="AlmostSolved"`` (as
Clarabel does) if the certified relative gap below is at most 1e-6 and ``w`` is feasible,
and raises `SolverError` otherwise. Grids finer than double
precision resolves (`check_grid_resolvable`) are refused by
`solve_problem` before any solver runs.

The returned ``dual_objective`` is a rigorous lower bound, independent of how well the
iterates satisfy the dual equations: the Lagrangian of the relaxation with the solver's
multipliers of the acceleration and stencil rows (scaled so that the stencil multipliers of
each node sum to at most 1, which makes the Lagrangian independent of ``t``) is minimised in
closed form over the box ``w_min <= w <= w_max``, node by node. The ``primal_objective`` is
``Σ max(τ_i / sqrt(w_i), max_f τ_i |c_fi · w| / B_fi)`` at the returned ``w``, i.e. the best
``t`` for it.

The kernel is compiled on first use after installation (or by ``speedplan compile``); until
then ``backend="auto"`` answers with Clarabel while a background process compiles it
(`kernel_ready`, `speedplan.core.jit`).
"""

from __future__ import annotations

import importlib.util
import sys
import time
from dataclasses import replace
from types import ModuleType
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from ..core.checks import FloatArray, IntArray
from ..core.errors import InvalidInputError, SolverError
from ..core.jit import FAMILIES
from .clarabel_ import RelaxationResult
from .nojerk import check_reachable, min_feasible_w, positive_feasible_w
from .problem import MAX_RAMP_STEPS, DiscreteProblem, ramp_steps

__all__ = [
    "ACCEPT_GAP", "KERNELS", "MAX_ITERATIONS", "MAX_RAMP_STEPS",
    "check_grid_resolvable", "compile_kernel", "kernel_for_auto", "kernel_ready", "ramp_steps",
    "solve_relaxation_banded",
    "solve_unit_relaxation", "unit_scales",
]


def _lazy_module(name: str) -> ModuleType:
    """``name`` imported on first attribute access (the standard library's LazyLoader recipe).

    The kernel module imports numba (about 0.2 s); ``import speedplan`` must not pay that for
    processes that never solve with the banded backend.
    """
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.find_spec(name)
    assert spec is not None and spec.loader is not None
    loader = importlib.util.LazyLoader(spec.loader)
    spec.loader = loader
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    loader.exec_module(module)
    return module


if TYPE_CHECKING:
    from . import _banded_ipm as ipm
else:
    ipm = _lazy_module(f"{__package__}._banded_ipm")


#: Largest certified relative gap with which a stop short of the kernel's tolerance is
#: accepted ("AlmostSolved"; Clarabel's own reduced tolerance is 5e-5). Falling back to
#: Clarabel instead cost 45 s at 20 000 nodes for a 4.5 cm move stopped at a 1.5e-6 gap, and
#: its duration was then within 1.2e-6 of ruckig's optimum either way (trust fuzz, measured).
ACCEPT_GAP = 1e-5
#: Iterations of the interior-point method before it stops (``MaxIterations``). Most grids
#: solve in 15-40; next to a slow zone or a hairpin the gap can fall slowly for a while and
#: the method still converges (a 20 000-node zone path, fuzz_zones seed 2 case 98: 117).
MAX_ITERATIONS = 200


class _Rows(NamedTuple):
    """Family and node of each stencil row of `Data`."""

    family: IntArray
    node: IntArray


def _stencil_rows(p: DiscreteProblem) -> tuple[list[IntArray], IntArray, _Rows]:
    """The finite rows of each stencil family, their order in the kernel, and its table.

    The kernel lists the rows by node, families in order at each node. The table (family
    and node of each listed row) is only read after the kernel: built again then, it is not
    alive during the iteration (8 bytes per row).
    """
    finite = [np.flatnonzero(np.isfinite(family.bound)) for family in p.stencil_families()]
    nodes = np.concatenate(finite)
    order = np.argsort(nodes, kind="stable")
    family = np.concatenate([np.full(rows.size, f) for f, rows in enumerate(finite)])
    return finite, order, _Rows(family=family[order], node=nodes[order].astype(np.intp))


def _prepare(p: DiscreteProblem, w_ref: FloatArray) -> ipm.Data:
    """Flatten the (already scaled) problem into the arrays the iteration uses.

    Variables are scaled per node, ``w = cw ŵ``, ``z = sqrt(cw) ẑ``, ``t = ct t̂`` with
    ``cw = w_ref`` and ``ct = τ / sqrt(cw)``, which turns both cones of every node into the
    same unit cones ``ẑ² <= ŵ`` and ``t̂ ẑ >= 1``; the acceleration rows get the coefficients
    ``cw``, the stencil rows (every finite row of every family of
    [`stencil_families`][speedplan.DiscreteProblem.stencil_families]) the stencil times
    ``cw`` and are divided by ``ct``. The rows are not normalised further:
    normalising the jerk rows to unit norm (as an earlier version did) made the method jam on
    grids finer than about 7 mm, e.g. ``paths/u_turn.json`` at ``n = 5000`` (NoProgress after
    36 iterations; without it, a certified gap below 1e-6 after 34), with no gain elsewhere.
    """
    n = p.n
    m = n - 2
    cw = w_ref
    ct = p.tau / np.sqrt(cw)
    cwp = np.concatenate(([0.0], cw, [0.0]))
    w_const = np.zeros(n)
    w_const[0], w_const[-1] = p.w_start, p.w_end
    finite, order, table = _stencil_rows(p)
    jstart = np.searchsorted(table.node, np.arange(m + 1)).astype(np.intp)
    k = table.node.size
    del table  # the rows' nodes are not alive during the kernel (jstart stands for them)
    stencils, coefs, consts = [], [], []
    for family, rows in zip(p.stencil_families(), finite, strict=True):
        c = np.asarray(family.coef)[rows]
        stencils.append(c * np.column_stack((cwp[rows], cw[rows], cwp[rows + 2])))
        cj = p.tau[rows] / family.bound[rows] / ct[rows]
        coefs.append(cj)
        # The fixed ends' share of the row, moved to the right-hand side.
        consts.append((c[:, 0] * w_const[rows] + c[:, 1] * w_const[rows + 1]
                       + c[:, 2] * w_const[rows + 2]) * cj)
    jconst = np.concatenate(consts)[order]
    lk = np.zeros(0, dtype=np.intp) if p.w_min is None else np.flatnonzero(p.w_min[1:-1] > 0)
    # G x + s = b with the fixed ends moved to b: b = bound - (row applied to the fixed ends).
    dconst = np.diff(w_const)
    b_lin = np.concatenate(
        (
            p.accel * p.h - dconst,
            p.decel * p.h + dconst,
            p.w_max[1:-1] / cw,
            np.zeros(0) if p.w_min is None else -p.w_min[1:-1][lk] / cw[lk],
            -jconst,  # the negative jerk rows' +jconst is not stored (ipm._b_lin)
        )
    )
    data = ipm.Data(
        jstart=jstart,
        jc=np.ascontiguousarray(np.concatenate(stencils)[order].T),
        cj=np.concatenate(coefs)[order], lk=lk.astype(np.intp), ct=ct, cw=cw, b_lin=b_lin,
        lay=ipm.layout(m, k, lk.size),
    )
    return data


# --- certificates -------------------------------------------------------------------------


def _primal_t(p: DiscreteProblem, w: FloatArray) -> FloatArray:
    """Smallest feasible ``t`` for the full ``w`` (interior ``w > 0``)."""
    t: FloatArray = p.tau / np.sqrt(w[1:-1])
    for family in p.stencil_families():
        finite = np.isfinite(family.bound)
        load = p.stencil_apply(family.coef, w)
        t[finite] = np.maximum(t[finite],
                               p.tau[finite] * np.abs(load[finite]) / family.bound[finite])
    return t


def _lagrangian_bound(
    p: DiscreteProblem, mu_acc: FloatArray, mu_dec: FloatArray,
    nu: list[tuple[FloatArray, FloatArray]], linear: tuple[FloatArray, float] | None = None,
) -> float:
    """Lower bound from multipliers of the acceleration and stencil rows (weak duality).

    With ``μ >= 0`` on the rows ``±(w_{k+1} - w_k) <= A_k h_k`` and ``ν±_f >= 0`` (per node,
    zero where the bound is ``inf``) on the rows ``±τ (c_f · w) / B_f - t <= 0`` of every
    family ``f``, scaled so that ``Σ_f (ν⁺_f + ν⁻_f) <= 1`` at every node, the multiplier
    ``λ = 1 - Σ_f (ν⁺_f + ν⁻_f) >= 0`` of ``t >= τ / sqrt(w)`` makes the Lagrangian free of
    ``t``; its minimum over the box ``w_min <= w <= w_max`` is separable and closed-form (the
    minimiser of the convex ``g w + c / sqrt(w)`` clipped to the box). Any such multipliers
    give a valid bound; non-finite ones (an iterate that broke down) give none, ``-inf``.
    ``linear = (g, c)`` adds ``g · w - c`` to the Lagrangian: the term of further rows
    ``a · w <= b`` with their multipliers ``π >= 0`` (``g = A' π``, ``c = b · π``, as for
    `speedplan.solve.cuts`).
    """
    arrays = [mu_acc, mu_dec, *(x for pair in nu for x in pair)]
    if linear is not None:
        arrays += [linear[0], np.array([linear[1]])]
    if not all(np.all(np.isfinite(x)) for x in arrays):
        return -np.inf
    mu_acc, mu_dec = np.maximum(mu_acc, 0.0), np.maximum(mu_dec, 0.0)
    nu = [(np.maximum(a, 0.0), np.maximum(b, 0.0)) for a, b in nu]
    excess = np.maximum(sum((a + b for a, b in nu), np.zeros(p.n - 2)), 1.0)  # λ >= 0
    nu = [(a / excess, b / excess) for a, b in nu]
    lam = np.ones(p.n - 2)
    for a, b in nu:
        lam = lam - a - b
    lam = np.maximum(lam, 0.0)  # >= 0 up to rounding; c / g below stays >= 0
    # Linear coefficient of the full w in the Lagrangian.
    net = mu_acc - mu_dec
    g = np.zeros(p.n)
    g[1:] += net
    g[:-1] -= net
    for family, (a, b) in zip(p.stencil_families(), nu, strict=True):
        finite = np.isfinite(family.bound)
        coef = np.where(finite, (a - b) * p.tau / np.where(finite, family.bound, 1.0), 0.0)
        g += p.stencil_adjoint(family.coef, coef)
    extra = 0.0
    if linear is not None:
        g += linear[0]
        extra = linear[1]
    const = (g[0] * p.w_start + g[-1] * p.w_end
             - float(mu_acc @ (p.accel * p.h)) - float(mu_dec @ (p.decel * p.h)) - extra)
    gi, c, wmax = g[1:-1], lam * p.tau, p.w_max[1:-1]
    pos = gi > 0
    w_opt = wmax.copy()
    w_opt[pos] = (c[pos] / (2.0 * gi[pos])) ** (2.0 / 3.0)
    w_low = np.zeros(wmax.size) if p.w_min is None else p.w_min[1:-1]
    w_opt = np.clip(w_opt, w_low, wmax)
    val = gi * w_opt
    cpos = c > 0
    if np.any(cpos & (w_opt <= 0)):
        return -np.inf
    val[cpos] += c[cpos] / np.sqrt(w_opt[cpos])
    return float(const + val.sum())


def _start(p: DiscreteProblem, d: ipm.Data) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Primal starting point ``(ŵ, t̂, ẑ)`` in the middle of the linear rows' feasible set.

    ``w`` is the mean of the fastest feasible profile ``w_ref`` and the slowest one
    (`min_feasible_w`); both meet every acceleration row, so
    their mean does too, strictly inside the speed bounds wherever they differ. ``z`` and
    ``t`` are then strictly inside their cones and above the stencil rows. Measured on
    ``plan()`` grids (with the jerk-row normalisation of the time) this more than halved the
    iterations of CVXOPT's least-squares start (55 -> 20 on ``paths/u_turn.json``), whose point
    ignores the chain of acceleration rows and spends iterations propagating it along the path.
    """
    w_hat = 0.5 * (min_feasible_w(p)[1:-1] / d.cw + 1.0)
    z_hat = 0.5 * np.sqrt(w_hat)
    # Stencil rows at t = 0: G x - b gives cj (jc · ŵ) plus the fixed ends' share (the
    # kernel's arithmetic, in numpy: the kernel itself is entered only once per solve).
    padded = np.concatenate(([0.0], w_hat, [0.0]))
    i = np.repeat(np.arange(d.lay.m), np.diff(d.jstart))  # the node of each row
    rows = d.cj * (d.jc[0] * padded[i] + d.jc[1] * padded[i + 1] + d.jc[2] * padded[i + 2])
    load = np.zeros(w_hat.size)
    np.maximum.at(load, i, np.abs(rows - d.b_lin[d.lay.jp : d.lay.jm]))
    t_hat = 2.0 * np.maximum(1.0 / z_hat, load) + 1.0
    return w_hat, t_hat, z_hat


def _row_multipliers(
    p: DiscreteProblem, d: ipm.Data, rows: _Rows, yl: FloatArray
) -> tuple[FloatArray, FloatArray, list[tuple[FloatArray, FloatArray]]]:
    """Multipliers of the problem's own rows (stencil rows: ``t`` rescaled by ``ct``).

    Returns ``(μ_acc, μ_dec, [(ν⁺_f, ν⁻_f) per family, per node]``).
    """
    lay = d.lay
    nu = []
    for f in range(1 + len(p.lateral_families)):  # the jerk rows, then each lateral family
        mine = rows.family == f
        node = rows.node[mine]
        nu_p, nu_m = np.zeros(lay.m), np.zeros(lay.m)
        nu_p[node] = yl[lay.jp : lay.jm][mine] / d.ct[node]
        nu_m[node] = yl[lay.jm : lay.n_lin][mine] / d.ct[node]
        nu.append((nu_p, nu_m))
    return yl[: lay.dec], yl[lay.dec : lay.up], nu


# --- driver --------------------------------------------------------------------------------


def _kernel_args(
    p: DiscreteProblem, d: ipm.Data
) -> tuple[ipm.Data, ipm.Point, ipm.Residual, ipm.Direction, ipm.Scaling, ipm.Factor]:
    """The kernel's arrays for ``d``, sizes checked, with `_start` in the point.

    The start is copied into the point before the other arrays are allocated, and its own
    arrays are freed at once: alive during the iteration they would add 24 bytes per node.
    """
    d.check()
    lay = d.lay
    pt = ipm.empty(ipm.Point, lay)
    pt.w[:], pt.t[:], pt.z[:] = _start(p, d)
    args = (d, pt, ipm.empty(ipm.Residual, lay), ipm.empty(ipm.Direction, lay),
            ipm.Scaling.identity(lay), ipm.empty(ipm.Factor, lay))
    ipm.check_sizes(*args)
    return args


def _run_kernel(
    p: DiscreteProblem, d: ipm.Data, tol: float, max_iter: int
) -> tuple[FloatArray, FloatArray, int, int]:
    """Iterate from `_start`; ``(w, yl, iterations, status code)``, internal units."""
    args = _kernel_args(p, d)
    log = np.full((max_iter + 1, len(ipm.LOG_COLUMNS)), np.nan)
    iterations, code = ipm.iterate(*args, log, tol, max_iter)
    _Diagnostics.last_log = log[: iterations + 1]
    pt = args[1]
    return pt.w, pt.yl, iterations, code


# --- first use: load, compile, or compile in the background ---------------------------------

#: The compiled kernel's family (`speedplan.core.jit` loads, compiles or starts it).
KERNELS = FAMILIES["relaxation"]


class _Diagnostics:
    """The iteration log of the last solve in this process, for diagnostics and benchmarks.

    Rows: iterations; columns: `LOG_COLUMNS`. Empty (no
    columns) until the first solve: sizing it would import the kernel.
    """

    last_log: FloatArray = np.zeros((0, 0))


def _example_problem() -> DiscreteProblem:
    n = 6
    return DiscreteProblem(s=np.arange(n, dtype=float), w_max=np.full(n, 1.0),
                           accel=np.full(n - 1, 0.5), decel=np.full(n - 1, 0.5),
                           jerk=np.full(n - 2, 0.1), w_min=np.full(n, 0.0))


def compile_kernel() -> None:
    """Make the compiled kernel available in this process now: load it, or compile it.

    ``backend="auto"`` answers with Clarabel while the kernel is not available (see
    `kernel_ready`); call this first for runs whose backend must not depend on timing
    (or run ``speedplan compile`` once after installing, which compiles every kernel).

    Examples
    --------
    >>> compile_kernel()
    >>> kernel_ready()
    True
    """
    KERNELS.compile()


def kernel_ready(*, start: bool = True) -> bool:
    """Whether the banded kernel runs now without compiling; else compile it in the background.

    The kernel is loaded from numba's cache when it is there. When it is not (first use
    after installation), and ``start`` is true, a background Python process compiles it into
    the cache, unless the environment variable ``SPEEDPLAN_BACKGROUND_COMPILE`` is ``0``;
    later calls load it once that process is done (`speedplan.core.jit.Kernels.ready`).
    """
    return KERNELS.ready(start=start)


def kernel_for_auto(*, wait: bool) -> bool:
    """Whether ``backend="auto"`` should use the banded kernel now.

    True when it is available (`kernel_ready`, which starts a background compilation
    if needed), or after compiling it here when ``wait`` is true or background compilation
    is off (``SPEEDPLAN_BACKGROUND_COMPILE=0``, or no process could be started).
    """
    return KERNELS.available(wait=wait) is not None


def check_grid_resolvable(problem: DiscreteProblem) -> None:
    """Raise `InvalidInputError` if the grid is too fine for the relaxation to resolve.

    See `MAX_RAMP_STEPS`; the message gives the finest step supported for these bounds.

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan.solve.problem import DiscreteProblem
    >>> n = 12_000
    >>> p = DiscreteProblem(s=np.arange(n) * 1e-3, w_max=np.full(n, 4.0),
    ...                     accel=np.full(n - 1, 2.0), decel=np.full(n - 1, 2.0),
    ...                     jerk=np.full(n - 2, 0.5))
    >>> check_grid_resolvable(p)
    Traceback (most recent call last):
    ...
    speedplan.core.errors.InvalidInputError: the grid is too fine for the jerk bounds: ...
    """
    steps = ramp_steps(problem)
    if steps <= MAX_RAMP_STEPS + 1:  # one step of slack: the count rounds up
        return
    h = float(np.mean(problem.h))
    h_min = h * steps / MAX_RAMP_STEPS
    length = float(problem.s[-1] - problem.s[0])
    n_max = int(length / h_min) + 1
    raise InvalidInputError(
        f"the grid is too fine for the jerk bounds: a jerk-limited change of acceleration "
        f"spans up to {steps:.0f} grid steps of {h:.3g}, more than the {MAX_RAMP_STEPS} the "
        f"relaxation resolves in double precision; use steps of at least {h_min:.3g} "
        f"(plan(): n <= {n_max} for this length {length:.6g}, or ds >= {h_min:.3g})"
    )


def unit_scales(problem: DiscreteProblem) -> tuple[float, float]:
    """``(s_scale, w_scale)`` of the relaxation's units: unit mean step and ``w_max <= 1``.

    `solve_problem` hands every relaxation backend
    ``problem.scaled(*unit_scales(problem))``.
    """
    return float(np.mean(problem.h)), float(np.max(problem.w_max))


def solve_relaxation_banded(
    problem: DiscreteProblem, *, tol: float = 1e-8, max_iter: int = MAX_ITERATIONS
) -> RelaxationResult:
    """Solve the SOCP relaxation with a banded primal–dual interior-point method.

    Parameters
    ----------
    problem : DiscreteProblem
        The discrete problem; any grid (uniform or not), ``n >= 3``.
    tol : float, optional
        Tolerance on the relative primal and dual residuals and on the relative duality gap
        (Clarabel's defaults are the same 1e-8). Tighter values reach the limit of double
        precision on some instances: the method then stalls near 1e-9 and reports
        ``"AlmostSolved"``.
    max_iter : int, optional
        Maximum number of interior-point iterations.

    Returns
    -------
    RelaxationResult
        ``w`` (n,) with the end values in place, the best ``t`` for it, ``primal_objective =
        Σ t``, ``dual_objective`` a certified lower bound on the relaxation's optimum,
        ``status="Solved"`` (residuals and gap within ``tol``) or ``"AlmostSolved"`` (the
        method stopped short of ``tol`` with a certified relative gap <= 1e-6).

    Raises
    ------
    InfeasibleError
        If no ``w`` with positive interior values meets the bounds and acceleration rows.
    SolverError
        If the method stops short of ``tol`` (iteration limit, stall, numerical breakdown or
        no progress) without a certified relative gap <= 1e-6 and a feasible ``w``
        (``backend="banded"``; ``status`` says why it stopped).

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan.solve.problem import DiscreteProblem
    >>> n = 50
    >>> p = DiscreteProblem(s=np.arange(n, dtype=float), w_max=np.full(n, 4.0),
    ...                     accel=np.full(n - 1, 0.5), decel=np.full(n - 1, 0.5),
    ...                     jerk=np.full(n - 2, 0.1))
    >>> res = solve_relaxation_banded(p)
    >>> res.status, bool(res.dual_objective <= res.primal_objective)
    ('Solved', True)

    """
    t_start = time.perf_counter()
    if problem.n >= 3:
        check_reachable(problem)
        positive_feasible_w(problem)  # here, for an error in the problem's own positions
    s_scale, w_scale = unit_scales(problem)
    res = solve_unit_relaxation(problem.scaled(s_scale, w_scale), tol=tol, max_iter=max_iter)
    time_scale = s_scale / np.sqrt(w_scale)
    w = res.w * w_scale
    w[0], w[-1] = problem.w_start, problem.w_end
    return replace(res, w=w, t=res.t * time_scale,
                   primal_objective=res.primal_objective * time_scale,
                   dual_objective=res.dual_objective * time_scale,
                   setup_time=time.perf_counter() - t_start - res.solve_time)


def solve_unit_relaxation(
    unit: DiscreteProblem, *, tol: float = 1e-8, max_iter: int = MAX_ITERATIONS
) -> RelaxationResult:
    """`solve_relaxation_banded` of a problem already in units and checked.

    ``unit`` is in the units of `unit_scales` (``w_max <= 1``, unit mean step) and its
    boundary values are reachable (`check_reachable`), as
    `solve_problem` hands it to every relaxation backend; results are
    in the same units.
    """
    t_start = time.perf_counter()
    if unit.n < 3:
        raise SolverError("the relaxation needs n >= 3 grid nodes", backend="banded",
                          status="InvalidProblem")
    wmf = positive_feasible_w(unit)
    d = _prepare(unit, wmf[1:-1])
    t_setup = time.perf_counter()
    w_int, yl, iterations, code = _run_kernel(unit, d, tol, max_iter)
    # Clip rounding-level excursions past the bounds; the ends are the given values.
    w_low = np.zeros(d.lay.m) if unit.w_min is None else unit.w_min[1:-1]
    w = np.concatenate(([unit.w_start], np.clip(w_int * d.cw, w_low, unit.w_max[1:-1]),
                        [unit.w_end]))
    t = _primal_t(unit, w)
    primal = float(t.sum())
    dual = _lagrangian_bound(unit, *_row_multipliers(unit, d, _stencil_rows(unit)[2], yl))
    status = ipm.STATUS_NAMES[code]
    if status != "Solved":
        # Like Clarabel's AlmostSolved: accepted only with a certified gap and feasible w,
        # whatever stopped the iteration. Both are checked here, independently of the
        # iterates' residuals: on fine grids the dual residual can stall at 1e-5 while the
        # certified gap is 3.6e-11 (paths/slow_zone.json, n = 20 000), or the next Newton
        # matrix fails to factor one step after a certified gap of 9.9e-8 (u_turn.json).
        cert_gap = (primal - dual) / max(abs(primal), 1e-300)
        feasible = (unit.linear_violation(w)
                    <= ipm.ALMOST_GAP * max(1.0, float(np.max(unit.w_max))))
        if not (cert_gap <= ACCEPT_GAP and feasible):
            raise SolverError(
                f"banded interior-point method stopped with status {status} after "
                f"{iterations} iterations (certified relative gap {cert_gap:.2e})",
                backend="banded",
                status=status,
            )
        status = "AlmostSolved"
    t_end = time.perf_counter()
    return RelaxationResult(
        w=w,
        t=t,
        primal_objective=primal,
        dual_objective=dual,
        status=status,
        iterations=iterations,
        solve_time=t_end - t_setup,
        setup_time=t_setup - t_start,
    )
