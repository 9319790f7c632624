"""The photoreceptor effects: lin-log and the intensity-dependent low-pass, each against a
hand-computed count of threshold crossings on uniform grey frames (every pixel alike)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from evclust.errors import EvclustError
from evclust.scenes import SensorSpec
from evclust.simulator import SensorGeometry, Simulator, build_effects

W, H, FPS = 8, 6, 100.0
T_FRAME = 1e6 / FPS
THETA = 0.2
EPS = 1.0  # SensorSpec's log_eps


def grey(values):
    """Uniform frames of the given grey levels (R = G = B, so luma is the value itself)."""
    return [np.full((H, W, 3), float(v), np.float32) for v in values]


def run(values, effects=None, detector="log"):
    geometry = SensorGeometry(W, H, T_FRAME)
    sensor = SensorSpec(detector=detector, threshold_on=THETA, threshold_off=THETA)
    simulator = Simulator(sensor, geometry, build_effects(effects or {}, geometry, seed=0))
    return simulator.run(grey(values)).events


def on_per_pixel(events):
    assert np.all(events["p"] == 1)
    return events.size / (W * H)


def crossings(level0, level1):
    """ON events a pixel fires when its L rises from level0 to level1 (reference at level0)."""
    return math.floor((level1 - level0) / THETA + 1e-9)


def test_lin_log_is_linear_below_the_cutoff():
    # 2 -> 18 grey levels, both under the 20 DN cutoff: L rises by 16·ln(21)/20 = 2.436, 12 events;
    # the log detector sees ln(19/3) = 1.846, 9 events.
    slope = math.log(20 + EPS) / 20
    assert on_per_pixel(run([2, 18], {"lin_log": {}})) == crossings(2 * slope, 18 * slope) == 12
    assert on_per_pixel(run([2, 18])) == crossings(math.log(2 + EPS), math.log(18 + EPS)) == 9


def test_lin_log_is_the_log_detector_above_the_cutoff():
    values = [30, 60, 90, 200, 120]
    a, b = run(values, {"lin_log": {}}), run(values)
    assert a.size > 0 and np.array_equal(a, b)


def test_lin_log_is_continuous_at_the_cutoff():
    # 19.999 -> 20.001 crosses the cutoff: L hardly moves, so no event (a jump would fire).
    assert run([19.999, 20.001, 19.999], {"lin_log": {}}).size == 0


def test_lin_log_needs_the_log_detector():
    with pytest.raises(EvclustError, match='effects.lin_log: .*sensor.detector = "log"'):
        run([10, 20], {"lin_log": {}}, detector="linear")


def filtered_levels(values, cutoff_hz):
    """L after v2e's low-pass, computed here by the recurrence with each sample's intensity."""
    out, lp = [], math.log(values[0] + EPS)
    for v in values[1:]:
        eps = min(1.0, (v + 20.0) / 275.0 * (T_FRAME * 1e-6) * 2 * math.pi * cutoff_hz)
        lp += eps * (math.log(v + EPS) - lp)
        out.append(lp)
    return out


@pytest.mark.parametrize("bright", [False, True])
def test_lowpass_spreads_a_step_over_frames_as_the_exponential_says(bright):
    low, high = (10, 40) if not bright else (100, 250)
    values = [low] + [high] * 30
    events = run(values, {"photoreceptor_lowpass": {"cutoff_hz": 5.0}})
    frame = np.floor(events["t"] / T_FRAME).astype(int)
    got = np.bincount(frame, minlength=len(values) - 1)[: len(values) - 1]
    levels = filtered_levels(values, 5.0)
    base = math.log(low + EPS)
    want = np.diff([0] + [crossings(base, level) for level in levels])
    assert np.array_equal(got, want * W * H)
    # Given time, all of the step's events come, as without the filter.
    assert run([low] + [high] * 300, {"photoreceptor_lowpass": {"cutoff_hz": 5.0}}).size == run([low, high]).size


def test_a_bright_pixel_follows_faster_than_a_dark_one():
    def frames_to_half(low, high):
        levels = filtered_levels([low] + [high] * 60, 5.0)
        half = (math.log(low + EPS) + math.log(high + EPS)) / 2
        return next(i for i, level in enumerate(levels) if level >= half) + 1

    dark, bright = frames_to_half(10, 40), frames_to_half(100, 250)
    assert bright < dark

    # The same check on the simulator's events: the frame of the median event.
    def median_frame(low, high):
        ev = run([low] + [high] * 60, {"photoreceptor_lowpass": {"cutoff_hz": 5.0}})
        return np.median(np.floor(ev["t"] / T_FRAME))

    assert median_frame(100, 250) < median_frame(10, 40)


def test_lowpass_passes_a_constant_scene_and_a_cutoff_above_the_sampling_changes_nothing():
    assert run([80] * 10, {"photoreceptor_lowpass": {}}).size == 0
    values = [30, 80, 50, 200, 10]
    assert np.array_equal(run(values, {"photoreceptor_lowpass": {"cutoff_hz": 1e6}}), run(values))
    # Textured frames: at 1 kHz every pixel's ε is 1 at 100 fps, so L must pass bit for bit.
    rng = np.random.default_rng(5)
    frames = [rng.uniform(0, 255, (H, W, 1)).repeat(3, axis=2).astype(np.float32) for _ in range(12)]
    geometry = SensorGeometry(W, H, T_FRAME)
    sensor = SensorSpec(threshold_on=THETA, threshold_off=THETA)
    plain = Simulator(sensor, geometry).run(frames).events
    filtered = Simulator(sensor, geometry, build_effects({"photoreceptor_lowpass": {"cutoff_hz": 1000.0}}, geometry, 0)).run(frames).events
    assert plain.size > 100 and np.array_equal(filtered, plain)


@pytest.mark.parametrize(
    "effects, fragment",
    [
        ({"lin_log": {"cutoff": 0}}, "effects.lin_log.cutoff"),
        ({"lin_log": {"cutof": 20}}, "effects.lin_log.cutof"),
        ({"photoreceptor_lowpass": {"cutoff_hz": -1}}, "effects.photoreceptor_lowpass.cutoff_hz"),
    ],
)
def test_bad_parameters_fail_with_one_line(effects, fragment):
    with pytest.raises(EvclustError) as err:
        run([10, 20], effects)
    assert fragment in str(err.value) and "\n" not in str(err.value)
