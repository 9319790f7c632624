"""`evclust generalize --pipeline` (docs/PIPELINE.md): the paired comparison and its page."""

from __future__ import annotations

import numpy as np

from evclust.cli import main
from evclust.suite.pipeline import (
    PERTURBATIONS, REFERENCE_VARIANTS, SWEEP_SLOTS, SWEEP_VARIANTS, TARGET_POINTS, configurations, reference_section, section,
    sweep_section,
)  # fmt: skip


def test_every_delay_is_paired_with_the_sequential_update_on_every_perturbation():
    runs = [c for c in configurations(delays=(2, 5)) if c.name.split("|")[1].isdigit()]
    names = {(c.name.split("|")[0], int(c.name.split("|")[1])) for c in runs}
    assert names == {(p, d) for p in PERTURBATIONS for d in (0, 2, 5)}
    for c in runs:
        perturbation, delay = c.name.split("|")
        assert c.params.update_delay == int(delay) and c.model == "float" and not c.params.activity_reference
        for key, value in PERTURBATIONS[perturbation].items():
            assert getattr(c.params, key) == value


def test_the_activity_reference_is_paired_with_the_papers_activity_in_each_model():
    by_name = {c.name: c for c in configurations(delays=(2,))}
    for perturbation, update in PERTURBATIONS.items():
        for model, before, after in REFERENCE_VARIANTS.values():
            a, b = by_name[f"{perturbation}|{before}"], by_name[f"{perturbation}|{after}"]
            assert (a.model, b.model) == (model, model)
            assert not a.params.activity_reference and b.params.activity_reference
            assert a.params.model_copy(update={"activity_reference": True}) == b.params  # the one switch apart
            for key, value in update.items():
                assert getattr(b.params, key) == value
    assert {by_name[f"defaults|{after}"].params.update_delay for _, _, after in REFERENCE_VARIANTS.values()} == {0, 2}


def test_the_sweep_beside_the_events_is_paired_with_the_sweep_between_them_one_switch_apart():
    by_name = {c.name: c for c in configurations(delays=(2,))}
    for perturbation in PERTURBATIONS:
        for model, before, after in SWEEP_VARIANTS.values():
            a, b = by_name[f"{perturbation}|{before}"], by_name[f"{perturbation}|{after}"]
            assert (a.model, b.model) == (model, model)
            assert a.params.sweep_slots_per_event == 0 and b.params.sweep_slots_per_event == SWEEP_SLOTS
            assert a.params.model_copy(update={"sweep_slots_per_event": SWEEP_SLOTS}) == b.params
    # the paper's update, and the pipelined core's (D = 2 against a reference time) in both models
    rows = {(by_name[f"defaults|{after}"].model, by_name[f"defaults|{after}"].params.update_delay,
             by_name[f"defaults|{after}"].params.activity_reference) for _, _, after in SWEEP_VARIANTS.values()}  # fmt: skip
    assert rows == {("float", 0, False), ("float", 2, True), ("fixed", 2, True)}
    base = ({"HOTA": 0.5}, {"HOTA": 0.5})
    zeros = np.zeros(2)
    changes = {("float, D = 0", "objects"): {"HOTA": np.array([-0.4, -0.8]), "recall": zeros, "precision": zeros, "base": base}}
    text = "\n".join(sweep_section(changes, held_out=True))
    assert "| float, D = 0 | objects | 50.0 → 50.0 % | -0.60 ± 0.20 |" in text and "| float, D = 0 | -0.60 points | no |" in text


def test_the_reference_section_gives_each_rows_mean_change_and_judges_it_on_the_held_out_split():
    base = ({"HOTA": 0.5}, {"HOTA": 0.51})
    zeros = np.zeros(2)
    changes = {
        ("float", "objects"): {"HOTA": np.array([0.1, 0.3]), "recall": zeros, "precision": zeros, "base": base},
        ("fixed", "objects"): {"HOTA": np.array([-0.6, -0.8]), "recall": zeros, "precision": zeros, "base": base},
    }
    text = "\n".join(reference_section(changes, held_out=True))
    # mean +0.20, s.e. std([0.1, 0.3], ddof=1) / sqrt(2) = 0.1414 / 1.414 = 0.10
    assert "| float | objects | 50.0 → 51.0 % | +0.20 ± 0.10 |" in text
    assert "| float | +0.20 points | yes |" in text and "| fixed | -0.70 points | no |" in text
    assert "Target:" not in "\n".join(reference_section(changes, held_out=False))


def test_the_page_gives_the_mean_change_and_its_standard_error_and_judges_the_target():
    base = ({"HOTA": 0.5}, {"HOTA": 0.49})
    changes = {
        (4, "objects"): {"HOTA": np.array([-0.2, -0.4, 0.0]), "recall": np.zeros(3), "precision": np.zeros(3), "base": base},
        (8, "objects"): {"HOTA": np.array([-0.9, -0.5, -0.7]), "recall": np.zeros(3), "precision": np.zeros(3), "base": base},
    }
    lines = section("test", changes, held_out=True)
    text = "\n".join(lines)
    # mean -0.20, s.e. std([-0.2, -0.4, 0.0], ddof=1) / sqrt(3) = 0.2 / sqrt(3) = 0.115...
    assert "| 4 | objects | 50.0 → 49.0 % | -0.20 ± 0.12 |" in text
    assert f"at most {TARGET_POINTS:g} HOTA points" in text
    assert "| 4 | -0.20 points | yes |" in text and "| 8 | -0.70 points | no |" in text
    assert "Target:" not in "\n".join(section("tuning", changes, held_out=False))  # no verdict off the held-out split


def test_pipeline_runs_whole_splits_and_refuses_seeds(tmp_path, capsys):
    assert main(["generalize", "--pipeline", "--seeds", "1000", "-o", str(tmp_path / "P.md")]) == 2
    err = capsys.readouterr().err.strip()
    assert "--pipeline" in err and "\n" not in err
