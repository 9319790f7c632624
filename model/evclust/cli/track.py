"""evclust track EVENTS -o tracks.csv [--params P.toml] [--model float]"""

from __future__ import annotations

from evclust.clusterer import load_params, preset_names, track_events
from evclust.errors import EvclustError
from evclust.clusterer.run import MODELS
from evclust.events import read_events
from evclust.tracks import write_tracks


def add_parser(sub) -> None:
    p = sub.add_parser(
        "track",
        help="cluster an event file into tracks (position, size, velocity, colour)",
        description=(
            "Run the event-by-event clusterer over an event file and write one track record per reported "
            "cluster per filter step (SPEC §4). Parameters come from --params (a TOML file with a [clusterer] "
            "table, or a preset name), else from the preset of the events' source scene, else the defaults, which "
            "hold across the generalization suite: their time constants are in frames of the event file's frame "
            "period (printed with the summary). "
            "DVS-only event files run with colour off."
        ),
    )
    p.add_argument("events", metavar="EVENTS", help="event file (.npz, .h5)")
    p.add_argument("-o", "--output", required=True, metavar="TRACKS", help="track file to write (.csv)")
    p.add_argument("--params", metavar="P", help=f"parameter file (.toml) or preset ({', '.join(preset_names())})")
    p.add_argument("--model", default="float", choices=sorted(MODELS), help="clusterer model (default: float)")
    p.add_argument("--ranges", action="store_true", help="fixed model: print each signal's range seen and its saturation count")
    p.add_argument("--beta-shift", action="store_true", help="fixed model: round every β to a power of two (shift-only filters)")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    p.set_defaults(run=run)


def run(args) -> int:
    events, meta = read_events(args.events)
    params, origin = load_params(args.params, meta.source)
    if (args.ranges or args.beta_shift) and args.model != "fixed":
        raise EvclustError("--ranges and --beta-shift are options of the fixed model: add --model fixed")
    options = {"ranges": args.ranges, "beta_shift_only": args.beta_shift} if args.model == "fixed" else {}
    result = track_events(events, meta, params, model=args.model, progress=not args.quiet, **options)
    write_tracks(args.output, result.tracks, result.meta)
    times = params.times(result.meta.t_frame_us)
    print(f"{args.events}: parameters from {origin} ({times}); {result.summary()}")
    if args.ranges:
        table = result.clusterer.table
        print(f"{'signal':<20} {'format':<9} {'range of the format':<24} {'seen':<26} saturations")
        for name, lo, hi, sat in result.clusterer.range_report():
            fmt = table[{"centre_step": "centre_step", "mcm_step": "v_mcm"}.get(name, name)]
            print(f"{name:<20} {fmt.q:<9} {f'{fmt.min:g}..{fmt.max:g}':<24} {f'{lo:.6g}..{hi:.6g}':<26} {sat}")
    return 0
