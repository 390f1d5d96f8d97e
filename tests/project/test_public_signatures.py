"""Typed public seams: no ``typing.Any`` in a public signature.

Every public name of ``speedplan``, ``speedplan.route``, ``speedplan.timing`` and
``speedplan.geometry``: each function, and for each class its constructor and every public
method, classmethod, staticmethod and property getter. ``from __future__ import annotations``
makes every annotation a string, so ``Any`` is looked for as a word in its text.
"""

from __future__ import annotations

import importlib
import inspect
import re
from collections.abc import Callable, Iterator
from functools import cached_property
from typing import Any

import pytest

MODULES = ("speedplan", "speedplan.route", "speedplan.timing", "speedplan.geometry")

ANY = re.compile(r"\bAny\b")


def _members(cls: type) -> Iterator[tuple[str, Callable[..., object]]]:
    """The constructor and the public callables of ``cls`` (its own and inherited ones)."""
    yield "__init__", cls.__init__
    for name in dir(cls):
        if name.startswith("_"):
            continue
        raw = inspect.getattr_static(cls, name)
        if isinstance(raw, property) and raw.fget is not None:
            yield name, raw.fget
        elif isinstance(raw, cached_property):
            yield name, raw.func
        elif isinstance(raw, classmethod | staticmethod):
            yield name, raw.__func__
        elif inspect.isfunction(raw):
            yield name, raw


def public_callables() -> dict[str, Callable[..., object]]:
    """Each public function, constructor and method, by its qualified name."""
    out: dict[str, Callable[..., object]] = {}
    for module_name in MODULES:
        module = importlib.import_module(module_name)
        for name in module.__all__:
            obj = getattr(module, name)
            if inspect.isclass(obj):
                for member, fn in _members(obj):
                    out.setdefault(f"{obj.__module__}.{obj.__qualname__}.{member}", fn)
            elif inspect.isfunction(obj):
                out.setdefault(f"{obj.__module__}.{obj.__qualname__}", obj)
    return out


def any_annotations(fn: Callable[..., object]) -> list[str]:
    """The parameters (and ``"return"``) of ``fn`` whose annotation names ``Any``."""
    try:
        sig = inspect.signature(fn)
    except (TypeError, ValueError):  # a builtin without a signature: nothing annotated
        return []
    found = [f"{name}: {p.annotation}" for name, p in sig.parameters.items()
             if p.annotation is not inspect.Parameter.empty and ANY.search(str(p.annotation))]
    if sig.return_annotation is not inspect.Signature.empty and ANY.search(
            str(sig.return_annotation)):
        found.append(f"return: {sig.return_annotation}")
    return found


PUBLIC = public_callables()


def test_the_walk_finds_the_public_seams() -> None:
    # Functions, constructors, methods, classmethods and properties of all four modules.
    for name in ("speedplan.plan.plan", "speedplan.geometry.path.Path.point",
                 "speedplan.geometry.path.Path.from_segments",
                 "speedplan.geometry.bounds.SpeedZone.__init__",
                 "speedplan.timing.profile.SpeedProfile.metadata",
                 "speedplan.route.profile.RouteTrajectory.__init__",
                 "speedplan.timing.profile.law_for", "speedplan.geometry.bounds.bound_breakpoints"):
        assert name in PUBLIC, name


@pytest.mark.parametrize("name", sorted(PUBLIC))
def test_no_any_in_a_public_signature(name: str) -> None:
    assert any_annotations(PUBLIC[name]) == []


def test_an_any_is_found() -> None:
    def loose(s: Any, *, n: int = 1) -> dict[str, Any]:
        return {"s": s, "n": n}

    def many(segments: list[Any]) -> None:
        del segments

    def anything(value: object, company: AnyName) -> object:
        return value, company

    assert any_annotations(loose) == ["s: Any", "return: dict[str, Any]"]
    assert any_annotations(many) == ["segments: list[Any]"]
    assert any_annotations(anything) == []


class AnyName:
    """A name that starts with ``Any`` is not ``Any``."""
