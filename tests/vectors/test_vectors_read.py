"""Reading vector cases back for the testbenches, and the scoreboard's reports."""

from __future__ import annotations

import hashlib
import json
import shutil
from pathlib import Path

import pytest

from evclust.errors import EvclustError
from evclust.vectors import CASES
from evclust.fixed.layouts import TRACE_FIELDS, event_fields, record_fields
from evclust.vectors.pack import pack, unpack
from evclust.vectors.read import load_case
from evclust.vectors.scoreboard import first_mismatch

VECTORS = Path(__file__).resolve().parents[2] / "vectors"


def _copy(tmp_path, name="gaps") -> Path:
    folder = tmp_path / name
    shutil.copytree(VECTORS / name, folder)
    return folder


def _rehash(folder: Path, file: str) -> None:
    manifest = json.loads((folder / "manifest.json").read_text())
    manifest["sha256"][file] = hashlib.sha256((folder / file).read_bytes()).hexdigest()
    (folder / "manifest.json").write_text(json.dumps(manifest))


@pytest.mark.parametrize("name", list(CASES))
def test_every_committed_case_loads_and_its_header_matches_its_manifest(name):
    case = load_case(VECTORS / name)
    assert len(case.events) == len(case.trace) == case.manifest["counts"]["events"]
    assert len(case.expected) == case.manifest["counts"]["records"]
    assert f"localparam integer N_CLUSTERS = {case.manifest['n_clusters']};" in case.header
    load_case(VECTORS / name, rtl_header=case.header)  # its own header is accepted


def test_an_edited_file_is_refused_by_its_hash(tmp_path):
    folder = _copy(tmp_path)
    text = (folder / "events.hex").read_text()
    (folder / "events.hex").write_text(text.replace("0", "1", 1))
    with pytest.raises(EvclustError, match="events.hex: sha256 differs from the manifest's"):
        load_case(folder)


def test_a_malformed_line_is_located(tmp_path):
    folder = _copy(tmp_path)
    lines = (folder / "trace.hex").read_text().splitlines()
    lines[9] = "zz" + lines[9][2:]
    (folder / "trace.hex").write_text("\n".join(lines) + "\n")
    _rehash(folder, "trace.hex")
    with pytest.raises(EvclustError, match=r"trace.hex:10: 'zz.*' is not hexadecimal"):
        load_case(folder)


def test_a_short_line_and_a_truncated_file_are_named(tmp_path):
    folder = _copy(tmp_path)
    lines = (folder / "expected.hex").read_text().splitlines()
    (folder / "expected.hex").write_text("\n".join([lines[0][:-1], *lines[1:]]) + "\n")
    _rehash(folder, "expected.hex")
    with pytest.raises(EvclustError, match=r"expected.hex:1: \d+ hex digits, the layout needs \d+"):
        load_case(folder)
    (folder / "expected.hex").write_text("\n".join(lines[:-1]) + "\n")
    _rehash(folder, "expected.hex")
    with pytest.raises(EvclustError, match=r"expected.hex: \d+ lines, the manifest says \d+ \(truncated\?\)"):
        load_case(folder)


def test_missing_files_and_a_foreign_header_are_refused(tmp_path):
    with pytest.raises(EvclustError, match="no manifest.json; not a vector case"):
        load_case(tmp_path)
    folder = _copy(tmp_path)
    (folder / "trace.hex").unlink()
    with pytest.raises(EvclustError, match="trace.hex: missing"):
        load_case(folder)
    other = load_case(VECTORS / "traffic_clip").header
    with pytest.raises(EvclustError, match=r"made for another parameter set .*N=16 on 64x48"):
        load_case(VECTORS / "gaps", rtl_header=other)


def _streams(name="table_full"):
    case = load_case(VECTORS / name)
    tags = [1] * len(case.expected)  # the tag only locates the report
    args = (case.events, event_fields(case.table), case.trace, list(case.trace), record_fields(case.table), case.expected)
    return case, args, tags


def test_the_scoreboard_passes_identical_streams_and_names_the_first_wrong_trace():
    case, args, tags = _streams()
    assert first_mismatch("c", *args, list(case.expected), tags) is None
    trace = list(case.trace)
    drops = [i for i, w in enumerate(trace) if unpack(w, TRACE_FIELDS)[0] == 3]
    trace[drops[0]] = pack((1, 2), TRACE_FIELDS)  # the RTL would have created in slot 2
    events, fields, expected_trace, _, rec_fields, expected = args
    message = first_mismatch("c", events, fields, expected_trace, trace, rec_fields, expected, list(expected), tags)
    assert message.startswith(f"c: event {drops[0]} (events.hex/trace.hex line {drops[0] + 1}: t=")
    assert message.endswith("RTL did 'create slot 2', the model 'drop slot 0'")


def test_the_scoreboard_lists_every_wrong_field_of_the_first_wrong_record():
    case, args, tags = _streams()
    fields = record_fields(case.table)
    names = [f[0] for f in fields]
    records = list(case.expected)
    values = unpack(records[3], fields)
    values[names.index("y")] += 1
    values[names.index("class")] = -1 if values[names.index("class")] != -1 else 0
    records[3] = pack(values, fields)
    records[5] ^= 1  # a later difference is not reported
    tags = list(range(1, len(records) + 1))
    message = first_mismatch("c", *args, records, tags)
    want = unpack(case.expected[3], fields)
    assert message == (
        f"c: record 3 (expected.hex line 4), emitted after event 3 (trace.hex line 4): "
        f"y: RTL {want[names.index('y')] + 1}, model {want[names.index('y')]}; "
        f"class: RTL {values[names.index('class')]}, model {want[names.index('class')]}"
    )
    assert "the RTL emitted 309 records, the model 310" in first_mismatch("c", *args, list(case.expected)[:-1], tags)


def test_the_scoreboard_reports_whichever_difference_comes_first_in_the_stream():
    case, args, _ = _streams()
    events, fields, expected_trace, _, rec_fields, expected = args
    trace, records = list(expected_trace), list(expected)
    trace[600] = pack((3, 0), TRACE_FIELDS) if trace[600] != pack((3, 0), TRACE_FIELDS) else pack((0, 1), TRACE_FIELDS)
    records[2] ^= 1 << 4
    tags = [10] * len(records)  # every record left after event 9, long before the trace difference
    assert first_mismatch("c", events, fields, expected_trace, trace, rec_fields, expected, records, tags).startswith("c: record 2 ")
    tags = [700] * len(records)  # now the trace difference comes first
    assert first_mismatch("c", events, fields, expected_trace, trace, rec_fields, expected, records, tags).startswith("c: event 600 ")
