"""Every configuration the model supports, co-simulated bit-exact to the fixed model in the loop
(records, trace, status counters) under Icarus and Verilator: the paper's configuration, and a
pairwise cover of the switches (tb/switch_cover.py). The cocotb test is test_evclust_core.py's
`model_in_the_loop`; the presets and the small configuration run there too.

`make test` runs one row of the cover chosen from the commit hash (their numbers are in the test
ids, and in a line at the end of the run); `make cosim-full` (EVCLUST_COVER=all) runs every row,
and the paper's configuration at N = 4 as well and with full-length streams under Icarus;
EVCLUST_COVER_ROWS=3,7 runs rows 3 and 7.
"""

from __future__ import annotations


import numpy as np
import pytest


from cosim import TIMING_SIMULATORS, cosim_share, random_config, run, selected_simulators
from switch_cover import (
    COUNT, HEIGHT, ROTATING, SWITCHES, T_FRAME_US, WIDTH, all_pairs, cover, cover_stream, full, live_stream, pairs, row_params, selected_rows,
)  # fmt: skip

SIMS = selected_simulators(TIMING_SIMULATORS)  # Icarus in make test-full only
GAP, STALL = 64, 96  # random input gaps 25 % of cycles, output stalls 37.5 %, as in test_evclust_core.py
ROWS, _ = selected_rows()


# ------------------------------------------------------------------------------------------
# The paper's configuration (presets/paper.toml) on the traffic sensor, at its own N = 16 (and
# N = 4 under cosim-full). Icarus, some 40 times slower than Verilator here, takes 2,000 events
# of the 10,000 in `make test` (some 30 records; 4,000 make some 200).


@pytest.mark.parametrize("n_clusters", [4, 16] if full() else [16])
@pytest.mark.parametrize("sim", SIMS)
def test_the_papers_configuration_matches_the_model_in_the_loop(sim, n_clusters):
    from evclust.clusterer import load_params

    count = 10_000 if sim == "verilator" or full() else 2000
    header, config = random_config("paper", n_clusters, seed=1000 + n_clusters, count=count, gap=GAP, stall=STALL)
    paper, _ = load_params("paper")
    assert config["parameters"] == paper.model_copy(update={"n_clusters": n_clusters}).model_dump(mode="json", exclude_none=True)
    result = run(sim, header, "model_in_the_loop", config)
    assert result["events"] == count
    assert result["records"] > 0, "a stream that reports nothing checks little"
    assert result["counters"]["records"] == result["records"]


# ------------------------------------------------------------------------------------------
# The switch cover.


def test_the_cover_holds_every_pair_of_switch_values():
    rows = cover()
    assert len(all_pairs()) == 309  # two three-valued switches and ten two-valued ones: 9 + 2·10·6 + 45·4
    assert pairs(rows) == all_pairs()
    # A pairwise cover needs at least 3 × 3 rows (the two three-valued switches); all
    # 3 × 3 × 2^10 = 9,216 combinations would be exhaustive.
    assert 9 <= len(rows) <= 12
    assert len({row.name for row in rows}) == len(rows)
    from evclust.clusterer import load_params

    paper, _ = load_params("paper")  # row 0: the paper's switches, on the small sensor
    assert all(
        getattr(row_params(rows[0]), name) == getattr(paper, name) for values in SWITCHES.values() for name in values[next(iter(values))]
    )
    for row in rows:  # each row a valid parameter set with its switches as its name says
        params = row_params(row)
        for switch, value in row.values.items():
            for name, setting in SWITCHES[switch][value].items():
                assert getattr(params, name) == setting, (row.name, name)


def test_a_stream_that_reports_nothing_exercises_no_switch():
    # The liveness check can fail: five events are too few to report a cluster (a_valid = 6), so no
    # flip changes anything.
    import switch_cover

    row = cover()[0]
    assert switch_cover.model_run(row, cover_stream(1, 5))[:2] == ([], [])
    assert len(switch_cover.dead_switches(row, cover_stream(1, 5))) == sum(len(v) - 1 for v in SWITCHES.values())
    with pytest.raises(AssertionError, match=f"{row.name}: none of 3 streams exercises every switch"):
        switch_cover.live_stream.__wrapped__(row, count=5, tries=3)


def test_the_share_is_a_stable_subset_drawn_apart_per_simulator_and_everything_under_test_full(monkeypatch):
    items = [f"case{i}" for i in range(20)]
    monkeypatch.delenv("EVCLUST_COVER", raising=False)
    share = cosim_share(items, 4, "vectors", "icarus")
    assert len(set(share)) == 4 and set(share) <= set(items)
    assert share == [item for item in items if item in share]  # in the list's order
    assert cosim_share(items, 4, "vectors", "icarus") == share  # every xdist worker draws the same
    # The simulators draw apart: two 4-of-20 draws coincide once in 4845 commits, so over fixed
    # commits, not this checkout's (whose draws may be that one, as at c86330e).
    import cosim

    coincide = 0
    for commit in range(40):
        monkeypatch.setattr(cosim, "rotation_key", lambda commit=commit: f"{commit:040x}")
        coincide += cosim_share(items, 4, "vectors", "verilator") == cosim_share(items, 4, "vectors", "icarus")
    assert coincide <= 1
    monkeypatch.undo()
    monkeypatch.delenv("EVCLUST_COVER", raising=False)
    assert cosim_share(items, 50, "vectors", "icarus") == items  # more than there are: all
    monkeypatch.setenv("EVCLUST_COVER", "all")
    assert cosim_share(items, 4, "vectors", "icarus") == items


def test_the_groups_of_a_pool_take_turns_one_per_commit_and_all_under_test_full(monkeypatch):
    import cosim

    items = [f"case{i}" for i in range(5)]
    monkeypatch.delenv("EVCLUST_COVER", raising=False)
    turns = {sim: set() for sim in cosim.TAKING_TURNS}
    for commit in range(60):  # commits, as the rotation key
        monkeypatch.setattr(cosim, "rotation_key", lambda commit=commit: f"{commit:040x}")
        for sim, groups in cosim.TAKING_TURNS.items():
            shares = {group: cosim.turn_share(items, 1, group, sim) for group in groups}
            on_turn = [group for group, share in shares.items() if share]
            assert on_turn == [cosim.group_on_turn(sim)], (commit, sim, shares)
            assert shares[on_turn[0]] == cosim.cosim_share(items, 1, on_turn[0], sim if sim in cosim.SIMULATORS else "")
            turns[sim].add(on_turn[0])
    # Over 60 commits every group has its turn (the chance that one of 4 misses is 4 * 0.75^60).
    assert turns == {sim: set(groups) for sim, groups in cosim.TAKING_TURNS.items()}
    monkeypatch.setenv("EVCLUST_COVER", "all")
    assert all(cosim.turn_share(items, 1, g, sim) == items for sim, groups in cosim.TAKING_TURNS.items() for g in groups)


def test_the_rotating_subset_follows_the_environment(monkeypatch):
    monkeypatch.setenv("EVCLUST_COVER", "all")
    assert selected_rows()[0] == cover()
    monkeypatch.delenv("EVCLUST_COVER")
    monkeypatch.setenv("EVCLUST_COVER_ROWS", "3,5")
    assert [row.index for row in selected_rows()[0]] == [3, 5]
    monkeypatch.setenv("EVCLUST_COVER_ROWS", "3,99")
    with pytest.raises(SystemExit, match="EVCLUST_COVER_ROWS=3,99"):
        selected_rows()
    monkeypatch.delenv("EVCLUST_COVER_ROWS")
    import switch_cover

    monkeypatch.setattr(switch_cover, "group_on_turn", lambda pool: "breakages")
    assert selected_rows()[0] == ()  # the broken proof's turn
    monkeypatch.setattr(switch_cover, "group_on_turn", lambda pool: "switch-cover")
    rows, how = selected_rows()
    assert len(rows) == ROTATING and len(set(rows)) == ROTATING
    assert how.endswith("EVCLUST_COVER_ROWS=" + ",".join(str(row.index) for row in rows))
    assert selected_rows() == (rows, how)  # the same on every call: every xdist worker agrees


@pytest.mark.rotating
@pytest.mark.parametrize("row", ROWS, ids=lambda row: row.name)
@pytest.mark.parametrize("sim", SIMS)
def test_switch_cover_row_matches_the_model_in_the_loop(sim, row, tmp_path):
    # The first stream of the row's own seeds on which flipping any one switch changes the
    # model's records (live_stream), so that each switch's setting is one the RTL must get right.
    seed, expected = live_stream(row)
    events = tmp_path / f"{row.name}-{seed}.npy"
    np.save(events, cover_stream(seed, COUNT))
    params = row_params(row)
    header, config = random_config("small", params.n_clusters, seed, COUNT, params=params, gap=GAP, stall=STALL, events=str(events))
    assert (config["width"], config["height"], config["t_frame_us"]) == (WIDTH, HEIGHT, T_FRAME_US)
    result = run(sim, header, "model_in_the_loop", config)  # records, trace and counters compared in the testbench
    assert result["events"] == COUNT
    assert result["records"] == expected["records"] > 0
    assert result["counters"] == expected
    if params.merge:
        assert expected["merges"] > 0
    if params.create_support:
        assert expected["unsupported"] > 0
    if params.objects:
        assert result["objects"] > 0
