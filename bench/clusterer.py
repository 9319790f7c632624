"""Clusterer speed: events per second of the float and fixed models on the built-in scenes'
events, one core, with the object layer on (the presets and the defaults have it) and, for its
cost, the defaults without it.

Writes its section of docs/BENCHMARKS.md. Targets (issues 11 and 23): on `traffic` events with
N = 16, the float model at >= 5 Mevents/s and the fixed model at >= 3 Mevents/s, with the scene's
preset and with the defaults, the object layer on.
"""

from __future__ import annotations

import common  # first: pins every thread pool to one core

import argparse
import datetime
import statistics
import time
from pathlib import Path

from evclust.clusterer import ClustererParams, load_params
from evclust.run import track_events
from evclust.scenes import load_scene
from evclust.simulator import simulate_scene

START, END = "<!-- bench:clusterer:start -->", "<!-- bench:clusterer:end -->"
SCENES = ("traffic", "pedestrian")
REPEAT = 5
MODELS = ("float", "fixed")  # the RTL's co-simulation speed is bench/rtl.py's


def measure(events, meta, params, model: str) -> tuple[float, float, int]:
    track_events(events[:10_000], meta, params, model=model)  # compile outside the timing
    walls = []
    for _ in range(REPEAT):
        start = time.perf_counter()
        run = track_events(events, meta, params, model=model)
        walls.append(time.perf_counter() - start)
    return statistics.median(walls), min(walls), len(run.output[0])


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--write", metavar="BENCHMARKS.md", help="rewrite this file's clusterer section")
    args = parser.parse_args()
    rows = []
    for name in SCENES:
        sim = simulate_scene(load_scene(name))
        preset, _ = load_params(name)
        configs = (("preset", preset), ("defaults", ClustererParams()), ("defaults, no object layer", ClustererParams(objects=False)))
        for config, params in configs:
            for model in MODELS:
                median, best, records = measure(sim.events, sim.meta, params, model)
                rows.append((name, config, model, params.n_clusters, sim.events.size, records, median, best))
    lines = [
        START,
        "## Clusterer speed",
        "",
        f"Command: `make bench` (= `.venv/bin/python bench/clusterer.py --write docs/BENCHMARKS.md`), "
        f"run {datetime.datetime.now(datetime.UTC):%Y-%m-%d %H:%M} UTC.",
        "",
        "Machine:",
        "",
        *common.machine(),
        "",
        f"Method: each scene simulated with its built-in sensor, tracked with its preset parameters and with the "
        f"defaults (the object layer, merging, noise gate, creation support, warm-up: docs/TUNING.md), then with the "
        f"defaults without the object layer, whose records are then the clusters'; "
        f"{REPEAT} timed runs of the whole stream (`track_events`: the compiled loop, chunking and record "
        "conversion; file I/O not included) after one warm-up. Mevents/s = events / wall / 10⁶.",
        "",
        "| scene | parameters | model | N | events | records (objects, or clusters without them) | median wall s | best wall s | Mevents/s (median) |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|",
    ]
    for name, config, model, n, events, records, median, best in rows:
        lines.append(
            f"| {name} | {config} | {model} | {n} | {events:,} | {records:,} | {median:.3f} | {best:.3f} | {events / median / 1e6:.2f} |"
        )
    lines.append("")
    for config in ("preset", "defaults"):
        rate = {r[2]: r[4] / r[6] / 1e6 for r in rows if r[0] == "traffic" and r[1] == config}
        lines.append(
            f"Targets on `traffic` ({config}), N = 16, one core: float model ≥ 5 Mevents/s: {rate['float']:.2f}, "
            f"**{'PASS' if rate['float'] >= 5 else 'FAIL'}**; fixed model ≥ 3 Mevents/s: {rate['fixed']:.2f}, "
            f"**{'PASS' if rate['fixed'] >= 3 else 'FAIL'}**."
        )  # fmt: skip
    for model in MODELS:
        with_layer = next(r[6] for r in rows if r[0] == "traffic" and r[1] == "defaults" and r[2] == model)
        without = next(r[6] for r in rows if r[0] == "traffic" and r[1] == "defaults, no object layer" and r[2] == model)
        lines.append(f"What the object layer adds to the {model} model's time on `traffic` (defaults, medians of the same run): "
                     f"{100 * (with_layer / without - 1):+.1f} %.")  # fmt: skip
    lines.append(END)
    text = "\n".join(lines) + "\n"
    print(text)
    if args.write:
        from evclust.stamps import stamp_for

        common.write_section(Path(args.write), text, START, END, stamp=stamp_for("BENCHMARKS:clusterer"))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
