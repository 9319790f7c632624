"""evclust render EVENTS TRACKS -o video.mp4|frame.png"""

from __future__ import annotations

import math
from pathlib import Path

from evclust.cli.common import EVENT_FILES, add_event_file_options
from evclust.errors import EvclustError


def add_parser(sub) -> None:
    p = sub.add_parser(
        "render",
        help="draw tracks over their events, as a video or one frame",
        description=(
            "Draw the events of a sliding window in the colour they carry and, over them, the track records of "
            "the latest filter step in the window: cluster box (red), seek region (green), centre (orange), "
            "MCM velocity (blue), interval velocity (yellow), estimated colour swatch, id and class. "
            "An .mp4 gets one frame per frame period from t0 to t1; a .png one frame at t1 "
            "(default: the end of the busiest window)."
        ),
    )
    p.add_argument(
        "events",
        metavar="EVENTS",
        help=f"event file ({EVENT_FILES}), or the scene or video the tracks came from (simulated again)",
    )
    p.add_argument("tracks", metavar="TRACKS", help="track file (tracks.csv from 'evclust track')")
    p.add_argument("-o", "--output", required=True, metavar="OUT", help="video (.mp4) or picture (.png) to write")
    p.add_argument("--t0", type=float, metavar="US", help="time of the first video frame in µs (default: the first frame with events)")
    p.add_argument("--t1", type=float, metavar="US", help="time of the last video frame, or of the picture, in µs")
    p.add_argument("--window", type=float, metavar="US", help="events drawn per frame: the last US µs (default: one frame period)")
    p.add_argument("--scale", type=int, default=2, metavar="K", help="upscaling of the sensor image (default: 2)")
    p.add_argument(
        "--arrow-frames", type=float, default=5.0, metavar="F", help="velocity arrows show the motion over F frames (default: 5)"
    )
    add_event_file_options(p)
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    p.set_defaults(run=run)


def run(args) -> int:
    from evclust.simulator.source import open_events
    from evclust.render.tracks import PNG_SUFFIXES, VIDEO_SUFFIXES, render_png, render_video
    from evclust.tracks import read_tracks

    out = Path(args.output)
    suffix = out.suffix.lower()
    if suffix not in VIDEO_SUFFIXES + PNG_SUFFIXES:
        raise EvclustError(f"{out}: the output must be a video (.mp4) or a picture (.png), not '{out.suffix or '(none)'}'")
    if args.window is not None and not 0 < args.window < math.inf:
        raise EvclustError(f"--window {args.window:g}: must be a positive number of µs")
    if not 1 <= args.scale <= 16:
        raise EvclustError(f"--scale {args.scale}: must be an integer from 1 to 16")
    if not args.arrow_frames >= 0:
        raise EvclustError(f"--arrow-frames {args.arrow_frames:g}: must not be negative")
    for name in ("t0", "t1"):
        value = getattr(args, name)
        if value is not None and not 0 <= value < math.inf:
            raise EvclustError(f"--{name} {value:g}: must be a finite time in µs, >= 0")
    source = open_events(args.events, sensor_size=args.sensor_size, polarity=args.polarity)
    events, ev_meta = source.read(), source.meta
    tracks, track_meta = read_tracks(args.tracks)
    common = dict(window_us=args.window, scale=args.scale, arrow_frames=args.arrow_frames)
    if suffix in VIDEO_SUFFIXES:
        n = render_video(
            events, ev_meta, tracks, track_meta, out, t0_us=args.t0, t1_us=args.t1, progress=False if args.quiet else None, **common
        )
        print(f"{out}: {n} frames")
    else:
        t = render_png(events, ev_meta, tracks, track_meta, out, t_us=args.t1, **common)
        print(f"{out}: frame at t={t / 1e6:.6f} s")
    return 0
