"""The documentation site as a reader meets it: the API reference documents every public name
as itself, shows no module's internals, and no docstring role is left for the reader to read.

The site is built with mkdocs (warnings are errors) from the project's own ``mkdocs.yml``;
the executed tutorial blocks are left unexecuted here (their own build runs in CI), so the
build takes seconds, not minutes.
"""

from __future__ import annotations

import dataclasses
import functools
import importlib
import importlib.util
import inspect
import os
import re
import shutil
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path
from typing import Any

import pytest

import speedplan

ROOT = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.skipif(
    shutil.which("mkdocs") is None and importlib.util.find_spec("mkdocs") is None,
    reason="the docs extra is not installed",
)

#: A Sphinx role written in a docstring or page (``:func:`plan```), which the site's renderer
#: prints literally.
LITERAL_ROLE = re.compile(
    r":(?:py:)?(?:func|class|meth|attr|mod|data|exc|obj|const|ref):(?=[`~\w])")

#: Public names beyond ``speedplan.__all__``: the readers, writers and figures of the lazily
#: imported modules, the geometry primitives of ``Path.from_segments``, the route's parts.
EXTRA_PUBLIC = (
    "speedplan.waypoints.WaypointPlanOptions",
    "speedplan.core.options.JsonObject",
    "speedplan.core.options.JsonValue",
    "speedplan.geometry.Line",
    "speedplan.geometry.Arc",
    "speedplan.geometry.Clothoid",
    "speedplan.route.RouteNode",
    "speedplan.route.RouteEdge",
    "speedplan.route.RouteTrajectory",
    "speedplan.batch.JobWarning",
    "speedplan.route_plan.route_jobs",
    "speedplan.solve.problem.StencilRows",
    "speedplan.solve.paper.paper_instance",
    "speedplan.core.attempts.Attempt",
    "speedplan.route.RouteTurn",
    "speedplan.timing.rotation.Turn",
    "speedplan.route.vda5050.OrderWarning",
    "speedplan.route_plan.route_turns",
    "speedplan.route_plan.RouteOptions",
    "speedplan.batch.PlanJob",
    "speedplan.core.options.Refine",
    "speedplan.core.options.Backend",
    "speedplan.core.options.Standstill",
    "speedplan.core.options.Grip",
    "speedplan.core.options.VLimit",
    "speedplan.timing.LimitCheck",
    "speedplan.core.kinematics.speed",
    "speedplan.core.kinematics.acceleration",
    "speedplan.core.kinematics.lateral_acceleration",
    "speedplan.core.kinematics.yaw_rate",
    "speedplan.core.kinematics.lateral_acceleration_rate",
    "speedplan.core.kinematics.lateral_jerk",
    "speedplan.core.kinematics.lateral_jerk_from_slope",
    "speedplan.core.kinematics.lateral_rate_weights",
    "speedplan.core.kinematics.friction_ellipse",
)
#: Members of public classes that are implementation details (the paper's scaled constants,
#: the solver's internals) and stay off the reference.
INTERNAL_MEMBERS = {
    "Limits": {"A", "A_decel", "J", "check_range"},
    "Path": set(),
    "StencilRows": {"scaled"},
    "SpeedProfile": {"law", "solution", "check_leg", "legs", "speed_bound", "request"},
    "Verification": {"merged"},
    "Route": {"base_edges", "base_nodes", "rounded_nodes", "turn_headings", "node_headings",
              "turn_rate_limit"},
    "RouteProfile": {"leg_starts", "start_s"},
    "DiscreteProblem": {"tau", "uniform", "has_lower_bounds", "lateral_families",
                        "second_difference_weights", "second_difference", "jerk_tol",
                        "stencil_matrix", "stencil_apply", "stencil_adjoint", "jerk_rows",
                        "lateral_rows", "linear_violation", "scaled", "has_grip", "grip_load",
                        "grip_violation"},
}


def _resolve(dotted: str) -> Any:
    """The object a dotted name denotes, as Python's attribute access sees it (a package's
    attribute before a submodule of the same name: ``speedplan.plan`` is the function), or a
    dataclass field as ``("field", cls, name)``."""
    parts = dotted.split(".")
    obj: Any = importlib.import_module(parts[0])
    for i, name in enumerate(parts[1:], 1):
        try:
            obj = inspect.getattr_static(obj, name)
            continue
        except AttributeError:
            pass
        if inspect.ismodule(obj):
            try:
                obj = importlib.import_module(".".join(parts[: i + 1]))
                continue
            except ImportError:
                pass
        if dataclasses.is_dataclass(obj) and name in {f.name for f in dataclasses.fields(obj)}:
            obj = ("field", obj, name)
            continue
        # A submodule shadowed by a package attribute of its name (``speedplan.plan.plan``).
        module = ".".join(parts[:i])
        if not inspect.ismodule(obj) and importlib.util.find_spec(module) is not None:
            return _resolve_from(importlib.import_module(module), parts[i:], dotted)
        raise AttributeError(f"{dotted}: no {name!r} in {module}")
    return obj


def _resolve_from(obj: Any, names: list[str], dotted: str) -> Any:
    for name in names:
        try:
            obj = inspect.getattr_static(obj, name)
        except AttributeError:
            if not (dataclasses.is_dataclass(obj)
                    and name in {f.name for f in dataclasses.fields(obj)}):
                raise AttributeError(f"{dotted}: no {name!r}") from None
            obj = ("field", obj, name)
    return obj


def public_objects() -> dict[str, Any]:
    """Every public name (dotted) and the object it denotes."""
    names = [f"speedplan.{n}" for n in speedplan.__all__ if n != "__version__"]
    for module in ("speedplan.io", "speedplan.plot"):
        mod = importlib.import_module(module)
        names += [f"{module}.{n}" for n in mod.__all__ if callable(getattr(mod, n))]
    names += EXTRA_PUBLIC
    return {name: _resolve(name) for name in names}


def public_members(cls: type) -> list[str]:
    """Methods and properties a user calls on ``cls`` (dataclass fields are documented in the
    class's own parameter table)."""
    internal = INTERNAL_MEMBERS.get(cls.__name__, set())
    kinds = (property, staticmethod, classmethod, functools.cached_property)
    return [name for name, value in vars(cls).items()
            if not name.startswith("_") and name not in internal
            and (isinstance(value, kinds) or inspect.isfunction(value))]


class _Anchors(HTMLParser):
    """The ids of the headings mkdocstrings renders for documented objects."""

    def __init__(self) -> None:
        super().__init__()
        self.objects: list[str] = []
        self.anchors: list[str] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        attr = dict(attrs)
        ident = attr.get("id") or ""
        if not ident.startswith("speedplan"):
            return
        if "doc-heading" in (attr.get("class") or ""):
            self.objects.append(ident)
        else:
            self.anchors.append(ident)


def _text(html: str) -> str:
    html = re.sub(r"<(script|style)\b.*?</\1>", " ", html, flags=re.S)
    return re.sub(r"<[^>]+>", "", html)


@pytest.fixture(scope="module")
def site(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("site")
    config = (ROOT / "mkdocs.yml").read_text(encoding="utf-8")
    # Unexecuted tutorials: their code blocks render as code (the full build runs in CI).
    config = config.replace("  - markdown-exec\n", "")
    config += f"\ndocs_dir: {ROOT / 'docs'}\n"
    cfg = out / "mkdocs.yml"
    cfg.write_text(config, encoding="utf-8")
    site_dir = out / "html"
    run = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "-f", str(cfg), "-d", str(site_dir)],
        cwd=ROOT, capture_output=True, text=True, timeout=600,
        env={**os.environ, "PYTHONPATH": str(ROOT), "NO_MKDOCS_2_WARNING": "1"},
    )
    assert run.returncode == 0, run.stderr[-4000:]
    return site_dir


def _api_pages(site: Path) -> list[Path]:
    pages = sorted((site / "api").rglob("index.html"))
    assert len(pages) > 1, "the API reference has no pages"
    return pages


def _anchors(site: Path) -> _Anchors:
    parser = _Anchors()
    for page in _api_pages(site):
        parser.feed(page.read_text(encoding="utf-8"))
    return parser


def test_no_literal_roles_on_the_site(site: Path) -> None:
    found = []
    for page in sorted(site.rglob("*.html")):
        for m in LITERAL_ROLE.finditer(_text(page.read_text(encoding="utf-8"))):
            found.append(f"{page.relative_to(site)}: ...{m.group(0)}...")
    assert not found, f"{len(found)} literal roles, e.g. {found[:5]}"


def test_no_literal_roles_in_the_sources() -> None:
    # Executed tutorials are skipped in the fast build above; their text must not hold roles.
    found = [f"{p.relative_to(ROOT)}:{i}" for p in sorted((ROOT / "docs").rglob("*.md"))
             for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1)
             if LITERAL_ROLE.search(line)]
    assert not found, found


def test_every_public_name_is_documented_as_itself(site: Path) -> None:
    anchors = _anchors(site)
    documented = {}
    for ident in anchors.objects:
        documented.setdefault(id(_resolve(ident)), ident)
    missing = [name for name, obj in public_objects().items() if id(obj) not in documented]
    assert not missing, f"public names without their own entry in the API reference: {missing}"
    # Their methods and properties too.
    objects = set(anchors.objects)
    absent = []
    for name, obj in public_objects().items():
        if inspect.isclass(obj) and not issubclass(obj, BaseException):
            head = documented[id(obj)]
            absent += [f"{name}.{m}" for m in public_members(obj) if f"{head}.{m}" not in objects]
    assert not absent, f"public members missing from the API reference: {absent}"


def test_no_internals_on_the_api_pages(site: Path) -> None:
    public = {id(obj) for obj in public_objects().values()}
    internals = []
    for ident in _anchors(site).objects:
        obj = _resolve(ident)
        if id(obj) in public:
            continue
        owner_name, _, member = ident.rpartition(".")
        owner = _resolve(owner_name)
        if (inspect.isclass(owner) and id(owner) in public
                and member not in INTERNAL_MEMBERS.get(owner.__name__, set())):
            continue
        internals.append(ident)
    assert not internals, f"internals on the API pages: {internals}"


def test_the_check_sees_what_it_checks(site: Path) -> None:
    # The parser must find the documented objects, or the two tests above pass vacuously.
    objects = set(_anchors(site).objects)
    assert {"speedplan.Limits", "speedplan.Path.from_waypoints"} <= objects
    assert LITERAL_ROLE.search("see :func:`plan`") and LITERAL_ROLE.search(":class:~x.Y")
    assert not LITERAL_ROLE.search("[`plan`][speedplan.plan] at 10:30: `x`")
    with pytest.raises(AttributeError):
        _resolve("speedplan.Limits.no_such_member")
