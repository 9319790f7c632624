"""Compiled code made when first needed, and `track`'s entry points built ahead of time
(evclust.jit, evclust.jit.ahead; issue 26: `track` on a short recording within a second)."""

from __future__ import annotations

import collections
import os
import pickle
import subprocess
import sys

import numba
import numpy as np
import pytest

from evclust.events.io import write_events
from evclust.jit import argument_kinds, named_record
from evclust.jit import ahead
from evclust.warm import sample_stream

# Runs a command of the CLI, then says whether numba was imported.
CLI = "import sys; from evclust.cli import main; code = main(); print('numba imported:', 'numba' in sys.modules); sys.exit(code)"


def run_cli(argv, cwd, **env) -> subprocess.CompletedProcess:
    run = subprocess.run([sys.executable, "-c", CLI, *argv], cwd=cwd, env={**os.environ, **env}, capture_output=True,
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


def test_argument_kinds_name_what_numba_types_a_call_by():
    """The words a build records for each export (from numba's types) are the ones a call's
    arguments give (from the values): numba's own typeof is the referee."""
    grid = np.zeros((4, 6))
    table = np.zeros(5, [("t", "<u8"), ("x", "<u2"), ("on", "?")])  # packed: 11-byte records
    frozen = np.arange(3.0)
    frozen.flags.writeable = False
    Pair = collections.namedtuple("Pair", "a b")
    values = [
        grid, np.asfortranarray(grid), grid[:, 1], grid[::2], frozen, table["t"], table["on"], np.zeros(3, bool),
        named_record(np.dtype([("r", "f8"), ("n", "f8")]), {"r": 1.0, "n": 2.0}),
        Pair(1.0, 2.0), (3, 2.5), None, True, 7, 2.5, np.float32(1.5), np.int64(2), np.uint16(3),
    ]  # fmt: skip
    for value in values:
        assert ahead._kind_of_type(numba.typeof(value)) == argument_kinds((value,))[0], value
    # Different types, different kinds: the layouts, writability and scalar widths numba tells
    # apart. (A Python int and np.int64 are the same to numba, and here.)
    kinds = [repr(argument_kinds((value,))[0]) for value in values]
    assert kinds.count(repr(argument_kinds((7,))[0])) == 2 and len(set(kinds)) == len(kinds) - 1


def test_a_default_track_runs_ahead_of_time_without_numba_and_writes_what_numba_writes(fresh_build, tmp_path):
    events, meta = sample_stream()
    write_events(tmp_path / "camera.aedat4", events, meta)  # faery's packets: the camera formats' conversion
    run_cli(["simulate", "crossing", "-o", "crossing.npz"], tmp_path)  # colour events
    for source in ("camera.aedat4", "crossing.npz"):
        built = run_cli(["track", source, "-o", f"{source}.ahead.csv"], tmp_path)
        assert "numba imported: False" in built.stdout
        assert "built ahead of time" in built.stdout and "numba's cache" not in built.stdout
        jit = run_cli(["track", source, "-o", f"{source}.numba.csv"], tmp_path, EVCLUST_AHEAD="0")
        assert "numba imported: True" in jit.stdout and "built ahead of time" not in jit.stdout
        ahead_csv, numba_csv = (tmp_path / f"{source}.{how}.csv" for how in ("ahead", "numba"))
        assert len(ahead_csv.read_text().splitlines()) > 2  # a header and records
        assert ahead_csv.read_bytes() == numba_csv.read_bytes()


def test_a_call_the_build_does_not_cover_runs_under_numba(fresh_build, tmp_path):
    """The fixed model has no export: the same command loads numba and compiles or loads it."""
    events, meta = sample_stream()
    write_events(tmp_path / "camera.aedat4", events, meta)
    run = run_cli(["track", "camera.aedat4", "-o", "fixed.csv", "--model", "fixed"], tmp_path)
    assert "numba imported: True" in run.stdout
    assert (tmp_path / "fixed.csv").stat().st_size > 0


def test_a_stale_or_broken_build_is_ignored(monkeypatch, tmp_path):
    monkeypatch.setattr(ahead, "folders", lambda: [tmp_path])
    module, manifest = ahead._files(tmp_path, "somekey")
    manifest.write_bytes(pickle.dumps({"key": "somekey", "exports": []}))
    try:
        ahead.loaded.cache_clear()
        monkeypatch.setattr(ahead, "source_key", lambda: "otherkey")  # the sources changed since
        assert ahead.loaded() == {} and ahead.location() is None
        ahead.loaded.cache_clear()
        monkeypatch.setattr(ahead, "source_key", lambda: "somekey")  # the manifest, but no module beside it
        assert not module.exists() and ahead.loaded() == {}
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
    run = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env={**os.environ, "EVCLUST_AHEAD": "0"},
                         capture_output=True, text=True, timeout=600)  # fmt: skip
    assert run.returncode == 0, run.stderr
    ufunc, clipped = run.stdout.splitlines()
    assert clipped == "[-4, 2, 4] 5"
    # The TDC's read-back of full scale is full scale (evclust.simulator.effects.tdc's docstring).
    assert float(ufunc.strip("[]").split()[0]) == pytest.approx(255.0, rel=0.02)
