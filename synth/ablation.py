"""What each event-rate addition costs in hardware, beside what it buys with the object layer on.

    .venv/bin/python synth/ablation.py [--figures build/ablation.json] [--write docs/TUNING.md]

Each addition (merging, the scaled seek, the noise gate, the interval warm start) is switched off
in turn from the defaults, and the core synthesised at N = 4 and N = 16 with the constants built
in (`RUNTIME_CONFIG = 0`), so that Yosys removes what an addition no longer uses. An addition's
cost per slot is the slope over N of what it adds, (on16 - off16 - (on4 - off4)) / 12, and its
shared cost what remains at N = 4. The creation-support map is a RAM of cells, one per pixel cell
and not per slot: its bits come from the formats table. The object unit (evclust_objects) is
synthesised alone at the defaults. Tracking figures come from `evclust generalize --split tuning
--ablation --json build/ablation.json` (`make ablation` runs both).
"""

import argparse
import datetime
import json
import sys
from pathlib import Path

from evclust.clusterer import ClustererParams
from evclust.errors import EvclustError
from evclust.rtl.sources import BUILD
from evclust.rtl.sources import params_header as rtl_header
from evclust.rtl.synth import rtl_snapshot, synthesise

ROOT = Path(__file__).resolve().parents[1]
START, END = "<!-- ablation:start -->", "<!-- ablation:end -->"
SENSOR = (480, 270, 50000.0)  # the synthesis sensor of synth/synth.py
N_SMALL, N_LARGE = 4, 16
# The additions a synthesis can remove, by the configuration name of `generalize --ablation`.
ADDITIONS = {
    "no merging": ("merging", {"merge": False}),
    "no scaled seek": ("scaled seek", {"seek_scale": 0.0}),
    "no noise gate": ("noise gate", {"noise_gate": 0.0}),
    "no warm start (plain α filters)": ("interval warm start", {"velocity_warm_start": False}),
}
SUPPORT = "no creation support"
KEYS = ("lut", "ff", "dsp48e1", "carry4")


def header(n: int, **update) -> str:
    """The defaults at N = n on the synthesis sensor, the support map left out (a block RAM)."""
    params = ClustererParams(n_clusters=n, create_support=False).model_copy(update=update)
    return rtl_header(params, *SENSOR)


def synth(label: str, text: str, snapshot, top: str = "evclust_core") -> dict:
    beat = lambda s, step: print(f"  {label}: {s:5.0f} s, {step}", file=sys.stderr)  # noqa: E731
    figures = synthesise(text, label, False, beat, snapshot, top=top, static=True)
    print(f"synth: {label} done in {figures['wall_s'] / 60:.1f} min{' (cached)' if figures['cached'] else ''}", file=sys.stderr)
    return figures


def support_bits() -> tuple[int, int, int]:
    """(cells, bits per cell, total bits) of the default creation-support map on the synthesis sensor."""
    from evclust.fixed.formats import build_formats

    params = ClustererParams()
    table = build_formats(params, SENSOR[0], SENSOR[1], SENSOR[2])
    cells_x = (SENSOR[0] >> params.support_cell_bits) + 2
    cells_y = (SENSOR[1] >> params.support_cell_bits) + 2
    bits = table["support_time"].word_bits + 1  # the time of the cell's latest event, and whether it has one
    return cells_x * cells_y, bits, cells_x * cells_y * bits


def cost(on: dict, off: dict) -> dict:
    """{key: (per slot, shared)} of what `on` adds over `off` (each {N: figures})."""
    out = {}
    for key in KEYS:
        small = on[N_SMALL][key] - off[N_SMALL][key]
        large = on[N_LARGE][key] - off[N_LARGE][key]
        per_slot = (large - small) / (N_LARGE - N_SMALL)
        out[key] = (per_slot, small - N_SMALL * per_slot)
    return out


def _pct(v):
    return "n/a" if v is None else f"{100 * v:.1f} %"


def section(defaults: dict, costs: dict, objects: dict, support: tuple, tracking: dict | None, rtl: str) -> str:
    base = tracking.get("default") if tracking else None

    def figures(name):
        f = tracking.get(name) if tracking else None
        if not f:
            return ["—"] * 5
        o = f["figures"]
        delta = f" ({100 * (o['HOTA'] - base['figures']['HOTA']):+.1f})" if base and name != "default" else ""
        return [_pct(o["recall"]), _pct(o["precision"]), f"{o['tracks_per_object']:.2f}", _pct(o["HOTA"]) + delta,
                _pct(o.get("best_velocity_nrmse"))]  # fmt: skip

    head = ("| configuration | recall | precision | tracks/object | HOTA (points vs defaults) | velocity NRMSE "
            "| LUT per slot | FF per slot | DSP48E1 per slot | LUT shared | FF shared | DSP48E1 shared |")  # fmt: skip
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    lines.append("| defaults (object layer on) | " + " | ".join(figures("default")) + " | " + " | ".join(
        [f"{(defaults[N_LARGE][k] - defaults[N_SMALL][k]) / (N_LARGE - N_SMALL):,.0f} (all)" for k in ("lut", "ff", "dsp48e1")]
        + [f"{defaults[N_SMALL][k] - N_SMALL * (defaults[N_LARGE][k] - defaults[N_SMALL][k]) / (N_LARGE - N_SMALL):,.0f} (all)" for k in ("lut", "ff", "dsp48e1")]
    ) + " |")  # fmt: skip
    for name, (label, _) in ADDITIONS.items():
        c = costs[name]
        lines.append(f"| {name} (saves: {label}) | " + " | ".join(figures(name)) + " | "
                     + " | ".join(f"{c[k][0]:,.1f}" for k in ("lut", "ff", "dsp48e1")) + " | "
                     + " | ".join(f"{c[k][1]:,.0f}" for k in ("lut", "ff", "dsp48e1")) + " |")  # fmt: skip
    cells, bits, total = support
    lines.append(f"| {SUPPORT} | " + " | ".join(figures(SUPPORT)) + f" | 0 | 0 | 0 | a RAM of {cells:,} cells × {bits} bits "
                 f"= {total / 8 / 1024:,.0f} KiB ({-(-total // 36864)} RAMB36) | | |")  # fmt: skip
    for name in ("none of the five", "no object layer", "paper"):
        if tracking and name in tracking:
            lines.append(f"| {name} | " + " | ".join(figures(name)) + " | | | | | | |")
    o = objects
    return "\n".join([
        START,
        f"Hardware: `.venv/bin/python synth/ablation.py --write docs/TUNING.md`, run "
        f"{datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC, RTL at {rtl}: Yosys `synth_xilinx` (the flow "
        f"of `make synth`), the defaults on 480×270 at 20 fps with the constants built in, N = {N_SMALL} and {N_LARGE}; per slot "
        f"is the slope over N of what the addition adds, shared what remains at N = {N_SMALL}. Tracking: the tuning split "
        "(`evclust generalize --split tuning --ablation`, float model, object records), in [ABLATION.md](ABLATION.md).",
        "",
        *lines,
        "",
        f"The object unit alone (`evclust_objects`, K = {ClustererParams().n_objects} object slots behind N = {N_LARGE} clusters, "
        f"constants built in): {o['lut']:,} LUT (+{o['inv']:,} INV), {o['ff']:,} FF, {o['dsp48e1']} DSP48E1, {o['carry4']:,} CARRY4, "
        f"{o['lutram_luts']} LUTRAM LUTs; logic depth {o['depth_cells']} cells. It does not grow with the event rate: it runs "
        "once per filter step.",
        END,
        "",
    ])  # fmt: skip


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--figures", type=Path, default=BUILD / "ablation.json", help="tracking figures of `generalize --ablation --json` (default: %(default)s)")
    parser.add_argument("--write", type=Path, metavar="TUNING.md", help="rewrite this file's ablation section")
    args = parser.parse_args()
    snapshot = rtl_snapshot()
    try:
        defaults = {n: synth(f"ablation-defaults-n{n}", header(n), snapshot) for n in (N_SMALL, N_LARGE)}
        costs = {}
        for name, (label, update) in ADDITIONS.items():
            slug = label.replace(" ", "-")
            off = {n: synth(f"ablation-no-{slug}-n{n}", header(n, **update), snapshot) for n in (N_SMALL, N_LARGE)}
            costs[name] = cost(defaults, off)
        objects = synth(f"objects-n{N_LARGE}", header(N_LARGE), snapshot, top="evclust_objects")
    except EvclustError as e:
        sys.exit(f"ablation: {e}")
    tracking = None
    if args.figures.exists():
        tracking = {row["name"]: row for row in json.loads(args.figures.read_text())}
    else:
        print(f"ablation: {args.figures} not found: the tracking columns stay empty (run `evclust generalize --split tuning "
              f"--ablation --json {args.figures}`)", file=sys.stderr)  # fmt: skip
    text = section(defaults, costs, objects, support_bits(), tracking, defaults[N_SMALL]["rtl"])
    print(text)
    if args.write:
        sys.path.insert(0, str(ROOT / "bench"))
        from common import write_section

        write_section(args.write, text, START, END)


if __name__ == "__main__":
    main()
