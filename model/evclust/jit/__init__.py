"""numba's compilers for the whole package: made when first needed, cached where the cache can be
written, and, for the functions `track` calls, taken from an ahead-of-time build when one is fresh.

Every compiled function of evclust is made by `njit` or `vectorize` from here, never by numba's
own decorators, so that one place decides three things.

**Lazily.** `njit` returns a `Compiled` function, not numba's dispatcher. numba is imported, and
every dispatcher made, the first time one of them has to run under numba (`_materialise`). Until
then nothing of numba is loaded: importing numba and decorating the package's functions took
0.6-0.8 s of a 2 s `track` on a short recording. At that moment each module's `Compiled` names are
replaced by their dispatchers, so numba compiles calls between them, and inlines them, as before.

**Ahead of time.** `evclust.jit.ahead` loads a build of `track`'s entry points (one extension
module, made by `python -m evclust.warm`) whose key matches the package's sources as they were
when this module was imported. A call whose arguments are of the kinds an export was built for
runs that export, without numba; any other call goes to numba, and once numba is in use in a
process (its dispatchers in the modules' names), every call does. docs/DESIGN.md, "Compiled code
ahead of time".

**The disk cache where it can be written.** Call sites keep ``cache=True``: it asks for the
cache, and gets it whenever numba could write one. numba (0.68) looks for a cache folder when a
dispatcher is made. It takes the first of NUMBA_CACHE_DIR (if set), the ``__pycache__`` folder
beside the source file, and the user-wide cache (``$XDG_CACHE_HOME/numba``, by default
``~/.cache/numba``) that it can create and write a file in. If it can write none of them (a
read-only install run by a user whose home is read-only or missing), it raises ``RuntimeError:
cannot cache function '...': no locator available for file '...'``. Here the same test is made
first, with numba's own operations (create the folder, write a temporary file in it). If no folder
is writable, the functions of that folder are compiled without a cache: everything works, each
run compiles them again (seconds, not minutes), and one line on stderr says so, once per process.
"""

from __future__ import annotations

import functools
import os
import sys
import threading

import numpy as np

from evclust.jit.ahead import argument_kinds, exports_for, source_key, writable_folder

source_key()  # the sources as imported: a build for them, not for a later edit, is what may load

_warned = False
_numba = None  # numba, once imported
_ready = False  # every dispatcher made and in place
_materialising = False  # `_materialise` is at work (in the thread holding `_LOCK`)
_LOCK = threading.RLock()  # the simulator's threads may make the first call together
_COMPILED: list[Compiled] = []  # every function made by `njit` or `vectorize`, in order
_DISPATCHERS = []  # numba's dispatchers of the `njit` ones, once made


@functools.cache
def _user_folder_writable(which: str) -> bool:
    """NUMBA_CACHE_DIR ("env") or numba's user-wide cache folder ("user"), tried once per process."""
    if which == "env":
        folder = _numba.config.CACHE_DIR
    else:
        try:
            from numba.misc.appdirs import AppDirs  # the helper numba itself locates it with
        except ImportError:  # a numba without it: assume the worst, compile without a cache
            return False
        folder = AppDirs(appname="numba", appauthor=False).user_cache_dir
    return bool(folder) and writable_folder(folder)


@functools.cache
def cache_writable(source_folder: str) -> bool:
    """Whether numba can cache the functions defined in `source_folder`, decided once per folder,
    in numba's order: NUMBA_CACHE_DIR, then the folder's __pycache__, then the user-wide cache."""
    if getattr(_numba.config, "CACHE_LOCATOR_CLASSES", None):  # the user chose numba's locators: trust them
        return True
    return _user_folder_writable("env") or writable_folder(os.path.join(source_folder, "__pycache__")) or _user_folder_writable("user")


def _cache_for(func) -> bool:
    source = func.__code__.co_filename
    # numba caches a function only if its source file is there (not an install of .pyc files only).
    if os.path.isfile(source) and cache_writable(os.path.dirname(os.path.abspath(source))):
        return True
    global _warned
    if not _warned:
        _warned = True
        print(
            "evclust: warning: no writable numba cache folder (set NUMBA_CACHE_DIR to one); compiling without a cache",
            file=sys.stderr,
        )
    return False


def _with_cache(func, options: dict) -> dict:
    """`options` with ``cache=True`` kept only where numba can write the cache."""
    return {**options, "cache": bool(options.get("cache")) and _cache_for(func)}


class Compiled:
    """A compiled function of evclust. Called, it runs its ahead-of-time export when one was built
    for arguments of these kinds, and numba's dispatcher otherwise. Any other attribute
    (``signatures``, ``overloads``, ...) is the dispatcher's."""

    _OWN = frozenset({"py_func", "ran_ahead", "dispatcher", "_make", "_dispatcher", "_exports"})

    def __init__(self, func, make):
        functools.update_wrapper(self, func)
        self.py_func = func
        self._make = make  # numba -> the dispatcher (or ufunc)
        self._dispatcher = None
        self._exports = None  # [(argument kinds, export)], read from the ahead-of-time build on first call
        self.ran_ahead = False  # an export of this function ran in this process
        _COMPILED.append(self)

    @property
    def dispatcher(self):
        if self._dispatcher is None:
            with _LOCK:
                if _materialising:  # asked for while `_materialise` makes the others (numba typing a caller)
                    self._dispatcher = self._make(_numba)
                else:
                    _materialise()
        return self._dispatcher

    def __call__(self, *args, **kwargs):
        if self._dispatcher is None and not kwargs:
            if self._exports is None:
                self._exports = exports_for(self.py_func)  # the build is looked for on the first call only
            if self._exports:
                kinds = argument_kinds(args)
                for built_for, export in self._exports:
                    if kinds == built_for:
                        self.ran_ahead = True
                        return export(*args)
        return self.dispatcher(*args, **kwargs)

    def __getattr__(self, name):
        if name.startswith("__") or name in self._OWN:
            raise AttributeError(name)  # not set yet (copying, pickling, a failed make): never numba for these
        return getattr(self.dispatcher, name)

    def __reduce__(self):  # pickled by name, as a plain function is
        return _by_name, (self.__module__, self.__qualname__)

    def __repr__(self) -> str:
        return f"<evclust.jit.Compiled {self.__module__}.{self.__qualname__}>"


def _by_name(module: str, qualname: str):
    import importlib

    return getattr(importlib.import_module(module), qualname)


def _materialise() -> None:
    """Import numba, make every dispatcher, and put them in place of their `Compiled` wherever a
    module of evclust holds one, so that numba sees dispatchers when it compiles a caller (and
    inlines what asks for it). A `Compiled` held anywhere else types as its dispatcher. Under
    `_LOCK`; a failure leaves what was made in place, and the next call makes the rest."""
    global _numba, _ready, _materialising
    with _LOCK:
        if _ready:
            return
        import numba
        from numba.core.typing.typeof import typeof_impl

        if _numba is None:
            typeof_impl.register(Compiled)(lambda value, context: typeof_impl(value.dispatcher, context))
        _numba = numba
        held = {}  # id of a Compiled -> the (module, name) pairs that hold it
        for name, module in list(sys.modules.items()):
            if module is not None and (name == "evclust" or name.startswith("evclust.")):
                for attribute, value in list(vars(module).items()):
                    if isinstance(value, Compiled):
                        held.setdefault(id(value), []).append((module, attribute))
        # In order of definition, each put in place before the next is made: a ufunc with explicit
        # signatures compiles when made, and must find the ones it calls made already.
        _materialising = True
        try:
            for compiled in _COMPILED:
                if compiled._dispatcher is None:
                    compiled._dispatcher = compiled._make(numba)
                for module, attribute in held.get(id(compiled), ()):
                    setattr(module, attribute, compiled._dispatcher)
        finally:
            _materialising = False
        _ready = True


def _lazily(func, make):
    """`make(numba)` now if numba is in use already (callers compiled later expect the dispatcher
    itself), else a `Compiled` that makes it when first needed."""
    with _LOCK:
        return make(_numba) if _ready else Compiled(func, make)


def njit(func=None, /, **options):
    """`numba.njit`, used as ``@njit(cache=True, ...)`` or ``njit(cache=True)(func)``: ``cache=True``
    is honoured when numba can write its cache (see the module's docstring), dropped otherwise."""
    if func is None:
        return functools.partial(njit, **options)

    def make(numba):
        dispatcher = numba.njit(func, **_with_cache(func, options))
        _DISPATCHERS.append(dispatcher)
        return dispatcher

    return _lazily(func, make)


def vectorize(signatures, **options):
    """`numba.vectorize` with explicit signatures, ``cache=True`` handled as by `njit`."""
    return lambda func: _lazily(func, lambda numba: numba.vectorize(signatures, **_with_cache(func, options))(func))


def compiled_code() -> tuple[int, int, int]:
    """(ahead, loaded, compiled): how many functions ran an ahead-of-time export in this process,
    and how many specialisations numba took from its disk cache and compiled, so far. A run's
    start-up is a difference of two of these."""
    ahead = sum(compiled.ran_ahead for compiled in _COMPILED)
    loaded = sum(sum(d.stats.cache_hits.values()) for d in _DISPATCHERS)
    made = sum(len(d.overloads) for d in _DISPATCHERS)
    return ahead, loaded, made - loaded


def named_record(dtype: np.dtype, values: dict) -> np.record:
    """One record of `dtype` holding `values` (every field, no other): what a compiled loop reads
    as named constants (`k.r_min`), passed by reference like an array and mutable from Python."""
    missing, extra = set(dtype.names) - set(values), set(values) - set(dtype.names)
    if missing or extra:
        raise ValueError(f"record fields: missing {sorted(missing)}, unknown {sorted(extra)}")
    row = np.rec.array(np.zeros(1, dtype))
    for name in dtype.names:
        row[name] = values[name]
    return row[0]
