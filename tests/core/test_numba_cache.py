"""A numba cache index left by an earlier version of a kernel module is recompiled over.

Numba pickles every compiled signature, with its argument types, into one index file per
function. When a ``NamedTuple`` argument class is later removed (the banded kernel's
``Work`` went in 0.2), an index left in ``__pycache__`` by the earlier
version failed to unpickle and numba raised ``AttributeError`` from the first call
(numba issue #6018). :func:`speedplan.core.jit.tolerate_stale_indexes` makes it
read as obsolete.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

# One kernel module in two versions, the function on the same line in both: version 1 calls
# it with a NamedTuple that version 2 no longer defines (two comment lines in its place).
_MODULE = """
    from typing import NamedTuple
    import numpy as np
    from numba import njit
    {harden}
    {gone}
    class Kept(NamedTuple):
        a: np.ndarray
    @njit(cache=True)
    def total(x):
        return x.a.sum()
    ARG = {arg}
"""
_VERSIONS = {
    1: {"gone": "class Gone(NamedTuple):\n        a: np.ndarray", "arg": "Gone(np.ones(3))"},
    2: {"gone": "#\n    #", "arg": "Kept(np.ones(4))"},
}
_HARDEN = ("from speedplan.core.jit import tolerate_stale_indexes; "
           "tolerate_stale_indexes()")


def _run(tmp_path: Path, version: int, harden: bool) -> subprocess.CompletedProcess[str]:
    src = textwrap.dedent(_MODULE.format(harden=_HARDEN if harden else "", **_VERSIONS[version]))
    (tmp_path / "kernelmod.py").write_text(src)
    os.utime(tmp_path / "kernelmod.py", (version * 1000.0, version * 1000.0))  # a new stamp
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache"),
           "PYTHONPATH": os.pathsep.join([str(tmp_path), *sys.path])}
    return subprocess.run(
        [sys.executable, "-c", "import kernelmod as k; print(k.total(k.ARG))"],
        env=env, capture_output=True, text=True, timeout=240, check=False)


@pytest.mark.slow
def test_a_stale_index_naming_a_removed_class_is_recompiled_over(tmp_path):
    first = _run(tmp_path, 1, harden=False)
    assert first.returncode == 0, first.stderr
    assert list((tmp_path / "cache").rglob("*.nbi")), "version 1 wrote no cache index"
    # Without the hardening numba (0.68) cannot read the index version 1 left: the failure
    # this guards against. A numba that reads it needs no guard; the rest still holds.
    plain = _run(tmp_path, 2, harden=False)
    if plain.returncode != 0:
        assert "Can't get attribute 'Gone'" in plain.stderr, plain.stderr
    hardened = _run(tmp_path, 2, harden=True)
    assert hardened.returncode == 0, hardened.stderr
    assert hardened.stdout.strip() == "4.0"
    again = _run(tmp_path, 2, harden=False)  # the index was rewritten: readable as it is
    assert again.returncode == 0, again.stderr


@pytest.mark.slow
@pytest.mark.parametrize("module", ["speedplan.core._law_kernel", "speedplan.solve._banded_ipm",
                                    "speedplan.solve._banded_nlp_kernels"])
def test_every_kernel_module_hardens_the_cache_on_its_own(module):
    # In a fresh process, loading the module alone must install the guard (in this process
    # another module may already have). The kernel modules are imported lazily: their body
    # runs at the first attribute access, before any kernel can be called.
    check = (f"import importlib; importlib.import_module({module!r}).signatures; "
             "from numba.core.caching import IndexDataCacheFile as C; "
             "print(C._load_index.__name__)")
    out = subprocess.run([sys.executable, "-c", check], capture_output=True, text=True,
                         timeout=240, check=False)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "_load_index_or_empty"
