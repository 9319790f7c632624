"""Events: one structured dtype everywhere; files in .npz, HDF5, AEDAT4, EVT2/3, DAT, ES, AEDAT 2.0 and text, read and
written in chunks, validated on read."""

from evclust.events.format import EVENT_DTYPE, COLOUR_FIELDS, EventMeta, concat_events, empty_events, sort_events
from evclust.events.io import CHUNK, SUFFIXES, EventReader, event_writer, read_events, write_events
from evclust.events.validate import validate_events

__all__ = [
    "EVENT_DTYPE",
    "COLOUR_FIELDS",
    "EventMeta",
    "concat_events",
    "empty_events",
    "sort_events",
    "CHUNK",
    "SUFFIXES",
    "EventReader",
    "event_writer",
    "read_events",
    "write_events",
    "validate_events",
]
