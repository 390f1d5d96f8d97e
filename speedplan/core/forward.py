"""Read-only attributes forwarded from another attribute of the same object."""

from __future__ import annotations

from typing import Any, Generic, TypeVar

__all__ = ["Forwarded"]

_T = TypeVar("_T")


class Forwarded(Generic[_T]):
    """A read-only attribute whose value is ``getattr(obj, source)[key]`` (or without ``[key]``).

    For the attributes a class only passes on from one of its parts, e.g.
    ``gap = Forwarded[float]("solution", "gap")`` reads ``self.solution.gap`` (``attribute``
    names an attribute of the part; ``key`` an item). The class docstring documents them.

    Examples
    --------
    >>> from dataclasses import dataclass
    >>> @dataclass
    ... class Result:
    ...     maxima: dict[str, float]
    ...     max_speed = Forwarded[float]("maxima", key="speed")
    >>> Result({"speed": 2.0}).max_speed
    2.0
    """

    def __init__(self, source: str, attribute: str | None = None, *, key: str | None = None):
        self.source, self.attribute, self.key = source, attribute, key
        part = f"{source}.{attribute}" if attribute is not None else source
        self.__doc__ = f"``{part}[{key!r}]``" if key is not None else f"``{part}``"

    def __get__(self, obj: Any, objtype: Any = None) -> _T:
        if obj is None:
            return self  # type: ignore[return-value]  # the class attribute: the descriptor
        value = getattr(obj, self.source)
        if self.attribute is not None:
            value = getattr(value, self.attribute)
        return value if self.key is None else value[self.key]  # type: ignore[no-any-return]

    def __set__(self, obj: Any, value: Any) -> None:
        raise AttributeError(f"{self.__doc__} is read-only")
