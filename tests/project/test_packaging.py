"""Packaging metadata: license file, typing marker, build backend able to write PEP 639."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_license_is_a_pep639_expression_with_its_file():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())
    assert project["project"]["license"] == "MIT"
    files = project["project"]["license-files"]
    assert files == ["LICENSE"] and (ROOT / "LICENSE").read_text().startswith("MIT License")
    # Hatchling writes License-Expression (metadata 2.4) from 1.27 on; older ones write 2.3.
    (req,) = [r for r in project["build-system"]["requires"] if r.startswith("hatchling")]
    major, minor = map(int, re.search(r">=\s*(\d+)\.(\d+)", req).groups())
    assert (major, minor) >= (1, 27)
    assert not any(c.startswith("License ::") for c in project["project"]["classifiers"])


def test_typed_marker_and_samples_ship_in_the_package():
    assert (ROOT / "speedplan" / "py.typed").exists()
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())
    wheel = project["tool"]["hatch"]["build"]["targets"]["wheel"]
    assert wheel["packages"] == ["speedplan"]
    assert wheel["force-include"]["paths"] == "speedplan/paths"


def test_demo_outputs_are_ignored_by_git():
    ignored = (ROOT / ".gitignore").read_text().splitlines()
    assert "speedplan-demo.csv" in ignored and "speedplan-demo.png" in ignored
