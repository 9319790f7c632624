"""The event record (SPEC §2) and the metadata every event file carries."""

from __future__ import annotations

import dataclasses
import json
import math

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
LOOP_FIELDS = ("t", "x", "y", "Y", "Cb", "Cr")  # what the clusterers' compiled loops read


def loop_columns(events: np.ndarray) -> tuple[np.ndarray, ...]:
    """The columns a compiled clusterer loop reads, each C-contiguous, writable and of its
    EVENT_DTYPE type. numba compiles a loop once per argument layout, and a loop takes 45 s (float)
    to 75 s (fixed) to compile: a record array's strided fields, a read-only map and contiguous
    columns each compiled it again (numba's cache held five specialisations of each loop). The
    copy is of six columns per call, outside the per-event loop."""
    return tuple(np.require(events[name], EVENT_DTYPE[name], "CW") for name in LOOP_FIELDS)


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
    def from_dict(cls, d: dict) -> EventMeta:
        """From a file's metadata, checked: EvclustError names the first value out of place."""
        known = {f.name for f in dataclasses.fields(cls)}
        meta = cls(**{k: v for k, v in d.items() if k in known})
        meta.check()
        return meta

    def check(self) -> None:
        """Types and ranges a stream can be run with; a sensor beyond the limit (limits.py:
        EVCLUST_MAX_SENSOR_PIXELS, default 2^25) is refused before anything is allocated."""
        from evclust import limits
        from evclust.errors import EvclustError

        for key in ("width", "height"):
            value = getattr(self, key)
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not 1 <= value <= MAX_SENSOR_SIDE:
                raise EvclustError(f"metadata: sensor {key} {value!r}: expected a whole number of pixels from 1 to {MAX_SENSOR_SIDE}")
        limits.check("SENSOR_PIXELS", int(self.width) * int(self.height), f"metadata: a {self.width}x{self.height} sensor's pixels")
        t = self.t_frame_us
        if t is not None and (isinstance(t, bool) or not isinstance(t, (int, float, np.integer, np.floating)) or not 0 < t < math.inf):
            raise EvclustError(f"metadata: t_frame_us {t!r}: expected a positive, finite frame period in µs")
        if not isinstance(self.source, str):
            raise EvclustError(f"metadata: source {self.source!r}: expected text")
        if not isinstance(self.has_colour, (bool, np.bool_)):
            raise EvclustError(f"metadata: has_colour {self.has_colour!r}: expected true or false")


# x and y are 16-bit; a sensor's pixel count is bounded by limits.SENSOR_PIXELS.
MAX_SENSOR_SIDE = 65535


_RECORD = np.dtype((np.void, EVENT_DTYPE.itemsize))


def concat_events(chunks) -> np.ndarray:
    """Concatenate event arrays. Copied as opaque records: numpy's field-by-field copy of a
    structured dtype is about ten times slower."""
    chunks = list(chunks)
    if not chunks:
        return empty_events()
    return np.concatenate([c.view(_RECORD) for c in chunks]).view(EVENT_DTYPE)


def empty_events(n: int = 0) -> np.ndarray:
    return np.zeros(n, dtype=EVENT_DTYPE)


def sort_events(ev: np.ndarray) -> np.ndarray:
    """Order by time, ties by y then x (SPEC §2), keeping the order of equal keys.

    Up to 2^32 µs (71 minutes) the three keys pack into one uint64, and one stable sort of it is
    several times faster than a three-key lexsort, above all on the nearly sorted streams that
    effects produce.
    """
    if ev.size < 2:
        return ev
    t = ev["t"]
    if int(t.max()) < 1 << 32:
        key = (t << np.uint64(32)) | (ev["y"].astype(np.uint64) << np.uint64(16)) | ev["x"].astype(np.uint64)
        return ev[np.argsort(key, kind="stable")]
    return ev[np.lexsort((ev["x"], ev["y"], t))]
