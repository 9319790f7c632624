"""evclust_slot_ram, the cluster table's rows that no search compares, against a list of rows:
one synchronous write port, three asynchronous read ports, under Icarus and Verilator.

Each cycle writes a random row to a random slot (or none) while the ports read random slots;
after the edge every port must show the list's rows, so a read of the slot just written sees the
new row and every other slot keeps its own. Depths 4, 16 and 64 (the core's N), rows of 421
bits (the width only scales the words).

The cocotb test runs inside the simulator (configured by EVCLUST_TB); the pytest function builds
and launches it through `cocotb_tools.runner`, as tb/evclust_core/test_evclust_core.py.
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

if cocotb is not None:

    @cocotb.test()
    async def slot_ram_vectors(dut):
        """Random writes and reads; the first read that differs from the list of rows fails."""
        await checked_vectors(dut, _slot_ram_vectors)

    async def _slot_ram_vectors(dut, config):
        depth, width = config["depth"], config["width"]
        rng = random.Random(config["seed"])
        cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start())
        rows = [None] * depth  # None: never written (undefined in the RAM, not compared)
        dut.we.value = 0
        await FallingEdge(dut.clk)
        checked = 0
        for cycle in range(CYCLES):
            write = rng.random() < 0.7
            slot, row = rng.randrange(depth), rng.getrandbits(width)
            a, b, e = rng.randrange(depth), rng.randrange(depth), rng.randrange(depth)
            dut.we.value = int(write)
            dut.waddr.value = slot
            dut.wdata.value = row
            dut.raddr_a.value = a
            dut.raddr_b.value = b
            dut.raddr_e.value = e
            await RisingEdge(dut.clk)
            if write:
                rows[slot] = row
            await FallingEdge(dut.clk)  # after the edge, before the next inputs: the stored rows
            for port, address in (("rdata_a", a), ("rdata_b", b), ("rdata_e", e)):
                if rows[address] is None:
                    continue
                got = int(getattr(dut, port).value)
                checked += 1
                if got != rows[address]:
                    return f"cycle {cycle}: {port} of slot {address} is {got:#x}, the row written last is {rows[address]:#x}", checked
        return None, checked


# ------------------------------------------------------------------------------------------
# pytest: build, launch, check.

from cosim import LEAF_SIMULATORS, configuration_params, run, selected_simulators  # noqa: E402


@pytest.mark.parametrize("depth", [4, 16, 64])
@pytest.mark.parametrize("sim", selected_simulators(LEAF_SIMULATORS))
def test_each_read_port_shows_the_row_last_written_to_its_slot(sim, depth):
    from evclust.fixed.formats import build_formats
    from evclust.fixed.header import verilog_header

    header = verilog_header(build_formats(configuration_params("traffic", 16), 480, 270, 50000.0))
    width, address_bits = 421, max(1, (depth - 1).bit_length())
    config = {"depth": depth, "width": width, "seed": depth}
    parameters = {"DEPTH": depth, "WIDTH": width, "ADDR_W": address_bits}
    result = run(sim, header, "slot_ram_vectors", config, toplevel="evclust_slot_ram", parameters=parameters)
    # Three reads a cycle once every slot has been written (a few dozen cycles at these depths).
    assert 3 * CYCLES * 0.9 < result["checked"] <= 3 * CYCLES
