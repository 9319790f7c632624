"""The report's error budget and its quick mode (issue: reports)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from evclust.clusterer import load_params
from evclust.run import track_events
from evclust.fixed.formats import build_formats, sweep_tail_cycles
from evclust.report.budget import OUTPUTS, PAIR_GATE_PX, SOURCES, budget, emulate, noise_sum_ratio, paired_records, record_errors
from evclust.report.report import NOISE_SUM_TOLERANCE_DB, write_report
from evclust.scenes import load_scene
from evclust.simulator import simulate_scene
from evclust.tracks import TRACK_DTYPE


@pytest.fixture(scope="module")
def traffic_clip():
    sim = simulate_scene(load_scene("traffic"))
    params, _ = load_params("traffic")
    return sim.events[:120_000], sim.meta, params


@pytest.fixture(scope="module")
def traffic_budget(traffic_clip):
    return budget(*traffic_clip)


def test_the_sources_noise_powers_add_up_to_the_total_within_the_stated_tolerance(traffic_budget):
    for group in OUTPUTS:
        ratio = noise_sum_ratio(traffic_budget["rows"], group)
        assert abs(10 * math.log10(ratio)) <= NOISE_SUM_TOLERANCE_DB, (group, ratio)


def test_the_emulated_total_is_the_fixed_models_error(traffic_budget):
    # Independent of the emulation: the bit-exact model's own error against float.
    rows = traffic_budget["rows"]
    for group in OUTPUTS:
        emulated, fixed = rows["all"][group].rms, rows["fixed model"][group].rms
        assert fixed > 0
        assert abs(emulated - fixed) <= 0.25 * fixed, (group, emulated, fixed)


def _records(*step_x):
    out = np.zeros(len(step_x), TRACK_DTYPE)
    out["step"], out["x"] = zip(*step_x)
    out["y"] = 20.0
    return out


def test_records_pair_within_the_steps_both_runs_emit_nearest_first_and_within_the_gate():
    reference = _records((0, 10.0), (1, 10.0), (1, 50.0), (3, 5.0), (4, 30.0), (4, 31.0))
    run = _records((1, 51.0), (1, 11.0), (2, 10.0), (3, 5.0 + PAIR_GATE_PX + 0.5), (4, 30.8))
    ia, ib = paired_records(reference, run)
    # Step 0 and 2 are one run's only; step 3's pair is beyond the gate; in step 4 the run's one
    # record goes to the nearer of the two (0.2 px against 0.8 px).
    assert list(zip(ia.tolist(), ib.tolist())) == [(1, 1), (2, 0), (5, 4)]


def test_a_source_touches_only_the_outputs_it_feeds(traffic_budget):
    rows = traffic_budget["rows"]
    assert rows["colour"]["position"].power == 0 and rows["colour"]["velocity"].power == 0
    assert rows["centre"]["position"].power > 0
    assert rows["half_size"]["position"].power == 0  # the size never moves the centre of the same events


@pytest.mark.parametrize("signal", ["centre", "v_mcm", "v_int", "colour", "activity"])
def test_a_format_widened_to_48_fraction_bits_adds_no_measurable_error(traffic_clip, signal):
    events, meta, params = traffic_clip
    table = build_formats(params, meta.width, meta.height, params.t_frame_us or meta.t_frame_us)
    reference = track_events(events, meta, params).tracks
    errors = record_errors(reference, emulate(events, meta, params, table, (signal,), {signal: 48}).tracks, table)
    default = record_errors(reference, emulate(events, meta, params, table, (signal,)).tracks, table)
    for group in OUTPUTS:
        assert errors[group].rms <= 1e-9, (signal, group, errors[group].rms)
    assert any(default[g].rms > 1e-6 for g in OUTPUTS), "the default format must show an error to widen away"


def test_every_source_is_in_the_budget(traffic_budget):
    assert set(traffic_budget["rows"]) == {*SOURCES, "all", "fixed model"}


def test_the_quick_report_writes_its_markdown_and_figures(tmp_path):
    path = write_report(tmp_path, quick=True, progress=False)
    text = path.read_text()
    assert text.startswith("<!-- inputs: formats=")  # its input stamp (evclust.stamps)
    for heading in ("## Fixed-point error budget", "## Error against fraction bits", "## Ranges and saturation", "## Task results: float and fixed",
                    "### Float, fixed and RTL", "### Word lengths and N: accuracy against area and cycles", "### Shift-only β against multiplier β"):  # fmt: skip
        assert heading in text
    for figure in ("budget_traffic.png", "budget_pedestrian.png", "error_vs_bits_traffic.png", "ranges_traffic.png", "runtime_traffic.png"):
        assert (tmp_path / "img" / figure).stat().st_size > 5000
        assert f"img/{figure}" in text
    # The RTL ran under both simulators, and its cycles per event follow the schedule: one cycle
    # an event plus, every filter_every events, a filter step of 1 + max(N, P) + the sweep tail
    # + 1 cycles (more only while a full table scans for a victim, and for the harness's start).
    for sim in ("verilator", "icarus"):
        assert f"| traffic | RTL, {sim} (stream) |" in text
    cycles = {row.split(" | ")[0].lstrip("| "): float(row.split(" | ")[2]) for row in text.splitlines() if row.startswith("| N=")}
    params, _ = load_params("traffic")
    for label, n in (("N=4", 4), ("N=16 (default)", 16)):  # the quick report's (QUICK_CONFIGS)
        tail = sweep_tail_cycles(build_formats(params.model_copy(update={"n_clusters": n}), 480, 270, params.t_frame_us or 50000.0))
        law = 1 + (2 + max(n, len(params.palette)) + tail) / params.filter_every
        assert law <= cycles[label] < law + 0.05, label


def test_the_object_records_budget_pairs_nearly_every_record_and_stays_far_below_a_pixel(traffic_budget):
    # The traffic preset keeps the object layer: its records get their own rows. The fixed model's
    # object layer makes the float one's decisions (nearly every record is paired within 2 px), so
    # what remains is rounding, well under the metrics' resolution.
    rows = traffic_budget["object_rows"]
    assert set(rows) == {"all", "fixed model"} and traffic_budget["reference_objects"] > 0
    for source in rows:
        errors = rows[source]
        assert errors["position"].pairs >= 0.95 * traffic_budget["reference_objects"], source
        assert errors["position"].rms < 0.05 and errors["size"].rms < 0.2, source
        assert errors["velocity"].rms < 0.01 and errors["colour"].rms < 0.05, source
    # The object layer's own formats add to the emulated clusters' error, never take from it much.
    for group in ("position", "size", "velocity"):
        assert rows["fixed model"][group].rms >= 0.9 * rows["all"][group].rms, group
