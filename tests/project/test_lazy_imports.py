"""``import speedplan`` leaves the heavy optional machinery unloaded until it is used."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

# casadi: only the IPOPT fallback of the refinement; matplotlib: only speedplan.plot;
# numba: only the banded kernel, loaded on the first banded solve.
LAZY = ("casadi", "matplotlib", "numba")


def _loaded_after(code: str, cwd: str) -> set[str]:
    env = {k: v for k, v in os.environ.items() if k != "MPLBACKEND"}
    res = subprocess.run(
        [sys.executable, "-c", f"import sys\n{code}\n"
         f"print(' '.join(m for m in {LAZY!r} if m in sys.modules))"],
        capture_output=True, text=True, timeout=300, cwd=cwd, env=env,
    )
    assert res.returncode == 0, res.stderr
    return set(res.stdout.split())


def test_import_speedplan_loads_no_casadi_matplotlib_or_numba(request):
    assert _loaded_after("import speedplan", str(request.config.rootpath)) == set()


@pytest.mark.parametrize(
    ("code", "loaded"),
    [
        # The fallback itself imports casadi, and returns a checked answer.
        ("import numpy as np\n"
         "from speedplan.solve import DiscreteProblem\n"
         "from speedplan.solve.ipopt_ import refine_ipopt\n"
         "p = DiscreteProblem(s=np.linspace(0, 1, 11), w_max=np.ones(11),"
         " accel=np.full(10, 4.0), decel=np.full(10, 4.0), jerk=np.full(9, 8.0))\n"
         "assert refine_ipopt(p, np.full(11, 0.5)).success",
         {"casadi"}),
        ("import speedplan.plot", set()),
        ("from speedplan.plot import _figure\n_figure()", {"matplotlib"}),
    ],
)
def test_each_lazy_module_is_loaded_by_its_user(request, code, loaded):
    assert _loaded_after(code, str(request.config.rootpath)) == loaded


def test_submodules_are_reachable_as_attributes_without_importing_them_first():
    code = ("import sys, speedplan; assert 'matplotlib' not in sys.modules; "
            "speedplan.io.read_path; assert 'matplotlib' not in sys.modules; "
            "speedplan.plot.plot_profile; "
            "speedplan.cli.main; print('ok')")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=False)
    assert out.stdout.strip() == "ok", out.stderr
