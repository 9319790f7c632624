"""The two record kinds and their metadata (track files: `files`, CSV in `text`, Parquet in
`columnar`).

Cluster records (TRACK_DTYPE) are the event-rate clusterer's, one per reported cluster per
filter step; object records (OBJECT_DTYPE) are the object layer's, one per reported object per
filter step. Columns that mean the same have the same names. A file holds one kind, named in
its metadata (`TrackMeta.kind`)."""

from __future__ import annotations

import dataclasses
import enum
import json

import numpy as np


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
