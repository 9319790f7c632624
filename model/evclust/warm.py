"""Compile the package's compiled loops into numba's disk cache before the runs that need them,
and build what `track` calls ahead of time.

`python -m evclust.warm` (`make warm`, which `make test` runs first). A first run of a model
compiles its loop for 45 to 75 s, and numba writes the cache only when it is done; a run started
meanwhile compiles the same loop again. Here each loop is compiled once, the jobs spread over the
cores, on a small made-up stream (what is compiled depends on the argument types, not on the
events), so the tests' durations are their own. Measured in a fresh clone (docs/RTL.md), it did
not shorten `make test`: the first test to need each loop had paid for it, not two at once.

One job also builds `track`'s entry points ahead of time (evclust.jit.ahead), after calling them
as `track` does: a default run of the float model, and a read of each event-camera format. Then a
`track` with the defaults loads them without numba. `python -m evclust.warm --ahead` runs that
job alone (`make demo-real`).
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor, as_completed

import numpy as np

WIDTH, HEIGHT, EVENTS = 96, 72, 4_000


def sample_stream():
    """A blob drifting right: events that create clusters, reach filter steps and give records."""
    from evclust.events import EVENT_DTYPE, EventMeta

    rng = np.random.default_rng(0)
    events = np.zeros(EVENTS, EVENT_DTYPE)
    events["t"] = np.arange(EVENTS, dtype=np.uint64) * 50
    events["x"] = np.clip(20 + events["t"] / 5_000 + rng.normal(0, 2, EVENTS), 0, WIDTH - 1).astype(np.uint16)
    events["y"] = np.clip(36 + rng.normal(0, 2, EVENTS), 0, HEIGHT - 1).astype(np.uint16)
    events["p"] = 1
    events["Y"], events["Cb"], events["Cr"] = 120, 90, 200
    return events, EventMeta(WIDTH, HEIGHT, "warm", t_frame_us=33_333.0)


def _track(model: str, **options) -> None:
    from evclust.clusterer import load_params
    from evclust.run import track_events

    events, meta = sample_stream()
    params, _ = load_params(None, meta.source)
    track_events(events, meta, params, model=model, **options)


# What `track` calls from Python with the defaults (the float model, its object layer, and the
# conversion of every event-camera format's packets); tests/run/test_ahead.py checks that a
# default `track` of a camera file needs nothing else compiled.
TRACK_ENTRY_POINTS = (
    "evclust.clusterer.float_model:run_events",
    "evclust.clusterer.objects:run_steps",
    "evclust.events.camera:_convert",
)
CAMERA_FILES = ("sample.aedat4", "sample.raw", "sample.dat", "sample.es")


def _track_ahead() -> None:
    """Call `track`'s entry points as `track` does, under numba (an earlier build would serve them
    otherwise, and numba would make nothing to build from), then build them ahead of time unless
    the build for these sources is there already."""
    from evclust.events.io import read_events, write_events
    from evclust.jit import ahead

    os.environ[ahead.DISABLE] = "0"  # this worker process's (its other jobs compile under numba anyway)
    _track("float")
    events, meta = sample_stream()
    with tempfile.TemporaryDirectory() as folder:
        for name in CAMERA_FILES:
            write_events(os.path.join(folder, name), events, meta)
            read_events(os.path.join(folder, name))
    if ahead.location() is not None:
        return
    functions = [getattr(importlib.import_module(module), name) for module, name in (e.split(":") for e in TRACK_ENTRY_POINTS)]
    ahead.build(functions)  # where it cannot build, it says why in one line, and runs load numba's cache


def _emulate() -> None:
    from evclust.clusterer import load_params
    from evclust.fixed.formats import build_formats
    from evclust.report.budget import emulate

    events, meta = sample_stream()
    params, _ = load_params(None, meta.source)
    table = build_formats(params, meta.width, meta.height, params.t_frame_us or meta.t_frame_us)
    emulate(events, meta, params, table, ("centre",))


def _traced() -> None:
    from evclust.clusterer import load_params
    from evclust.fixed.model import FixedClusterer
    from evclust.vectors.write import model_words

    events, meta = sample_stream()
    params, _ = load_params(None, meta.source)
    model_words(FixedClusterer(params, meta.width, meta.height, meta.t_frame_us), events)


def _simulator() -> None:
    from evclust.scenes import load_scene
    from evclust.simulator import simulate_scene

    simulate_scene(load_scene("slow"))


AHEAD_JOB = "float model, and track's entry points ahead of time"
# Longest first, so that two cores finish together.
JOBS = {
    AHEAD_JOB: _track_ahead,
    "fixed model": lambda: _track("fixed"),
    "fixed model, traced or range-instrumented (vectors, co-simulation, report)": _traced,
    "float model, emulating formats (report)": _emulate,
    "simulator": _simulator,
}


def _run(name: str) -> tuple[str, float]:
    start = time.perf_counter()
    JOBS[name]()
    return name, time.perf_counter() - start


def warm(workers: int | None = None, out=sys.stderr, jobs=tuple(JOBS)) -> float:
    """Run `jobs` (default: all), `workers` at a time (default: one per core); the wall time."""
    start = time.perf_counter()
    with ProcessPoolExecutor(max_workers=workers or os.cpu_count() or 1) as pool:
        for done in as_completed([pool.submit(_run, name) for name in jobs]):
            name, seconds = done.result()
            print(f"warm: {name}: {seconds:.1f} s", file=out, flush=True)
    return time.perf_counter() - start


if __name__ == "__main__":
    parser = argparse.ArgumentParser(prog="python -m evclust.warm", description=__doc__.split("\n\n")[0])
    parser.add_argument("--ahead", action="store_true", help="only build track's entry points ahead of time")
    jobs = [AHEAD_JOB] if parser.parse_args().ahead else tuple(JOBS)
    print(f"warm: compiled code ready in {warm(jobs=jobs):.1f} s", file=sys.stderr)
