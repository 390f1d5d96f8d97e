"""Structure of the ``speedplan`` package at two commits: long functions, layers, wide imports.

Usage::

    python benchmarks/architecture_stats.py [--before 4f4e992^] [--after HEAD] [--top 10]
    python benchmarks/architecture_stats.py --page           # the figures of the working tree
    python benchmarks/architecture_stats.py --page --write   # ... written into the page

``--page`` measures the working tree (the files on disk, committed or not) and prints the
figures block of ``docs/architecture.md`` (between its ``architecture-stats`` markers);
``--write`` replaces the block in the page. ``tests/project/test_architecture_page.py`` fails
when the page's block differs from what the tree gives, so the page cannot quote an old tree.

Reads both trees straight from git (``git ls-tree``/``git show``, no checkout) and parses every
``speedplan/**.py`` with :mod:`ast`. The layers and the rule that assigns a module to one are
those of ``tests/project/test_architecture.py`` in the working tree (read with ``ast``, not
imported): ``speedplan.<layer>...`` is in that layer, ``speedplan._version`` in the lowest,
everything else at the top. Per tree it prints:

* the ``--top`` longest functions and methods, by source lines (``end_lineno - lineno + 1``,
  decorators and docstring included);
* the modules per layer;
* upward imports (what the contract test forbids) and imports that cross more than one layer
  downwards (e.g. top level -> core), lazy imports inside functions included.

The layer rule is applied to both trees as it stands now: in a tree from before the layers
existed, a base module that sat at the top level (``speedplan.errors``) counts as top level,
so every lower layer importing it shows up as an upward import.
"""

from __future__ import annotations

import argparse
import ast
import subprocess
import sys
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CONTRACT = ROOT / "tests" / "project" / "test_architecture.py"
sys.path.insert(0, str(ROOT / "tests"))

from shared import code_lines, imported_modules  # noqa: E402  (the contract test's own resolution)


def contract_layers(file: Path = CONTRACT) -> tuple[str, ...]:
    """The ``LAYERS`` tuple of the import-contract test, bottom to top."""
    for node in ast.parse(file.read_text(encoding="utf-8")).body:
        if (isinstance(node, ast.Assign) and len(node.targets) == 1
                and isinstance(node.targets[0], ast.Name) and node.targets[0].id == "LAYERS"):
            value = ast.literal_eval(node.value)
            return tuple(str(v) for v in value)
    raise SystemExit(f"no LAYERS = (...) in {file}")


def layer_of(module: str, layers: tuple[str, ...]) -> int:
    """Layer index of a dotted module name (``len(layers)`` is the top level)."""
    parts = module.split(".")
    if len(parts) >= 2 and parts[1] in layers:
        return layers.index(parts[1])
    if len(parts) >= 2 and parts[1] == "_version":
        return 0
    return len(layers)


def layer_name(index: int, layers: tuple[str, ...]) -> str:
    return layers[index] if index < len(layers) else "top"


def git(*args: str) -> str:
    return subprocess.run(["git", *args], cwd=ROOT, check=True, capture_output=True,
                          text=True).stdout


def tree_sources(ref: str) -> dict[str, str]:
    """``{path: source}`` of every ``speedplan/**.py`` at ``ref``."""
    names = [n for n in git("ls-tree", "-r", "--name-only", ref, "speedplan").splitlines()
             if n.endswith(".py")]
    return {n: git("show", f"{ref}:{n}") for n in names}


def worktree_sources() -> dict[str, str]:
    """``{path: source}`` of every ``speedplan/**.py`` on disk."""
    return {p.relative_to(ROOT).as_posix(): p.read_text(encoding="utf-8")
            for p in sorted((ROOT / "speedplan").rglob("*.py"))}


def module_name(path: str) -> str:
    parts = list(Path(path).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


@dataclass(frozen=True)
class Function:
    module: str
    name: str
    lines: int
    code: int  # lines without the docstring (the contract test's longest-function rule)


def functions(tree: ast.Module, module: str) -> list[Function]:
    """Every function and method with its qualified name and length in lines."""
    out: list[Function] = []

    def visit(body: list[ast.stmt], prefix: str) -> None:
        for node in body:
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                start = min([node.lineno, *(d.lineno for d in node.decorator_list)])
                end = node.end_lineno if node.end_lineno is not None else node.lineno
                out.append(Function(module, prefix + node.name, end - start + 1,
                                    code_lines(node)))
                visit(node.body, f"{prefix}{node.name}.")
            elif isinstance(node, ast.ClassDef):
                visit(node.body, f"{prefix}{node.name}.")

    visit(tree.body, "")
    return out


@dataclass(frozen=True)
class Stats:
    ref: str
    commit: str
    lines: int
    functions: list[Function]
    modules: dict[int, list[str]]
    upward: list[tuple[str, str]]
    wide: list[tuple[str, str]]


def measure(ref: str | None, layers: tuple[str, ...]) -> Stats:
    """The structure of the tree at git ``ref``, or of the working tree when ``None``."""
    sources = worktree_sources() if ref is None else tree_sources(ref)
    funcs: list[Function] = []
    modules: dict[int, list[str]] = {}
    upward: list[tuple[str, str]] = []
    wide: list[tuple[str, str]] = []
    for path, text in sorted(sources.items()):
        module = module_name(path)
        tree = ast.parse(text)
        funcs.extend(functions(tree, module))
        own = layer_of(module, layers)
        modules.setdefault(own, []).append(module)
        for target in sorted(set(imported_modules(tree, module, path.endswith("__init__.py")))):
            other = layer_of(target, layers)
            if other > own:
                upward.append((module, target))
            elif own - other > 1:
                wide.append((module, target))
    funcs.sort(key=lambda f: (-f.lines, f.module, f.name))
    return Stats(ref=ref or "working tree",
                 commit="" if ref is None else git("rev-parse", "--short", ref).strip(),
                 lines=sum(t.count("\n") for t in sources.values()), functions=funcs,
                 modules=modules, upward=upward, wide=wide)


def report(stats: Stats, layers: tuple[str, ...], top: int) -> None:
    n_mod = sum(len(v) for v in stats.modules.values())
    print(f"== {stats.ref} ({stats.commit}): {n_mod} modules, {stats.lines} lines, "
          f"{len(stats.functions)} functions")
    print(f"longest functions (top {top}, lines):")
    for f in stats.functions[:top]:
        print(f"  {f.lines:4d}  {f.module}.{f.name}")
    long = sum(f.lines > 100 for f in stats.functions)
    print(f"functions over 100 lines: {long}; over 50 lines: "
          f"{sum(f.lines > 50 for f in stats.functions)}")
    print("modules per layer:")
    for index in sorted(stats.modules):
        names = stats.modules[index]
        print(f"  {layer_name(index, layers):8s} {len(names):3d}  "
              + ", ".join(m.removeprefix("speedplan.") or "speedplan" for m in names))
    print(f"upward imports (forbidden by the contract): {len(stats.upward)}")
    for module, target in stats.upward:
        print(f"  {module} -> {target}")
    pairs = Counter((layer_name(layer_of(m, layers), layers), layer_name(layer_of(t, layers),
                                                                         layers))
                    for m, t in stats.wide)
    base = sum(n for (_, b), n in pairs.items() if b == layers[0])
    print(f"imports crossing more than one layer downwards: {len(stats.wide)}, "
          f"{len(stats.wide) - base} of them not into {layers[0]} "
          f"({', '.join(f'{a}->{b} {n}' for (a, b), n in sorted(pairs.items()))})")


PAGE = ROOT / "docs" / "architecture.md"
START, END = "<!-- architecture-stats:start -->", "<!-- architecture-stats:end -->"


def page_block(stats: Stats, layers: tuple[str, ...], top: int = 5) -> str:
    """The figures block of docs/architecture.md, markers included."""
    n_mod = sum(len(v) for v in stats.modules.values())
    pairs = Counter(layer_name(layer_of(t, layers), layers) for _, t in stats.wide)
    per_layer = ", ".join(f"{layer_name(i, layers)} {len(stats.modules[i])}"
                          for i in sorted(stats.modules))
    rows = [
        START,
        "| | |",
        "|---|---|",
        f"| modules, lines, functions | {n_mod}, {stats.lines}, {len(stats.functions)} |",
        f"| modules per layer | {per_layer} |",
        f"| functions over 100 / over 50 lines | {sum(f.lines > 100 for f in stats.functions)}"
        f" / {sum(f.lines > 50 for f in stats.functions)} |",
        "| longest functions (lines) | " + ", ".join(
            f"`{f.module.removeprefix('speedplan.')}.{f.name}` {f.lines}"
            for f in stats.functions[:top]) + " |",
        "| over 80 lines of code (docstring excluded) | " + (", ".join(
            f"`{f.module.removeprefix('speedplan.')}.{f.name}` {f.code}"
            for f in sorted(stats.functions, key=lambda f: -f.code) if f.code > 80)
            or "none") + " |",
        f"| upward imports (forbidden) | {len(stats.upward)} |",
        f"| imports skipping a layer downwards | {len(stats.wide)}: "
        + ", ".join(f"into {k} {n}" for k, n in sorted(pairs.items())) + " |",
        END,
    ]
    return "\n".join(rows)


def page_is_current(text: str, block: str) -> bool:
    return START in text and text[text.index(START):text.index(END) + len(END)] == block


def write_page(block: str) -> None:
    text = PAGE.read_text(encoding="utf-8")
    text = text[:text.index(START)] + block + text[text.index(END) + len(END):]
    PAGE.write_text(text, encoding="utf-8")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--page", action="store_true",
                    help="the figures block of docs/architecture.md for the working tree")
    ap.add_argument("--write", action="store_true", help="with --page: write it into the page")
    ap.add_argument("--before", default="4f4e992^", help="git ref of the 'before' tree")
    ap.add_argument("--after", default="HEAD", help="git ref of the 'after' tree")
    ap.add_argument("--top", type=int, default=10, help="how many longest functions")
    args = ap.parse_args()
    layers = contract_layers()
    if args.page:
        block = page_block(measure(None, layers), layers)
        if args.write:
            write_page(block)
        print(block)
        return
    print("layers (tests/project/test_architecture.py), bottom to top:", ", ".join(layers),
          "+ top")
    for ref in (args.before, args.after):
        report(measure(ref, layers), layers, args.top)


if __name__ == "__main__":
    main()
