"""evclust_core against the fixed-point model, bit for bit, under Icarus and Verilator.

Two halves in one file, in the style of verilog-axis: cocotb tests (run inside the simulator,
configured by the EVCLUST_TB environment variable) and the pytest functions that build the RTL
for each parameter set and launch them through `cocotb_tools.runner` (tb/cosim.py).
"""

from __future__ import annotations

import hashlib
import json
import os
import sys
import time
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

# ------------------------------------------------------------------------------------------
# Inside the simulator.

try:
    import cocotb
    from cocotb.clock import Clock
    from cocotb.triggers import ClockCycles, RisingEdge, with_timeout
    from cocotb.triggers import SimTimeoutError
except ImportError:  # collected by pytest without cocotb: the pytest half still reports why
    cocotb = None

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


if cocotb is not None:
    from evclust.fixed.registers import model_counters

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


# ------------------------------------------------------------------------------------------
# pytest: build per parameter set, launch, check.

from cosim import CONFIGURATIONS, FORMAT_VARIANTS, cosim_share, full, random_config, run, selected_simulators  # noqa: E402

from evclust.vectors import CASES  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
VECTORS = ROOT / "vectors"
SIMS = selected_simulators()
GAP, STALL = 64, 96  # random input gaps 25 % of cycles, output stalls 37.5 %


def _case_header(name: str) -> str:
    from evclust.vectors.read import load_case

    return load_case(VECTORS / name).header


# `make test` replays, under each simulator, the cases that anchor the schedule and the pipeline
# and ROTATING_CASES more drawn from the commit hash for that simulator (tb/cosim.py's rotating
# subset: successive commits cover them all); `make test-full` replays every case under both.
ANCHOR_CASES = ("traffic_clip", "pipelined_traffic", "pipelined_eviction_voids", "table_full")
ROTATING_CASES = 4


def replayed_cases() -> list[tuple[str, str]]:
    """(simulator, case) pairs this run replays."""
    others = [case for case in CASES if case not in ANCHOR_CASES]
    return [(sim, case) for sim in SIMS for case in (*ANCHOR_CASES, *cosim_share(others, ROTATING_CASES, "vectors", sim))]


@pytest.mark.rotating
@pytest.mark.parametrize("sim, case", replayed_cases())
def test_vector_case_replays_bit_exact(sim, case):
    result = run(sim, _case_header(case), "replay_vectors", {"cases": [str(VECTORS / case)], "seed": 1, "gap": GAP, "stall": STALL})
    assert case in result["cases"]
    assert result["cases"][case]["records"] == json.loads((VECTORS / case / "manifest.json").read_text())["counts"]["records"]


BUILT_IN_CASES = ("traffic_clip", "table_full", "merge_edges")  # one a simulator in make test


@pytest.mark.rotating
@pytest.mark.parametrize("sim, case", [(sim, c) for sim in SIMS for c in cosim_share(BUILT_IN_CASES, 1, "built-in", sim)])
def test_the_core_with_its_constants_built_in_replays_bit_exact(sim, case):
    # RUNTIME_CONFIG = 0: the header's constants folded into the datapath, the cfg port unread.
    config = {"cases": [str(VECTORS / case)], "seed": 2, "gap": GAP, "stall": STALL}
    result = run(sim, _case_header(case), "replay_vectors", config, parameters={"RUNTIME_CONFIG": 0})
    assert result["runtime_config"] == 0
    assert result["cases"][case]["records"] == json.loads((VECTORS / case / "manifest.json").read_text())["counts"]["records"]


# Icarus is some 30 times slower than Verilator per cycle, and slower still where the object
# unit works every few events: in `make test` it runs the first 3,000 events of the streams on
# the small and defaults sensors, which report hundreds to thousands of records by then (the
# traffic and pedestrian streams report nothing before 4,000 events, and run whole).
# `make cosim-full` (EVCLUST_COVER=all) runs every stream whole.
ICARUS_EVENTS = {"small": 3000, "defaults": 3000}


def _stream_length(sim: str, preset: str, count: int) -> int:
    """Events of a random stream on `preset`'s sensor under `sim`."""
    if sim == "verilator" or full():
        return count
    return min(count, ICARUS_EVENTS.get(preset, count))


def _random_config(preset, n_clusters, seed, count, **extra):
    return random_config(preset, n_clusters, seed, count, **({"gap": GAP, "stall": STALL} | extra))


STREAMS = [(preset, n) for preset in CONFIGURATIONS for n in (4, 16)]  # half of them a simulator in make test


@pytest.mark.rotating
@pytest.mark.parametrize(
    "sim, preset, n_clusters", [(sim, *stream) for sim in SIMS for stream in cosim_share(STREAMS, len(STREAMS) // 2, "streams", sim)]
)
def test_random_streams_match_the_model_in_the_loop(sim, preset, n_clusters):
    # EVCLUST_SEED=n draws other streams than the committed seeds.
    seed = int(os.environ.get("EVCLUST_SEED", 1000)) + n_clusters
    count = _stream_length(sim, preset, 10_000)
    header, config = _random_config(preset, n_clusters, seed=seed, count=count)
    result = run(sim, header, "model_in_the_loop", config)
    assert result["events"] == count
    assert result["records"] > 0, "a stream that reports nothing checks little"


@pytest.mark.parametrize("preset, delay", [("small", 2), ("defaults", 1), ("defaults", 2)])
@pytest.mark.parametrize("sim", SIMS)
def test_the_pipelined_core_matches_the_model_in_the_loop_through_gaps_and_stalls(sim, preset, delay):
    # update_delay = 1: each update commits as the next event finishes; 2: as the one after
    # finishes, its second half computed a stage later. The pipeline is event-clocked, so the
    # stream's random gaps and output stalls must not change what it computes.
    from cosim import configuration_params

    seed = int(os.environ.get("EVCLUST_SEED", 1000)) + 7 + delay
    count = _stream_length(sim, preset, 10_000)
    params = configuration_params(preset, 16).model_copy(update={"update_delay": delay})
    header, config = _random_config(preset, 16, seed=seed, count=count, params=params)
    result = run(sim, header, "model_in_the_loop", config)
    assert result["events"] == count
    assert result["records"] > 0, "a stream that reports nothing checks little"


def _second_parameter_set(params):
    """Another parameter set for the same build: every run-time switch flipped and most constants
    moved (build-time ones kept: N, palette size, merging, creation support, warm-up length)."""
    return params.model_copy(update=dict(
        alpha_pos=0.99, alpha_size=0.995, alpha_lum=0.99, alpha_chro=0.98, alpha_bg=0.998, alpha_vel_mcm=0.9999,
        gamma_mode="activity", velocity_warm_start=not params.velocity_warm_start, mcm_bias_correction=not params.mcm_bias_correction,
        palette_assign="nearest", palette_vote="count", tau_us=15000.0, filter_every=5, a_valid=4.0, a_min=0.8,
        seek_margin=3.0, r_init=3.0, size_gain=1.3, background=(90, 120, 140), luma_weight=1.5, p_correction=0.6,
        palette=tuple(entry.model_copy(update={"rgb": tuple(reversed(entry.rgb))}) for entry in params.palette),
    ))  # fmt: skip


@pytest.mark.parametrize("sim", SIMS)
def test_parameters_written_over_axi_lite_between_two_streams_are_bit_exact(sim):
    from evclust.clusterer import ClustererParams

    count = _stream_length(sim, "small", 6000)
    header, config = _random_config("small", 4, seed=77, count=count)
    second = _second_parameter_set(ClustererParams(**config["parameters"]))
    result = run(sim, header, "reconfigure", config | {"second": second.model_dump(mode="json", exclude_none=True)})
    first, then = result["stream 1"], result["stream 2"]
    assert first["records"] > 0 and then["records"] > 0, "streams that report nothing check little"
    assert first["counters"]["events"] == then["counters"]["events"] == count  # CLEAR_COUNTERS between them


def test_a_second_parameter_set_needing_another_build_is_refused():
    from evclust.clusterer import ClustererParams
    from evclust.errors import EvclustError
    from evclust.fixed.model import FixedClusterer

    header, config = _random_config("small", 4, seed=77, count=10)
    built = ClustererParams(**config["parameters"])
    build = FixedClusterer(built, 64, 48, 10000.0).table
    for change, message in (({"n_clusters": 8}, "build-time"), ({"r_max": 1000.0}, "saturates"),
                            ({"merge": not built.merge}, "build-time")):  # fmt: skip
        with pytest.raises(EvclustError, match=message):
            FixedClusterer(built.model_copy(update=change), 64, 48, 10000.0, build=build)


@pytest.mark.parametrize("variant", list(FORMAT_VARIANTS))
@pytest.mark.parametrize("sim", SIMS)
def test_the_formats_tables_other_shapes_match_the_model_in_the_loop(sim, variant):
    # Shift-only βs (the products become shifts) and the narrowest filter states: the RTL takes
    # both from its header alone, so they must stay bit-exact without an RTL change.
    header, config = _random_config("traffic", 16, seed=5, count=10_000, formats=FORMAT_VARIANTS[variant])
    default, _ = _random_config("traffic", 16, seed=5, count=0)
    assert header != default
    result = run(sim, header, "model_in_the_loop", config)
    assert result["events"] == 10_000 and result["records"] > 0


def test_the_two_format_sets_differ():
    a, _ = _random_config("traffic", 16, 0, 0)
    b, _ = _random_config("pedestrian", 16, 0, 0)
    widths = lambda h: {line.split("=")[0] for line in h.splitlines() if "_W =" in line and "PALETTE" not in line}
    assert widths(a) == widths(b)
    assert [line for line in a.splitlines() if "_W =" in line] != [line for line in b.splitlines() if "_W =" in line]


RESET_CYCLES = (5, 1501, 4003)  # in the mixing table's fill, early, late: one a simulator in make test


@pytest.mark.rotating
@pytest.mark.parametrize("sim, reset_cycle", [(sim, c) for sim in SIMS for c in cosim_share(RESET_CYCLES, 1, "reset", sim)])
def test_a_reset_in_the_middle_of_a_stream_recovers_the_models_state_after_reset(sim, reset_cycle):
    # The small configuration learns its background and refreshes the mixing table, so state a
    # reset forgets to clear would show; the part before the reset runs with gaps and stalls.
    header, config = _random_config("small", 4, seed=77, count=4000, reset_at=4000, reset_cycle=reset_cycle)
    result = run(sim, header, "model_in_the_loop", config)
    assert result["events"] == 4000


@pytest.mark.parametrize("sim", SIMS)
def test_no_event_is_lost_or_duplicated_under_heavy_back_pressure(sim):
    # The output stalled 75 % of the cycles, with input gaps: the trace must count every event
    # once, in order, and every record must match the model. 10^5 events under Verilator; Icarus,
    # some 40 times slower on this design, checks the same behaviour on 10^4.
    count = 100_000 if sim == "verilator" else 10_000
    header, config = _random_config("traffic", 16, seed=5, count=count)
    result = run(sim, header, "model_in_the_loop", config | {"gap": 32, "stall": 192})
    assert result["events"] == count


@pytest.mark.parametrize("sim", SIMS)
def test_a_sparse_input_feeds_events_while_the_sweep_emits_records(sim):
    # Input gaps 94 % of the cycles: stage A is often empty when a sweep starts, so it takes the
    # next event while records leave (the coverage bin "an event in and a record out in one cycle").
    count = 20_000 if sim == "verilator" else 3_000
    header, config = _random_config("small", 4, seed=6, count=count)
    result = run(sim, header, "model_in_the_loop", config | {"gap": 240, "stall": 64})
    assert result["events"] == count
    assert result["coverage"]["stream: an event in and a record out in one cycle"] > 0


@pytest.mark.parametrize("sim", SIMS)
def test_one_cycle_per_event_and_max_n_p_plus_the_tail_per_sweep(sim):
    # Without gaps or stalls: each event takes one cycle (the seek of the next overlaps its
    # update); each filter step its phase cycle (fewer than two tau boundaries here), max(N, P)
    # cycles and the sweep tail's, then one cycle in which the held event enters the seek again;
    # besides, the cycles the object unit holds the core (counted apart, and bounded below).
    from evclust.fixed.formats import mixing_fill_cycles, sweep_tail_cycles
    from evclust.vectors.read import load_case

    case = "bursts"  # no evictions: no scans
    result = run(sim, _case_header(case), "replay_vectors", {"cases": [str(VECTORS / case)], "seed": 1, "gap": 0, "stall": 0})
    stats = result["cases"][case]
    manifest = json.loads((VECTORS / case / "manifest.json").read_text())
    table = load_case(VECTORS / case).table
    tail, start = sweep_tail_cycles(table), mixing_fill_cycles(table) + 8  # the reset's fill, the harness's start
    assert stats["filter_steps"] == manifest["counts"]["steps"]
    own = stats["filter_cycles"] - stats["object_wait_cycles"]
    assert own == stats["filter_steps"] * (1 + max(manifest["n_clusters"], manifest["palette_size"]) + tail)
    outside = stats["cycles"] - stats["filter_cycles"] - stats["object_drain_cycles"]  # not the object unit's last step
    assert stats["events"] + stats["filter_steps"] <= outside <= stats["events"] + stats["filter_steps"] + start
    # The object unit works on every step and holds the core for at most the part of its work
    # that outlasts the events between two steps.
    assert stats["object_busy_cycles"] > stats["filter_steps"] * 8
    assert stats["object_wait_cycles"] <= stats["object_busy_cycles"]
    # Latency: the edge after the one that takes an event moves it into EXEC, the next writes its
    # slot. An event taken as a filter step starts waits in stage A for the whole step (its
    # phase cycle, the sweep and its tail, the object unit's hold) and re-enters the seek.
    assert stats["latency_min"] == 2
    step = 1 + max(manifest["n_clusters"], manifest["palette_size"]) + tail
    assert 2 < stats["latency_max"] <= 2 + step + stats["object_wait_cycles"] + 1
    assert (
        2 * stats["events"]
        <= stats["latency_sum"]
        <= 2 * stats["events"] + stats["filter_steps"] * (step + 1) + stats["object_wait_cycles"]
    )


@pytest.mark.parametrize("sim", SIMS)
def test_each_merge_holds_the_sweep_for_the_dividers_steps_plus_three_cycles(sim):
    # Without gaps or stalls: each filter step's 1 + max(N, P) + tail cycles plus, for each
    # merge, the detection, the dividers' start, their MERGE_MOMENT_W steps and the write; outside
    # the steps one cycle per event and one per step (the held event re-enters the seek).
    from evclust.fixed.formats import mixing_fill_cycles, sweep_tail_cycles
    from evclust.vectors.read import load_case

    case = "merge_edges"
    result = run(sim, _case_header(case), "replay_vectors", {"cases": [str(VECTORS / case)], "seed": 1, "gap": 0, "stall": 0})
    stats = result["cases"][case]
    manifest = json.loads((VECTORS / case / "manifest.json").read_text())
    table = load_case(VECTORS / case).table
    moment_bits = table["merge_moment"].word_bits
    counts = manifest["counts"]
    assert counts["merged"] > 0 and counts["evicted"] == counts["dropped"] == 0  # no eviction scans
    assert stats["filter_steps"] == counts["steps"]  # filter_active stays high through a step's merges
    sweeps = counts["steps"] * (1 + max(manifest["n_clusters"], manifest["palette_size"]) + sweep_tail_cycles(table))
    merges = stats["filter_cycles"] - stats["object_wait_cycles"] - sweeps
    outside = stats["cycles"] - stats["filter_cycles"] - stats["object_drain_cycles"]  # not the object unit's last step
    assert stats["events"] + counts["steps"] <= outside <= stats["events"] + counts["steps"] + mixing_fill_cycles(table) + 8
    assert merges == counts["merged"] * (moment_bits + 3)


def _tampered_copy(tmp_path, case: str, edit) -> Path:
    """A copy of a case with one file edited and its manifest's sha256 updated to match."""
    import shutil

    folder = tmp_path / case
    shutil.copytree(VECTORS / case, folder)
    file = edit(folder)
    manifest = json.loads((folder / "manifest.json").read_text())
    manifest["sha256"][file] = hashlib.sha256((folder / file).read_bytes()).hexdigest()
    (folder / "manifest.json").write_text(json.dumps(manifest))
    return folder


@pytest.mark.parametrize("sim", SIMS)
def test_a_wrong_expected_record_is_reported_field_by_field(sim, tmp_path):
    from evclust.fixed.layouts import record_fields
    from evclust.vectors.pack import pack, unpack
    from evclust.vectors.read import load_case

    case = load_case(VECTORS / "bursts")
    fields = record_fields(case.table)
    values = unpack(case.expected[7], fields)
    values[[f[0] for f in fields].index("vx_int")] += 1

    def edit(folder):
        lines = (folder / "expected.hex").read_text().splitlines()
        lines[7] = f"{pack(values, fields):0{len(lines[7])}x}"
        (folder / "expected.hex").write_text("\n".join(lines) + "\n")
        return "expected.hex"

    folder = _tampered_copy(tmp_path, "bursts", edit)
    with pytest.raises(
        AssertionError,
        match=r"bursts: record 7 \(expected.hex line 8\), emitted after event \d+ \(trace.hex line \d+\): vx_int: RTL -?\d+, model -?\d+$",
    ):
        run(sim, case.header, "replay_vectors", {"cases": [str(folder)], "seed": 1, "gap": 0, "stall": 0})


@pytest.mark.parametrize("sim", SIMS)
def test_a_case_for_another_parameter_set_fails_clearly(sim):
    header = _case_header("traffic_clip")
    with pytest.raises(AssertionError, match="bursts: made for another parameter set than the RTL was built with"):
        run(sim, header, "replay_vectors", {"cases": [str(VECTORS / "bursts")], "seed": 1, "gap": 0, "stall": 0})


@pytest.mark.parametrize("sim", SIMS)
def test_a_truncated_case_fails_clearly(sim, tmp_path):
    def edit(folder):
        lines = (folder / "events.hex").read_text().splitlines()
        (folder / "events.hex").write_text("\n".join(lines[:-5]) + "\n")
        return "events.hex"

    folder = _tampered_copy(tmp_path, "bursts", edit)
    with pytest.raises(AssertionError, match=r"events.hex: 1995 lines, the manifest says 2000 \(truncated\?\)"):
        run(sim, _case_header("bursts"), "replay_vectors", {"cases": [str(folder)], "seed": 1, "gap": 0, "stall": 0})
