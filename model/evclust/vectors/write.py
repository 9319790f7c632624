"""Writing the vector cases, and checking the committed ones are what the model makes now."""

from __future__ import annotations

import hashlib
import json
import tempfile
from pathlib import Path
from typing import NamedTuple

import numpy as np

from evclust import __version__
from evclust.clusterer.run import records_to_tracks, rows_to_records
from evclust.errors import atomic_folder
from evclust.fixed.model import FixedClusterer
from evclust.fixed.registers import SATURATING_SIGNALS
from evclust.vectors.cases import CASES, Case
from evclust.tracks import OBJECT_DTYPE
from evclust.fixed.layouts import TRACE_FIELDS, event_fields, object_fields, record_fields
from evclust.vectors.pack import event_words, hex_lines, object_words, pack, record_words

FILES = ("events.hex", "expected.hex", "trace.hex", "objects.hex")


def _layout(fields) -> list[dict]:
    """Field name, width, signedness and LSB position (bit 0 = the word's last bit)."""
    out, lsb = [], sum(f[1] for f in fields)
    for name, width, signed, *rest in fields:
        lsb -= width
        out.append({"name": name, "bits": width, "signed": signed, "lsb": lsb} | ({"frac_bits": rest[0]} if rest else {}))
    return out


class ModelWords(NamedTuple):
    """A stream's words as the RTL's ports carry them."""

    events: list[int]
    records: list[int]  # cluster records
    trace: list[int]
    objects: list[int]  # object records (none without an object layer)


def model_words(model: FixedClusterer, events: np.ndarray, objects=None) -> ModelWords:
    """Feed events to the fixed model and, when its parameters have one, its object layer
    (`objects`, made on the first call if None: pass the same one to feed a stream in pieces)."""
    trace = np.zeros(events.size, np.int64)
    rows = model.feed(events, trace)
    words = [pack((int(v) >> 16, int(v) & 0xFFFF), TRACE_FIELDS) for v in trace]
    object_list = []
    if model.params.objects:
        layer = objects if objects is not None else model.object_layer()
        object_list = object_words(rows_to_records(layer.feed(rows, model.steps), OBJECT_DTYPE), model.table)
    return ModelWords(event_words(events, model.table), record_words(records_to_tracks(rows), model.table), words, object_list)


def _counts(model: FixedClusterer) -> dict:
    """The run's counters, with every saturating signal's count (0 included) in register order."""
    stats = model.stats()
    return stats | {"saturations": {name: stats["saturations"].get(name, 0) for name in SATURATING_SIGNALS}}


def write_case(name: str, folder: Path, case: Case | None = None) -> dict:
    """Write one case: a built-in one by name, or `case` (e.g. from an event file) under `name`."""
    case = case or CASES[name]()
    model = FixedClusterer(case.params, case.width, case.height, case.t_frame_us, **case.formats)
    layer = model.object_layer() if case.params.objects else None
    event_list, record_list, trace_list, object_list = model_words(model, case.events, layer)
    table = model.table
    contents = {
        "events.hex": hex_lines(event_list, event_fields(table)),
        "expected.hex": hex_lines(record_list, record_fields(table)),
        "trace.hex": hex_lines(trace_list, TRACE_FIELDS),
        "objects.hex": hex_lines(object_list, object_fields(table)),
    }
    manifest = {
        "case": name,
        "description": case.description,
        "source": case.source,
        "seed": case.seed,
        "model": f"evclust {__version__}, fixed-point model",
        "sensor": {"width": case.width, "height": case.height},
        "t_frame_us": case.t_frame_us,
        "n_clusters": case.params.n_clusters,
        "palette_size": len(case.params.palette),
        "parameters": case.params.model_dump(mode="json", exclude_none=True),
        "format_options": case.formats,
        "constants": {c.name: c.raw for c in table.constants.values()},
        "formats": {
            f.name: {
                "q": f.q,
                "signed": f.signed,
                "int_bits": f.int_bits,
                "frac_bits": f.frac_bits,
                "rounding": f.rounding,
                "overflow": f.overflow,
            }
            for f in table.formats.values()
        },  # fmt: skip
        "layouts": {
            "events.hex": _layout(event_fields(table)),
            "expected.hex": _layout(record_fields(table)),
            "trace.hex": _layout(TRACE_FIELDS),
            "objects.hex": _layout(object_fields(table)),
        },  # fmt: skip
        "counts": {
            "events": int(case.events.size),
            "records": len(record_list),
            "objects": len(object_list),
            **_counts(model),
            **({"object_layer": layer.stats()} if layer is not None else {}),
        },
        "sha256": {file: hashlib.sha256(text.encode()).hexdigest() for file, text in contents.items()},
    }
    with atomic_folder(folder) as tmp:  # a case is whole or absent, even if interrupted
        for file, text in contents.items():
            (tmp / file).write_text(text)
        (tmp / "manifest.json").write_text(json.dumps(manifest, indent=1, sort_keys=False) + "\n")
    return manifest


def write_vectors(root: Path, names=None) -> dict[str, dict]:
    return {name: write_case(name, Path(root) / name) for name in (names or CASES)}


def check_vectors(root: Path) -> list[str]:
    """Cases whose committed files differ from a fresh generation (empty: all up to date)."""
    stale = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in CASES:
            write_case(name, Path(tmp) / name)
            for file in (*FILES, "manifest.json"):
                committed = Path(root) / name / file
                if not committed.is_file() or committed.read_bytes() != (Path(tmp) / name / file).read_bytes():
                    stale.append(f"{name}/{file}")
    return stale
