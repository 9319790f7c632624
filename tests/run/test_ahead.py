"""Compiled code made when first needed, and `track`'s entry points built ahead of time
(evclust.jit, evclust.jit.ahead; issue 26: `track` on a short recording within a second)."""

from __future__ import annotations

import collections
import itertools
import os
import pickle
import subprocess
import sys

import numba
import numpy as np
import pytest

from evclust.events.io import write_events
from evclust.jit import ahead, named_record
from evclust.jit.ahead import argument_kinds
from evclust.warm import sample_stream

# Runs a command of the CLI, then says whether numba was imported.
CLI = "import sys; from evclust.cli import main; code = main(); print('numba imported:', 'numba' in sys.modules); sys.exit(code)"


def run_python(code: str, cwd, argv=(), **env) -> subprocess.CompletedProcess:
    run = subprocess.run([sys.executable, "-c", code, *argv], cwd=cwd, env={**os.environ, **env}, capture_output=True,
                         text=True, timeout=900)  # fmt: skip
    assert run.returncode == 0, run.stderr
    return run


@pytest.fixture(scope="module")
def fresh_build():
    """The build for these sources: `make warm` made it; made here when it is missing."""
    if ahead.location() is None:
        subprocess.run([sys.executable, "-m", "evclust.warm", "--ahead"], check=True, timeout=900)
        ahead.loaded.cache_clear()
    assert ahead.location() is not None
    return ahead.location()


def test_two_arguments_are_of_one_kind_exactly_when_numba_gives_them_one_type():
    """The words a build records for each export (from numba's types) are the ones a call's
    arguments give (from the values), and they tell apart what numba's typeof tells apart: numba
    is the referee, pair by pair."""
    grid = np.zeros((4, 6))
    table = np.zeros(5, [("t", "<u8"), ("x", "<u2"), ("on", "?")])  # packed: 11-byte records
    frozen = np.arange(3.0)
    frozen.flags.writeable = False
    Pair = collections.namedtuple("Pair", "a b")
    Swapped = collections.namedtuple("Pair", "b a")  # the same name, other fields
    values = [
        grid, np.asfortranarray(grid), grid[:, 1], grid[::2], frozen, table["t"], table["on"], np.zeros(3, bool),
        np.array(2.0), np.zeros((1, 3)), np.zeros((3, 1)), np.zeros(3, np.float32),
        named_record(np.dtype([("r", "f8"), ("n", "f8")]), {"r": 1.0, "n": 2.0}),
        named_record(np.dtype([("n", "f8"), ("r", "f8")]), {"r": 1.0, "n": 2.0}),
        Pair(1.0, 2.0), Swapped(1.0, 2.0), (3, 2.5), None, True, 7, 2.5, np.float32(1.5), np.int64(2), np.uint16(3),
    ]  # fmt: skip
    types = [numba.typeof(value) for value in values]
    for value, numba_type in zip(values, types):
        assert ahead.kind_of_type(numba_type) == argument_kinds((value,))[0], value
    for (a, type_a), (b, type_b) in itertools.combinations(zip(values, types), 2):
        assert (argument_kinds((a,)) == argument_kinds((b,))) == (type_a == type_b), (a, b)
    # What numba refuses is never of a built kind: a masked array (its data alone would ignore
    # the mask) and a byte-swapped array.
    for refused in (np.ma.masked_array(np.zeros(3), mask=[0, 1, 0]), np.zeros(3, ">f8")):
        with pytest.raises((ValueError, TypeError, numba.core.errors.NumbaError)):
            numba.typeof(refused)
        assert all(argument_kinds((refused,))[0] != ahead.kind_of_type(t) for t in types)


def test_a_default_track_runs_ahead_of_time_without_numba_and_writes_what_numba_writes(fresh_build, tmp_path):
    events, meta = sample_stream()
    write_events(tmp_path / "camera.aedat4", events, meta)  # faery's packets: the camera formats' conversion
    run_python(CLI, tmp_path, ["simulate", "crossing", "-o", "crossing.npz"])  # colour events
    for source in ("camera.aedat4", "crossing.npz"):
        built = run_python(CLI, tmp_path, ["track", source, "-o", f"{source}.ahead.csv"])
        assert "numba imported: False" in built.stdout
        assert "built ahead of time" in built.stdout and "numba's cache" not in built.stdout
        jit = run_python(CLI, tmp_path, ["track", source, "-o", f"{source}.numba.csv"], EVCLUST_AHEAD="0")
        assert "numba imported: True" in jit.stdout and "built ahead of time" not in jit.stdout
        ahead_csv, numba_csv = (tmp_path / f"{source}.{how}.csv" for how in ("ahead", "numba"))
        assert len(ahead_csv.read_text().splitlines()) > 2  # a header and records
        assert ahead_csv.read_bytes() == numba_csv.read_bytes()


# The float loop fed as `track` feeds it, then emulating the fixed model's formats (a precision
# table where `track` passes None, as the report does): whether each ran its export, whether numba
# was imported by then, and the records.
EXPORTED_LOOP_OF_TWO_KINDS = """
import sys
import numpy as np
from evclust.clusterer import float_model, load_params
from evclust.clusterer.run import FloatClusterer
from evclust.fixed.formats import build_formats, precision_table
from evclust.warm import sample_stream
events, meta = sample_stream()
params, _ = load_params(None, meta.source)
rows = FloatClusterer(params, meta.width, meta.height, meta.t_frame_us).feed(events)
loop = float_model.run_events
print("as track:", "numba" in sys.modules, getattr(loop, "ran_ahead", False), len(rows), rows.sum())
table = build_formats(params, meta.width, meta.height, meta.t_frame_us)
precision = precision_table(table, ("centre",))
rows = FloatClusterer(params, meta.width, meta.height, meta.t_frame_us, precision=precision).feed(events)
print("emulating:", "numba" in sys.modules, len(rows), rows.sum())
"""


def test_a_call_of_other_kinds_runs_under_numba_with_numbas_result(fresh_build, tmp_path):
    """The float loop has an export for the kinds `track` passes; other kinds of the same loop go
    to numba, and give what they give in a process that never saw the build."""
    built = run_python(EXPORTED_LOOP_OF_TWO_KINDS, tmp_path).stdout.splitlines()
    numba_only = run_python(EXPORTED_LOOP_OF_TWO_KINDS, tmp_path, EVCLUST_AHEAD="0").stdout.splitlines()
    as_track, emulating = built
    assert as_track.startswith("as track: False True ") and int(as_track.split()[-2]) > 0
    assert emulating.startswith("emulating: True ")
    assert numba_only[0].split()[-2:] == as_track.split()[-2:]  # the records, both ways
    assert numba_only[1] == emulating


def test_a_call_the_build_does_not_cover_runs_under_numba(fresh_build, tmp_path):
    """The fixed model has no export: the same command loads numba and compiles or loads it."""
    events, meta = sample_stream()
    write_events(tmp_path / "camera.aedat4", events, meta)
    run = run_python(CLI, tmp_path, ["track", "camera.aedat4", "-o", "fixed.csv", "--model", "fixed"])
    assert "numba imported: True" in run.stdout
    assert len((tmp_path / "fixed.csv").read_text().splitlines()) > 2


def test_a_stale_or_broken_build_is_ignored(monkeypatch, tmp_path):
    monkeypatch.setattr(ahead, "folders", lambda: [tmp_path])
    module, manifest = ahead._files(tmp_path, "somekey")
    export = {"module": "evclust.clusterer.float_model", "qualname": "run_events", "export": "run_events__0", "kinds": ()}
    manifest.write_bytes(pickle.dumps({"exports": [export]}))
    try:
        ahead.loaded.cache_clear()
        monkeypatch.setattr(ahead, "source_key", lambda: "otherkey")  # the sources changed since
        assert ahead.loaded() == {} and ahead.location() is None
        ahead.loaded.cache_clear()
        monkeypatch.setattr(ahead, "source_key", lambda: "somekey")  # the manifest, but no module beside it
        assert not module.exists() and ahead.loaded() == {} and ahead.location() is None
        ahead.loaded.cache_clear()
        module.write_bytes(b"not an extension module")  # a module that does not load
        assert ahead.loaded() == {}
    finally:
        ahead.loaded.cache_clear()


def test_numba_is_imported_when_a_function_first_runs_under_it(tmp_path):
    """Importing every model compiles nothing and imports no numba; the first call does both, and
    from then on the modules hold numba's dispatchers, which a caller compiled elsewhere calls too."""
    code = """
import sys
import numpy as np
import evclust.cli, evclust.run, evclust.fixed.model, evclust.simulator, evclust.simulator.effects.tdc as tdc
from evclust.fixed import arith
assert "numba" not in sys.modules
saturate = arith.saturate_nb  # held outside the package's modules
assert type(saturate).__name__ == "Compiled"
print(tdc.tdc_read(np.array([255.0, 64.0]), 100.0, 10000.0, 8))  # a ufunc calling another
assert "numba" in sys.modules and type(arith.saturate_nb).__name__ == "CPUDispatcher"
import numba
@numba.njit
def clip_all(values):
    return [saturate(v, -4, 4) for v in values]
print(clip_all(np.array([-9, 2, 9])), saturate(12, 0, 5))
"""
    ufunc, clipped = run_python(code, tmp_path, EVCLUST_AHEAD="0").stdout.splitlines()
    assert clipped == "[-4, 2, 4] 5"
    # The TDC's read-back of full scale is full scale (evclust.simulator.effects.tdc's docstring).
    assert float(ufunc.strip("[]").split()[0]) == pytest.approx(255.0, rel=0.02)


def test_threads_making_the_first_call_together_all_get_the_dispatcher(tmp_path):
    """The simulator's bands call the kernel from a thread pool: numba is made ready once, and
    every thread's call runs."""
    code = """
from concurrent.futures import ThreadPoolExecutor
from evclust.fixed import arith
import evclust.jit as jit
with ThreadPoolExecutor(8) as pool:
    print(sorted(pool.map(lambda v: int(arith.saturate_nb(v, 0, 5)), range(-4, 12))))
made = [c._dispatcher for c in jit._COMPILED]
# Every function made, and each once: a second making would leave a dispatcher no function holds.
print(all(d is not None for d in made) and all(any(d is m for m in made) for d in jit._DISPATCHERS))
"""
    values, once = run_python(code, tmp_path, EVCLUST_AHEAD="0").stdout.splitlines()
    assert values == str(sorted(min(max(v, 0), 5) for v in range(-4, 12)))
    assert once == "True"
