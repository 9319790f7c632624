#!/usr/bin/env python
"""Real recordings (evclust.events.recordings, `make recordings`): how fast each is read, and
where `evclust track`'s wall time goes on each, warm (numba's cache filled by a first run).

    make bench        # ... .venv/bin/python bench/recordings.py --write docs/BENCHMARKS.md

1. Reading: evclust's EventReader over the whole file (its chunks validated: the path `track`
   takes), best of --repeat, in Mevents/s.
2. Tracking: `evclust track FILE -o tracks.parquet` in a child process, the defaults, no
   --frame-us (a camera's stream: the frameless period), after one untimed run. The command's
   own wall time (process start to exit, median of --repeat), beside what it reports of itself:
   compiled code made ready, the event loop, and the rest (imports, opening and writing files).
"""

from __future__ import annotations

import common  # first: pins every thread pool to one core

import argparse
import datetime
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


def track_times(recording, repeat: int) -> tuple[float, tuple[float, float, float]]:
    size = ["--sensor-size", "x".join(map(str, recording.sensor_size))] if recording.sensor_size else []
    cmd = [str(EVCLUST), "track", str(recording.path), "-o", str(WORK / f"{recording.name}.parquet"), "-q", *size]
    subprocess.run(cmd, check=True, capture_output=True)  # fills numba's cache, if it is not yet
    walls, parts = [], []
    for _ in range(repeat):
        start = time.perf_counter()
        out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
        walls.append(time.perf_counter() - start)
        parts.append(tuple(float(v) for v in TIME_LINE.search(out).groups()))
    i = walls.index(statistics.median_low(walls))
    return walls[i], parts[i]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--write", metavar="MD")
    args = parser.parse_args()
    WORK.mkdir(parents=True, exist_ok=True)
    machine = common.machine()
    rows = [
        "| recording | camera | format | events | read, Mevents/s | `track` wall (median) | compiled code | event loop | event loop, Mevents/s | the rest |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|---:|",
    ]
    verdict = ""
    for r in RECORDINGS:
        recording = require(r.name)
        n, rate = read_rate(recording, args.repeat)
        wall, (ready, loop, rest) = track_times(recording, args.repeat)
        rows.append(f"| {r.name} | {r.camera} | {r.format} | {n:,} | {rate:.1f} | {wall:.2f} s | {ready:.2f} s | {loop:.2f} s "
                    f"| {n / loop / 1e6 if loop else float('inf'):.1f} | {rest:.2f} s |")  # fmt: skip
        if r.name == TARGET[0]:
            verdict = f"target: `track` on {r.name}, warm, ≤ {TARGET[1]:g} s wall: {wall:.2f} s, {'PASS' if wall <= TARGET[1] else 'FAIL'}"
        print(rows[-1], flush=True)
    section = "\n".join([
        START, "## Real recordings: reading and tracking", "",
        f"Measured {datetime.date.today()} by `.venv/bin/python bench/recordings.py --write docs/BENCHMARKS.md` (part of "
        "`make bench`; the files from `make recordings`). Reading: evclust's EventReader, every chunk validated, best of "
        f"{args.repeat}. `track`: the whole command in a child process, defaults, no `--frame-us`, warm (an untimed run "
        f"first), median of {args.repeat}; its own time line splits it into the compiled code made ready (loaded from "
        "numba's cache), the event loop (reading included) and the rest (imports, opening and writing files).", "",
        *machine, "", *rows, "", verdict, "", END,
    ])  # fmt: skip
    print(section)
    if args.write:
        from evclust.stamps import stamp_for

        common.write_section(Path(args.write), section, START, END, stamp=stamp_for("BENCHMARKS:recordings"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
