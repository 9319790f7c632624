"""Golden vectors: up to date, self-consistent, and decodable to exactly what the model outputs."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import pytest

from evclust.clusterer.run import records_to_tracks
from evclust.fixed.model import FixedClusterer
from evclust.fixed.registers import SATURATING_SIGNALS
from evclust.vectors import CASES, check_vectors, record_fields
from evclust.vectors.pack import unpack

ROOT = Path(__file__).resolve().parents[2] / "vectors"


def test_the_committed_vectors_are_what_the_model_makes_now():
    assert check_vectors(ROOT) == [], "stale: run `make vectors`"


@pytest.mark.parametrize("name", list(CASES))
def test_manifest_hashes_and_counts_match_the_files(name):
    manifest = json.loads((ROOT / name / "manifest.json").read_text())
    for file, digest in manifest["sha256"].items():
        assert hashlib.sha256((ROOT / name / file).read_bytes()).hexdigest() == digest
    lines = {f: (ROOT / name / f).read_text().splitlines() for f in ("events.hex", "expected.hex", "trace.hex")}
    assert len(lines["events.hex"]) == len(lines["trace.hex"]) == manifest["counts"]["events"]
    assert len(lines["expected.hex"]) == manifest["counts"]["records"]
    widths = {len(line) for line in lines["events.hex"]}
    assert widths == {-(-sum(f["bits"] for f in manifest["layouts"]["events.hex"]) // 4)}


def _manifests() -> dict[str, dict]:
    return {name: json.loads((ROOT / name / "manifest.json").read_text()) for name in CASES}


def test_every_saturating_signal_saturates_somewhere_in_the_suite():
    # Each count is the model's; the RTL's status counters must equal it case by case (the
    # replay testbench compares them), so every saturate branch of the RTL is exercised.
    totals = dict.fromkeys(SATURATING_SIGNALS, 0)
    for name, manifest in _manifests().items():
        assert list(manifest["counts"]["saturations"]) == list(SATURATING_SIGNALS), name
        for signal, count in manifest["counts"]["saturations"].items():
            totals[signal] += count
    assert all(totals.values()), f"never saturated: {[s for s, c in totals.items() if not c]}"


def test_every_action_of_the_table_happens_somewhere_in_the_suite():
    actions = ("created", "evicted", "dropped", "expired", "exited", "merged", "unsupported", "noise_decisions")
    totals = {a: sum(m["counts"][a] for m in _manifests().values()) for a in actions}
    assert all(totals.values()), f"never happens: {[a for a, c in totals.items() if not c]}"
    # A slot freed by expiry is used again: more clusters created than the table holds, with expiries.
    recreate = _manifests()["expire_evict_recreate"]
    assert recreate["counts"]["expired"] >= 1 and recreate["counts"]["evicted"] >= 1 and recreate["counts"]["dropped"] >= 1
    assert recreate["counts"]["created"] > recreate["n_clusters"]


def test_expected_records_decode_to_the_models_output():
    case = CASES["pedestrian_clip"]()
    model = FixedClusterer(case.params, case.width, case.height, case.t_frame_us)
    tracks = records_to_tracks(model.feed(case.events))
    fields = record_fields(model.table)
    words = [int(line, 16) for line in (ROOT / "pedestrian_clip" / "expected.hex").read_text().split()]
    assert len(words) == tracks.size > 0
    for word, row in zip(words, tracks):
        values = unpack(word, fields)
        for value, (name, _, _, frac) in zip(values, fields):
            assert value * 2.0**-frac == float(row[name]), name


def test_the_wrap_case_wraps_and_the_tie_case_ties_low():
    t = [int(line, 16) >> (sum(f["bits"] for f in json.loads((ROOT / "timestamp_wrap" / "manifest.json").read_text())["layouts"]["events.hex"]) - 32)
         for line in (ROOT / "timestamp_wrap" / "events.hex").read_text().split()]  # fmt: skip
    drops = [i for i in range(1, len(t)) if t[i] < t[i - 1]]
    assert len(drops) == 1 and 0 < drops[0] < len(t) - 1  # one wrap, mid-stream
    manifest = json.loads((ROOT / "palette_tie" / "manifest.json").read_text())
    layout = {f["name"]: f for f in manifest["layouts"]["expected.hex"]}
    classes = set()
    for line in (ROOT / "palette_tie" / "expected.hex").read_text().split():
        f = layout["class"]
        v = (int(line, 16) >> f["lsb"]) & ((1 << f["bits"]) - 1)
        classes.add(v - (1 << f["bits"]) if v >> (f["bits"] - 1) else v)
    # Every event is at Y = 120, equidistant from the entries at 100 and 140: the tie goes to entry 0.
    assert classes == {0}
