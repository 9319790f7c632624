"""Event files in text: the Event Camera Dataset's `events.txt` and CSV with named columns.

- `.txt` (the Event Camera Dataset's layout, Mueggler et al. 2017): one event a line,
  `t x y p` separated by spaces or tabs, t in seconds (rounded to the nearest µs), p 0 (OFF) or
  1 (ON). No header; lines starting with `#` and blank lines are skipped.
- `.csv`: a header line names the columns, in any order (spaces ignored; case too where no
  column has the exact name); other columns are ignored. Time: `t`, `ts`, `timestamp` or `t_us` in whole µs, or `t_s` in seconds.
  Coordinates: `x`, `y`. Polarity: `p`, `pol`, `polarity` or `on`.

The sensor size comes from the file where it can: a CSV whose coordinate columns are named
`x@W` and `y@H` (faery's layout), or an `events.txt` with the dataset's `images.txt` and frames
beside it (the first frame's size). Otherwise the reader is given it (`track --sensor-size WxH`). Polarity
values are read by `POLARITY` conventions: `auto` takes 1 as ON and 0 or -1 as OFF; `01` takes
only 0/1, `pm1` only -1/+1. Any other value, a garbled line, a negative time or a coordinate
outside the sensor is refused in one line naming the file's line number. Written files use p 0/1,
so the Event Camera Dataset's tools read them; `.txt` times are written with six decimals, so a
round trip is exact.
"""

from __future__ import annotations

import itertools
from pathlib import Path
from collections.abc import Iterator

import numpy as np

from evclust.errors import EvclustError
from evclust.events.format import EVENT_DTYPE, EventMeta

ECD_SUFFIXES = (".txt",)
CSV_SUFFIXES = (".csv",)
POLARITY = ("auto", "01", "pm1")
POLARITY_VALUES = {"auto": (-1, 0, 1), "01": (0, 1), "pm1": (-1, 1)}
CSV_NAMES = {
    "t": ("t", "ts", "timestamp", "t_us"),
    "t_s": ("t_s",),
    "x": ("x",),
    "y": ("y",),
    "p": ("p", "pol", "polarity", "on"),
}
LINES = 1 << 18  # lines parsed at once


def _shown(line: str) -> str:
    line = line.rstrip("\r\n")
    return repr(line if len(line) <= 60 else line[:57] + "...")


class TextFormat:
    """Where the four fields are in a line, and how time is written."""

    def __init__(self, path: Path, kind: str):
        self.path, self.kind = path, kind
        self.header_lines = 0
        if kind == "ecd":
            self.delimiter, self.columns, self.seconds = None, (0, 1, 2, 3), True
            return
        self.delimiter = ","
        try:
            with open(path, encoding="utf-8", errors="strict") as f:
                header = ""
                for header in f:
                    self.header_lines += 1
                    if header.strip() and not header.lstrip().startswith("#"):
                        break
        except UnicodeDecodeError:
            raise EvclustError(f"{path}: not a text file (bytes that are not UTF-8 in its first lines)") from None
        names, self.size = [], {}
        for column in header.strip().split(","):
            # faery writes the sensor size into the coordinate columns' names: `x@320,y@240`.
            name, at, size = column.strip().partition("@")
            names.append(name.strip())
            if at and name.strip().lower() in ("x", "y"):
                if not size.strip().isdigit() or int(size) < 1:
                    raise EvclustError(
                        f"{path}: line {self.header_lines}: column {column.strip()!r}: the size after '@' is not a whole number"
                    )
                self.size[name.strip().lower()] = int(size)
        found = {}
        for field, accepted in CSV_NAMES.items():
            # Exact names first: a colour file's luma column `Y` is not its row `y`.
            hits = [i for i, name in enumerate(names) if name in accepted] or [
                i for i, name in enumerate(names) if name.lower() in accepted
            ]
            if len(hits) > 1:
                raise EvclustError(f"{path}: line {self.header_lines}: more than one {field} column ({', '.join(names[i] for i in hits)})")
            if hits:
                found[field] = hits[0]
        if "t" in found and "t_s" in found:
            raise EvclustError(f"{path}: line {self.header_lines}: both a µs and a seconds time column; keep one")
        self.seconds = "t_s" in found
        found.setdefault("t", found.pop("t_s", None))
        missing = [field for field in ("t", "x", "y", "p") if found.get(field) is None]
        if missing:
            accepted = "; ".join(f"{' '.join(CSV_NAMES[f] + (CSV_NAMES['t_s'] if f == 't' else ()))}" for f in missing)
            raise EvclustError(
                f"{path}: line {self.header_lines}: the header {header.strip()[:60]!r} names no {', '.join(missing)} column "
                f"(accepted: {accepted})"
            )
        self.columns = (found["t"], found["x"], found["y"], found["p"])


def text_header(path: Path, kind: str) -> tuple[dict, None]:
    form = TextFormat(path, kind)  # refuses a CSV header without the four columns now
    meta = {"source": path.stem, "has_colour": False}
    if kind == "csv" and {"x", "y"} <= form.size.keys():
        meta.update(width=form.size["x"], height=form.size["y"])
    elif kind == "ecd":
        meta.update(_frame_size(path))
    return meta, None


def _frame_size(path: Path) -> dict:
    """The Event Camera Dataset keeps the camera's frames beside `events.txt`, listed in
    `images.txt` (`t images/frame_….png`): the first frame's size is the sensor's. Nothing when
    there is no such list or frame (the reader then needs --sensor-size)."""
    listing = path.with_name("images.txt")
    if not listing.is_file():
        return {}
    with open(listing, encoding="utf-8", errors="replace") as f:
        first = next((line.split() for line in f if line.strip() and not line.lstrip().startswith("#")), [])
    frame = path.parent / first[1] if len(first) == 2 else None
    if frame is None or not frame.is_file():
        return {}
    import cv2

    image = cv2.imread(str(frame), cv2.IMREAD_UNCHANGED)
    if image is None:
        raise EvclustError(f"{frame}: the first frame {listing.name} lists is not a readable image; give the size with --sensor-size WxH")
    return {"width": int(image.shape[1]), "height": int(image.shape[0])}


def text_chunks(path: Path, kind: str, meta: EventMeta, polarity: str = "auto", size: int = LINES) -> Iterator[np.ndarray]:
    """EVENT_DTYPE chunks of the file, in file order (the reader orders ties and validates)."""
    form = TextFormat(path, kind)
    t_type = np.float64 if form.seconds else np.int64
    dtype = np.dtype([("t", t_type), ("x", np.int64), ("y", np.int64), ("p", np.int64)])
    allowed = np.array(POLARITY_VALUES[polarity])
    try:
        with open(path, encoding="utf-8", errors="strict") as f:
            first = 1 + form.header_lines
            for _ in range(form.header_lines):
                next(f)
            while True:
                lines = list(itertools.islice(f, size))
                if not lines:
                    return
                try:
                    rows = np.loadtxt(lines, dtype=dtype, delimiter=form.delimiter, usecols=form.columns, comments="#", ndmin=1)
                except ValueError:
                    _raise_bad_line(path, form, lines, first)
                    raise  # pragma: no cover (the line is always found)
                # Line numbers of the rows: blank and comment lines give none.
                kept = np.flatnonzero([bool(s.strip()) and not s.lstrip().startswith("#") for s in lines]) + first
                yield _events(path, rows, kept, form.seconds, meta, allowed, polarity)
                first += len(lines)
    except UnicodeDecodeError as exc:
        raise EvclustError(f"{path}: not a text file ({exc.reason} at byte {exc.start} of a block)") from None


def _raise_bad_line(path: Path, form: TextFormat, lines: list[str], first: int) -> None:
    need = max(form.columns) + 1
    for number, line in enumerate(lines, first):
        text = line.strip()
        if not text or text.startswith("#"):
            continue
        fields = text.split(form.delimiter) if form.delimiter else text.split()
        if len(fields) < need:
            raise EvclustError(f"{path}: line {number}: {len(fields)} fields, expected at least {need}: {_shown(line)}")
        for name, column in zip("txyp", form.columns):
            value = fields[column].strip()
            try:
                float(value) if (name == "t" and form.seconds) else int(value)
            except ValueError:
                unit = "seconds" if form.seconds else "whole µs" if name == "t" else "an integer"
                raise EvclustError(f"{path}: line {number}: {name} {value[:30]!r} is not a number ({unit}): {_shown(line)}") from None
    raise EvclustError(f"{path}: lines {first} to {first + len(lines) - 1}: not readable as events")


def _events(path, rows, line_of, seconds, meta, allowed, polarity) -> np.ndarray:
    t = rows["t"]
    if seconds:
        bad = np.flatnonzero(~np.isfinite(t) | (t < 0) | (t * 1e6 >= 2.0**63))
        if bad.size:
            i = int(bad[0])
            raise EvclustError(f"{path}: line {line_of[i]}: time {t[i]!r} s is not a time from 0 on")
        t = np.rint(t * 1e6)
    faults = (
        ("t", t < 0, "is negative"),
        ("x", (rows["x"] < 0) | (rows["x"] >= meta.width), f"is outside the {meta.width}x{meta.height} sensor"),
        ("y", (rows["y"] < 0) | (rows["y"] >= meta.height), f"is outside the {meta.width}x{meta.height} sensor"),
        ("p", ~np.isin(rows["p"], allowed), f"is not a polarity of the '{polarity}' convention ({'/'.join(map(str, allowed))})"),
    )
    for name, bad, why in faults:
        where = np.flatnonzero(bad)
        if where.size:
            i = int(where[0])
            value = (t if name == "t" else rows[name])[i]
            raise EvclustError(
                f"{path}: line {line_of[i]} (event t={int(t[i])} us, x={rows['x'][i]}, y={rows['y'][i]}, p={rows['p'][i]}): "
                f"{name}={int(value)} {why}"
            )
    ev = np.zeros(rows.size, EVENT_DTYPE)
    ev["t"], ev["x"], ev["y"] = t, rows["x"], rows["y"]
    ev["p"] = np.where(rows["p"] > 0, 1, -1)
    return ev


class TextWriter:
    """`.txt`: `t x y p`, t in seconds with six decimals; `.csv`: `t,x,y,p`, t in µs. p is 0/1."""

    def __init__(self, tmp: Path, meta: EventMeta, kind: str):
        self.kind = kind
        self.file = open(tmp, "w", encoding="utf-8", newline="\n")
        if kind == "csv":
            self.file.write("t,x,y,p\n")

    def write(self, ev: np.ndarray) -> None:
        if not ev.size:
            return
        p = (ev["p"] > 0).astype(np.int64)
        x, y = ev["x"].astype(np.int64), ev["y"].astype(np.int64)
        if self.kind == "csv":
            np.savetxt(self.file, np.column_stack([ev["t"].astype(np.int64), x, y, p]), fmt="%d", delimiter=",")
        else:
            seconds, micro = np.divmod(ev["t"], np.uint64(1_000_000))
            np.savetxt(self.file, np.column_stack([seconds.astype(np.int64), micro.astype(np.int64), x, y, p]), fmt="%d.%06d %d %d %d")

    def close(self, failed: bool = False) -> None:
        self.file.close()
