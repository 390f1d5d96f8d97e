"""Build hook: compile speedplan's numba kernels for this machine into the wheel.

Without it, the first plans after installing run on the fallbacks (Clarabel, numpy) while a
background process compiles the kernels into numba's cache (about 9 s on an idle 2-core
machine, over a minute on a loaded one). Compiled at build time, they ship as numba cache
files in ``speedplan/*/__pycache__``, which numba loads on first use: numba 0.68 stamps a
cache with a hash of the source file's content and keys each entry by numba's version and
the CPU it was compiled for, so the files are used wherever the same sources are installed
with the same numba on the same kind of CPU, and ignored (compiled again, as without them)
anywhere else.

The kernels are compiled in a temporary copy of the package whose ``__init__.py`` files are
empty: the kernel modules need only numpy and numba, which is all this hook adds to the build
environment (``[tool.hatch.build.targets.wheel.hooks.custom]`` in ``pyproject.toml``).
An editable install gets the files in the source tree instead. ``SPEEDPLAN_BUILD_KERNELS=0``
builds without them (e.g. a wheel meant for other machines); a compilation that fails only
warns: the package then compiles its kernels on first use, as it would without this hook.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

from hatchling.builders.hooks.plugin.interface import BuildHookInterface

#: Environment variable: ``0`` builds without compiled kernels.
BUILD_KERNELS_ENV = "SPEEDPLAN_BUILD_KERNELS"

#: numba's cache files: an index per function and its compiled code.
CACHE_PATTERNS = ("*.nbi", "*.nbc")

COMPILE = "from speedplan.core.jit import compile_families; compile_families()"


def cache_files(package: Path) -> list[Path]:
    """Every numba cache file under ``package``."""
    return sorted(p for pattern in CACHE_PATTERNS
                  for p in package.glob(f"**/__pycache__/{pattern}"))


def compile_kernels(root: Path, work: Path, *, reuse: bool, timeout: float = 900.0
                    ) -> list[Path]:
    """Compile every kernel family into a copy of ``root/speedplan`` made in ``work``.

    With ``reuse``, the copy starts with the cache files of the source tree, so kernels that
    are there and current load instead of compiling. Returns the copy's cache files.
    """
    package = work / "speedplan"
    shutil.copytree(root / "speedplan", package, ignore=shutil.ignore_patterns("__pycache__"))
    if reuse:
        for path in cache_files(root / "speedplan"):
            inside = package / path.relative_to(root / "speedplan")
            inside.parent.mkdir(exist_ok=True)
            shutil.copy2(path, inside)
    for init in package.glob("**/__init__.py"):
        init.write_text("")  # the kernel modules import no more than numpy and numba
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    # pip's isolated build environment reaches its packages through PYTHONPATH: keep it.
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(work), env.get("PYTHONPATH")) if p)
    subprocess.run([sys.executable, "-c", COMPILE], cwd=work, env=env, check=True,
                   stdin=subprocess.DEVNULL, capture_output=True, timeout=timeout)
    return cache_files(package)


class KernelCacheHook(BuildHookInterface):  # type: ignore[type-arg]
    """Adds the compiled kernels' numba cache to the wheel (or, editable, to the tree)."""

    PLUGIN_NAME = "custom"

    def initialize(self, version: str, build_data: dict[str, Any]) -> None:
        """Compile the kernels; include their cache files in the build."""
        if os.environ.get(BUILD_KERNELS_ENV) == "0":
            return
        root = Path(self.root)
        self._work = Path(tempfile.mkdtemp(prefix="speedplan-kernels-"))
        try:
            files = compile_kernels(root, self._work, reuse=version == "editable")
        except (OSError, subprocess.SubprocessError) as exc:
            detail = getattr(exc, "stderr", b"") or b""
            self.app.display_warning(
                f"speedplan: the numba kernels were not compiled at build time ({exc}; "
                f"{detail.decode(errors='replace').strip()[-800:]}); the first plans after "
                "installing compile them instead")
            return
        for path in files:
            inside = path.relative_to(self._work)
            if version == "editable":
                (root / inside).parent.mkdir(exist_ok=True)
                shutil.copy2(path, root / inside)
            else:
                build_data["force_include"][str(path)] = str(inside)
        self.app.display_info(f"speedplan: {len(files)} compiled kernel cache files included")

    def finalize(self, version: str, build_data: dict[str, Any], artifact_path: str) -> None:
        """Remove the temporary copy of the package."""
        work = getattr(self, "_work", None)
        if work is not None:
            shutil.rmtree(work, ignore_errors=True)
