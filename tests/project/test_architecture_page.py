"""docs/architecture.md quotes the package as it is: its figures are regenerated from the tree."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _stats_module():
    spec = importlib.util.spec_from_file_location(
        "architecture_stats", ROOT / "benchmarks" / "architecture_stats.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up
    spec.loader.exec_module(module)
    return module


def test_architecture_page_figures_are_current() -> None:
    stats = _stats_module()
    layers = stats.contract_layers()
    block = stats.page_block(stats.measure(None, layers), layers)
    page = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    assert stats.page_is_current(page, block), (
        "docs/architecture.md quotes other figures than the tree has; run "
        "`python benchmarks/architecture_stats.py --page --write`")
    assert "| modules, lines, functions |" in block


def test_the_check_sees_a_stale_page() -> None:
    stats = _stats_module()
    layers = stats.contract_layers()
    block = stats.page_block(stats.measure(None, layers), layers)
    stale = block.replace("| modules, lines, functions | ", "| modules, lines, functions | 1")
    assert not stats.page_is_current(f"text\n{stale}\nmore", block)
    assert stats.page_is_current(f"text\n{block}\nmore", block)


def test_the_diagram_renders_offline() -> None:
    page = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    assert "```mermaid" not in page and "<script" not in page
    svg = (ROOT / "docs" / "assets" / "architecture.svg").read_text(encoding="utf-8")
    assert "assets/architecture.svg" in page and "<svg" in svg and "<script" not in svg
