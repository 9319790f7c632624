"""evclust_decay_apply, A * 2^(-m/64) floored, against the model's `arith.decay_apply` under Icarus
and Verilator, at the width the core gives it against a reference time: the activity's plus
REFERENCE_HALVINGS bits (Ã; the sweep's stage 0, a merge's absorbed slot, the background). At the
activity's own width it runs inside evclust_decay, whose bench covers it there.

Exhaustive over m from 0 to two whole halvings past the point where nothing is left (every
table entry, every shift, the cut-off), each with the largest Ã, with 1 and with a random one;
random m over all 64 bits and random Ã.
"""

from __future__ import annotations

import functools
import random

import pytest


try:
    import cocotb

    from cosim import checked_vectors
    from cocotb.triggers import Timer
except ImportError:  # collected by pytest without cocotb: the pytest half still reports why
    cocotb = None

RANDOM_CASES = 4000


def apply_cases(bits: int, seed: int):
    """(activity, m) inputs: the sweep over m, then random ones."""
    from evclust.fixed.formats import DECAY_FRAC_BITS, DECAY_TABLE_BITS

    rng = random.Random(seed)
    a_max = (1 << bits) - 1
    for m in range(((62 - DECAY_FRAC_BITS + 2) << DECAY_TABLE_BITS) + 1):
        yield a_max, m
        yield 1, m
        yield rng.randrange(a_max + 1), m
    for _ in range(RANDOM_CASES):
        m = rng.choice((rng.randrange(1 << 64), rng.randrange(1 << 13), rng.randrange(1 << 8)))
        yield rng.choice((a_max, rng.randrange(a_max + 1))), m


@functools.cache
def _table():
    from evclust.fixed.arith import decay_table
    from evclust.fixed.formats import DECAY_FRAC_BITS, DECAY_TABLE_BITS

    return decay_table(DECAY_TABLE_BITS, DECAY_FRAC_BITS)


def model_apply(activity: int, m: int) -> int:
    from evclust.fixed.arith import FLOOR, decay_apply
    from evclust.fixed.formats import DECAY_FRAC_BITS, DECAY_TABLE_BITS

    return decay_apply(activity, m, _table(), DECAY_TABLE_BITS, DECAY_FRAC_BITS, FLOOR)


if cocotb is not None:

    @cocotb.test()
    async def apply_vectors(dut):
        """Every case through the combinational module; the first difference from the model fails."""
        await checked_vectors(dut, _apply_vectors)

    async def _apply_vectors(dut, config):
        error, checked = None, 0
        for activity, m in apply_cases(config["bits"], config["seed"]):
            dut.activity.value, dut.m.value = activity, m
            await Timer(1, unit="ns")
            got, want = int(dut.decayed.value), model_apply(activity, m)
            checked += 1
            if got != want:
                error = f"activity={activity} m={m}: RTL {got}, model {want}"
                break
        return error, checked


# ------------------------------------------------------------------------------------------
# pytest: build, launch, check.

from cosim import LEAF_SIMULATORS, configuration_params, run, selected_simulators  # noqa: E402


def apply_build() -> tuple[str, int]:
    """(header, Ã's width) of the defaults with the mode on, on the traffic sensor."""
    from evclust.clusterer.params import REFERENCE_HALVINGS
    from evclust.fixed.formats import build_formats
    from evclust.fixed.header import verilog_header

    params = configuration_params("defaults", 16).model_copy(update={"activity_reference": True})
    table = build_formats(params, 480, 270, 50000.0)
    return verilog_header(table), table["activity"].word_bits + REFERENCE_HALVINGS


@pytest.mark.parametrize("sim", selected_simulators(LEAF_SIMULATORS))
def test_the_decay_of_a_referenced_activity_matches_the_models_function(sim):
    from evclust.fixed.formats import DECAY_FRAC_BITS, DECAY_TABLE_BITS

    header, bits = apply_build()
    result = run(
        sim, header, "apply_vectors", {"bits": bits, "seed": 5}, toplevel="evclust_decay_apply", parameters={"ACTIVITY_BITS": bits}
    )
    assert result["checked"] == 3 * (((62 - DECAY_FRAC_BITS + 2) << DECAY_TABLE_BITS) + 1) + RANDOM_CASES


def test_the_sweep_reaches_the_cut_off_and_known_values():
    """The cases' own coverage: a half-life halves, no time leaves Ã unchanged, past the cut-off
    nothing is left, and the sweep holds m on both sides of it."""
    from evclust.fixed.formats import DECAY_FRAC_BITS, DECAY_TABLE_BITS

    _, bits = apply_build()
    a_max = (1 << bits) - 1
    assert model_apply(a_max, 0) == a_max
    assert model_apply(a_max, 1 << DECAY_TABLE_BITS) == a_max >> 1
    cut = (62 - DECAY_FRAC_BITS + 1) << DECAY_TABLE_BITS
    assert model_apply(a_max, cut) == 0 and model_apply(a_max, cut + (1 << 40)) == 0
    assert model_apply(a_max, bits << DECAY_TABLE_BITS) == 0 < model_apply(a_max, (bits - 1) << DECAY_TABLE_BITS)  # Ã's last bit
    ms = {m for _, m in apply_cases(bits, 5)}
    assert cut - 1 in ms and cut in ms and max(ms) >= 1 << 60
