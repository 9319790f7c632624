"""evclust_seek_key, one slot's seek key, against the fixed model under Icarus and Verilator: the
slot is a hit exactly when the model's `_seek` takes it as the only slot of a table, and the key
is {miss, L1 distance, slot} with the distance |x - Px| + |y - Py| in P's format (0 on a miss).

Random slots around each event, and the edges the key's widths must hold: centres at 0 and at
the sensor's last pixel, an event at a corner, each axis exactly at the reach and one LSB
beyond it, half-sizes over their whole format (the window as the core derives it from the
model's `_margin` when the slot is written: tb/seek_builds.py), dead slots. The seek's two builds (tb/seek_builds.py):
the scaled seek in `make test`, both in `make test-full`.
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

from seek_builds import BUILDS, model_for, slot_windows, widths

SLOTS = 3000


def slots(model, width: int, height: int, seed: int):
    """(event x, y, one-slot table S): random, and at the reach's edges on either axis."""
    from evclust.clusterer.layout import PX, PY, RX, RY, SLOT_COLUMNS, VALID
    from evclust.fixed import fixed_model

    rng = random.Random(seed)
    fp, fr = model.table["centre"].frac_bits, model.table["half_size"].frac_bits
    r_max = (1 << model.table["half_size"].word_bits) - 1
    last_x, last_y = (width - 1) << fp, (height - 1) << fp
    for i in range(SLOTS):
        S = np.zeros((1, len(SLOT_COLUMNS)), dtype=np.int64)
        S[0, VALID] = rng.random() < 0.9
        S[0, RX] = rng.choice((0, r_max, rng.randrange(r_max + 1), rng.randrange(1 << fr, 30 << fr)))
        S[0, RY] = rng.choice((0, r_max, rng.randrange(r_max + 1), rng.randrange(1 << fr, 30 << fr)))
        x = rng.choice((0, width - 1, rng.randrange(width)))
        y = rng.choice((0, height - 1, rng.randrange(height)))
        kind = i % 4
        if kind == 0:  # anywhere
            S[0, PX], S[0, PY] = rng.randrange(last_x + 1), rng.randrange(last_y + 1)
        elif kind == 1:  # a corner of the sensor
            S[0, PX], S[0, PY] = rng.choice((0, last_x)), rng.choice((0, last_y))
        else:  # the event exactly at the reach on one axis, or one LSB beyond it (kind 3)
            up = fp - fr
            reach = (int(S[0, RX]) << up) + int(fixed_model._margin(S, 0, model.k)) + (kind == 3)
            side = rng.choice((-1, 1))
            S[0, PX] = min(max(0, (x << fp) + side * reach), last_x)
            S[0, PY] = min(max(0, (y << fp) + rng.randrange(-(8 << fp), 8 << fp)), last_y)
        yield x, y, S


def model_key(model, x: int, y: int, S, slot: int, slot_w: int, distance_w: int) -> int:
    """The key the model implies: a hit is a slot `_seek` takes; its distance is the L1 one."""
    from evclust.clusterer.layout import PX, PY
    from evclust.fixed import fixed_model

    fp = model.table["centre"].frac_bits
    hit = fixed_model._seek(S, x << fp, y << fp, model.k) == 0
    distance = abs((x << fp) - int(S[0, PX])) + abs((y << fp) - int(S[0, PY]))
    assert not hit or distance < 1 << distance_w, "seek_distance's format does not hold an in-reach distance"
    return (int(not hit) << (distance_w + slot_w)) | ((distance if hit else 0) << slot_w) | slot


if cocotb is not None:

    @cocotb.test()
    async def seek_key_vectors(dut):
        await checked_vectors(dut, _seek_key_vectors)

    async def _seek_key_vectors(dut, config):
        from evclust.clusterer.layout import PX, PY, VALID

        model, width, height = model_for(config["build"])
        slot_w, key_w = config["slot_w"], config["key_w"]
        distance_w = key_w - 1 - slot_w
        rng = random.Random(config["seed"])
        checked = 0
        for x, y, S in slots(model, width, height, config["seed"]):
            slot = rng.randrange(1 << slot_w)
            wx, wy = slot_windows(model, S, 0)
            dut.x.value, dut.y.value, dut.live.value, dut.slot.value = x, y, int(S[0, VALID]), slot
            dut.centre_x.value, dut.centre_y.value = int(S[0, PX]), int(S[0, PY])
            dut.window_x.value, dut.window_y.value = wx, wy
            await Timer(1, unit="ns")
            got, want = int(dut.key.value), model_key(model, x, y, S, slot, slot_w, distance_w)
            checked += 1
            if got != want:
                return f"event ({x}, {y}), slot {S[0].tolist()} as {slot}: RTL key {got:#x}, model {want:#x}", checked
        return None, checked


# ------------------------------------------------------------------------------------------
# pytest: build, launch, check.

from cosim import LEAF_SIMULATORS, full, run, selected_simulators  # noqa: E402


# make test: the scaled seek (its reach grows with the half-size: the widest key); make test-full: both builds
@pytest.mark.parametrize("build", sorted(BUILDS) if full() else ["scaled_seek"])
@pytest.mark.parametrize("sim", selected_simulators(LEAF_SIMULATORS))
def test_each_slots_key_is_the_models_hit_and_distance(sim, build):
    w = widths(build)
    parameters = {"XY_BITS": w["xy_w"], "CENTRE_BITS": w["centre_w"], "WINDOW_BITS": w["window_w"], "SLOT_BITS": w["slot_w"],
                  "KEY_BITS": w["key_w"]}  # fmt: skip
    header = w.pop("header")
    result = run(sim, header, "seek_key_vectors", {"build": build, "seed": 5} | w, toplevel="evclust_seek_key", parameters=parameters)
    assert result["checked"] == SLOTS


def test_the_slots_reach_both_sides_of_the_edge():
    """The generated slots hit and miss, and both at the reach's edge: kind 2 lies at the reach
    (a hit when the other axis is in reach), kind 3 one LSB beyond it (a miss)."""
    from evclust.fixed import fixed_model

    for build in BUILDS:
        model, width, height = model_for(build)
        fp = model.table["centre"].frac_bits
        hits = [fixed_model._seek(S, x << fp, y << fp, model.k) == 0 for x, y, S in slots(model, width, height, 5)]
        assert SLOTS // 10 < sum(hits) < SLOTS - SLOTS // 10
        assert sum(hits[2::4]) > 0 and sum(hits[3::4]) < sum(hits[2::4])
