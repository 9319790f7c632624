#!/usr/bin/env python
"""Real recordings (evclust.events.recordings, `make recordings`): how fast each is read, and
where `evclust track`'s wall time goes on each, warm: with the entry points built ahead of time
(`python -m evclust.warm --ahead`, run first) and with numba's cache (EVCLUST_AHEAD=0).

    make bench        # ... .venv/bin/python bench/recordings.py --write docs/BENCHMARKS.md

1. Reading: evclust's EventReader over the whole file (its chunks validated: the path `track`
   takes), best of --repeat, in Mevents/s.
2. Tracking: `evclust track FILE -o tracks.parquet` in a child process, the defaults, no
   --frame-us (a camera's stream: the frameless period), after one untimed run. The command's
   own wall time (process start to exit, median of --repeat), beside what it reports of itself:
   compiled code made ready, the event loop, and the rest (imports, opening and writing files).
   Both ways in turn, round by round: the build ahead of time, then numba's cache.
"""

from __future__ import annotations

import common  # first: pins every thread pool to one core

import argparse
import datetime
import os
import re
import statistics
import subprocess
import sys
import time
from pathlib import Path

from evclust.events import EventReader
from evclust.events.recordings import RECORDINGS, require

ROOT = Path(__file__).resolve().parents[1]
WORK = ROOT / "build" / "bench" / "recordings"
EVCLUST = ROOT / ".venv" / "bin" / "evclust"
START, END = "<!-- bench:recordings:start -->", "<!-- bench:recordings:end -->"
TARGET = ("davis346", 1.0)  # issue 26: `track` on the 2.4 s DAVIS346 clip, warm, at most 1 s wall
TIME_LINE = re.compile(r"compiled code ([0-9.]+) s, event loop ([0-9.]+) s, the rest \(imports, opening and writing files\) ([0-9.]+) s")


def read_rate(recording, repeat: int) -> tuple[int, float]:
    best = float("inf")
    for _ in range(repeat):
        start = time.perf_counter()
        reader = EventReader(recording.path, recording.sensor_size)
        n = sum(chunk.size for chunk in reader.chunks())
        best = min(best, time.perf_counter() - start)
    return n, n / best / 1e6


def track_times(recording, repeat: int) -> dict[str, tuple[float, tuple[float, float, float]]]:
    """{"ahead" | "numba": (median wall, (compiled code, event loop, the rest) of that run)}."""
    size = ["--sensor-size", "x".join(map(str, recording.sensor_size))] if recording.sensor_size else []
    cmd = [str(EVCLUST), "track", str(recording.path), "-o", str(WORK / f"{recording.name}.parquet"), "-q", *size]
    ways = {"ahead": dict(os.environ), "numba": {**os.environ, "EVCLUST_AHEAD": "0"}}
    for env in ways.values():
        subprocess.run(cmd, check=True, capture_output=True, env=env)  # fills numba's cache, if it is not yet
    walls, parts = {way: [] for way in ways}, {way: [] for way in ways}
    for _ in range(repeat):
        for way, env in ways.items():
            start = time.perf_counter()
            out = subprocess.run(cmd, check=True, capture_output=True, text=True, env=env).stdout
            walls[way].append(time.perf_counter() - start)
            parts[way].append(tuple(float(v) for v in TIME_LINE.search(out).groups()))
    medians = {}
    for way in ways:
        i = walls[way].index(statistics.median_low(walls[way]))
        medians[way] = walls[way][i], parts[way][i]
    return medians


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--write", metavar="MD")
    args = parser.parse_args()
    WORK.mkdir(parents=True, exist_ok=True)
    subprocess.run([sys.executable, "-m", "evclust.warm", "--ahead"], check=True)  # the build for these sources
    machine = common.machine()
    rows = [
        "| recording | camera | format | events | read, Mevents/s | `track` wall (median) | compiled code | event loop "
        "| event loop, Mevents/s | the rest | `track` wall, numba's cache | compiled code, numba's cache |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    verdict = ""
    for r in RECORDINGS:
        recording = require(r.name)
        n, rate = read_rate(recording, args.repeat)
        times = track_times(recording, args.repeat)
        wall, (ready, loop, rest) = times["ahead"]
        numba_wall, (numba_ready, _, _) = times["numba"]
        rows.append(f"| {r.name} | {r.camera} | {r.format} | {n:,} | {rate:.1f} | {wall:.2f} s | {ready:.2f} s | {loop:.2f} s "
                    f"| {n / loop / 1e6 if loop else float('inf'):.1f} | {rest:.2f} s | {numba_wall:.2f} s | {numba_ready:.2f} s |")  # fmt: skip
        if r.name == TARGET[0]:
            verdict = f"target: `track` on {r.name}, warm, ≤ {TARGET[1]:g} s wall: {wall:.2f} s, {'PASS' if wall <= TARGET[1] else 'FAIL'}"
        print(rows[-1], flush=True)
    section = "\n".join([
        START, "## Real recordings: reading and tracking", "",
        f"Measured {datetime.date.today()} by `.venv/bin/python bench/recordings.py --write docs/BENCHMARKS.md` (part of "
        "`make bench`; the files from `make recordings`). Reading: evclust's EventReader, every chunk validated, best of "
        f"{args.repeat}. `track`: the whole command in a child process, defaults, no `--frame-us`, warm (an untimed run "
        f"first), median of {args.repeat}; its own time line splits it into the compiled code made ready, the event loop "
        "(reading included) and the rest (imports, opening and writing files). First with `track`'s entry points built "
        "ahead of time (`python -m evclust.warm --ahead`: no numba imported), then, alternating round by round, with "
        "numba's disk cache (`EVCLUST_AHEAD=0`: numba imported and the loops loaded).", "",
        *machine, "", *rows, "", verdict, "", END,
    ])  # fmt: skip
    print(section)
    if args.write:
        from evclust.stamps import stamp_for

        common.write_section(Path(args.write), section, START, END, stamp=stamp_for("BENCHMARKS:recordings"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
