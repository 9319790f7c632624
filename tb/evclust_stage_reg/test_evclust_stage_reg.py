"""evclust_stage_reg, the register between a leaf module's two stages, against a one-word model:
STAGES = 2 holds `d` as it was at the last edge with `advance` (zero after an edge with `rst`,
which wins over `advance`); STAGES = 1 passes `d` through in the same cycle. Under Icarus and
Verilator.

Each cycle drives a random word with random `advance` (60 %) and `rst` (5 %); before the edge
the output must be the model's (for STAGES = 1, the word just driven), so a register that loads
without `advance`, ignores `rst` or lags a cycle fails.
"""

from __future__ import annotations

import random

import pytest


try:
    import cocotb

    from cosim import checked_vectors
    from cocotb.clock import Clock
    from cocotb.triggers import FallingEdge, RisingEdge, Timer
except ImportError:  # collected by pytest without cocotb: the pytest half still reports why
    cocotb = None

CYCLES = 2000
WIDTH = 45  # wider than a 32-bit word, so a truncation shows

if cocotb is not None:

    @cocotb.test()
    async def stage_reg_vectors(dut):
        """Random words, advances and resets; the first output that differs from the model fails."""
        await checked_vectors(dut, _stage_reg_vectors)

    async def _stage_reg_vectors(dut, config):
        stages, rng = config["stages"], random.Random(config["seed"])
        cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start())
        held = 0  # the model's register, as after a reset
        dut.rst.value, dut.advance.value, dut.d.value = 1, 0, 0
        await RisingEdge(dut.clk)
        await FallingEdge(dut.clk)
        checked = 0
        for cycle in range(CYCLES):
            word, advance, reset = rng.getrandbits(WIDTH), rng.random() < 0.6, rng.random() < 0.05
            dut.d.value, dut.advance.value, dut.rst.value = word, int(advance), int(reset)
            await Timer(1, unit="ns")
            expected = word if stages == 1 else held
            got = int(dut.q.value)
            checked += 1
            if got != expected:
                return f"cycle {cycle} (advance={int(advance)}, rst={int(reset)}): q = {got:#x}, the model's {expected:#x}", checked
            await RisingEdge(dut.clk)
            held = 0 if reset else word if advance else held
            await FallingEdge(dut.clk)
        return None, checked


# ------------------------------------------------------------------------------------------
# pytest: build, launch, check.

from cosim import LEAF_SIMULATORS, configuration_params, run, selected_simulators  # noqa: E402


@pytest.mark.parametrize("stages", [1, 2])
@pytest.mark.parametrize("sim", selected_simulators(LEAF_SIMULATORS))
def test_the_output_is_the_word_of_the_last_advance(sim, stages):
    from evclust.fixed.formats import build_formats
    from evclust.fixed.header import verilog_header

    header = verilog_header(build_formats(configuration_params("traffic", 16), 480, 270, 50000.0))
    config = {"stages": stages, "seed": stages}
    result = run(sim, header, "stage_reg_vectors", config, toplevel="evclust_stage_reg", parameters={"W": WIDTH, "STAGES": stages})
    assert result["checked"] == CYCLES
