"""Sensor effects (SPEC §3): each one is shown to change what its model says it changes, with
expected values derived here from the model, not read back from the code."""

from __future__ import annotations

import json
import math
from collections import defaultdict

import numpy as np
import pytest

from evclust.errors import EvclustError
from evclust.events import EVENT_DTYPE, EventMeta, validate_events
from evclust.scenes import Scene, scene_from_toml
from evclust.simulator import make_simulator
from evclust.simulator.effects import EFFECTS, Effect, SensorGeometry, build_effects

PIPELINE_ORDER = [
    "bayer",
    "lin_log",
    "photoreceptor_lowpass",
    "threshold_mismatch",
    "background_activity",
    "hot_pixels",
    "refractory",
    "tdc_quantisation",
    "tfs_latency",
    "timestamp_quantisation",
    "readout_limit",
]
HOOKS = ("observe", "transfer", "photoreceptor", "thresholds", "interval", "stream")

# BT.601 full range (JPEG, ITU-T T.871), written out here independently of evclust.colour.
KR, KB = 0.299, 0.114
KG = 1.0 - KR - KB


def ycbcr_of(r, g, b):
    y = KR * r + KG * g + KB * b
    return y, 128.0 + 0.5 * (b - y) / (1.0 - KB), 128.0 + 0.5 * (r - y) / (1.0 - KR)


def rgb_of(y, cb, cr):
    r = y + 2.0 * (1.0 - KR) * (cr - 128.0)
    b = y + 2.0 * (1.0 - KB) * (cb - 128.0)
    return r, (y - KR * r - KB * b) / KG, b


def u8(v):
    return int(math.floor(min(max(v, 0.0), 255.0) + 0.5))


# ------------------------------------------------------------------------------------------------
# Scenes and streams for the tests.


def make_scene(
    effects: dict | None = None,
    *,
    width=32,
    height=24,
    fps=1000.0,
    frames=3,
    background=(128, 128, 128),
    objects="",
    seed=0,
) -> Scene:
    """A synthetic scene parsed from TOML, so [effects.NAME] tables take the real path."""
    tables = "".join(
        f"\n[effects.{name}]\n" + "".join(f"{k} = {json.dumps(v)}\n" for k, v in params.items()) for name, params in (effects or {}).items()
    )
    text = f"""
name = "test"
width = {width}
height = {height}
fps = {fps}
frames = {frames}
seed = {seed}

[background]
kind = "uniform"
colour = {json.dumps(list(background))}
{objects}
{tables}
"""
    return scene_from_toml(text, "test scene")


def run_scene(scene: Scene, seed=None, frames=None):
    simulator = make_simulator(scene, seed)
    return simulator.run(scene.source.frames() if frames is None else frames, source="test")


def grey_frames(scene: Scene, *levels):
    g = scene.source
    return [np.full((g.height, g.width, 3), float(v), np.float32) for v in levels]


def moving_object(colour, size=(16, 16), start=(8.0, 24.0), velocity=(2.0, 0.0), frames=40, shape="rectangle"):
    return f"""
[[objects]]
id = 1
label = "obj"
shape = "{shape}"
size = {json.dumps(list(size))}
colour = {json.dumps(list(colour))}
start = {json.dumps(list(start))}
legs = [{{ frames = {frames}, velocity = {json.dumps(list(velocity))} }}]
"""


def make_events(rows) -> np.ndarray:
    """rows: (t, x, y, p, Y, Cb, Cr) tuples."""
    ev = np.zeros(len(rows), EVENT_DTYPE)
    for i, row in enumerate(rows):
        ev[i] = row
    return ev


def assert_sorted(ev: np.ndarray):
    t = ev["t"].astype(np.int64)
    key = ev["y"].astype(np.int64) * 65536 + ev["x"].astype(np.int64)
    assert np.all(np.diff(t) >= 0), "time goes backwards"
    same = np.diff(t) == 0
    assert np.all(np.diff(key)[same] >= 0), "ties in time not ordered by y, then x"


GEOMETRY = SensorGeometry(64, 48, 1000.0)


def effect(name: str, geometry=GEOMETRY, seed=0, **params) -> Effect:
    (e,) = build_effects({name: params}, geometry, seed)
    return e


def per_pixel(ev: np.ndarray) -> dict:
    out = defaultdict(list)
    for t, x, y in zip(ev["t"].tolist(), ev["x"].tolist(), ev["y"].tolist()):
        out[(x, y)].append(t)
    return out


# ------------------------------------------------------------------------------------------------
# The registry: names, order, interface, and "off costs nothing".


def test_registry_lists_every_effect_in_pipeline_order_with_its_one_hook():
    assert list(EFFECTS) == PIPELINE_ORDER
    for name, cls in EFFECTS.items():
        assert cls.name == name
        assert cls.stage in HOOKS
        # The hook of its stage is its own; the others are the base class's (unimplemented).
        for hook in HOOKS:
            own = getattr(cls, hook) is not getattr(Effect, hook)
            assert own == (hook == cls.stage), f"{name}.{hook}"
        doc = (cls.__doc__ or "").strip()
        assert doc and "\n" not in doc, f"{name} needs a one-line class docstring"
        assert cls.Params.model_config.get("extra") == "forbid"
        cls.Params()  # every parameter has a default: [effects.NAME] alone switches it on


def test_an_effect_the_scene_does_not_name_is_never_constructed_or_called(monkeypatch):
    def boom(*args, **kwargs):
        raise AssertionError("an effect that is off was touched")

    for cls in EFFECTS.values():
        monkeypatch.setattr(cls, "__init__", boom)
        for hook in HOOKS:
            monkeypatch.setattr(cls, hook, boom)
    scene = make_scene(objects=moving_object((220, 40, 40), frames=5), frames=5)
    sim = run_scene(scene)
    assert len(sim.events) > 0


def test_a_scene_naming_one_effect_constructs_only_that_one(monkeypatch):
    def boom(*args, **kwargs):
        raise AssertionError("an effect that is off was touched")

    built = []
    real_init = Effect.__init__
    for name, cls in EFFECTS.items():
        if name == "refractory":

            def record(self, *args, **kwargs):
                built.append(self.name)
                real_init(self, *args, **kwargs)

            monkeypatch.setattr(cls, "__init__", record)
            continue
        monkeypatch.setattr(cls, "__init__", boom)
        for hook in HOOKS:
            monkeypatch.setattr(cls, hook, boom)
    scene = make_scene({"refractory": {"period_us": 100.0}}, objects=moving_object((220, 40, 40), frames=5), frames=5)
    sim = run_scene(scene)
    assert built == ["refractory"]
    assert len(sim.events) > 0


@pytest.mark.parametrize(
    "effects, where",
    [
        ({"no_such_effect": {}}, "effects.no_such_effect"),
        ({"refractory": {"period_us": 0}}, "effects.refractory.period_us"),
        ({"refractory": {"period_us": 10, "bogus": 1}}, "effects.refractory.bogus"),
        ({"bayer": {"pattern": "RGBG"}}, "effects.bayer.pattern"),
        ({"threshold_mismatch": {"sigma": 2.0}}, "effects.threshold_mismatch.sigma"),
        ({"background_activity": {"rate_hz": -1}}, "effects.background_activity.rate_hz"),
        ({"background_activity": {"on_fraction": 1.5}}, "effects.background_activity.on_fraction"),
        ({"hot_pixels": {"count": 0}}, "effects.hot_pixels.count"),
        ({"hot_pixels": {"count": 10_000}}, "effects.hot_pixels.count"),  # more than 32x24 pixels
        ({"tdc_quantisation": {"bits": 17}}, "effects.tdc_quantisation.bits"),
        ({"tdc_quantisation": {"k_us": 100, "t_max_us": 50}}, "effects.tdc_quantisation.t_max_us"),
        ({"tfs_latency": {"k_us": 0}}, "effects.tfs_latency.k_us"),
        ({"timestamp_quantisation": {"step_us": 0}}, "effects.timestamp_quantisation.step_us"),
        ({"timestamp_quantisation": {"step_us": 2.5}}, "effects.timestamp_quantisation.step_us"),
        ({"readout_limit": {"timestamp": "never"}}, "effects.readout_limit.timestamp"),
        ({"readout_limit": {"fifo_depth": 0}}, "effects.readout_limit.fifo_depth"),
    ],
)
def test_bad_effect_names_and_parameters_fail_with_one_line_naming_the_effect(effects, where):
    scene = make_scene(effects)  # the scene file accepts any table; the simulator owns effects
    with pytest.raises(EvclustError) as info:
        make_simulator(scene)
    message = str(info.value)
    assert message.startswith(f"test scene: {where}:"), message
    assert "\n" not in message


def test_an_effect_entry_that_is_not_a_table_is_refused():
    with pytest.raises(EvclustError, match=r"^effects\.refractory: expected a table"):
        build_effects({"refractory": 5}, SensorGeometry(8, 8, 1000.0), 0)


# ------------------------------------------------------------------------------------------------
# bayer


@pytest.mark.parametrize("pattern", ["RGGB", "BGGR", "GRBG", "GBRG"])
def test_bayer_samples_the_filter_colour_and_demosaics_a_uniform_frame_back(pattern):
    colour = np.array([200.0, 100.0, 30.0])
    bayer = effect("bayer", SensorGeometry(10, 8, 1000.0), pattern=pattern)
    frame = np.broadcast_to(colour.astype(np.float32), (8, 10, 3)).copy()
    intensity, rgb = bayer.observe(frame)
    assert intensity.shape == (8, 10) and rgb.shape == (8, 10, 3)
    index = {"R": 0, "G": 1, "B": 2}
    for (row, col), letter in zip([(0, 0), (0, 1), (1, 0), (1, 1)], pattern):
        # The 2x2 block repeats over the whole sensor.
        assert np.all(intensity[row::2, col::2] == colour[index[letter]]), (pattern, row, col)
    # Away from the borders a bilinear demosaic of a uniform mosaic is that uniform colour
    # (to the 1/256 of the 16-bit mosaic).
    assert np.abs(rgb[2:-2, 2:-2] - colour).max() <= 1 / 256 + 1e-6


def test_bayer_sees_a_colour_edge_that_a_stacked_sensor_cannot():
    # Same luma as the grey background: 0.299·200 + 0.587·100 + 0.114·B = 128.
    blue = (128 - KR * 200 - KG * 100) / KB
    assert 0 < blue < 255
    obj = moving_object((200.0, 100.0, blue), size=(12, 12), start=(12.0, 24.0), velocity=(2.0, 0.0), frames=8)
    stacked = run_scene(make_scene(width=48, height=48, frames=8, objects=obj))
    assert len(stacked.events) == 0  # the change detector sees Y only, and Y never changes
    mosaic = run_scene(make_scene({"bayer": {}}, width=48, height=48, frames=8, objects=obj))
    ev = mosaic.events
    assert len(ev) > 50
    assert_sorted(ev)
    # Only pixels the object swept change: x in [12-6, 12+2·7+6], y in [24-6, 24+6].
    assert ev["x"].min() >= 5 and ev["x"].max() <= 33
    assert ev["y"].min() >= 17 and ev["y"].max() <= 30
    # Pixels the object reaches after frame 0 (x >= 19) first see it arrive: red-filtered ones
    # (even x, even y for RGGB) brighten, 128 -> 200, and green and blue ones darken (100, 83 < 128).
    first = {}
    for x, y, p in zip(ev["x"].tolist(), ev["y"].tolist(), ev["p"].tolist()):
        first.setdefault((x, y), p)
    arrivals = {(x, y): p for (x, y), p in first.items() if x >= 19}
    red = [p for (x, y), p in arrivals.items() if x % 2 == 0 and y % 2 == 0]
    other = [p for (x, y), p in arrivals.items() if x % 2 == 1 or y % 2 == 1]
    assert red and all(p == 1 for p in red)
    assert other and all(p == -1 for p in other)


# ------------------------------------------------------------------------------------------------
# threshold_mismatch


def test_threshold_mismatch_spreads_thresholds_by_sigma_independently_and_deterministically():
    g = SensorGeometry(200, 200, 1000.0)
    n = g.width * g.height
    on, off = effect("threshold_mismatch", g, seed=3, sigma=0.05).thresholds(0.2, 0.3)
    assert on.shape == (n,) and off.shape == (n,)
    rel_on, rel_off = on / 0.2, off / 0.3
    for rel in (rel_on, rel_off):
        assert abs(rel.mean() - 1.0) < 5 * 0.05 / math.sqrt(n)
        assert abs(rel.std() - 0.05) < 5 * 0.05 / math.sqrt(2 * n)
    assert abs(np.corrcoef(rel_on, rel_off)[0, 1]) < 5 / math.sqrt(n)
    again = effect("threshold_mismatch", g, seed=3, sigma=0.05).thresholds(0.2, 0.3)
    other = effect("threshold_mismatch", g, seed=4, sigma=0.05).thresholds(0.2, 0.3)
    assert np.array_equal(on, again[0]) and np.array_equal(off, again[1])
    assert not np.array_equal(on, other[0])
    floored = effect("threshold_mismatch", g, sigma=1.0, floor=0.5).thresholds(0.2, 0.3)[0]
    assert floored.min() == pytest.approx(0.1)  # θ never below floor·θ_nominal


def test_threshold_mismatch_makes_a_sub_threshold_step_fire_at_the_low_threshold_pixels():
    """A uniform step of log contrast c = 0.95·θ: an ideal sensor is silent; with mismatch σ a pixel
    fires once iff θ_i = θ(1 + σz) <= c, i.e. z <= -0.05/σ; for σ = 0.1 that is Φ(-0.5) = 0.30854."""
    theta, sigma = 0.2, 0.1
    y0 = 100.0
    y1 = (y0 + 1.0) * math.exp(0.95 * theta) - 1.0  # L = ln(Y + 1)
    ideal = make_scene(width=64, height=64, frames=2)
    assert len(run_scene(ideal, frames=grey_frames(ideal, y0, y1)).events) == 0
    scene = make_scene({"threshold_mismatch": {"sigma": sigma}}, width=64, height=64, frames=2)
    ev = run_scene(scene, frames=grey_frames(scene, y0, y1)).events
    n = 64 * 64
    p = 0.5 * math.erfc(0.5 / math.sqrt(2))  # Φ(-0.5)
    assert abs(len(ev) - n * p) < 5 * math.sqrt(n * p * (1 - p))
    assert np.all(ev["p"] == 1)
    assert len(per_pixel(ev)) == len(ev)  # one event per pixel: a second needs θ_i <= c/2 (z <= -5.25)


# ------------------------------------------------------------------------------------------------
# background_activity


def test_background_activity_adds_poisson_noise_with_the_pixel_colour():
    rate, on_fraction = 50.0, 0.3
    bg = (90, 140, 200)
    scene = make_scene({"background_activity": {"rate_hz": rate, "on_fraction": on_fraction}},
                       width=64, height=64, fps=100, frames=21, background=bg)  # fmt: skip
    assert len(run_scene(make_scene(width=64, height=64, fps=100, frames=21, background=bg)).events) == 0
    sim = run_scene(scene, seed=1)
    ev = sim.events
    duration_s = 20 / 100
    expected = rate * 64 * 64 * duration_s  # 40960
    assert abs(len(ev) - expected) < 5 * math.sqrt(expected)
    n = len(ev)
    on = np.count_nonzero(ev["p"] == 1)
    assert abs(on - n * on_fraction) < 5 * math.sqrt(n * on_fraction * (1 - on_fraction))
    assert np.all(np.isin(ev["p"], [-1, 1]))
    # Uniform in time over the run and in space over the sensor.
    assert ev["t"].max() <= duration_s * 1e6
    assert abs(ev["t"].mean() - duration_s * 1e6 / 2) < 5 * duration_s * 1e6 / math.sqrt(12 * n)
    assert abs(ev["x"].mean() - 31.5) < 5 * 64 / math.sqrt(12 * n)
    assert abs(ev["y"].mean() - 31.5) < 5 * 64 / math.sqrt(12 * n)
    # A static scene: every noise event carries the background colour.
    y, cb, cr = (u8(v) for v in ycbcr_of(*bg))
    assert np.all(ev["Y"] == y) and np.all(ev["Cb"] == cb) and np.all(ev["Cr"] == cr)
    assert_sorted(ev)
    validate_events(ev, sim.meta, "background_activity")
    again = run_scene(scene, seed=1).events
    other = run_scene(scene, seed=2).events
    assert np.array_equal(ev, again)
    assert len(other) != len(ev) or not np.array_equal(ev, other)


def test_background_activity_colour_follows_the_pixel_between_frames():
    """Between a black and a white frame the colour is interpolated linearly in time."""
    scene = make_scene({"background_activity": {"rate_hz": 2000.0}}, width=16, height=16, fps=100, frames=2,
                       background=(0, 0, 0))  # fmt: skip
    frames = [np.zeros((16, 16, 3), np.float32), np.full((16, 16, 3), 255.0, np.float32)]
    sim = run_scene(scene, seed=5, frames=frames)
    ev = sim.events
    # Change events are those of the ideal sensor; the rest is noise. Noise Y = 255·t/10000 (±1).
    ideal = run_scene(make_scene(width=16, height=16, fps=100, frames=2), frames=frames).events
    assert len(ev) > len(ideal)
    noise_mask = np.ones(len(ev), bool)
    # Remove the ideal sensor's events (a multiset difference on whole records).
    remaining = defaultdict(int)
    for rec in ideal.tolist():
        remaining[rec] += 1
    for i, rec in enumerate(ev.tolist()):
        if remaining[rec] > 0:
            remaining[rec] -= 1
            noise_mask[i] = False
    assert not any(remaining.values())
    noise = ev[noise_mask]
    assert abs(len(noise) - 2000 * 256 * 0.01) < 5 * math.sqrt(2000 * 256 * 0.01)
    expected_y = 255.0 * noise["t"].astype(float) / 10000.0
    assert np.abs(noise["Y"] - expected_y).max() <= 1.0 + 255 / 10000 / 2
    assert np.all(np.abs(noise["Cb"].astype(int) - 128) <= 1) and np.all(np.abs(noise["Cr"].astype(int) - 128) <= 1)


# ------------------------------------------------------------------------------------------------
# hot_pixels


def test_hot_pixels_fire_only_at_a_fixed_set_of_pixels():
    count, rate = 5, 2000.0
    scene = make_scene({"hot_pixels": {"count": count, "rate_hz": rate}}, width=32, height=32, fps=100, frames=11)
    simulator = make_simulator(scene, seed=7)
    (hot,) = simulator.effects
    sim = simulator.run(scene.source.frames())
    ev = sim.events
    chosen = {(int(i) % 32, int(i) // 32) for i in hot.pixels}
    assert len(chosen) == count
    fired = per_pixel(ev)
    assert set(fired) == chosen  # every hot pixel fires over 0.1 s (P(silent) = e^-200), nothing else
    expected_each = rate * 0.1
    for times in fired.values():
        assert abs(len(times) - expected_each) < 5 * math.sqrt(expected_each)
    assert abs(len(ev) - count * expected_each) < 5 * math.sqrt(count * expected_each)
    assert np.all(ev["p"] == 1)  # default on_fraction = 1
    y, cb, cr = (u8(v) for v in ycbcr_of(128, 128, 128))
    assert np.all(ev["Y"] == y) and np.all(ev["Cb"] == cb) and np.all(ev["Cr"] == cr)
    assert_sorted(ev)
    # The set is drawn from the seed: the same seed gives the same pixels, another seed others.
    same = make_simulator(scene, seed=7).effects[0].pixels
    other = make_simulator(scene, seed=8).effects[0].pixels
    assert np.array_equal(same, hot.pixels) and not np.array_equal(other, hot.pixels)
    assert np.array_equal(make_simulator(scene, seed=7).run(scene.source.frames()).events, ev)


# ------------------------------------------------------------------------------------------------
# refractory


@pytest.mark.parametrize("period_us, kept_times", [(250.0, [286, 571, 857]), (300.0, [286, 857]), (600.0, [286])])
def test_refractory_on_a_step_with_three_crossings_per_pixel(period_us, kept_times):
    """A uniform step of log contrast 3.5θ over a 1000 µs interval: every pixel crosses θ, 2θ, 3θ
    at 1000·j/3.5 µs = 286, 571, 857 µs. The gaps are 285/286 µs between neighbours and 571 µs
    between first and third, so a 250 µs period keeps all three, 300 µs drops only the second
    (571 - 286 < 300 but 857 - 286 >= 300), and 600 µs keeps only the first."""
    y0 = 50.0
    y1 = (y0 + 1.0) * math.exp(3.5 * 0.2) - 1.0
    plain = make_scene(width=8, height=6, frames=2)
    base = per_pixel(run_scene(plain, frames=grey_frames(plain, y0, y1)).events)
    assert len(base) == 48 and all(len(t) == 3 for t in base.values())
    assert all(abs(a - b) <= 1 for times in base.values() for a, b in zip(times, [286, 571, 857]))
    scene = make_scene({"refractory": {"period_us": period_us}}, width=8, height=6, frames=2)
    ev = run_scene(scene, frames=grey_frames(scene, y0, y1)).events
    kept = per_pixel(ev)
    assert len(kept) == 48
    for times in kept.values():
        assert len(times) == len(kept_times)
        assert all(abs(a - b) <= 1 for a, b in zip(times, kept_times))
    assert_sorted(ev)


def test_refractory_keeps_exactly_the_events_a_reference_filter_keeps():
    period = 3000.0
    obj = moving_object((230, 230, 230), size=(20, 20), start=(14.0, 24.0), velocity=(1.5, 0.3), frames=15)
    plain = make_scene(width=64, height=48, fps=100, frames=15, background=(20, 20, 20), objects=obj)
    base = run_scene(plain).events
    scene = make_scene({"refractory": {"period_us": period}}, width=64, height=48, fps=100, frames=15,
                       background=(20, 20, 20), objects=obj)  # fmt: skip
    ev = run_scene(scene).events
    # Reference: walk the stream, keep an event if its pixel's last kept event is >= period ago.
    last, keep = {}, []
    for rec in base.tolist():
        t, x, y = rec[0], rec[1], rec[2]
        if (x, y) in last and t - last[(x, y)] < period:
            continue
        last[(x, y)] = t
        keep.append(rec)
    assert len(ev) < len(base)  # the scene has pixels with several events within 3 ms
    assert ev.tolist() == keep
    for times in per_pixel(ev).values():
        assert min(np.diff(times), default=period) >= period
    assert_sorted(ev)


# ------------------------------------------------------------------------------------------------
# tdc_quantisation (defaults k = 100 µs, t_max = 2550 µs: K = k·255 = 25500 µs·grey)

K, T_MAX = 100.0 * 255.0, 2550.0


def grey_events(levels):
    return make_events([(1000 + i, i % 64, i // 64, 1, v, 128, 128) for i, v in enumerate(levels)])


def expected_tdc_level(intensity, bits, k_us=100.0, t_max_us=T_MAX):
    """The TFS pixel + TDC model restated: t = k·255/I; t >= t_max reads 0; else count
    n = floor(t/step) with step = t_max/(2^bits - 1), read back from the middle of its bin as
    k·255/((n + 1/2)·step), clipped to 255."""
    k = k_us * 255.0
    if intensity <= 0 or k / intensity >= t_max_us:
        return 0.0
    step = t_max_us / (2**bits - 1)
    n = math.floor((k / intensity) / step)
    return min(k / ((n + 0.5) * step), 255.0)


@pytest.mark.parametrize("bits", [1, 3, 5])
def test_tdc_gives_at_most_2_to_the_bits_grey_levels(bits):
    # k and t_max chosen so that no integer grey sits exactly on a bin edge (k·255/I = n·step),
    # where float rounding in the colour conversion could pick either side.
    k_us, t_max_us = 101.3, 2600.7
    ev = grey_events(range(256))
    out = effect("tdc_quantisation", bits=bits, k_us=k_us, t_max_us=t_max_us).stream(ev)
    assert len(np.unique(out["Y"])) <= 2**bits
    expected = [expected_tdc_level(v, bits, k_us, t_max_us) for v in range(256)]
    assert np.abs(out["Y"].astype(float) - expected).max() <= 0.5 + 1e-9
    assert np.all(out["Cb"] == 128) and np.all(out["Cr"] == 128)
    for f in ("t", "x", "y", "p"):
        assert np.array_equal(out[f], ev[f])


def test_tdc_clips_dark_channels_to_zero():
    # Darker than K/t_max = 10 never spikes within t_max: it reads 0. Brighter does not.
    out = effect("tdc_quantisation").stream(grey_events([0, 3, 9, 11, 12]))
    assert out["Y"].tolist()[:3] == [0, 0, 0]
    assert out["Y"][3] > 0 and out["Y"][4] > 0
    # Per channel: a colour whose green is dark loses its green only.
    y, cb, cr = (u8(v) for v in ycbcr_of(200, 4, 120))
    out = effect("tdc_quantisation").stream(make_events([(0, 0, 0, 1, y, cb, cr)]))
    r, g, b = rgb_of(*(float(out[f][0]) for f in ("Y", "Cb", "Cr")))
    assert abs(g) <= 1.5
    assert abs(r - expected_tdc_level(200, 8)) <= 1.5 and abs(b - expected_tdc_level(120, 8)) <= 1.5


def test_tdc_keeps_a_bright_colour_within_one_tdc_step():
    """With step s, a channel of intensity I (t = K/I) reads K/t_q with |t_q - t| <= s/2, so it
    lies in [K/(t + s/2), K/(t - s/2)]; the two uint8 YCbCr roundings add up to about 1.5 grey."""
    colours = [(220, 180, 60), (250, 250, 250), (100, 200, 150), (60, 90, 255)]
    rows = []
    for i, c in enumerate(colours):
        y, cb, cr = (u8(v) for v in ycbcr_of(*c))
        rows.append((i, i, 0, 1, y, cb, cr))
    ev = make_events(rows)
    for bits in (8, 12):
        tdc = effect("tdc_quantisation", bits=bits)
        out = tdc.stream(ev)
        s = T_MAX / (2**bits - 1)
        for i, c in enumerate(colours):
            read = rgb_of(*(float(out[f][i]) for f in ("Y", "Cb", "Cr")))
            sent = rgb_of(*(float(ev[f][i]) for f in ("Y", "Cb", "Cr")))
            for got, true in zip(read, sent):
                t = K / min(max(true, 0.0), 255.0)  # the pixel measures 0..255
                lo, hi = K / (t + s / 2), min(K / (t - s / 2), 255.0)
                assert lo - 1.5 <= got <= hi + 1.5, (bits, c, got, lo, hi)
    assert np.array_equal(effect("tdc_quantisation").stream(ev), effect("tdc_quantisation").stream(ev))
    # 12 bits: a step of 0.62 µs; bright colours come back within 2 grey levels.
    fine = effect("tdc_quantisation", bits=12).stream(ev)
    for f in ("Y", "Cb", "Cr"):
        assert np.abs(fine[f].astype(int) - ev[f].astype(int)).max() <= 2


# ------------------------------------------------------------------------------------------------
# tfs_latency


def test_tfs_latency_stamps_events_at_the_end_of_the_integration():
    ys = [255, 128, 51, 5, 0]
    ev = make_events([(1000, i, 0, 1, y, 128, 128) for i, y in enumerate(ys)])
    out = effect("tfs_latency").stream(ev)
    assert len(out) == len(ev)
    assert_sorted(out)
    shift = {int(r["x"]): int(r["t"]) - 1000 for r in out}
    assert shift[0] == 100  # Y = 255: exactly k_us
    assert abs(shift[1] - K / 128) <= 0.5  # 199.2
    assert abs(shift[2] - K / 51) <= 0.5  # 500
    assert shift[3] == 2550 and shift[4] == 2550  # K/5 = 5100 > t_max: capped
    assert [shift[i] for i in range(5)] == sorted(shift[i] for i in range(5))  # darker is later
    # A shift reorders: a dark event before a bright one ends up after it.
    ev = make_events([(0, 0, 0, 1, 20, 128, 128), (500, 1, 0, 1, 255, 128, 128)])
    out = effect("tfs_latency").stream(ev)
    assert out["x"].tolist() == [1, 0] and out["t"].tolist() == [600, 1275]


def test_tfs_latency_on_a_simulated_stream_moves_every_event_by_its_latency():
    obj = moving_object((220, 60, 40), size=(14, 14), start=(10.0, 20.0), velocity=(2.0, 1.0), frames=10, shape="ellipse")
    kw = dict(width=48, height=40, fps=200, frames=10, background=(30, 30, 30), objects=obj)
    base = run_scene(make_scene(**kw)).events
    ev = run_scene(make_scene({"tfs_latency": {"k_us": 50.0, "t_max_us": 3000.0}}, **kw)).events
    assert len(ev) == len(base) > 100
    assert_sorted(ev)
    latency = np.minimum(50.0 * 255.0 / np.maximum(base["Y"].astype(float), 1e-9), 3000.0)
    expected = sorted(zip(np.floor(base["t"] + latency + 0.5).astype(int).tolist(), base["x"].tolist(), base["y"].tolist()))
    assert sorted(zip(ev["t"].astype(int).tolist(), ev["x"].tolist(), ev["y"].tolist())) == expected


# ------------------------------------------------------------------------------------------------
# timestamp_quantisation


def test_timestamp_quantisation_floors_times_and_reorders_ties():
    ev = make_events([(1001, 3, 5, 1, 9, 9, 9), (1002, 3, 1, -1, 9, 9, 9), (1999, 0, 0, 1, 9, 9, 9), (2000, 7, 7, 1, 9, 9, 9)])
    out = effect("timestamp_quantisation", step_us=1000).stream(ev)
    # Both first events tick at 1000; at equal times y = 1 comes before y = 5.
    assert out["t"].tolist() == [1000, 1000, 1000, 2000]
    assert [(int(r["x"]), int(r["y"])) for r in out] == [(0, 0), (3, 1), (3, 5), (7, 7)]


def test_timestamp_quantisation_on_a_simulated_stream():
    step = 700
    obj = moving_object((230, 200, 40), size=(12, 12), start=(10.0, 16.0), velocity=(1.0, 0.5), frames=10)
    kw = dict(width=40, height=32, fps=500, frames=10, objects=obj)
    base = run_scene(make_scene(**kw)).events
    ev = run_scene(make_scene({"timestamp_quantisation": {"step_us": step}}, **kw)).events
    assert len(ev) == len(base) > 50
    assert np.all(ev["t"] % step == 0)
    assert_sorted(ev)
    assert len(np.unique(ev["t"])) < len(np.unique(base["t"]))
    key = lambda e: sorted(zip((e["t"] // step * step).tolist(), e["y"].tolist(), e["x"].tolist(), e["p"].tolist()))
    assert key(ev) == key(base)


# ------------------------------------------------------------------------------------------------
# readout_limit


def burst(t, n, x0=0):
    return make_events([(t, x0 + i % 64, i // 64, 1, 100, 128, 128) for i in range(n)])


def test_readout_limit_drops_what_a_full_fifo_cannot_hold():
    """Service time s = 1e6/rate = 10 µs, depth D = 16. The FIFO holds every event not yet read out.
    A burst of 100 simultaneous events at t = 1000 into an empty FIFO: the first 16 fill it, the
    other 84 are dropped; they leave at 1000 + 10k, k = 1..16. A second burst of 20 at t = 1050:
    the events leaving at 1010..1050 have gone (5 places free), so 5 more are kept, leaving at
    1170..1210 behind the first 16. Kept: 16 + 5 = 21."""
    ev = np.concatenate([burst(1000, 100), burst(1050, 20)])
    arrival = effect("readout_limit", rate_ev_s=1e5, fifo_depth=16, timestamp="arrival").stream(ev)
    assert len(arrival) == 21
    assert arrival["t"].tolist() == [1000] * 16 + [1050] * 5
    assert arrival[:16]["x"].tolist() == list(range(16))  # first come, first kept, in stream order
    assert arrival[16:]["x"].tolist() == list(range(5))
    readout = effect("readout_limit", rate_ev_s=1e5, fifo_depth=16, timestamp="readout").stream(ev)
    assert readout["t"].tolist() == [1000 + 10 * k for k in range(1, 17)] + [1160 + 10 * k for k in range(1, 6)]
    assert np.all(np.diff(readout["t"].astype(int)) >= 10)
    assert_sorted(readout)
    # A burst no larger than the FIFO loses nothing.
    assert len(effect("readout_limit", rate_ev_s=1e5, fifo_depth=16).stream(burst(0, 16))) == 16
    assert effect("readout_limit").params.timestamp == "arrival"  # the default keeps the pixel time


def test_readout_limit_below_its_rate_only_delays_by_one_service_time():
    rng = np.random.default_rng(0)
    t = np.cumsum(rng.integers(2, 50, 2000))  # arrivals at least 2 µs apart, service 1 µs
    ev = make_events([(int(ti), int(ti) % 64, 0, 1, 100, 128, 128) for ti in t])
    out = effect("readout_limit", rate_ev_s=1e6, fifo_depth=1, timestamp="readout").stream(ev)
    assert len(out) == len(ev)
    assert np.array_equal(out["t"], ev["t"] + 1)


def test_readout_limit_on_a_simulated_stream():
    obj = moving_object((240, 240, 240), size=(16, 16), start=(12.0, 16.0), velocity=(2.0, 0.0), frames=8)
    kw = dict(width=48, height=32, fps=1000, frames=8, background=(10, 10, 10), objects=obj)
    base = run_scene(make_scene(**kw)).events
    rate, depth = 2e5, 32  # 5 µs per event, below the bursts of this scene
    ev = run_scene(make_scene({"readout_limit": {"rate_ev_s": rate, "fifo_depth": depth, "timestamp": "readout"}}, **kw)).events
    assert 0 < len(ev) < len(base)
    assert_sorted(ev)
    assert np.all(np.diff(ev["t"].astype(int)) >= 5)  # one event per 5 µs at most
    # Every kept event leaves after it arrived: its departure is at least one service time later.
    arrivals = run_scene(make_scene({"readout_limit": {"rate_ev_s": rate, "fifo_depth": depth, "timestamp": "arrival"}}, **kw)).events
    assert len(arrivals) == len(ev)
    assert np.all(ev["t"] >= arrivals["t"] + 5)
    assert np.array_equal(ev[["x", "y", "p"]], arrivals[["x", "y", "p"]])


# ------------------------------------------------------------------------------------------------
# All together


def test_all_effects_together_give_a_valid_deterministic_stream():
    obj = moving_object((210, 40, 40), size=(14, 14), start=(10.0, 20.0), velocity=(2.0, 0.5), frames=12, shape="ellipse")
    effects = {name: {} for name in EFFECTS}
    effects["background_activity"] = {"rate_hz": 20.0}
    effects["timestamp_quantisation"] = {"step_us": 10}
    scene = make_scene(effects, width=48, height=40, fps=100, frames=12, objects=obj)
    sim = run_scene(scene, seed=3)
    assert [e.name for e in make_simulator(scene, 3).effects] == PIPELINE_ORDER
    assert len(sim.events) > 0
    validate_events(sim.events, EventMeta(48, 40), "all effects")
    assert np.all(sim.events["t"] % 10 == 0)
    assert np.array_equal(run_scene(scene, seed=3).events, sim.events)


@pytest.mark.parametrize("name", list(EFFECTS))
def test_each_effect_alone_is_deterministic_under_a_seed(name):
    # A busy scene (a moving object) so that every effect has events to act on.
    scene = make_scene({name: {}}, width=48, height=36, fps=100.0, frames=12, objects=moving_object((240, 240, 240), frames=12))
    first = run_scene(scene, seed=11).events
    assert first.size > 0
    assert np.array_equal(run_scene(scene, seed=11).events, first)
