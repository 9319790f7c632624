"""Track files as CSV: one leading comment line holding the metadata as JSON, then a header
line and one record per line, appended chunk by chunk."""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path

import numpy as np

from evclust.errors import EvclustError
from evclust.tracks.record import TrackMeta

INTEGER_FIELDS = {"t_us", "step", "slot", "id", "class", "flags", "members"}  # written as integers, read as such
MAGIC = "# evclust-tracks "  # the first line's start; the metadata follows as JSON


def _format(value, integer: bool) -> str:
    return str(int(value)) if integer else f"{float(value):.6g}"


class CsvTrackWriter:
    """Records as CSV, appended chunk by chunk."""

    def __init__(self, tmp: Path, meta: TrackMeta):
        self.fields = meta.dtype.names
        self.file = open(tmp, "w", newline="")
        self.file.write(MAGIC + meta.to_json() + "\n")
        self.file.write(",".join(self.fields) + "\n")
        self.integer = [name in INTEGER_FIELDS for name in self.fields]

    def write(self, tracks: np.ndarray) -> None:
        columns = [tracks[name].tolist() for name in self.fields]
        self.file.writelines(",".join(_format(v, i) for v, i in zip(row, self.integer)) + "\n" for row in zip(*columns))

    def close(self) -> None:
        self.file.close()


def read_csv_tracks(path: Path) -> tuple[np.ndarray, TrackMeta]:
    try:
        text = path.read_text()
    except UnicodeDecodeError as exc:
        raise EvclustError(f"{path}: not a text track file ({exc.reason} at byte {exc.start})") from None
    first, _, rest = text.partition("\n")
    if not first.startswith(MAGIC):
        raise EvclustError(f"{path}: not an evclust track file (its first line must start with '{MAGIC.strip()}')")
    try:
        data = json.loads(first[len(MAGIC) :])
        if not isinstance(data, dict):
            raise TypeError("metadata is not a JSON object")
        meta = TrackMeta.from_dict(data)
    except (json.JSONDecodeError, TypeError, ValueError) as exc:
        raise EvclustError(f"{path}: line 1: unreadable metadata ({exc})") from None
    reader = csv.reader(io.StringIO(rest))
    header = next(reader, None)
    if header is None:
        raise EvclustError(f"{path}: no header line")
    dtype = meta.dtype
    fields = dtype.names
    missing = [name for name in fields if name not in header]
    if missing:
        raise EvclustError(f"{path}: missing column(s) {', '.join(missing)}")
    index = [header.index(name) for name in fields]
    limits = {name: np.iinfo(dtype[name]) for name in INTEGER_FIELDS if name in fields}
    rows = []
    for line_no, row in enumerate(reader, start=3):
        if not row:
            continue
        try:
            values = tuple(float(row[i]) if name not in INTEGER_FIELDS else int(row[i]) for i, name in zip(index, fields))
        except (ValueError, IndexError):
            raise EvclustError(f"{path}: line {line_no}: not a track record: {','.join(row)[:80]}") from None
        for name, value in zip(fields, values):
            if name in limits and not limits[name].min <= value <= limits[name].max:
                raise EvclustError(f"{path}: line {line_no}: {name}={value} does not fit {dtype[name]}")
            if name not in limits and not np.isfinite(value):
                raise EvclustError(f"{path}: line {line_no}: {name} is {value}")
        rows.append(values)
    return np.array(rows, dtype=dtype), meta
