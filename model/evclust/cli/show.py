"""evclust show EVENTS -o picture.png"""

from __future__ import annotations

from evclust.cli.common import EVENT_FILES, add_event_file_options


def add_parser(sub) -> None:
    p = sub.add_parser(
        "show",
        help="draw a picture of an event file",
        description="Draw the ON/OFF events and their colours over a time window, and the event rate over the whole stream.",
    )
    p.add_argument("events", metavar="EVENTS", help=f"event file ({EVENT_FILES})")
    add_event_file_options(p)
    p.add_argument("-o", "--output", required=True, metavar="PICTURE", help="image to write (.png, .svg, .pdf)")
    p.add_argument("--t0", type=float, metavar="US", help="start of the window in µs (default: the busiest stretch)")
    p.add_argument("--span", type=float, metavar="US", help="length of the window in µs (default: three frames)")
    p.set_defaults(run=run)


def run(args) -> int:
    from evclust.events import read_events
    from evclust.render import draw_events

    events, meta = read_events(args.events, args.sensor_size, args.polarity)
    draw_events(events, meta, args.output, t0_us=args.t0, span_us=args.span)
    print(f"{args.output}: {events.size} events drawn")
    return 0
