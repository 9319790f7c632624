"""The two record kinds, their metadata, and track files: CSV here, Parquet in `columnar`.

Cluster records (TRACK_DTYPE) are the event-rate clusterer's, one per reported cluster per
filter step; object records (OBJECT_DTYPE) are the object layer's, one per reported object per
filter step. Columns that mean the same have the same names. A file holds one kind, named in
its metadata (`TrackMeta.kind`)."""

from __future__ import annotations

import contextlib
import csv
import dataclasses
import enum
import io
import json
from pathlib import Path

import numpy as np

from evclust.errors import EvclustError, atomic_output

TRACK_DTYPE = np.dtype(
    [
        ("t_us", np.uint64),  # time of the filter step (the event that triggered it)
        ("step", np.uint32),  # filter step index, from 0
        ("slot", np.uint16),  # cluster table slot
        ("id", np.uint32),  # unique, increasing cluster id
        ("x", np.float64),  # centre, px (pixel-index coordinates)
        ("y", np.float64),
        ("rx", np.float64),  # half-size, px
        ("ry", np.float64),
        ("activity", np.float64),  # decayed event count
        ("vx_mcm", np.float64),  # mean-centre-motion velocity, px/frame
        ("vy_mcm", np.float64),
        ("vx_int", np.float64),  # regular-interval velocity, px/frame
        ("vy_int", np.float64),
        ("Y", np.float64),  # object colour after background correction, 0..255
        ("Cb", np.float64),
        ("Cr", np.float64),
        ("class", np.int16),  # palette index of the histogram's argmax (non-background); -1: none
        ("flags", np.uint16),  # TrackFlags
    ]
)
TRACK_FIELDS = TRACK_DTYPE.names
OBJECT_DTYPE = np.dtype(
    [
        ("t_us", np.uint64),  # time of the filter step
        ("step", np.uint32),  # filter step index, from 0
        ("slot", np.uint16),  # object table slot
        ("id", np.uint32),  # unique, increasing object id
        ("x", np.float64),  # centre, px (pixel-index coordinates)
        ("y", np.float64),
        ("rx", np.float64),  # half-size of the box, px
        ("ry", np.float64),
        ("vx", np.float64),  # velocity, px/frame
        ("vy", np.float64),
        ("Y", np.float64),  # object colour, 0..255
        ("Cb", np.float64),
        ("Cr", np.float64),
        ("class", np.int16),  # palette index; -1: none
        ("members", np.uint16),  # clusters that joined it at this step (0: coasting)
        ("flags", np.uint16),  # ObjectFlags
    ]
)
OBJECT_FIELDS = OBJECT_DTYPE.names
RECORD_KINDS = ("clusters", "objects")
RECORD_DTYPES = {"clusters": TRACK_DTYPE, "objects": OBJECT_DTYPE}
# The velocity estimates of each kind, by method: (name, vx field, vy field).
VELOCITY_METHODS = {
    "clusters": (("mcm", "vx_mcm", "vy_mcm"), ("interval", "vx_int", "vy_int")),
    "objects": (("object", "vx", "vy"),),
}
_INTEGER_FIELDS = {"t_us", "step", "slot", "id", "class", "flags", "members"}
MAGIC = "# evclust-tracks "
TRACK_SUFFIXES = (".csv", ".parquet")


def record_kind(records: np.ndarray) -> str:
    """ "clusters" or "objects", from a record array's fields."""
    return "objects" if "members" in (np.asarray(records).dtype.names or ()) else "clusters"


class TrackFlags(enum.IntFlag):
    NEW = 1  # first record of this id
    BORDER = 2  # centre within exit_margin of a border
    MOVING_MCM = 4  # uncorrected |V_mcm| >= v_min (the evidence the noise filter weighs)
    MOVING_INT = 8  # |V_int| >= v_min


class ObjectFlags(enum.IntFlag):
    NEW = 1  # first record of this id
    COASTING = 2  # no cluster joined it at this step: its position is predicted


@dataclasses.dataclass(frozen=True)
class TrackMeta:
    """What a track file needs beside its rows."""

    width: int
    height: int
    t_frame_us: float
    source: str = ""  # the event file's source (scene name or video)
    model: str = "float"  # float | fixed | rtl
    palette: tuple[str, ...] = ()  # palette entry names, by class index
    palette_ycbcr: tuple[tuple[float, float, float], ...] = ()  # the entries' colours
    palette_background: tuple[str, ...] = ()  # entries that are background, never a class
    luma_weight: float = 1.0  # weight of |ΔY| in the palette's L1 distance
    seek_margin: float = 0.0  # S: the seek region is the box grown by S on every side, px
    seek_scale: float = 0.0  # ... plus seek_scale·max(rx, ry) (beyond the paper)
    exit_margin: float = 0.0  # M: the border band where exit prediction acts, px
    has_colour: bool = True
    per_frame: bool = False  # thinned to one record per cluster or object per frame (evclust.tracks.thin)
    kind: str = "clusters"  # the records: "clusters" (TRACK_DTYPE) or "objects" (OBJECT_DTYPE)

    @property
    def dtype(self) -> np.dtype:
        return RECORD_DTYPES[self.kind]

    def to_json(self) -> str:
        return json.dumps(dataclasses.asdict(self), sort_keys=True)

    @classmethod
    def from_dict(cls, d: dict) -> TrackMeta:
        known = {f.name for f in dataclasses.fields(cls)}
        d = {k: v for k, v in d.items() if k in known}
        if d.get("kind", "clusters") not in RECORD_KINDS:
            raise ValueError(f"unknown record kind {d['kind']!r} (expected {' or '.join(RECORD_KINDS)})")
        for key in ("palette", "palette_background"):
            if key in d:
                d[key] = tuple(d[key])
        if "palette_ycbcr" in d:
            d["palette_ycbcr"] = tuple(tuple(float(c) for c in e) for e in d["palette_ycbcr"])
        return cls(**d)


def _format(value, integer: bool) -> str:
    return str(int(value)) if integer else f"{float(value):.6g}"


class CsvTrackWriter:
    """Records as CSV, appended chunk by chunk."""

    def __init__(self, tmp: Path, meta: TrackMeta):
        self.fields = meta.dtype.names
        self.file = open(tmp, "w", newline="")
        self.file.write(MAGIC + meta.to_json() + "\n")
        self.file.write(",".join(self.fields) + "\n")
        self.integer = [name in _INTEGER_FIELDS for name in self.fields]

    def write(self, tracks: np.ndarray) -> None:
        columns = [tracks[name].tolist() for name in self.fields]
        self.file.writelines(",".join(_format(v, i) for v, i in zip(row, self.integer)) + "\n" for row in zip(*columns))

    def close(self) -> None:
        self.file.close()


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
    return _read_csv_tracks(path)


def _read_csv_tracks(path: Path) -> tuple[np.ndarray, TrackMeta]:
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
    limits = {name: np.iinfo(dtype[name]) for name in _INTEGER_FIELDS if name in fields}
    rows = []
    for line_no, row in enumerate(reader, start=3):
        if not row:
            continue
        try:
            values = tuple(float(row[i]) if name not in _INTEGER_FIELDS else int(row[i]) for i, name in zip(index, fields))
        except (ValueError, IndexError):
            raise EvclustError(f"{path}: line {line_no}: not a track record: {','.join(row)[:80]}") from None
        for name, value in zip(fields, values):
            if name in limits and not limits[name].min <= value <= limits[name].max:
                raise EvclustError(f"{path}: line {line_no}: {name}={value} does not fit {dtype[name]}")
            if name not in limits and not np.isfinite(value):
                raise EvclustError(f"{path}: line {line_no}: {name} is {value}")
        rows.append(values)
    return np.array(rows, dtype=dtype), meta
