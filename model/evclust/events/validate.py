"""Checks every reader runs: known fields, sorted time, coordinates inside the sensor."""

from __future__ import annotations

import numpy as np

from evclust.errors import EvclustError
from evclust.events.format import EventMeta


def validate_events(ev: np.ndarray, meta: EventMeta, name: str, offset: int = 0, previous=None) -> None:
    """Raise EvclustError naming `name`, the first faulty record and the fault.

    For a chunk of a longer stream, `offset` is the index of its first record in the stream and
    `previous` the record before it, so the seam between chunks is checked too.
    """
    if meta.width <= 0 or meta.height <= 0:
        raise EvclustError(f"{name}: sensor size {meta.width}x{meta.height} is not positive")
    if ev.size == 0:
        return
    if previous is not None:
        ev = np.concatenate([np.asarray([previous], dtype=ev.dtype), ev])
        offset -= 1
    bad_p = np.flatnonzero((ev["p"] != 1) & (ev["p"] != -1))
    if bad_p.size:
        i = int(bad_p[0])
        raise EvclustError(f"{name}: record {i + offset}: polarity {int(ev['p'][i])} is not +1 or -1")
    for axis, limit in (("x", meta.width), ("y", meta.height)):
        outside = np.flatnonzero(ev[axis] >= limit)
        if outside.size:
            i = int(outside[0])
            e = ev[i]
            raise EvclustError(
                f"{name}: record {i + offset}: {axis}={int(e[axis])} is outside the {meta.width}x{meta.height} sensor "
                f"(event t={int(e['t'])} us, x={int(e['x'])}, y={int(e['y'])}, p={int(e['p']):+d})"
            )
    t = ev["t"]
    back = np.flatnonzero(t[1:] < t[:-1])
    if back.size:
        i = int(back[0]) + 1
        raise EvclustError(f"{name}: record {i + offset}: t={int(t[i])} us is before the previous t={int(t[i - 1])} us")
    # Ties in time must be ordered by y then x, so every consumer sees the same stream.
    same_t = t[1:] == t[:-1]
    key = ev["y"].astype(np.int64) * 65536 + ev["x"]
    tie_back = np.flatnonzero(same_t & (key[1:] < key[:-1]))
    if tie_back.size:
        i = int(tie_back[0]) + 1
        raise EvclustError(f"{name}: record {i + offset}: events at the same t={int(t[i])} us are not ordered by y then x")
