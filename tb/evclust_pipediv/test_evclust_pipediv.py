"""evclust_pipediv, the sweep tail's pipelined divider, against integer division: the dividend
is remainder_in * 2^Q_W + bits_in (remainder_in below the divisor, so the quotient fits Q_W
bits), and its quotient leaves ceil(Q_W / STEP) enabled cycles later with the tag it came in
with, in order. Under Icarus and Verilator.

Each cycle offers random operands (edge values a quarter of the time: divisor 1 and all ones,
remainder 0 and divisor - 1, bits all zeros and all ones) with a random enable (70 %); a
synchronous reset now and then clears the tags in flight. The shapes: the core's (Q_W = 38,
DEN_W = 21, STEP = 4) and one whose first stage takes fewer bits than the others (Q_W = 10,
DEN_W = 5, STEP = 3).
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

CYCLES = 3000
TAG_W = 8


def operands(rng: random.Random, q_w: int, den_w: int) -> tuple[int, int, int]:
    """(remainder_in, bits_in, divisor) with remainder_in < divisor, edge values a quarter of the time."""
    edge = rng.random() < 0.25
    divisor = rng.choice((1, (1 << den_w) - 1)) if edge else rng.randrange(1, 1 << den_w)
    remainder = rng.choice((0, divisor - 1)) if edge else rng.randrange(divisor)
    bits = rng.choice((0, (1 << q_w) - 1)) if edge else rng.getrandbits(q_w)
    return remainder, bits, divisor


if cocotb is not None:

    @cocotb.test()
    async def pipediv_vectors(dut):
        """Random operands, enables and resets; the first quotient or tag that differs fails."""
        await checked_vectors(dut, _pipediv_vectors)

    async def _pipediv_vectors(dut, config):
        q_w, den_w, step = config["q_w"], config["den_w"], config["step"]
        stages = -(-q_w // step)
        rng = random.Random(config["seed"])
        cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start())
        dut.rst.value, dut.en.value = 1, 0
        dut.remainder_in.value, dut.bits_in.value, dut.divisor.value, dut.tag_in.value = 0, 0, 1, 0
        await RisingEdge(dut.clk)
        await FallingEdge(dut.clk)
        # The model: stage r's entry at pipe[r - 1] (stage 1 the newest, the last the output);
        # None for a stage whose tag a reset cleared.
        pipe: list[tuple[int, int] | None] = [None] * stages
        checked = 0
        for cycle in range(CYCLES):
            remainder, bits, divisor = operands(rng, q_w, den_w)
            tag, en, rst = rng.randrange(1, 1 << TAG_W), rng.random() < 0.7, rng.random() < 0.01
            dut.remainder_in.value, dut.bits_in.value, dut.divisor.value = remainder, bits, divisor
            dut.tag_in.value, dut.en.value, dut.rst.value = tag, int(en), int(rst)
            await RisingEdge(dut.clk)
            if rst:  # the tags clear; the data stages move only with en (their words are then don't-care)
                pipe = [None] * stages
            elif en:
                pipe = [(((remainder << q_w) | bits) // divisor, tag), *pipe[:-1]]
            await FallingEdge(dut.clk)
            head = pipe[-1]
            got_tag = int(dut.tag_out.value)
            if head is None:
                if got_tag != 0:
                    return f"cycle {cycle}: tag {got_tag:#x} out of an empty (reset) stage", checked
                continue
            want_q, want_tag = head
            got_q = int(dut.quotient.value)
            checked += 1
            if (got_q, got_tag) != (want_q, want_tag):
                return (
                    f"cycle {cycle}: RTL (quotient, tag) ({got_q:#x}, {got_tag:#x}), integer division ({want_q:#x}, {want_tag:#x})",
                    checked,
                )
        return None, checked


# ------------------------------------------------------------------------------------------
# pytest: build, launch, check.

from cosim import LEAF_SIMULATORS, configuration_params, run, selected_simulators  # noqa: E402

SHAPES = {"core": (38, 21, 4), "short_first_stage": (10, 5, 3)}


@pytest.mark.parametrize("shape", list(SHAPES))
@pytest.mark.parametrize("sim", selected_simulators(LEAF_SIMULATORS))
def test_each_quotient_leaves_with_its_tag_after_the_stages(sim, shape):
    from evclust.fixed.formats import build_formats
    from evclust.fixed.header import verilog_header

    q_w, den_w, step = SHAPES[shape]
    header = verilog_header(build_formats(configuration_params("traffic", 16), 480, 270, 50000.0))
    config = {"q_w": q_w, "den_w": den_w, "step": step, "seed": q_w}
    parameters = {"Q_W": q_w, "DEN_W": den_w, "STEP": step, "TAG_W": TAG_W}
    result = run(sim, header, "pipediv_vectors", config, toplevel="evclust_pipediv", parameters=parameters)
    # Entries come out once the pipe has filled after each reset: most enabled cycles check one.
    assert result["checked"] > 0.5 * CYCLES
