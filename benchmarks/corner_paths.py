"""Waypoint paths before and after the G2 default: distance from the legs, curvature jumps.

For four waypoint sets (a serpentine aisle, a dock approach, the README example, a tight
zigzag) it measures the former default (a G1 clothoid chain whose waypoint headings are the
tangents of a chord-length cubic spline, as ``Path.from_waypoints`` did before ``"g2"``), the
clothoid chain with the leg-bisector headings, and the new default ``"g2"``:

* the largest distance from the waypoint polyline (shapely, on 20 001 samples plus the joins);
* the largest curvature jump at a join between pieces (both one-sided values of the pieces);
* the largest curvature and the length.

Run ``python benchmarks/corner_paths.py [--figure docs/assets/serpentine_corners.png]
[--headings]``; it prints a Markdown table (docs/geometry.md) and draws the serpentine figure;
``--headings`` adds clothoid chains whose headings split each turn by the leg lengths (toward
the longer or the shorter leg), the alternatives measured against the bisector.
"""

from __future__ import annotations

import argparse

import numpy as np
import shapely
from scipy.interpolate import CubicSpline

from speedplan import Path

CASES = {
    "serpentine aisle": [[0, 0], [20, 0], [20, 6], [0, 6], [0, 12]],
    "dock approach": [[0, 0], [30, 0], [32, 1.5], [40, 1.5]],
    "README example": [[0, 0], [10, 0], [14, 4], [14, 12]],
    "tight zigzag": [[0, 0], [3, 2], [4, 0], [7, 2], [8, 0]],
}


def former_default(pts: np.ndarray) -> Path:
    """The former default: clothoid chain through the chord-length spline's tangents."""
    tau = np.concatenate(([0.0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))))
    d1 = CubicSpline(tau, pts, bc_type="not-a-knot")(tau, 1)
    return Path.from_waypoints(pts, kind="clothoid", headings=np.arctan2(d1[:, 1], d1[:, 0]))


def weighted_chain(pts: np.ndarray, toward_longer: bool) -> Path:
    """Clothoid chain whose interior headings split the turn by the adjacent leg lengths."""
    legs = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    d = np.diff(pts, axis=0)
    head = np.arctan2(d[:, 1], d[:, 0])
    turn = np.angle(np.exp(1j * np.diff(head)))
    share = (legs[1:] if toward_longer else legs[:-1]) / (legs[:-1] + legs[1:])
    th = head[0] + np.concatenate(([0.0], np.cumsum(turn)))
    headings = np.concatenate((th[:1], th[:-1] + share * turn, th[-1:]))
    return Path.from_waypoints(pts, kind="clothoid", headings=headings)


def measure(path: Path, pts: np.ndarray) -> dict[str, float]:
    s = np.union1d(np.linspace(0.0, path.length, 20001), path.offsets)
    xy, _, kappa = path.evaluate(s)
    dist = shapely.distance(shapely.points(xy), shapely.LineString(pts)).max()
    left = [p.curvature(np.array(p.length)) for p in path.pieces[:-1]]
    right = [p.curvature(np.array(0.0)) for p in path.pieces[1:]]
    jump = float(np.max(np.abs(np.subtract(left, right)), initial=0.0))
    return {"distance": float(dist), "jump": jump, "kmax": float(np.abs(kappa).max()),
            "length": path.length}


def figure(file: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    pts = np.array(CASES["serpentine aisle"], dtype=float)
    old, new = former_default(pts), Path.from_waypoints(pts)
    aisle = shapely.LineString(pts).buffer(1.5, cap_style="flat", join_style="mitre")
    fig, (ax, zx, bx) = plt.subplots(1, 3, figsize=(13, 4.2),
                                     gridspec_kw={"width_ratios": [1.25, 0.8, 1]})
    for axis in (ax, zx):
        axis.fill(*aisle.exterior.xy, color="0.92", zorder=0, label="aisle (±1.5 m)")
        axis.plot(pts[:, 0], pts[:, 1], "o--", color="0.45", lw=1, ms=4, label="waypoints, legs")
    for path, label, style in ((old, "former default (G1 clothoid chain)", "C3"),
                               (new, 'new default kind="g2"', "C0")):
        xy = path.point(np.linspace(0, path.length, 8001))
        for axis in (ax, zx):
            axis.plot(xy[:, 0], xy[:, 1], color=style, lw=1.8, label=label)
        s = np.union1d(np.linspace(0, path.length, 4001), path.offsets)
        bx.plot(s, path.curvature(s), color=style, lw=1.4, label=label)
    ax.set_title("serpentine aisle")
    ax.legend(loc="upper right", fontsize=7)
    zx.set_xlim(18.4, 20.6)
    zx.set_ylim(4.4, 6.6)
    zx.set_title("corner at (20, 6): cut by 0.25 m")
    for axis in (ax, zx):
        axis.set_aspect("equal")
        axis.set_xlabel("x [m]")
        axis.set_ylabel("y [m]")
    bx.set_xlabel("s [m]")
    bx.set_ylabel("curvature [1/m]")
    bx.set_title("curvature: steps (G1) vs continuous (G2)")
    bx.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(file, dpi=150)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--figure", help="write the serpentine figure to this PNG")
    parser.add_argument("--headings", action="store_true",
                        help="also the clothoid chain with leg-length weighted headings")
    args = parser.parse_args()
    print("| path | path kind | distance from the legs [m] | largest curvature jump [1/m] "
          "| max curvature [1/m] | length [m] |")
    print("|---|---|---|---|---|---|")
    for name, xy in CASES.items():
        pts = np.array(xy, dtype=float)
        for label, path in (("before: former default", former_default(pts)),
                            ("clothoid, bisector headings", Path.from_waypoints(pts,
                                                                                kind="clothoid")),
                            ('after: default "g2"', Path.from_waypoints(pts))):
            m = measure(path, pts)
            print(f"| {name} | {label} | {m['distance']:.3f} | {m['jump']:.3g} | "
                  f"{m['kmax']:.3f} | {m['length']:.2f} |")
        if args.headings:
            for label, longer in (("clothoid, toward the longer leg", True),
                                  ("clothoid, toward the shorter leg", False)):
                m = measure(weighted_chain(pts, longer), pts)
                print(f"| {name} | {label} | {m['distance']:.3f} | {m['jump']:.3g} | "
                      f"{m['kmax']:.3f} | {m['length']:.2f} |")
    if args.figure:
        figure(args.figure)


if __name__ == "__main__":
    main()
