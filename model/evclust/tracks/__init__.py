"""The track record (SPEC §4): one row per reported cluster per filter step.

The same fields are the float model's, the fixed model's and the RTL's output. Files are CSV with
one leading comment line holding the metadata as JSON (`# evclust-tracks {...}`), or Parquet with
the same JSON in the schema metadata; both are written chunk by chunk.
"""

from evclust.tracks.record import (
    TRACK_DTYPE,
    TRACK_FIELDS,
    TRACK_SUFFIXES,
    TrackFlags,
    TrackMeta,
    read_tracks,
    track_writer,
    write_tracks,
)

__all__ = [
    "TRACK_DTYPE",
    "TRACK_FIELDS",
    "TRACK_SUFFIXES",
    "TrackFlags",
    "TrackMeta",
    "read_tracks",
    "track_writer",
    "write_tracks",
]
