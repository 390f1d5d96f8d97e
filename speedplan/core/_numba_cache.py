"""Numba's on-disk cache, made to treat an index it cannot read as obsolete.

The compiled kernels are cached with ``cache=True``. Numba keeps one index file per
function (in ``__pycache__`` next to the source, or under ``NUMBA_CACHE_DIR``), named after
the function and its line number, and pickles into it every signature it has compiled for,
with their argument types. Our kernels take ``NamedTuple`` arguments. When a later version
of the package drops or renames one of those classes, an index left behind by the earlier
version (``pip install -U`` leaves ``__pycache__`` in place) fails to unpickle, and numba
raises that error from the first call instead of recompiling: ``AttributeError: Can't get
attribute 'Work' on <module 'speedplan.solve._banded_ipm'>`` (numba issue #6018, still so in
numba 0.68). `tolerate_stale_indexes` makes such an index read as empty, which is how
numba already treats an index written by another numba version or for an older source; the
next compilation writes a fresh one.
"""

from __future__ import annotations

from typing import Any

__all__ = ["tolerate_stale_indexes"]


def tolerate_stale_indexes() -> None:
    """Make numba read a cache index that fails to unpickle as empty (idempotent).

    Called by every module of ours that defines cached kernels, before any of them runs.
    If numba's internals ever differ from what this expects, nothing is changed.

    Examples
    --------
    >>> tolerate_stale_indexes()
    >>> from numba.core.caching import IndexDataCacheFile
    >>> IndexDataCacheFile._load_index.__name__
    '_load_index_or_empty'
    """
    try:
        from numba.core.caching import IndexDataCacheFile
    except ImportError:  # pragma: no cover - numba reorganised: leave it as it is
        return
    original = getattr(IndexDataCacheFile, "_load_index", None)
    if original is None or getattr(original, "__name__", "") == "_load_index_or_empty":
        return

    def _load_index_or_empty(self: Any) -> dict[Any, Any]:
        try:
            index: dict[Any, Any] = original(self)
        except Exception:  # an index pickled with types that no longer exist
            return {}
        return index

    IndexDataCacheFile._load_index = _load_index_or_empty  # type: ignore[method-assign]
