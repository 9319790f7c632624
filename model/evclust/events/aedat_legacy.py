"""jAER's AEDAT 2.0 and cAER's AEDAT 3.1 (`.aedat`): a small reader, and a writer for 2.0.

No maintained Python library streams them (faery, aedat and dv-processing read AEDAT 4 only; evlib
reads them into one Polars frame, a test dependency here), so they are decoded here
(docs/DESIGN.md, "Event-camera files").

AEDAT 2.0 (jAER's AEFileInputStream and DVS128.Extractor, github.com/SensorsINI/jaer,
src/ch/unizh/ini/jaer/chip/retina/DVS128.java), from a DVS128 or eDVS128:
- a text header of lines starting with `#`, the first `#!AER-DAT2.0`, each ending in CR LF;
- then 8-byte records, big-endian: a 32-bit address, then a 32-bit timestamp in µs;
- address bits: 0 = polarity, 0 for ON (the extractor flips it: `type = 1 - addr & 1`);
  1-7 = column, mirrored (`x = 127 - (addr & 0xFE) >> 1`); 8-14 = row counted from the
  bottom (`y = (addr & 0x7F00) >> 8`, which jAER draws upwards); bit 15 (sync) or bit 31
  (special) mark an event that is not a pixel's.
evclust counts rows from the top, so a pixel event becomes x = 127 - column, y = 127 - row;
special events are skipped. The 32-bit timestamps wrap every 71.6 minutes: a step back of more
than 2^31 µs is read as a wrap. The sensor is 128x128 (7-bit column and row).

AEDAT 3.1 (libcaer's include/libcaer/events/common.h and polarity.h, github.com/inivation/libcaer):
- `#` header lines from `#!AER-DAT3.1` to `#!END-HEADER`;
- then packets, little-endian: a 28-byte header (int16 type, int16 source, int32 event size,
  int32 timestamp offset, int32 timestamp overflow, int32 capacity, int32 number, int32 valid)
  and `capacity x size` bytes of events;
- type 1 = polarity events, 8 bytes: uint32 data (bit 0 valid, bit 1 polarity, 1 = ON,
  bits 2-16 y, bits 17-31 x; (0, 0) is the top-left pixel) and int32 timestamp; the full time is
  overflow << 31 | timestamp. Other packet types and invalid events are skipped.
The size comes from the header (`dvsSizeX`/`dvsSizeY`, else a known source name such as
DAVIS346), else from --sensor-size.
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


VERSIONS = ("2.0", "3.1")
PACKET = np.dtype(
    [
        ("type", "<i2"),
        ("source", "<i2"),
        ("size", "<i4"),
        ("ts_offset", "<i4"),
        ("overflow", "<i4"),
        ("capacity", "<i4"),
        ("number", "<i4"),
        ("valid", "<i4"),
    ]
)
POLARITY_EVENT = 1
KNOWN_SOURCES = {"DVS128": (128, 128), "EDVS": (128, 128), "DAVIS240": (240, 180), "DAVIS346": (346, 260), "DVXPLORER": (640, 480)}


def header(path: Path) -> tuple[int, str, bytes]:
    """(offset of the first record, version, header text) after the `#` lines; refuses other
    versions."""
    with open(path, "rb") as f:
        first = f.readline(256)
        if not first.startswith(MAGIC):
            raise EvclustError(f"{path}: not an AEDAT file (no '#!AER-DAT' first line)")
        version = first[len(MAGIC) :].strip().decode("ascii", "replace")
        if version not in VERSIONS:
            raise EvclustError(f"{path}: AEDAT {version[:10]!r} is not read (AEDAT 2.0, 3.1 and 4.0 are)")
        offset, text = len(first), [first]
        while True:
            line = f.readline(HEADER_LIMIT)
            if not line.startswith(b"#"):
                if version == "3.1":
                    raise EvclustError(f"{path}: AEDAT 3.1 header without its '#!END-HEADER' line")
                return offset, version, b"".join(text)
            offset += len(line)
            text.append(line)
            if version == "3.1" and line.startswith(b"#!END-HEADER"):
                return offset, version, b"".join(text)
            if offset > HEADER_LIMIT:
                raise EvclustError(f"{path}: AEDAT header longer than {HEADER_LIMIT} bytes")


def legacy_header(path: Path) -> tuple[dict, None]:
    """(metadata, None); AEDAT 3.1 without a size it can be read from gives no width/height."""
    offset, version, text = header(path)
    if version == "3.1":
        return {**_size_31(text), "source": path.stem, "has_colour": False}, None
    return aedat2_header(path, offset)


def legacy_chunks(path: Path, size: int) -> Iterator[np.ndarray]:
    offset, version, _ = header(path)
    return aedat31_chunks(path, offset, size) if version == "3.1" else aedat2_chunks(path, offset, size)


def _size_31(text: bytes) -> dict:
    import re

    found = {}
    for key, name in (("width", b"dvsSizeX"), ("height", b"dvsSizeY")):
        match = re.search(rb'"' + name + rb'"[^>]*>\s*(\d+)\s*<', text)
        if match:
            found[key] = int(match.group(1))
    if len(found) == 2:
        return found
    source = re.search(rb"#Source \d+: *([A-Za-z0-9_]+)", text)
    name = source.group(1).decode().upper() if source else ""
    for known, (width, height) in KNOWN_SOURCES.items():
        if name.startswith(known):
            return {"width": width, "height": height}
    return {}


def aedat31_chunks(path: Path, offset: int, size: int) -> Iterator[np.ndarray]:
    held, held_n = [], 0
    with open(path, "rb") as f:
        f.seek(offset)
        while True:
            at = f.tell()
            raw = f.read(PACKET.itemsize)
            if not raw:
                break
            if len(raw) < PACKET.itemsize:
                raise EvclustError(f"{path}: the file ends inside a packet header (byte {at})")
            head = np.frombuffer(raw, PACKET)[0]
            capacity, event_size, number = int(head["capacity"]), int(head["size"]), int(head["number"])
            if capacity < 0 or event_size < 0 or not 0 <= number <= capacity:
                raise EvclustError(f"{path}: the packet header at byte {at} is not an AEDAT 3.1 header")
            length = capacity * event_size
            if head["type"] != POLARITY_EVENT:
                f.seek(length, 1)
                continue
            if event_size != 8:
                raise EvclustError(f"{path}: the polarity packet at byte {at} has {event_size}-byte events, not 8")
            data = f.read(length)
            if len(data) < length:
                raise EvclustError(f"{path}: the file ends inside the packet at byte {at} ({len(data)} of its {length} bytes)")
            records = np.frombuffer(data, [("data", "<u4"), ("t", "<i4")], count=number)
            records = records[(records["data"] & 1) == 1]
            if not records.size:
                continue
            if (records["t"] < 0).any():
                raise EvclustError(f"{path}: the polarity packet at byte {at} has a negative timestamp ({int(records['t'].min())})")
            ev = np.zeros(records.size, EVENT_DTYPE)
            ev["t"] = (np.int64(head["overflow"]) << 31) | records["t"].astype(np.int64)
            ev["x"] = (records["data"] >> 17) & 0x7FFF
            ev["y"] = (records["data"] >> 2) & 0x7FFF
            ev["p"] = np.where(records["data"] & 2, 1, -1)
            held.append(ev)
            held_n += ev.size
            if held_n >= size:
                yield np.concatenate(held)
                held, held_n = [], 0
    if held:
        yield np.concatenate(held)


def aedat2_header(path: Path, offset: int) -> tuple[dict, int | None]:
    size = path.stat().st_size - offset
    if size % RECORD.itemsize:
        raise EvclustError(f"{path}: the last event is cut short ({size % RECORD.itemsize} of its {RECORD.itemsize} bytes)")
    return {"width": SIZE, "height": SIZE, "source": path.stem, "has_colour": False}, None


def aedat2_chunks(path: Path, offset: int, size: int) -> Iterator[np.ndarray]:
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
