"""evclust score TRACKS --truth GT.csv [--json out.json] [--gate PX] [--fully-visible]"""

from __future__ import annotations

import argparse
import json
import math

from evclust.choices import DEFAULT_GATE_PX
from evclust.errors import atomic_output


def _gate(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a number") from None
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"{text} is not a positive number of pixels")
    return value


def add_parser(sub) -> None:
    p = sub.add_parser(
        "score",
        help="score a track file against the ground truth (paper's Tables 5 and 7)",
        description=(
            "Match the track records of every filter step to the ground-truth objects of that moment "
            "(frame k = floor(t_us / t_frame_us), centre interpolated between frames k and k+1) by "
            "Hungarian assignment on the centre distance, gated; then print the velocity errors "
            "(RMSE, NRMSE, angular; MCM and interval methods), the position and colour errors, the "
            "classification accuracy (direct and palette) and tracking figures (recall, precision, "
            "identity switches). Definitions: docs/METRICS.md."
        ),
        epilog=(
            "Prints three plain-text tables (velocity, position and colour, tracking) on stdout. "
            "Exit status: 0 on success, 2 on bad input (one line on stderr naming the file and the fault)."
        ),
    )
    p.add_argument("tracks", metavar="TRACKS", help="track file written by 'evclust track' (.csv or .parquet)")
    p.add_argument("--truth", required=True, metavar="GT.csv", help="ground-truth CSV written by 'evclust simulate --truth'")
    p.add_argument("--json", metavar="OUT.json", help="also write every figure (and the inputs and options) to this JSON file")
    p.add_argument(
        "--gate",
        type=_gate,
        default=DEFAULT_GATE_PX,
        metavar="PX",
        help=f"a track and an object farther apart than this many pixels are never matched (default: {DEFAULT_GATE_PX:g})",
    )
    p.add_argument(
        "--fully-visible",
        action="store_true",
        help="evaluate only objects whose whole box is inside the sensor (partly visible objects still take part in the matching)",
    )
    p.set_defaults(run=run)


def run(args) -> int:
    from evclust.metrics import format_tables, score
    from evclust.scenes.truth import read_truth
    from evclust.tracks import read_tracks

    tracks, meta = read_tracks(args.tracks)
    truth = read_truth(args.truth)
    scores = score(tracks, meta, truth, gate_px=args.gate, fully_visible_only=args.fully_visible)
    print(format_tables(scores))
    if args.json:
        document = {"tracks": str(args.tracks), "truth": str(args.truth), "source": meta.source, "model": meta.model}
        document.update(scores.to_dict())
        with atomic_output(args.json) as tmp:
            tmp.write_text(json.dumps(document, indent=2) + "\n")
        print(f"{args.json}: figures written")
    return 0
