"""The records (SPEC §4): cluster records, one row per reported cluster per filter step, and
object records, one row per reported object per filter step.

The same fields are the float model's, the fixed model's and the RTL's output. Files are CSV with
one leading comment line holding the metadata as JSON (`# evclust-tracks {...}`), or Parquet with
the same JSON in the schema metadata; both are written chunk by chunk.
"""

from evclust.tracks.record import (
    OBJECT_DTYPE,
    OBJECT_FIELDS,
    RECORD_DTYPES,
    RECORD_KINDS,
    TRACK_DTYPE,
    TRACK_FIELDS,
    TRACK_SUFFIXES,
    VELOCITY_METHODS,
    ObjectFlags,
    TrackFlags,
    TrackMeta,
    record_kind,
)
from evclust.tracks.files import read_tracks, track_writer, write_tracks

__all__ = [
    "OBJECT_DTYPE",
    "OBJECT_FIELDS",
    "RECORD_DTYPES",
    "RECORD_KINDS",
    "TRACK_DTYPE",
    "TRACK_FIELDS",
    "TRACK_SUFFIXES",
    "VELOCITY_METHODS",
    "ObjectFlags",
    "TrackFlags",
    "TrackMeta",
    "read_tracks",
    "record_kind",
    "track_writer",
    "write_tracks",
]
