"""What several verbs' parsers share. Nothing here imports the library: `evclust --help` builds
every parser, and must not pay for numba, OpenCV or the models."""

from __future__ import annotations

from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1]


def preset_list() -> str:
    """The clusterer presets' names, from the files (the same list `load_params` accepts)."""
    return ", ".join(sorted(p.stem for p in (PACKAGE / "clusterer" / "presets").glob("*.toml")))


# Each verb's file arguments (argparse dests): those it reads and those it writes. An output that
# is one of the inputs, or another of the outputs, is refused before anything runs: the run
# would replace a file it reads, or one output would replace the other.
FILE_ARGUMENTS = {
    "simulate": (("scene",), ("output", "truth")),
    "track": (("events", "params"), ("output",)),
    "score": (("tracks", "truth"), ("json",)),
    "reference": (("video", "params"), ("output",)),
    "tune": (("scene", "params"), ("output",)),
    "formats": (("params", "write_for"), ("verilog", "rdl", "c_header", "registers", "ipxact")),
    "show": (("events",), ("output",)),
    "render": (("events", "tracks"), ("output",)),
    "plot": (("tracks", "truth", "events"), ("output",)),
    "generalize": ((), ("output",)),
}
POSITIONAL = ("scene", "events", "tracks", "video")


def _label(dest: str) -> str:
    if dest in POSITIONAL:
        return dest.upper()
    return "-o" if dest == "output" else "--" + dest.replace("_", "-")


def _same_file(a: Path, b: Path) -> bool:
    """One file by inode when both exist (links and symlinks too), else by resolved path."""
    import os

    if a.exists() and b.exists():
        return os.path.samefile(a, b)
    return a.resolve() == b.resolve()


def refuse_overwriting(args) -> None:
    """EvclustError when an output of this run is one of its inputs or another output. Special
    files (/dev/null, a FIFO) may take several outputs and are never replaced, so they pass."""
    import stat

    from evclust.errors import EvclustError

    inputs, outputs = FILE_ARGUMENTS.get(getattr(args, "verb", ""), ((), ()))
    taken = [(dest, Path(getattr(args, dest))) for dest in inputs if getattr(args, dest, None) and Path(getattr(args, dest)).is_file()]
    for dest in outputs:
        value = getattr(args, dest, None)
        if not value:
            continue
        path = Path(value)
        if path.exists() and not stat.S_ISREG(path.stat().st_mode):
            continue
        for other, other_path in taken:
            if _same_file(path, other_path):
                role = "an input" if other in inputs else "another output"
                raise EvclustError(f"{_label(dest)} {value}: is {role} of this run ({_label(other)} {other_path}); write it elsewhere")
        taken.append((dest, path))


EVENT_FILES = ".npz, .h5, .aedat4, .raw (EVT2/EVT3), .dat, .es, .aedat (AEDAT 2.0/3.1), .txt (t x y p, seconds), .csv"
POLARITY_CONVENTIONS = ("auto", "01", "pm1")


def sensor_size(text: str) -> tuple[int, int]:
    """argparse type for --sensor-size WxH."""
    import argparse

    width, sep, height = text.lower().partition("x")
    if (
        not sep
        or not width.strip().isdigit()
        or not height.strip().isdigit()
        or not (1 <= int(width) <= 65535 and 1 <= int(height) <= 65535)
    ):
        raise argparse.ArgumentTypeError(f"'{text}' is not a sensor size WxH in pixels, 1 to 65535 each (e.g. 346x260)")
    return int(width), int(height)


def add_event_file_options(p) -> None:
    """--sensor-size and --polarity, for verbs that read an event file."""
    p.add_argument(
        "--sensor-size",
        type=sensor_size,
        metavar="WxH",
        help="sensor size of an event file that gives none (.txt, .csv; .raw or .dat whose header lacks it); "
        "for a file that gives one it must agree",
    )
    p.add_argument(
        "--polarity",
        default="auto",
        choices=POLARITY_CONVENTIONS,
        help="polarity column of a text event file (.txt, .csv): 01 = 0 OFF / 1 ON, pm1 = -1 OFF / +1 ON, "
        "auto (default) = 1 ON, 0 or -1 OFF",
    )
