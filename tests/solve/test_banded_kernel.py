"""The banded kernel's algebra against independent dense references built with numpy.

The constraint map ``G`` is rebuilt here from the relaxation's definition (rows of the
problem, the two cones per node), not from the kernel; the Newton system is solved densely
(the full KKT system with the Nesterov–Todd scaling written out as matrices). CI also runs
this file with ``NUMBA_BOUNDSCHECK=1``.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg

from speedplan.solve import _banded_ipm as ipm
from speedplan.solve._banded_ipm import python_callable as _py
from speedplan.solve.banded import _prepare, unit_scales
from speedplan.solve.nojerk import positive_feasible_w
from speedplan.solve.paper import paper_instance
from speedplan.solve.problem import DiscreteProblem, StencilRows

N = 24
J = np.diag([1.0, -1.0, -1.0])


def _problem(seed: int) -> DiscreteProblem:
    """Non-uniform grid, floors, some infinite jerk rows, lateral rows, moving ends."""
    rng = np.random.default_rng(seed)
    inst = paper_instance("rnd", "rnd", "rnd", n=N, seed=seed)
    s = np.concatenate(([0.0], np.cumsum(rng.uniform(0.5, 1.5, N - 1))))
    jerk = inst.J.copy()
    jerk[::4] = np.inf
    bound = rng.uniform(0.5, 5.0, N - 2)
    bound[1::3] = np.inf
    lateral = StencilRows(coef=rng.normal(size=(N - 2, 3)), bound=bound)
    w_max = inst.w_max.copy()
    w_min = np.zeros(N)
    w_min[5:8] = 0.01 * w_max[5:8]
    return DiscreteProblem(s=s, w_max=w_max, accel=inst.A, decel=inst.A, jerk=jerk,
                           w_start=0.2 * w_max[0], w_end=0.0, w_min=w_min, lateral=lateral)


def _setup(seed: int):
    p = _problem(seed)
    unit = p.scaled(*unit_scales(p))
    d = _prepare(unit, positive_feasible_w(unit)[1:-1])
    return unit, d


def _dense_g(unit: DiscreteProblem, d: ipm.Data) -> tuple[np.ndarray, np.ndarray]:
    """``(G_lin, G_soc)`` over ``x = (ŵ, t̂, ẑ)`` from the relaxation's definition.

    ``G_soc`` has shape ``(3, nc, 3 m)``: component, cone, variable.
    """
    m = unit.n - 2
    cw = d.cw
    ct = unit.tau / np.sqrt(cw)

    def full(w_hat):  # the full w of a scaled interior ŵ, fixed ends at 0 (linear part)
        return np.concatenate(([0.0], cw * w_hat, [0.0]))

    w_min = np.zeros(m) if unit.w_min is None else unit.w_min[1:-1]
    low = np.flatnonzero(w_min > 0)
    stencil_rows = []  # (node, family, operator row over w, coefficient)
    for f, fam in enumerate(unit.stencil_families()):
        op = unit.stencil_matrix(fam.coef).toarray()
        for i in np.flatnonzero(np.isfinite(fam.bound)):
            stencil_rows.append((i, f, op[i], unit.tau[i] / fam.bound[i] / ct[i]))
    stencil_rows.sort(key=lambda r: (r[0], r[1]))
    cols = []
    for k in range(3 * m):
        x = np.zeros(3 * m)
        x[k] = 1.0
        w_hat, t_hat, z_hat = x[:m], x[m : 2 * m], x[2 * m :]
        acc = np.diff(full(w_hat))
        jp = np.array([c * (row @ full(w_hat)) - t_hat[i] for i, _, row, c in stencil_rows])
        jm = np.array([-c * (row @ full(w_hat)) - t_hat[i] for i, _, row, c in stencil_rows])
        lin = np.concatenate((acc, -acc, w_hat, -w_hat[low], jp, jm))
        # s = b - G x: (1 + ŵ, 2ẑ, ŵ - 1) for ẑ² <= ŵ and (t̂ + ẑ, t̂ - ẑ, 2) for t̂ ẑ >= 1.
        soc = np.zeros((3, 2 * m))
        soc[:, :m] = -np.vstack((w_hat, 2.0 * z_hat, w_hat))
        soc[:, m:] = -np.vstack((t_hat + z_hat, t_hat - z_hat, np.zeros(m)))
        cols.append((lin, soc))
    g_lin = np.column_stack([c[0] for c in cols])
    g_soc = np.stack([c[1] for c in cols], axis=-1)
    return g_lin, g_soc


def _interior_cones(rng: np.random.Generator, nc: int) -> np.ndarray:
    u = rng.normal(size=(3, nc))
    u[0] = np.hypot(u[1], u[2]) * (1.0 + 10.0 ** rng.uniform(-3, 0, nc))
    return u


def _w_matrix(sc: ipm.Scaling, c: int) -> np.ndarray:
    v = sc.v[:, c]
    return sc.beta[c] * (2.0 * np.outer(v, v) - J)


def _arrow(lam: np.ndarray) -> np.ndarray:
    """Matrix of ``u -> λ ∘ u`` (the Jordan product of the second-order cone)."""
    return np.array([[lam[0], lam[1], lam[2]], [lam[1], lam[0], 0.0], [lam[2], 0.0, lam[0]]])


@pytest.mark.parametrize("seed", [0, 1])
def test_constraint_map_matches_the_definition_and_its_adjoint(seed):
    unit, d = _setup(seed)
    lay = d.lay
    g_lin, g_soc = _dense_g(unit, d)
    assert g_lin.shape == (lay.n_lin, 3 * lay.m)
    rng = np.random.default_rng(seed)
    x = rng.normal(size=3 * lay.m)
    w, t, z = np.split(x, 3)
    out_lin, out_soc = np.zeros(lay.n_lin), np.zeros((3, lay.nc))
    _py(ipm.g_lin_into)(d, w, t, out_lin)
    _py(ipm.g_soc_into)(w, t, z, out_soc)
    np.testing.assert_allclose(out_lin, g_lin @ x, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(out_soc, g_soc @ x, rtol=1e-12, atol=1e-12)
    # Adjoint: <G x, y> = <x, G' y>, and G' y is the dense transpose applied.
    yl, ys = rng.normal(size=lay.n_lin), rng.normal(size=(3, lay.nc))
    gw, gt, gz = np.zeros(lay.m), np.zeros(lay.m), np.zeros(lay.m)
    _py(ipm.g_adjoint_into)(d, yl, ys, gw, gt, gz, ipm.ADJ_SET)
    gty = np.concatenate((gw, gt, gz))
    lhs = float(out_lin @ yl + np.sum(out_soc * ys))
    assert lhs == pytest.approx(float(x @ gty), rel=1e-12)
    ref = g_lin.T @ yl + np.einsum("rck,rc->k", g_soc, ys)
    np.testing.assert_allclose(gty, ref, rtol=1e-12, atol=1e-12)
    # The other modes round as the finished G' y combined with g; each returns the squared
    # norms of what it wrote.
    g0 = [rng.normal(size=lay.m) for _ in range(3)]
    ct = np.zeros(3 * lay.m)
    ct[lay.m : 2 * lay.m] = d.ct
    for mode, want in ((ipm.ADJ_SUBTRACT, np.concatenate(g0) - gty),
                       (ipm.ADJ_ADD, gty + np.concatenate(g0)),
                       (ipm.ADJ_DUAL_RESIDUAL, -(gty + ct))):
        got = [a.copy() for a in g0]
        norms = _py(ipm.g_adjoint_into)(d, yl, ys, *got, mode)
        np.testing.assert_array_equal(np.concatenate(got), want)
        assert norms == pytest.approx([float(a @ a) for a in got], rel=1e-13)


def _in_soc(u: np.ndarray) -> bool:
    return bool(u[0] >= np.hypot(u[1], u[2]))


@pytest.mark.parametrize("seed", range(5))
def test_max_step_is_the_step_to_the_cone_boundary(seed):
    rng = np.random.default_rng(seed)
    nc = 40
    u = _interior_cones(rng, nc)
    du = rng.normal(size=(3, nc)) * 10.0 ** rng.uniform(-1, 1)
    alpha = _py(ipm.max_step_soc)(u, du)
    # Per cone by bisection on membership; the kernel's step is the smallest one.
    steps = []
    for c in range(nc):
        if _in_soc(u[:, c] + 1e6 * du[:, c]) and all(
            _in_soc(u[:, c] + a * du[:, c]) for a in np.geomspace(1e-6, 1e6, 200)
        ):
            steps.append(np.inf)
            continue
        lo, hi = 0.0, 1e6
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if _in_soc(u[:, c] + mid * du[:, c]) else (lo, mid)
        steps.append(lo)
    assert alpha == pytest.approx(min(steps), rel=1e-9)
    # Linear rows.
    ul = 10.0 ** rng.uniform(-2, 2, 50)
    dul = rng.normal(size=50)
    ref = min((-ul[dul < 0] / dul[dul < 0]), default=np.inf)
    assert _py(ipm.max_step_lin)(ul, dul) == pytest.approx(ref, rel=1e-14)
    assert _py(ipm.max_step_lin)(ul, np.abs(dul)) == np.inf


@pytest.mark.parametrize("seed", range(3))
def test_nesterov_todd_scaling_identities(seed):
    rng = np.random.default_rng(seed)
    nc = 30
    s, y = _interior_cones(rng, nc), _interior_cones(rng, nc)
    lay = ipm.layout(nc // 2, 0, 0)
    sc = ipm.Scaling.identity(lay)
    for c in range(nc):
        _py(ipm.cone_scaling_into)(sc, c, *s[:, c], *y[:, c])
    for c in range(nc):
        w = _w_matrix(sc, c)
        lam = np.array(_py(ipm._lambda)(sc, y, c))
        np.testing.assert_allclose(w @ y[:, c], lam, rtol=1e-10, atol=1e-12)  # W y = λ
        np.testing.assert_allclose(np.linalg.solve(w, s[:, c]), lam, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(w @ J @ w, sc.beta[c] ** 2 * J, rtol=1e-10, atol=1e-12)
        h = np.linalg.inv(w @ w)
        for k in range(3):
            e = np.eye(3)[k]
            np.testing.assert_allclose(_py(ipm._apply_h)(sc, *e, c), h[:, k], rtol=1e-9,
                                       atol=1e-12 * np.abs(h).max())
            np.testing.assert_allclose(_py(ipm._apply_winv)(sc, *e, c), np.linalg.inv(w)[:, k],
                                       rtol=1e-9, atol=1e-12 * np.abs(h).max())


def _interior_x(rng: np.random.Generator, m: int) -> tuple[np.ndarray, ...]:
    """``(w, t, z)`` with both cones of every node strictly interior: ``z² < w``, ``t z > 1``."""
    w = 10.0 ** rng.uniform(-1, 1, m)
    z = np.sqrt(w) * rng.uniform(0.05, 0.95, m)
    t = (1.0 + 10.0 ** rng.uniform(-3, 0, m)) / z
    return w, t, z


def _b_soc(m: int) -> np.ndarray:
    """Constant part of the cone rows: ``(1, 0, -1)`` per node cone, ``(0, 0, 2)`` per t-z cone."""
    b = np.zeros((3, 2 * m))
    b[0, :m], b[2, :m], b[2, m:] = 1.0, -1.0, 2.0
    return b


def _random_state(seed: int):
    """A factored Newton system at a random interior point of the seed's problem."""
    unit, d = _setup(seed)
    lay = d.lay
    rng = np.random.default_rng(100 + seed)
    pt = ipm.empty(ipm.Point, lay)
    pt.w[:], pt.t[:], pt.z[:] = _interior_x(rng, lay.m)
    pt.sl[:], pt.yl[:] = 10.0 ** rng.uniform(-1, 1, (2, lay.n_lin))
    pt.ys[:] = _interior_cones(rng, lay.nc)
    sc = ipm.Scaling.identity(lay)
    _py(ipm.scaling_into)(pt, sc)
    fac = ipm.empty(ipm.Factor, lay)
    assert _py(ipm.factor_into)(d, sc, pt.yl, pt.sl, fac)
    g_lin, g_soc = _dense_g(unit, d)
    # Dense H = W⁻²: diag(y / s) on the linear rows, inv(W_c)² per cone (cone-major order).
    g_cones = np.concatenate([g_soc[:, c, :] for c in range(lay.nc)])
    h_cones = scipy.linalg.block_diag(*(np.linalg.inv(_w_matrix(sc, c) @ _w_matrix(sc, c))
                                        for c in range(lay.nc)))
    k_mat = g_lin.T @ np.diag(pt.yl / pt.sl) @ g_lin + g_cones.T @ h_cones @ g_cones
    return d, pt, sc, fac, g_lin, g_soc, k_mat, rng


@pytest.mark.parametrize("seed", [0, 1])
def test_cone_slacks_are_b_minus_g_x(seed):
    # The kernel keeps no cone slacks: s = b - G x and Δs = -G Δx, against the dense G.
    d, pt, sc, _, _, g_soc, _, rng = _random_state(seed)
    lay = d.lay
    x = np.concatenate((pt.w, pt.t, pt.z))
    dx = rng.normal(size=3 * lay.m)
    s_ref, ds_ref = _b_soc(lay.m) - g_soc @ x, -(g_soc @ dx)
    dw, dt, dz = np.split(dx, 3)
    for c in range(lay.nc):
        np.testing.assert_allclose(_py(ipm._cone_s)(pt.w, pt.t, pt.z, c), s_ref[:, c], rtol=1e-14)
        np.testing.assert_allclose(_py(ipm._cone_ds)(dw, dt, dz, c), ds_ref[:, c], rtol=1e-14)
    # The scaling is the one of those slacks: W⁻¹ s = W y.
    for c in range(lay.nc):
        w = _w_matrix(sc, c)
        np.testing.assert_allclose(np.linalg.solve(w, s_ref[:, c]), w @ pt.ys[:, c],
                                   rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("seed", [0, 1])
def test_reduced_matrix_is_the_schur_complement_and_its_banded_solve(seed):
    d, _, _, fac, _, _, k_mat, rng = _random_state(seed)
    m = d.lay.m
    kww, kwx, kxx = k_mat[:m, :m], k_mat[:m, m:], k_mat[m:, m:]
    schur = kww - kwx @ np.linalg.solve(kxx, kwx.T)
    # L D L' of the kernel, rebuilt densely; its band is 2.
    lower = np.eye(m) + np.diag(fac.l1[1:], -1) + np.diag(fac.l2[2:], -2)
    np.testing.assert_allclose(lower @ np.diag(fac.dd) @ lower.T, schur, rtol=1e-9,
                               atol=1e-9 * np.abs(schur).max())
    assert np.all(np.abs(np.tril(schur, -3)) <= 1e-12 * np.abs(schur).max())
    b = rng.normal(size=m)
    x = b.copy()
    _py(ipm.solve_banded_inplace)(fac, x)
    ab = np.zeros((3, m))  # upper banded form for solveh_banded
    for k in range(3):
        ab[2 - k, k:] = np.diag(schur, k)
    np.testing.assert_allclose(x, scipy.linalg.solveh_banded(ab, b), rtol=1e-8,
                               atol=1e-10 * np.abs(x).max())


@pytest.mark.parametrize("seed", [0, 1])
def test_normal_equations_solve_matches_a_dense_solve(seed):
    d, _, _, fac, _, _, k_mat, rng = _random_state(seed)
    m = d.lay.m
    r = rng.normal(size=3 * m)
    x = r.copy()
    _py(ipm.solve_normal_inplace)(d, fac, x[:m], x[m : 2 * m], x[2 * m :])
    np.testing.assert_allclose(x, np.linalg.solve(k_mat, r), rtol=1e-8,
                               atol=1e-10 * np.abs(x).max())


def _jordan(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """The Jordan product ``u ∘ v`` of one second-order cone."""
    return np.array([u @ v, u[0] * v[1] + v[0] * u[1], u[0] * v[2] + v[0] * u[2]])


@pytest.mark.parametrize("seed", [0, 1])
@pytest.mark.parametrize("refine_above", [np.inf, 0.0])
@pytest.mark.parametrize("corrector", [False, True])
def test_newton_direction_solves_the_full_kkt_system(seed, refine_above, corrector):
    # G'Δy = bx, GΔx + Δs = by, λ ∘ (WΔy + W⁻¹Δs) = bs, solved densely. by is the scalar rp
    # on the linear rows and 0 on the cones; bs is -λ∘λ (predictor) or Mehrotra's
    # -λ∘λ - η (W⁻¹Δs_a) ∘ (WΔy_a) + σμ e for a given predictor direction and weight η of
    # the second-order term (corrector).
    d, pt, sc, fac, g_lin, g_soc, _, rng = _random_state(seed)
    lay = d.lay
    m, nl, nc = lay.m, lay.n_lin, lay.nc
    res = ipm.empty(ipm.Residual, lay)
    _py(ipm.dual_residual_into)(d, pt, res)  # newton_into's bx is the iterate's dual residual
    rp, sigma_mu = float(rng.normal()), float(10.0 ** rng.uniform(-2, 0))
    second_order = float(rng.uniform(0.1, 1.0))
    dn = ipm.empty(ipm.Direction, lay)
    for arr in dn:  # the predictor's direction, read by the corrector
        arr[:] = rng.normal(size=arr.shape)
    pred = [np.copy(a) for a in dn]
    _py(ipm.newton_into)(d, sc, fac, pt, res, rp, corrector, sigma_mu, second_order,
                         refine_above, dn)
    # Unknowns: Δx (3m), Δs_lin (nl), Δs_soc (3 nc, cone-major), Δy_lin, Δy_soc.
    g_cones = np.concatenate([g_soc[:, c, :] for c in range(nc)])
    nx, ns = 3 * m, nl + 3 * nc
    g = np.vstack((g_lin, g_cones))
    kkt = np.zeros((nx + 2 * ns, nx + 2 * ns))
    rhs_vec = np.zeros(nx + 2 * ns)
    kkt[:nx, nx + ns :] = g.T
    rhs_vec[:nx] = np.concatenate((res.gw, res.gt, res.gz))
    kkt[nx : nx + ns, :nx] = g
    kkt[nx : nx + ns, nx : nx + ns] = np.eye(ns)
    rhs_vec[nx : nx + nl] = rp
    row = nx + ns
    # Linear rows: λ = sqrt(s y), W = sqrt(s / y): λ (W Δy + Δs / W) = y Δs + s Δy.
    kkt[row : row + nl, nx : nx + nl] = np.diag(pt.yl)
    kkt[row : row + nl, nx + ns : nx + ns + nl] = np.diag(pt.sl)
    rhs_vec[row : row + nl] = -pt.sl * pt.yl
    if corrector:
        rhs_vec[row : row + nl] += sigma_mu - second_order * pred[3] * pred[4]
    ds_pred = -(g_soc @ np.concatenate(pred[:3]))
    for c in range(nc):
        w = _w_matrix(sc, c)
        lam = w @ pt.ys[:, c]
        r0 = row + nl + 3 * c
        kkt[r0 : r0 + 3, nx + nl + 3 * c : nx + nl + 3 * c + 3] = _arrow(lam) @ np.linalg.inv(w)
        kkt[r0 : r0 + 3, nx + ns + nl + 3 * c : nx + ns + nl + 3 * c + 3] = _arrow(lam) @ w
        rhs_vec[r0 : r0 + 3] = -_jordan(lam, lam)
        if corrector:
            rhs_vec[r0 : r0 + 3] += sigma_mu * np.array([1.0, 0.0, 0.0]) - second_order * (
                _jordan(np.linalg.solve(w, ds_pred[:, c]), w @ pred[5][:, c]))
    sol = np.linalg.solve(kkt, rhs_vec)
    dx = np.concatenate((dn.dw, dn.dt, dn.dz))
    ds_soc = -(g_soc @ dx)  # the kernel's implied Δs of the cones
    got = np.concatenate((dx, dn.dsl, ds_soc.T.ravel(), dn.dyl, dn.dys.T.ravel()))
    np.testing.assert_allclose(got, sol, rtol=1e-7, atol=1e-9 * np.abs(sol).max())


@pytest.mark.parametrize("seed", [0, 1])
@pytest.mark.parametrize("iterations", [1, 3])
def test_linear_rows_primal_residual_stays_one_number(seed, iterations):
    # The kernel carries the linear rows' primal residual b - G x - s as one scalar: the
    # start's shift is the same on every row and each step removes the fraction α_primal of
    # it (log column "primal_step"). Forced here by a start above a speed bound; checked
    # against the dense G.
    from speedplan.solve.banded import _kernel_args

    unit, d = _setup(seed)
    lay = d.lay
    g_lin, _ = _dense_g(unit, d)
    b = d.rhs_lin()

    def run(iters):
        args = _kernel_args(unit, d)
        pt = args[1]
        pt.w[3] = 3.0 * unit.w_max[4] / d.cw[3]  # z² < w and t z > 1 still hold
        log = np.full((iters + 1, len(ipm.LOG_COLUMNS)), np.nan)
        ipm.iterate(*args, log, 1e-8, iters)
        return pt, log, b - g_lin @ np.concatenate((pt.w, pt.t, pt.z)) - pt.sl

    _, _, r0 = run(0)  # the start's residual: no step taken
    pt, log, r = run(iterations)
    assert np.abs(r).max() > 1e-6  # the shift is not yet gone
    assert np.ptp(r) <= 1e-12 * max(1.0, float(np.abs(b).max()))
    primal = log[:iterations, ipm.LOG_COLUMNS.index("primal_step")]
    dual = log[:iterations, ipm.LOG_COLUMNS.index("dual_step")]
    assert np.all((primal > 0) & (dual > 0))
    assert r.mean() == pytest.approx(r0.mean() * np.prod(1.0 - primal), rel=1e-9)
    # The logged primal residual of the last iteration is that of the iterate.
    _, _, _, ry2, _ = _py(ipm.residuals_into)(d, pt, ipm.empty(ipm.Residual, lay),
                                              np.zeros(lay.n_lin))
    assert ry2 == pytest.approx(float(r @ r), rel=1e-9)


def test_kernel_keeps_fifty_seven_doubles_per_node():
    # The kernel's arrays on a plain jerk-limited problem (one stencil row per node, no
    # floors): 57 doubles per node (docs/banded-ipm.md lists them), 456 bytes.
    from speedplan.solve.banded import _kernel_args

    inst = paper_instance("rnd", "cnst", "cnst", n=2000, seed=0)
    p = DiscreteProblem(s=np.arange(inst.w_max.size, dtype=float), w_max=inst.w_max,
                        accel=inst.A, decel=inst.A, jerk=inst.J)
    unit = p.scaled(*unit_scales(p))
    d = _prepare(unit, positive_feasible_w(unit)[1:-1])
    kernel = _kernel_args(unit, d)[1:]
    doubles = sum(a.size for part in kernel for a in part) / d.lay.m
    assert 56.9 < doubles <= 57.01


def test_solve_discrete_peak_memory_per_node():
    # Memory: solve_discrete at most 600 bytes per node at its peak.
    # tracemalloc counts numpy's allocations, so the number is deterministic (no timing);
    # it was 1 048 B/node before the kernel stopped storing its derivable vectors.
    import tracemalloc

    from speedplan import solve_discrete

    small = paper_instance("rnd", "cnst", "cnst", n=200, seed=0)
    solve_discrete(small.w_max, small.A, small.J, backend="banded")  # compiled before tracing
    n = 20_000
    inst = paper_instance("rnd", "cnst", "cnst", n=n, seed=0)
    tracemalloc.start()
    try:
        sol = solve_discrete(inst.w_max, inst.A, inst.J, backend="banded")
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert sol.status == "optimal"
    assert peak / n <= 600
