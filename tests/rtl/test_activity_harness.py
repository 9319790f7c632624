"""synth/activity_reference.py times the activity against a reference time in a harness, since the
RTL does not carry the mode yet: the harness must compute what the fixed model computes, or its
figures price something else. Icarus runs it on random operands against evclust.fixed.arith."""

from __future__ import annotations

from pathlib import Path

import pytest

from evclust.errors import EvclustError

SYNTH = Path(__file__).resolve().parents[2] / "synth"


@pytest.fixture
def harness(monkeypatch):
    monkeypatch.syspath_prepend(str(SYNTH))  # a script importing its neighbour synth.py, as scripts do
    import activity_reference

    return activity_reference


def test_the_reference_harness_computes_the_fixed_models_weight_commit_and_sweep(harness, tmp_path):
    harness.check_against_the_model(*harness._header_formats(), out=tmp_path)


def test_a_harness_that_rounds_one_table_index_differently_is_caught(harness, tmp_path, monkeypatch):
    text = (SYNTH / "activity" / "activity_reference.v").read_text()
    broken = text.replace("(DECAY_TABLE_FRAC + left[8:6])", "(DECAY_TABLE_FRAC + left[8:6] + (left[5:0] == 6'd7))")
    assert broken != text
    (tmp_path / "activity_reference.v").write_text(broken)
    monkeypatch.setattr(harness, "HARNESS", tmp_path)
    with pytest.raises(EvclustError, match="differs from the fixed model"):
        harness.check_against_the_model(*harness._header_formats(), out=tmp_path / "check")


def test_the_stored_product_harness_computes_the_fixed_models_paper_commit(harness, tmp_path):
    harness.check_the_stored_product(*harness._header_formats(), out=tmp_path)


def test_a_stored_product_that_forgets_the_clocks_wrap_is_caught(harness, tmp_path, monkeypatch):
    text = (SYNTH / "activity" / "activity_paper.v").read_text()
    broken = text.replace("(wrapped_q ?", "(1'b0 ?")
    assert broken != text
    (tmp_path / "activity_paper.v").write_text(broken)
    monkeypatch.setattr(harness, "HARNESS", tmp_path)
    with pytest.raises(EvclustError, match="differs from the fixed model"):
        harness.check_the_stored_product(*harness._header_formats(), out=tmp_path / "check")
