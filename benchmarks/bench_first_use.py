"""First use of one or more copies of speedplan, side by side: fresh cache, then warm.

For each copy (a source tree, e.g. a ``git worktree`` of another commit), in turn and for
``--rounds`` rounds: a new process with an empty numba cache (``NUMBA_CACHE_DIR``) and no
``__pycache__`` plans ``paths/u_turn.json`` ``--plans + 1`` times with the LGV limits
(the kernels compile in the background meanwhile) and then waits for that background
compilation; a second process plans the same with the cache it filled. Printed per run: the
load average when it started, the first plan, the further plans, when the banded kernel first
answered and when the background compilation was done (both from the end of ``import
speedplan``), the warm run, and the ratio fresh / warm of the planning time.

    python benchmarks/bench_first_use.py --copies /path/to/old /path/to/new --rounds 2
    python benchmarks/bench_first_use.py --busy 4       # with 4 busy processes started here
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

RUN = """
import os, sys, time
t0 = time.perf_counter()
import speedplan as sp
from speedplan.io import read_path
t1 = time.perf_counter()
path = read_path(os.path.join(sys.argv[2], "paths", "u_turn.json"))
lim = sp.Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5)
sp.plan(path, lim)
t2 = time.perf_counter()
banded_at = None
for _ in range(int(sys.argv[1])):
    prof = sp.plan(path, lim)
    if banded_at is None and "banded" in prof.solution.backend:
        banded_at = time.perf_counter() - t1
t3 = time.perf_counter()
from speedplan.core.jit import FAMILIES
background = FAMILIES["relaxation"].background
if background is not None:
    background.wait()
print(t2 - t1, t3 - t2, -1.0 if banded_at is None else banded_at, time.perf_counter() - t1)
"""


def _run(copy: Path, cache: str, plans: int) -> list[float]:
    env = {**os.environ, "PYTHONPATH": str(copy), "NUMBA_CACHE_DIR": cache}
    out = subprocess.run([sys.executable, "-c", RUN, str(plans), str(copy)], env=env,
                         cwd=tempfile.gettempdir(), capture_output=True, text=True,
                         check=True, timeout=1800).stdout
    return [float(x) for x in out.split()]


def _first_use(copy: Path, plans: int) -> str:
    for cache in copy.rglob("__pycache__"):
        shutil.rmtree(cache, ignore_errors=True)
    load = os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as cache:
        first, more, banded, done = _run(copy, cache, plans)
        w_first, w_more, _, _ = _run(copy, cache, plans)
    after = "never" if banded < 0 else f"{banded:.1f} s"
    ratio = (first + more) / (w_first + w_more)
    return (f"{copy.name:<16} load {load:4.1f}: fresh 1st {first:5.2f} s + {plans} {more:6.2f} s, "
            f"banded after {after:>7}, compiled after {done:5.1f} s | warm 1st {w_first:4.2f} s "
            f"+ {plans} {w_more:5.2f} s | fresh / warm {ratio:4.2f}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--copies", nargs="+", type=Path, default=[ROOT],
                    help="source trees of speedplan (default: this one)")
    ap.add_argument("--rounds", type=int, default=1)
    ap.add_argument("--plans", type=int, default=200)
    ap.add_argument("--busy", type=int, default=0, help="busy processes to start meanwhile")
    args = ap.parse_args()
    busy = [subprocess.Popen([sys.executable, "-c", "while True: pass"])
            for _ in range(args.busy)]
    try:
        if busy:
            time.sleep(2.0)
        print(f"{os.cpu_count()} cores; {args.busy} busy processes started here")
        for _ in range(args.rounds):
            for copy in args.copies:
                print(_first_use(copy.resolve(), args.plans), flush=True)
    finally:
        for proc in busy:
            proc.kill()
            proc.wait()


if __name__ == "__main__":
    main()
