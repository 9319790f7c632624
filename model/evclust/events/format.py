"""The event record (SPEC §2) and the metadata every event file carries."""

from __future__ import annotations

import dataclasses
import json

import numpy as np

# t in µs; x, y pixel indices; p = +1 ON / -1 OFF; Y, Cb, Cr: BT.601 full range (JPEG) of the
# intensity the TFS part of the pixel measured.
EVENT_DTYPE = np.dtype(
    [
        ("t", np.uint64),
        ("x", np.uint16),
        ("y", np.uint16),
        ("p", np.int8),
        ("Y", np.uint8),
        ("Cb", np.uint8),
        ("Cr", np.uint8),
    ]
)
COLOUR_FIELDS = ("Y", "Cb", "Cr")
DVS_FIELDS = ("t", "x", "y", "p")


@dataclasses.dataclass(frozen=True)
class EventMeta:
    """What a stream needs beside its records: the sensor size, where it came from, the frame period."""

    width: int
    height: int
    source: str = ""
    t_frame_us: float | None = None
    has_colour: bool = True

    def to_json(self) -> str:
        return json.dumps(dataclasses.asdict(self), sort_keys=True)

    @classmethod
    def from_dict(cls, d: dict) -> "EventMeta":
        known = {f.name for f in dataclasses.fields(cls)}
        return cls(**{k: v for k, v in d.items() if k in known})


def empty_events(n: int = 0) -> np.ndarray:
    return np.zeros(n, dtype=EVENT_DTYPE)


def sort_events(ev: np.ndarray) -> np.ndarray:
    """Order by time, ties by y then x (SPEC §2). Stable, so equal keys keep their order."""
    order = np.lexsort((ev["x"], ev["y"], ev["t"]))
    return ev[order]
