"""Track files by suffix (.csv: `text`, .parquet: `columnar`): a checked, atomic writer and a
reader, the one entry point the rest of the project uses."""

from __future__ import annotations

import contextlib
from pathlib import Path

import numpy as np

from evclust.errors import EvclustError, atomic_output
from evclust.tracks.record import OBJECT_DTYPE, TRACK_SUFFIXES, TrackMeta
from evclust.tracks.text import CsvTrackWriter, read_csv_tracks


def _writer_class(path: Path):
    suffix = path.suffix.lower()
    if suffix == ".csv":
        return CsvTrackWriter
    if suffix == ".parquet":
        from evclust.tracks.columnar import ParquetTrackWriter

        return ParquetTrackWriter
    raise EvclustError(f"{path}: unknown track file type '{suffix}' (use {', '.join(TRACK_SUFFIXES)})")


@contextlib.contextmanager
def track_writer(path: str | Path, meta: TrackMeta):
    """Yield a writer with `.write(tracks)`; the file appears only if the block succeeds."""
    path = Path(path)
    cls = _writer_class(path)
    with atomic_output(path) as tmp:
        writer = cls(tmp, meta)
        try:
            yield _CheckedTrackWriter(writer, path, meta.dtype)
        finally:
            writer.close()


class _CheckedTrackWriter:
    def __init__(self, writer, path: Path, dtype: np.dtype):
        self.writer, self.path, self.dtype, self.count = writer, path, dtype, 0

    def write(self, tracks: np.ndarray) -> None:
        tracks = np.asarray(tracks)
        if tracks.dtype != self.dtype:
            raise EvclustError(
                f"{self.path}: records of dtype {tracks.dtype} are not {'object' if self.dtype == OBJECT_DTYPE else 'cluster'} records"
            )
        if tracks.size:
            self.writer.write(tracks)
            self.count += tracks.size


def write_tracks(path: str | Path, tracks: np.ndarray, meta: TrackMeta) -> None:
    with track_writer(path, meta) as writer:
        writer.write(tracks)


def read_tracks(path: str | Path) -> tuple[np.ndarray, TrackMeta]:
    """Read a track file (.csv or .parquet): (records, TrackMeta); the records are TRACK_DTYPE
    or OBJECT_DTYPE as `TrackMeta.kind` says."""
    path = Path(path)
    if not path.is_file():
        raise EvclustError(f"{path}: no such track file")
    if _writer_class(path) is not CsvTrackWriter:
        from evclust.tracks.columnar import read_parquet_tracks

        return read_parquet_tracks(path)
    return read_csv_tracks(path)
