"""The functional-coverage bins of the RTL runs (evclust.rtl.coverage): what each source adds,
how runs merge, and how holes and unexpected arcs are named."""

from __future__ import annotations

import json

import pytest

from evclust.errors import EvclustError

from evclust.fixed.registers import SATURATING_SIGNALS
from evclust.rtl import coverage


def _fsm(**arcs):
    arc = [0] * 64
    for name, count in arcs.items():
        a, b = name.split("_to_")
        arc[coverage.STATES.index(a) * 8 + coverage.STATES.index(b)] = count
    return {"state": [1] * 8, "arc": arc, "phase": [2, 0, 1, 0], "stream": [3, 0, 0, 4]}


def test_each_source_fills_its_bins():
    records = [{"flags": 0b0101, "class": 2}, {"flags": 0, "class": -1}]
    bins = coverage.run_bins(_fsm(INIT_to_IDLE=1, SWEEP_to_INIT=5, SWEEP_to_EXEC=2), {"creates": 7, "sat_gamma": 3}, records)
    assert bins["action: creates"] == 7 and bins["action: drops"] == 0
    assert bins["saturation: gamma"] == 3 and bins["saturation: activity"] == 0
    assert bins["flag: new set"] == 1 and bins["flag: new clear"] == 1  # bit 0
    assert bins["flag: moving (MCM) set"] == 1 and bins["flag: border set"] == 0  # bit 2 set, bit 1 never
    assert bins["class: none"] == 1 and bins["class: a palette entry"] == 1
    assert bins["arc: INIT -> IDLE"] == 1
    assert not any(name.endswith("-> INIT") for name in bins)  # a reset is no arc of the design
    assert bins["arc: SWEEP -> EXEC"] == 2 and coverage.unexpected(bins) == ["arc: SWEEP -> EXEC"]
    assert bins["filter step: decide"] == 2 and bins["filter step: divide the frame period"] == 1
    assert bins["stream: an event in and a record out in one cycle"] == 4


def test_runs_merge_by_sum_and_holes_are_the_empty_bins(tmp_path):
    one = coverage.run_bins(_fsm(INIT_to_IDLE=1), {"creates": 1}, [])
    two = coverage.run_bins(_fsm(IDLE_to_EXEC=2), {f"sat_{s}": 1 for s in SATURATING_SIGNALS}, [])
    for i, bins in enumerate((one, two)):
        (tmp_path / f"{i}.json").write_text(json.dumps({"bins": bins}))
    merged, runs = coverage.load(tmp_path)
    assert runs == 2
    assert merged["arc: INIT -> IDLE"] == 1 and merged["arc: IDLE -> EXEC"] == 2 and merged["state: IDLE"] == 2
    assert all(merged[f"saturation: {s}"] == 1 for s in SATURATING_SIGNALS)
    holes = coverage.holes(merged)
    assert "action: drops" in holes and "action: creates" not in holes and "arc: IDLE -> EXEC" not in holes


def test_the_report_rewrites_only_its_section(tmp_path):
    doc = tmp_path / "doc.md"
    doc.write_text(f"before\n{coverage.BEGIN}\nold\n{coverage.END}\nafter\n")
    bins = coverage.run_bins(_fsm(INIT_to_IDLE=1), {}, [])
    coverage.write_table(doc, coverage.markdown(bins, 1))
    text = doc.read_text()
    assert text.startswith("before\n") and text.endswith("after\n") and "old" not in text
    assert f"{coverage.BEGIN}\n<!-- inputs: formats=" in text  # its input stamp (evclust.stamps)
    other = tmp_path / "other.md"
    other.write_text("no coverage section here\n")
    with pytest.raises(EvclustError, match="no <!-- coverage:begin --> ... <!-- coverage:end --> section"):
        coverage.write_table(other, [])
    assert other.read_text() == "no coverage section here\n"
    assert "| arc | INIT -> IDLE | 1 |" in text and "| action | drops | 0 **hole** |" in text
