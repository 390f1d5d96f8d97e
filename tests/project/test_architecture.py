"""Import contract: every module imports only from its own layer or the layers below it.

Layers, bottom to top: core, geometry, solve, model, timing, route, then the top-level
modules (plan, waypoints, batch, io, plot, cli). Lazy imports inside functions count too:
a layer must not reach upwards, whatever the moment it does so.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest
from shared import imported_modules

PACKAGE = Path(__file__).resolve().parents[2] / "speedplan"
LAYERS = ("core", "geometry", "solve", "model", "timing", "route")
TOP = len(LAYERS)


def _module_name(file: Path) -> str:
    rel = file.relative_to(PACKAGE.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _layer(module: str) -> int:
    parts = module.split(".")
    if len(parts) >= 2 and parts[1] in LAYERS:
        return LAYERS.index(parts[1])
    if len(parts) >= 2 and parts[1] == "_version":
        return 0
    return TOP


def _imports(source: str, module: str, is_package: bool = False) -> list[str]:
    return imported_modules(ast.parse(source), module, is_package)


FILES = sorted(PACKAGE.rglob("*.py"))


def _upward(source: str, module: str, is_package: bool = False) -> list[str]:
    own = _layer(module)
    return [m for m in _imports(source, module, is_package) if _layer(m) > own]


@pytest.mark.parametrize("file", FILES, ids=lambda f: str(f.relative_to(PACKAGE)))
def test_imports_go_only_downwards(file):
    module = _module_name(file)
    upward = _upward(file.read_text(encoding="utf-8"), module, file.name == "__init__.py")
    assert not upward, f"{module} (layer {_layer(module)}) imports upwards: {upward}"


def test_the_contract_sees_an_upward_import():
    # The checker must be able to fail: the import main had in timing/profile.py before.
    lazy = "def plot(self):\n    from ..plot import plot_profile\n    return plot_profile(self)\n"
    assert _upward(lazy, "speedplan.timing.profile") == ["speedplan.plot"]
    assert _upward("from ..model import build_model\n", "speedplan.solve.discrete") == [
        "speedplan.model"]
    assert _upward("from ..core.errors import SolverError\n", "speedplan.solve.discrete") == []


def test_every_layer_is_a_package():
    for layer in LAYERS:
        if layer != "route" or (PACKAGE / layer).exists():
            assert (PACKAGE / layer / "__init__.py").exists(), layer
