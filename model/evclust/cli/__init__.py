"""`evclust` command line: thin verbs over the library. Bad input ends in one line and exit code 2."""

from __future__ import annotations

import argparse
import sys

from evclust import __version__
from evclust.cli import formats, generalize, plot, reference, render, report, scenes, score, show, simulate, track, tune, vectors
from evclust.errors import EvclustError

VERBS = (simulate, track, score, reference, tune, formats, vectors, report, show, render, plot, scenes, generalize)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="evclust",
        description=(
            "Colour event camera simulator and event-by-event clusterer. "
            "Data flows scene -> simulate -> events -> track -> tracks -> score."
        ),
        epilog="Run 'evclust VERB --help' for the options of each verb.",
    )
    parser.add_argument("--version", action="version", version=f"evclust {__version__}")
    sub = parser.add_subparsers(dest="verb", metavar="VERB", required=True)
    for verb in VERBS:
        verb.add_parser(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return args.run(args) or 0
    except EvclustError as exc:
        print(f"evclust: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("evclust: interrupted", file=sys.stderr)
        return 130
    except OSError as exc:  # output folder not writable, disk full, ...
        print(f"evclust: error: {exc.filename or ''}: {exc.strerror or exc}", file=sys.stderr)
        return 2
