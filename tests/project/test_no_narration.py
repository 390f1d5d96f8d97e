"""The project speaks of itself: no file narrates how it was developed.

README, docs, docstrings, comments, tests and benchmark output describe the library and its
users' world. Sessions of work, who helped, reviews, our own issue numbers and "this change"
belong to git history and CHANGELOG.md (what changed for users, by version), not in files.
"""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SCANNED = ("README.md", "CHANGELOG.md", "pyproject.toml", "mkdocs.yml", "conftest.py",
           "docs", "tests", "benchmarks", "speedplan", "paths", ".ci")
SUFFIXES = {".md", ".py", ".toml", ".yml", ".yaml", ".json", ".csv", ".txt", ".cfg", ""}

#: Upstream projects whose issue trackers the code may cite (a bug of theirs, not our story).
UPSTREAM = ("numba", "numpy", "scipy", "casadi", "ipopt", "clarabel", "shapely", "ruckig",
            "toppra", "mkdocs", "matplotlib", "griffe", "python", "cpython")

NARRATION = [
    ("a session of work", re.compile(r"\bsessions?\b", re.I)),
    ("who helped", re.compile(r"\bhelpers?('s|s')?\b", re.I)),
    ("a review", re.compile(r"\breview(s|ed|er|ers|'s)?\b", re.I)),
    ("a round of work", re.compile(
        r"\b(this|that|the (first|second|third|last|next|previous)) round\b"
        r"|\brounds? of (work|review|development|fixes)\b", re.I)),
    ("our issue number", re.compile(r"\bissues?\s*#?\s*\d+|(?<![\w&/#'\"])#\d{1,4}\b(?![\w-])",
                                    re.I)),
    ("this change", re.compile(r"\b(before|after|since|until|with|without) (this|the) change\b"
                               r"|\bthis change\b|\bpull request\b|\bthis (PR|commit)\b"
                               r"|\bbranch base\b", re.I)),
]

#: Code that uses the words in another sense: markdown-exec's ``session="..."`` (a shared
#: namespace of executed blocks) and pytest's ``scope="session"``.
CODE_SENSES = re.compile(r"""session=["'][\w-]+["']|scope=["']session["']""")


def _files() -> list[Path]:
    files: list[Path] = []
    for name in SCANNED:
        p = ROOT / name
        if p.is_file():
            files.append(p)
        elif p.is_dir():
            files += [f for f in p.rglob("*") if f.is_file() and f.suffix in SUFFIXES
                      and "__pycache__" not in f.parts and f.name != Path(__file__).name]
    return sorted(files)


def narration(line: str) -> str | None:
    """What kind of development narration ``line`` holds, if any."""
    line = CODE_SENSES.sub("", line)
    for what, pattern in NARRATION:
        for m in pattern.finditer(line):
            if what == "our issue number":
                before = line[: m.start()].split()
                if before and before[-1].strip("(`'\"").lower() in UPSTREAM:
                    continue
                if re.search(r"color|colour|#[0-9a-f]{6}\b", line, re.I):
                    continue
            return what
    return None


def test_the_check_finds_narration() -> None:
    # Made-up lines of each kind (none tells anything that happened).
    for text in ("the n-th session: the time law", "a helper wrote it",
                 "found by a review", "Issue #99's target", "speedplan issue #98, item 1",
                 "as measured in this round", "`Path.from_waypoints` before this change",
                 "(#97)"):
        assert narration(text), text
    for text in ('```python exec="on" session="t1"', '@pytest.fixture(scope="session")',
                 "numba issue #6018", "color='#1f77b4'", "rounded to a round number",
                 "the index of node 3"):
        assert narration(text) is None, text


def test_no_file_narrates_the_development() -> None:
    found = []
    for file in _files():
        try:
            text = file.read_text(encoding="utf-8")
        except UnicodeDecodeError:
            continue
        for i, line in enumerate(text.splitlines(), 1):
            what = narration(line)
            if what:
                found.append(f"{file.relative_to(ROOT)}:{i}: {what}: {line.strip()[:90]}")
    assert not found, f"{len(found)} lines narrate the development:\n" + "\n".join(found)
