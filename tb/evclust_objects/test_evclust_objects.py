"""evclust_objects, the object layer behind the core's record port, on its own: cluster records and
filter-step ends in, object records out, against the fixed model's object layer
(`evclust.fixed.objects.FixedObjects`) on the same input, bit for bit, under Icarus and Verilator.

The input is a vector case's cluster records (vectors/<case>/expected.hex, as the core emits
them), grouped into their filter steps. A step that emitted no record still ends, at a time
between its neighbours' (the records do not carry it), and some steps are left out altogether,
so that Δt varies as the core's own vectors never make it. Every port handshakes at random: the
records and step ends arrive with gaps, and the passed-on records and the object records are
taken with random back-pressure. The configuration block comes from the register map
(`evclust.fixed.registers`), not from the header's reset value, so the run-time path is the one
checked; the records passed on must leave unchanged and in order.
"""

from __future__ import annotations

import random

import numpy as np
import pytest

try:
    import cocotb

    from cosim import checked_vectors
    from cocotb.clock import Clock
    from cocotb.triggers import FallingEdge, RisingEdge
except ImportError:  # collected by pytest without cocotb: the pytest half still reports why
    cocotb = None

WRAP = 1 << 32
SKIP_STEPS = 0.05  # the share of filter steps left out of the stream (Δt grows)
MAX_CYCLES_PER_STEP = 20000  # a step the unit has not finished by then is a hang


def steps_of(case, seed: int) -> list[tuple[int, list[int]]]:
    """(the step's whole time, its record words) for each step the stream carries: the case's
    steps from its first record on, in order; a step without records at a time between its
    neighbours', a few of those left out."""
    from evclust.fixed.layouts import record_fields
    from evclust.vectors.pack import unpack

    fields = record_fields(case.table)
    step_at, t_at = [f[0] for f in fields].index("step"), [f[0] for f in fields].index("t_us")
    by_step: dict[int, list[int]] = {}
    times: dict[int, int] = {}
    for word in case.expected:
        values = unpack(word, fields)
        by_step.setdefault(values[step_at], []).append(word)
        times[values[step_at]] = values[t_at]
    known = sorted(times)
    whole, offset, last = {}, 0, None
    for s in known:  # the records' 32-bit times, unwrapped
        if last is not None and times[s] < last:
            offset += WRAP
        last = times[s]
        whole[s] = times[s] + offset
    rng = random.Random(seed)
    stream = []
    for before, after in zip(known, known[1:] + [None]):
        stream.append((whole[before], by_step[before]))
        if after is None:
            break
        for s in range(before + 1, after):  # steps without a record, spread between their neighbours
            t = whole[before] + (whole[after] - whole[before]) * (s - before) // (after - before)
            if whole[before] < t < whole[after] and rng.random() >= SKIP_STEPS:
                stream.append((t, []))
    return stream


def model_objects(case, stream) -> list[int]:
    """The fixed model's object records for the stream, as the unit's words."""
    from evclust.clusterer.layout import R_STEP
    from evclust.clusterer.run import rows_to_records
    from evclust.fixed.objects import FixedObjects
    from evclust.tracks import OBJECT_DTYPE
    from evclust.vectors.pack import object_words, record_rows

    words = [w for _, records in stream for w in records]
    rows = record_rows(words, case.table)
    rows[:, R_STEP] = [i for i, (_, records) in enumerate(stream) for _ in records]  # the stream's own step numbers
    layer = FixedObjects(case.table, case.params)
    out = layer.feed(rows, np.array([t for t, _ in stream], dtype=np.int64))
    return object_words(rows_to_records(out, OBJECT_DTYPE), case.table)


def configuration_block(table) -> int:
    """The configuration block's bits for the table, from the register map's fields."""
    from evclust.fixed.registers import config_fields

    return sum(field.reset << (32 * field.word) for field in config_fields(table))


if cocotb is not None:

    @cocotb.test()
    async def objects_vectors(dut):
        await checked_vectors(dut, _objects_vectors)

    async def _objects_vectors(dut, config):
        from evclust.fixed.layouts import object_fields
        from evclust.vectors.read import load_case
        from evclust.vectors.scoreboard import first_object_mismatch

        case = load_case(config["case"])
        stream = steps_of(case, config["seed"])
        expected = model_objects(case, stream)
        rng = random.Random(config["seed"])
        gap, stall = config["gap"], config["stall"]

        cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start())
        dut.rst.value, dut.clear.value = 1, 0
        dut.cfg.value = configuration_block(case.table)
        dut.rec_valid.value, dut.rec_data.value, dut.step_valid.value, dut.step_t.value = 0, 0, 0, 0
        dut.out_rec_ready.value, dut.obj_ready.value = 1, 1
        for _ in range(2):
            await RisingEdge(dut.clk)
        dut.rst.value = 0

        passed, objects, tags = [], [], []
        ended = 0
        for index, (t, records) in enumerate(stream):
            pending = [("record", w) for w in records] + [("step", t % WRAP)]
            cycles = 0
            while pending:
                await FallingEdge(dut.clk)
                kind, value = pending[0]
                offer = rng.random() >= gap
                dut.rec_valid.value = int(offer and kind == "record")
                dut.step_valid.value = int(offer and kind == "step")
                if kind == "record":
                    dut.rec_data.value = value
                else:
                    dut.step_t.value = value
                dut.out_rec_ready.value = int(rng.random() >= stall)
                dut.obj_ready.value = int(rng.random() >= stall)
                await RisingEdge(dut.clk)
                # what the handshakes took on this edge (sampled before the next cycle's inputs)
                if int(dut.out_rec_valid.value) and int(dut.out_rec_ready.value):
                    passed.append(int(dut.out_rec_data.value))
                if int(dut.obj_valid.value) and int(dut.obj_ready.value):
                    objects.append(int(dut.obj_data.value))
                    tags.append(ended)  # the steps taken so far: the message names the last
                took = (kind == "record" and offer and int(dut.rec_ready.value)) or (kind == "step" and offer and int(dut.step_ready.value))
                if took:
                    pending.pop(0)
                    ended += kind == "step"
                cycles += 1
                if cycles > MAX_CYCLES_PER_STEP:
                    return f"step {index} (t {t}): not taken after {cycles} cycles (a hang)", len(objects)
        # drain: the last step's object records, then idle
        await FallingEdge(dut.clk)
        dut.rec_valid.value, dut.step_valid.value = 0, 0
        for _ in range(MAX_CYCLES_PER_STEP):
            dut.out_rec_ready.value = int(rng.random() >= stall)
            dut.obj_ready.value = int(rng.random() >= stall)
            await RisingEdge(dut.clk)
            if int(dut.obj_valid.value) and int(dut.obj_ready.value):
                objects.append(int(dut.obj_data.value))
                tags.append(ended)
            await FallingEdge(dut.clk)
            if int(dut.idle.value) and not int(dut.obj_valid.value) and len(objects) >= len(expected):
                break
        else:
            return f"the unit did not go idle within {MAX_CYCLES_PER_STEP} cycles of the last step", len(objects)
        words = [w for _, records in stream for w in records]
        if passed != words:
            at = next((j for j, (a, b) in enumerate(zip(words, passed)) if a != b), min(len(words), len(passed)))
            return f"passed-on records: {len(passed)} of {len(words)}, the first difference at record {at}", len(objects)
        message = first_object_mismatch(case.name, object_fields(case.table), expected, objects, tags, tagged="filter step",
                                        source="the model's records for this stream")  # fmt: skip
        if message is None and len(objects) != len(expected):
            message = f"{case.name}: {len(objects)} object records, the model's {len(expected)}"
        return message, len(objects)


# ------------------------------------------------------------------------------------------
# pytest: build, launch, check.

from pathlib import Path  # noqa: E402

from cosim import LEAF_SIMULATORS, full, run, selected_simulators  # noqa: E402

VECTORS = Path(__file__).resolve().parents[2] / "vectors"
# (share of cycles an input waits, share of cycles an output is not taken)
HANDSHAKES = {"steady": (0.0, 0.0), "bursty": (0.4, 0.3)}
# make test: object births, losses and slot reuse with two object slots under random handshakes
# (the core's co-simulation of the object vectors runs the unit at full rate there); make
# test-full: every case whose object layer confirms an object or saturates, both ways.
QUICK = (("object_birth_death", "bursty"),)
FULL = ("borders", "bursts", "creation_support", "gaps", "object_birth_death", "object_crossing", "object_merge",
        "object_occlusion", "object_split", "object_turn", "object_two_edges", "saturation_counts", "saturation_mcm",
        "timestamp_wrap")  # fmt: skip
RUNS = [(case, handshake) for case in FULL for handshake in HANDSHAKES] if full() else list(QUICK)


@pytest.mark.parametrize("case, handshake", RUNS, ids=[f"{c}-{h}" for c, h in RUNS])
@pytest.mark.parametrize("sim", selected_simulators(LEAF_SIMULATORS))
def test_object_records_are_the_models_on_the_cores_records(sim, case, handshake):
    from evclust.vectors.read import load_case

    loaded = load_case(VECTORS / case)
    gap, stall = HANDSHAKES[handshake]
    config = {"case": str(VECTORS / case), "seed": len(case), "gap": gap, "stall": stall}
    result = run(sim, loaded.header, "objects_vectors", config, toplevel="evclust_objects")
    stream = steps_of(loaded, config["seed"])
    assert result["checked"] == len(model_objects(loaded, stream))
    assert len(stream) > 0.9 * loaded.manifest["counts"]["steps"]  # the steps ran, but a few left out


def test_the_stream_keeps_every_record_and_its_steps_times_increase():
    from evclust.vectors.read import load_case

    case = load_case(VECTORS / "timestamp_wrap")
    stream = steps_of(case, 1)
    assert [w for _, records in stream for w in records] == case.expected
    times = [t for t, _ in stream]
    assert all(a < b for a, b in zip(times, times[1:]))
    assert times[-1] >= WRAP  # the case's clock wraps: the whole times run on past 2^32


def test_the_model_on_the_unchanged_steps_writes_the_cases_object_records():
    """With no step left out and the empty steps at their true times, the stream is the case's own,
    and the model's object records are the committed ones (an independent check of `model_objects`)."""
    from evclust.vectors.read import load_case

    case = load_case(VECTORS / "object_crossing")
    stream = steps_of(case, 1)
    assert len(stream) == case.manifest["counts"]["steps"]  # every step carried a record: no time invented
    assert len(case.objects) > 0
    assert model_objects(case, stream) == case.objects
