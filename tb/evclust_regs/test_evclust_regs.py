"""evclust_regs, the register file on the AXI4-Lite slave, against a model of the register map
built from the compiled SystemRDL (rtl/evclust_regs.rdl, which `make params` writes from
evclust.fixed.registers and tests/fixed/test_rdl.py keeps fresh): every register's address and
size, each field's bits, software access (read, write, write-1-to-clear, write-1 pulse) and
reset value come from the RDL, so an RTL that disagrees with the RDL fails here. What the RDL
does not say is the model's: which of the core's increments feed which counter (the header's
order), which sticky flag each sets, and that CTRL.CLEAR_COUNTERS clears the `hwclr` fields.
Checked: identity and build words, the configuration block reset to the build's parameter set
and written whole or a run of bytes at a time (read-only with the constants built in),
IRQ_ENABLE, CTRL's CLEAR pulse and CLEAR_COUNTERS, the counters adding the core's increments
modulo 2^32, STATUS's sticky flags (write 1 to clear) and `irq` (the RDL's `intr` fields and
their `enable`s), and 0 outside the map. Driven by cocotbext-axi's AXI4-Lite master, under
Icarus and Verilator.

First every register word and its neighbours read once out of reset (the RDL's reset values);
then rounds of: random counter increments for a while (then none, so that reads are exact), then
random bus operations (every kind above, reads of every register word and of addresses around
the map), each read compared with the model, `irq` and the CLEAR pulses checked throughout.
"""

from __future__ import annotations

import dataclasses
import random
from pathlib import Path

import pytest

from evclust.fixed.registers import COUNTER_INC_BITS, COUNTERS

try:
    import cocotb
    from cocotb.clock import Clock
    from cocotb.triggers import ClockCycles, FallingEdge, RisingEdge

    from cosim import checked_vectors
except ImportError:  # collected by pytest without cocotb: the pytest half still reports why
    cocotb = None

ROUNDS = 40
MASK = 0xFFFFFFFF
ADDRESS_SPACE = 1 << 12  # the slave's ADDR_W
# The core's events that set each sticky STATUS flag: any increment of these counters.
STICKY_SOURCES = {"SATURATED": tuple(name for name in COUNTERS if name.startswith("sat_")), "DROPPED": ("drops",)}


@dataclasses.dataclass(frozen=True)
class RdlField:
    name: str
    lsb: int
    width: int
    readable: bool
    writable: bool
    write_one_clears: bool  # onwrite = woclr
    pulse: bool  # singlepulse: a write of 1 pulses the core, the field reads 0
    counter: bool
    hw_clear: bool  # hwclr: cleared by CTRL.CLEAR_COUNTERS
    interrupt: bool
    enable: tuple[str, str] | None  # (register, field) whose bit enables the interrupt
    reset: int | None  # None: the core drives it (STATUS.IDLE)

    @property
    def mask(self) -> int:
        return ((1 << self.width) - 1) << self.lsb


@dataclasses.dataclass(frozen=True)
class RdlRegister:
    name: str
    address: int
    width: int  # bits: 32, or 64 for a configuration value wider than 32 bits
    fields: tuple[RdlField, ...]


def rdl_registers(path: str) -> tuple[RdlRegister, ...]:
    """The registers of the compiled SystemRDL file `path` (systemrdl-compiler), in address order."""
    from systemrdl.rdltypes import OnWriteType

    from evclust.fixed.rdl import compile_rdl

    root = compile_rdl(Path(path).read_text())
    out = []
    for reg in root.top.registers():
        fields = []
        for f in reg.fields():
            enable = f.get_property("enable")
            fields.append(RdlField(
                f.inst_name, f.lsb, f.width, f.is_sw_readable, f.is_sw_writable, f.get_property("onwrite") == OnWriteType.woclr,
                bool(f.get_property("singlepulse")), bool(f.get_property("counter")), bool(f.get_property("hwclr")),
                bool(f.get_property("intr")), (enable.parent.inst_name, enable.inst_name) if enable is not None else None,
                f.get_property("reset"),
            ))  # fmt: skip
        out.append(RdlRegister(reg.inst_name, reg.absolute_address, reg.get_property("regwidth"), tuple(fields)))
    return tuple(sorted(out, key=lambda r: r.address))


class RegisterMap:
    """What the register file holds, from the SystemRDL register map (not from the RTL)."""

    def __init__(self, registers: tuple[RdlRegister, ...], runtime: bool):
        self.registers = {reg.name: reg for reg in registers}
        self.runtime = runtime  # 0: the configuration (CFG_*) is built in, read-only
        self.words = {}  # byte address of each 32-bit word -> (register, word index in it)
        for reg in registers:
            for k in range(reg.width // 32):
                self.words[reg.address + 4 * k] = (reg, k)
        live = {(reg.name, f.name) for reg in registers for f in reg.fields if f.reset is None}
        assert live == {("STATUS", "IDLE")}, f"fields without a reset value, which the model cannot drive: {sorted(live)}"
        self.reset()

    def reset(self) -> None:
        self.values = {(reg.name, f.name): f.reset or 0 for reg in self.registers.values() for f in reg.fields}

    def address(self, name: str) -> int:
        return self.registers[name].address

    def config_words(self) -> list[int]:
        return [a for a, (reg, _) in self.words.items() if reg.name.startswith("CFG_")]

    def count(self, increments: list[int]) -> None:
        for name, inc in zip(COUNTERS, increments):
            reg = self.registers[f"COUNT_{name.upper()}"]
            (field,) = [f for f in reg.fields if f.counter]
            key = (reg.name, field.name)
            self.values[key] = (self.values[key] + inc) % (1 << field.width)
        moved = {name for name, inc in zip(COUNTERS, increments) if inc}
        for flag, sources in STICKY_SOURCES.items():
            if moved.intersection(sources):
                self.values[("STATUS", flag)] = 1

    def write(self, address: int, data: int, strobe: int) -> int:
        """The write's effect; the number of CLEAR pulses it gives."""
        if address not in self.words:
            return 0
        reg, k = self.words[address]
        if reg.name.startswith("CFG_") and not self.runtime:
            return 0
        lanes = sum(0xFF << (8 * b) for b in range(4) if strobe >> b & 1) << (32 * k)
        data = (data & MASK) << (32 * k)
        pulses = []
        for f in reg.fields:
            written = lanes & f.mask
            if not (f.writable and written):
                continue
            key, bits = (reg.name, f.name), (data & written) >> f.lsb
            if f.pulse:
                pulses += [f.name] if bits else []
            elif f.write_one_clears:
                self.values[key] &= ~bits
            else:
                keep = self.values[key] & ~(written >> f.lsb)
                self.values[key] = keep | bits
        if "CLEAR_COUNTERS" in pulses:
            for other in self.registers.values():
                for f in other.fields:
                    if f.hw_clear:
                        self.values[(other.name, f.name)] = 0
        return pulses.count("CLEAR")

    def read(self, address: int, idle: int) -> int:
        if address not in self.words:
            return 0
        reg, k = self.words[address]
        word = 0
        for f in reg.fields:
            if f.readable:
                word |= (idle if f.reset is None else self.values[(reg.name, f.name)]) << f.lsb
        return (word >> (32 * k)) & MASK

    @property
    def irq(self) -> int:
        return int(any(self.values[(reg.name, f.name)] and self.values[f.enable] for reg in self.registers.values()
                       for f in reg.fields if f.interrupt))  # fmt: skip


if cocotb is not None:

    @cocotb.test()
    async def regs_vectors(dut):
        """Rounds of counting and bus operations; the first read, irq or CLEAR pulse that differs fails."""
        await checked_vectors(dut, _regs_vectors)

    async def _regs_vectors(dut, config):
        from cocotbext.axi import AxiLiteBus, AxiLiteMaster

        model = RegisterMap(rdl_registers(config["rdl"]), config["runtime"])
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
        # Every register word, and the words just before and after each register (most outside the map).
        addresses = sorted({a + d for a in model.words for d in (-4, 0, 4) if 0 <= a + d < ADDRESS_SPACE} | {ADDRESS_SPACE - 4})
        config_words = model.config_words()
        status, irq_enable, ctrl = model.address("STATUS"), model.address("IRQ_ENABLE"), model.address("CTRL")
        checked, expected_pulses = 0, 0
        # Out of reset, before any write: every word reads its RDL reset value.
        for address in addresses:
            got, want = await bus.read_dword(address), model.read(address, int(dut.idle.value))
            checked += 1
            if got != want:
                return f"after reset: read 0x{address:03x}: RTL {got:#010x}, register map {want:#010x}", checked
        for round_ in range(ROUNDS):
            await FallingEdge(dut.clk)  # each increment set between edges, taken by the next rising one
            for _ in range(rng.randrange(1, 40)):  # the core counting: up to 3 per counter per cycle
                increments = [rng.choice((0, 0, 0, 1, 2, 3)) if rng.random() < 0.3 else 0 for _ in COUNTERS]
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
                    address, data = rng.choice(config_words), rng.getrandbits(32)
                elif kind < 0.75:
                    address, data = status, rng.getrandbits(3)
                elif kind < 0.85:
                    address, data = irq_enable, rng.getrandbits(3)
                elif kind < 0.95:
                    address, data = ctrl, rng.getrandbits(2)
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

from cosim import LEAF_SIMULATORS, RTL, configuration_params, run, selected_simulators  # noqa: E402

RDL = RTL / "evclust_regs.rdl"


def _header() -> str:
    """The build the RDL describes: the committed header's (the traffic preset, N = 16, 480x270)."""
    from evclust.fixed.formats import build_formats
    from evclust.fixed.header import verilog_header

    header = verilog_header(build_formats(configuration_params("traffic", 16), 480, 270, 50000.0))
    assert header == (RTL / "evclust_params.vh").read_text(), (
        "rtl/evclust_regs.rdl describes the committed header's build: run `make params`"
    )
    return header


def test_the_rdl_model_is_the_register_tables():
    # The model, from the RDL alone, against registers.py: reset reads, a wide value's two words,
    # a strobed byte, CTRL's pulses, a sticky flag and its interrupt.
    from evclust.fixed.generate import reference_table
    from evclust.fixed import registers

    _header()
    model = RegisterMap(rdl_registers(str(RDL)), runtime=True)
    table = reference_table()
    for field in registers.config_fields(table):
        words = [model.read(field.address + 4 * i, 1) for i in range(field.words)]
        assert sum(w << (32 * i) for i, w in enumerate(words)) == field.reset, field.name
    assert model.read(registers.REG_ID, 1) == registers.ID_VALUE and model.read(registers.REG_VERSION, 1) == registers.VERSION
    assert model.read(registers.REG_BUILD, 0) == table.n_clusters | table.palette_size << 16
    assert model.read(registers.REG_STATUS, 1) == registers.STATUS_IDLE and model.read(0x018, 1) == 0
    wide = next(f for f in registers.config_fields(table) if f.words == 2)
    model.write(wide.address + 4, 0xFFFFFFFF, 0b0010)
    assert model.read(wide.address + 4, 1) == ((wide.reset >> 32) | 0xFF00) & MASK
    assert model.write(registers.REG_CTRL, registers.CTRL_CLEAR | registers.CTRL_CLEAR_COUNTERS, 0b0001) == 1
    model.count([1 if name == "drops" else 0 for name in COUNTERS])
    assert model.read(registers.counter_address("drops"), 1) == 1 and model.irq == 0
    model.write(registers.REG_IRQ_ENABLE, registers.STATUS_DROPPED, 0b1111)
    assert model.irq == 1 and model.read(registers.REG_STATUS, 0) == registers.STATUS_DROPPED
    model.write(registers.REG_STATUS, registers.STATUS_DROPPED, 0b0001)
    assert model.irq == 0 and model.read(registers.counter_address("drops"), 1) == 1
    model.write(registers.REG_CTRL, registers.CTRL_CLEAR_COUNTERS, 0b0001)
    assert model.read(registers.counter_address("drops"), 1) == 0


@pytest.mark.parametrize("runtime", [1, 0], ids=["runtime_registers", "constants_built_in"])
@pytest.mark.parametrize("sim", selected_simulators(LEAF_SIMULATORS))
def test_every_register_reads_as_the_rdl_says(sim, runtime):
    result = run(sim, _header(), "regs_vectors", {"runtime": runtime, "seed": 5 + runtime, "rdl": str(RDL)}, toplevel="evclust_regs",
                 parameters={"RUNTIME_CONFIG": runtime})  # fmt: skip
    assert result["checked"] > 3 * ROUNDS
