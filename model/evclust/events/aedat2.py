"""jAER's AEDAT 2.0 (`.aedat`) from a DVS128 or eDVS128: a small reader and writer.

No maintained Python library streams it (faery, aedat and dv-processing read AEDAT 4 only; evlib
reads it into one Polars frame, a test dependency here), so it is decoded here (docs/DESIGN.md).

Layout (jAER's AEFileInputStream and DVS128.Extractor, github.com/SensorsINI/jaer,
src/ch/unizh/ini/jaer/chip/retina/DVS128.java):
- a text header of lines starting with `#`, the first `#!AER-DAT2.0`, each ending in CR LF;
- then 8-byte records, big-endian: a 32-bit address, then a 32-bit timestamp in µs;
- address bits: 0 = polarity, 0 for ON (the extractor flips it: `type = 1 - addr & 1`);
  1-7 = column, mirrored (`x = 127 - (addr & 0xFE) >> 1`); 8-14 = row counted from the
  bottom (`y = (addr & 0x7F00) >> 8`, which jAER draws upwards); bit 15 (sync) or bit 31
  (special) mark an event that is not a pixel's.
evclust counts rows from the top, so a pixel event becomes x = 127 - column, y = 127 - row;
special events are skipped. The 32-bit timestamps wrap every 71.6 minutes: a step back of more
than 2^31 µs is read as a wrap. The sensor is 128x128 (7-bit column and row).
"""

from __future__ import annotations

from pathlib import Path
from collections.abc import Iterator

import numpy as np

from evclust.errors import EvclustError
from evclust.events.format import EVENT_DTYPE, EventMeta

SUFFIXES = (".aedat",)
MAGIC = b"#!AER-DAT"
SIZE = 128
SPECIAL = np.uint32(0x8000 | 0x80000000)
RECORD = np.dtype([("address", ">u4"), ("t", ">u4")])
MAX_T = 1 << 32
HEADER_LIMIT = 1 << 20  # a header longer than 1 MiB is not a jAER header


def header(path: Path) -> tuple[int, str]:
    """(offset of the first record, version) after the `#` lines; refuses other versions."""
    with open(path, "rb") as f:
        first = f.readline(256)
        if not first.startswith(MAGIC):
            raise EvclustError(f"{path}: not an AEDAT file (no '#!AER-DAT' first line)")
        version = first[len(MAGIC) :].strip().decode("ascii", "replace")
        if version != "2.0":
            raise EvclustError(f"{path}: AEDAT {version} is not read (AEDAT 2.0 from jAER is; convert AEDAT 3.1 with DV, or write .aedat4)")
        offset = len(first)
        while True:
            line = f.readline(HEADER_LIMIT)
            if not line.startswith(b"#"):
                return offset, version
            offset += len(line)
            if offset > HEADER_LIMIT:
                raise EvclustError(f"{path}: AEDAT header longer than {HEADER_LIMIT} bytes")


def aedat2_header(path: Path) -> tuple[dict, int | None]:
    offset, _ = header(path)
    size = path.stat().st_size - offset
    if size % RECORD.itemsize:
        raise EvclustError(f"{path}: the last event is cut short ({size % RECORD.itemsize} of its {RECORD.itemsize} bytes)")
    return {"width": SIZE, "height": SIZE, "source": path.stem, "has_colour": False}, None


def aedat2_chunks(path: Path, size: int) -> Iterator[np.ndarray]:
    offset, _ = header(path)
    records = np.memmap(path, RECORD, mode="r", offset=offset) if path.stat().st_size > offset else np.zeros(0, RECORD)
    wraps, last = 0, None
    for lo in range(0, records.size, size):
        block = records[lo : lo + size]
        address = block["address"].astype(np.uint32)
        t = block["t"].astype(np.int64)
        keep = (address & SPECIAL) == 0
        address, t = address[keep], t[keep]
        if not t.size:
            continue
        # Wraps: a step back of more than half the clock.
        previous = np.concatenate([[t[0] if last is None else last], t[:-1]])
        step = np.cumsum(t - previous < -(1 << 31)) + wraps
        last, wraps = int(t[-1]), int(step[-1])
        ev = np.zeros(t.size, EVENT_DTYPE)
        ev["t"] = t + step * MAX_T
        ev["x"] = SIZE - 1 - ((address >> 1) & 0x7F)
        ev["y"] = SIZE - 1 - ((address >> 8) & 0x7F)
        ev["p"] = np.where(address & 1, -1, 1)
        yield ev


class Aedat2Writer:
    """DVS128 records from events on a sensor of at most 128x128 and t below 2^32 µs."""

    def __init__(self, tmp: Path, meta: EventMeta):
        if meta.width > SIZE or meta.height > SIZE:
            raise EvclustError(f"a {meta.width}x{meta.height} sensor: AEDAT 2.0 (DVS128 layout) holds at most {SIZE}x{SIZE}")
        self.file = open(tmp, "wb")
        self.file.write(
            b"#!AER-DAT2.0\r\n"
            b"# This is a raw AE data file created by evclust\r\n"
            b"# Data format is int32 address, int32 timestamp (8 bytes total), repeated for each event\r\n"
            b"# Timestamps tick is 1 us\r\n"
            b"# AEChip: ch.unizh.ini.jaer.chip.retina.DVS128\r\n"
        )

    def write(self, ev: np.ndarray) -> None:
        if not ev.size:
            return
        if int(ev["t"][-1]) >= MAX_T:
            i = int(np.flatnonzero(ev["t"] >= MAX_T)[0])
            raise EvclustError(f"event at t={int(ev['t'][i])} us: AEDAT 2.0 stores 32-bit µs timestamps; write .aedat4 or .h5")
        records = np.empty(ev.size, RECORD)
        column = (SIZE - 1 - ev["x"].astype(np.uint32)) << 1
        row = (SIZE - 1 - ev["y"].astype(np.uint32)) << 8
        records["address"] = row | column | (ev["p"] < 0).astype(np.uint32)
        records["t"] = ev["t"]
        self.file.write(records.tobytes())

    def close(self, failed: bool = False) -> None:
        self.file.close()
