"""The change detector against closed-form answers (SPEC §3).

Pixel x covers [x - 0.5, x + 0.5]. An edge moving at v px/frame covers a pixel linearly in time,
so a linear detector sees Y(t) linear in t and the crossing times are exact; a log detector sees
L interpolated linearly between frames, as the model defines it.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from evclust.colour import rgb_to_ycbcr
from evclust.events import validate_events
from evclust.scenes import SensorSpec
from evclust.simulator import SensorGeometry, Simulator, make_simulator
from evclust.simulator.kernel import EventBuffer

from evclust.scenes import scene_from_toml

from testkit import pixel_events, simulate_toml

FPS = 100
T_US = 1e6 / FPS


def edge_scene(velocity: float, detector: str, th_on: float, th_off: float, frames: int, bg=50, obj=200, width=40, substeps=1):
    """A wide grey rectangle whose right edge sits on the boundary x = 2.5 at frame 0."""
    right = 2.5
    return f"""
width = 16
height = 8
fps = {FPS}
frames = {frames}
substeps = {substeps}
[sensor]
detector = "{detector}"
threshold_on = {th_on}
threshold_off = {th_off}
[background]
colour = [{bg}, {bg}, {bg}]
[[objects]]
id = 1
label = "grey"
size = [{width}, 20]
colour = [{obj}, {obj}, {obj}]
start = [{right - width / 2}, 3.5]
legs = [{{ frames = {frames - 1}, velocity = [{velocity}, 0.0] }}]
"""


def test_linear_detector_edge_at_quarter_pixel_per_frame_fires_at_exact_times():
    # Y of pixel 3 rises linearly from 50 to 200 over the 4 frames the edge takes to cross it.
    bg, obj, theta, v = 50, 200, 20.0, 0.25
    ev = simulate_toml(edge_scene(v, "linear", theta, theta, frames=24, bg=bg, obj=obj)).events
    crossing_us = T_US / v  # time for the edge to sweep one pixel
    n_expected = math.floor((obj - bg) / theta)  # 7 levels: 70, 90, ..., 190
    for x in (3, 4, 5):
        got = pixel_events(ev, x, 4)
        assert got.size == n_expected
        assert np.all(got["p"] == 1)
        start = (x - 3) * crossing_us  # the edge reaches pixel x at this time
        expected = start + crossing_us * theta * np.arange(1, n_expected + 1) / (obj - bg)
        assert np.max(np.abs(got["t"].astype(float) - expected)) <= 1.0
        # Each event carries the grey level it crossed: Y = bg + k·θ, neutral chroma.
        assert np.max(np.abs(got["Y"].astype(float) - (bg + theta * np.arange(1, n_expected + 1)))) <= 1.0
        assert np.all(np.abs(got["Cb"].astype(int) - 128) <= 1) and np.all(np.abs(got["Cr"].astype(int) - 128) <= 1)


def test_log_detector_edge_at_one_pixel_per_frame_gives_several_events_in_one_interval():
    bg, obj, theta = 50, 200, 0.2
    ev = simulate_toml(edge_scene(1.0, "log", theta, theta, frames=10, bg=bg, obj=obj)).events
    span = math.log(obj + 1.0) - math.log(bg + 1.0)  # log_eps = 1
    n_expected = math.floor(span / theta)  # 6 crossings of 0.2 in ln(201/51) = 1.37
    for x in (3, 6):
        got = pixel_events(ev, x, 2)
        assert got.size == n_expected
        frame0 = (x - 3) * T_US  # the edge crosses pixel x between frames x-3 and x-2
        expected = frame0 + T_US * theta * np.arange(1, n_expected + 1) / span
        assert np.max(np.abs(got["t"].astype(float) - expected)) <= 1.0
        assert np.all(got["t"] < frame0 + T_US)  # all within the one frame interval


@pytest.mark.parametrize("th_on, th_off", [(0.15, 0.4), (0.4, 0.15)])
def test_asymmetric_thresholds_give_the_expected_on_and_off_counts(th_on, th_off):
    # A 4 px bright square passes over the pixel at 1 px/frame: L rises by span, holds, falls back.
    bg, obj = 50, 200
    ev = simulate_toml(edge_scene(1.0, "log", th_on, th_off, frames=12, bg=bg, obj=obj, width=4)).events
    span = math.log(obj + 1.0) - math.log(bg + 1.0)
    n_on = math.floor(span / th_on)
    # After the ON events the reference sits n_on·θ_on above the background level.
    n_off = math.floor(n_on * th_on / th_off)
    for x in (4, 8):
        got = pixel_events(ev, x, 5)
        assert int(np.sum(got["p"] == 1)) == n_on
        assert int(np.sum(got["p"] == -1)) == n_off
        assert np.all(np.diff(got["t"].astype(np.int64)) >= 0)


def test_static_textured_scene_gives_no_events():
    text = """
width = 64
height = 48
fps = 30
frames = 20
[background]
kind = "texture"
colour = [120, 110, 100]
contrast = 30
scale = 1.5
[[objects]]
id = 1
label = "parked"
size = [10, 12]
colour = [200, 30, 30]
start = [20.3, 20.7]
legs = [{ frames = 19, velocity = [0.0, 0.0] }]
"""
    assert simulate_toml(text).events.size == 0


def test_events_carry_the_interpolated_colour_of_a_uniform_object_within_one_lsb():
    # The whole view is one uniform surface whose colour ramps linearly from A to B over 4
    # frames; the pixels see the same colour at every instant, so each event's YCbCr must be
    # the ramp's colour at that event's time.
    a, b = np.array([40.0, 80.0, 160.0]), np.array([200.0, 120.0, 60.0])
    n_frames, width, height = 5, 6, 4
    frames = [np.broadcast_to(a + (b - a) * k / (n_frames - 1), (height, width, 3)).astype(np.float32) for k in range(n_frames)]
    sim = Simulator(SensorSpec(threshold_on=0.05, threshold_off=0.05), SensorGeometry(width, height, T_US))
    ev = sim.run(frames).events
    expected_count = math.floor((math.log(rgb_to_ycbcr(b)[0] + 1) - math.log(rgb_to_ycbcr(a)[0] + 1)) / 0.05)
    assert ev.size == expected_count * width * height
    fraction = ev["t"].astype(float) / ((n_frames - 1) * T_US)
    expected = rgb_to_ycbcr(a + np.outer(fraction, b - a))
    got = np.stack([ev["Y"], ev["Cb"], ev["Cr"]], axis=1).astype(float)
    assert np.max(np.abs(got - expected)) <= 1.0


def test_busy_scene_is_sorted_deterministic_and_inside_the_sensor():
    first = simulate_toml(edge_scene(1.7, "log", 0.1, 0.1, frames=12))
    second = simulate_toml(edge_scene(1.7, "log", 0.1, 0.1, frames=12))
    validate_events(first.events, first.meta, "first")
    assert first.events.size > 100
    assert np.array_equal(first.events, second.events)


def test_metadata_carries_sensor_size_source_and_frame_period():
    sim = simulate_toml(edge_scene(1.0, "log", 0.2, 0.2, frames=4))
    assert (sim.meta.width, sim.meta.height) == (16, 8)
    assert sim.meta.t_frame_us == pytest.approx(T_US)
    assert sim.frames == 4


def test_substeps_put_a_fast_edge_at_the_right_time():
    # At 4 px/frame the edge sweeps pixel x in the quarter frame starting at (x-3)·T/4, where a
    # linear detector sees Y rise linearly. With 4 sub-steps per frame the sensor samples every
    # quarter frame, so its interpolation is exact; sampling whole frames spreads the same rise
    # over the full frame.
    bg, obj, theta, v = 50, 200, 20.0, 4.0
    n_expected = math.floor((obj - bg) / theta)
    sweep_us = T_US / v
    errors = {}
    for substeps in (1, 4):
        sim = simulate_toml(edge_scene(v, "linear", theta, theta, frames=4, bg=bg, obj=obj, substeps=substeps))
        assert sim.frames == 4 and sim.meta.t_frame_us == pytest.approx(T_US)
        got = pixel_events(sim.events, 5, 4)
        assert got.size == n_expected
        expected = 2 * sweep_us + sweep_us * theta * np.arange(1, n_expected + 1) / (obj - bg)
        errors[substeps] = np.max(np.abs(got["t"].astype(float) - expected))
    assert errors[4] <= 1.0
    assert errors[1] > sweep_us  # whole-frame sampling is off by more than the sweep itself


@pytest.mark.parametrize("capacity", [1, 7, 64])
def test_a_small_event_buffer_gives_the_same_stream(capacity):
    # Intervals overflow the buffer (and at capacity 1 a single pixel does): the detector must
    # resume where it stopped and the pieces must join in (t, y, x) order.
    scene = scene_from_toml(edge_scene(1.7, "log", 0.1, 0.1, frames=8))
    reference = make_simulator(scene).run(scene.source.frames()).events
    small = make_simulator(scene)
    small.buffer = EventBuffer(capacity)
    assert np.array_equal(small.run(scene.source.frames()).events, reference)


@pytest.mark.parametrize("threads", [2, 3, 7])
@pytest.mark.parametrize("scene_name", ["traffic", "pedestrian"])
def test_bands_on_several_threads_give_the_same_stream(scene_name, threads):
    # Each band of rows is detected apart and the bands merged: the stream must not change.
    from evclust.scenes import load_scene
    from evclust.simulator import Simulator

    scene = load_scene(scene_name, max_frames=40)
    reference = make_simulator(scene).run(scene.source.frames())
    one = Simulator(scene.spec.sensor, make_simulator(scene).geometry, threads=1)
    many = Simulator(scene.spec.sensor, make_simulator(scene).geometry, threads=threads)
    assert len(many.bands) == min(threads, one.geometry.width * one.geometry.height // (1 << 15)) and len(one.bands) == 1
    events_one = one.run(scene.source.frames()).events
    assert events_one.size > 1000 and np.array_equal(events_one, reference.events)
    assert np.array_equal(many.run(scene.source.frames()).events, events_one)


def test_a_run_spread_over_many_arena_blocks_gives_the_same_stream(monkeypatch):
    # Blocks of 50 events: intervals land in new blocks, and the run's end joins them.
    from evclust.simulator import pipeline

    scene = scene_from_toml(edge_scene(1.7, "log", 0.1, 0.1, frames=8))
    reference = make_simulator(scene).run(scene.source.frames()).events
    assert reference.size > 3 * 50
    monkeypatch.setattr(pipeline._EventArena, "BLOCK_EVENTS", 50)
    assert np.array_equal(make_simulator(scene).run(scene.source.frames()).events, reference)


@pytest.mark.skipif(not Path("/proc/self/smaps").exists(), reason="the page flags are read from Linux's /proc")
def test_the_event_arena_is_mapped_without_huge_pages():
    # The arena's block is its own mapping, and the kernel was never asked for huge pages in it
    # (VmFlags "hg" is MADV_HUGEPAGE; numpy's own arrays over 4 MB carry it).
    from evclust.simulator.pipeline import _EventArena

    def flags_of(address: int) -> list[str]:
        inside = False
        for line in Path("/proc/self/smaps").read_text().splitlines():
            head = line.split()[0]
            if "-" in head and ":" not in head:
                lo, hi = (int(v, 16) for v in head.split("-"))
                inside = lo <= address < hi
            elif inside and head == "VmFlags:":
                return line.split()[1:]
        raise AssertionError("address not mapped")

    events = _EventArena().take(1 << 20)
    events["t"] = 1  # touched
    assert "hg" not in flags_of(events[1 << 19 :].ctypes.data)
    numpy_array = np.empty(1 << 24, np.uint8)  # numpy leaves its first page out of the advice
    assert "hg" in flags_of(numpy_array[1 << 23 :].ctypes.data) or not np._core.multiarray._get_madvise_hugepage()


@pytest.mark.parametrize("seed", range(5))
def test_joining_two_intervals_orders_the_boundary_microsecond_by_row_then_column(seed):
    # Two intervals each in (t, y, x) order, sharing the boundary's microsecond in random rows and
    # columns: after the join their union is in (t, y, x) order, the records the same, and records
    # of one pixel keep their interval order (previous first).
    from evclust.events.format import EVENT_DTYPE
    from evclust.simulator.pipeline import _join_at_boundary

    rng = np.random.default_rng(seed)

    def interval(times):
        e = np.zeros(len(times), EVENT_DTYPE)
        e["t"], e["x"], e["y"] = times, rng.integers(0, 4, len(times)), rng.integers(0, 3, len(times))
        e["p"] = rng.choice([-1, 1], len(times))
        return e[np.lexsort((e["x"], e["y"], e["t"]))]

    previous = interval(np.r_[rng.integers(0, 100, 30), np.full(rng.integers(1, 12), 100)])
    current = interval(np.r_[np.full(rng.integers(1, 12), 100), rng.integers(101, 200, 30)])
    previous["Y"], current["Y"] = 1, 2  # which interval a record came from
    before = np.concatenate([previous, current])
    _join_at_boundary(previous, current)
    after = np.concatenate([previous, current])
    assert np.array_equal(np.sort(after), np.sort(before))
    assert np.array_equal(after, before[np.lexsort((before["x"], before["y"], before["t"]))])  # lexsort is stable
