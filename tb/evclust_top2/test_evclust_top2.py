"""evclust_top2, the seek's comparator tree, against the model's choice: the core packs each
slot's key as {miss, distance, slot} (nearest slot in the window, ties to the lower one) or
{taken, slot} (the lowest free slot), so the seek's answer is the smallest key, and the
runner-up, which stage B falls back on, is the smallest of the others. Reference: the keys
sorted (Python), under Icarus and Verilator.

Random keys for N = 1, 3 (not a power of two), 16 and 64, including keys made the way the core
makes them (distinct by their slot bits) and raw keys with repeats (equal keys: the runner-up
equals the smallest).
"""

from __future__ import annotations

import random

import pytest


try:
    import cocotb

    from cosim import checked_vectors
    from cocotb.triggers import Timer
except ImportError:  # collected by pytest without cocotb: the pytest half still reports why
    cocotb = None

CASES = 2000


def key_sets(n: int, key_w: int, seed: int):
    """Lists of n keys: seek keys {miss, distance, slot}, then raw keys with repeats."""
    rng = random.Random(seed)
    slot_w = max(1, (n - 1).bit_length())
    for i in range(CASES):
        if i % 2 == 0:
            keys = []
            for slot in range(n):
                miss = rng.random() < 0.5
                distance = 0 if miss else rng.randrange(1 << (key_w - 1 - slot_w))
                keys.append((int(miss) << (key_w - 1)) | (distance << slot_w) | slot)
        else:
            pool = [rng.getrandbits(key_w) for _ in range(max(1, n // 2))]
            keys = [rng.choice(pool) for _ in range(n)]
        yield keys


def model_top2(keys: list[int], key_w: int) -> tuple[int, int]:
    ordered = sorted(keys)
    return ordered[0], ordered[1] if len(ordered) > 1 else (1 << key_w) - 1


if cocotb is not None:

    @cocotb.test()
    async def top2_vectors(dut):
        await checked_vectors(dut, _top2_vectors)

    async def _top2_vectors(dut, config):
        n, key_w = config["n"], config["key_w"]
        checked = 0
        for keys in key_sets(n, key_w, config["seed"]):
            dut.keys.value = sum(k << (i * key_w) for i, k in enumerate(keys))
            await Timer(1, unit="ns")
            got = (int(dut.first.value), int(dut.second.value))
            want = model_top2(keys, key_w)
            checked += 1
            if got != want:
                return f"keys {keys}: RTL (first, second) {got}, sorted {want}", checked
        return None, checked


# ------------------------------------------------------------------------------------------
# pytest: build, launch, check.

from cosim import LEAF_SIMULATORS, configuration_params, run, selected_simulators  # noqa: E402


@pytest.mark.parametrize("n", [1, 3, 16, 64])
@pytest.mark.parametrize("sim", selected_simulators(LEAF_SIMULATORS))
def test_the_tree_gives_the_smallest_key_and_the_smallest_of_the_others(sim, n):
    from evclust.fixed.formats import build_formats
    from evclust.fixed.header import verilog_header

    header = verilog_header(build_formats(configuration_params("traffic", 16), 480, 270, 50000.0))
    key_w = 1 + 27 + max(1, (n - 1).bit_length())  # the seek key's width at the defaults' distance format
    result = run(sim, header, "top2_vectors", {"n": n, "key_w": key_w, "seed": n}, toplevel="evclust_top2",
                 parameters={"N": n, "KEY_W": key_w})  # fmt: skip
    assert result["checked"] == CASES


def test_the_reference_is_the_seeks_choice():
    """The sorted keys' first is the nearest hit with ties to the lower slot, else the lowest miss."""
    keys = [(0 << 31) | (5 << 4) | 2, (0 << 31) | (5 << 4) | 1, (1 << 31) | 0, (0 << 31) | (9 << 4) | 0]
    assert model_top2(keys, 32) == ((5 << 4) | 1, (5 << 4) | 2)
    assert model_top2([7], 8) == (7, 255)
