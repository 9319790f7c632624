"""Functional coverage of the RTL over co-simulation runs: which actions, flags, saturations, FSM
states and arcs, filter-step paths and stream conditions the testbenches drove the core through.

Each run's bins come from what the RTL itself reports: its status counters (actions,
saturations), its record words (flags, classes) and the harness's counters of the core's FSM
(tb/evclust_core/evclust_tb.v, `cov_*`). `evclust.rtl.cosim.run` saves them per run under
build/coverage/; `python -m evclust.rtl.coverage` merges every saved run and writes the table
into docs/VERIFICATION.md with the holes named.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from evclust.clusterer.layout import FLAG_BORDER, FLAG_MOVING_INT, FLAG_MOVING_MCM, FLAG_NEW
from evclust.documents import write_section
from evclust.fixed.enums import enum
from evclust.fixed.registers import SATURATING_SIGNALS
from evclust.stamps import stamp_for

COVERAGE_DIR = Path("build") / "coverage"
STATES = tuple(enum("evclust_core", "ST_").codes)  # the FSM's states, by code 0..7
# The state changes the FSM is designed to make (rtl/evclust_core.v, "the FSM's next state"):
# an event is taken into EXEC from IDLE or straight from the state that finishes the last one
# without a filter step (EXEC -> EXEC is no change); it finishes in EXEC (a slot takes it) or
# EVICT (created, evicted, dropped, unsupported), going to PHASE when a filter step is due; a
# sweep runs PHASE -> SWEEP <-> MERGE -> IDLE (stage B takes no event during a filter step).
# With the activity against a reference time, a move of the reference before the event in stage
# A runs IDLE -> PHASE (the drain) -> SWEEP (the slots' decay) -> IDLE.
# A reset enters INIT from wherever the core was, which these do not list.
ARCS = (
    ("INIT", "IDLE"), ("IDLE", "EXEC"), ("IDLE", "PHASE"), ("EXEC", "IDLE"), ("EXEC", "SCAN"), ("EXEC", "PHASE"),
    ("SCAN", "EVICT"), ("EVICT", "IDLE"), ("EVICT", "EXEC"), ("EVICT", "PHASE"),
    ("PHASE", "SWEEP"), ("SWEEP", "MERGE"), ("MERGE", "SWEEP"), ("SWEEP", "IDLE"),
)  # fmt: skip
PHASE_STEPS = ("decide", "divide the phase by τ", "divide the frame period")
STREAM = ("a record held by back-pressure", "an input gap while the core is ready",
          "a record held while an event waits", "an event in and a record out in one cycle")  # fmt: skip
ACTIONS = ("updates", "creates", "evictions", "drops", "unsupported", "expiries", "exits", "merges", "records")
FLAGS = {"new": FLAG_NEW, "border": FLAG_BORDER, "moving (MCM)": FLAG_MOVING_MCM, "moving (interval)": FLAG_MOVING_INT}
GROUPS = ("action", "saturation", "flag", "class", "state", "arc", "filter step", "stream")


def empty() -> dict[str, int]:
    """Every bin, at 0: the bins a complete suite must hit."""
    bins = {f"action: {a}": 0 for a in ACTIONS}
    bins |= {f"saturation: {s}": 0 for s in SATURATING_SIGNALS}
    bins |= {f"flag: {name} {state}": 0 for name in FLAGS for state in ("set", "clear")}
    bins |= {"class: none": 0, "class: a palette entry": 0}
    bins |= {f"state: {s}": 0 for s in STATES}
    bins |= {f"arc: {a} -> {b}": 0 for a, b in ARCS}
    bins |= {f"filter step: {p}": 0 for p in PHASE_STEPS}
    bins |= {f"stream: {c}": 0 for c in STREAM}
    return bins


def run_bins(fsm: dict, counters: dict, records: list[dict]) -> dict[str, int]:
    """One run's bins: `fsm` the harness's cov_* arrays, `counters` the status counters summed
    over the run, `records` the decoded records (flags and class)."""
    bins = empty()
    for a in ACTIONS:
        bins[f"action: {a}"] = counters.get(a, 0)
    for s in SATURATING_SIGNALS:
        bins[f"saturation: {s}"] = counters.get(f"sat_{s}", 0)
    for record in records:
        for name, bit in FLAGS.items():
            bins[f"flag: {name} {'set' if record['flags'] & bit else 'clear'}"] += 1
        bins["class: none" if record["class"] < 0 else "class: a palette entry"] += 1
    for code, cycles in enumerate(fsm["state"]):
        bins[f"state: {STATES[code]}"] = cycles
    for code, count in enumerate(fsm["arc"]):
        a, b = STATES[code >> 3], STATES[code & 7]
        if count and b != "INIT":  # into INIT: a reset
            bins[f"arc: {a} -> {b}"] = bins.get(f"arc: {a} -> {b}", 0) + count
    for code, name in enumerate(PHASE_STEPS):
        bins[f"filter step: {name}"] = fsm["phase"][code]
    for code, name in enumerate(STREAM):
        bins[f"stream: {name}"] = fsm["stream"][code]
    return bins


def merge(runs) -> dict[str, int]:
    total = empty()
    for bins in runs:
        for name, count in bins.items():
            total[name] = total.get(name, 0) + count
    return total


def load(folder: Path = COVERAGE_DIR) -> tuple[dict[str, int], int]:
    """The merged bins of every saved run under `folder`, and the number of runs."""
    files = sorted(Path(folder).glob("*.json"))
    return merge(json.loads(f.read_text())["bins"] for f in files), len(files)


def holes(bins: dict[str, int]) -> list[str]:
    return [name for name, count in bins.items() if count == 0]


def unexpected(bins: dict[str, int]) -> list[str]:
    """Arcs seen that the design does not list (a surprise to explain, not a pass)."""
    designed = {f"arc: {a} -> {b}" for a, b in ARCS}
    return [name for name, count in bins.items() if name.startswith("arc: ") and name not in designed and count]


def markdown(bins: dict[str, int], runs: int) -> list[str]:
    lines = [f"Merged over {runs} co-simulation runs (`build/coverage/`, one file per run).", "",
             "| group | bin | hits |", "|---|---|---:|"]  # fmt: skip
    for name, count in bins.items():
        group, bin_name = name.split(": ", 1)
        lines.append(f"| {group} | {bin_name} | {count:,}{' **hole**' if not count else ''} |")
    missing, extra = holes(bins), unexpected(bins)
    lines += ["", f"Bins: {len(bins)}; hit: {len(bins) - len(missing)}; holes: {', '.join(missing) if missing else 'none'}."]
    if extra:
        lines.append(f"Arcs seen that the design does not list: {', '.join(extra)}.")
    return lines


BEGIN, END = "<!-- coverage:begin -->", "<!-- coverage:end -->"


def write_table(doc: Path, lines: list[str]) -> None:
    """The coverage table into `doc`'s coverage section (a document without one is an error)."""
    write_section(doc, "\n".join([BEGIN, *lines, END]), BEGIN, END, append=False, stamp=stamp_for("VERIFICATION:coverage"))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m evclust.rtl.coverage", description=__doc__.splitlines()[0])
    parser.add_argument("--dir", type=Path, default=COVERAGE_DIR, help="the saved runs (default build/coverage)")
    parser.add_argument("--write", type=Path, help="a document with a coverage section to rewrite (docs/VERIFICATION.md)")
    args = parser.parse_args(argv)
    bins, runs = load(args.dir)
    if not runs:
        raise SystemExit(f"{args.dir}: no saved runs; run the co-simulation first (make cosim-full)")
    lines = markdown(bins, runs)
    if args.write:
        write_table(args.write, lines)
    print("\n".join(lines))
    return 1 if holes(bins) or unexpected(bins) else 0


if __name__ == "__main__":
    raise SystemExit(main())
