"""Compiled (numba) per-iteration work of `speedplan.solve.banded_nlp`.

The interior-point method's control flow (barrier update, filter line search, restoration)
stays in Python; what an iteration computes on arrays of ``n`` runs here, one call per step
of the method, so the ~100 numpy passes of an iteration become a handful of fused loops.
The formulas are those of the numpy path in `banded_nlp` (which runs
until these kernels are compiled); ``tests/solve/test_refine.py`` checks that both agree.

Layout (``m`` interior nodes, ``na = m + 1`` acceleration rows, ``R`` rows in all):

- family rows are flattened: row ``j`` has interior node ``kk[j]`` (its ``sqrt(w)``, full
  nodes ``kk[j] .. kk[j] + 2``), stencil ``cc[j]`` and scale ``rr[j]``; it is row ``na + j``;
- the gaps and their multipliers are stacked ``(x - lb, ub - x, s - lo, hi - s, p, q)``
  (``p, q`` only in the restoration phase, ``ne = R`` there, else ``0``);
- the objective is ``mode`` 0, ``Σ a_i / sqrt(x_i)`` (travel time), or ``mode`` 1,
  ``Σ a_i (x_i - b_i)² / 2`` (the restoration's proximity term).

Every kernel has one explicit signature (`SIGNATURES`): the caller loads them from
numba's cache or compiles them once, never per call.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..core.checks import FloatArray, IntArray
from ..core.jit import inner, kernel, tolerate_stale_indexes

tolerate_stale_indexes()  # before any kernel below is loaded from the cache


def _kernel(fn: Any) -> Any:
    """`speedplan.core.jit.kernel` raising on a division by zero (numba's Python model)."""
    return kernel(fn, error_model="python")


def _inner(fn: Any) -> Any:
    """`speedplan.core.jit.inner` raising on a division by zero."""
    return inner(fn, error_model="python")


# IPOPT's inertia-correction constants, the numpy path's (banded_nlp). Written here, not
# imported: numba freezes globals into cached code and re-validates the cache against this
# file only. tests/solve/test_refine.py checks that the two sets agree.
DELTA_W_FIRST, DELTA_W_MIN, DELTA_W_MAX = 1e-4, 1e-20, 1e40
KAPPA_W_PLUS_FIRST, KAPPA_W_PLUS, KAPPA_W_MINUS = 100.0, 8.0, 1.0 / 3.0

_F = "float64[::1]"
_F2 = "float64[:, ::1]"
_I = "int64[::1]"

#: Explicit signature of every kernel (argument types as the callers pass them), each after
#: the kernels it calls.
SIGNATURES: dict[str, str] = {
    "_objective_value": f"float64(int64, {_F}, {_F}, {_F})",
    "_cholesky": f"boolean({_F2}, float64, {_F2})",
    "_band_solve": f"void({_F2}, {_F})",
    "evaluate": f"void(float64, float64, {_F}, {_I}, {_F2}, {_F}, {_F}, {_F2}, {_F}, {_F})",
    "jac_t": f"void({_F}, {_I}, {_F2}, {_F})",
    "objective": f"float64(int64, {_F}, {_F}, {_F}, {_F}, {_F})",
    "gaps": f"void({_F}, {_F}, {_F}, {_F}, {_F}, {_F}, {_F}, {_F}, {_F})",
    "residual": f"void({_F}, {_F}, {_F}, {_F}, int64, {_F})",
    "barrier": f"UniTuple(float64, 2)(int64, {_F}, {_F}, {_F}, {_F}, {_F}, float64, {_F})",
    "errors": (f"UniTuple(float64, 2)(int64, int64, {_F}, {_F}, {_F}, {_F}, {_F}, {_F}, "
               f"{_F}, float64, float64)"),
    "newton": (f"UniTuple(float64, 2)(int64, int64, {_F}, {_F}, {_F}, {_F}, {_F}, {_F}, "
               f"{_I}, {_F2}, {_F}, {_F2}, {_F}, {_F}, float64, float64, float64, "
               f"{_F2}, {_F}, {_F}, {_F}, {_F}, {_F}, {_F}, {_F}, {_F}, {_F2})"),
    "direction": (f"void(int64, {_F2}, {_F}, {_F}, {_F}, {_F}, {_F}, {_F}, {_F}, {_F}, "
                  f"{_I}, {_F2}, {_F}, {_F}, {_F}, {_F}, {_F}, {_F}, {_F})"),
    "max_step": f"float64({_F}, {_F}, float64)",
    "dual_step": (f"UniTuple(float64, 2)(int64, {_F}, {_F}, {_F}, {_F}, {_F}, {_F}, float64, "
                  f"float64, float64, {_F})"),
    "new_z": f"void({_F}, float64, {_F}, {_F}, float64, float64, {_F})",
    "tiny": f"float64({_F}, {_F})",
}


@_kernel
def evaluate(
    w_start: float, w_end: float, x: FloatArray, kk: IntArray, cc: FloatArray, rr: FloatArray,
    c: FloatArray, d: FloatArray, load: FloatArray, sq: FloatArray
) -> None:  # pragma: no cover - compiled
    """Row values ``c`` and, per family row, the derivatives ``d``, ``c · w`` and ``sqrt(x)``."""
    m = x.size
    na = m + 1
    for i in range(na):
        hi = w_end if i == m else x[i]
        lo = w_start if i == 0 else x[i - 1]
        c[i] = hi - lo
    for j in range(kk.size):
        k = kk[j]
        w0 = w_start if k == 0 else x[k - 1]
        w1 = x[k]
        w2 = w_end if k == m - 1 else x[k + 1]
        s = np.sqrt(w1)
        lj = cc[j, 0] * w0 + cc[j, 1] * w1 + cc[j, 2] * w2
        c[na + j] = rr[j] * lj * s
        d[j, 0] = rr[j] * cc[j, 0] * s
        d[j, 1] = rr[j] * (cc[j, 1] * s + lj / (2.0 * s))
        d[j, 2] = rr[j] * cc[j, 2] * s
        load[j] = lj
        sq[j] = s


@_kernel
def jac_t(
    v: FloatArray, kk: IntArray, d: FloatArray, out: FloatArray
) -> None:  # pragma: no cover - compiled
    """``out = J' v`` (interior nodes)."""
    m = out.size
    for i in range(m):
        out[i] = v[i] - v[i + 1]
    na = m + 1
    for j in range(kk.size):
        k = kk[j]
        vv = v[na + j]
        if k > 0:
            out[k - 1] += vv * d[j, 0]
        out[k] += vv * d[j, 1]
        if k < m - 1:
            out[k + 1] += vv * d[j, 2]


@_kernel
def objective(
    mode: int, a: FloatArray, b: FloatArray, x: FloatArray, grad: FloatArray, hess: FloatArray
) -> float:  # pragma: no cover - compiled
    """Value of the objective; its gradient and (diagonal) Hessian into ``grad``, ``hess``."""
    value = 0.0
    for i in range(x.size):
        if mode == 0:
            sx = np.sqrt(x[i])
            value += a[i] / sx
            grad[i] = -0.5 * a[i] / (x[i] * sx)
            hess[i] = 0.75 * a[i] / (x[i] * x[i] * sx)
        else:
            r = x[i] - b[i]
            value += 0.5 * a[i] * r * r
            grad[i] = a[i] * r
            hess[i] = a[i]
    return value


@_inner
def _objective_value(
    mode: int, a: FloatArray, b: FloatArray, x: FloatArray
) -> float:  # pragma: no cover - compiled
    value = 0.0
    for i in range(x.size):
        if mode == 0:
            value += a[i] / np.sqrt(x[i])
        else:
            r = x[i] - b[i]
            value += 0.5 * a[i] * r * r
    return value


@_kernel
def gaps(
    x: FloatArray, s: FloatArray, p: FloatArray, q: FloatArray, lb: FloatArray, ub: FloatArray,
    lo: FloatArray, hi: FloatArray, g: FloatArray
) -> None:  # pragma: no cover - compiled
    """The stacked gaps ``(x - lb, ub - x, s - lo, hi - s, p, q)`` into ``g``."""
    m, r, e = x.size, s.size, p.size
    for i in range(m):
        g[i] = x[i] - lb[i]
        g[m + i] = ub[i] - x[i]
    o = 2 * m
    for i in range(r):
        g[o + i] = s[i] - lo[i]
        g[o + r + i] = hi[i] - s[i]
    o += 2 * r
    for i in range(e):
        g[o + i] = p[i]
        g[o + e + i] = q[i]


@_kernel
def residual(
    c: FloatArray, s: FloatArray, p: FloatArray, q: FloatArray, ne: int, out: FloatArray
) -> None:  # pragma: no cover - compiled
    """``out = c - s (+ p - q)``."""
    for i in range(c.size):
        out[i] = c[i] - s[i]
        if ne:
            out[i] = out[i] + p[i] - q[i]


@_kernel
def barrier(
    mode: int, a: FloatArray, b: FloatArray, x: FloatArray, p: FloatArray, q: FloatArray,
    rho: float, g: FloatArray
) -> tuple[float, float]:  # pragma: no cover - compiled
    """The barrier's parts ``(f(x) + ρ Σ (p + q), Σ log g)`` (``nan``, ``-inf`` off bounds)."""
    logs = 0.0
    for i in range(g.size):
        logs += np.log(g[i])
    pen = 0.0
    for i in range(p.size):
        pen += p[i] + q[i]
    return _objective_value(mode, a, b, x) + rho * pen, logs


@_kernel
def errors(
    m: int, ne: int, grad: FloatArray, jty: FloatArray, y: FloatArray, z: FloatArray, g:
    FloatArray, res: FloatArray, tmp: FloatArray, rho: float, mu: float
) -> tuple[float, float]:  # pragma: no cover - compiled
    """IPOPT's scaled optimality error for ``mu = 0`` and for ``mu`` (see ``_Phase.errors``)."""
    r = y.size
    dual = 0.0
    for i in range(m):
        dual = max(dual, abs(grad[i] + jty[i] - z[i] + z[m + i]))
    o = 2 * m
    for i in range(r):
        dual = max(dual, abs(-y[i] - z[o + i] + z[o + r + i]))
    if ne:
        o = 2 * m + 2 * r
        for i in range(r):
            dual = max(dual, abs(rho + y[i] - z[o + i]))
            dual = max(dual, abs(rho - y[i] - z[o + r + i]))
    z_sum = 0.0
    for i in range(z.size):
        z_sum += z[i]
    y_abs = 0.0
    for i in range(r):
        y_abs += abs(y[i])
    s_d = max(1.0, (y_abs + z_sum) / (100.0 * (m + r + g.size)))
    s_c = max(1.0, z_sum / (100.0 * g.size))
    res_max = 0.0
    for i in range(res.size):
        res_max = max(res_max, abs(res[i]))
    rest = max(dual / s_d, res_max)
    gz_max = -np.inf
    gz_mu = 0.0
    for i in range(g.size):
        gz = g[i] * z[i]
        gz_max = max(gz_max, gz)
        gz_mu = max(gz_mu, abs(gz - mu))
    return max(rest, gz_max / s_c), max(rest, gz_mu / s_c)


@_inner
def _cholesky(
    ab: FloatArray, shift: float, f: FloatArray
) -> bool:  # pragma: no cover - compiled
    """Banded Cholesky of ``ab + shift I`` (lower band storage, bandwidth 2) into ``f``.

    Returns False when a pivot is not positive (LAPACK's ``dpbtrf`` with ``info > 0``).
    """
    m = ab.shape[1]
    for j in range(m):
        dj = ab[0, j] + shift
        if j >= 1:
            dj -= f[1, j - 1] * f[1, j - 1]
        if j >= 2:
            dj -= f[2, j - 2] * f[2, j - 2]
        if not dj > 0.0:
            return False
        ljj = np.sqrt(dj)
        f[0, j] = ljj
        if j + 1 < m:
            a1 = ab[1, j]
            if j >= 1:
                a1 -= f[2, j - 1] * f[1, j - 1]
            f[1, j] = a1 / ljj
        else:
            f[1, j] = 0.0
        f[2, j] = ab[2, j] / ljj if j + 2 < m else 0.0
    return True


@_inner
def _band_solve(
    f: FloatArray, b: FloatArray
) -> None:  # pragma: no cover - compiled
    """Solve ``L L' x = b`` in place with the factor of `_cholesky`."""
    m = b.size
    for j in range(m):
        v = b[j]
        if j >= 1:
            v -= f[1, j - 1] * b[j - 1]
        if j >= 2:
            v -= f[2, j - 2] * b[j - 2]
        b[j] = v / f[0, j]
    for j in range(m - 1, -1, -1):
        v = b[j]
        if j + 1 < m:
            v -= f[1, j] * b[j + 1]
        if j + 2 < m:
            v -= f[2, j] * b[j + 2]
        b[j] = v / f[0, j]


@_kernel
def newton(
    m: int, ne: int, y: FloatArray, z: FloatArray, g: FloatArray, grad: FloatArray, jty:
    FloatArray, hess: FloatArray, kk: IntArray, d: FloatArray, rr: FloatArray, cc: FloatArray,
    load: FloatArray, sq: FloatArray, rho: float, mu: float, delta_last: float, ab: FloatArray,
    sig: FloatArray, sig_s: FloatArray, sig_e: FloatArray, r_x: FloatArray, r_s: FloatArray,
    r_p: FloatArray, r_q: FloatArray, r_extra: FloatArray, factor: FloatArray
) -> tuple[float, float]:  # pragma: no cover
    """Condense and factor the Newton system (``_Phase.newton``); returns ``(δ, count)``.

    The Hessian of row ``r (c · w) sqrt(w_k)`` is ``r c1 / sq - r load / (4 sq³)`` on its
    diagonal and ``r c0 / (2 sq)``, ``r c2 / (2 sq)`` next to it; ``δ < 0`` means the
    inertia correction failed.
    """
    r = y.size
    nf = kk.size
    na = m + 1
    o = 2 * m
    for i in range(g.size):
        sig[i] = z[i] / g[i]
    for i in range(r):
        sig_s[i] = sig[o + i] + sig[o + r + i]
        r_s[i] = -y[i] - mu / g[o + i] + mu / g[o + r + i]
        inv = 1.0 / sig_s[i]
        rex = r_s[i] / sig_s[i]
        if ne:
            op = 2 * m + 2 * r
            r_p[i] = rho + y[i] - mu / g[op + i]
            r_q[i] = rho - y[i] - mu / g[op + r + i]
            inv = inv + 1.0 / sig[op + i] + 1.0 / sig[op + r + i]
            rex = rex - r_p[i] / sig[op + i] + r_q[i] / sig[op + r + i]
        r_extra[i] = rex
        sig_e[i] = 1.0 / inv
    # The condensed matrix on the full grid's interior: acceleration rows first.
    for i in range(m):
        r_x[i] = grad[i] + jty[i] - mu / g[i] + mu / g[m + i]
        ab[0, i] = sig_e[i] + sig_e[i + 1] + sig[i] + sig[m + i] + hess[i]
        ab[1, i] = -sig_e[i + 1] if i + 1 < m else 0.0
        ab[2, i] = 0.0
    for j in range(nf):
        k = kk[j]
        s = sig_e[na + j]
        yr = y[na + j] * rr[j]
        sj = sq[j]
        d0, d1, d2 = d[j, 0], d[j, 1], d[j, 2]
        # Interior index of full node k + t is k + t - 1.
        if k >= 1:
            ab[0, k - 1] += s * d0 * d0
            ab[1, k - 1] += s * d0 * d1 + yr * cc[j, 0] / (2.0 * sj)
            if k + 1 < m:
                ab[2, k - 1] += s * d0 * d2
        ab[0, k] += s * d1 * d1 + yr * (cc[j, 1] / sj - load[j] / (4.0 * sj**3))
        if k + 1 < m:
            ab[0, k + 1] += s * d2 * d2
            ab[1, k] += s * d1 * d2 + yr * cc[j, 2] / (2.0 * sj)
    if _cholesky(ab, 0.0, factor):
        return 0.0, 1.0
    count = 1.0
    if delta_last == 0.0:
        delta = DELTA_W_FIRST
    else:
        delta = max(DELTA_W_MIN, KAPPA_W_MINUS * delta_last)
    while delta <= DELTA_W_MAX:
        count += 1.0
        if _cholesky(ab, delta, factor):
            return delta, count
        delta *= KAPPA_W_PLUS_FIRST if delta_last == 0.0 else KAPPA_W_PLUS
    return -1.0, count


@_kernel
def direction(
    ne: int, factor: FloatArray, sig: FloatArray, sig_s: FloatArray, sig_e: FloatArray, r_x:
    FloatArray, r_s: FloatArray, r_p: FloatArray, r_q: FloatArray, r_extra: FloatArray, kk:
    IntArray, d: FloatArray, r_c: FloatArray, dx: FloatArray, ds: FloatArray, dp: FloatArray,
    dq: FloatArray, dy: FloatArray, dz: FloatArray
) -> None:  # pragma: no cover - compiled
    """The Newton step for the row residual ``r_c`` (``_Phase.direction``)."""
    m = dx.size
    r = r_c.size
    na = m + 1
    for i in range(r):
        dy[i] = sig_e[i] * (r_c[i] + r_extra[i])  # sig_e r_t, reused below
    jac_t(dy, kk, d, dx)
    for i in range(m):
        dx[i] = -r_x[i] - dx[i]
    _band_solve(factor, dx)
    # dy = sig_e (J dx + r_t)
    for i in range(na):
        hi = dx[i] if i < m else 0.0
        lo = dx[i - 1] if i >= 1 else 0.0
        dy[i] = sig_e[i] * (hi - lo + r_c[i] + r_extra[i])
    for j in range(kk.size):
        k = kk[j]
        a0 = dx[k - 1] if k >= 1 else 0.0
        a2 = dx[k + 1] if k + 1 < m else 0.0
        jd = d[j, 0] * a0 + d[j, 1] * dx[k] + d[j, 2] * a2
        dy[na + j] = sig_e[na + j] * (jd + r_c[na + j] + r_extra[na + j])
    for i in range(r):
        ds[i] = (dy[i] - r_s[i]) / sig_s[i]
    for i in range(m):
        dz[i] = dx[i]
        dz[m + i] = -dx[i]
    o = 2 * m
    for i in range(r):
        dz[o + i] = ds[i]
        dz[o + r + i] = -ds[i]
    if ne:
        o = 2 * m + 2 * r
        for i in range(r):
            dp[i] = (-dy[i] - r_p[i]) / sig[o + i]
            dq[i] = (dy[i] - r_q[i]) / sig[o + r + i]
            dz[o + i] = dp[i]
            dz[o + r + i] = dq[i]


@_kernel
def max_step(
    v: FloatArray, dv: FloatArray, tau: float
) -> float:  # pragma: no cover - compiled
    """Largest ``α <= 1`` with ``v + α dv >= (1 - τ) v`` (fraction to the boundary)."""
    ratio = np.inf
    for i in range(v.size):
        if dv[i] < 0:
            ratio = min(ratio, -v[i] / dv[i])
    return min(1.0, tau * ratio)


@_kernel
def dual_step(
    ne: int, grad: FloatArray, dx: FloatArray, z: FloatArray, g: FloatArray, sig: FloatArray,
    gstep: FloatArray, mu: float, tau: float, rho: float, dz: FloatArray
) -> tuple[float, float]:  # pragma: no cover
    """The bound multipliers' step ``dz``; returns ``(α_dual, ∇φ · d)``.

    ``gstep`` is the gaps' step (``d.z``); ``dz = μ/g - z - σ gstep``.
    """
    ratio = np.inf
    dphi = 0.0
    for i in range(dx.size):
        dphi += grad[i] * dx[i]
    for i in range(g.size):
        mg = mu / g[i]
        dz[i] = mg - z[i] - sig[i] * gstep[i]
        dphi -= mg * gstep[i]
        if dz[i] < 0:
            ratio = min(ratio, -z[i] / dz[i])
    if ne:
        m = dx.size
        r = (g.size - 2 * m) // 4
        o = 2 * m + 2 * r
        for i in range(2 * r):
            dphi += rho * gstep[o + i]
    return min(1.0, tau * ratio), dphi


@_kernel
def new_z(
    z: FloatArray, a_dual: float, dz: FloatArray, g: FloatArray, mu: float, kappa_sigma: float,
    out: FloatArray
) -> None:  # pragma: no cover - compiled
    """``z + α dz`` kept within a factor ``κ_Σ`` of ``μ / g`` (IPOPT's safeguard)."""
    for i in range(z.size):
        out[i] = min(max(z[i] + a_dual * dz[i], mu / (kappa_sigma * g[i])),
                     kappa_sigma * mu / g[i])


@_kernel
def tiny(
    dv: FloatArray, g: FloatArray
) -> float:  # pragma: no cover - compiled
    """``max |dv| / (1 + g)`` (IPOPT's tiny-step test)."""
    out = 0.0
    for i in range(dv.size):
        out = max(out, abs(dv[i]) / (1.0 + g[i]))
    return out


#: The kernels called from Python (all but the three called only from the others).
ENTRY_POINTS = tuple(name for name in SIGNATURES if not name.startswith("_"))


def signatures() -> dict[str, str]:
    """Every kernel and its signature, `SIGNATURES` (see `speedplan.core.jit`)."""
    return dict(SIGNATURES)
