"""The simulator as a stream: the same events as in one piece, written to a file as they are made."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from evclust.cli import main
from evclust.events import EventReader, concat_events
from evclust.scenes import load_scene
from evclust.simulator import simulate_scene, stream_scene


NOISE = {"background_activity": {"rate_hz": 0.5}, "refractory": {"period_us": 1000.0}}  # interval + stream effects


def crossing(effects):
    scene = load_scene("crossing")
    return dataclasses.replace(scene, spec=scene.spec.model_copy(update={"effects": effects}))


@pytest.mark.parametrize("effects", [{}, NOISE], ids=["ideal", "noise"])
def test_streamed_events_are_the_whole_run_cut_into_intervals(effects):
    whole = simulate_scene(crossing(effects))
    stream = stream_scene(crossing(effects))
    chunks = list(stream)
    assert np.array_equal(concat_events(chunks), whole.events)
    assert stream.samples == whole.samples and stream.meta == whole.meta
    if not stream.simulator.stream_effects:
        assert len(chunks) > 10  # interval by interval, not all at the end


def test_simulate_writes_the_stream_to_the_file_unchanged(tmp_path):
    out = tmp_path / "c.h5"
    assert main(["simulate", "crossing", "-o", str(out), "-q"]) == 0
    reader = EventReader(out)
    assert np.array_equal(reader.read(), simulate_scene(load_scene("crossing")).events)
