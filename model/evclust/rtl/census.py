"""Where the clock goes, register by register: a census of a routed core's endpoints.

nextpnr's report with `--detailed-timing-report` gives, for every net that ends at a register (a
flip-flop's data, enable or reset, a distributed RAM's write address, data or enable), each
endpoint's arrival time, earliest and latest: the clock-to-out, logic and routing of its fastest
and slowest input paths (nextpnr's `TimingAnalyser::build_detailed_net_timing_report`; the
setup time is not in it). The critical path is the latest of them; the census is all of them. Grouped by the
register they belong to, they say how many registers miss a clock target, by how much, and how
many cycles of logic each register's input holds at that clock: the number of pipeline cuts a
target needs, where the critical path alone names one at a time.
"""

from __future__ import annotations

import argparse
import bisect
import json
import math
import re
import sys
from pathlib import Path
from typing import NamedTuple

# Yosys names a flip-flop after the net it drives (`<net>_TRELLIS_FF_Q`, then `_1`, `_2` ... for
# the other bits), and a net it makes after a cell it meets (`<net>_LUT4_Z_..._TRELLIS_FF_DI`, a
# flip-flop it added beside `<net>`'s logic); nextpnr names a packed cell `<cell>$<part>`; a bus's
# bits are `<name>[i]`, a RAM's rows `<name>.<i>.<j>`. All of them are one register.
_PACKED = re.compile(r"\$.*$")
_FF = re.compile(r"_(?:TRELLIS_FF|TRELLIS_DPR16X4|LUT4|PFUMX|L6MUX21|CCU2C|MULT18X18D)(?:_.*)?$")
_INDEX = re.compile(r"(\[\d+\]|\.\d+)+$")
_INNER_INDEX = re.compile(r"\[\d+\]")


def register_of(cell: str) -> str:
    """The register (or RAM) an endpoint cell belongs to, by its name: a generate loop's copies
    (`seek.slot[15].key`) are one register, `seek.slot[i].key`."""
    return _INNER_INDEX.sub("[i]", _INDEX.sub("", _FF.sub("", _PACKED.sub("", cell))))


class Register(NamedTuple):
    name: str
    endpoints: int
    worst_ns: float  # the slowest endpoint's latest arrival (clock-to-out, logic, routing)
    missing: int  # endpoints whose arrival exceeds the target's period (before their setup time)

    def cycles(self, target_mhz: float) -> int:
        """Clock periods of the target its slowest input path takes: the cuts it needs, plus one."""
        return math.ceil(self.worst_ns * target_mhz / 1000.0)


class Census(NamedTuple):
    target_mhz: float
    endpoints: int
    missing: int  # endpoints slower than the target's period
    registers: list[Register]  # slowest first
    arrivals_ns: list[float]  # every endpoint's, in ascending order

    def share_within(self, mhz: float) -> float:
        """The share of endpoints whose arrival fits a clock of `mhz`."""
        return bisect.bisect_right(self.arrivals_ns, 1000.0 / mhz) / self.endpoints

    @property
    def registers_missing(self) -> int:
        return sum(r.missing > 0 for r in self.registers)


def endpoint_arrivals(report: dict) -> list[tuple[str, str, float]]:
    """(cell, port, latest arrival ns) of every register endpoint on the clock in nextpnr's
    report, whose `delay` is the arrival's [min, max]."""
    arrivals = []
    for net in report.get("detailed_net_timings", []):
        for end in net.get("endpoints", []):
            delay = end.get("delay")
            if isinstance(delay, list) and len(delay) == 2 and end.get("event", "").endswith("clk"):
                arrivals.append((end["cell"], end["port"], float(delay[1])))
    return arrivals


def endpoint_census(report: dict, target_mhz: float) -> Census | None:
    """The endpoints of a report grouped by register, slowest first; None when the report has no
    detailed net timings (nextpnr run without `--detailed-timing-report`, or not placed)."""
    arrivals = endpoint_arrivals(report)
    if not arrivals:
        return None
    period = 1000.0 / target_mhz
    by_register: dict[str, list[float]] = {}
    for cell, _port, arrival in arrivals:
        by_register.setdefault(register_of(cell), []).append(arrival)
    registers = [Register(name, len(a), max(a), sum(x > period for x in a)) for name, a in by_register.items()]
    registers.sort(key=lambda r: (-r.worst_ns, r.name))
    return Census(target_mhz, len(arrivals), sum(r.missing for r in registers), registers, sorted(a for _, _, a in arrivals))


def plot_clock_shares(runs: dict[str, Census], path, fmax: dict[str, float] | None = None) -> None:
    """One curve per run: the share of its register endpoints that a clock would meet, against
    the clock, with the target and each run's achieved Fmax marked (matplotlib, Agg)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    clocks = [1.0 + 0.5 * i for i in range(2 * 130)]  # 1 to 130.5 MHz
    fig, ax = plt.subplots(figsize=(8, 4.2))
    for name, census in runs.items():
        (line,) = ax.plot(clocks, [100 * census.share_within(f) for f in clocks], label=name)
        if fmax and fmax.get(name):
            ax.axvline(fmax[name], color=line.get_color(), linestyle=":", linewidth=1)
    target = next(iter(runs.values())).target_mhz
    ax.axvline(target, color="black", linestyle="--", linewidth=1)
    ax.text(target, 2, f" target {target:g} MHz", fontsize=8)
    ax.set_xlabel("clock (MHz)")
    ax.set_ylabel("register endpoints that meet it (%)")
    ax.set_ylim(0, 101)
    ax.set_xlim(clocks[0], clocks[-1])
    ax.set_title("Where the clock goes: every register endpoint, not only the critical path\n(dotted: each run's Fmax)",
                 fontsize=10)  # fmt: skip
    ax.legend(fontsize=8, loc="upper right")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


class Change(NamedTuple):
    register: str
    before_ns: float | None  # None: the register is not in that run
    after_ns: float | None

    @property
    def delta_ns(self) -> float:
        return (self.after_ns or 0.0) - (self.before_ns or 0.0)


def _worst_by_register(census: Census) -> dict[str, float]:
    return {r.name: r.worst_ns for r in census.registers}


def compare(before: Census, after: Census) -> list[Change]:
    """Every register of either run with its slowest arrival in each, largest change first: what
    a cut did to the registers it aimed at, and where the worst paths went."""
    worst_before, worst_after = _worst_by_register(before), _worst_by_register(after)
    changes = [Change(name, worst_before.get(name), worst_after.get(name)) for name in worst_before.keys() | worst_after.keys()]
    changes.sort(key=lambda c: (-abs(c.delta_ns), c.register))
    return changes


def comparison_table(before: Census, after: Census, top: int = 15) -> str:
    """Markdown: the totals of both runs, then the `top` registers that changed most and the
    `top` slowest after."""
    ns = lambda v: "–" if v is None else f"{v:.1f}"
    lines = ["| | before | after |", "|---|---:|---:|"]
    for label, b, a in (("endpoints", before.endpoints, after.endpoints),
                        (f"missing {before.target_mhz:g} MHz", before.missing, after.missing),
                        ("registers", len(before.registers), len(after.registers)),
                        (f"registers missing {before.target_mhz:g} MHz", before.registers_missing, after.registers_missing),
                        ("slowest arrival (ns)", ns(before.registers[0].worst_ns), ns(after.registers[0].worst_ns))):  # fmt: skip
        lines.append(f"| {label} | {b:,} | {a:,} |" if isinstance(b, int) else f"| {label} | {b} | {a} |")
    lines += ["", "| register (most changed) | before (ns) | after (ns) |", "|---|---:|---:|"]
    lines += [f"| `{c.register}` | {ns(c.before_ns)} | {ns(c.after_ns)} |" for c in compare(before, after)[:top]]
    worst_before = _worst_by_register(before)
    lines += ["", "| register (slowest after) | before (ns) | after (ns) |", "|---|---:|---:|"]
    lines += [f"| `{r.name}` | {ns(worst_before.get(r.name))} | {ns(r.worst_ns)} |" for r in after.registers[:top]]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m evclust.rtl.census",
        description="Compare two routed runs' register endpoints (nextpnr report.json with --detailed-timing-report).",
    )
    parser.add_argument("before", type=Path, help="the report.json before the change")
    parser.add_argument("after", type=Path, help="the report.json after it")
    parser.add_argument("--target-mhz", type=float, default=100.0)
    parser.add_argument("--top", type=int, default=15, help="registers listed per table")
    args = parser.parse_args(argv)
    censuses = []
    for path in (args.before, args.after):
        try:
            report = json.loads(path.read_text())
        except (OSError, ValueError) as error:
            print(f"census: cannot read {path}: {error}", file=sys.stderr)
            return 2
        census = endpoint_census(report, args.target_mhz)
        if census is None:
            print(f"census: {path} has no detailed net timings (nextpnr without --detailed-timing-report?)", file=sys.stderr)
            return 2
        censuses.append(census)
    print(comparison_table(*censuses, top=args.top))
    return 0


if __name__ == "__main__":
    sys.exit(main())
