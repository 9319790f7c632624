"""The filter step's sweep beside the events (ClustererParams.sweep_slots_per_event = R): a step
does not stop the events; its sweep runs on, R slots before each event after the step's, each
event and each swept slot seeing the table as it then is. Checked for what follows from the rule:
a sweep that finishes before the next event is the step between two events, its schedule is one
group of R slots an event, a step coming while a sweep is open finishes it first, a stream cut
into pieces gives what it gives whole, and the fixed model follows the float model."""

from __future__ import annotations

import math

import numpy as np
import pytest

from evclust.clusterer import ClustererParams
from evclust.clusterer.layout import R_STEP, SWEEP_FORCED, SWEEP_LEFT
from evclust.clusterer.run import FloatClusterer
from evclust.errors import EvclustError
from evclust.fixed.model import FixedClusterer
from evclust.rtl.sources import params_header

from testkit import simulate_toml

# Two squares crossing on a textured background, then a third: creations, merges, expiries.
SCENE = """
width = 160
height = 96
fps = 50
frames = 30
seed = 3
[background]
kind = "texture"
colour = [80, 90, 100]
contrast = 8
scale = 3
[[objects]]
id = 1
label = "red"
size = [16, 12]
colour = [210, 40, 40]
start = [10.0, 30.0]
legs = [{ frames = 30, velocity = [4.0, 0.5] }]
[[objects]]
id = 2
label = "blue"
size = [12, 12]
colour = [40, 60, 220]
start = [140.0, 70.0]
legs = [{ frames = 30, velocity = [-3.0, -1.0] }]
[[objects]]
id = 3
label = "white"
size = [8, 16]
colour = [235, 235, 230]
start = [80.0, 100.0]
start_frame = 8
legs = [{ frames = 22, velocity = [0.0, -4.0] }]
"""


@pytest.fixture(scope="module")
def scene():
    sim = simulate_toml(SCENE)
    assert sim.events.size > 5_000
    return sim.events, sim.meta


def run(model, events, meta, pieces=1, **update):
    c = model(ClustererParams(**update), meta.width, meta.height, meta.t_frame_us)
    rows = [c.feed(part) for part in np.array_split(events, pieces)]
    return c, np.concatenate(rows)


@pytest.mark.parametrize("model", [FloatClusterer, FixedClusterer])
def test_a_sweep_that_ends_before_the_next_event_is_the_step_between_two_events(scene, model):
    """With nothing in flight (D = 0) and the paper's activity, R >= N sweeps every slot before the
    event after the step's, as the step between two events does: the same records, bit for bit."""
    events, meta = scene
    _, between = run(model, events, meta)
    c, beside = run(model, events, meta, sweep_slots_per_event=16)
    assert len(between) > 100 and np.array_equal(between, beside)
    assert c.globals[SWEEP_FORCED] == 0


def test_against_a_reference_time_the_steps_decay_read_not_stored_is_the_same_activity(scene):
    """With the activity against a reference time the reference stays at the steps and the sweep
    reads A = Ã·2^-((t - t_ref)/T_half): in exact arithmetic the activity the step's move gives."""
    events, meta = scene
    _, moved = run(FloatClusterer, events, meta, activity_reference=True)
    _, read = run(FloatClusterer, events, meta, activity_reference=True, sweep_slots_per_event=16)
    assert moved.shape == read.shape and len(moved) > 100
    assert np.allclose(moved, read, rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("model", [FloatClusterer, FixedClusterer])
@pytest.mark.parametrize("slots", [1, 3])
def test_the_sweep_takes_one_group_of_slots_an_event_and_the_step_closes_with_its_last(scene, model, slots):
    events, meta = scene
    every, n = 64, 16
    c = model(ClustererParams(sweep_slots_per_event=slots, filter_every=every), meta.width, meta.height, meta.t_frame_us)
    c.feed(events[:every])  # the step's event: the sweep opens, nothing swept yet
    assert c.globals[SWEEP_LEFT] == n and c.steps.size == 0
    groups = math.ceil(n / slots)
    for k in range(1, groups):
        c.feed(events[every + k - 1 : every + k])
        assert c.globals[SWEEP_LEFT] == n - k * slots and c.steps.size == 0
    rows = c.feed(events[every + groups - 1 : every + groups])  # the last group: the step closes
    assert c.globals[SWEEP_LEFT] == 0 and c.steps.size == 1 and c.steps[0] == events["t"][every - 1]
    assert np.all(rows[:, R_STEP] == 0)


@pytest.mark.parametrize("model", [FloatClusterer, FixedClusterer])
def test_a_step_that_comes_while_a_sweep_is_open_finishes_it_first(scene, model):
    """16 slots at one an event take 16 events; with a step every 10 each sweep is cut short."""
    events, meta = scene
    c, rows = run(model, events, meta, sweep_slots_per_event=1, filter_every=10)
    steps = events.size // 10
    assert c.globals[SWEEP_FORCED] == steps - 1  # every step but the first found one open
    assert c.stats()["steps"] == steps - 1  # the last is still open
    assert np.all(np.diff(rows[:, R_STEP]) >= 0)  # records in step order


@pytest.mark.parametrize("model", [FloatClusterer, FixedClusterer])
@pytest.mark.parametrize("update", [{}, {"update_delay": 2, "activity_reference": True}, {"update_delay": 3}], ids=["D0", "D2-ref", "D3"])
def test_a_stream_cut_into_pieces_gives_what_it_gives_whole(scene, model, update):
    events, meta = scene
    c, whole = run(model, events, meta, sweep_slots_per_event=1, **update)
    c7, pieces = run(model, events, meta, pieces=7, sweep_slots_per_event=1, **update)
    assert len(whole) > 100 and np.array_equal(whole, pieces)
    assert np.array_equal(c.steps, c7.steps) or c7.steps.size <= c.steps.size  # (steps: the last feed's)
    assert c.stats() == c7.stats()


@pytest.mark.parametrize("update", [{}, {"update_delay": 2, "activity_reference": True}, {"update_delay": 2}], ids=["D0", "D2-ref", "D2"])
def test_the_fixed_model_follows_the_float_model_beside_the_events(scene, update):
    """The fixed model's roundings aside, the same semantics: as many steps and about as many
    records, at about the same places. (With the paper's activity and updates in flight, a commit
    that finds a slot swept after its event must not decay it back: a wrapping time difference
    would empty it, and the fixed model would report a fraction of the float model's records.)"""
    events, meta = scene
    cf, f = run(FloatClusterer, events, meta, sweep_slots_per_event=1, **update)
    cx, x = run(FixedClusterer, events, meta, sweep_slots_per_event=1, **update)
    assert cf.stats()["steps"] == cx.stats()["steps"]
    assert abs(len(x) - len(f)) <= 0.03 * len(f), (len(f), len(x))
    # the records of each step close to the float model's: mean centre within a pixel
    for step in np.intersect1d(f[:, R_STEP], x[:, R_STEP])[::25]:
        a, b = f[f[:, R_STEP] == step], x[x[:, R_STEP] == step]
        assert abs(a[:, 4].mean() - b[:, 4].mean()) < 1.0 and abs(a[:, 5].mean() - b[:, 5].mean()) < 1.0


def test_the_rtl_refuses_the_sweep_beside_the_events_in_one_line():
    with pytest.raises(EvclustError, match="sweep_slots_per_event = 1") as info:
        params_header(ClustererParams(sweep_slots_per_event=1), 64, 48, 10_000.0)
    assert "\n" not in str(info.value)
