"""First use of one or more copies of speedplan, side by side: fresh, then warm.

For each copy (a source tree, e.g. a ``git worktree`` of another commit), in turn and for
``--rounds`` rounds, one of two first uses:

``--install wheel`` (the default)
    what ``pip install .`` gives: the copy's wheel is built with ``pip wheel --no-deps`` (its
    build hooks included; the time is printed) and unpacked into an empty directory, as pip
    installs it; the processes below import it from there, with numba's default cache
    locations (``NUMBA_CACHE_DIR`` unset).
``--install source``
    the copy itself with an empty numba cache (``NUMBA_CACHE_DIR`` in a new temporary
    directory, no ``__pycache__``): the first use of a wheel built on another kind of machine,
    or of any install whose compiled kernels are missing.

A new process then plans ``paths/u_turn.json`` ``--plans + 1`` times with the LGV limits
(whatever kernels are missing compile in the background meanwhile) and waits for that
background compilation; a second process plans the same with what the first left behind.
Printed per run: the load average when it started, the first plan, the further plans, when the
banded kernel first answered and when the background compilation was done (both from the end
of ``import speedplan``), the warm run, and the ratio fresh / warm of the planning time.

    python benchmarks/bench_first_use.py --copies /path/to/old /path/to/new --rounds 2
    python benchmarks/bench_first_use.py --busy 4       # with 4 busy processes started here
    python benchmarks/bench_first_use.py --install source
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

RUN = """
import os, sys, time
t0 = time.perf_counter()
import speedplan as sp
from speedplan.io import read_path
t1 = time.perf_counter()
path = read_path(sys.argv[2])
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


def _run(env: dict[str, str], plans: int) -> list[float]:
    sample = ROOT / "paths" / "u_turn.json"
    out = subprocess.run([sys.executable, "-c", RUN, str(plans), str(sample)], env=env,
                         cwd=tempfile.gettempdir(), capture_output=True, text=True, check=True,
                         timeout=1800).stdout
    return [float(x) for x in out.split()]


def install_wheel(copy: Path, target: Path) -> float:
    """Build ``copy``'s wheel as ``pip install`` does and unpack it into ``target``; seconds.

    The build runs the copy's build hooks in pip's isolated build environment; the time
    printed is the build's alone (unpacking takes well under a second).
    """
    with tempfile.TemporaryDirectory() as out:
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-m", "pip", "wheel", "--quiet", "--no-deps",
                        "--wheel-dir", out, str(copy)], check=True, capture_output=True,
                       timeout=1800)
        seconds = time.perf_counter() - t0
        (wheel,) = Path(out).glob("*.whl")
        with zipfile.ZipFile(wheel) as archive:
            archive.extractall(target)
    return seconds


def _first_use(copy: Path, plans: int, install: str) -> str:
    load = os.getloadavg()[0]
    base = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    with tempfile.TemporaryDirectory() as place:
        if install == "wheel":
            build = install_wheel(copy, Path(place))
            env = {**base, "PYTHONPATH": place}
            how = f"wheel built in {build:4.1f} s"
        else:
            for cache in copy.rglob("__pycache__"):
                shutil.rmtree(cache, ignore_errors=True)
            env = {**base, "PYTHONPATH": str(copy), "NUMBA_CACHE_DIR": place}
            how = "empty numba cache"
        first, more, banded, done = _run(env, plans)
        w_first, w_more, _, _ = _run(env, plans)
    after = "never" if banded < 0 else f"{banded:.1f} s"
    ratio = (first + more) / (w_first + w_more)
    return (f"{copy.name:<16} {how}, load {load:4.1f}: fresh 1st {first:5.2f} s + {plans} "
            f"{more:6.2f} s, banded after {after:>7}, compiled after {done:5.1f} s | warm 1st "
            f"{w_first:4.2f} s + {plans} {w_more:5.2f} s | fresh / warm {ratio:4.2f}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--copies", nargs="+", type=Path, default=[ROOT],
                    help="source trees of speedplan (default: this one)")
    ap.add_argument("--rounds", type=int, default=1)
    ap.add_argument("--plans", type=int, default=200)
    ap.add_argument("--busy", type=int, default=0, help="busy processes to start meanwhile")
    ap.add_argument("--install", choices=("wheel", "source"), default="wheel",
                    help="first use of a built wheel, or of a source tree with an empty cache")
    args = ap.parse_args()
    busy = [subprocess.Popen([sys.executable, "-c", "while True: pass"])
            for _ in range(args.busy)]
    try:
        if busy:
            time.sleep(2.0)
        print(f"{os.cpu_count()} cores; {args.busy} busy processes started here")
        for _ in range(args.rounds):
            for copy in args.copies:
                print(_first_use(copy.resolve(), args.plans, args.install), flush=True)
    finally:
        for proc in busy:
            proc.kill()
            proc.wait()


if __name__ == "__main__":
    main()
