"""Event-camera files through faery: AEDAT4 (iniVation DV), EVT2/EVT3 `.raw` and DAT `.dat`
(Prophesee), Event Stream `.es` (Neuromorphic Paris).

These formats carry DVS events only (t, x, y, polarity). Reading gives events with zero colour
fields and `has_colour=False`; writing drops the colour fields. AEDAT4 files written here keep
evclust's metadata (source, frame period) in the stream's info node, where DV keeps `sizeX`.
Why faery and not dv-processing, aedat or evlib: docs/DESIGN.md, "Event-camera files".
"""

from __future__ import annotations

import json
from pathlib import Path
from collections.abc import Iterator

import numpy as np

from evclust.errors import EvclustError
from evclust.events.format import EVENT_DTYPE, EventMeta
from evclust.jit import njit

AEDAT_SUFFIXES = (".aedat4",)
EVT_SUFFIXES = (".raw",)
DAT_SUFFIXES = (".dat",)
ES_SUFFIXES = (".es",)
EVT_VERSIONS = ("evt2", "evt3")
META_ATTRIBUTE = "evclustMeta"  # AEDAT4 info-node attribute holding EventMeta as JSON
# The size faery is given for a file whose header has none: nothing is outside it, so the
# validator, not faery, names the first event outside the size the user gave (--sensor-size).
NO_SIZE = (65535, 65535)
DAT_MAX_T = 1 << 32  # DAT stores 32-bit µs timestamps, with no overflow marker
DAT_CD_TYPE, DAT_CD_BYTES = 0x0C, 8  # the two bytes after a DAT header: CD events of 8 bytes each


def faery_dtype() -> np.dtype:
    import faery

    return faery.EVENTS_DTYPE


def from_faery(packet: np.ndarray) -> np.ndarray:
    """faery's (t u64, x u16, y u16, on bool) records -> EVENT_DTYPE with p = ±1, no colour."""
    ev = np.empty(packet.size, EVENT_DTYPE)
    _convert(packet["t"], packet["x"], packet["y"], packet["on"], ev["t"], ev["x"], ev["y"], ev["p"], ev["Y"], ev["Cb"], ev["Cr"])
    return ev


@njit(cache=True, nogil=True)
def _convert(t, x, y, on, t_out, x_out, y_out, p_out, lum, cb, cr):  # pragma: no cover (compiled)
    # One pass writing every field of each record: several times faster than a numpy pass per
    # field on fresh memory, which reading speed comes down to.
    for i in range(t.size):
        t_out[i] = t[i]
        x_out[i] = x[i]
        y_out[i] = y[i]
        p_out[i] = 1 if on[i] else -1
        lum[i] = 0
        cb[i] = 0
        cr[i] = 0


def to_faery(ev: np.ndarray) -> np.ndarray:
    packet = np.empty(ev.size, faery_dtype())
    packet["t"] = ev["t"]
    packet["x"] = ev["x"]
    packet["y"] = ev["y"]
    packet["on"] = ev["p"] > 0
    return packet


def _faery_error(path: Path, exc: Exception) -> EvclustError:
    return EvclustError(f"{path}: not a readable event-camera file ({str(exc).splitlines()[0] if str(exc) else exc.__class__.__name__})")


# ------------------------------------------------------------------------------------------------
# AEDAT4


def _aedat_description(meta: EventMeta, compression: str):
    from faery import aedat

    attr, node = aedat.DescriptionAttribute, aedat.DescriptionNode
    info = {
        "sizeX": attr("int", meta.width),
        "sizeY": attr("int", meta.height),
        "source": attr("string", "evclust"),
        META_ATTRIBUTE: attr("string", meta.to_json()),
    }
    stream = {
        "compression": attr("string", compression.upper()),
        "originalOutputName": attr("string", "events"),
        "typeIdentifier": attr("string", "EVTS"),
    }
    root = "/mainloop/Recorder/outInfo/"
    return [node("outInfo", root, {}, [node("0", root + "0/", stream, [node("info", root + "0/info/", info, [])])])]


def _aedat_event_track(path: Path, decoder) -> tuple[int, tuple[int, int], dict]:
    """The first event track's id and size, and the evclust metadata if the file carries it."""
    tracks = [t for t in decoder.tracks() if t.data_type == "events"]
    if not tracks:
        raise EvclustError(f"{path}: the AEDAT4 file has no event stream")
    track = tracks[0]
    extra: dict = {}
    stack = list(decoder.description())
    while stack:
        node = stack.pop()
        stack.extend(node.nodes)
        if META_ATTRIBUTE in node.attributes:
            try:
                extra = json.loads(node.attributes[META_ATTRIBUTE].value)
            except (json.JSONDecodeError, TypeError):
                raise EvclustError(f"{path}: unreadable {META_ATTRIBUTE} attribute") from None
    return track.id, tuple(track.dimensions), extra if isinstance(extra, dict) else {}


def aedat_header(path: Path) -> tuple[dict, int | None]:
    """(metadata dict, event count from the file's data table, or None if it has none)."""
    from faery import aedat

    try:
        with aedat.Decoder(path) as decoder:
            track_id, (width, height), extra = _aedat_event_track(path, decoder)
            try:
                definitions = decoder.file_data_definitions()
            except Exception:  # a file cut short has no data table: count unknown
                definitions = None
    except EvclustError:
        raise
    except Exception as exc:  # faery raises plain exceptions for malformed files
        raise _faery_error(path, exc) from None
    count = sum(d.elements_count for d in definitions if d.track_id == track_id) if definitions else None
    meta = {**extra, "width": width, "height": height, "source": extra.get("source") or path.stem, "has_colour": False}
    return meta, count


def aedat_packets(path: Path) -> Iterator[np.ndarray]:
    from faery import aedat

    try:
        with aedat.Decoder(path) as decoder:
            track_id, _, _ = _aedat_event_track(path, decoder)
            for track, packet in decoder:
                if track.id == track_id and len(packet):
                    yield packet
    except EvclustError:
        raise
    except Exception as exc:
        raise _faery_error(path, exc) from None


class AedatWriter:
    def __init__(self, tmp: Path, meta: EventMeta, compression: str = "lz4"):
        from faery import aedat

        self._encoder = aedat.Encoder(tmp, _aedat_description(meta, compression), (compression, 1)).__enter__()

    def write(self, ev: np.ndarray) -> None:
        if ev.size:
            self._encoder.write(0, to_faery(ev))

    def close(self, failed: bool = False) -> None:
        self._encoder.__exit__(None, None, None)


# ------------------------------------------------------------------------------------------------
# EVT2 / EVT3 (.raw)


def _text_header(path: Path) -> tuple[int, list[str]]:
    """(byte where the binary part starts, the header's lines) of a Prophesee file, whose header is
    lines of printable text that begin '% '. Binary data that happened to begin the same way would
    need a whole printable line before a newline, so the end is not mistaken."""
    with open(path, "rb") as f:
        head = f.read(1 << 16)
    start, lines = 0, []
    while head.startswith(b"% ", start):
        end = head.find(b"\n", start)
        line = head[start:end]
        if end < 0 or not all(0x20 <= b < 0x7F for b in line.rstrip(b"\r")):
            break
        lines.append(line.decode().rstrip("\r"))
        start = end + 1
    return start, lines


def _refuse_a_cut_word(path: Path, payload: int, word: int, what: str) -> None:
    """A file that ends inside one of its fixed-size words was cut short: refused in one line."""
    if word and payload % word:
        raise EvclustError(f"{path}: the file ends inside its last {what} ({payload % word} of its {word} bytes): a truncated file")


# Bytes per word of each EVT version, as the header names it.
_EVT_WORD_BYTES = {"2.0": 4, "2.1": 8, "3.0": 2, "EVT2": 4, "EVT21": 8, "EVT3": 2}


def _sized_header(path: Path, decoder_class, version_fallback) -> dict:
    """The metadata of an EVT or DAT file; no width and height when its header has none."""
    try:
        with decoder_class(path, None, version_fallback) as decoder:
            width, height = decoder.dimensions
    except Exception as exc:
        if "no size information" not in str(exc):
            raise _faery_error(path, exc) from None
        try:  # is the size the only thing missing?
            with decoder_class(path, NO_SIZE, version_fallback):
                pass
        except Exception:
            raise _faery_error(path, exc) from None
        return {"source": path.stem, "has_colour": False}
    return {"width": width, "height": height, "source": path.stem, "has_colour": False}


def evt_header(path: Path) -> tuple[dict, None]:
    """(metadata, None): EVT headers give no event count. No width and height when the header has
    none (Gen3 and some Gen4 recordings): the reader then asks for --sensor-size."""
    from faery import evt

    meta = _sized_header(path, evt.Decoder, None)
    start, lines = _text_header(path)
    # '% evt 3.0', '% format EVT3', or Metavision 4's '% format EVT3;height=720;width=1280'
    names = [line.split()[2].split(";")[0] for line in lines if len(line.split()) == 3 and line.split()[1] in ("evt", "format")]
    word = next((_EVT_WORD_BYTES[name] for name in names if name in _EVT_WORD_BYTES), 0)
    _refuse_a_cut_word(path, path.stat().st_size - start, word, "EVT word")
    return meta, None


def evt_packets(path: Path, sized: bool = True) -> Iterator[np.ndarray]:
    """faery's packets; `sized` False for a header without a size (the reader checks it)."""
    from faery import evt

    try:
        with evt.Decoder(path, None if sized else NO_SIZE, None) as decoder:
            for packet in decoder:
                events = packet.get("events")
                if events is not None and len(events):
                    yield events
    except Exception as exc:
        raise _faery_error(path, exc) from None


class EvtWriter:
    def __init__(self, tmp: Path, meta: EventMeta, version: str = "evt3"):
        from faery import evt

        if version not in EVT_VERSIONS:
            raise EvclustError(f"EVT version '{version}' is not one of {', '.join(EVT_VERSIONS)}")
        # zero_t0=False: timestamps are stored as they are, so a round trip is exact.
        self._encoder = evt.Encoder(tmp, version, False, (meta.width, meta.height), True).__enter__()

    def write(self, ev: np.ndarray) -> None:
        if ev.size:
            self._encoder.write({"events": to_faery(ev)})

    def close(self, failed: bool = False) -> None:
        self._encoder.__exit__(None, None, None)


# ------------------------------------------------------------------------------------------------
# DAT (Prophesee's decoded CD events: 32-bit µs timestamp, x, y, polarity in a 32-bit word)


def dat_header(path: Path) -> tuple[dict, int | None]:
    """(metadata, event count from the file's size). A header without `% Version` is read as
    DAT 2, the only version Metavision writes; without `% Width`/`% Height` the size is asked
    for (--sensor-size)."""
    from faery import dat

    meta = _sized_header(path, dat.Decoder, "dat2")
    try:
        with dat.Decoder(path, NO_SIZE, "dat2") as decoder:
            kind = decoder.event_type
    except Exception as exc:
        raise _faery_error(path, exc) from None
    if kind != "cd":
        raise EvclustError(f"{path}: a DAT file of {kind} events; only CD (contrast detection) events are read")
    start, _ = _text_header(path)
    with open(path, "rb") as f:  # after the text: one byte of event type, one of event size
        f.seek(start)
        kind_and_size = f.read(2)
    if kind_and_size == bytes([DAT_CD_TYPE, DAT_CD_BYTES]):  # where the header was found to end for sure
        _refuse_a_cut_word(path, path.stat().st_size - start - 2, DAT_CD_BYTES, "event")
    return meta, None


def dat_packets(path: Path, sized: bool = True) -> Iterator[np.ndarray]:
    from faery import dat

    try:
        with dat.Decoder(path, None if sized else NO_SIZE, "dat2") as decoder:
            for packet in decoder:
                if len(packet):
                    events = np.empty(packet.size, faery_dtype())
                    events["t"], events["x"], events["y"] = packet["t"], packet["x"], packet["y"]
                    events["on"] = packet["payload"] > 0  # payload 1 = ON, 0 = OFF
                    yield events
    except Exception as exc:
        raise _faery_error(path, exc) from None


class DatWriter:
    """DAT 2, CD events. Its timestamps are 32-bit: a stream reaching 2^32 µs (71.6 minutes)
    is refused rather than written wrapped."""

    def __init__(self, tmp: Path, meta: EventMeta):
        from faery import dat

        self._encoder = dat.Encoder(tmp, "dat2", "cd", False, (meta.width, meta.height)).__enter__()

    def write(self, ev: np.ndarray) -> None:
        if not ev.size:
            return
        if int(ev["t"][-1]) >= DAT_MAX_T:
            i = int(np.flatnonzero(ev["t"] >= DAT_MAX_T)[0])
            raise EvclustError(
                f"event at t={int(ev['t'][i])} us: DAT stores 32-bit µs timestamps (up to {DAT_MAX_T - 1}); write .h5 or .raw"
            )
        packet = np.empty(ev.size, [("t", "<u8"), ("x", "<u2"), ("y", "<u2"), ("payload", "u1")])
        packet["t"], packet["x"], packet["y"] = ev["t"], ev["x"], ev["y"]
        packet["payload"] = ev["p"] > 0
        self._encoder.write(packet)

    def close(self, failed: bool = False) -> None:
        self._encoder.__exit__(None, None, None)


# ------------------------------------------------------------------------------------------------
# Event Stream (.es), version 2, DVS events. ES puts y = 0 at the bottom row: it is turned to the
# image convention (y = 0 at the top) on reading and back on writing, as faery's own stream API
# does (faery.file_decoder / file_encoder).


def es_header(path: Path) -> tuple[dict, None]:
    from faery import es

    try:
        with es.Decoder(path, 0) as decoder:
            kind, dimensions = decoder.event_type, decoder.dimensions
    except Exception as exc:
        raise _faery_error(path, exc) from None
    if kind not in ("dvs", "atis") or dimensions is None:
        raise EvclustError(f"{path}: an Event Stream file of {kind} events; only DVS and ATIS events are read")
    width, height = dimensions
    return {"width": width, "height": height, "source": path.stem, "has_colour": False}, None


def es_packets(path: Path, height: int) -> Iterator[np.ndarray]:
    from faery import es

    try:
        with es.Decoder(path, 0) as decoder:
            atis = decoder.event_type == "atis"
            for packet in decoder:
                if atis:  # ATIS: keep the change detections, drop the exposure measurements
                    packet = packet[np.logical_not(packet["exposure"])]
                if not len(packet):
                    continue
                events = np.empty(packet.size, faery_dtype())
                events["t"], events["x"] = packet["t"], packet["x"]
                events["y"] = height - 1 - packet["y"].astype(np.int64)
                events["on"] = packet["polarity"] if atis else packet["on"]
                yield events
    except Exception as exc:
        raise _faery_error(path, exc) from None


class EsWriter:
    def __init__(self, tmp: Path, meta: EventMeta):
        from faery import es

        self.height = meta.height
        self._encoder = es.Encoder(tmp, "dvs", False, (meta.width, meta.height)).__enter__()

    def write(self, ev: np.ndarray) -> None:
        if ev.size:
            packet = to_faery(ev)
            packet["y"] = self.height - 1 - ev["y"].astype(np.int64)
            self._encoder.write(packet)

    def close(self, failed: bool = False) -> None:
        self._encoder.__exit__(None, None, None)
