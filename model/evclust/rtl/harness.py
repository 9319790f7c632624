"""The co-simulation harness of evclust_core (tb/evclust_core/evclust_tb.v), run inside the
simulator by cocotb: it drives the core's streams and AXI4-Lite registers and compares every
trace entry, record, object record and counter with the fixed model, bit for bit.

`evclust.rtl.cosim.run` launches one of its cocotb tests (replay_vectors, model_in_the_loop,
serve, reconfigure), configured by the EVCLUST_TB environment variable, and reads the result
back: the RTL model (evclust.rtl.session), the stream runs (evclust.rtl.stream) and the
testbenches in tb/evclust_core/ all go through it. cocotb is the test extra's: this module is
imported only inside a simulator.
"""

from __future__ import annotations

import hashlib
import json
import os
import time
from pathlib import Path

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, RisingEdge, SimTimeoutError, with_timeout

from evclust.fixed.registers import model_counters

CLOCK_NS = 10


def _config() -> dict:
    return json.loads(os.environ["EVCLUST_TB"])


def _finish(config: dict, result: dict) -> None:
    Path(config["out"]).write_text(json.dumps(result))
    if result.get("error"):
        raise AssertionError(result["error"])


class Harness:
    """The evclust_tb harness: batches in, records and trace out."""

    def __init__(self, dut, n_clusters: int, filter_every: int):
        self.dut = dut
        self.depth = len(dut.ev_mem)
        rec_depth = len(dut.rec_mem)
        # A batch's records must fit the capture memory: at most N per filter step.
        self.batch = max(1, min(self.depth, (rec_depth // n_clusters - 1) * filter_every))
        self.ev_mem = [dut.ev_mem[i] for i in range(self.depth)]
        self.filter_every = filter_every
        self.stats = {
            "cycles": 0,
            "filter_cycles": 0,
            "filter_steps": 0,
            "object_wait_cycles": 0,
            "object_busy_cycles": 0,
            "object_drain_cycles": 0,
            "events": 0,
            "wall_s": 0.0,
            "latency_min": None,
            "latency_max": 0,
            "latency_sum": 0,
        }

    async def reset(self, cycles: int = 3):
        self.dut.rst.value = 1
        self.dut.start.value = 0
        await ClockCycles(self.dut.clk, cycles)
        self.dut.rst.value = 0
        await ClockCycles(self.dut.clk, 2)  # the harness holds events until the core is ready

    async def stream(self, words: list[int], seed: int, gap: int, stall: int, n_clusters: int):
        """All words through the core in batches: (trace words, record words, record tags); the
        object unit's record words and their tags in `self.objects`, `self.object_tags`."""
        trace, records, tags = [], [], []
        self.objects, self.object_tags = [], []
        dut = self.dut
        start = time.perf_counter()
        for lo in range(0, len(words), self.batch):
            batch = words[lo : lo + self.batch]
            for handle, word in zip(self.ev_mem, batch):
                handle.value = word
            dut.count.value = len(batch)
            dut.seed.value = (seed + lo) & 0xFFFFFFFF or 1
            dut.gap_threshold.value = gap
            dut.stall_threshold.value = stall
            dut.start.value = 1
            await RisingEdge(dut.clk)
            dut.start.value = 0
            # Bound: every event, eviction scan and filter step at its worst (with every slot merging,
            # each merge a division of up to 128 cycles, and the object unit's step: its scans of
            # K slots per group and per merge), slowed by the gaps and stalls.
            merges = n_clusters * 130 // self.filter_every + 1
            objects = (n_clusters * n_clusters * 8 + 64 * n_clusters + 200) // self.filter_every + 1
            bound = 1000 + len(batch) * (8 + 2 * n_clusters + merges + objects) * 256 // max(1, 256 - max(gap, stall))
            try:
                await with_timeout(RisingEdge(dut.done), bound * CLOCK_NS, "ns")
            except SimTimeoutError:
                raise AssertionError(
                    f"no progress: after {bound} cycles the core took {int(dut.accepted.value)} of {len(batch)} events "
                    f"of batch {lo // self.batch}, traced {int(dut.traced.value)}, emitted {int(dut.captured.value)} records"
                ) from None
            await RisingEdge(dut.clk)
            if int(dut.overflow.value):
                raise AssertionError("the harness's record memory overflowed: a smaller batch is needed")
            traced, captured = int(dut.traced.value), int(dut.captured.value)
            trace += [int(dut.trace_mem[i].value) for i in range(traced)]
            records += [int(dut.rec_mem[i].value) for i in range(captured)]
            tags += [lo + int(dut.rec_tag[i].value) for i in range(captured)]
            objects = int(dut.objects_captured.value)
            self.objects += [int(dut.obj_mem[i].value) for i in range(objects)]
            self.object_tags += [lo + int(dut.obj_tag[i].value) for i in range(objects)]
            for name in (
                "cycles",
                "filter_cycles",
                "filter_steps",
                "object_wait_cycles",
                "object_busy_cycles",
                "object_drain_cycles",
                "latency_sum",
            ):
                self.stats[name] += int(getattr(dut, name).value)
            low = int(dut.latency_min.value)
            self.stats["latency_min"] = low if self.stats["latency_min"] is None else min(self.stats["latency_min"], low)
            self.stats["latency_max"] = max(self.stats["latency_max"], int(dut.latency_max.value))
            self.stats["events"] += len(batch)
        self.stats["wall_s"] += time.perf_counter() - start
        return trace, records, tags


class Registers:
    """The register file through cocotbext-axi's AXI4-Lite master (docs/REGISTERS.md)."""

    def __init__(self, dut):
        from cocotbext.axi import AxiLiteBus, AxiLiteMaster

        self.dut = dut
        self.bus = AxiLiteMaster(AxiLiteBus.from_prefix(dut, "s_axil"), dut.clk, dut.rst)

    async def program(self, writes) -> None:
        for address, word in writes:
            await self.bus.write_dword(address, word)

    async def counters(self) -> dict[str, int]:
        from evclust.fixed.registers import COUNTERS, counter_address

        return {name: await self.bus.read_dword(counter_address(name)) for name in COUNTERS}

    async def clear(self) -> None:
        """CTRL.CLEAR and CLEAR_COUNTERS, once the core is idle; then INIT runs."""
        from evclust.fixed.registers import CTRL_CLEAR, CTRL_CLEAR_COUNTERS, REG_CTRL

        while not int(self.dut.idle.value):
            await RisingEdge(self.dut.clk)
        await self.bus.write_dword(REG_CTRL, CTRL_CLEAR | CTRL_CLEAR_COUNTERS)
        await ClockCycles(self.dut.clk, 2)


def _counter_mismatch(expected: dict, got: dict) -> str | None:
    wrong = {name: (expected[name], got[name]) for name in expected if expected[name] != got[name]}
    return f"status counters (model, RTL): {wrong}" if wrong else None


def _records_seen(words: list[int], table) -> list[dict]:
    """Each record word's flags and class, for the coverage bins."""
    from evclust.fixed.layouts import record_fields
    from evclust.vectors.pack import unpack

    fields = record_fields(table)
    names = [f[0] for f in fields]
    flags, klass = names.index("flags"), names.index("class")
    return [{"flags": v[flags], "class": v[klass]} for v in (unpack(w, fields) for w in words)]


async def _coverage(dut, counters: dict, records: list[dict]) -> dict:
    """The run's functional-coverage bins (evclust.rtl.coverage): the harness's counters of the
    core's FSM, the status counters summed over the run, the records' flags and classes."""
    from evclust.rtl.coverage import run_bins

    def read(handle):  # X before the first clock edge (a run refused before it starts): nothing counted
        return [int(handle[i].value) if handle[i].value.is_resolvable else 0 for i in range(len(handle))]

    fsm = {
        name: read(handle)
        for name, handle in (("state", dut.cov_state), ("arc", dut.cov_arc), ("phase", dut.cov_phase), ("stream", dut.cov_stream))
    }
    return run_bins(fsm, counters, records)


def _add(total: dict, counters: dict) -> dict:
    return {name: total.get(name, 0) + value for name, value in counters.items()}


def _seed(*parts) -> int:
    return int.from_bytes(hashlib.sha256(repr(parts).encode()).digest()[:4], "little") or 1


def _compare(name, events, expected_trace, trace, expected, records, tags, table, expected_objects=(), harness=None):
    """The first mismatch of the trace and the cluster records, else of the object records."""
    from evclust.fixed.layouts import event_fields, object_fields, record_fields
    from evclust.vectors.scoreboard import first_mismatch, first_object_mismatch

    error = first_mismatch(name, events, event_fields(table), expected_trace, trace, record_fields(table), expected, records, tags)
    if error or harness is None:
        return error
    return first_object_mismatch(name, object_fields(table), list(expected_objects), harness.objects, harness.object_tags)


@cocotb.test()
async def replay_vectors(dut):
    """Every listed vector case, each after a reset, with random input gaps and output stalls."""
    from evclust.errors import EvclustError
    from evclust.vectors.read import load_case

    config = _config()
    result = {"cases": {}, "runtime_config": int(dut.RUNTIME_CONFIG.value)}
    cocotb.start_soon(Clock(dut.clk, CLOCK_NS, unit="ns").start())
    registers = Registers(dut)  # the build's parameters, from reset; the counters read after each case
    header = Path(config["header"]).read_text()
    summed, seen = {}, []
    for folder in config["cases"]:
        try:
            case = load_case(folder, rtl_header=header)
        except EvclustError as exc:
            result["error"] = str(exc)
            break
        harness = Harness(dut, case.table.n_clusters, case.params.filter_every)
        await harness.reset()
        trace, records, tags = await harness.stream(
            case.events, _seed(case.name, config["seed"]), config["gap"], config["stall"], case.table.n_clusters
        )
        error = _compare(case.name, case.events, case.trace, trace, case.expected, records, tags, case.table, case.objects, harness)
        counters = await registers.counters()
        # The manifest's counts, saturations of every signal included, against the RTL's status counters.
        error = error or _counter_mismatch(model_counters(case.manifest["counts"], len(case.expected)), counters)
        result["cases"][case.name] = harness.stats | {"records": len(records), "objects": len(harness.objects), "counters": counters}
        summed, seen = _add(summed, counters), seen + _records_seen(records, case.table)
        if error:
            result["error"] = error
            break
    result["coverage"] = await _coverage(dut, summed, seen)
    _finish(config, result)


@cocotb.test()
async def model_in_the_loop(dut):
    """Random streams through the RTL and the fixed model in this process, compared bit for bit;
    with `reset_at`, a reset lands in the middle of the stream and both start again."""
    config = _config()
    try:
        error, stats = await _model_in_the_loop(dut, config)
    except Exception as exc:  # a model or harness failure, reported as such rather than as a missing result
        error, stats = f"{type(exc).__name__}: {exc}", {}
    _finish(config, stats | {"error": error})


async def _model_in_the_loop(dut, config):
    import numpy as np

    from evclust.clusterer import ClustererParams
    from evclust.fixed.header import verilog_header
    from evclust.fixed.model import FixedClusterer
    from evclust.vectors.stimulus import random_stream
    from evclust.vectors.write import model_words

    cocotb.start_soon(Clock(dut.clk, CLOCK_NS, unit="ns").start())
    params = ClustererParams(**config["parameters"])
    width, height, t_frame = config["width"], config["height"], config["t_frame_us"]
    formats = config.get("formats", {})  # build_formats's options: beta_shift_only, dead_band_bits
    if config.get("events"):  # a recorded stream (evclust.rtl.run_stream), else a random one
        events = np.load(config["events"])
    else:
        events = random_stream(config["seed"], config["count"], width, height, t_frame)
    model = FixedClusterer(params, width, height, t_frame, **formats)
    if verilog_header(model.table) != Path(config["header"]).read_text():
        return "the RTL was built with another header than these parameters make", {}
    harness = Harness(dut, params.n_clusters, params.filter_every)
    registers = Registers(dut)
    await harness.reset()
    if config.get("reset_at"):
        # Part of the stream, with the same gaps and stalls, cut off by a reset while it flows.
        part = events[: config["reset_at"]]
        words = model_words(FixedClusterer(params, width, height, t_frame, **formats), part).events
        for handle, word in zip(harness.ev_mem, words):
            handle.value = word
        dut.count.value, dut.seed.value = len(words), 7
        dut.gap_threshold.value, dut.stall_threshold.value = config["gap"], config["stall"]
        dut.start.value = 1
        await RisingEdge(dut.clk)
        dut.start.value = 0
        await ClockCycles(dut.clk, config["reset_cycle"])
        if int(dut.done.value):
            return "the stream ended before the reset: choose an earlier reset_cycle", {}
        await harness.reset(cycles=1)
    event_list, expected, expected_trace, expected_objects = model_words(model, events)
    trace, records, tags = await harness.stream(event_list, config["seed"], config["gap"], config["stall"], params.n_clusters)
    name = Path(config["events"]).stem if config.get("events") else f"random stream {config['seed']}"
    error = _compare(name, event_list, expected_trace, trace, expected, records, tags, model.table, expected_objects, harness)
    counters = await registers.counters()
    if not error:
        error = _counter_mismatch(model_counters(model.stats(), len(expected)), counters)
    coverage = await _coverage(dut, counters, _records_seen(records, model.table))
    return error, harness.stats | {"records": len(records), "objects": len(harness.objects), "counters": counters, "coverage": coverage}


@cocotb.test()
async def serve(dut):
    """The RTL as a clusterer model (evclust.rtl.session): batches of event words in over a
    named pipe, record words and object record words back, the status counters at the end. No model here: the
    caller's own tests compare it with the fixed model."""
    import numpy as np

    config = _config()
    cocotb.start_soon(Clock(dut.clk, CLOCK_NS, unit="ns").start())
    registers = Registers(dut)
    harness = Harness(dut, config["n_clusters"], config["filter_every"])
    await harness.reset()
    with open(config["requests"]) as requests, open(config["answers"], "w") as answers:
        for line in requests:
            if not line.strip():
                answers.write(json.dumps(await registers.counters()) + "\n")
                answers.flush()
                break
            words = [int(w) for w in np.load(line.strip()).tolist()]
            _, records, _ = await harness.stream(words, 1, 0, 0, config["n_clusters"])
            out = line.strip()[: -len(".npy")] + "-records.npy"
            objects = line.strip()[: -len(".npy")] + "-objects.npy"
            np.save(out, np.array([str(r) for r in records]))
            np.save(objects, np.array([str(r) for r in harness.objects]))
            answers.write(f"{out} {objects}\n")
            answers.flush()
    _finish(config, {"error": None})


@cocotb.test()
async def reconfigure(dut):
    """Two streams with two parameter sets: the build's from reset, then another written over
    AXI4-Lite and a CTRL.CLEAR (no reset); records, trace and counters bit-exact to the model."""
    config = _config()
    try:
        error, stats = await _reconfigure(dut, config)
    except Exception as exc:
        error, stats = f"{type(exc).__name__}: {exc}", {}
    _finish(config, stats | {"error": error})


async def _reconfigure(dut, config):
    from evclust.clusterer import ClustererParams
    from evclust.fixed.model import FixedClusterer
    from evclust.fixed.registers import ID_VALUE, REG_BUILD, REG_ID, register_writes
    from evclust.vectors.stimulus import random_stream
    from evclust.vectors.write import model_words

    cocotb.start_soon(Clock(dut.clk, CLOCK_NS, unit="ns").start())
    width, height, t_frame = config["width"], config["height"], config["t_frame_us"]
    built = ClustererParams(**config["parameters"])
    build = FixedClusterer(built, width, height, t_frame).table
    registers = Registers(dut)
    harness = Harness(dut, built.n_clusters, built.filter_every)
    await harness.reset()
    if await registers.bus.read_dword(REG_ID) != ID_VALUE:
        return "the ID register does not read EVCL", {}
    if await registers.bus.read_dword(REG_BUILD) != build.n_clusters | build.palette_size << 16:
        return "the BUILD register does not give N and the palette size", {}
    out, summed, seen = {}, {}, []
    for step, (params, seed) in enumerate(((built, config["seed"]), (ClustererParams(**config["second"]), config["seed"] + 1))):
        if step:
            model = FixedClusterer(params, width, height, t_frame, build=build)
            await registers.program(register_writes(build, model.table))
            await registers.clear()
        else:
            model = FixedClusterer(params, width, height, t_frame)
        harness = Harness(dut, params.n_clusters, params.filter_every)  # its batch follows the filter period
        events = random_stream(seed, config["count"], width, height, t_frame)
        event_list, expected, expected_trace, expected_objects = model_words(model, events)
        trace, records, tags = await harness.stream(event_list, seed, config["gap"], config["stall"], params.n_clusters)
        error = _compare(
            f"stream {step + 1}", event_list, expected_trace, trace, expected, records, tags, model.table, expected_objects, harness
        )
        counters = await registers.counters()
        error = error or _counter_mismatch(model_counters(model.stats(), len(expected)), counters)
        if error:
            return f"stream {step + 1}: {error}", out
        out[f"stream {step + 1}"] = {"records": len(records), "objects": len(harness.objects), "counters": counters}
        summed, seen = _add(summed, counters), seen + _records_seen(records, model.table)
    return None, out | {"coverage": await _coverage(dut, summed, seen)}
