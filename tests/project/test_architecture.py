"""Import contract: every module imports only from its own layer or the layers below it.

Layers, bottom to top: core, geometry, solve, model, timing, route, then the top-level
modules (plan, waypoints, batch, io, plot, cli). Lazy imports inside functions count too:
a layer must not reach upwards, whatever the moment it does so.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest
from shared import code_lines, imported_modules

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


def _module_graph() -> dict[str, set[str]]:
    """Module -> the ``speedplan`` modules it imports (packages by their ``__init__``)."""
    names = {_module_name(f): f for f in FILES}

    def owner(target: str) -> str:
        while target not in names and "." in target:
            target = target.rsplit(".", 1)[0]
        return target

    return {m: {owner(t) for t in _imports(f.read_text(encoding="utf-8"), m,
                                           f.name == "__init__.py")} - {m}
            for m, f in names.items()}


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    out: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def test_no_module_imports_itself_through_others():
    assert _cycles(_module_graph()) == []


def test_the_cycle_check_sees_a_circle():
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}
    assert _cycles(graph) == [["a", "b", "c"]]


def test_the_model_builds_data_and_calls_no_solver():
    # From solve/ the model reads the problem's data class and its resolution limit only.
    for file in (PACKAGE / "model").glob("*.py"):
        module = _module_name(file)
        solve = {m for m in _imports(file.read_text(encoding="utf-8"), module,
                                     file.name == "__init__.py") if m.startswith("speedplan.solve")}
        assert solve <= {"speedplan.solve.problem"}, f"{module} imports {sorted(solve)}"


#: Functions allowed over `MAX_CODE_LINES`, each with its reason (named in docs/architecture.md).
LONG_FUNCTIONS = {
    # A numba kernel: one loop over the pieces with the inversion inlined, so that it
    # compiles to a single function without calls in its inner loop.
    "speedplan.core._law_kernel._invert_into",
}
#: Longest function, in lines of code (decorators included, docstring excluded).
MAX_CODE_LINES = 80


def _long_functions(source: str, module: str) -> dict[str, int]:
    out = {}
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            lines = code_lines(node)
            if lines > MAX_CODE_LINES:
                out[f"{module}.{node.name}"] = lines
    return out


def test_no_function_is_longer_than_the_rule_allows_except_the_named_kernels():
    long = {}
    for file in FILES:
        long.update(_long_functions(file.read_text(encoding="utf-8"), _module_name(file)))
    assert set(long) <= LONG_FUNCTIONS, {k: v for k, v in long.items() if k not in LONG_FUNCTIONS}
    page = (PACKAGE.parent / "docs" / "architecture.md").read_text(encoding="utf-8")
    for name in LONG_FUNCTIONS:
        assert name.removeprefix("speedplan.") in page, f"docs/architecture.md: explain {name}"


def test_the_length_rule_counts_code_not_the_docstring():
    body = "".join(f"    x{i} = {i}\n" for i in range(MAX_CODE_LINES))
    doc = '    """' + "\n" * 30 + '    """\n'
    assert _long_functions("def f():\n" + doc + body, "m") == {"m.f": MAX_CODE_LINES + 1}
    assert _long_functions("def f():\n" + doc + body[body.index("\n") + 1:], "m") == {}
