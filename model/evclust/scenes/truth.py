"""Ground-truth CSV: one row per visible object per frame."""

from __future__ import annotations

import csv
import io
from pathlib import Path

import numpy as np

from evclust.errors import EvclustError, atomic_output
from evclust.scenes.schema import LABEL_CHARS
from evclust.scenes.synthetic import TRUTH_COLUMNS, TRUTH_OPTIONAL


def write_truth(path: str | Path, rows: list[dict]) -> None:
    with atomic_output(path) as tmp:
        with open(tmp, "w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=TRUTH_COLUMNS + tuple(TRUTH_OPTIONAL))
            writer.writeheader()
            writer.writerows({**TRUTH_OPTIONAL, **row} for row in rows)  # optional columns at their defaults


# ---------------------------------------------------------------------------------------------
# Reading (docs/METRICS.md "Ground truth"): a numpy structured array, one element per CSV row.

TRUTH_DTYPE = np.dtype(
    [
        ("frame", np.int64),  # frame index k; the row describes the object at t_k = k · t_frame
        ("t_us", np.float64),
        ("id", np.int64),  # object id
        ("cx", np.float64),  # box centre, px (pixel-index coordinates)
        ("cy", np.float64),
        ("w", np.float64),  # bounding box, px
        ("h", np.float64),
        ("vx", np.float64),  # velocity from frame k to k+1, px/frame
        ("vy", np.float64),
        ("Y", np.float64),  # mean colour of the object's own pixels, BT.601 full range
        ("Cb", np.float64),
        ("Cr", np.float64),
        ("label", f"U{LABEL_CHARS}"),  # colour label, compared with the palette entry names
        ("fully_visible", np.bool_),  # the whole box is inside the sensor
        ("visible", np.float64),  # optional: area fraction in view and not occluded (default 1)
    ]
)
assert TRUTH_DTYPE.names == TRUTH_COLUMNS + tuple(TRUTH_OPTIONAL)
_INTEGER_COLUMNS = ("frame", "id")
_TEXT_COLUMNS = ("label",)
_BOOL_WORDS = {"0": False, "1": True, "false": False, "true": True}


def _parse_value(name: str, text: str):
    """One CSV cell -> its typed value; ValueError with the fault in words."""
    text = text.strip()
    if name == "label":
        if len(text) > LABEL_CHARS:
            raise ValueError(f"column label: '{text[:40]}...' is longer than {LABEL_CHARS} characters")
        return text
    if name == "fully_visible":
        word = text.lower()
        if word in _BOOL_WORDS:
            return _BOOL_WORDS[word]
        try:
            value = float(text)
        except ValueError:
            raise ValueError(f"column fully_visible: '{text[:40]}' is not 0/1 or true/false") from None
        if value not in (0.0, 1.0):
            raise ValueError(f"column fully_visible: '{text[:40]}' is not 0/1 or true/false")
        return bool(value)
    try:
        value = float(text)
    except ValueError:
        raise ValueError(f"column {name}: '{text[:40]}' is not a number") from None
    if not np.isfinite(value):
        raise ValueError(f"column {name}: '{text[:40]}' is not a finite number")
    if name == "visible" and not 0.0 <= value <= 1.0:
        raise ValueError(f"column visible: {text[:40]} is not a fraction in [0, 1]")
    if name in _INTEGER_COLUMNS:
        if value != int(value):
            raise ValueError(f"column {name}: '{text[:40]}' is not an integer")
        if name == "frame" and value < 0:
            raise ValueError(f"column frame: {text[:40]} is negative")
        return int(value)
    return value


def truth_array(rows) -> np.ndarray:
    """Ground truth as TRUTH_DTYPE from an array of that dtype or from dicts keyed by TRUTH_COLUMNS
    (as `write_truth` takes and a synthetic scene's `truth()` returns)."""
    if isinstance(rows, np.ndarray) and rows.dtype == TRUTH_DTYPE:
        return rows
    if isinstance(rows, np.ndarray) and rows.dtype.names is not None:
        missing = [c for c in TRUTH_COLUMNS if c not in rows.dtype.names]
        if missing:
            raise EvclustError(f"ground truth: missing field(s) {', '.join(missing)}")
        out = np.zeros(rows.size, dtype=TRUTH_DTYPE)
        for name in TRUTH_COLUMNS:
            out[name] = rows[name]
        for name, default in TRUTH_OPTIONAL.items():
            out[name] = rows[name] if name in rows.dtype.names else default
        return out
    out = np.zeros(len(rows), dtype=TRUTH_DTYPE)
    for i, row in enumerate(rows):
        missing = [c for c in TRUTH_COLUMNS if c not in row]
        if missing:
            raise EvclustError(f"ground truth: row {i}: missing field(s) {', '.join(missing)}")
        try:
            out[i] = tuple(_parse_value(c, str(row[c])) for c in TRUTH_COLUMNS) + tuple(
                _parse_value(c, str(row.get(c, default))) for c, default in TRUTH_OPTIONAL.items()
            )
        except ValueError as exc:
            raise EvclustError(f"ground truth: row {i}: {exc}") from None
    return out


def read_truth(path: str | Path) -> np.ndarray:
    """Read a ground-truth CSV written by `write_truth` (or by hand, for a video).

    Returns a numpy structured array of dtype TRUTH_DTYPE, one element per data row, in file
    order. The header must name every column of TRUTH_COLUMNS (in any order; extra columns are
    ignored; `visible` is optional, 1.0 when absent, and must lie in [0, 1]). Numbers must be finite, `frame` and `id` integers, `frame` >= 0, `fully_visible`
    0/1 or true/false, `label` at most 32 characters; one (frame, id) pair per file. Any fault
    raises EvclustError with one line naming the file, the line number and the fault.
    """
    path = Path(path)
    if not path.is_file():
        raise EvclustError(f"{path}: no such ground-truth file")
    try:
        text = path.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError as exc:
        raise EvclustError(f"{path}: not a text file ({exc.reason} at byte {exc.start})") from None
    reader = csv.reader(io.StringIO(text))
    try:
        header = next(reader, None)
    except csv.Error as exc:
        raise EvclustError(f"{path}: line 1: {exc}") from None
    if header is None:
        raise EvclustError(f"{path}: line 1: empty file, expected a header naming {', '.join(TRUTH_COLUMNS)}")
    header = [h.strip() for h in header]
    missing = [c for c in TRUTH_COLUMNS if c not in header]
    if missing:
        raise EvclustError(f"{path}: line 1: missing column(s) {', '.join(missing)}")
    index = [header.index(c) for c in TRUTH_COLUMNS]
    optional = [(header.index(c) if c in header else None, c, default) for c, default in TRUTH_OPTIONAL.items()]
    rows = []
    seen: dict[tuple[int, int], int] = {}
    line_no = 1
    try:
        for row in reader:
            line_no = reader.line_num
            if not row or all(not cell.strip() for cell in row):
                continue
            if len(row) < len(header):
                raise EvclustError(f"{path}: line {line_no}: {len(row)} values, the header names {len(header)} columns")
            try:
                values = tuple(_parse_value(c, row[i]) for i, c in zip(index, TRUTH_COLUMNS)) + tuple(
                    default if i is None else _parse_value(c, row[i]) for i, c, default in optional
                )
            except ValueError as exc:
                raise EvclustError(f"{path}: line {line_no}: {exc}") from None
            key = (values[0], values[2])
            if key in seen:
                raise EvclustError(f"{path}: line {line_no}: object {key[1]} already has a row for frame {key[0]} (line {seen[key]})")
            seen[key] = line_no
            rows.append(values)
    except csv.Error as exc:
        raise EvclustError(f"{path}: line {reader.line_num}: {exc}") from None
    return np.array(rows, dtype=TRUTH_DTYPE)
