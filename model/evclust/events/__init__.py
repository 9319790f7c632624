"""Events: one structured dtype everywhere, files in .npz and HDF5, validated on read."""

from evclust.events.format import EVENT_DTYPE, COLOUR_FIELDS, EventMeta, concat_events, empty_events, sort_events
from evclust.events.io import read_events, write_events
from evclust.events.validate import validate_events

__all__ = [
    "EVENT_DTYPE",
    "COLOUR_FIELDS",
    "EventMeta",
    "concat_events",
    "empty_events",
    "sort_events",
    "read_events",
    "write_events",
    "validate_events",
]
