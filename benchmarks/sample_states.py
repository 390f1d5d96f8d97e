"""Record or compare every sampled state of ``plan()`` on the benchmark cases, to rounding.

For each case of ``bench_all.cases()`` (the sample paths, the 20-waypoint serpentine, the
braking start), with its own limits on the default grid, at ``n = 1000`` and without a jerk
limit: the duration, the 100 Hz trajectory's columns (``t, s, v, a, j, x, y, heading,
curvature, a_lat, j_lat``), ``time_at`` on 777 arc lengths and the ratios of ``verify()``.
``compare`` prints, per column, the largest difference relative to the column's largest value
over all cases (a change of rounding shows as ~1e-16; a change of results would not).

    python benchmarks/sample_states.py record /tmp/before.npz
    python benchmarks/sample_states.py compare /tmp/before.npz /tmp/after.npz
"""

from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np
from bench_all import cases
from kernel_fingerprint import record_or_compare

import speedplan as sp
from speedplan.solve.banded import compile_kernel

COLUMNS = ("t", "s", "v", "a", "j", "x", "y", "heading", "curvature", "a_lat", "j_lat")


def record(path: str) -> None:
    compile_kernel()  # the banded backend and the compiled time law, not their fallbacks
    out: dict[str, Any] = {}
    for name, p, lim, kw in cases():
        nojerk = sp.Limits(v_max=lim.v_max, a_max=lim.a_max, a_lat_max=lim.a_lat_max,
                           j_max=math.inf)
        for tag, limits, extra in (("default", lim, {}), ("n1000", lim, {"n": 1000}),
                                   ("nojerk", nojerk, {})):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                prof = sp.plan(p, limits, **kw, **extra)
            key = f"{name}|{tag}"
            traj = prof.sample(0.01)
            out[f"{key}|duration"] = np.array(prof.duration)
            for c in COLUMNS:
                out[f"{key}|{c}"] = np.asarray(getattr(traj, c))
            out[f"{key}|time_at"] = prof.law.time_at(np.linspace(0.0, prof.law.length, 777))
            for k, r in prof.verify().ratios.items():
                out[f"{key}|ratio_{k}"] = np.array(r)
    np.savez(path, **out)
    print(f"recorded {len(out)} arrays into {path}")


def compare(a_path: str, b_path: str) -> None:
    a, b = np.load(a_path), np.load(b_path)
    worst: dict[str, tuple[float, str]] = {}
    same = 0
    for k in sorted(set(a.files) | set(b.files)):
        if k not in a.files or k not in b.files or a[k].shape != b[k].shape:
            print(f"{k}: missing or of another shape")
            continue
        if np.array_equal(a[k], b[k]):
            same += 1
            continue
        scale = max(float(np.max(np.abs(a[k]))), 1e-300)
        d = float(np.max(np.abs(a[k] - b[k]))) / scale
        col = k.split("|")[-1]
        if d > worst.get(col, (-1.0, ""))[0]:
            worst[col] = (d, k.rsplit("|", 1)[0])
    print(f"{same} of {len(a.files)} arrays bitwise equal; the others, per column:")
    for col, (d, where) in sorted(worst.items()):
        print(f"{col:>14}: max |diff| / max |value| = {d:.2e}  ({where})")


def main() -> None:
    record_or_compare(__doc__.splitlines()[0], record, compare)


if __name__ == "__main__":
    main()
