"""Event files, read and written in chunks so a stream larger than memory passes through.

Formats, by suffix:
- `.npz`: native, the whole stream in one array (written at once: keep it for small streams);
- `.h5`, `.hdf5`: `events/{t,x,y,p[,Y,Cb,Cr]}` datasets plus the metadata as attributes;
- `.aedat4` (iniVation DV), `.raw` (Prophesee EVT3, or EVT2), `.dat` (Prophesee DAT) and `.es`
  (Event Stream): DVS events only, via faery (evclust.events.camera);
- `.aedat`: jAER's AEDAT 2.0 (DVS128) and cAER's AEDAT 3.1 through evclust.events.aedat_legacy,
  AEDAT 4 through faery;
- `.txt` (the Event Camera Dataset's `t x y p`, t in seconds) and `.csv` (named columns):
  evclust.events.text.

Files without a sensor size (text, and EVT or DAT whose header has none) are read with the size
the caller gives (`sensor_size`, the CLI's --sensor-size); a size given for a file that has one
must agree with it.

Readers validate every chunk and the seams between chunks, and fail with one line. Writers are
atomic: a failed write leaves no file.
"""

from __future__ import annotations

import contextlib
import json
import zipfile
from pathlib import Path
from collections.abc import Iterator

import numpy as np

from evclust.errors import EvclustError, atomic_output
from evclust.events import aedat_legacy, camera, text
from evclust.events.format import COLOUR_FIELDS, DVS_FIELDS, EVENT_DTYPE, EventMeta, concat_events, sort_events
from evclust.events.validate import validate_events

HDF5_SUFFIXES = (".h5", ".hdf5")
NPZ_SUFFIXES = (".npz",)
SUFFIXES = (
    NPZ_SUFFIXES + HDF5_SUFFIXES + camera.AEDAT_SUFFIXES + camera.EVT_SUFFIXES + camera.DAT_SUFFIXES + camera.ES_SUFFIXES
    + aedat_legacy.SUFFIXES + text.ECD_SUFFIXES + text.CSV_SUFFIXES
)  # fmt: skip
TEXT_KINDS = ("ecd", "csv")
CHUNK = 1 << 20  # events per chunk: about 15 MB of records


def _kind(path: Path) -> str:
    suffix = path.suffix.lower()
    for kind, suffixes in (
        ("npz", NPZ_SUFFIXES),
        ("hdf5", HDF5_SUFFIXES),
        ("aedat", camera.AEDAT_SUFFIXES),
        ("evt", camera.EVT_SUFFIXES),
        ("dat", camera.DAT_SUFFIXES),
        ("es", camera.ES_SUFFIXES),
        ("aedat2", aedat_legacy.SUFFIXES),
        ("ecd", text.ECD_SUFFIXES),
        ("csv", text.CSV_SUFFIXES),
    ):
        if suffix in suffixes:
            return kind
    raise EvclustError(f"{path}: unknown event file type '{suffix}' (use {', '.join(SUFFIXES)})")


# ------------------------------------------------------------------------------------------------
# Reading


class EventReader:
    """An event file opened for reading: its metadata now, its records chunk by chunk.

    `count` is the number of events when the file says so without decoding it (else None).
    `sensor_size` (width, height) is the size of a file that gives none; `polarity` the
    convention of a text file's polarity column (evclust.events.text.POLARITY).
    """

    def __init__(self, path: str | Path, sensor_size: tuple[int, int] | None = None, polarity: str = "auto"):
        self.path = path = Path(path)
        self.kind = _kind(path)
        if not path.is_file():
            raise EvclustError(f"{path}: no such event file")
        if polarity not in text.POLARITY:
            raise EvclustError(f"polarity convention '{polarity}' is not one of {', '.join(text.POLARITY)}")
        if polarity != "auto" and self.kind not in TEXT_KINDS:
            raise EvclustError(f"{path}: --polarity {polarity} is for text files (.txt, .csv); this format's polarity is a bit it defines")
        self.polarity = polarity
        self._columns = None
        if self.kind == "aedat2":
            self.kind = _aedat_version(path)
        if self.kind == "npz":
            self._columns, meta_dict = _read_npz(path)
            self.count = len(self._columns.get("t", ()))
        elif self.kind == "hdf5":
            meta_dict, self.count = _hdf5_header(path)
        elif self.kind == "aedat":
            meta_dict, self.count = camera.aedat_header(path)
        elif self.kind == "evt":
            meta_dict, self.count = camera.evt_header(path)
        elif self.kind == "dat":
            meta_dict, self.count = camera.dat_header(path)
        elif self.kind == "es":
            meta_dict, self.count = camera.es_header(path)
        elif self.kind == "aedat2":
            meta_dict, self.count = aedat_legacy.legacy_header(path)
        else:
            meta_dict, self.count = text.text_header(path, self.kind)
        self._sized = "width" in meta_dict and "height" in meta_dict
        meta_dict = _with_size(path, meta_dict, sensor_size)
        try:
            self.meta = EventMeta.from_dict(meta_dict)
        except EvclustError as exc:
            raise EvclustError(f"{path}: {exc}") from None

    def chunks(self, size: int = CHUNK) -> Iterator[np.ndarray]:
        """Validated EVENT_DTYPE chunks of about `size` events, in stream order."""
        name = str(self.path)
        if self.kind == "npz":
            ev, has_colour = _assemble(self.path, self._columns)
            self._set_colour(has_colour)
            pieces = (ev[lo : lo + size] for lo in range(0, ev.size, size))
        elif self.kind == "hdf5":
            pieces = self._hdf5_chunks(size)
        elif self.kind == "aedat2":
            pieces = _order_ties(aedat_legacy.legacy_chunks(self.path, size))
        elif self.kind in TEXT_KINDS:
            pieces = _order_ties(text.text_chunks(self.path, self.kind, self.meta, self.polarity, size=min(size, text.LINES)))
        else:
            packets = {
                "aedat": lambda: camera.aedat_packets(self.path),
                "evt": lambda: camera.evt_packets(self.path, self._sized),
                "dat": lambda: camera.dat_packets(self.path, self._sized),
                "es": lambda: camera.es_packets(self.path, self.meta.height),
            }[self.kind]()
            # Cut faery's small packets into chunks first: one conversion per chunk, not per packet.
            pieces = _order_ties(camera.from_faery(chunk) for chunk in _regroup(packets, size))
        offset, last = 0, None
        for piece in pieces:
            validate_events(piece, self.meta, name, offset=offset, previous=last)
            offset += piece.size
            last = piece[-1] if piece.size else last
            yield piece

    def read(self) -> np.ndarray:
        return concat_events(self.chunks())

    def _set_colour(self, has_colour: bool) -> None:
        if self.meta.has_colour != has_colour:
            self.meta = EventMeta.from_dict({**json.loads(self.meta.to_json()), "has_colour": has_colour})

    def _hdf5_chunks(self, size: int) -> Iterator[np.ndarray]:
        import h5py

        try:
            with h5py.File(self.path, "r") as f:
                group = f["events"]
                datasets = {name: group[name] for name in group.keys()}
                _check_fields(self.path, datasets.keys())
                for name, data in datasets.items():
                    if data.ndim != 1 or data.shape[0] != self.count:
                        raise EvclustError(f"{self.path}: field {name} has {data.shape} values, expected ({self.count},)")
                self._set_colour(COLOUR_FIELDS[0] in datasets)
                for lo in range(0, self.count, size):
                    ev, _ = _assemble(self.path, {n: d[lo : lo + size] for n, d in datasets.items()})
                    yield ev
        except EvclustError:
            raise
        except OSError as exc:
            raise EvclustError(f"{self.path}: not a readable HDF5 file ({exc})") from None


def _aedat_version(path: Path) -> str:
    """`.aedat` holds AEDAT 2.0 (jAER), 3.1 (cAER) or 4.0 (DV): the first line says which."""
    try:
        with open(path, "rb") as f:
            first = f.readline(64)
    except OSError as exc:
        raise EvclustError(f"{path}: cannot be read ({exc.strerror})") from None
    return "aedat" if first.startswith(b"#!AER-DAT4") else "aedat2"


def _with_size(path: Path, meta: dict, sensor_size: tuple[int, int] | None) -> dict:
    """The file's size, or the one given where it has none; one line where neither is known or
    the two disagree."""
    has = "width" in meta and "height" in meta
    if sensor_size is None:
        if not has:
            raise EvclustError(f"{path}: the file gives no sensor size: give it with --sensor-size WxH")
        return meta
    width, height = sensor_size
    if has and (meta["width"], meta["height"]) != (width, height):
        raise EvclustError(
            f"{path}: --sensor-size {width}x{height} disagrees with the file's {meta['width']}x{meta['height']}; leave it out"
        )
    return {**meta, "width": width, "height": height}


def read_events(path: str | Path, sensor_size: tuple[int, int] | None = None, polarity: str = "auto") -> tuple[np.ndarray, EventMeta]:
    """Return (events, meta). DVS-only files get zero colour fields and `meta.has_colour=False`."""
    reader = EventReader(path, sensor_size, polarity)
    events = reader.read()
    return events, reader.meta


def _read_npz(path: Path) -> tuple[dict[str, np.ndarray], dict]:
    try:
        with np.load(path, allow_pickle=False) as z:
            if "events" not in z.files:
                raise EvclustError(f"{path}: no 'events' array (found: {', '.join(z.files) or 'nothing'})")
            events = z["events"]
            meta = json.loads(str(z["meta"])) if "meta" in z.files else {}
            if not isinstance(meta, dict):
                raise EvclustError(f"{path}: metadata is {type(meta).__name__}, expected a JSON object")
    except EvclustError:
        raise
    except (OSError, ValueError, EOFError, zipfile.BadZipFile, json.JSONDecodeError) as exc:
        raise EvclustError(f"{path}: not a readable event file ({exc.__class__.__name__}: {exc})") from None
    if events.dtype.names is None:
        raise EvclustError(f"{path}: 'events' is not a structured array with fields {', '.join(EVENT_DTYPE.names)}")
    columns = {name: events[name] for name in events.dtype.names}
    _check_fields(path, columns)
    meta["has_colour"] = COLOUR_FIELDS[0] in columns
    return columns, meta


def _hdf5_header(path: Path) -> tuple[dict, int]:
    import h5py

    try:
        with h5py.File(path, "r") as f:
            if "events" not in f or not isinstance(f["events"], h5py.Group):
                raise EvclustError(f"{path}: no 'events' group")
            group = f["events"]
            _check_fields(path, group.keys())
            not_data = [name for name in group.keys() if not isinstance(group[name], h5py.Dataset)]
            if not_data:
                raise EvclustError(
                    f"{path}: events/{not_data[0]} is a {type(group[not_data[0]]).__name__.lower()}, not a dataset of values"
                )
            count = group["t"].shape[0] if group["t"].ndim == 1 else -1
            meta = {k: (v.item() if getattr(v, "size", 0) == 1 else v) for k, v in f.attrs.items()}  # arrays stay, for check() to refuse
            meta["has_colour"] = COLOUR_FIELDS[0] in group
    except EvclustError:
        raise
    except OSError as exc:
        raise EvclustError(f"{path}: not a readable HDF5 file ({exc})") from None
    return meta, count


def _check_fields(path: Path, names) -> None:
    names = set(names)
    unknown = sorted(names - set(EVENT_DTYPE.names))
    if unknown:
        raise EvclustError(f"{path}: unknown event field(s) {', '.join(unknown)}")
    missing = [name for name in DVS_FIELDS if name not in names]
    if missing:
        raise EvclustError(f"{path}: missing event field(s) {', '.join(missing)}")
    colour_present = [name for name in COLOUR_FIELDS if name in names]
    if colour_present and len(colour_present) != len(COLOUR_FIELDS):
        raise EvclustError(f"{path}: colour fields must be all of Y, Cb, Cr or none (found {', '.join(colour_present)})")


def _assemble(path: Path, columns: dict[str, np.ndarray]) -> tuple[np.ndarray, bool]:
    _check_fields(path, columns)
    n = len(columns["t"])
    ev = np.zeros(n, dtype=EVENT_DTYPE)
    for name, column in columns.items():
        column = np.asarray(column)
        if column.ndim != 1 or len(column) != n:
            raise EvclustError(f"{path}: field {name} has {column.shape} values, expected ({n},)")
        if not np.issubdtype(column.dtype, np.integer):
            raise EvclustError(f"{path}: field {name} has type {column.dtype}, expected integers")
        info = np.iinfo(EVENT_DTYPE[name])
        if n and (column.min() < info.min or column.max() > info.max):
            i = int(np.flatnonzero((column < info.min) | (column > info.max))[0])
            raise EvclustError(f"{path}: record {i}: {name}={int(column[i])} does not fit {EVENT_DTYPE[name]}")
        ev[name] = column
    return ev, COLOUR_FIELDS[0] in columns


def _regroup(packets: Iterator[np.ndarray], size: int) -> Iterator[np.ndarray]:
    """Cut a camera decoder's packets (of any size, any dtype with a `t` field) into chunks of
    about `size` events. A chunk
    ends between two timestamps, never inside a run of equal ones, so ties can be ordered per
    chunk."""
    held: list[np.ndarray] = []
    held_n = 0
    for packet in packets:
        held.append(packet)
        held_n += packet.size
        if held_n < size:
            continue
        chunk = np.concatenate(held) if len(held) > 1 else held[0]
        t = chunk["t"]
        start = 0
        while chunk.size - start >= size:
            run = t[start + size - 1]
            cut = int(np.searchsorted(t, run, side="left"))
            if cut <= start:  # one timestamp fills the chunk: take its whole run
                cut = int(np.searchsorted(t, run, side="right"))
            if cut >= chunk.size:  # the run may go on in the next packet
                break
            yield chunk[start:cut]
            start = cut
        held, held_n = [chunk[start:]], chunk.size - start
    if held_n:
        yield np.concatenate(held) if len(held) > 1 else held[0]


def _order_ties(chunks: Iterator[np.ndarray]) -> Iterator[np.ndarray]:
    """Cameras emit the events of one timestamp in readout order; the stream contract (SPEC §2)
    orders them by y then x. Only chunks that need it are sorted, and only when time is monotonic
    (a chunk going back in time is left as it is, for the validator to name)."""
    for ev in chunks:
        t = ev["t"]
        if ev.size > 1 and not (t[1:] < t[:-1]).any():
            key = ev["y"].astype(np.int64) * 65536 + ev["x"]
            if ((t[1:] == t[:-1]) & (key[1:] < key[:-1])).any():
                ev = sort_events(ev)
        yield ev


# ------------------------------------------------------------------------------------------------
# Writing


class _NpzWriter:
    """npz holds one array: chunks are gathered and written at close."""

    def __init__(self, tmp: Path, meta: EventMeta):
        self.tmp, self.meta, self.chunks = tmp, meta, []

    def write(self, ev: np.ndarray) -> None:
        self.chunks.append(ev)

    def close(self, failed: bool = False) -> None:
        if failed:
            return
        with open(self.tmp, "wb") as f:
            np.savez(f, events=concat_events(self.chunks), meta=np.array(self.meta.to_json()))


class _Hdf5Writer:
    def __init__(self, tmp: Path, meta: EventMeta):
        import h5py

        self.file = h5py.File(tmp, "w")
        group = self.file.create_group("events")
        fields = DVS_FIELDS + (COLOUR_FIELDS if meta.has_colour else ())
        self.datasets = {
            name: group.create_dataset(
                name,
                shape=(0,),
                maxshape=(None,),
                dtype=EVENT_DTYPE[name],
                chunks=(1 << 16,),
                compression="gzip",
                compression_opts=1,
                shuffle=True,
            )  # fmt: skip
            for name in fields
        }
        for key, value in json.loads(meta.to_json()).items():
            if value is not None:
                self.file.attrs[key] = value

    def write(self, ev: np.ndarray) -> None:
        for name, data in self.datasets.items():
            n = data.shape[0]
            data.resize((n + ev.size,))
            data[n:] = ev[name]

    def close(self, failed: bool = False) -> None:
        self.file.close()


@contextlib.contextmanager
def event_writer(path: str | Path, meta: EventMeta, evt_version: str = "evt3"):
    """Yield a writer with `.write(chunk)`; the file appears only if the block succeeds.

    Camera and text formats drop the colour fields (DVS events only); `evt_version` picks EVT3
    or EVT2 for `.raw`. `.aedat` is written as AEDAT 2.0 (DVS128, at most 128x128).
    """
    path = Path(path)
    kind = _kind(path)
    with atomic_output(path) as tmp:
        if kind == "npz":
            writer = _NpzWriter(tmp, meta)
        elif kind == "hdf5":
            writer = _Hdf5Writer(tmp, meta)
        elif kind == "aedat":
            writer = camera.AedatWriter(tmp, meta)
        elif kind == "evt":
            writer = camera.EvtWriter(tmp, meta, evt_version)
        elif kind == "dat":
            writer = camera.DatWriter(tmp, meta)
        elif kind == "es":
            writer = camera.EsWriter(tmp, meta)
        elif kind == "aedat2":
            writer = aedat_legacy.Aedat2Writer(tmp, meta)
        else:
            writer = text.TextWriter(tmp, meta, kind)
        checked = _CheckedWriter(writer, path, meta)
        try:
            yield checked
        except BaseException:
            writer.close(failed=True)
            raise
        writer.close()


class _CheckedWriter:
    """Refuses records that are not events, and streams out of order, before they reach a file."""

    def __init__(self, writer, path: Path, meta: EventMeta):
        self.writer, self.path, self.meta = writer, path, meta
        self.count, self.last = 0, None

    def write(self, ev: np.ndarray) -> None:
        if ev.dtype != EVENT_DTYPE:
            raise EvclustError(f"{self.path}: records of dtype {ev.dtype} are not events ({EVENT_DTYPE})")
        validate_events(ev, self.meta, str(self.path), offset=self.count, previous=self.last)
        if ev.size:
            self.writer.write(ev)
            self.count += ev.size
            self.last = ev[-1]


def write_events(path: str | Path, ev: np.ndarray, meta: EventMeta, evt_version: str = "evt3") -> None:
    with event_writer(path, meta, evt_version) as writer:
        for lo in range(0, max(ev.size, 1), CHUNK):
            writer.write(ev[lo : lo + CHUNK])
