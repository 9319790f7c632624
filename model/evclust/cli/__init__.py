"""`evclust` command line: thin verbs over the library. Bad input ends in one line and exit code 2."""

from __future__ import annotations

import argparse
import atexit
import os
import signal
import sys
import threading

from evclust import __version__
from evclust.cli import formats, generalize, plot, reference, render, report, scenes, score, show, simulate, track, tune, vectors
from evclust.cli.common import refuse_overwriting
from evclust.errors import EvclustError

VERBS = (simulate, track, score, reference, tune, formats, vectors, report, show, render, plot, scenes, generalize)


class Parser(argparse.ArgumentParser):
    """argparse with the CLI's promise: a usage error is one line ('evclust VERB --help' has the
    rest) and exit code 2. Sub-parsers are made of the same class."""

    def error(self, message: str):
        verb = self.prog.removeprefix("evclust").strip()
        print(f"evclust: error: {verb + ': ' if verb else ''}{message} (see '{self.prog} --help')", file=sys.stderr)
        raise SystemExit(2)


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(
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


class Terminated(KeyboardInterrupt):
    """SIGTERM, handled as Ctrl-C is: the run unwinds, so no temporary or partial file is left."""


def _terminate(signum, frame):
    raise Terminated


def _stop_readers() -> None:
    """Finish now the generators an interrupted run left suspended, and stop the background
    threads still running (the simulator's frame reader among them), which the interpreter's exit
    would otherwise kill inside OpenCV ("terminate called without an active exception", exit -6,
    not 130). Collecting the generators alone was not enough: one still referenced from the
    interrupt's traceback is not collected, and its reader ran on (a fresh-clone CI run at
    089ed178 ended so)."""
    import gc

    from evclust.threads import stop_background_threads

    gc.collect()
    stop_background_threads()


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help, --version, or a usage error already reported in one line
        return exc.code if isinstance(exc.code, int) else 2
    main_thread = threading.current_thread() is threading.main_thread()  # signal handlers live there only
    # SIGINT raises KeyboardInterrupt even where the process started with it ignored (a job put in
    # the background by a non-interactive shell, which Python would otherwise leave deaf to it).
    previous = (
        (signal.signal(signal.SIGTERM, _terminate), signal.signal(signal.SIGINT, signal.default_int_handler)) if main_thread else None
    )
    try:
        refuse_overwriting(args)
        return args.run(args) or 0
    except EvclustError as exc:
        print(f"evclust: error: {exc}", file=sys.stderr)
        return 2
    except Terminated:
        _stop_readers()
        print("evclust: terminated", file=sys.stderr)
        return 128 + signal.SIGTERM
    except KeyboardInterrupt:
        _stop_readers()
        print("evclust: interrupted", file=sys.stderr)
        return 130
    except OSError as exc:  # output folder not writable, disk full, ...
        print(f"evclust: error: {exc.filename or ''}: {exc.strerror or exc}", file=sys.stderr)
        return 2
    finally:
        if main_thread:
            signal.signal(signal.SIGTERM, previous[0])
            signal.signal(signal.SIGINT, previous[1])


def entry() -> None:
    """The `evclust` command: `main`, then out. By then every output file is closed; what Python
    would still do is run the exit handlers (done here) and then finalise every module and
    numba's and LLVM's objects, about half a second on a short `track`, which os._exit skips.
    A traceback (a bug) still leaves the ordinary way."""
    code = main()
    atexit._run_exitfuncs()  # logging, tqdm's monitor, multiprocessing's children, Yosys runs
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):  # a closed pipe: nothing more can be said on it
            code = code or 120  # what Python itself returns when the final flush fails
    os._exit(code)
