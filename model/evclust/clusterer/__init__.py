"""The clusterer (SPEC §4): events in, track records out. Models: float (the algorithm); the
bit-accurate fixed model and the RTL implement the same interface."""

from evclust.clusterer.params import ClustererParams, PaletteEntry, load_params, parse_params, preset_names
from evclust.clusterer.run import FloatClusterer, TrackRun, track_events

__all__ = [
    "ClustererParams",
    "FloatClusterer",
    "PaletteEntry",
    "TrackRun",
    "load_params",
    "parse_params",
    "preset_names",
    "track_events",
]
