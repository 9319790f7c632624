"""The clusterer (SPEC §4): events in, track records out. Models: float (the algorithm); the
bit-accurate fixed model and the RTL implement the same interface, and evclust.run drives any
of the three by name."""

from evclust.clusterer.params import ClustererParams, PaletteEntry, load_params, parse_params, preset_names
from evclust.clusterer.run import FloatClusterer

__all__ = [
    "ClustererParams",
    "FloatClusterer",
    "PaletteEntry",
    "load_params",
    "parse_params",
    "preset_names",
]
