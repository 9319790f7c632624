"""What several verbs' parsers share. Nothing here imports the library: `evclust --help` builds
every parser, and must not pay for numba, OpenCV or the models."""

from __future__ import annotations

from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1]


def preset_list() -> str:
    """The clusterer presets' names, from the files (the same list `load_params` accepts)."""
    return ", ".join(sorted(p.stem for p in (PACKAGE / "clusterer" / "presets").glob("*.toml")))
