"""Compiling, caching and fallback of every compiled (numba) kernel of the library.

Three families of kernels are compiled with numba and cached on disk (``cache=True``: in
``__pycache__`` next to the sources, or under ``NUMBA_CACHE_DIR``):

``"relaxation"``
    the banded interior-point iteration (`speedplan.solve._banded_ipm`); until it is
    available, ``backend="auto"`` answers with Clarabel;
``"time law"``
    the time law's quadrature, inversion and kinematics (`speedplan.core._law_kernel`);
    until it is available, the same formulas run in numpy (`speedplan.timing._law_numpy`);
``"refinement"``
    the banded refinement's array work (`speedplan.solve._banded_nlp_kernels`); until it
    is available, the same steps run in numpy (`speedplan.solve.banded_nlp`).

Each kernel module declares its kernels with `kernel` (called from Python), `inner`
(called only from other kernels) and `inlined` (inlined by numba into its callers), and
lists every kernel numba compiles on its own with one explicit signature
(``signatures()``), each after the kernels it calls, and the entry points called from
Python (``ENTRY_POINTS``). `Kernels.load` loads the entry points from numba's cache without
ever compiling (`load_cached_overload`); `Kernels.compile` loads or compiles every kernel in
that order, each for its one signature, and then refuses any other. A caller passing a
constant (a mode, ``False``) thus uses the kernel compiled for the constant's type, where
numba would otherwise compile one more copy specialised to the value.

Numba links the code of every kernel a function calls into that function and optimises and
emits it again there, so a kernel's compilation costs about what it calls in all. The
relaxation's single entry point, `speedplan.solve._banded_ipm.iterate`, is therefore the
last and largest step; the kernels below it are independent subtrees (`Kernels.parts`),
which worker processes compile side by side into the cache before the process compiling
the family compiles the entry point, loading the rest (`part_count`, `_compile_whole`).

When a family is not in the cache, `Kernels.ready` starts one background Python process
that compiles it (and the families after it) while the fallback answers. A lock file per
family (`Kernels.lock_path`) keeps the workers of [`plan_many`][speedplan.plan_many], which
all start cold, from compiling the same family at once. ``pip install`` runs
`compile_families` while it builds the wheel (the build hook ``hatch_build.py``) and
installs the cache with the package, so that the first ``plan()`` after installing loads the
kernels. ``speedplan compile`` (`compile_families`, every family in parallel processes, then
waits) is the step where those do not apply: a wheel built on another kind of machine,
another numba, a cache under ``NUMBA_CACHE_DIR``.

Setting the environment variable ``SPEEDPLAN_BACKGROUND_COMPILE=0`` makes every fallback
compile in the calling process instead (the results are then independent of timing).

Numba keeps one index file per function and pickles into it every signature it has compiled
for, with their argument types. Our kernels take ``NamedTuple`` arguments. When a later
version of the package drops or renames one of those classes, an index left behind by the
earlier version (``pip install -U`` leaves ``__pycache__`` in place) fails to unpickle, and
numba raises that error from the first call instead of recompiling: ``AttributeError: Can't
get attribute 'Work' on <module 'speedplan.solve._banded_ipm'>`` (numba issue #6018, still so
in numba 0.68). `tolerate_stale_indexes` makes such an index read as empty, which is how
numba already treats an index written by another numba version or for an older source; the
next compilation writes a fresh one.
"""

from __future__ import annotations

import hashlib
import importlib
import importlib.util
import os
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterable
from types import ModuleType
from typing import Any, TypeVar

__all__ = [
    "BACKGROUND_COMPILE_ENV", "COMPILE_LOCK_STALE", "FAMILIES", "Kernels", "compile_families",
    "inlined", "inner", "kernel", "load_cached_overload", "tolerate_stale_indexes",
]

_K = TypeVar("_K", bound=Callable[..., Any])

#: numba options of every kernel. The kernels allocate nothing (their callers pass every
#: array), so they run without numba's reference counting (``_nrt=False``): no increment
#: and decrement of every array at every call to lower, optimise and emit. No C entry point
#: either. The arithmetic is the same.
KERNEL_OPTIONS: dict[str, Any] = {"cache": True, "error_model": "numpy", "_nrt": False,
                                  "no_cfunc_wrapper": True}


def _njit(fn: _K, options: dict[str, Any]) -> _K:
    from numba import njit

    compiled: _K = njit(**options)(fn)
    return compiled


def kernel(fn: _K, error_model: str = "numpy") -> _K:
    """A kernel called from Python: ``numba.njit(**KERNEL_OPTIONS)``.

    ``error_model="python"`` makes a division by zero raise instead of giving ``inf``.
    """
    return _njit(fn, {**KERNEL_OPTIONS, "error_model": error_model})


def inner(fn: _K, error_model: str = "numpy") -> _K:
    """A kernel called only from other kernels: no Python entry point to generate."""
    return _njit(fn, {**KERNEL_OPTIONS, "error_model": error_model, "no_cpython_wrapper": True})


def inlined(fn: _K) -> _K:
    """A kernel that numba inlines into each caller: no code of its own to compile.

    For kernels that only call others in sequence: compiled on their own, each would carry
    a copy of everything it calls, optimised and emitted once more (numba links a callee's
    code into each of its callers').
    """
    options = {k: v for k, v in KERNEL_OPTIONS.items() if k != "cache"}
    return _njit(fn, {**options, "no_cpython_wrapper": True, "inline": "always"})


#: Environment variable: set to ``0`` to make every fallback compile its kernels in the calling
#: process instead of answering without them while a background process compiles them.
BACKGROUND_COMPILE_ENV = "SPEEDPLAN_BACKGROUND_COMPILE"

#: A compile lock older than this [s] is taken to be left by a process that died.
COMPILE_LOCK_STALE = 600.0


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


def load_cached_overload(disp: Any, sig: Any) -> bool:
    """Load numba dispatcher ``disp``'s overload for ``sig`` from the on-disk cache; never compiles.

    ``sig``: a signature string or a tuple of numba types. Mirrors what
    `numba.core.dispatcher.Dispatcher.compile` does on a cache hit (numba's dispatcher
    offers no public "load but do not compile"); any failure means "not loaded".
    """
    from numba.core import sigutils
    from numba.core.compiler_lock import global_compiler_lock

    try:
        args, _ = sigutils.normalize_signature(sig)  # type: ignore[no-untyped-call]
        if tuple(args) in disp.overloads:
            return True
        with global_compiler_lock:
            cres = disp._cache.load_overload(sig, disp.targetctx)
            if cres is None:
                return False
            disp.targetctx.insert_user_function(cres.entry_point, cres.fndesc, [cres.library])
            disp.add_overload(cres)
        return True
    except Exception:  # pragma: no cover - numba internals changed: behave as "not cached"
        return False


def background_allowed() -> bool:
    """Whether fallbacks may compile in a background process (``SPEEDPLAN_BACKGROUND_COMPILE``)."""
    return os.environ.get(BACKGROUND_COMPILE_ENV) != "0"


class Kernels:
    """One family of compiled kernels: loaded from the cache, compiled, or in the background.

    Parameters
    ----------
    name : str
        The family's name (a key of `FAMILIES`).
    module : str
        The module defining the kernels. It calls `tolerate_stale_indexes` and
        defines ``signatures()``: ``{dispatcher name: signature}`` of every kernel called from
        Python; nothing else of the family is ever compiled in a process that uses it.
    then : tuple of str
        Families that this family's background process compiles after it.
    split : bool
        Whether a compilation of the whole family starts worker processes for parts of it
        (`parts`), up to one per core (at most `MAX_PARTS`), before its entry points.
    """

    def __init__(self, name: str, module: str, then: tuple[str, ...] = (),
                 split: bool = False) -> None:
        self.name = name
        self.module_name = module
        #: Families its background process compiles next (when no other process does).
        self.then = then
        #: Whether its compilation is split over several processes.
        self.split = split
        #: The kernel module once every kernel of the family is loaded in this process.
        self.module: ModuleType | None = None
        #: The background compilation started by this process, while it runs.
        self.background: subprocess.Popen[bytes] | None = None
        #: Set when a background compilation failed or could not start: never again.
        self.spawn_failed = False

    def __repr__(self) -> str:
        return f"Kernels({self.name!r}, {self.module_name!r})"

    def _entries(self, *, every: bool = False) -> tuple[ModuleType, list[tuple[Any, Any]]]:
        """The module and ``(dispatcher, signature)`` of its entry points (``every``: all)."""
        kn = importlib.import_module(self.module_name)  # imports numba
        sigs = kn.signatures()
        names = list(sigs) if every else getattr(kn, "ENTRY_POINTS", list(sigs))
        return kn, [(getattr(kn, name), sigs[name]) for name in names]

    def _finish(self, kn: ModuleType, entries: list[tuple[Any, Any]]) -> ModuleType:
        for disp, _ in entries:
            disp.disable_compile()  # a call with other types is a bug, not a compilation
        self.module = kn
        return kn

    def load(self) -> bool:
        """Load every kernel of the family from numba's cache; never compiles.

        Returns whether they are all available in this process now.
        """
        if self.module is not None:
            return True
        kn, entries = self._entries()
        if all(load_cached_overload(disp, sig) for disp, sig in entries):
            self._finish(kn, entries)
            return True
        return False

    def compile(self) -> ModuleType:
        """Make the family available in this process now: load it, or compile it here.

        Waits for this process's own background compilation first (it fills the cache).
        """
        if self.module is not None:
            return self.module
        if self.background is not None:
            self.background.wait()
            self.background = None
        kn, entries = self._entries(every=True)
        for disp, sig in entries:
            if not load_cached_overload(disp, sig):
                disp.compile(sig)
            disp.disable_compile()  # its callers use this overload, whatever they pass
        return self._finish(kn, entries)

    def compile_part(self, names: Iterable[str]) -> None:
        """Load or compile the kernels ``names`` here, in the family's order; nothing else."""
        kn = importlib.import_module(self.module_name)
        chosen = set(names)
        for name, sig in kn.signatures().items():
            if name in chosen:
                disp = getattr(kn, name)
                if not load_cached_overload(disp, sig):
                    disp.compile(sig)
                disp.disable_compile()

    def parts(self, count: int) -> list[list[str]]:
        """The kernels below the entry points in up to ``count`` groups of similar size.

        Each group holds whole subtrees of calls (a kernel with every kernel it calls), so
        that processes compiling one group each need nothing from the others: a kernel
        called from two groups is compiled in both. Sizes are measured in bytecode. The
        entry points compiled afterwards load every group from numba's cache.

        Examples
        --------
        >>> groups = FAMILIES["relaxation"].parts(2)
        >>> len(groups), "iterate" in groups[0] + groups[1]
        (2, False)
        """
        kn = importlib.import_module(self.module_name)
        sigs = kn.signatures()
        entries = set(getattr(kn, "ENTRY_POINTS", sigs))
        below = _callees(kn, list(sigs))
        called = set().union(*(below[n] - {n} for n in sigs if n not in entries))
        tops = [n for n in sigs if n not in entries and n not in called]
        size = {n: len(getattr(kn, n).py_func.__code__.co_code) for n in sigs}
        groups: list[set[str]] = [set() for _ in range(max(1, count))]
        for top in sorted(tops, key=lambda t: -sum(size[k] for k in below[t])):
            group = min(groups, key=lambda g: sum(size[k] for k in g | below[top]))
            group |= below[top]
        return [[n for n in sigs if n in g] for g in groups if g]

    def ready(self, *, start: bool = True) -> bool:
        """Whether the kernels run now without compiling; else compile them in the background.

        They are loaded from numba's cache when they are there. When they are not (first use
        after installation), and ``start`` is true, a background Python process compiles
        them into the cache, unless ``SPEEDPLAN_BACKGROUND_COMPILE=0`` or another process
        holds the family's lock; later calls load them once that process is done.
        """
        if self.module is not None:
            return True
        if not self.background_done():
            return False
        if self.load():
            return True
        if start and self.background_allowed() and claim_lock(self.lock_path()):
            names = [self.name, *(n for n in self.then
                                  if FAMILIES[n].module is None
                                  and claim_lock(FAMILIES[n].lock_path()))]
            self.background = spawn_compile(names)
            self.spawn_failed = self.background is None
            if self.background is None:
                for name in names:
                    _release(FAMILIES[name])
        return False

    def available(self, *, wait: bool) -> ModuleType | None:
        """The kernel module if the family runs now, after compiling it here if need be.

        The family is compiled in this process when ``wait`` is true or background
        compilation is off (``SPEEDPLAN_BACKGROUND_COMPILE=0``, or no process could be
        started or it failed); otherwise ``None`` while a background process compiles it.
        """
        if self.ready(start=not wait):
            return self.module
        if wait or (self.background is None and not self.background_allowed()):
            return self.compile()
        return None

    def background_done(self) -> bool:
        """Whether this process's background compilation is over, or none ran."""
        if self.background is None:
            return True
        code = self.background.poll()
        if code is None:
            return False
        self.background = None
        self.spawn_failed = code != 0
        return True

    def background_allowed(self) -> bool:
        """Whether a background compilation may start (on, and none failed before)."""
        return not self.spawn_failed and background_allowed()

    def lock_path(self) -> str:
        """One lock per family, copy of speedplan, numba version, cache directory, interpreter."""
        import numba

        spec = importlib.util.find_spec(self.module_name)
        origin = spec.origin if spec is not None and spec.origin else self.module_name
        key = "|".join((os.path.abspath(origin), numba.__version__,
                        os.environ.get("NUMBA_CACHE_DIR", ""), sys.executable))
        digest = hashlib.sha256(key.encode()).hexdigest()[:16]
        return os.path.join(tempfile.gettempdir(), f"speedplan-kernel-{digest}.lock")


def _callees(kn: ModuleType, names: list[str]) -> dict[str, set[str]]:
    """Each kernel of ``names`` with every kernel of ``names`` it calls, directly or not.

    Read from the functions' code (the global names they use), through kernels numba
    inlines (`inlined`), which are not in ``names``.
    """
    from numba.core.registry import CPUDispatcher

    kernels = {n: d for n in dir(kn) if isinstance(d := getattr(kn, n), CPUDispatcher)}
    direct = {n: {c for c in d.py_func.__code__.co_names if c in kernels and c != n}
              for n, d in kernels.items()}
    out: dict[str, set[str]] = {}
    for name in names:
        seen, todo = set(), [name]
        while todo:
            k = todo.pop()
            if k not in seen:
                seen.add(k)
                todo.extend(direct[k])
        out[name] = seen & set(names)
    return out


#: Most processes a split family's compilation uses (`Kernels.parts`).
MAX_PARTS = 4


def part_count() -> int:
    """How many processes compile a split family: one per core, at most `MAX_PARTS`."""
    return max(1, min(MAX_PARTS, os.cpu_count() or 1))


#: Every family of compiled kernels, by name, in the order a plan() needs them.
FAMILIES: dict[str, Kernels] = {
    "relaxation": Kernels("relaxation", "speedplan.solve._banded_ipm", then=("time law",),
                          split=True),
    "time law": Kernels("time law", "speedplan.core._law_kernel"),
    "refinement": Kernels("refinement", "speedplan.solve._banded_nlp_kernels"),
}


def claim_lock(path: str) -> bool:
    """Create the lock file ``path``; False if a fresh one exists (another process compiles).

    A lock older than `COMPILE_LOCK_STALE` was left by a process that died: taken over.
    """
    for _ in range(2):
        try:
            os.close(os.open(path, os.O_CREAT | os.O_EXCL | os.O_WRONLY))
            return True
        except FileExistsError:
            try:
                if time.time() - os.path.getmtime(path) < COMPILE_LOCK_STALE:
                    return False
                os.remove(path)  # stale: its compiling process died
            except OSError:
                return False
        except OSError:
            return True  # no usable temporary directory: compile without a lock
    return False


#: The compiling process's program (``-c``; ``-m`` would import this module twice).
_MAIN = "import sys; from speedplan.core.jit import _main; sys.exit(_main(sys.argv[1:]))"


def _package_root() -> str:
    return os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def spawn_compile(names: Iterable[str]) -> subprocess.Popen[bytes] | None:
    """Start a Python process compiling the families ``names``, on this very copy of speedplan.

    The process compiles the families ``names`` into numba's cache and removes each one's
    lock (claimed by the caller) when it is done. It runs at normal priority: measured on a
    loaded 2-core machine, a compilation at the lowest priority took 75 s instead of 25 s,
    and every plan meanwhile ran on the slower fallback.
    """
    return _spawn(list(names), subprocess.DEVNULL)


def _spawn(args: list[str], output: int) -> subprocess.Popen[bytes] | None:
    """A Python process running `_main` with ``args`` on this copy of speedplan.

    Its standard output and error go to ``output``; None if no process could start.
    """
    if not sys.executable:
        return None
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (_package_root(), env.get("PYTHONPATH")) if p)
    try:
        return subprocess.Popen([sys.executable, "-c", _MAIN, *args], env=env,
                                stdin=subprocess.DEVNULL, stdout=output,
                                stderr=subprocess.STDOUT)
    except OSError:
        return None


def compile_families(names: Iterable[str] | None = None, *, parallel: bool = True
                     ) -> dict[str, float]:
    """Compile the kernel families ``names`` (default: all) into numba's cache; wait for them.

    With ``parallel``, each family compiles in its own process (the compilation is
    single-threaded, so this uses the machine's cores); otherwise they compile here, one
    after the other. Families already in the cache load in well under a second.

    Returns
    -------
    dict
        Seconds per family (wall clock, from the start of the call).

    Raises
    ------
    RuntimeError
        If a compilation process failed (its output is in the message).

    Examples
    --------
    >>> seconds = compile_families(["time law"], parallel=False)
    >>> list(seconds)
    ['time law']
    """
    chosen = list(FAMILIES) if names is None else list(names)
    unknown = [n for n in chosen if n not in FAMILIES]
    if unknown:
        raise ValueError(f"unknown kernel families {unknown}; valid: {list(FAMILIES)}")
    t0 = time.perf_counter()
    seconds: dict[str, float] = {}
    if not parallel:
        for name in chosen:
            FAMILIES[name].compile()
            seconds[name] = time.perf_counter() - t0
        return seconds
    procs = {name: _spawn(["--no-lock", name], subprocess.PIPE) for name in chosen}
    failed = [f"{name}: no process could start" for name, p in procs.items() if p is None]
    pending = {name: proc for name, proc in procs.items() if proc is not None}
    while pending:
        for name, proc in list(pending.items()):
            if proc.poll() is not None:
                seconds[name] = time.perf_counter() - t0
                out = proc.communicate()[0].decode(errors="replace")
                if proc.returncode != 0:
                    failed.append(f"{name}: {out.strip()[-2000:]}")
                del pending[name]
        time.sleep(0.02)
    if failed:
        raise RuntimeError("compiling the kernels failed:\n" + "\n".join(failed))
    return seconds


def _main(argv: list[str]) -> int:
    """The compiling process: ``[--no-lock] TOKEN...``, each token in turn.

    A token is a family's name (compile it, then release its lock) or ``NAME#I/K``, the
    group ``I`` of the family's `Kernels.parts` in ``K`` (a worker of the former).
    """
    lock = "--no-lock" not in argv
    for token in (a for a in argv if a != "--no-lock"):
        name, _, part = token.partition("#")
        family = FAMILIES[name]
        if part:
            index, count = (int(x) for x in part.split("/"))
            family.compile_part(family.parts(count)[index])
            continue
        try:
            _compile_whole(family)
        finally:
            if lock:
                _release(family)
    return 0


def _compile_whole(family: Kernels) -> None:
    """Compile ``family``; a split one with worker processes for all of its parts but one.

    This process compiles the first part, waits for the workers (their parts are then in
    numba's cache), and compiles the entry points, loading the rest. A worker that fails
    costs time only: whatever is missing is compiled here.
    """
    workers: list[subprocess.Popen[bytes]] = []
    try:
        if family.split and part_count() > 1:
            groups = family.parts(part_count())
            for index in range(1, len(groups)):
                worker = _spawn([f"{family.name}#{index}/{part_count()}"], subprocess.DEVNULL)
                if worker is not None:
                    workers.append(worker)
            family.compile_part(groups[0])
    finally:
        for worker in workers:
            worker.wait()
    family.compile()


def _release(family: Kernels) -> None:
    """Remove ``family``'s compile lock."""
    try:
        os.remove(family.lock_path())
    except OSError:
        pass
