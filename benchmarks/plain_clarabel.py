"""The paper's SOCP (eq. relax_SOCP) built the obvious way, for comparison only.

Three 3-D cones per node with auxiliary ``x1, x2`` exactly as printed in the paper, rows
appended one node at a time in Python. This is the baseline our ratios are measured against.
"""

from __future__ import annotations

import time

import clarabel
import numpy as np
import scipy.sparse as sp


def solve_plain(w_max, A, J, h=1.0):
    """Return (objective, w, solve_seconds, total_seconds) of the paper's SOCP via Clarabel."""
    t0 = time.perf_counter()
    n = len(w_max)
    A = np.broadcast_to(np.asarray(A, float), (n - 1,))
    J = np.broadcast_to(np.asarray(J, float), (n - 2,))
    m = n - 2
    # variables: w (n), t (m), x1 (m), x2 (m)
    W, T, X1, X2 = 0, n, n + m, n + 2 * m
    nvar = n + 3 * m
    eq_rows, ineq_rows, soc_rows = [], [], []
    eq_rows.append(({W: 1.0}, 0.0))
    eq_rows.append(({W + n - 1: 1.0}, 0.0))
    for i in range(n - 1):
        ineq_rows.append(({W + i + 1: 1.0, W + i: -1.0}, A[i] * h))
        ineq_rows.append(({W + i: 1.0, W + i + 1: -1.0}, A[i] * h))
    for i in range(n):
        ineq_rows.append(({W + i: 1.0}, w_max[i]))
        ineq_rows.append(({W + i: -1.0}, 0.0))
    for k in range(m):
        i = k + 1
        c = 1.0 / (h * J[k])
        ineq_rows.append(({W + i - 1: c, W + i: -2 * c, W + i + 1: c, T + k: -1.0}, 0.0))
        ineq_rows.append(({W + i - 1: -c, W + i: 2 * c, W + i + 1: -c, T + k: -1.0}, 0.0))
        ineq_rows.append(({X1 + k: -1.0}, 0.0))
        ineq_rows.append(({X2 + k: -1.0}, 0.0))
        sq = 1.0 / np.sqrt(h)
        # ||(2 x2/sqrt(h), t - 1)|| <= t + 1
        soc_rows.append([({T + k: -1.0}, 1.0), ({X2 + k: -2 * sq}, 0.0), ({T + k: -1.0}, -1.0)])
        # ||(2 x1/sqrt(h), t - w)|| <= t + w
        soc_rows.append([({T + k: -1.0, W + i: -1.0}, 0.0), ({X1 + k: -2 * sq}, 0.0),
                         ({T + k: -1.0, W + i: 1.0}, 0.0)])
        # ||(2h, x2 - x1)|| <= x2 + x1
        soc_rows.append([({X2 + k: -1.0, X1 + k: -1.0}, 0.0), ({}, 2 * h),
                         ({X2 + k: -1.0, X1 + k: 1.0}, 0.0)])
    rows, cols, vals, b = [], [], [], []
    r = 0
    for block in (eq_rows, ineq_rows, [row for cone in soc_rows for row in cone]):
        for coeffs, rhs in block:
            for col, v in coeffs.items():
                rows.append(r)
                cols.append(col)
                vals.append(v)
            b.append(rhs)
            r += 1
    Amat = sp.csc_matrix((vals, (rows, cols)), shape=(r, nvar))
    q = np.zeros(nvar)
    q[T : T + m] = 1.0
    cones = [clarabel.ZeroConeT(len(eq_rows)), clarabel.NonnegativeConeT(len(ineq_rows))]
    cones += [clarabel.SecondOrderConeT(3)] * len(soc_rows)
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    t1 = time.perf_counter()
    solver = clarabel.DefaultSolver(sp.csc_matrix((nvar, nvar)), q, Amat, np.array(b), cones,
                                    settings)
    sol = solver.solve()
    t2 = time.perf_counter()
    if str(sol.status) not in ("Solved", "AlmostSolved"):
        raise RuntimeError(f"plain Clarabel: {sol.status}")
    return float(sol.obj_val), np.asarray(sol.x)[:n], t2 - t1, t2 - t0
