"""numba's compilers for the whole package, with the on-disk cache only where it can be written.

Every compiled function of evclust is made by `njit` or `vectorize` from here, never by numba's
own decorators, so that one place decides whether numba's disk cache is used. Call sites keep
``cache=True``: it asks for the cache, and gets it whenever numba could write one.

Why: numba (0.68) looks for a cache folder when a function with ``cache=True`` is *decorated*,
that is when its module is imported. It takes the first of NUMBA_CACHE_DIR (if set), the
``__pycache__`` folder beside the source file, and the user-wide cache (``$XDG_CACHE_HOME/numba``,
by default ``~/.cache/numba``) that it can create and write a file in. If it can write none of
them (a read-only install run by a user whose home is read-only or missing), the decorator raises
``RuntimeError: cannot cache function '...': no locator available for file '...'``, so importing
the module, and with it every command, failed.

Here the same test is made first, with numba's own operations (create the folder, write a
temporary file in it): NUMBA_CACHE_DIR and the user-wide cache are tried once per process, a
``__pycache__`` once per source folder. If none is writable, the functions of that folder are
compiled without a cache: everything works, each run compiles them again (seconds, not minutes),
and one line on stderr says so, once per process.
"""

from __future__ import annotations

import functools
import os
import sys
import tempfile

import numba
import numpy as np

_warned = False


def _writable(folder: str) -> bool:
    """What numba's cache locators check: the folder can be created and a file written in it."""
    try:
        os.makedirs(folder, exist_ok=True)
        tempfile.TemporaryFile(dir=folder).close()
    except OSError:  # read-only, missing permissions, a file or a device on the path, ...
        return False
    return True


@functools.cache
def _user_folder_writable(which: str) -> bool:
    """NUMBA_CACHE_DIR ("env") or numba's user-wide cache folder ("user"), tried once per process."""
    if which == "env":
        folder = numba.config.CACHE_DIR
    else:
        try:
            from numba.misc.appdirs import AppDirs  # the helper numba itself locates it with
        except ImportError:  # a numba without it: assume the worst, compile without a cache
            return False
        folder = AppDirs(appname="numba", appauthor=False).user_cache_dir
    return bool(folder) and _writable(folder)


@functools.cache
def cache_writable(source_folder: str) -> bool:
    """Whether numba can cache the functions defined in `source_folder`, decided once per folder,
    in numba's order: NUMBA_CACHE_DIR, then the folder's __pycache__, then the user-wide cache."""
    if getattr(numba.config, "CACHE_LOCATOR_CLASSES", None):  # the user chose numba's locators: trust them
        return True
    return _user_folder_writable("env") or _writable(os.path.join(source_folder, "__pycache__")) or _user_folder_writable("user")


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


_DISPATCHERS = []  # every function compiled through `njit`, for `compiled_code`


def njit(func=None, /, **options):
    """`numba.njit`, used as ``@njit(cache=True, ...)`` or ``njit(cache=True)(func)``: ``cache=True``
    is honoured when numba can write its cache (see the module's docstring), dropped otherwise."""
    if func is None:
        return functools.partial(njit, **options)
    if options.get("cache"):
        options["cache"] = _cache_for(func)
    dispatcher = numba.njit(func, **options)
    _DISPATCHERS.append(dispatcher)
    return dispatcher


def compiled_code() -> tuple[int, int]:
    """(loaded, compiled): how many of the compiled functions' specialisations this process took
    from numba's disk cache, and how many it compiled, so far. A run's start-up is a difference
    of two of these."""
    loaded = sum(sum(d.stats.cache_hits.values()) for d in _DISPATCHERS)
    made = sum(len(d.overloads) for d in _DISPATCHERS)
    return loaded, made - loaded


def vectorize(signatures, **options):
    """`numba.vectorize` with explicit signatures, ``cache=True`` handled as by `njit`."""

    def decorate(func):
        if options.get("cache"):
            return numba.vectorize(signatures, **{**options, "cache": _cache_for(func)})(func)
        return numba.vectorize(signatures, **options)(func)

    return decorate


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
