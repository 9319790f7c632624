"""Compiled functions built ahead of time: the functions a run calls from Python, compiled by
numba.pycc into one extension module that loads in a millisecond and needs no numba.

A short `track` spent most of its time getting numba ready: importing it (0.4 s), decorating the
package's functions (0.3 s) and loading the loops from numba's disk cache (0.6-0.8 s), against
0.08 s of event loop on a 2.4 s recording. `build` (run by `python -m evclust.warm`) compiles
every specialisation the given functions were called with into `_evclust_ahead_<key>.so`, beside a
manifest of what each export was built for. `exports_for` hands a `Compiled` function its exports
when the build's key is the package's: a hash of every source file of evclust, the Python, numpy
and numba versions, and the processor (the build uses its instruction set, as numba's own code
does: for a generic one the loop ran 3.5 Mevents/s against numba's 5.3). Edit any source file
and the build is ignored (numba compiles as before) until the next `build`. EVCLUST_AHEAD=0
ignores it too. The exports hold the GIL while they run (numba's `nogil` has no pycc form):
`track` runs one loop per process.

Where: the first folder of `folders()` that can be written (NUMBA_CACHE_DIR/evclust when set, the
package's __pycache__, the user's cache folder), looked for in the same order. Where none can be
written, or no C compiler or Python headers are there, nothing is built and numba's cache serves.
numba.pycc is pending deprecation in numba 0.68; its successor is not released. Without it,
`build` says so and the runs use numba's cache. docs/DESIGN.md, "Compiled code ahead of time".
"""

from __future__ import annotations

import functools
import hashlib
import importlib.machinery
import importlib.util
import itertools
import os
import platform
import pickle
import sys
import sysconfig
import tempfile
import warnings
from pathlib import Path

import numpy as np

PACKAGE = Path(__file__).resolve().parents[1]
PREFIX = "_evclust_ahead_"
DISABLE = "EVCLUST_AHEAD"  # "0": numba for everything


@functools.cache
def source_key() -> str:
    """The hash a build is valid for, computed once per process (evclust.jit computes it when it
    is imported): every source file of the package, and what compiles and runs them."""
    return _key_now()


def _key_now() -> str:
    digest = hashlib.sha256()
    numba_spec = importlib.util.find_spec("numba")  # its version without importing it
    numba_version = Path(numba_spec.origin).with_name("_version.py") if numba_spec and numba_spec.origin else None
    digest.update(f"{sys.version}|{np.__version__}|{_cpu()}|".encode())
    digest.update(numba_version.read_bytes() if numba_version and numba_version.is_file() else b"no numba")
    for path in sorted(PACKAGE.rglob("*.py")):
        digest.update(str(path.relative_to(PACKAGE)).encode() + b"\0" + path.read_bytes() + b"\0")
    return digest.hexdigest()[:20]


def _cpu() -> str:
    """The processor the build is compiled for (pycc's "host"): its model and instruction-set
    flags, so that a folder copied to another machine is not run there."""
    try:
        with open("/proc/cpuinfo", encoding="utf-8", errors="replace") as info:
            lines = [line for line in itertools.islice(info, 64) if line.startswith(("model name", "flags", "Features", "CPU part"))]
        if lines:
            return "".join(lines)
    except OSError:  # not Linux
        pass
    return f"{platform.machine()}|{platform.processor()}"


def writable_folder(folder: str) -> bool:
    """What numba's cache locators check: the folder can be created and a file written in it."""
    try:
        os.makedirs(folder, exist_ok=True)
        tempfile.TemporaryFile(dir=folder).close()
    except OSError:  # read-only, missing permissions, a file or a device on the path, ...
        return False
    return True


def folders() -> list[Path]:
    """Where a build may be, in the order it is looked for and written."""
    found = []
    if os.environ.get("NUMBA_CACHE_DIR"):
        found.append(Path(os.environ["NUMBA_CACHE_DIR"]) / "evclust")
    found.append(PACKAGE / "__pycache__")
    found.append(Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "evclust")
    return found


def _files(folder: Path, key: str) -> tuple[Path, Path]:
    """The extension module and its manifest for `key` in `folder`."""
    name = PREFIX + key
    return folder / (name + sysconfig.get_config_var("EXT_SUFFIX")), folder / (name + ".manifest")


def _whole_builds():
    """(module, manifest) of each build for this package's sources that has both files, in the
    order of `folders()`."""
    key = source_key()
    for folder in folders():
        module_path, manifest_path = _files(folder, key)
        if manifest_path.is_file() and module_path.is_file():
            yield module_path, manifest_path


@functools.cache
def loaded() -> dict:
    """{(module, qualified name): [(argument kinds, export)]} of the first build that loads."""
    if os.environ.get(DISABLE) == "0":
        return {}
    for module_path, manifest_path in _whole_builds():
        name = module_path.name.split(".")[0]
        try:
            manifest = pickle.loads(manifest_path.read_bytes())
            loader = importlib.machinery.ExtensionFileLoader(name, str(module_path))
            spec = importlib.util.spec_from_file_location(name, module_path, loader=loader)
            module = importlib.util.module_from_spec(spec)
            loader.exec_module(module)
        except Exception:  # a broken build: the next one, or numba
            continue
        exports = {}
        for entry in manifest["exports"]:
            exports.setdefault((entry["module"], entry["qualname"]), []).append((entry["kinds"], getattr(module, entry["export"])))
        return exports
    return {}


def exports_for(func) -> list:
    """The exports built for `func` (a Python function), with the argument kinds of each."""
    return loaded().get((func.__module__, func.__qualname__), [])


def location() -> Path | None:
    """The manifest of the build that serves this package's sources, if one is there whole."""
    return next((manifest for _, manifest in _whole_builds()), None)


# The kinds of argument an export is built for, in the words numba's dispatch goes by: an array's
# dtype, dimensions, layout and writability (numba's typeof ignores alignment); a record's dtype;
# a tuple's class (module, name, fields) and its items' kinds; a scalar's numba type. Anything
# else is never built ahead of time, and goes to numba.
_INT64 = (-(1 << 63), (1 << 63) - 1)


def argument_kinds(args) -> tuple:
    """The kinds of a call's arguments. Calls of the same kinds run the same specialisation."""
    return tuple(_kind(value) for value in args)


def _tuple_class(cls) -> tuple:
    return (cls.__module__, cls.__qualname__, getattr(cls, "_fields", None))


def _kind(value):
    if type(value) is np.ndarray:  # not a subclass: numba refuses a masked array, for one
        layout = "C" if value.flags.c_contiguous else "F" if value.flags.f_contiguous else "A"  # numba's map_layout
        return ("array", value.dtype, value.ndim, layout, value.flags.writeable)
    if isinstance(value, np.void):
        return ("record", value.dtype)
    if isinstance(value, tuple):
        return ("tuple", _tuple_class(type(value)), tuple(_kind(item) for item in value))
    if value is None:
        return ("scalar", "none")
    if isinstance(value, bool):  # before int: a bool is an int
        return ("scalar", "bool")
    if isinstance(value, int):
        return ("scalar", "int64") if _INT64[0] <= value <= _INT64[1] else ("other", "int")
    if isinstance(value, float):
        return ("scalar", "float64")
    if isinstance(value, np.generic):
        return ("scalar", str(value.dtype))
    return ("other", type(value).__qualname__)


def kind_of_type(numba_type):
    """The kind of argument numba types as `numba_type` (what a build records for each export)."""
    from numba.core import types
    from numba.np.numpy_support import as_dtype

    if isinstance(numba_type, types.Array):
        return ("array", as_dtype(numba_type.dtype), numba_type.ndim, numba_type.layout, numba_type.mutable)
    if isinstance(numba_type, types.Record):
        return ("record", as_dtype(numba_type))
    if isinstance(numba_type, types.BaseTuple):
        cls = getattr(numba_type, "instance_class", tuple)
        return ("tuple", _tuple_class(cls), tuple(kind_of_type(t) for t in numba_type.types))
    if isinstance(numba_type, (types.Boolean, types.Integer, types.Float, types.NoneType)):
        return ("scalar", str(numba_type))
    raise TypeError(f"no ahead-of-time export for arguments of type {numba_type}")


def build(functions, out=sys.stderr) -> Path | None:
    """Compile every specialisation numba has made of `functions` (`Compiled` functions or their
    dispatchers, each called already) into one extension module with its manifest, in the first
    writable folder; remove the builds of other keys there. The manifest, or None (said on `out`)."""
    folder = next((f for f in folders() if writable_folder(str(f))), None)
    if folder is None:
        print("evclust: no writable folder for the ahead-of-time build: runs load numba's cache", file=out)
        return None
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # pycc's pending-deprecation notice
            from numba.pycc import CC
    except ImportError as error:
        print(f"evclust: numba.pycc is not available ({error}): runs load numba's cache", file=out)
        return None
    key = source_key()
    if _key_now() != key:  # the compiled code came from the sources as imported
        print("evclust: the package's sources changed since they were imported: nothing built; build again", file=out)
        return None
    module_path, manifest_path = _files(folder, key)
    entries = []
    with tempfile.TemporaryDirectory(dir=folder, prefix=".build-") as scratch:
        cc = CC(PREFIX + key)
        cc.output_dir = scratch
        cc.target_cpu = "host"
        for function in functions:
            dispatcher = getattr(function, "dispatcher", function)
            py_func = dispatcher.py_func
            for number, signature in enumerate(dispatcher.nopython_signatures):
                export = f"{py_func.__module__}.{py_func.__qualname__}".replace(".", "_") + f"__{number}"
                kinds = tuple(kind_of_type(t) for t in signature.args)
                cc.export(export, signature)(py_func)
                entries.append({"module": py_func.__module__, "qualname": py_func.__qualname__, "export": export, "kinds": kinds})
        if not entries:
            print("evclust: nothing to build ahead of time: the functions were never called", file=out)
            return None
        try:
            cc.compile()
        except Exception as error:  # no C compiler, no Python headers, ...
            print(f"evclust: the ahead-of-time build failed ({type(error).__name__}: {error}): runs load numba's cache", file=out)
            return None
        built = next(Path(scratch).glob(PREFIX + key + "*"))
        os.replace(built, module_path)
    staged = manifest_path.with_suffix(".manifest.tmp")
    staged.write_bytes(pickle.dumps({"exports": entries}))  # the key is in the file's name
    os.replace(staged, manifest_path)  # last: a manifest means its module is whole
    for stale in folder.glob(PREFIX + "*"):
        if not stale.name.startswith(PREFIX + key):
            stale.unlink(missing_ok=True)
    loaded.cache_clear()
    return manifest_path
