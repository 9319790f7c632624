"""Event files: `.npz` (native) and HDF5 (`events/{t,x,y,p,Y,Cb,Cr}` plus attributes).

Writers are atomic: a failed write leaves no file. Readers validate and fail with one line.
"""

from __future__ import annotations

import json
import zipfile
from pathlib import Path

import numpy as np

from evclust.errors import EvclustError, atomic_output
from evclust.events.format import COLOUR_FIELDS, DVS_FIELDS, EVENT_DTYPE, EventMeta
from evclust.events.validate import validate_events

HDF5_SUFFIXES = (".h5", ".hdf5")
NPZ_SUFFIXES = (".npz",)


def _kind(path: Path) -> str:
    suffix = path.suffix.lower()
    if suffix in NPZ_SUFFIXES:
        return "npz"
    if suffix in HDF5_SUFFIXES:
        return "hdf5"
    raise EvclustError(f"{path}: unknown event file type '{suffix}' (use .npz, .h5 or .hdf5)")


def write_events(path: str | Path, ev: np.ndarray, meta: EventMeta) -> None:
    path = Path(path)
    kind = _kind(path)
    if ev.dtype != EVENT_DTYPE:
        raise EvclustError(f"{path}: records of dtype {ev.dtype} are not events ({EVENT_DTYPE})")
    with atomic_output(path) as tmp:
        if kind == "npz":
            with open(tmp, "wb") as f:
                np.savez(f, events=ev, meta=np.array(meta.to_json()))
        else:
            import h5py

            with h5py.File(tmp, "w") as f:
                group = f.create_group("events")
                fields = DVS_FIELDS + (COLOUR_FIELDS if meta.has_colour else ())
                for name in fields:
                    group.create_dataset(name, data=ev[name], compression="gzip", shuffle=True)
                for key, value in json.loads(meta.to_json()).items():
                    if value is not None:
                        f.attrs[key] = value


def read_events(path: str | Path) -> tuple[np.ndarray, EventMeta]:
    """Return (events, meta). DVS-only files get zero colour fields and `meta.has_colour=False`."""
    path = Path(path)
    kind = _kind(path)
    if not path.is_file():
        raise EvclustError(f"{path}: no such event file")
    columns, meta_dict = _read_npz(path) if kind == "npz" else _read_hdf5(path)
    for key in ("width", "height"):
        if key not in meta_dict:
            raise EvclustError(f"{path}: metadata has no sensor {key}")
    ev, has_colour = _assemble(path, columns)
    meta = EventMeta.from_dict({**meta_dict, "has_colour": has_colour})
    validate_events(ev, meta, str(path))
    return ev, meta


def _read_npz(path: Path) -> tuple[dict[str, np.ndarray], dict]:
    try:
        with np.load(path, allow_pickle=False) as z:
            if "events" not in z.files:
                raise EvclustError(f"{path}: no 'events' array (found: {', '.join(z.files) or 'nothing'})")
            events = z["events"]
            meta = json.loads(str(z["meta"])) if "meta" in z.files else {}
    except EvclustError:
        raise
    except (OSError, ValueError, zipfile.BadZipFile, json.JSONDecodeError) as exc:
        raise EvclustError(f"{path}: not a readable event file ({exc.__class__.__name__}: {exc})") from None
    if events.dtype.names is None:
        raise EvclustError(f"{path}: 'events' is not a structured array with fields {', '.join(EVENT_DTYPE.names)}")
    return {name: events[name] for name in events.dtype.names}, meta


def _read_hdf5(path: Path) -> tuple[dict[str, np.ndarray], dict]:
    import h5py

    try:
        with h5py.File(path, "r") as f:
            if "events" not in f:
                raise EvclustError(f"{path}: no 'events' group")
            group = f["events"]
            columns = {name: group[name][()] for name in group.keys()}
            meta = {k: (v.item() if hasattr(v, "item") else v) for k, v in f.attrs.items()}
    except EvclustError:
        raise
    except OSError as exc:
        raise EvclustError(f"{path}: not a readable HDF5 file ({exc})") from None
    return columns, meta


def _assemble(path: Path, columns: dict[str, np.ndarray]) -> tuple[np.ndarray, bool]:
    unknown = sorted(set(columns) - set(EVENT_DTYPE.names))
    if unknown:
        raise EvclustError(f"{path}: unknown event field(s) {', '.join(unknown)}")
    missing = [name for name in DVS_FIELDS if name not in columns]
    if missing:
        raise EvclustError(f"{path}: missing event field(s) {', '.join(missing)}")
    colour_present = [name for name in COLOUR_FIELDS if name in columns]
    if colour_present and len(colour_present) != len(COLOUR_FIELDS):
        raise EvclustError(f"{path}: colour fields must be all of Y, Cb, Cr or none (found {', '.join(colour_present)})")
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
    return ev, bool(colour_present)
