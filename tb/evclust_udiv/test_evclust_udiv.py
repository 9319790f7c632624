"""evclust_udiv, the merge's iterative divider, against integer division: NUM_W cycles after
`start`, `done` rises with floor(numerator / denominator) and the remainder, and holds them
until the next start. Under Icarus and Verilator.

Random operands (edge values a quarter of the time: numerator 0 and all ones, denominator 1
and all ones), a random pause before each start, and now and then a start while busy, which
must drop the division under way for the new one; a reset clears `done`. Two shapes: the
merge's (NUM_W = 32, DEN_W = 16) and a narrow one (NUM_W = 5, DEN_W = 3).
"""

from __future__ import annotations

import random

import pytest

try:
    import cocotb

    from cosim import checked_vectors
    from cocotb.clock import Clock
    from cocotb.triggers import FallingEdge, RisingEdge
except ImportError:  # collected by pytest without cocotb: the pytest half still reports why
    cocotb = None

DIVISIONS = 400


if cocotb is not None:

    @cocotb.test()
    async def udiv_vectors(dut):
        """Random divisions, restarts and resets; the first quotient, remainder or done that differs fails."""
        await checked_vectors(dut, _udiv_vectors)

    async def _udiv_vectors(dut, config):
        num_w, den_w = config["num_w"], config["den_w"]
        rng = random.Random(config["seed"])
        cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start())
        dut.rst.value, dut.start.value, dut.numerator.value, dut.denominator.value = 1, 0, 0, 1
        await RisingEdge(dut.clk)
        await FallingEdge(dut.clk)
        dut.rst.value = 0
        if int(dut.done.value) != 0:
            return "done high after a reset", 0

        def draw() -> tuple[int, int]:
            edge = rng.random() < 0.25
            num = rng.choice((0, (1 << num_w) - 1)) if edge else rng.getrandbits(num_w)
            den = rng.choice((1, (1 << den_w) - 1)) if edge else rng.randrange(1, 1 << den_w)
            return num, den

        async def cycles(n: int) -> None:
            for _ in range(n):
                await RisingEdge(dut.clk)
                await FallingEdge(dut.clk)

        async def start() -> tuple[int, int]:
            """A start with new operands; then other operands on the inputs, which a busy divider ignores."""
            num, den = draw()
            dut.numerator.value, dut.denominator.value, dut.start.value = num, den, 1
            await cycles(1)
            dut.start.value = 0
            dut.numerator.value, dut.denominator.value = rng.getrandbits(num_w), rng.randrange(1, 1 << den_w)
            return num, den

        checked = 0
        for division in range(DIVISIONS):
            await cycles(rng.randrange(3))  # a pause: done and the last result hold
            num, den = await start()
            if rng.random() < 0.1:  # a start part way through: the new division replaces it
                await cycles(rng.randrange(1, num_w))
                num, den = await start()
            for cycle in range(num_w):
                if int(dut.done.value) != 0:
                    return f"division {division}: done after {cycle} of {num_w} cycles", checked
                await cycles(1)
            got = (int(dut.done.value), int(dut.quotient.value), int(dut.remainder_out.value))
            want = (1, num // den, num % den)
            checked += 1
            if got != want:
                return f"division {division}: {num} / {den}: RTL (done, quotient, remainder) {got}, integer division {want}", checked
        return None, checked


# ------------------------------------------------------------------------------------------
# pytest: build, launch, check.

from cosim import LEAF_SIMULATORS, configuration_params, run, selected_simulators  # noqa: E402

SHAPES = {"merge": (32, 16), "narrow": (5, 3)}


@pytest.mark.parametrize("shape", list(SHAPES))
@pytest.mark.parametrize("sim", selected_simulators(LEAF_SIMULATORS))
def test_done_rises_num_w_cycles_after_start_with_the_quotient_and_remainder(sim, shape):
    from evclust.fixed.formats import build_formats
    from evclust.fixed.header import verilog_header

    num_w, den_w = SHAPES[shape]
    header = verilog_header(build_formats(configuration_params("traffic", 16), 480, 270, 50000.0))
    config = {"num_w": num_w, "den_w": den_w, "seed": num_w}
    result = run(sim, header, "udiv_vectors", config, toplevel="evclust_udiv", parameters={"NUM_W": num_w, "DEN_W": den_w})
    assert result["checked"] == DIVISIONS
