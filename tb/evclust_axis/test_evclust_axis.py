"""evclust_axis, the integration top (AXI4-Stream events and records, AXI4-Lite registers),
against the fixed model under Icarus and Verilator, driven by cocotbext-axi's stream source and
sink with random pauses on both sides and its AXI4-Lite master.

As tb/evclust_core/test_evclust_core.py: the cocotb test runs inside the simulator (configured
by EVCLUST_TB), the pytest function builds and launches it through `cocotb_tools.runner`.
"""

from __future__ import annotations

import json
import os
import random
from pathlib import Path

import pytest


try:
    import cocotb
    from cocotb.clock import Clock
    from cocotb.triggers import ClockCycles, RisingEdge, with_timeout
except ImportError:  # collected by pytest without cocotb: the pytest half still reports why
    cocotb = None

CLOCK_NS = 10


def _pauses(seed: int, probability: float):
    """A pause generator for cocotbext-axi: True (pause) on a random share of cycles."""
    rng = random.Random(seed)
    while True:
        yield rng.random() < probability


if cocotb is not None:

    @cocotb.test()
    async def axis_stream(dut):
        """Random events through the AXI4-Stream ports with random pauses; cluster records, object
        records, trace and counters against the fixed model, bit for bit."""
        config = json.loads(os.environ["EVCLUST_TB"])
        try:
            error, stats = await _axis_stream(dut, config)
        except Exception as exc:
            error, stats = f"{type(exc).__name__}: {exc}", {}
        Path(config["out"]).write_text(json.dumps(stats | {"error": error}))
        assert error is None, error

    async def _axis_stream(dut, config):
        from cocotbext.axi import AxiLiteBus, AxiLiteMaster, AxiStreamBus, AxiStreamSink, AxiStreamSource

        from evclust.clusterer import ClustererParams
        from evclust.fixed.model import FixedClusterer
        from evclust.fixed.registers import COUNTERS, counter_address, model_counters
        from evclust.fixed.layouts import event_fields, object_fields, record_fields
        from evclust.vectors.scoreboard import first_mismatch, first_object_mismatch
        from evclust.vectors.stimulus import random_stream
        from evclust.vectors.write import model_words

        cocotb.start_soon(Clock(dut.clk, CLOCK_NS, unit="ns").start())
        params = ClustererParams(**config["parameters"])
        width, height, t_frame = config["width"], config["height"], config["t_frame_us"]
        model = FixedClusterer(params, width, height, t_frame)
        events, expected, expected_trace, expected_objects = model_words(
            model, random_stream(config["seed"], config["count"], width, height, t_frame)
        )

        source = AxiStreamSource(AxiStreamBus.from_prefix(dut, "s_axis_event"), dut.clk, dut.rst)
        sink = AxiStreamSink(AxiStreamBus.from_prefix(dut, "m_axis_record"), dut.clk, dut.rst)
        object_sink = AxiStreamSink(AxiStreamBus.from_prefix(dut, "m_axis_object"), dut.clk, dut.rst)
        registers = AxiLiteMaster(AxiLiteBus.from_prefix(dut, "s_axil"), dut.clk, dut.rst)
        source.set_pause_generator(_pauses(config["seed"], config["pause"]))
        sink.set_pause_generator(_pauses(config["seed"] + 1, config["pause"]))
        object_sink.set_pause_generator(_pauses(config["seed"] + 2, config["pause"]))

        # Monitor: each trace word, and each record and object record as it is taken with the events traced so far.
        trace, records, tags, objects, object_tags = [], [], [], [], []

        async def monitor():
            while True:
                await RisingEdge(dut.clk)
                if int(dut.trace_valid.value):
                    trace.append(int(dut.trace_data.value))
                if int(dut.m_axis_record_tvalid.value) and int(dut.m_axis_record_tready.value):
                    records.append(int(dut.m_axis_record_tdata.value))
                    tags.append(len(trace))
                if int(dut.m_axis_object_tvalid.value) and int(dut.m_axis_object_tready.value):
                    objects.append(int(dut.m_axis_object_tdata.value))
                    object_tags.append(len(trace))

        dut.rst.value = 1
        await ClockCycles(dut.clk, 4)
        dut.rst.value = 0
        cocotb.start_soon(monitor())
        ev_bytes = len(source.bus.tdata) // 8
        for word in events:
            await source.send(word.to_bytes(ev_bytes, "little"))
        bound = 1000 + len(events) * 64  # cycles: pauses on both sides, every filter step
        await with_timeout(source.wait(), bound * CLOCK_NS, "ns")
        while len(trace) < len(events) or len(records) < len(expected) or len(objects) < len(expected_objects):
            await RisingEdge(dut.clk)
            bound -= 1
            if bound < 0:
                return (
                    f"no progress: {len(trace)} of {len(events)} events traced, {len(records)} of {len(expected)} records, "
                    f"{len(objects)} of {len(expected_objects)} object records"
                ), {}
        await ClockCycles(dut.clk, 4)  # a record more than the model's would show here
        while not sink.empty():
            sink.recv_nowait()
        while not object_sink.empty():
            object_sink.recv_nowait()
        counters = {name: await registers.read_dword(counter_address(name)) for name in COUNTERS}
        error = first_mismatch("axis stream", events, event_fields(model.table), expected_trace, trace,
                               record_fields(model.table), expected, records, tags)  # fmt: skip
        error = error or first_object_mismatch("axis stream", object_fields(model.table), expected_objects, objects, object_tags)
        error = error or (None if counters == model_counters(model.stats(), len(expected)) else f"counters: RTL {counters}")
        return error, {"events": len(trace), "records": len(records), "objects": len(objects), "counters": counters}


# ------------------------------------------------------------------------------------------
# pytest: build, launch, check.

from cosim import ICARUS_EVENTS, LEAF_SIMULATORS, random_config, run, selected_simulators, short_icarus  # noqa: E402


@pytest.mark.parametrize("sim", selected_simulators(LEAF_SIMULATORS))
def test_events_and_records_over_axi4_stream_with_random_pauses_match_the_model(sim):
    count = ICARUS_EVENTS if short_icarus(sim) else 3000
    header, config = random_config("small", 4, seed=31, count=count, pause=0.3)
    result = run(sim, header, "axis_stream", config, toplevel="evclust_axis")
    assert result["events"] == count
    assert result["records"] > 0, "a stream that reports nothing checks little"
    assert result["objects"] > 0, "nor one without objects"
    assert result["counters"]["events"] == count
