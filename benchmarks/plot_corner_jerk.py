"""The jerk through a corner with comfort limits, as a controller reads it at 100 Hz.

Usage::

    python benchmarks/plot_corner_jerk.py --save after.npz --label "this version"
    PYTHONPATH=/path/to/other/checkout python benchmarks/plot_corner_jerk.py --save before.npz \
        --label "the other version"
    python benchmarks/plot_corner_jerk.py --draw before.npz after.npz --out corner-jerk.png

``--save`` plans the corner case of ``tests/model/test_comfort.py`` (a slow shuttle's comfort
limits on a three-corner G2 path) with whichever ``speedplan`` is imported and stores its
trajectory at 100 Hz with a label; ``--draw`` plots the jerk and the acceleration of stored
runs over the first corner, one row per run.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

TESTS = Path(__file__).resolve().parent.parent / "tests"
sys.path.insert(0, str(TESTS))  # oracles, imported by the test module below
sys.path.insert(0, str(TESTS / "model"))  # test_comfort: the corner case


def save(out: str, label: str) -> None:
    from test_comfort import CHATTER_LIMITS, CHATTER_PATH

    import speedplan as sp

    prof = sp.plan(sp.Path.from_waypoints(CHATTER_PATH), CHATTER_LIMITS)
    tr = prof.sample(0.01)
    np.savez(out, t=tr.t, a=tr.a, j=tr.j, curvature=tr.curvature, j_max=CHATTER_LIMITS.j_max,
             a_max=CHATTER_LIMITS.a_max, label=label, status=prof.status,
             duration=prof.duration)
    print(f"{out}: {label} (speedplan {sp.__version__} from {Path(sp.__file__).parent}), "
          f"{prof.status}, {prof.duration:.4f} s")


def draw(runs: list[str], out: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(len(runs), 1, figsize=(8, 2.4 * len(runs)), sharex=True,
                             layout="constrained", squeeze=False)
    for ax, run in zip(axes[:, 0], runs, strict=True):
        d = np.load(run)
        curved = np.flatnonzero(np.abs(d["curvature"]) > 1e-12)
        first = curved[: np.argmax(np.diff(curved) > 1) or curved.size]  # the first corner
        lo, hi = max(first[0] - 100, 0), min(first[-1] + 100, d["t"].size)
        t = d["t"][lo:hi]
        ax.step(t, d["j"][lo:hi], where="post", lw=0.8, label="jerk j [m/s³]")
        ax.plot(t, d["a"][lo:hi], lw=1.2, label="acceleration a [m/s²]")
        ax.axvspan(d["t"][first[0]], d["t"][first[-1]], color="0.9", zorder=0,
                   label="in the corner")
        ax.axhline(float(d["j_max"]), color="k", lw=0.5, ls=":")
        ax.axhline(-float(d["j_max"]), color="k", lw=0.5, ls=":")
        ax.set_title(f"{d['label']}: {d['status']}, {float(d['duration']):.3f} s",
                     fontsize=9)
        ax.legend(loc="upper left", fontsize=7)
    axes[-1, 0].set_xlabel("t [s]")
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--save", metavar="NPZ")
    ap.add_argument("--draw", nargs="+", metavar="NPZ")
    ap.add_argument("--label", default="speedplan")
    ap.add_argument("--out", default="corner-jerk.png")
    args = ap.parse_args()
    if args.save:
        save(args.save, args.label)
    if args.draw:
        draw(args.draw, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
