#!/usr/bin/env python
"""Event files: reading speed per format and library, and peak memory of a 50-million-event track.

    make bench        # ... .venv/bin/python bench/event_io.py --write docs/BENCHMARKS.md

1. Reading. One stream of camera-like DVS events (640x480, 20 M events over 20 s, ties in
   (t, y, x) order) is written once per format by evclust, then read back:
   - by evclust's EventReader (chunks of 2^20 events, every chunk validated: the path `evclust
     track` takes), and by `read_events` (the same, joined into one array);
   - by each library alone, decoding to its own arrays (no validation): faery, dv-processing,
     aedat, evlib. These are the candidates compared in docs/DESIGN.md ("Event-camera files").
   Each figure is the best of --repeat runs, in Mevents/s.
2. Memory. `evclust track` runs in a child process on 50 M events (the built-in `traffic`
   scene's events, tiled in time until there are 50 M) stored as AEDAT4, EVT3 and HDF5, writing
   Parquet; the child's peak resident memory (getrusage) is reported with its wall time.
"""

from __future__ import annotations

import common  # first: pins every thread pool to one core

import argparse
import datetime
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from evclust.events import EVENT_DTYPE, EventMeta, EventReader, event_writer, read_events, sort_events

ROOT = Path(__file__).resolve().parents[1]
WORK = ROOT / "build" / "bench" / "event_io"
START, END = "<!-- bench:event_io:start -->", "<!-- bench:event_io:end -->"
W, H, N_READ, N_TRACK = 640, 480, 20_000_000, 50_000_000
TARGET_READ_MEV, TARGET_PEAK_GB = 20.0, 1.5
FORMATS = {"aedat4": ".aedat4", "evt3": ".raw", "evt2": "_evt2.raw", "hdf5": ".h5", "npz": ".npz"}


def camera_stream(n: int, seed: int = 0, chunk: int = 1 << 21):
    """Chunks of a sorted DVS stream: 20 M events over 20 s, like a busy VGA camera."""
    rng = np.random.default_rng(seed)
    t_per_chunk = 1_000_000 * chunk // N_READ
    for k, lo in enumerate(range(0, n, chunk)):
        m = min(chunk, n - lo)
        ev = np.zeros(m, EVENT_DTYPE)
        ev["t"] = k * t_per_chunk + np.sort(rng.integers(0, t_per_chunk, m)).astype(np.uint64)
        ev["x"] = rng.integers(0, W, m)
        ev["y"] = rng.integers(0, H, m)
        ev["p"] = rng.choice(np.array([-1, 1], np.int8), m)
        yield sort_events(ev)


def write_all(n: int) -> dict[str, Path]:
    WORK.mkdir(parents=True, exist_ok=True)
    meta = EventMeta(width=W, height=H, source="bench_camera", t_frame_us=33333.0, has_colour=False)
    paths = {}
    for name, suffix in FORMATS.items():
        path = WORK / f"camera_{n // 1_000_000}M{suffix}"
        if not path.exists():
            with event_writer(path, meta, evt_version="evt2" if name == "evt2" else "evt3") as writer:
                for ev in camera_stream(n):
                    writer.write(ev)
        paths[name] = path
    return paths


def best_of(repeat: int, fn) -> tuple[float, int]:
    best, count = float("inf"), 0
    for _ in range(repeat):
        start = time.perf_counter()
        count = fn()
        best = min(best, time.perf_counter() - start)
    return best, count


def evclust_chunks(path):
    return lambda: sum(c.size for c in EventReader(path).chunks())


def evclust_whole(path):
    return lambda: read_events(path)[0].size


def faery_decode(path):
    import faery

    return lambda: sum(p.size for p in faery.events_stream_from_file(path))


def dv_decode(path):
    import dv_processing as dv

    def run():
        recording, n = dv.io.MonoCameraRecording(str(path)), 0
        while (batch := recording.getNextEventBatch()) is not None:
            n += batch.numpy().size
        return n

    return run


def aedat_decode(path):
    import aedat

    return lambda: sum(p["events"].size for p in aedat.Decoder(str(path)) if "events" in p)


def evlib_decode(path):
    import evlib

    return lambda: len(evlib.load_events(str(path), sort=False).collect())


LIBRARIES = {
    "faery": (faery_decode, ("aedat4", "evt3", "evt2")),
    "dv-processing": (dv_decode, ("aedat4",)),
    "aedat": (aedat_decode, ("aedat4",)),
    "evlib": (evlib_decode, ("aedat4", "evt3", "evt2", "hdf5")),
}


def reading(paths: dict[str, Path], repeat: int) -> list[str]:
    rows = ["| format | file size, B/event | evclust, chunks validated | evclust, one array | " + " | ".join(LIBRARIES) + " |",
            "|---|---:|---:|---:|" + "---:|" * len(LIBRARIES)]  # fmt: skip
    for name, path in paths.items():
        size = path.stat().st_size / N_READ
        cells = []
        for fn in (evclust_chunks, evclust_whole):
            wall, count = best_of(repeat, fn(path))
            assert count == N_READ, (name, count)
            cells.append(f"{N_READ / wall / 1e6:.1f}")
        for make, formats in LIBRARIES.values():
            if name not in formats:
                cells.append("–")
                continue
            try:
                wall, count = best_of(repeat, make(path))
                cells.append(f"{N_READ / wall / 1e6:.1f}" + ("" if count == N_READ else f" ({count} events!)"))
            except Exception as exc:  # a library that cannot read the file: say so in the table
                cells.append(f"fails: {str(exc).splitlines()[0][:40]}")
        rows.append(f"| {name} | {size:.2f} | " + " | ".join(cells) + " |")
        print(rows[-1], flush=True)
    return rows


def tiled_traffic(n: int):
    """The `traffic` scene's events, repeated in time (each copy after the last) until n events."""
    from evclust.simulator import simulate_scene
    from evclust.scenes import load_scene

    sim = simulate_scene(load_scene("traffic"))
    base = sim.events
    span = int(base["t"][-1]) + int(sim.meta.t_frame_us)
    done, copy = 0, 0
    while done < n:
        ev = base[: n - done].copy()
        ev["t"] += np.uint64(copy * span)
        yield ev, sim.meta
        done += ev.size
        copy += 1


def memory(repeat_formats=("aedat4", "evt3", "hdf5")) -> list[str]:
    paths = {}
    for name in repeat_formats:
        path = WORK / f"traffic_{N_TRACK // 1_000_000}M{FORMATS[name]}"
        paths[name] = path
        if path.exists():
            continue
        writer_cm = None
        for ev, meta in tiled_traffic(N_TRACK):
            if writer_cm is None:
                writer_cm = event_writer(path, meta, evt_version="evt3")
                writer = writer_cm.__enter__()
            writer.write(ev)
        writer_cm.__exit__(None, None, None)
    rows = ["| input | events | wall time | peak memory (max RSS) | track records | output size |", "|---|---:|---:|---:|---:|---:|"]
    for name, path in paths.items():
        out = WORK / f"traffic_{name}.parquet"
        cmd = [
            str(ROOT / ".venv" / "bin" / "evclust"),
            "track",
            str(path),
            "-o",
            str(out),
            "--params",
            "traffic",
            "--frame-us",
            "50000",
            "-q",
        ]
        # A fresh wrapper process per run: RUSAGE_CHILDREN is then the peak of this one child.
        wrapper = (
            "import resource, subprocess, sys; done = subprocess.run(sys.argv[1:]); "
            "print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss, file=sys.stderr); sys.exit(done.returncode)"
        )
        start = time.perf_counter()
        done = subprocess.run([sys.executable, "-c", wrapper, *cmd], capture_output=True, text=True)
        wall = time.perf_counter() - start
        if done.returncode != 0:
            raise SystemExit(f"{' '.join(cmd)} failed: {done.stderr.strip()}")
        peak_kb = int(done.stderr.strip().splitlines()[-1])
        records = done.stdout.split(" track records")[0].rsplit(" ", 1)[-1]
        rows.append(
            f"| {name} ({path.stat().st_size / 2**30:.2f} GiB) | {N_TRACK:,} | {wall:.1f} s | {peak_kb / 2**20:.2f} GiB | {records} | {out.stat().st_size / 2**20:.1f} MiB |"
        )
        print(rows[-1], flush=True)
    return rows


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--write", metavar="MD", help="rewrite this file's event_io section")
    parser.add_argument("--skip-memory", action="store_true")
    args = parser.parse_args()
    read_rows = reading(write_all(N_READ), args.repeat)
    mem_rows = [] if args.skip_memory else memory()
    section = "\n".join(
        [
            START,
            "## Event files: reading speed and memory",
            "",
            f"Measured {datetime.date.today()} by `.venv/bin/python bench/event_io.py --write docs/BENCHMARKS.md` "
            f"(part of `make bench`), one core:",
            *common.machine(),
            "",
            f"Reading {N_READ // 1_000_000} M camera-like DVS events ({W}×{H}, 20 s), Mevents/s, best of {args.repeat} "
            f"(target: evclust ≥ {TARGET_READ_MEV:g} Mevents/s). The library columns decode to their own arrays "
            "without evclust's checks; they are the candidates of docs/DESIGN.md.",
            "",
            *read_rows,
            "",
            *(
                [
                    f"Peak memory of `evclust track FILE -o out.parquet --params traffic` on {N_TRACK // 1_000_000} M events "
                    f"(the `traffic` scene tiled in time), in a child process (target ≤ {TARGET_PEAK_GB:g} GB):",
                    "",
                    *mem_rows,
                    "",
                ]
                if mem_rows
                else []
            ),
            END,
        ]
    )
    print(section)
    if args.write:
        common.write_section(Path(args.write), section, START, END)
    return 0


if __name__ == "__main__":
    sys.exit(main())
