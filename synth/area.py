"""Where the logic cells go: the defaults' core synthesised for the ECP5 with its hierarchy kept,
each unit's cells at two or more N, and what each unit costs per slot.

    .venv/bin/python synth/area.py [--n 16 64] [--write docs/BENCHMARKS.md]

The defaults as `make timing` builds them (run-time registers, the creation-support map left out)
on 480x270; `evclust.rtl.area` runs the flow and counts the cells. A run takes about a minute and a
half at N = 16 and four at N = 64, so a change to one unit is priced before it is placed. Results are cached by
content in build/area/.
"""

import argparse
import datetime
import sys
from pathlib import Path

from evclust.errors import EvclustError
from evclust.rtl.area import CORE_OWN, area, plot_units, slopes
from evclust.rtl.synth import in_parallel, rtl_snapshot, say
from evclust.rtl.timing import PART

from synth import defaults_header  # synth/synth.py: a script's folder is on its path

ROOT = Path(__file__).resolve().parents[1]
START, END = "<!-- bench:area:start -->", "<!-- bench:area:end -->"
PLOT = ROOT / "docs" / "img" / "area_units.png"


def command() -> str:
    return " ".join([".venv/bin/python", "synth/area.py", *sys.argv[1:]])


def table(by_n: dict[int, dict[str, dict[str, int]]]) -> str:
    ns = sorted(by_n)
    hi = ns[-1]
    line = slopes(by_n)
    units = sorted(by_n[hi], key=lambda u: -by_n[hi][u]["logic"])
    total = {n: sum(u["logic"] for u in by_n[n].values()) for n in ns}
    head = (["unit (instance, module)"] + [f"logic cells, N = {n}" for n in ns]
            + [f"share at N = {hi}", "per slot", "shared", f"FF, N = {hi}", f"MULT18X18D, N = {hi}"])  # fmt: skip
    lines = ["| " + " | ".join(head) + " |", "|---|" + "---:|" * (len(head) - 1)]
    for unit in units:
        per_slot, shared = line[unit]
        cells = by_n[hi][unit]
        lines.append(
            "| " + " | ".join([unit.replace(CORE_OWN, "the core's own logic (table fields, control, filter step)")]
                              + [f"{by_n[n].get(unit, {}).get('logic', 0):,}" for n in ns]
                              + [f"{100 * cells['logic'] / total[hi]:.1f} %", f"{per_slot:,.1f}", f"{shared:,.0f}",
                                 f"{cells['ff']:,}", f"{cells['mult18']:,}"]) + " |")  # fmt: skip
    per_slot = sum(p for p, _ in line.values())
    shared = sum(s for _, s in line.values())
    lines.append("| **all** | " + " | ".join(f"**{total[n]:,}**" for n in ns)
                 + f" | 100 % | **{per_slot:,.1f}** | **{shared:,.0f}** | {sum(u['ff'] for u in by_n[hi].values()):,} "
                 f"| {sum(u['mult18'] for u in by_n[hi].values()):,} |")  # fmt: skip
    return "\n".join(lines)


def section(by_n: dict[int, dict[str, dict[str, int]]], rows: list[dict]) -> str:
    ns = sorted(by_n)
    lo, hi = ns[0], ns[-1]
    line = slopes(by_n)
    per_slot = sum(p for p, _ in line.values())
    shared = sum(s for _, s in line.values())
    part = PART["logic_cells"]
    at = {n: shared + per_slot * n for n in (64, 256)}
    fit = int((part - shared) // per_slot)  # the most slots whose line stays within the part
    seconds = ", ".join(f"N = {r['n']}: {r['wall_s'] / 60:.1f} min" for r in rows)
    return "\n".join([
        START,
        "## RTL: where the logic cells go",
        "",
        f"Command: `{command()}` (part of `make area`), run {datetime.datetime.now(datetime.UTC):%Y-%m-%d %H:%M} UTC on the "
        f"machine above, RTL at {rows[0]['rtl']}. Flow: {rows[0]['yosys']} `synth_ecp5 -noflatten` of the defaults as "
        "`make timing` builds them (the parameters in run-time registers, the creation-support map left out) on 480x270; "
        "`evclust.rtl.area` counts each unit's cells: an instance of the core with everything below it, or the core's own "
        "logic outside every instance. Logic cells are LUT4s plus two per CCU2C (nextpnr's TRELLIS_COMB before packing). "
        "With the hierarchy kept no optimisation crosses a port, so the totals run above the flattened build's (the "
        "datasheet's totals stay `make timing`'s): the shares and the slopes are the measurement. "
        f"Synthesis time: {seconds}.",
        "",
        table(by_n),
        "",
        f"`per slot` and `shared` are the straight line through N = {lo} and N = {hi}. On that line the defaults need "
        f"{at[64]:,.0f} logic cells at N = 64 ({100 * at[64] / part:.0f} % of the LFE5U-85F's {part:,}) and {at[256]:,.0f} "
        f"at N = 256 ({100 * at[256] / part:.0f} %); with this design the part holds N ≤ {fit} on the line "
        f"(in this count, before the flattened build's savings). The picture splits each unit at N = {hi} the same way.",
        "",
        f"![logic cells per unit at N = {hi}](img/{PLOT.name})",
        END,
        "",
    ])  # fmt: skip


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, nargs="+", default=[16, 64], help="cluster slots, two or more (default: 16 64, the datasheet's)")
    parser.add_argument("--write", type=Path, metavar="BENCHMARKS.md", help="rewrite this file's area section")
    parser.add_argument("--jobs", type=int, help="runs at a time (default: one per core)")
    args = parser.parse_args()
    if len(set(args.n)) < 2:
        parser.error("--n needs two or more different N: the cells per slot are a slope")
    snapshot = rtl_snapshot()

    def run(n: int) -> dict:
        say(f"area: defaults, N={n} ...")
        beat = lambda seconds, step: say(f"  N={n}: {seconds:5.0f} s {step}")
        figures = area(defaults_header(n), f"defaults-n{n}", beat, snapshot)
        total = sum(u["logic"] for u in figures["units"].values())
        say(f"area: N={n}: {total:,} logic cells{' (cached)' if figures['cached'] else ''}")
        return figures | {"n": n}

    try:
        rows = in_parallel(run, [(n,) for n in sorted(set(args.n))], args.jobs)
    except EvclustError as e:
        sys.exit(f"area: {e}")
    by_n = {r["n"]: r["units"] for r in rows}
    print(table(by_n))
    if args.write:
        from evclust.documents import write_section
        from evclust.stamps import stamp_for

        hi = max(by_n)
        plot_units(by_n[hi], slopes(by_n), hi, PLOT, PART["logic_cells"])
        write_section(args.write, section(by_n, rows), START, END, stamp=stamp_for("BENCHMARKS:area"))


if __name__ == "__main__":
    main()
