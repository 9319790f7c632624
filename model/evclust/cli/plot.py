"""evclust plot TRACKS --truth GT.csv -o plot.png [--kind velocity|colour|scatter]"""

from __future__ import annotations

from evclust.errors import EvclustError
from evclust.choices import DEFAULT_GATE_PX, PLOT_AXES, PLOT_KINDS


def add_parser(sub) -> None:
    p = sub.add_parser(
        "plot",
        help="plot one tracked object against its ground truth",
        description=(
            "Match the track records to the ground-truth objects at each filter step and plot one object: "
            "velocity (vy above vx; ground truth blue, MCM green, interval yellow), colour (Y, Cb, Cr; "
            "estimate green, ground truth blue) or scatter (the colours of the events inside the matched "
            "cluster's box, with the palette; needs --events). Red lines mark exits and re-entries."
        ),
    )
    p.add_argument("tracks", metavar="TRACKS", help="track file (tracks.csv from 'evclust track')")
    p.add_argument("--truth", required=True, metavar="GT.csv", help="ground truth ('evclust simulate --truth')")
    p.add_argument("-o", "--output", required=True, metavar="PLOT", help="image to write (.png, .svg, .pdf)")
    p.add_argument("--kind", choices=PLOT_KINDS, default="velocity", help="what to plot (default: velocity)")
    p.add_argument("--events", metavar="EVENTS", help="the event file the tracks came from (needed by --kind scatter)")
    p.add_argument("--gt-id", type=int, metavar="N", help="ground-truth object to plot (default: the one with the most matches)")
    p.add_argument(
        "--gate",
        type=float,
        default=DEFAULT_GATE_PX,
        metavar="PX",
        help=f"largest centre distance of a match, px (default: {DEFAULT_GATE_PX:g})",
    )
    p.add_argument(
        "--x", dest="axis", choices=PLOT_AXES, default="index", help="x axis: evaluation index, as the paper, or time (default: index)"
    )
    p.set_defaults(run=run)


def run(args) -> int:
    from evclust.metrics.match import match
    from evclust.render.plots import check_plot_path, plot_colour, plot_scatter, plot_velocity
    from evclust.scenes.truth import read_truth
    from evclust.tracks import read_tracks

    out = check_plot_path(args.output)
    if args.kind == "scatter" and not args.events:
        raise EvclustError("--kind scatter needs --events EVENTS: the event file the tracks came from")
    tracks, meta = read_tracks(args.tracks)
    truth = read_truth(args.truth)
    matches = match(tracks, meta, truth, gate_px=args.gate)
    if matches.size == 0:
        raise EvclustError(f"{args.tracks}: no track record is within {args.gate:g} px of an object of {args.truth}")
    title = meta.source or str(args.tracks)
    if args.kind == "velocity":
        gt_id = plot_velocity(matches, out, args.gt_id, truth, args.axis, meta.t_frame_us, title)
    elif args.kind == "colour":
        gt_id = plot_colour(matches, out, args.gt_id, truth, args.axis, meta.t_frame_us, meta.palette, title)
    else:
        from evclust.events import read_events

        events, ev_meta = read_events(args.events)
        gt_id = plot_scatter(matches, events, ev_meta, tracks, meta, out, args.gt_id, title=title)
    n = int((matches["gt_id"] == gt_id).sum())
    print(f"{out}: {args.kind} of object {gt_id} ({n} matched evaluations)")
    return 0
