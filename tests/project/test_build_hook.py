"""The wheel's build hook: the numba kernels compiled at build time load where it is installed."""

from __future__ import annotations

import importlib.util
import os
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def _hook_module():
    spec = importlib.util.spec_from_file_location("speedplan_build_hook", ROOT / "hatch_build.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _hook(module):
    return module.KernelCacheHook(str(ROOT), {}, None, None, str(ROOT), "wheel")


def test_the_wheel_and_the_sdist_carry_the_hook():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())
    build = project["tool"]["hatch"]["build"]["targets"]
    deps = build["wheel"]["hooks"]["custom"]["dependencies"]
    assert {d.split(">")[0] for d in deps} == {"numba", "numpy"}
    assert "hatch_build.py" in build["sdist"]["include"]


def test_kernels_compiled_by_the_hook_load_in_an_installed_copy(tmp_path):
    # What pip does: the hook compiles in the build environment, the wheel's files land in
    # another directory; a new process importing speedplan from there finds every kernel
    # family in numba's default cache location without compiling.
    files = _hook_module().compile_kernels(ROOT, tmp_path / "work", reuse=True)
    assert files
    site = tmp_path / "site"
    shutil.copytree(ROOT / "speedplan", site / "speedplan",
                    ignore=shutil.ignore_patterns("__pycache__"))
    for path in files:
        inside = site / path.relative_to(tmp_path / "work")
        inside.parent.mkdir(exist_ok=True)
        shutil.copy2(path, inside)
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env["PYTHONPATH"] = str(site)
    code = ("import speedplan; from speedplan.core.jit import FAMILIES; "
            "print(speedplan.__file__); print(all(f.load() for f in FAMILIES.values()))")
    out = subprocess.run([sys.executable, "-c", code], env=env, cwd=tmp_path, check=True,
                         capture_output=True, text=True, timeout=300).stdout.split()
    assert out == [str(site / "speedplan" / "__init__.py"), "True"]


def test_a_wheel_lists_the_cache_files_an_editable_install_copies_them(monkeypatch, tmp_path):
    module = _hook_module()
    work_files = []

    def fake_compile(root, work, *, reuse):
        path = work / "speedplan" / "solve" / "__pycache__" / "k.f-1.py311.nbi"
        path.parent.mkdir(parents=True)
        path.write_bytes(b"index")
        work_files.append((path, reuse))
        return [path]

    monkeypatch.setattr(module, "compile_kernels", fake_compile)
    monkeypatch.delenv(module.BUILD_KERNELS_ENV, raising=False)
    hook = _hook(module)
    data = {"force_include": {}}
    hook.initialize("standard", data)
    ((path, reuse),) = work_files
    assert data["force_include"] == {str(path): os.path.join("speedplan", "solve", "__pycache__",
                                                             "k.f-1.py311.nbi")}
    assert not reuse  # a wheel never ships what happens to lie in the source tree
    hook.finalize("standard", data, "")
    assert not path.exists()

    tree = tmp_path / "tree"
    (tree / "speedplan" / "solve").mkdir(parents=True)
    editable = module.KernelCacheHook(str(tree), {}, None, None, str(tree), "wheel")
    editable.initialize("editable", {"force_include": {}})
    assert work_files[-1][1]  # reuses the tree's cache
    assert (tree / "speedplan" / "solve" / "__pycache__" / "k.f-1.py311.nbi").read_bytes() == (
        b"index")


def test_without_the_kernels_the_build_still_succeeds(monkeypatch, capsys):
    module = _hook_module()

    def failing(root, work, *, reuse):
        raise subprocess.CalledProcessError(1, "compile", stderr=b"LLVM ERROR: out of memory")

    monkeypatch.setattr(module, "compile_kernels", failing)
    data = {"force_include": {}}
    _hook(module).initialize("standard", data)
    assert data["force_include"] == {}
    assert "out of memory" in capsys.readouterr().err

    monkeypatch.setenv(module.BUILD_KERNELS_ENV, "0")
    monkeypatch.setattr(module, "compile_kernels", pytest.fail)
    _hook(module).initialize("standard", data)
    assert data["force_include"] == {}
