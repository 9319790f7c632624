"""evclust vectors [-o vectors] [--check] | evclust vectors --events FILE [--max-events N] [--replay SIM]"""

from __future__ import annotations

from pathlib import Path

from evclust.choices import SIMULATORS
from evclust.cli.common import preset_list

DEFAULT_MAX_EVENTS = 20_000  # about a minute under Icarus; raise it for a longer replay


def add_parser(sub) -> None:
    p = sub.add_parser(
        "vectors",
        help="write the golden vectors the RTL is checked against (built-in cases, or your own event file)",
        description=(
            "Run the fixed-point model on every vector case (clips of the built-in scenes and directed hard "
            "cases) and write vectors/<case>/ with manifest.json, events.hex, expected.hex and trace.hex "
            "(vectors/README.md documents the formats). Regeneration is bit-identical; --check only compares. "
            "With --events, write one case from the first events of any event file instead, and with --replay "
            "run it through the RTL at once."
        ),
    )
    p.add_argument("-o", "--output", default="vectors", metavar="DIR", help="folder of the cases (default: vectors)")
    p.add_argument("--check", action="store_true", help="do not write: fail if a committed case differs from the model")
    own = p.add_argument_group("vectors from your own events")
    own.add_argument("--events", metavar="FILE", help="event file with colour (.npz, .h5, ...): write DIR/<its name>/")
    own.add_argument(
        "--max-events",
        type=int,
        default=DEFAULT_MAX_EVENTS,
        metavar="N",
        help=f"events to take from the start (default: {DEFAULT_MAX_EVENTS})",
    )
    own.add_argument("--params", metavar="P", help=f"parameter file (.toml) or preset ({preset_list()}); default as for 'evclust track'")
    own.add_argument("--frame-us", type=float, metavar="US", help="frame period in µs (default: the event file's)")
    own.add_argument(
        "--replay", choices=SIMULATORS, help="then replay the case through the RTL under this simulator (a repository checkout)"
    )
    p.set_defaults(run=run)


def run(args) -> int:
    from evclust.errors import EvclustError

    own = args.events is not None
    if not own and (args.replay or args.params or args.frame_us is not None or args.max_events != DEFAULT_MAX_EVENTS):
        raise EvclustError("--max-events, --params, --frame-us and --replay go with --events FILE")
    if own:
        if args.check:
            raise EvclustError("--check compares the built-in cases; it does not go with --events")
        return _own_case(args)
    from evclust.vectors import CASES, check_vectors, write_vectors

    root = Path(args.output)
    if args.check:
        stale = check_vectors(root)
        if stale:
            raise EvclustError(f"{root}: {len(stale)} stale vector file(s), e.g. {stale[0]}: run `make vectors`")
        print(f"{root}: {len(CASES)} cases up to date")
        return 0
    manifests = write_vectors(root)
    events = sum(m["counts"]["events"] for m in manifests.values())
    records = sum(m["counts"]["records"] for m in manifests.values())
    print(f"{root}: {len(manifests)} cases, {events} events, {records} expected records")
    return 0


def _own_case(args) -> int:
    import shutil
    import tempfile

    from evclust.clusterer import load_params
    from evclust.errors import EvclustError
    from evclust.events import EventReader
    from evclust.vectors import write_case
    from evclust.vectors.cases import file_case

    if args.max_events < 1:
        raise EvclustError(f"--max-events {args.max_events}: at least one event")
    if args.frame_us is not None and not 0 < args.frame_us < float("inf"):
        raise EvclustError(f"--frame-us {args.frame_us}: the frame period must be positive")
    params, origin = load_params(args.params, EventReader(args.events).meta.source)
    case = file_case(args.events, args.max_events, params, args.frame_us)
    name = Path(args.events).stem
    folder = Path(args.output) / name
    # Written beside, then moved: a failure leaves no half-written case.
    folder.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=folder.parent, prefix=f".{name}.") as tmp:
        manifest = write_case(name, Path(tmp) / name, case)
        if folder.exists():
            shutil.rmtree(folder)
        shutil.move(str(Path(tmp) / name), folder)
    counts = manifest["counts"]
    print(f"{folder}: {counts['events']} events of {args.events} (parameters from {origin}), {counts['records']} expected records")
    if args.replay:
        from evclust.rtl.cosim import run as run_rtl
        from evclust.vectors.read import load_case

        config = {"cases": [str(folder.resolve())], "seed": 1, "gap": 0, "stall": 0}  # the path whole: the simulator runs elsewhere
        result = run_rtl(args.replay, load_case(folder).header, "replay_vectors", config)
        stats = result["cases"][name]
        print(f"{folder}: RTL ({args.replay}) matches the fixed model bit for bit: {stats['records']} records; {stats}")
    return 0
