"""synth/activity_reference.py times the activity against a reference time in a harness, its
datapath apart from the core's other paths: the harness must compute what the fixed model
computes, or its figures price something else. Icarus runs it on random operands against evclust.fixed.arith."""

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


def test_the_stored_product_harness_computes_the_fixed_models_paper_commit(harness, tmp_path):
    harness.check_the_stored_product(*harness._header_formats(), out=tmp_path)


# A harness one step away from the model, and the check that must catch it.
MUTATIONS = {
    "a table index rounded differently": (
        "activity_reference.v", "(DECAY_TABLE_FRAC + left[8:6])", "(DECAY_TABLE_FRAC + left[8:6] + (left[5:0] == 6'd7))",
        "check_against_the_model",
    ),
    "a stored product that forgets the clock's wrap": ("activity_paper.v", "(wrapped_q ?", "(1'b0 ?", "check_the_stored_product"),
}  # fmt: skip


@pytest.mark.parametrize("mutation", MUTATIONS)
def test_a_harness_one_step_from_the_model_is_caught(harness, tmp_path, monkeypatch, mutation):
    file, old, new, check = MUTATIONS[mutation]
    text = (SYNTH / "activity" / file).read_text()
    broken = text.replace(old, new)
    assert broken != text
    (tmp_path / file).write_text(broken)
    monkeypatch.setattr(harness, "HARNESS", tmp_path)
    with pytest.raises(EvclustError, match="differs from the fixed model"):
        getattr(harness, check)(*harness._header_formats(), out=tmp_path / "check")
