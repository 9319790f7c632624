"""evclust_seek, step 1 (every slot's key and the comparator trees), against the fixed model's
`_seek` (the nearest live slot in reach, ties to the lower one; none) and its lowest free slot,
under Icarus and Verilator.

Random tables around each event: live and free slots, centres near the event and far from it,
half-sizes over their format, equal distances (ties). Each slot's window comes from the model's
`_margin`, as the core derives it when the slot is written (tb/seek_builds.py). Two builds: the defaults with a
scaled seek (seek_scale > 0, so the reach grows with max(Rx, Ry)) at N = 16, and the traffic
preset (a fixed margin) at N = 4.
"""

from __future__ import annotations

import random

import numpy as np
import pytest


try:
    import cocotb

    from cosim import checked_vectors
    from cocotb.triggers import Timer
except ImportError:  # collected by pytest without cocotb: the pytest half still reports why
    cocotb = None

from seek_builds import BUILDS, build_params, model_for, slot_windows, widths  # noqa: F401  (tb/seek_builds.py)

TABLES = 1500


def tables(model, width: int, height: int, seed: int):
    """(event x, y, slot table S) triples: centres near the event (some at equal distances) and far."""
    from evclust.clusterer.layout import PX, PY, RX, RY, SLOT_COLUMNS, VALID

    rng = random.Random(seed)
    fp, fr = model.table["centre"].frac_bits, model.table["half_size"].frac_bits
    r_max = (1 << model.table["half_size"].word_bits) - 1
    n = model.params.n_clusters
    for _ in range(TABLES):
        x, y = rng.randrange(width), rng.randrange(height)
        S = np.zeros((n, len(SLOT_COLUMNS)), dtype=np.int64)
        tie = rng.randrange(1, 40) << fp
        crowd = rng.choice((0.0, 0.1, 0.8))  # how many slots sit near the event: none, few, most
        live = rng.choice((0.1, 0.8, 1.0))  # how many slots are live: a sparse, a busy, a full table
        for s in range(n):
            S[s, VALID] = rng.random() < live
            kind = rng.random() * 0.8 / crowd if crowd else 1.0
            if kind < 0.3:  # the same distance as others: ties go to the lower slot
                S[s, PX], S[s, PY] = min(max(0, (x << fp) + rng.choice((-tie, tie))), (width - 1) << fp), y << fp
            elif kind < 0.8:  # near
                S[s, PX] = min(max(0, (x << fp) + rng.randrange(-60 << fp, 60 << fp)), (width - 1) << fp)
                S[s, PY] = min(max(0, (y << fp) + rng.randrange(-60 << fp, 60 << fp)), (height - 1) << fp)
            else:  # anywhere
                S[s, PX], S[s, PY] = rng.randrange(width << fp), rng.randrange(height << fp)
            S[s, RX] = rng.randrange(r_max + 1) if rng.random() < 0.2 else rng.randrange(1 << fr, 30 << fr)
            S[s, RY] = rng.randrange(r_max + 1) if rng.random() < 0.2 else rng.randrange(1 << fr, 30 << fr)
        yield x, y, S


def model_choice(model, x: int, y: int, S) -> tuple[int, int]:
    """(the model's slot or -1, the lowest free slot or -1)."""
    from evclust.clusterer.layout import VALID
    from evclust.fixed import fixed_model

    fp = model.table["centre"].frac_bits
    free = [s for s in range(S.shape[0]) if not S[s, VALID]]
    return int(fixed_model._seek(S, x << fp, y << fp, model.k)), (free[0] if free else -1)


if cocotb is not None:

    @cocotb.test()
    async def seek_vectors(dut):
        await checked_vectors(dut, _seek_vectors)

    async def _seek_vectors(dut, config):
        from evclust.clusterer.layout import PX, PY, VALID

        model, width, height = model_for(config["build"])
        centre_w, window_w, slot_w, key_w = config["centre_w"], config["window_w"], config["slot_w"], config["key_w"]
        checked = 0
        for x, y, S in tables(model, width, height, config["seed"]):
            n = S.shape[0]
            windows = [slot_windows(model, S, s) for s in range(n)]
            dut.x.value, dut.y.value = x, y
            dut.valid.value = sum(int(S[s, VALID]) << s for s in range(n))
            dut.centre_x.value = sum(int(S[s, PX]) << (s * centre_w) for s in range(n))
            dut.centre_y.value = sum(int(S[s, PY]) << (s * centre_w) for s in range(n))
            dut.window_x.value = sum(w[0] << (s * window_w) for s, w in enumerate(windows))
            dut.window_y.value = sum(w[1] << (s * window_w) for s, w in enumerate(windows))
            await Timer(1, unit="ns")
            first, free = int(dut.seek_first.value), int(dut.free_first.value)
            got = (-1 if first >> (key_w - 1) else first & ((1 << slot_w) - 1), -1 if free >> slot_w else free & ((1 << slot_w) - 1))
            want = model_choice(model, x, y, S)
            checked += 1
            if got != want:
                return f"event ({x}, {y}): RTL (slot, free slot) {got}, model {want}; table {S.tolist()}", checked
        return None, checked


# ------------------------------------------------------------------------------------------
# pytest: build, launch, check.

from cosim import LEAF_SIMULATORS, run, selected_simulators  # noqa: E402


@pytest.mark.parametrize("build", sorted(BUILDS))
@pytest.mark.parametrize("sim", selected_simulators(LEAF_SIMULATORS))
def test_the_seek_chooses_the_models_slot_and_the_lowest_free_one(sim, build):
    w = widths(build)
    parameters = {"N": w["n"], "XY_BITS": w["xy_w"], "CENTRE_BITS": w["centre_w"], "WINDOW_BITS": w["window_w"], "SLOT_BITS": w["slot_w"],
                  "KEY_BITS": w["key_w"]}  # fmt: skip
    header = w.pop("header")
    result = run(sim, header, "seek_vectors", {"build": build, "seed": 3} | w, toplevel="evclust_seek", parameters=parameters)
    assert result["checked"] == TABLES


def test_the_tables_hit_miss_and_fill_the_table():
    """The generated tables reach the cases that matter: hits, misses, no free slot."""
    from evclust.clusterer.layout import VALID

    model, width, height = model_for("scaled_seek")
    hits = misses = full = 0
    for x, y, S in tables(model, width, height, 3):
        slot, free = model_choice(model, x, y, S)
        hits += slot >= 0
        misses += slot < 0
        full += free < 0 and bool(S[:, VALID].all())
    assert hits > TABLES // 4 and misses > TABLES // 50 and full > TABLES // 50
