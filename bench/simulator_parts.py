#!/usr/bin/env python
"""Where one core's time goes when the simulator runs a folder of frames, part by part.

    .venv/bin/python bench/simulator_parts.py [FRAMES_DIR] [--fps 30] [--repeat 3]

By default the frames are the panning video's uncompressed BMPs that `make bench-peers` writes
(build/peers/frames/pan_disks/), the case where evclust's lead over the peers is smallest. Each
part is timed alone, in CPU seconds of this process (pinned to one core, every pool one thread),
the median of --repeat rounds after a warm-up:

- decode:      reading and decoding every frame (OpenCV), as `evclust simulate FOLDER` does;
- observe:     each frame's detector input, ln(Y + 1) (OpenCV's RGB->GRAY on float32, numpy's log);
- scan:        the detector kernel over every pixel of every interval with no pixel firing (an
               infinite threshold): what visiting the pixels costs, whatever the events;
- detect:      the kernel with the scene's thresholds (scan included), into a reused buffer;
- order:       each interval's events into time order, into memory already touched;
- first touch: writing the run's events into fresh memory, as the run's event arena does;
- whole run:   `simulate_scene`, for the sum of the parts to be checked against.

Decode, observe, scan and first touch do not depend on how fast events are made: their sum is a
floor under the whole run that only a change of the frames' format, the detector's arithmetic (the
events would change) or the machine's memory would lower (docs/DESIGN.md, "What is left on one
core"). Prints a table; writes nothing.
"""

from __future__ import annotations

import common  # noqa: F401  (first: pins every thread pool to one core)

import argparse
import mmap
import os
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from evclust.colour import RGB_TO_YCBCR
from evclust.events.format import EVENT_DTYPE
from evclust.scenes import load_scene
from evclust.simulator import make_simulator, simulate_scene
from evclust.simulator.kernel import EventBuffer, detect_interval

ROOT = Path(__file__).resolve().parents[1]
FRAMES = ROOT / "build" / "peers" / "frames" / "pan_disks"


def cpu_seconds(fn: Callable[[], object], repeat: int) -> float:
    """Median CPU time of fn over `repeat` rounds, after one round of warm-up."""
    fn()
    times = []
    for _ in range(repeat):
        start = time.process_time()
        fn()
        times.append(time.process_time() - start)
    return statistics.median(times)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("frames", nargs="?", type=Path, default=FRAMES)
    parser.add_argument("--fps", type=float, default=30.0)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args(argv)
    if not args.frames.is_dir():
        raise SystemExit(f"{args.frames}: no such folder of frames (`make bench-peers` writes {FRAMES})")
    os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[0]})

    scene = load_scene(str(args.frames), fps=args.fps)
    sim = make_simulator(scene)
    src = scene.source
    width, pixels = src.width, src.width * src.height
    frames = list(src.frames())

    def observed_frames() -> list[tuple[np.ndarray, np.ndarray]]:
        out = []
        for rgb in frames:
            level = np.empty(pixels, np.float32)
            out.append((level, sim._observe(rgb, level)))  # the simulator's own per-frame step
        return out

    def observe() -> None:
        level = np.empty(pixels, np.float32)  # one plane, as the run's freed planes are reused
        for rgb in frames:
            sim._observe(rgb, level)

    def decode() -> None:
        for _ in src.frames():  # each frame dropped as the run drops it
            pass

    observed = observed_frames()
    dt_us = src.t_sample_us
    buffer = EventBuffer(max(1 << 16, pixels))
    silent = np.array([np.inf])
    th_on, th_off, th_stride = sim.th_on, sim.th_off, sim.th_stride

    def detect(on: np.ndarray, off: np.ndarray, stride: int, kept: list[np.ndarray] | None = None) -> None:
        """The kernel over every interval into the one buffer; `kept` gets a copy of each
        interval's words (for `order`)."""
        ref = observed[0][0].astype(np.float64)
        for k in range(1, len(observed)):
            (l0, c0), (l1, c1) = observed[k - 1], observed[k]
            n, done = detect_interval(l0, l1, c0, c1, ref, on, off, stride, width, (k - 1) * dt_us, dt_us, 0, buffer.words, RGB_TO_YCBCR)
            if done != pixels:
                raise SystemExit("an interval overflowed the buffer: raise its capacity")
            if kept is not None:
                kept.append(buffer.words[: 2 * n].copy())

    intervals: list[np.ndarray] = []
    detect(th_on, th_off, th_stride, intervals)
    total = sum(w.size // 2 for w in intervals)
    ordered = np.empty(total, EVENT_DTYPE)

    def order() -> None:
        at = 0
        for k, words in enumerate(intervals):
            n = words.size // 2
            buffer.words[: 2 * n] = words
            buffer.time_ordered([(0, n)], k * dt_us, dt_us, ordered[at : at + n])
            at += n

    def first_touch() -> None:
        fresh = np.frombuffer(mmap.mmap(-1, total * EVENT_DTYPE.itemsize), np.uint64)
        fresh[:] = 1

    def whole() -> None:
        simulate_scene(load_scene(str(args.frames), fps=args.fps))

    parts = [
        ("decode", decode, f"{len(frames)} frames"),
        ("observe", observe, f"{len(frames)} frames"),
        ("scan", lambda: detect(silent, silent, 0), f"{pixels * (len(frames) - 1) / 1e6:.1f} M pixel-frames"),
        ("detect", lambda: detect(th_on, th_off, th_stride), f"{total / 1e6:.2f} M events"),
        ("order", order, f"{total / 1e6:.2f} M events"),
        ("first touch", first_touch, f"{total * EVENT_DTYPE.itemsize / 2**20:.0f} MiB"),
    ]
    print(f"{args.frames} ({src.width}x{src.height}, {len(frames)} frames, {total:,} events), one core, CPU time, median of {args.repeat}")
    print("| part | CPU ms | per unit | of |\n|---|---:|---:|---|")
    seconds = {}
    for name, fn, units in parts:
        seconds[name] = cpu_seconds(fn, args.repeat)
        per = seconds[name] / (pixels * (len(frames) - 1) if name == "scan" else total if name in ("detect", "order") else 1)
        unit = f"{per * 1e9:.1f} ns" if name in ("scan", "detect", "order") else ""
        print(f"| {name} | {seconds[name] * 1e3:.1f} | {unit} | {units} |", flush=True)
    run = cpu_seconds(whole, args.repeat)
    parts_sum = sum(seconds[p] for p in ("decode", "observe", "detect", "order", "first touch"))
    floor = sum(seconds[p] for p in ("decode", "observe", "scan", "first touch"))
    events_ns = (seconds["detect"] - seconds["scan"] + seconds["order"]) / total * 1e9
    print(f"| whole run (simulate_scene) | {run * 1e3:.1f} | | sum of the parts but scan: {parts_sum * 1e3:.1f} ms |")
    print(
        f"floor (decode + observe + scan + first touch): {floor * 1e3:.1f} ms; making and ordering the events: {events_ns:.1f} ns an event"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
