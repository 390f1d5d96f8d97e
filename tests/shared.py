"""Values shared by the tests: the LGV limits of the sample paths, also as CLI flags."""

from __future__ import annotations

import ast
import os

from speedplan import Limits

#: The forklift / LGV limits every sample path is planned with (README, docs, benchmarks).
LGV = Limits(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=0.5)

#: :data:`LGV` as ``speedplan plan`` flags.
LGV_ARGS = ["--v-max", "2", "--a-max", "1", "--a-lat-max", "1", "--j-max", "0.5"]

#: A 250 m road corner with comfort limits, started at 5 cm/s (a draw of
#: ``benchmarks/bench_latency.py``): its refinement is not exact, and next to its stop the
#: travel time's gradient is 2e10 times its median. Waypoints, limits, boundary state.
CRAWL_CORNER = [[0.0, 0.0], [113.38235734017698, 8.749957855774369],
                [234.0445076283548, 71.52871606833898]]
CRAWL_CORNER_LIMITS = Limits(v_max=12.027445314993807, a_max=0.05766831099292436,
                             a_lat_max=0.8511906239752254, j_max=14.6601905484736,
                             j_lat_max=0.2086658984788041, yaw_rate_max=0.2512549495004922)
CRAWL_CORNER_START = {"v0": 0.0547170655868091, "a0": 0.004650246484588454}

#: The hypothesis profile of this run (registered in ``conftest.py``).
HYPOTHESIS_PROFILE = os.environ.get("SPEEDPLAN_HYPOTHESIS", "ci")
if HYPOTHESIS_PROFILE not in ("ci", "dev", "deep"):
    raise ValueError(f"SPEEDPLAN_HYPOTHESIS={HYPOTHESIS_PROFILE!r}: use 'ci', 'dev' or 'deep'")


def examples(n: int) -> int:
    """``n`` hypothesis examples, ten times as many under the ``deep`` profile."""
    return 10 * n if HYPOTHESIS_PROFILE == "deep" else n


def imported_modules(tree: ast.AST, module: str, is_package: bool = False) -> list[str]:
    """``speedplan`` modules (or ``module.name``) imported anywhere in ``tree`` by ``module``.

    Relative imports are resolved against ``module`` (its own package when ``is_package``);
    imports inside functions count too. Used by the import-contract test and by
    ``benchmarks/architecture_stats.py``.
    """
    package = module if is_package else module.rsplit(".", 1)[0]
    out: list[str] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            names = [target] if node.module else [f"{target}.{a.name}" for a in node.names]
            out.extend(n for n in names if n.startswith("speedplan"))
        elif isinstance(node, ast.Import):
            out.extend(a.name for a in node.names if a.name.startswith("speedplan"))
    return out


def code_lines(node: ast.FunctionDef | ast.AsyncFunctionDef) -> int:
    """Source lines of a function, decorators included and its docstring excluded.

    Used by the import-contract test (the longest-function rule) and by
    ``benchmarks/architecture_stats.py``.
    """
    start = min([node.lineno, *(d.lineno for d in node.decorator_list)])
    end = node.end_lineno if node.end_lineno is not None else node.lineno
    lines = end - start + 1
    first = node.body[0]
    if (isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant)
            and isinstance(first.value.value, str)):
        lines -= (first.end_lineno or first.lineno) - first.lineno + 1
    return lines
