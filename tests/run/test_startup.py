"""A run makes its compiled loops ready before the event loop's clock starts (evclust.run.track:
an empty feed), and reports that time apart (issue 26: honest speed on short files)."""

from __future__ import annotations

import numpy as np
import pytest

from evclust.clusterer import ClustererParams, float_model
from evclust.events import EVENT_DTYPE, EventMeta
from evclust.events.format import LOOP_FIELDS, loop_columns
from evclust.fixed import fixed_model
from evclust.jit import compiled_code
from evclust.run import track_events
from evclust.run.track import MODELS, _object_layer
from evclust.warm import sample_stream

from testkit import classic_params, simulate_toml, square_scene

META = EventMeta(width=64, height=48, t_frame_us=33333.0, source="unit", has_colour=True)


def _state(model, layer) -> list[np.ndarray]:
    arrays = [v for v in vars(model).values() if isinstance(v, np.ndarray)]
    arrays += [v for v in vars(layer).values() if isinstance(v, np.ndarray)] if layer is not None else []
    return [a.copy() for a in arrays]


@pytest.mark.parametrize("model", ["float", "fixed"])
def test_an_empty_feed_changes_no_state(model):
    params = ClustererParams(t_frame_us=33333.0).resolved(33333.0)
    clusterer = MODELS[model](params, META.width, META.height, 33333.0, True)
    layer = _object_layer(clusterer, params, model, META.width, META.height, 33333.0)
    before = _state(clusterer, layer)
    rows = clusterer.feed(np.zeros(0, EVENT_DTYPE))
    assert rows.shape[0] == 0 and clusterer.steps.size == 0
    if layer is not None:
        assert layer.feed(rows, clusterer.steps).shape[0] == 0
    after = _state(clusterer, layer)
    assert len(before) == len(after) > 3
    assert all(np.array_equal(a, b) for a, b in zip(before, after))


@pytest.mark.parametrize("model", ["float", "fixed"])
def test_the_run_reports_its_start_up_apart_and_the_loop_compiles_nothing(model):
    sim = simulate_toml(square_scene([(12, (2.0, 1.0))]))
    run = track_events(sim.events, sim.meta, classic_params(), model)
    assert run.startup is not None and run.startup.seconds >= 0
    assert "compiled code ready in" in run.summary() and "event loop" in run.summary()
    # Everything the event loop needs was made in the start-up: a second run loads or compiles nothing new.
    counts = compiled_code()
    track_events(sim.events, sim.meta, classic_params(), model)
    assert compiled_code() == counts


def test_a_stream_without_frame_period_is_tracked_at_the_frameless_period():
    """At 25 fps the frameless period is the scene's own: withholding it changes nothing. At 100
    fps the time constants are 4 times longer, and the velocities, converted back to px per frame
    of the scene, are the frameless run's times 10,000/40,000."""
    import dataclasses

    from evclust.choices import FRAMELESS_PERIOD_US
    from evclust.run.track import at_frame_period

    sim = simulate_toml(square_scene([(30, (2.0, 1.0))]))  # 100 fps
    native = track_events(sim.events, sim.meta, classic_params())
    bare = dataclasses.replace(sim.meta, t_frame_us=None)
    withheld = track_events(sim.events, bare, classic_params())
    assert withheld.meta.t_frame_us == FRAMELESS_PERIOD_US and native.meta.t_frame_us == 10_000.0
    assert native.tracks.size != withheld.tracks.size or not np.array_equal(native.tracks, withheld.tracks)
    as_scene = at_frame_period(withheld, sim.meta.t_frame_us)
    assert as_scene.meta.t_frame_us == 10_000.0
    for field in ("vx_mcm", "vy_mcm", "vx_int", "vy_int"):
        assert np.array_equal(as_scene.tracks[field], withheld.tracks[field] * 0.25)
    assert np.array_equal(as_scene.tracks["x"], withheld.tracks["x"]) and np.array_equal(as_scene.tracks["t_us"], withheld.tracks["t_us"])
    at_25 = dataclasses.replace(sim.meta, t_frame_us=FRAMELESS_PERIOD_US)
    given = track_events(sim.events, at_25, classic_params())
    assert np.array_equal(given.tracks, withheld.tracks)


def test_loop_columns_are_contiguous_writable_columns_of_the_events():
    events = np.zeros(50, EVENT_DTYPE)
    events["t"], events["x"], events["Cr"] = np.arange(50) * 7, np.arange(50) % 13, 200
    events.flags.writeable = False  # as a read-only map of a file gives them
    for name, column in zip(LOOP_FIELDS, loop_columns(events)):
        assert column.flags.c_contiguous and column.flags.writeable, name
        assert column.dtype == EVENT_DTYPE[name]
        assert np.array_equal(column, events[name])


@pytest.mark.parametrize("model", ["float", "fixed"])
def test_one_compiled_loop_serves_record_arrays_read_only_maps_and_strided_slices(model, tmp_path):
    # Each argument layout would compile the loop again, a minute or two in a fresh clone: the
    # columns are made contiguous and writable first (evclust.events.format.loop_columns).
    events, meta = sample_stream()
    np.save(tmp_path / "events.npy", events)
    mapped = np.load(tmp_path / "events.npy", mmap_mode="r")  # read-only
    params = classic_params()
    # numba's dispatcher (this makes numba ready, so every run below is numba's and none the
    # ahead-of-time build's, which would leave the signatures untouched whatever the layouts).
    loop = {"float": float_model, "fixed": fixed_model}[model].run_events
    loop = getattr(loop, "dispatcher", loop)
    first = track_events(events, meta, params, model=model).tracks
    compiled = len(loop.signatures)
    assert np.array_equal(track_events(mapped, meta, params, model=model).tracks, first)
    every_other = track_events(events[::2], meta, params, model=model).tracks  # a strided slice
    assert np.array_equal(every_other, track_events(events[::2].copy(), meta, params, model=model).tracks)
    assert len(loop.signatures) == compiled
