"""Packing events, track records and trace entries into fixed-width hex words, MSB first, in the
layouts of evclust.fixed.layouts."""

from __future__ import annotations

import math

import numpy as np

from evclust.fixed.formats import FormatTable
from evclust.fixed.layouts import event_fields, object_fields, record_fields
from evclust.tracks import OBJECT_DTYPE, TRACK_DTYPE


def pack(values, fields) -> int:
    """Concatenate field values (ints), MSB first; signed fields in two's complement."""
    word = 0
    for value, (name, width, signed, *_) in zip(values, fields):
        value = int(value)
        lo, hi = (-(1 << (width - 1)), (1 << (width - 1)) - 1) if signed else (0, (1 << width) - 1)
        if not lo <= value <= hi:
            raise ValueError(f"field {name}={value} does not fit {width} bits{' signed' if signed else ''}")
        word = (word << width) | (value & ((1 << width) - 1))
    return word


def unpack(word: int, fields) -> list[int]:
    values = []
    for _name, width, signed, *_ in reversed(fields):
        v = word & ((1 << width) - 1)
        word >>= width
        if signed and v >> (width - 1):
            v -= 1 << width
        values.append(v)
    return values[::-1]


def hex_lines(words, fields) -> str:
    digits = math.ceil(sum(f[1] for f in fields) / 4)
    return "".join(f"{w:0{digits}x}\n" for w in words)


def event_words(events: np.ndarray, table: FormatTable) -> list[int]:
    fields = event_fields(table)
    t = (events["t"] & np.uint64(0xFFFFFFFF)).tolist()
    cols = zip(t, events["x"].tolist(), events["y"].tolist(), (events["p"] > 0).astype(int).tolist(),
               events["Y"].tolist(), events["Cb"].tolist(), events["Cr"].tolist())  # fmt: skip
    return [pack(row, fields) for row in cols]


def record_rows(words, table: FormatTable) -> np.ndarray:
    """Record words (the RTL's) as the fixed model's record rows: each field in its real units."""
    fields = record_fields(table)
    scale = np.array([2.0**-frac for *_, frac in fields])
    rows = np.array([unpack(int(word), fields) for word in words], dtype=np.float64).reshape(-1, len(fields))
    return rows * scale


def object_rows(words, table: FormatTable) -> np.ndarray:
    """Object record words (the RTL's) as the fixed model's object record rows, in real units."""
    fields = object_fields(table)
    scale = np.array([2.0**-frac for *_, frac in fields])
    rows = np.array([unpack(int(word), fields) for word in words], dtype=np.float64).reshape(-1, len(fields))
    return rows * scale


def record_words(tracks: np.ndarray, table: FormatTable) -> list[int]:
    """Cluster records (values converted from their formats) back to raw integers, exactly."""
    return _words(tracks, record_fields(table), TRACK_DTYPE)


def object_words(objects: np.ndarray, table: FormatTable) -> list[int]:
    """Object records back to the raw integers of the object unit's words, exactly."""
    return _words(objects, object_fields(table), OBJECT_DTYPE)


def _words(tracks: np.ndarray, fields, dtype: np.dtype) -> list[int]:
    assert tuple(f[0] for f in fields) == dtype.names
    raws = []
    for name, _, _, frac in fields:
        column = tracks[name].astype(np.float64) * 2.0**frac
        if name == "t_us":  # the RTL's record carries the time's low 32 bits, as its counter does
            column = np.mod(column, 2.0**32)
        raw = np.rint(column)
        if not np.array_equal(raw, column):
            raise ValueError(f"record field {name} is not a whole number of LSBs")
        raws.append(raw.astype(np.int64).tolist())
    return [pack(row, fields) for row in zip(*raws)]
