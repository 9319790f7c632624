"""Packing events, track records and trace entries into fixed-width hex words, MSB first."""

from __future__ import annotations

import math

import numpy as np

from evclust.fixed.formats import FormatTable
from evclust.tracks import OBJECT_DTYPE, TRACK_DTYPE

# (name, width, signed) per field; events and trace have fixed layouts apart from the coordinates.
TRACE_FIELDS = (("action", 3, False), ("slot", 8, False))  # action: 0 update, 1 create, 2 evict, 3 drop, 4 unsupported


def event_fields(table: FormatTable):
    xy = table["ev_xy"].word_bits
    return (("t", 32, False), ("x", xy, False), ("y", xy, False), ("on", 1, False), ("Y", 8, False), ("Cb", 8, False), ("Cr", 8, False))


def record_fields(table: FormatTable):
    """The track record as the RTL emits it: raw values in their formats."""
    f = table.formats
    slot_bits = max(1, math.ceil(math.log2(table.n_clusters)))
    return (
        ("t_us", 32, False, 0), ("step", 32, False, 0), ("slot", slot_bits, False, 0), ("id", 32, False, 0),
        ("x", f["centre"].word_bits, False, f["centre"].frac_bits), ("y", f["centre"].word_bits, False, f["centre"].frac_bits),
        ("rx", f["half_size"].word_bits, False, f["half_size"].frac_bits), ("ry", f["half_size"].word_bits, False, f["half_size"].frac_bits),
        ("activity", f["activity"].word_bits, False, f["activity"].frac_bits),
        ("vx_mcm", f["v_mcm"].word_bits, True, f["v_mcm"].frac_bits), ("vy_mcm", f["v_mcm"].word_bits, True, f["v_mcm"].frac_bits),
        ("vx_int", f["v_int"].word_bits, True, f["v_int"].frac_bits), ("vy_int", f["v_int"].word_bits, True, f["v_int"].frac_bits),
        ("Y", f["colour"].word_bits, False, f["colour"].frac_bits), ("Cb", f["colour"].word_bits, False, f["colour"].frac_bits),
        ("Cr", f["colour"].word_bits, False, f["colour"].frac_bits),
        ("class", 8, True, 0), ("flags", 4, False, 0),
    )  # fmt: skip


def object_fields(table: FormatTable):
    """The object record as the RTL's object unit emits it: raw values in their formats."""
    f = table.formats
    options = dict(table.options)
    slot_bits = max(1, math.ceil(math.log2(options["N_OBJECTS"])))
    members_bits = max(1, table.n_clusters.bit_length())
    return (
        ("t_us", 32, False, 0), ("step", 32, False, 0), ("slot", slot_bits, False, 0), ("id", 32, False, 0),
        ("x", f["obj_centre"].word_bits, True, f["obj_centre"].frac_bits), ("y", f["obj_centre"].word_bits, True, f["obj_centre"].frac_bits),
        ("rx", f["obj_half"].word_bits, False, f["obj_half"].frac_bits), ("ry", f["obj_half"].word_bits, False, f["obj_half"].frac_bits),
        ("vx", f["obj_velocity"].word_bits, True, f["obj_velocity"].frac_bits), ("vy", f["obj_velocity"].word_bits, True, f["obj_velocity"].frac_bits),
        ("Y", f["colour"].word_bits, False, f["colour"].frac_bits), ("Cb", f["colour"].word_bits, False, f["colour"].frac_bits),
        ("Cr", f["colour"].word_bits, False, f["colour"].frac_bits),
        ("class", 8, True, 0), ("members", members_bits, False, 0), ("flags", 2, False, 0),
    )  # fmt: skip


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
    for name, width, signed, *_ in reversed(fields):
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
