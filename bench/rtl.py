"""RTL figures: cycles per event and per filter sweep (measured by the testbench on every vector
case, without input gaps or output stalls), and co-simulation speed under Icarus and Verilator.

Writes its section of docs/BENCHMARKS.md. Targets: Verilator co-simulation >= 50k events/s
(issue 5); 1 cycle per event outside sweeps and scans, and >= 90 Mevents/s on the traffic clip at
the placed Fmax (issue 12; `make timing` first).

Each run saves its figures in build/bench_rtl.json; `--figures build/bench_rtl.json` writes the
section again from them without simulating (for instance once `make timing` has given the Fmax
the sustained rate needs).
"""

from __future__ import annotations

import common  # first: pins every thread pool to one core

import argparse
import datetime
import json
import sys
import time
from pathlib import Path

from evclust.rtl.configurations import random_config
from evclust.rtl.cosim import SIMULATORS, run
from evclust.vectors import CASES
from evclust.vectors.read import load_case

ROOT = Path(__file__).resolve().parents[1]

START, END = "<!-- bench:rtl:start -->", "<!-- bench:rtl:end -->"
VECTORS = ROOT / "vectors"
STREAM = {"icarus": 20_000, "verilator": 200_000}  # random events per co-simulation speed run


def cycles_per_case(sim: str) -> list[dict]:
    rows = []
    for name in CASES:
        case = load_case(VECTORS / name)
        stats = run(sim, case.header, "replay_vectors", {"cases": [str(VECTORS / name)], "seed": 1, "gap": 0, "stall": 0})["cases"][name]
        rows.append(stats | {"case": name, "n": case.table.n_clusters, "p": case.table.palette_size,
                             "evictions": case.manifest["counts"]["evicted"] + case.manifest["counts"]["dropped"]})  # fmt: skip
    return rows


def stream_speed(sim: str) -> dict:
    header, config = random_config("traffic", 16, seed=3, count=STREAM[sim])
    run(sim, header, "model_in_the_loop", config | {"count": 1000})  # build outside the timing
    start = time.perf_counter()
    result = run(sim, header, "model_in_the_loop", config)
    return result | {"total_s": time.perf_counter() - start}


def sustained(rows) -> list[str]:
    """Events per second at the placed Fmax (make timing's N = 16 result): the traffic clip's
    counted cycles per event times the clock."""
    timing = ROOT / "build" / "timing" / "results.json"
    fmax = (
        {r["n_clusters"]: r for r in json.loads(timing.read_text()) if r.get("configuration") == "defaults" and not r.get("static")}
        if timing.exists()
        else {}
    )
    if 16 not in fmax:
        return [
            "",
            "Sustained rate at Fmax: not computed in this run: no result of `make timing` for the defaults at N = 16 in "
            "build/timing/results.json (the placed figures in the section below are of the RTL they name).",
        ]
    mhz = fmax[16]["fmax_mhz"]
    if mhz is None:
        return ["", "Sustained rate at Fmax: none: the N = 16 core of `make timing` does not fit the part (section below)."]
    out = [""]
    for name in ("traffic_clip", "suite_clip"):
        clip = next(r for r in rows if r["case"] == name)
        rate = clip["events"] / clip["cycles"] * mhz
        out.append(f"Sustained rate on `{name}` at the defaults' N = 16 Fmax of `make timing` ({mhz:.1f} MHz, LFE5U-85F speed 8): "
                   f"{clip['events']:,} events in {clip['cycles']:,} cycles, **{rate:.1f} Mevents/s** "
                   f"(target ≥ 90: **{'PASS' if rate >= 90 else 'FAIL'}**); latency {clip['latency_min']} to {clip['latency_max']} edges, "
                   f"{1000 * clip['latency_min'] / mhz:.0f} to {1000 * clip['latency_max'] / mhz:,.0f} ns (target ≤ 300 ns: "
                   f"**{'PASS' if 1000 * clip['latency_max'] / mhz <= 300 else 'FAIL'}**).")  # fmt: skip
        out.append("")
    return out[:-1]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--write", metavar="BENCHMARKS.md", help="rewrite this file's RTL section")
    parser.add_argument("--figures", type=Path, metavar="JSON", help="an earlier run's figures (build/bench_rtl.json): no simulation")
    args = parser.parse_args()
    if args.figures:
        saved = json.loads(args.figures.read_text())
        cases, speed = saved["cases"], saved["speed"]
        run_at = datetime.datetime.fromisoformat(saved["run_at"]) if "run_at" in saved else \
            datetime.datetime.fromtimestamp(args.figures.stat().st_mtime, datetime.UTC)  # fmt: skip
    else:
        cases = {sim: cycles_per_case(sim) for sim in SIMULATORS}
        speed = {sim: stream_speed(sim) for sim in SIMULATORS}
        run_at = datetime.datetime.now(datetime.UTC)
    lines = [
        START,
        "## RTL: cycles and co-simulation speed",
        "",
        f"Command: `make bench` (= `.venv/bin/python bench/rtl.py --write docs/BENCHMARKS.md`), "
        f"run {run_at:%Y-%m-%d %H:%M} UTC, on the machine above.",
        "",
        "Cycles, counted by the harness (tb/evclust_core/evclust_tb.v) while every vector case replays "
        "with no input gap and no output stall. `filter` cycles are those with `filter_active` high (a step's phase, "
        "sweep, merges and tail). Cycles count from the end of the reset, so they include the reset's fill: one cycle "
        "per creation-support map cell where the map is on (creation_support, suite_clip).",
        "",
        "The object unit (evclust_objects, where the case has an object layer) works on each step while the core goes "
        "on with its events: `object unit cycles/step` is its busy time per step, and `core held` the filter-step cycles "
        "the core waited for it (a record it could not pass on, or the last step's end not taken yet). `latency` counts "
        "clock edges from the one that takes an event to the one that writes its slot (the harness stamps both); the "
        "largest is an event taken as a filter step begins, which waits in stage A for the whole step. In the "
        "`pipelined_*` cases (update_delay = 1) the edge stamped is the one that decides the event; its update is "
        'written as the next event finishes (docs/RTL.md, "Pipeline semantics").',
        "",
        "| case | N | events | cycles | cycles/event | cycles/event outside sweeps | sweeps | cycles/sweep | evictions + drops "
        "| object unit cycles/step | core held (cycles) | latency, edges: min / mean / max |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in cases["verilator"]:
        outside = (r["cycles"] - r["filter_cycles"]) / r["events"]
        busy = f"{r['object_busy_cycles'] / max(1, r['filter_steps']):.1f}" if r["object_busy_cycles"] else "—"
        lines.append(f"| {r['case']} | {r['n']} | {r['events']:,} | {r['cycles']:,} | {r['cycles'] / r['events']:.2f} | {outside:.2f} "
                     f"| {r['filter_steps']} | {r['filter_cycles'] / max(1, r['filter_steps']):.1f} | {r['evictions']} "
                     f"| {busy} | {r['object_wait_cycles']:,} "
                     f"| {r['latency_min']} / {r['latency_sum'] / r['events']:.2f} / {r['latency_max']} |")  # fmt: skip
    same = all(a["cycles"] == b["cycles"] for a, b in zip(cases["icarus"], cases["verilator"]))
    lines += ["", f"Icarus counts the same cycles for every case: {'yes' if same else '**no**'}.", *sustained(cases["verilator"])]
    lines += [
        "",
        "Co-simulation speed: random streams (traffic parameters, N = 16, 480x270) through the RTL and the "
        "fixed model in one process, no gaps or stalls. `stream` is the time cocotb spends loading the batches, "
        "simulating and reading the records back; `whole run` adds the simulator's start, the model and the "
        "comparison.",
        "",
        "| simulator | events | records | stream s | events/s (stream) | whole run s | events/s (whole run) |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ]
    for sim, r in speed.items():
        lines.append(f"| {sim} | {r['events']:,} | {r['records']:,} | {r['wall_s']:.2f} | {r['events'] / r['wall_s']:,.0f} "
                     f"| {r['total_s']:.1f} | {r['events'] / r['total_s']:,.0f} |")  # fmt: skip
    v = speed["verilator"]
    lines += ["", f"Target: Verilator co-simulation ≥ 50k events/s: {v['events'] / v['wall_s']:,.0f} (stream), "
              f"**{'PASS' if v['events'] / v['wall_s'] >= 50_000 else 'FAIL'}**.", END, ""]  # fmt: skip
    text = "\n".join(lines)
    print(text)
    if args.write:
        from evclust.stamps import stamp_for

        common.write_section(Path(args.write), text, START, END, stamp=stamp_for("BENCHMARKS:rtl"))
    if not args.figures:
        (ROOT / "build" / "bench_rtl.json").write_text(json.dumps({"cases": cases, "speed": speed, "run_at": run_at.isoformat()}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
