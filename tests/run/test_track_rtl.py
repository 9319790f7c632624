"""`evclust track --model rtl`: the RTL under Verilator as a clusterer model, its cluster records
and its object unit's records bit for bit the fixed model's on a segment of a built-in scene,
with the status counters read from its registers."""

from __future__ import annotations

import numpy as np
import pytest

from evclust.cli import main
from evclust.clusterer import load_params
from evclust.run import track_events
from evclust.events.io import EventReader, event_writer
from evclust.scenes import load_scene
from evclust.simulator import simulate_scene


@pytest.fixture(scope="module")
def segment(tmp_path_factory):
    """The first 40000 events of `traffic`: creations, filter steps, reported clusters and objects."""
    folder = tmp_path_factory.mktemp("rtl_track")
    sim = simulate_scene(load_scene("traffic"), seed=1)
    path = folder / "segment.npz"
    with event_writer(path, sim.meta) as writer:
        writer.write(sim.events[:40000])
    return path


def _records(path):
    lines = path.read_text().splitlines()
    assert lines[0].startswith("# evclust-tracks")
    return lines[1:]


@pytest.mark.parametrize("kind", ["--clusters", "--every-step"])
def test_track_model_rtl_writes_the_fixed_models_track_file(segment, tmp_path, kind):
    for model in ("fixed", "rtl"):
        assert main(["track", str(segment), "-o", str(tmp_path / f"{model}.csv"), "--model", model, kind, "-q"]) == 0
    fixed, rtl = _records(tmp_path / "fixed.csv"), _records(tmp_path / "rtl.csv")
    assert len(fixed) > 30, "a segment that reports little checks little"
    assert rtl == fixed
    assert '"model": "rtl"' in (tmp_path / "rtl.csv").read_text().splitlines()[0]


def test_the_rtl_models_counters_are_the_fixed_models_statistics(segment):
    reader = EventReader(segment)
    events = reader.read()
    params, _ = load_params("traffic")
    fixed = track_events(events, reader.meta, params, model="fixed")
    rtl = track_events(events, reader.meta, params, model="rtl")
    assert np.array_equal(rtl.tracks, fixed.tracks)
    assert fixed.objects.size > 0 and np.array_equal(rtl.objects, fixed.objects)
    for name in ("events", "steps", "created", "evicted", "dropped", "expired", "exited", "merged", "records"):
        assert rtl.stats[name] == fixed.stats[name], name
    assert rtl.stats["counters"]["updates"] == events.size - fixed.stats["created"] - fixed.stats["dropped"] - fixed.stats["unsupported"]
