"""What each event-rate addition costs in hardware, beside what it buys with the object layer on.

    .venv/bin/python synth/ablation.py [--figures build/ablation.json] [--write docs/TUNING.md]

Each addition (merging, the scaled seek, the noise gate, the interval warm start) is switched off
in turn from the defaults with every addition on (the scaled seek, off by default, at its last
tuned scale), and the core synthesised at N = 4 and N = 16 with the constants built in
(`RUNTIME_CONFIG = 0`), so that Yosys removes what an addition no longer uses. An addition's cost
per slot is the slope over N of what it adds, (on16 - off16 - (on4 - off4)) / 12, and its shared
cost what remains at N = 4. The creation-support map is a RAM of cells, one per pixel cell and
not per slot: its bits come from the formats table. The object unit (evclust_objects) is
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
from evclust.paths import BUILD
from evclust.rtl.sources import params_header as rtl_header
from evclust.rtl.synth import in_parallel, rtl_snapshot, say, synthesise

ROOT = Path(__file__).resolve().parents[1]
START, END = "<!-- ablation:start -->", "<!-- ablation:end -->"
SENSOR = (480, 270, 50000.0)  # the synthesis sensor of synth/synth.py
N_SMALL, N_LARGE = 4, 16
# The additions' configuration names in `generalize --ablation` (with it off, or on when the
# defaults leave it off), and what switches each off from "every addition on".
ADDITIONS = {
    "merging": ("no merging", {"merge": False}),
    "scaled seek": ("scaled seek on", {"seek_scale": 0.0}),
    "noise gate": ("no noise gate", {"noise_gate": 0.0}),
    "interval warm start": ("no warm start (plain α filters)", {"velocity_warm_start": False}),
}
SUPPORT = ("creation-support map", "no creation support")
KEYS = ("lut", "ff", "dsp48e1", "carry4")


def header(n: int, **update) -> str:
    """The defaults with every addition on, at N = n on the synthesis sensor, the support map left
    out (a block RAM); `update` switches some off."""
    from evclust.suite.report import SEEK_SCALE_TUNED

    params = ClustererParams(n_clusters=n, create_support=False, seek_scale=SEEK_SCALE_TUNED).model_copy(update=update)
    return rtl_header(params, *SENSOR)


def synth(label: str, text: str, snapshot, top: str = "evclust_core") -> dict:
    beat = lambda s, step: say(f"  {label}: {s:5.0f} s, {step}")
    figures = synthesise(text, label, False, beat, snapshot, top=top, static=True)
    say(f"synth: {label} done in {figures['wall_s'] / 60:.1f} min{' (cached)' if figures['cached'] else ''}")
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


def section(all_on: dict, costs: dict, objects: dict, support: tuple, tracking: dict | None, rtl: str) -> str:
    from evclust.suite.report import SEEK_SCALE_TUNED

    defaults = ClustererParams()

    def on_off(config: str, in_defaults: bool) -> list[str]:
        """The addition's tracking figures with it and without it ("with → without")."""
        if not tracking or "default" not in tracking or config not in tracking:
            return ["—"] * 5
        a, b = tracking["default"]["figures"], tracking[config]["figures"]
        on, off = (a, b) if in_defaults else (b, a)
        cells = [f"{_pct(on[k])} → {_pct(off[k])}" for k in ("HOTA", "recall", "precision")]
        cells.append(f"{on['tracks_per_object']:.2f} → {off['tracks_per_object']:.2f}")
        cells.append(f"{100 * (on['HOTA'] - off['HOTA']):+.1f}")
        return cells

    head = ("| addition | in the defaults | HOTA with → without | recall | precision | tracks/object | HOTA bought (points) "
            "| LUT per slot | FF per slot | DSP48E1 per slot | LUT shared | FF shared | DSP48E1 shared |")  # fmt: skip
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    slope = {k: (all_on[N_LARGE][k] - all_on[N_SMALL][k]) / (N_LARGE - N_SMALL) for k in KEYS}
    lines.append("| the core, every addition on | | | | | | | " + " | ".join(f"{slope[k]:,.0f}" for k in ("lut", "ff", "dsp48e1")) + " | "
                 + " | ".join(f"{all_on[N_SMALL][k] - N_SMALL * slope[k]:,.0f}" for k in ("lut", "ff", "dsp48e1")) + " |")  # fmt: skip
    for label, (config, _) in ADDITIONS.items():
        in_defaults = not config.endswith(" on")
        c = costs[label]
        lines.append(f"| {label} | {'yes' if in_defaults else '**no**'} | " + " | ".join(on_off(config, in_defaults)) + " | "
                     + " | ".join(f"{c[k][0]:,.1f}" for k in ("lut", "ff", "dsp48e1")) + " | "
                     + " | ".join(f"{c[k][1]:,.0f}" for k in ("lut", "ff", "dsp48e1")) + " |")  # fmt: skip
    cells, bits, total = support
    label, config = SUPPORT
    lines.append(f"| {label} | {'yes' if defaults.create_support else '**no**'} | " + " | ".join(on_off(config, defaults.create_support))
                 + f" | 0 | 0 | 0 | RAM: {cells:,} cells × {bits} bits = {total / 8 / 1024:,.0f} KiB ({-(-total // 36864)} RAMB36) | | |")  # fmt: skip
    o = objects
    bought = ""
    if tracking and "no object layer" in tracking and "default" in tracking:
        on, off = tracking["default"]["figures"], tracking["no object layer"]["figures"]
        bought = (
            f" With it, on the tuning split: HOTA {_pct(on['HOTA'])} against {_pct(off['HOTA'])} for the cluster records "
            f"of the same run, {on['tracks_per_object']:.2f} tracks per object against {off['tracks_per_object']:.2f}."
        )
    return "\n".join([
        START,
        f"Hardware: `.venv/bin/python synth/ablation.py --write docs/TUNING.md`, run "
        f"{datetime.datetime.now(datetime.UTC):%Y-%m-%d %H:%M} UTC, RTL at {rtl}: Yosys `synth_xilinx` (the flow "
        f"of `make synth`) on 480×270 at 20 fps, the defaults with every addition on (the scaled seek at "
        f"{SEEK_SCALE_TUNED}, its last tuned scale) and one switched off at a time, the constants built in, "
        f"N = {N_SMALL} and {N_LARGE}; per slot is the slope over N of what the addition adds, shared what remains at "
        f"N = {N_SMALL}. Tracking: the tuning split, float model, object records (`evclust generalize --split tuning --ablation`, "
        "[ABLATION.md](ABLATION.md)), the defaults against the defaults with the addition switched.",
        "",
        *lines,
        "",
        f"The object unit alone (`evclust_objects`, K = {defaults.n_objects} object slots behind N = {N_LARGE} clusters, "
        f"constants built in): {o['lut']:,} LUT (+{o['inv']:,} INV), {o['ff']:,} FF, {o['dsp48e1']} DSP48E1, {o['carry4']:,} CARRY4, "
        f"{o['lutram_luts']} LUTRAM LUTs; logic depth {o['depth_cells']} cells. It runs once per filter step, not per event.{bought}",
        END,
        "",
    ])  # fmt: skip


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--figures",
        type=Path,
        default=BUILD / "ablation.json",
        help="tracking figures of `generalize --ablation --json` (default: %(default)s)",
    )
    parser.add_argument("--write", type=Path, metavar="TUNING.md", help="rewrite this file's ablation section")
    args = parser.parse_args()
    snapshot = rtl_snapshot()
    # Every build at once, a Yosys run per core, the largest first.
    builds = {("all on", n): (f"ablation-all-on-n{n}", header(n), snapshot) for n in (N_LARGE, N_SMALL)}
    for label, (_, update) in ADDITIONS.items():
        slug = label.replace(" ", "-")
        builds |= {(label, n): (f"ablation-no-{slug}-n{n}", header(n, **update), snapshot) for n in (N_LARGE, N_SMALL)}
    builds[("objects", N_LARGE)] = (
        f"objects-n{N_LARGE}",
        header(N_LARGE, seek_scale=ClustererParams().seek_scale),
        snapshot,
        "evclust_objects",
    )
    order = sorted(builds, key=lambda key: -key[1])
    try:
        done = dict(zip(order, in_parallel(synth, [builds[key] for key in order])))
    except EvclustError as e:
        sys.exit(f"ablation: {e}")
    defaults = {n: done[("all on", n)] for n in (N_SMALL, N_LARGE)}
    costs = {label: cost(defaults, {n: done[(label, n)] for n in (N_SMALL, N_LARGE)}) for label in ADDITIONS}
    objects = done[("objects", N_LARGE)]
    tracking = None
    if args.figures.exists():
        tracking = {row["name"]: row for row in json.loads(args.figures.read_text())}
    else:
        print(f"ablation: {args.figures} not found: the tracking columns stay empty (run `evclust generalize --split tuning "
              f"--ablation --json {args.figures}`)", file=sys.stderr)  # fmt: skip
    text = section(defaults, costs, objects, support_bits(), tracking, defaults[N_SMALL]["rtl"])
    print(text)
    if args.write:
        from evclust.documents import write_section
        from evclust.stamps import stamp_for

        write_section(args.write, text, START, END, stamp=stamp_for("TUNING:ablation"))


if __name__ == "__main__":
    main()
