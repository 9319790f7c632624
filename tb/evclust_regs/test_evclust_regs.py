"""evclust_regs, the register file on the AXI4-Lite slave, against a model of the register map
(docs/REGISTERS.md, evclust.fixed.registers): identity and build words, the configuration block
reset to the build's parameter set and written whole or a run of bytes at a time (read-only with the constants
built in), IRQ_ENABLE, CTRL's CLEAR pulse and CLEAR_COUNTERS, the counters adding the core's
increments modulo 2^32, STATUS's sticky flags (write 1 to clear) and `irq`, and 0 outside the
map. Driven by cocotbext-axi's AXI4-Lite master, under Icarus and Verilator.

Rounds of: random counter increments for a while (then none, so that reads are exact), then
random bus operations (every kind above, reads of random addresses in and around the map),
each read compared with the model, `irq` and the CLEAR pulses checked throughout.
"""

from __future__ import annotations

import random

import pytest

from evclust.fixed.registers import (
    CONFIG_BASE, COUNTER_INC_BITS, COUNTERS, COUNTERS_BASE, CTRL_CLEAR, CTRL_CLEAR_COUNTERS, ID_VALUE, REG_BUILD, REG_CTRL, REG_ID,
    REG_IRQ_ENABLE, REG_STATUS, REG_VERSION, STATUS_DROPPED, STATUS_SATURATED, VERSION, config_fields, config_words,
)  # fmt: skip

try:
    import cocotb
    from cocotb.clock import Clock
    from cocotb.triggers import ClockCycles, FallingEdge, RisingEdge

    from cosim import checked_vectors
except ImportError:  # collected by pytest without cocotb: the pytest half still reports why
    cocotb = None

ROUNDS = 40
MASK = 0xFFFFFFFF


class RegisterMap:
    """What the register file holds, from the register map (not from the RTL)."""

    def __init__(self, table, runtime: bool):
        self.runtime = runtime
        self.n_counters = len(COUNTERS)
        self.reset_words = [0] * config_words(table)
        for field in config_fields(table):
            for i in range(field.words):
                self.reset_words[field.word + i] = (field.reset >> (32 * i)) & MASK
        self.build = (table.palette_size << 16) | table.n_clusters
        self.reset()

    def reset(self) -> None:
        self.config = list(self.reset_words)
        self.counters = [0] * self.n_counters
        self.irq_enable = self.saturated = self.dropped = 0

    def count(self, increments: list[int]) -> None:
        self.counters = [(c + i) & MASK for c, i in zip(self.counters, increments)]
        self.saturated |= any(i for name, i in zip(COUNTERS, increments) if name.startswith("sat_"))
        self.dropped |= increments[COUNTERS.index("drops")] != 0

    def write(self, address: int, data: int, strobe: int) -> int:
        """The write's effect; the number of CLEAR pulses it gives."""
        word = (address - CONFIG_BASE) // 4
        if address >= CONFIG_BASE and word < len(self.config) and self.runtime:
            keep = sum(0xFF << (8 * b) for b in range(4) if not strobe >> b & 1)
            self.config[word] = (self.config[word] & keep) | (data & ~keep & MASK)
        if not strobe & 1:  # CTRL, STATUS and IRQ_ENABLE live in byte 0
            return 0
        if address == REG_IRQ_ENABLE:
            self.irq_enable = data & 7
        if address == REG_STATUS:
            self.saturated &= not data & STATUS_SATURATED
            self.dropped &= not data & STATUS_DROPPED
        if address == REG_CTRL:
            if data & CTRL_CLEAR_COUNTERS:
                self.counters = [0] * self.n_counters
                self.saturated = self.dropped = 0
            return int(bool(data & CTRL_CLEAR))
        return 0

    def read(self, address: int, idle: int) -> int:
        fixed = {REG_ID: ID_VALUE, REG_VERSION: VERSION, REG_BUILD: self.build, REG_IRQ_ENABLE: self.irq_enable,
                 REG_STATUS: idle | self.saturated << 1 | self.dropped << 2}  # fmt: skip
        if address in fixed:
            return fixed[address]
        if COUNTERS_BASE <= address < COUNTERS_BASE + 4 * self.n_counters and address % 4 == 0:
            return self.counters[(address - COUNTERS_BASE) // 4]
        if CONFIG_BASE <= address < CONFIG_BASE + 4 * len(self.config) and address % 4 == 0:
            return self.config[(address - CONFIG_BASE) // 4]
        return 0

    @property
    def irq(self) -> int:
        return int(bool(self.saturated and self.irq_enable & 2) or bool(self.dropped and self.irq_enable & 4))


if cocotb is not None:

    @cocotb.test()
    async def regs_vectors(dut):
        """Rounds of counting and bus operations; the first read, irq or CLEAR pulse that differs fails."""
        await checked_vectors(dut, _regs_vectors)

    async def _regs_vectors(dut, config):
        from cocotbext.axi import AxiLiteBus, AxiLiteMaster

        from evclust.fixed.formats import build_formats
        from evclust.rtl.configurations import configuration_params

        table = build_formats(configuration_params("traffic", 16), 480, 270, 50000.0)
        model = RegisterMap(table, config["runtime"])
        rng = random.Random(config["seed"])
        cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start())
        dut.count_inc.value, dut.idle.value, dut.rst.value = 0, 1, 1
        bus = AxiLiteMaster(AxiLiteBus.from_prefix(dut, "s_axil"), dut.clk, dut.rst)
        await ClockCycles(dut.clk, 3)
        dut.rst.value = 0
        pulses = [0]

        async def count_pulses():
            while True:
                await RisingEdge(dut.clk)
                await FallingEdge(dut.clk)
                pulses[0] += int(dut.clear.value)

        cocotb.start_soon(count_pulses())
        addresses = [0x000, 0x004, 0x008, 0x00C, 0x010, 0x014, 0x018, 0x03C, 0x0FC]
        addresses += [COUNTERS_BASE + 4 * i for i in range(model.n_counters + 1)]
        addresses += [CONFIG_BASE + 4 * i for i in range(len(model.config) + 1)]
        checked, expected_pulses = 0, 0
        for round_ in range(ROUNDS):
            await FallingEdge(dut.clk)  # each increment set between edges, taken by the next rising one
            for _ in range(rng.randrange(1, 40)):  # the core counting: up to 3 per counter per cycle
                increments = [rng.choice((0, 0, 0, 1, 2, 3)) if rng.random() < 0.3 else 0 for _ in range(model.n_counters)]
                dut.count_inc.value = sum(v << (COUNTER_INC_BITS * i) for i, v in enumerate(increments))
                await FallingEdge(dut.clk)
                model.count(increments)
            dut.count_inc.value = 0
            await FallingEdge(dut.clk)
            for _ in range(rng.randrange(4, 16)):
                kind = rng.random()
                if kind < 0.35:
                    address = rng.choice(addresses)
                    got = await bus.read_dword(address)
                    want = model.read(address, int(dut.idle.value))
                    checked += 1
                    if got != want:
                        return f"round {round_}: read 0x{address:03x}: RTL {got:#010x}, register map {want:#010x}", checked
                    continue
                if kind < 0.6:
                    address, data = CONFIG_BASE + 4 * rng.randrange(len(model.config)), rng.getrandbits(32)
                elif kind < 0.75:
                    address, data = REG_STATUS, rng.getrandbits(3)
                elif kind < 0.85:
                    address, data = REG_IRQ_ENABLE, rng.getrandbits(3)
                elif kind < 0.95:
                    address, data = REG_CTRL, rng.getrandbits(2)
                else:
                    address, data = rng.choice(addresses), rng.getrandbits(32)
                # The master strobes the bytes it is given: a whole word, or a run of bytes in it.
                first, length = (0, 4) if rng.random() < 0.6 else (lambda b: (b, rng.randrange(1, 5 - b)))(rng.randrange(4))
                strobe = ((1 << length) - 1) << first
                await bus.write(address + first, data.to_bytes(4, "little")[first : first + length])
                expected_pulses += model.write(address, data, strobe)
                dut.idle.value = rng.random() < 0.8
            await ClockCycles(dut.clk, 2)
            if int(dut.irq.value) != model.irq:
                return f"round {round_}: irq {int(dut.irq.value)}, register map {model.irq}", checked
            if pulses[0] != expected_pulses:
                return f"round {round_}: {pulses[0]} CLEAR pulses, register map {expected_pulses}", checked
        return None, checked


# ------------------------------------------------------------------------------------------
# pytest: build, launch, check.

from cosim import configuration_params, run, selected_simulators  # noqa: E402


@pytest.mark.parametrize("runtime", [1, 0], ids=["runtime_registers", "constants_built_in"])
@pytest.mark.parametrize("sim", selected_simulators())
def test_every_register_reads_as_the_register_map_says(sim, runtime):
    from evclust.fixed.formats import build_formats
    from evclust.fixed.header import verilog_header

    header = verilog_header(build_formats(configuration_params("traffic", 16), 480, 270, 50000.0))
    result = run(sim, header, "regs_vectors", {"runtime": runtime, "seed": 5 + runtime}, toplevel="evclust_regs",
                 parameters={"RUNTIME_CONFIG": runtime})  # fmt: skip
    assert result["checked"] > 3 * ROUNDS
