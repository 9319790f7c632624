"""Reading a vector case back, for the testbenches: every file checked before anything runs, so a
malformed, truncated or foreign case fails with one clear message instead of a hang or a
mismatch deep in a simulation."""

from __future__ import annotations

import dataclasses
import hashlib
import json
from pathlib import Path

from evclust.clusterer import ClustererParams
from evclust.errors import EvclustError
from evclust.fixed.formats import FormatTable, build_formats
from evclust.fixed.header import verilog_header
from evclust.fixed.layouts import TRACE_FIELDS, event_fields, object_fields, record_fields
from evclust.vectors.write import FILES


@dataclasses.dataclass
class VectorCase:
    name: str
    folder: Path
    manifest: dict
    params: ClustererParams
    table: FormatTable
    events: list[int]
    expected: list[int]
    trace: list[int]
    objects: list[int]  # the object records (none without an object layer)

    @property
    def header(self) -> str:
        """The RTL parameter header this case needs (`rtl/evclust_params.vh` for its parameters)."""
        return verilog_header(self.table)


def _words(path: Path, fields, count: int) -> list[int]:
    bits = sum(f[1] for f in fields)
    digits = -(-bits // 4)
    words = []
    for number, line in enumerate(path.read_text().splitlines(), 1):
        text = line.strip()
        if len(text) != digits:
            raise EvclustError(f"{path}:{number}: {len(text)} hex digits, the layout needs {digits}")
        try:
            word = int(text, 16)
        except ValueError:
            raise EvclustError(f"{path}:{number}: {text!r} is not hexadecimal") from None
        if word >> bits:
            raise EvclustError(f"{path}:{number}: the word has bits above the layout's {bits}")
        words.append(word)
    if len(words) != count:
        raise EvclustError(f"{path}: {len(words)} lines, the manifest says {count} (truncated?)")
    return words


def load_case(folder: str | Path, rtl_header: str | None = None) -> VectorCase:
    """A case folder, checked: manifest, sha256 of each file, line counts, widths. With
    `rtl_header` (the evclust_params.vh the RTL was built with), a case made for another
    parameter set is refused."""
    folder = Path(folder)
    try:
        manifest = json.loads((folder / "manifest.json").read_text())
    except FileNotFoundError:
        raise EvclustError(f"{folder}: no manifest.json; not a vector case") from None
    except json.JSONDecodeError as exc:
        raise EvclustError(f"{folder}/manifest.json: not valid JSON ({exc.msg}, line {exc.lineno})") from None
    for key in ("parameters", "sensor", "t_frame_us", "constants", "counts", "sha256"):
        if key not in manifest:
            raise EvclustError(f"{folder}/manifest.json: no '{key}'")
    for file in FILES:
        path = folder / file
        if not path.is_file():
            raise EvclustError(f"{path}: missing")
        digest = hashlib.sha256(path.read_bytes()).hexdigest()
        if digest != manifest["sha256"].get(file):
            raise EvclustError(f"{path}: sha256 differs from the manifest's (edited or truncated; `make vectors` regenerates)")
    params = ClustererParams(**manifest["parameters"])
    own = build_formats(params, manifest["sensor"]["width"], manifest["sensor"]["height"], manifest["t_frame_us"],
                        **manifest.get("format_options", {}))  # fmt: skip
    constants = {c.name: c.raw for c in own.constants.values()}
    if constants != manifest["constants"]:
        bad = sorted(set(constants.items()) ^ set(manifest["constants"].items()))[0][0]
        raise EvclustError(f"{folder}/manifest.json: constant {bad} is not what the parameters quantise to")
    if rtl_header is not None:
        _same_configuration(folder, own, rtl_header)
    counts = manifest["counts"]
    return VectorCase(
        folder.name, folder, manifest, params, own,
        _words(folder / "events.hex", event_fields(own), counts["events"]),
        _words(folder / "expected.hex", record_fields(own), counts["records"]),
        _words(folder / "trace.hex", TRACE_FIELDS, counts["events"]),
        _words(folder / "objects.hex", object_fields(own), counts["objects"]),
    )  # fmt: skip


def _same_configuration(folder: Path, case: FormatTable, rtl_header: str) -> None:
    ours = verilog_header(case)
    if ours != rtl_header:
        pairs = zip(ours.splitlines(), rtl_header.splitlines())
        line = next((a for a, b in pairs if a != b), "the header's length")
        raise EvclustError(
            f"{folder}: made for another parameter set than the RTL was built with "
            f"(N={case.n_clusters} on {case.width}x{case.height}; first difference: {line.split('//')[0].strip()})"
        )
