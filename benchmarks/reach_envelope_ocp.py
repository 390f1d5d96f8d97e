"""Check the reach envelope of a moving state against a direct optimal-control solve.

Usage::

    python benchmarks/reach_envelope_ocp.py [--states 40] [--seed 7]

For random states ``(v, a)``, limits and distances ``D``, CasADi + IPOPT maximise ``v(T)²``
over piecewise-constant jerk (150 intervals, free ``T``, ``v >= 0``, acceleration and jerk
bounds, ``s(T) = D``) from three initial durations, and the best is printed next to the
max-jerk motion (``jerk_motion_w``) and the envelope (``fastest_w``). A local solver only
finds motions, so it can show the envelope too low (``<-- above``), never too high.
"""

from __future__ import annotations

import argparse

import casadi as ca
import numpy as np

from speedplan.model.boundary import fastest_w, jerk_motion_w


def best_w(v0: float, a0: float, j: float, a_hi: float, a_lo: float, d: float,
           n: int = 150) -> float:
    best = -1.0
    for t0 in (d / max(v0, 1e-3) * 0.5, d / max(v0, 1e-3), 3 * (6 * d / j) ** (1 / 3)):
        opti = ca.Opti()
        x, u, t_end = opti.variable(3, n + 1), opti.variable(n), opti.variable()
        h = t_end / n
        for k in range(n):
            s, v, a = x[0, k], x[1, k], x[2, k]
            opti.subject_to(x[:, k + 1] == ca.vertcat(s + v * h + a * h**2 / 2 + u[k] * h**3 / 6,
                                                      v + a * h + u[k] * h**2 / 2, a + u[k] * h))
        opti.subject_to(x[:, 0] == ca.vertcat(0, v0, a0))
        opti.subject_to(x[0, n] == d)
        opti.subject_to(opti.bounded(-j, u, j))
        opti.subject_to(opti.bounded(-a_lo, x[2, :], a_hi))
        opti.subject_to(x[1, :] >= 0)
        opti.subject_to(t_end >= 1e-6)
        opti.minimize(-x[1, n] ** 2)
        opti.set_initial(t_end, t0)
        opti.set_initial(x[1, :], v0)
        opti.solver("ipopt", {"print_time": False},
                    {"print_level": 0, "max_iter": 2000, "tol": 1e-10, "sb": "yes"})
        try:
            sol = opti.solve()
        except RuntimeError:
            continue
        best = max(best, float(sol.value(x[1, n])) ** 2)
    return best


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--states", type=int, default=40)
    ap.add_argument("--seed", type=int, default=7)
    args = ap.parse_args()
    rng = np.random.default_rng(args.seed)
    above = solved = 0
    for _ in range(args.states):
        j = 10 ** rng.uniform(-1.5, 0.5)
        a_hi, a_lo = 10 ** rng.uniform(-1, 0.3), 10 ** rng.uniform(-1, 0.3)
        v = 10 ** rng.uniform(-1.5, 0.5)
        a = rng.uniform(-a_lo, a_hi)
        if a < 0 and v - a * a / (2 * j) <= 0:
            continue  # a forced stop: planned as one, not capped
        d = 10 ** rng.uniform(-1.5, 1.5)
        at = np.array([d])
        fast_in_time = float(jerk_motion_w(at, v, a, j, a_hi)[0])
        envelope = float(fastest_w(at, v, a, j, a_hi, a_lo)[0])
        found = best_w(v, a, j, a_hi, a_lo, d)
        solved += found >= 0
        flag = "  <-- above" if found > envelope * (1 + 1e-4) else ""
        above += bool(flag)
        print(f"v={v:.3g} a={a:.3g} j={j:.3g} a_max={a_hi:.3g} a_brake={a_lo:.3g} D={d:.3g}: "
              f"max-jerk {fast_in_time:.6g}  envelope {envelope:.6g}  OCP {found:.6g}{flag}")
    print(f"{solved} solved, {above} above the envelope")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
