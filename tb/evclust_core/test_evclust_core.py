"""evclust_core against the fixed-point model, bit for bit, under Icarus and Verilator.

The pytest functions that build the RTL for each parameter set and launch the harness's cocotb
tests (evclust.rtl.harness, run inside the simulator) through `cocotb_tools.runner`
(evclust.rtl.cosim).
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

import pytest


# ------------------------------------------------------------------------------------------
# pytest: build per parameter set, launch, check.

from cosim import (
    CONFIGURATIONS,
    FORMAT_VARIANTS,
    ICARUS_EVENTS,
    TIMING_SIMULATORS,
    turn_share,
    full,
    random_config,
    run,
    selected_simulators,
    short_icarus,
)

from evclust.vectors import CASES

ROOT = Path(__file__).resolve().parents[2]
VECTORS = ROOT / "vectors"
SIMS = selected_simulators()
SIMS_TIMING = selected_simulators(TIMING_SIMULATORS)  # Icarus in make test-full only
GAP, STALL = 64, 96  # random input gaps 25 % of cycles, output stalls 37.5 %


def _case_header(name: str) -> str:
    from evclust.vectors.read import load_case

    return load_case(VECTORS / name).header


# `make test` replays, under each simulator, the cases that anchor the schedule and the pipeline
# and ROTATING_CASES more drawn from the commit hash for that simulator (tb/cosim.py's rotating
# subset: successive commits cover them all); Icarus there only cases of at most
# ICARUS_CASE_EVENTS events. `make test-full` replays every case under both.
ANCHOR_CASES = ("traffic_clip", "pipelined_traffic", "pipelined_eviction_voids", "table_full")
ROTATING_CASES = 1
ICARUS_CASE_EVENTS = 3000


def _case_events(case: str) -> int:
    return json.loads((VECTORS / case / "manifest.json").read_text())["counts"]["events"]


def _replayable(sim: str, cases) -> list[str]:
    return [case for case in cases if not short_icarus(sim) or _case_events(case) <= ICARUS_CASE_EVENTS]


def replayed_cases() -> list[tuple[str, str]]:
    """(simulator, case) pairs this run replays."""
    others = [case for case in CASES if case not in ANCHOR_CASES]
    return [
        (sim, case)
        for sim in SIMS
        for case in (*_replayable(sim, ANCHOR_CASES), *turn_share(_replayable(sim, others), ROTATING_CASES, "vectors", sim))
    ]


@pytest.mark.rotating
@pytest.mark.parametrize("sim, case", replayed_cases())
def test_vector_case_replays_bit_exact(sim, case):
    result = run(sim, _case_header(case), "replay_vectors", {"cases": [str(VECTORS / case)], "seed": 1, "gap": GAP, "stall": STALL})
    assert case in result["cases"]
    assert result["cases"][case]["records"] == json.loads((VECTORS / case / "manifest.json").read_text())["counts"]["records"]


BUILT_IN_CASES = ("traffic_clip", "table_full", "merge_edges")  # one a simulator in make test


@pytest.mark.rotating
@pytest.mark.parametrize("sim, case", [(sim, c) for sim in SIMS for c in turn_share(_replayable(sim, BUILT_IN_CASES), 1, "built-in", sim)])
def test_the_core_with_its_constants_built_in_replays_bit_exact(sim, case):
    # RUNTIME_CONFIG = 0: the header's constants folded into the datapath, the cfg port unread.
    config = {"cases": [str(VECTORS / case)], "seed": 2, "gap": GAP, "stall": STALL}
    result = run(sim, _case_header(case), "replay_vectors", config, parameters={"RUNTIME_CONFIG": 0})
    assert result["runtime_config"] == 0
    assert result["cases"][case]["records"] == json.loads((VECTORS / case / "manifest.json").read_text())["counts"]["records"]


# The sensors whose random streams report within ICARUS_EVENTS events (tb/cosim.py): the small
# configuration and the defaults'. The traffic streams report nothing in their first 5,000
# events (seed 5, by the fixed model).
SHORT_SENSORS = ("small", "defaults")


def _stream_length(sim: str, count: int) -> int:
    """Events of a random stream under `sim`: ICARUS_EVENTS for Icarus in `make test`."""
    return min(count, ICARUS_EVENTS) if short_icarus(sim) else count


def _random_config(preset, n_clusters, seed, count, **extra):
    return random_config(preset, n_clusters, seed, count, **({"gap": GAP, "stall": STALL} | extra))


STREAMS = [(preset, n) for preset in CONFIGURATIONS for n in (4, 16)]
# make test: Verilator the traffic streams, whose builds the traffic_clip case and the quick
# report share; Icarus one short stream drawn from the commit. make test-full: all under both.
PINNED_STREAMS = [("traffic", 4), ("traffic", 16)]


def streams(sim: str) -> list[tuple[str, int]]:
    if full():
        return STREAMS
    if sim == "verilator":
        return PINNED_STREAMS
    return turn_share([s for s in STREAMS if s[0] in SHORT_SENSORS], 1, "streams", sim)


@pytest.mark.rotating
@pytest.mark.parametrize("sim, preset, n_clusters", [(sim, *stream) for sim in SIMS for stream in streams(sim)])
def test_random_streams_match_the_model_in_the_loop(sim, preset, n_clusters):
    # EVCLUST_SEED=n draws other streams than the committed seeds.
    seed = int(os.environ.get("EVCLUST_SEED", 1000)) + n_clusters
    count = _stream_length(sim, 10_000)
    header, config = _random_config(preset, n_clusters, seed=seed, count=count)
    result = run(sim, header, "model_in_the_loop", config)
    assert result["events"] == count
    assert result["records"] > 0, "a stream that reports nothing checks little"


# (preset, update_delay, activity_reference): one a simulator in make test.
PIPELINED = [("small", 2, False), ("defaults", 1, False), ("defaults", 2, False), ("small", 1, True), ("defaults", 2, True)]


@pytest.mark.rotating
@pytest.mark.parametrize(
    "sim, preset, delay, reference", [(sim, *case) for sim in SIMS_TIMING for case in turn_share(PIPELINED, 1, "pipelined", sim)]
)
def test_the_pipelined_core_matches_the_model_in_the_loop_through_gaps_and_stalls(sim, preset, delay, reference):
    # update_delay = 1: each update commits as the next event finishes; 2: as the one after
    # finishes, its second half computed a stage later; activity_reference: each commit adds the
    # event's weight, and the reference moves before an event Ã could outgrow (the stream's
    # gaps of seconds). The pipeline is event-clocked, so the stream's random gaps and output
    # stalls must not change what it computes.
    from cosim import configuration_params

    seed = int(os.environ.get("EVCLUST_SEED", 1000)) + 7 + delay
    count = _stream_length(sim, 10_000)
    params = configuration_params(preset, 16).model_copy(update={"update_delay": delay, "activity_reference": reference})
    header, config = _random_config(preset, 16, seed=seed, count=count, params=params)
    result = run(sim, header, "model_in_the_loop", config)
    assert result["events"] == count
    assert result["records"] > 0, "a stream that reports nothing checks little"


def _second_parameter_set(params):
    """Another parameter set for the same build: every run-time switch flipped and most constants
    moved (build-time ones kept: N, palette size, merging, creation support, warm-up length)."""
    return params.model_copy(update=dict(
        alpha_pos=0.99, alpha_size=0.995, alpha_lum=0.99, alpha_chro=0.98, alpha_bg=0.998, alpha_vel_mcm=0.9999,
        gamma_mode="activity", velocity_warm_start=not params.velocity_warm_start, mcm_bias_correction=not params.mcm_bias_correction,
        palette_assign="nearest", palette_vote="count", tau_us=15000.0, filter_every=5, a_valid=4.0, a_min=0.8,
        seek_margin=3.0, r_init=3.0, size_gain=1.3, background=(90, 120, 140), luma_weight=1.5, p_correction=0.6,
        palette=tuple(entry.model_copy(update={"rgb": tuple(reversed(entry.rgb))}) for entry in params.palette),
    ))  # fmt: skip


@pytest.mark.parametrize("sim", SIMS_TIMING)
def test_parameters_written_over_axi_lite_between_two_streams_are_bit_exact(sim):
    from evclust.clusterer import ClustererParams

    count = _stream_length(sim, 6000)
    header, config = _random_config("small", 4, seed=77, count=count)
    second = _second_parameter_set(ClustererParams(**config["parameters"]))
    result = run(sim, header, "reconfigure", config | {"second": second.model_dump(mode="json", exclude_none=True)})
    first, then = result["stream 1"], result["stream 2"]
    assert first["records"] > 0 and then["records"] > 0, "streams that report nothing check little"
    assert first["counters"]["events"] == then["counters"]["events"] == count  # CLEAR_COUNTERS between them


def test_a_second_parameter_set_needing_another_build_is_refused():
    from evclust.clusterer import ClustererParams
    from evclust.errors import EvclustError
    from evclust.fixed.model import FixedClusterer

    header, config = _random_config("small", 4, seed=77, count=10)
    built = ClustererParams(**config["parameters"])
    build = FixedClusterer(built, 64, 48, 10000.0).table
    for change, message in (({"n_clusters": 8}, "build-time"), ({"r_max": 1000.0}, "saturates"),
                            ({"merge": not built.merge}, "build-time")):  # fmt: skip
        with pytest.raises(EvclustError, match=message):
            FixedClusterer(built.model_copy(update=change), 64, 48, 10000.0, build=build)


# make test: Verilator the shift-only βs (the quick report's build); Icarus, too slow for the 6,000
# events the traffic sensor needs to report, runs them in make test-full.
PINNED_VARIANTS = {"verilator": ["shift_only"], "icarus": []}


@pytest.mark.parametrize("sim, variant", [(sim, v) for sim in SIMS for v in (list(FORMAT_VARIANTS) if full() else PINNED_VARIANTS[sim])])
def test_the_formats_tables_other_shapes_match_the_model_in_the_loop(sim, variant):
    # Shift-only βs (the products become shifts) and the narrowest filter states: the RTL takes
    # both from its header alone, so they must stay bit-exact without an RTL change.
    header, config = _random_config("traffic", 16, seed=5, count=10_000, formats=FORMAT_VARIANTS[variant])
    default, _ = _random_config("traffic", 16, seed=5, count=0)
    assert header != default
    result = run(sim, header, "model_in_the_loop", config)
    assert result["events"] == 10_000 and result["records"] > 0


def test_the_two_format_sets_differ():
    a, _ = _random_config("traffic", 16, 0, 0)
    b, _ = _random_config("pedestrian", 16, 0, 0)
    widths = lambda h: {line.split("=")[0] for line in h.splitlines() if "_W =" in line and "PALETTE" not in line}
    assert widths(a) == widths(b)
    assert [line for line in a.splitlines() if "_W =" in line] != [line for line in b.splitlines() if "_W =" in line]


RESET_CYCLES = (5, 1501, 4003)  # in the mixing table's fill, early, late: one a simulator in make test


def _reset_cycles(sim: str) -> list[int]:
    # Icarus in make test: a stream of 2,500 events before the reset, which lasts past cycle 1501.
    return turn_share([c for c in RESET_CYCLES if not short_icarus(sim) or c < 2500], 1, "reset", sim)


@pytest.mark.rotating
@pytest.mark.parametrize("sim, reset_cycle", [(sim, c) for sim in SIMS for c in _reset_cycles(sim)])
def test_a_reset_in_the_middle_of_a_stream_recovers_the_models_state_after_reset(sim, reset_cycle):
    # The small configuration learns its background and refreshes the mixing table, so state a
    # reset forgets to clear would show; the part before the reset runs with gaps and stalls.
    count, before = (ICARUS_EVENTS, 2500) if short_icarus(sim) else (4000, 4000)
    header, config = _random_config("small", 4, seed=77, count=count, reset_at=before, reset_cycle=reset_cycle)
    result = run(sim, header, "model_in_the_loop", config)
    assert result["events"] == count


@pytest.mark.parametrize("sim", SIMS_TIMING)
def test_no_event_is_lost_or_duplicated_under_heavy_back_pressure(sim):
    # The output stalled 75 % of the cycles, with input gaps: the trace must count every event
    # once, in order, and every record must match the model. 10^5 events under Verilator; Icarus,
    # some 40 times slower on this design, checks the same behaviour on 10^4 (make test-full), or
    # in make test on a short stream of the small configuration, which reports within it.
    count = 100_000 if sim == "verilator" else 10_000
    preset, n_clusters = ("small", 4) if short_icarus(sim) else ("traffic", 16)
    count = _stream_length(sim, count)
    header, config = _random_config(preset, n_clusters, seed=5, count=count)
    result = run(sim, header, "model_in_the_loop", config | {"gap": 32, "stall": 192})
    assert result["events"] == count


@pytest.mark.parametrize("sim", SIMS_TIMING)
def test_a_sparse_input_feeds_events_while_the_sweep_emits_records(sim):
    # Input gaps 94 % of the cycles: stage A is often empty when a sweep starts, so it takes the
    # next event while records leave (the coverage bin "an event in and a record out in one cycle").
    count = 20_000 if sim == "verilator" else 3_000  # fewer under Icarus meet no such cycle
    header, config = _random_config("small", 4, seed=6, count=count)
    result = run(sim, header, "model_in_the_loop", config | {"gap": 240, "stall": 64})
    assert result["events"] == count
    assert result["coverage"]["stream: an event in and a record out in one cycle"] > 0


@pytest.mark.parametrize("sim", SIMS_TIMING)
def test_one_cycle_per_event_and_max_n_p_plus_the_tail_per_sweep(sim):
    # Without gaps or stalls: each event takes one cycle (the seek of the next overlaps its
    # update); each filter step its phase cycle (fewer than two tau boundaries here), max(N, P)
    # cycles and the sweep tail's, then one cycle in which the held event enters the seek again;
    # besides, the cycles the object unit holds the core (counted apart, and bounded below).
    from evclust.fixed.formats import mixing_fill_cycles, sweep_tail_cycles
    from evclust.vectors.read import load_case

    case = "bursts"  # no evictions: no scans
    result = run(sim, _case_header(case), "replay_vectors", {"cases": [str(VECTORS / case)], "seed": 1, "gap": 0, "stall": 0})
    stats = result["cases"][case]
    manifest = json.loads((VECTORS / case / "manifest.json").read_text())
    table = load_case(VECTORS / case).table
    tail, start = sweep_tail_cycles(table), mixing_fill_cycles(table) + 8  # the reset's fill, the harness's start
    assert stats["filter_steps"] == manifest["counts"]["steps"]
    own = stats["filter_cycles"] - stats["object_wait_cycles"]
    assert own == stats["filter_steps"] * (1 + max(manifest["n_clusters"], manifest["palette_size"]) + tail)
    outside = stats["cycles"] - stats["filter_cycles"] - stats["object_drain_cycles"]  # not the object unit's last step
    assert stats["events"] + stats["filter_steps"] <= outside <= stats["events"] + stats["filter_steps"] + start
    # The object unit works on every step and holds the core for at most the part of its work
    # that outlasts the events between two steps.
    assert stats["object_busy_cycles"] > stats["filter_steps"] * 8
    assert stats["object_wait_cycles"] <= stats["object_busy_cycles"]
    # Latency: the edge after the one that takes an event moves it into EXEC, the next writes its
    # slot. An event taken as a filter step starts waits in stage A for the whole step (its
    # phase cycle, the sweep and its tail, the object unit's hold) and re-enters the seek.
    assert stats["latency_min"] == 2
    step = 1 + max(manifest["n_clusters"], manifest["palette_size"]) + tail
    assert 2 < stats["latency_max"] <= 2 + step + stats["object_wait_cycles"] + 1
    assert (
        2 * stats["events"]
        <= stats["latency_sum"]
        <= 2 * stats["events"] + stats["filter_steps"] * (step + 1) + stats["object_wait_cycles"]
    )


@pytest.mark.parametrize("sim", SIMS_TIMING)
def test_each_merge_holds_the_sweep_for_the_dividers_steps_plus_three_cycles(sim):
    # Without gaps or stalls: each filter step's 1 + max(N, P) + tail cycles plus, for each
    # merge, the detection, the dividers' start, their MERGE_MOMENT_W steps and the write; outside
    # the steps one cycle per event and one per step (the held event re-enters the seek).
    from evclust.fixed.formats import mixing_fill_cycles, sweep_tail_cycles
    from evclust.vectors.read import load_case

    case = "merge_edges"
    result = run(sim, _case_header(case), "replay_vectors", {"cases": [str(VECTORS / case)], "seed": 1, "gap": 0, "stall": 0})
    stats = result["cases"][case]
    manifest = json.loads((VECTORS / case / "manifest.json").read_text())
    table = load_case(VECTORS / case).table
    moment_bits = table["merge_moment"].word_bits
    counts = manifest["counts"]
    assert counts["merged"] > 0 and counts["evicted"] == counts["dropped"] == 0  # no eviction scans
    assert stats["filter_steps"] == counts["steps"]  # filter_active stays high through a step's merges
    sweeps = counts["steps"] * (1 + max(manifest["n_clusters"], manifest["palette_size"]) + sweep_tail_cycles(table))
    merges = stats["filter_cycles"] - stats["object_wait_cycles"] - sweeps
    outside = stats["cycles"] - stats["filter_cycles"] - stats["object_drain_cycles"]  # not the object unit's last step
    assert stats["events"] + counts["steps"] <= outside <= stats["events"] + counts["steps"] + mixing_fill_cycles(table) + 8
    assert merges == counts["merged"] * (moment_bits + 3)


def _tampered_copy(tmp_path, case: str, edit) -> Path:
    """A copy of a case with one file edited and its manifest's sha256 updated to match."""
    import shutil

    folder = tmp_path / case
    shutil.copytree(VECTORS / case, folder)
    file = edit(folder)
    manifest = json.loads((folder / "manifest.json").read_text())
    manifest["sha256"][file] = hashlib.sha256((folder / file).read_bytes()).hexdigest()
    (folder / "manifest.json").write_text(json.dumps(manifest))
    return folder


@pytest.mark.parametrize("sim", SIMS_TIMING)
def test_a_wrong_expected_record_is_reported_field_by_field(sim, tmp_path):
    from evclust.fixed.layouts import record_fields
    from evclust.vectors.pack import pack, unpack
    from evclust.vectors.read import load_case

    case = load_case(VECTORS / "bursts")
    fields = record_fields(case.table)
    values = unpack(case.expected[7], fields)
    values[[f[0] for f in fields].index("vx_int")] += 1

    def edit(folder):
        lines = (folder / "expected.hex").read_text().splitlines()
        lines[7] = f"{pack(values, fields):0{len(lines[7])}x}"
        (folder / "expected.hex").write_text("\n".join(lines) + "\n")
        return "expected.hex"

    folder = _tampered_copy(tmp_path, "bursts", edit)
    with pytest.raises(
        AssertionError,
        match=r"bursts: record 7 \(expected.hex line 8\), emitted after event \d+ \(trace.hex line \d+\): vx_int: RTL -?\d+, model -?\d+$",
    ):
        run(sim, case.header, "replay_vectors", {"cases": [str(folder)], "seed": 1, "gap": 0, "stall": 0})


@pytest.mark.parametrize("sim", SIMS)
def test_a_case_for_another_parameter_set_fails_clearly(sim):
    header = _case_header("traffic_clip")
    with pytest.raises(AssertionError, match="bursts: made for another parameter set than the RTL was built with"):
        run(sim, header, "replay_vectors", {"cases": [str(VECTORS / "bursts")], "seed": 1, "gap": 0, "stall": 0})


@pytest.mark.parametrize("sim", SIMS)
def test_a_truncated_case_fails_clearly(sim, tmp_path):
    def edit(folder):
        lines = (folder / "events.hex").read_text().splitlines()
        (folder / "events.hex").write_text("\n".join(lines[:-5]) + "\n")
        return "events.hex"

    folder = _tampered_copy(tmp_path, "bursts", edit)
    with pytest.raises(AssertionError, match=r"events.hex: 1995 lines, the manifest says 2000 \(truncated\?\)"):
        run(sim, _case_header("bursts"), "replay_vectors", {"cases": [str(folder)], "seed": 1, "gap": 0, "stall": 0})


def test_verilator_makes_only_the_testbench_top_visible():
    # evclust.rtl.cosim.TOP_ONLY in place of cocotb's --public-flat-rw: the harness reaches only
    # the toplevel's signals, and every co-simulation here passes with that alone. The build is
    # the traffic_clip case's, which make test builds anyway.
    from cosim import build

    _, folder = build("verilator", _case_header("traffic_clip"))
    command = (folder / "Vtop__verFiles.dat").read_text().splitlines()[1]
    assert "--public-depth 1" in command and "--public-flat-rw" not in command
    symbols = sum(path.stat().st_size for path in folder.glob("Vtop__Syms__*.cpp"))
    assert symbols < 1_000_000, symbols  # every signal's VPI entry made 2.9 to 5.4 MB
