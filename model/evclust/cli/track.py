"""evclust track EVENTS -o tracks.csv|tracks.parquet [--params P.toml] [--model float]"""

from __future__ import annotations

from evclust.choices import FRAMELESS_PERIOD_US, TRACK_MODELS
from evclust.cli.common import EVENT_FILES, add_event_file_options, preset_list


def add_parser(sub) -> None:
    p = sub.add_parser(
        "track",
        help="cluster an event file into tracks (position, size, velocity, colour)",
        description=(
            "Run the event-by-event clusterer and its object layer over an event file and write the objects: one "
            "record per reported object per frame period (its last filter step's), or every filter step with "
            "--every-step; --clusters writes the clusters instead, one record per reported cluster per filter step "
            "(SPEC §4). The stream is read and the records written chunk by chunk, so "
            "files larger than memory pass through. Parameters come from --params (a TOML file with a [clusterer] "
            "table, or a preset name), else from the preset of the events' source scene, else the defaults, which "
            "hold across the generalization suite: their time constants are in frames of the event file's frame "
            "period (printed with the summary). "
            "DVS-only event files (camera and text formats, or HDF5 without colour) run with colour off."
        ),
    )
    p.add_argument(
        "events",
        metavar="EVENTS",
        help=f"event file ({EVENT_FILES}), or a scene or video to simulate on the fly (no event file written)",
    )
    add_event_file_options(p)
    p.add_argument("-o", "--output", required=True, metavar="TRACKS", help="track file to write (.csv, or .parquet: smaller and faster)")
    p.add_argument("--params", metavar="P", help=f"parameter file (.toml) or preset ({preset_list()})")
    p.add_argument("--model", default="float", choices=TRACK_MODELS, help="clusterer model (default: float)")
    p.add_argument(
        "--frame-us",
        type=float,
        metavar="US",
        help=f"frame period in µs, the unit of the velocities (default: the event file's; a file without one, such as a camera "
        f"recording, is tracked at {FRAMELESS_PERIOD_US:,.0f} µs)",
    )
    p.add_argument(
        "--clusters", action="store_true", help="write the cluster records (the event-rate clusterer's output) instead of the objects"
    )
    every = p.add_mutually_exclusive_group()
    every.add_argument(
        "--per-frame",
        action="store_true",
        help="one record per cluster or object per frame period, its last (the default for objects; for --clusters, far smaller outputs for videos)",
    )
    every.add_argument(
        "--every-step", action="store_true", help="one record per object or cluster per filter step (the default for --clusters)"
    )
    p.add_argument("--ranges", action="store_true", help="fixed model: print each signal's range seen and its saturation count")
    p.add_argument("--beta-shift", action="store_true", help="fixed model: round every β to a power of two (shift-only filters)")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    p.set_defaults(run=run)


def run(args) -> int:
    import dataclasses

    from evclust.clusterer import load_params
    from evclust.run.track import frameless, prepare_run, track_stream
    from evclust.errors import EvclustError
    from evclust.simulator.source import open_events
    from evclust.tracks import track_writer
    from evclust.tracks.thin import PerFrame

    if args.frame_us is not None and not 0 < args.frame_us < float("inf"):
        raise EvclustError(f"--frame-us {args.frame_us}: the frame period must be a positive, finite number of µs")
    if (args.ranges or args.beta_shift) and args.model != "fixed":
        raise EvclustError("--ranges and --beta-shift are options of the fixed model: add --model fixed")
    reader = open_events(args.events, progress=not args.quiet, sensor_size=args.sensor_size, polarity=args.polarity)
    meta = reader.meta
    if args.frame_us is not None:
        meta = dataclasses.replace(meta, t_frame_us=args.frame_us)
    params, origin = load_params(args.params, meta.source)
    options = {"ranges": args.ranges, "beta_shift_only": args.beta_shift} if args.model == "fixed" else {}
    # The metadata is known before the first event: the file is opened once and filled as we go.
    _, out_meta = prepare_run(meta, params, args.model)
    objects = params.objects and not args.clusters
    note = "" if objects or args.clusters else " (these parameters have no object layer: clusters written)"
    if args.clusters:
        params = params.model_copy(update={"objects": False})  # the object layer would run for nothing
    per_frame = args.per_frame or (objects and not args.every_step)
    out_meta = dataclasses.replace(out_meta, per_frame=per_frame, kind="objects" if objects else "clusters")
    discard = lambda records: None
    with track_writer(args.output, out_meta) as writer:
        thinner = PerFrame(writer.write, out_meta.t_frame_us) if per_frame else None
        sink = thinner.write if thinner else writer.write
        result = track_stream(
            reader.chunks(), meta, params, model=args.model, progress=not args.quiet, total=reader.count,
            sink=discard if objects else sink, object_sink=sink if objects else None, **options,
        )  # fmt: skip
        if thinner:
            thinner.close()
    times = params.times(out_meta.t_frame_us)
    if frameless(meta, params):
        fps = 1e6 / FRAMELESS_PERIOD_US
        times += (f"; no frame period in the file: the time constants are taken at {FRAMELESS_PERIOD_US:,.0f} µs "
                  f"({fps:g} fps, --frame-us to choose), velocities are in px per {FRAMELESS_PERIOD_US / 1e3:g} ms: x{fps:g} for px/s")  # fmt: skip
    kind = "object" if objects else "cluster"
    written = f"; {writer.count} {kind} records written" + (f", one per {kind} per frame" if per_frame else "")
    print(f"{args.events}: parameters from {origin}{note} ({times}); {result.summary()}{written}")
    print(_time_line(result))
    if args.ranges:
        print_ranges(result.clusterer)
    return 0


def _time_line(result) -> str:
    """Where the command's time went, so that a short file's wall time is not read as the tracker's
    speed: the compiled code's start-up and the event loop apart from the rest."""
    import time

    from evclust import STARTED

    total = time.perf_counter() - STARTED
    ready = result.startup.seconds if result.startup else 0.0
    parts = [f"compiled code {ready:.2f} s"] if result.startup else []
    parts += [f"event loop {result.wall_s:.2f} s", f"the rest (imports, opening and writing files) {total - ready - result.wall_s:.2f} s"]
    return f"time: {total:.2f} s since evclust was imported: " + ", ".join(parts)


def print_ranges(clusterer) -> None:
    table = clusterer.table
    print(f"{'signal':<20} {'format':<9} {'range of the format':<24} {'seen':<26} saturations")
    for name, lo, hi, sat in clusterer.range_report():
        fmt = table[{"centre_step": "centre_step", "mcm_step": "v_mcm"}.get(name, name)]
        print(f"{name:<20} {fmt.q:<9} {f'{fmt.min:g}..{fmt.max:g}':<24} {f'{lo:.6g}..{hi:.6g}':<26} {sat}")
