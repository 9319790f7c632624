"""evclust_decay, the activity decay A * 2^(-dt/T_half), against the model's functions
(`arith.decay_steps` then `arith.decay_apply`, floor rounding, as the fixed model decays a slot)
under Icarus and Verilator.

Exhaustive where the input space is small: every step count m = dt * (1/T_half) / 2^DROP from 0
to two whole halvings past the point where nothing is left (every table entry, every shift, the
cut-off), each with the largest activity and the largest residual (used: it carries into m; unused:
it must not), with 1, and with random ones; the residual out.
Random elsewhere: activity, dt, the residual and 1/T_half drawn over their whole widths, within
the model's documented domain dt * (1/T_half) + residual < 2^62.

The cocotb test runs inside the simulator (configured by EVCLUST_TB); the pytest function builds
and launches it through `cocotb_tools.runner`, as tb/evclust_core/test_evclust_core.py.
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

RANDOM_CASES = 4000
PRODUCT_LIMIT_BITS = 62  # arith.decay's domain: dt * inv_t_half_raw + residual < 2^62


def decay_cases(widths: dict, seed: int):
    """(activity, dt, residual, use_residual, inv_t_half) inputs: the exhaustive sweep over m, then random ones."""
    from evclust.fixed.formats import DECAY_FRAC_BITS, DECAY_TABLE_BITS

    rng = random.Random(seed)
    drop = widths["INV_T_HALF_FRAC"] - DECAY_TABLE_BITS
    a_max = (1 << widths["ACTIVITY_W"]) - 1
    residual_max = (1 << widths["DECAY_RESIDUAL_W"]) - 1
    # inv_t_half = 2^DROP makes m = dt exactly, whatever residual comes in below one step.
    one_step = 1 << drop
    last_m = (62 - DECAY_FRAC_BITS + 2) << DECAY_TABLE_BITS
    for m in range(last_m + 1):
        # The largest residual carries into m when used and must not when not; then 1 and 0.
        yield a_max, m, residual_max, 1, one_step
        yield a_max, m, residual_max, 0, one_step
        yield 1, m, 0, 1, one_step
        yield rng.randrange(a_max + 1), m, rng.randrange(residual_max + 1), rng.randrange(2), one_step
    for _ in range(RANDOM_CASES):
        inv_bits = rng.randrange(1, widths["INV_T_HALF_W"] + 1)
        inv = rng.randrange(1 << (inv_bits - 1), 1 << inv_bits)
        dt_bits = min(widths["DT_W"], PRODUCT_LIMIT_BITS - 1 - inv_bits)
        residual = rng.choice((0, residual_max, rng.randrange(residual_max + 1)))
        activity = rng.choice((0, a_max, rng.randrange(a_max + 1)))
        yield activity, rng.randrange(1 << dt_bits), residual, rng.randrange(2), inv


def model_decay(widths: dict, activity: int, dt: int, residual: int, use_residual: int, inv: int) -> tuple[int, int]:
    """(decayed activity, residual out) as the fixed model's `_decay_slot` computes them."""
    from evclust.fixed.arith import FLOOR, decay_apply, decay_steps
    from evclust.fixed.formats import DECAY_FRAC_BITS, DECAY_TABLE_BITS

    m, residual_out = decay_steps(dt, residual if use_residual else 0, inv, widths["INV_T_HALF_FRAC"], DECAY_TABLE_BITS)
    return decay_apply(activity, m, widths["table"], DECAY_TABLE_BITS, DECAY_FRAC_BITS, FLOOR), residual_out


if cocotb is not None:

    @cocotb.test()
    async def decay_vectors(dut):
        """Every case through the combinational module; the first difference from the model fails."""
        await checked_vectors(dut, _decay_vectors)

    async def _decay_vectors(dut, config):
        widths = config["widths"] | {"table": config["table"]}
        error, checked = None, 0
        for activity, dt, residual, use_residual, inv in decay_cases(widths, config["seed"]):
            dut.activity.value = activity
            dut.dt.value = dt
            dut.residual.value = residual
            dut.use_residual.value = use_residual
            dut.inv_t_half.value = inv
            await Timer(1, unit="ns")
            got = (int(dut.decayed.value), int(dut.residual_out.value))
            want = model_decay(widths, activity, dt, residual, use_residual, inv)
            checked += 1
            if got != want:
                error = (f"activity={activity} dt={dt} residual={residual} use_residual={use_residual} inv_t_half={inv}: "
                         f"RTL (decayed, residual) {got}, model {want}")  # fmt: skip
                break
        return error, checked


# ------------------------------------------------------------------------------------------
# pytest: build, launch, check.

from cosim import LEAF_SIMULATORS, configuration_params, run, selected_simulators  # noqa: E402

# Two builds whose decay widths differ: the traffic preset's T_half and a small sensor's.
BUILDS = {"traffic": (480, 270, 50000.0), "small": (64, 48, 10000.0)}


def decay_build(name: str) -> tuple[str, dict, dict]:
    """(header, module parameters, widths and table for the cocotb side) of a build."""
    from evclust.fixed.formats import build_formats, decay_table
    from evclust.fixed.header import verilog_header

    width, height, t_frame = BUILDS[name]
    table = build_formats(configuration_params(name, 16), width, height, t_frame)
    widths = {"ACTIVITY_W": table["activity"].word_bits, "DT_W": table["dt"].word_bits,
              "DECAY_RESIDUAL_W": table["decay_residual"].word_bits,
              "INV_T_HALF_W": table.constants["inv_t_half"].fmt.word_bits,
              "INV_T_HALF_FRAC": table.constants["inv_t_half"].fmt.frac_bits}  # fmt: skip
    parameters = {"ACTIVITY_BITS": widths["ACTIVITY_W"], "DT_BITS": widths["DT_W"],
                  "RESIDUAL_BITS": widths["DECAY_RESIDUAL_W"], "INV_T_HALF_BITS": widths["INV_T_HALF_W"]}  # fmt: skip
    return verilog_header(table), parameters, {"widths": widths, "table": [int(v) for v in decay_table(table)]}


@pytest.mark.parametrize("build", sorted(BUILDS))
@pytest.mark.parametrize("sim", selected_simulators(LEAF_SIMULATORS))
def test_the_decay_matches_the_models_functions_over_every_step_count_and_random_inputs(sim, build):
    header, parameters, config = decay_build(build)
    result = run(sim, header, "decay_vectors", config | {"seed": 7}, toplevel="evclust_decay", parameters=parameters)
    from evclust.fixed.formats import DECAY_FRAC_BITS, DECAY_TABLE_BITS

    exhaustive = ((62 - DECAY_FRAC_BITS + 2) << DECAY_TABLE_BITS) + 1
    assert result["checked"] == 4 * exhaustive + RANDOM_CASES


def test_the_exhaustive_sweep_reaches_every_table_entry_every_shift_and_the_cut_off():
    """The sweep's own coverage, independent of the simulator: every index of the table, every
    shift up to the cut-off, and results of 0 beyond it."""
    _, _, config = decay_build("traffic")
    widths = config["widths"] | {"table": config["table"]}
    from evclust.fixed.formats import DECAY_FRAC_BITS, DECAY_TABLE_BITS

    drop = widths["INV_T_HALF_FRAC"] - DECAY_TABLE_BITS
    swept = [(dt, inv) for _, dt, _, _, inv in decay_cases(widths, 7) if inv == 1 << drop]
    ms = {dt for dt, _ in swept}
    assert {m & ((1 << DECAY_TABLE_BITS) - 1) for m in ms} == set(range(1 << DECAY_TABLE_BITS))
    assert {m >> DECAY_TABLE_BITS for m in ms} == set(range(62 - DECAY_FRAC_BITS + 3))
    a_max = (1 << widths["ACTIVITY_W"]) - 1
    beyond = (62 - DECAY_FRAC_BITS + 1) << DECAY_TABLE_BITS
    assert model_decay(widths, a_max, beyond, 0, 0, 1 << drop)[0] == 0  # past the cut-off: nothing left
    assert model_decay(widths, a_max, 0, 0, 0, 1 << drop)[0] == a_max  # no time: unchanged
    # One half-life halves (floor): 2^-(64/64) = 1/2 exactly.
    assert model_decay(widths, a_max, 1 << DECAY_TABLE_BITS, 0, 0, 1 << drop)[0] == a_max >> 1
