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


def test_a_frame_reader_left_suspended_is_stopped_by_the_interrupt_cleanup():
    # An interrupted run may leave the prefetching generator suspended and still referenced (from
    # the interrupt's traceback), so its own cleanup never runs; the CLI's cleanup must still end
    # its thread, which the interpreter's exit would kill inside OpenCV (exit -6).
    import threading
    import time

    from evclust.simulator.pipeline import _prefetched
    from evclust.threads import stop_background_threads

    def frames():
        for k in range(10_000):
            time.sleep(0.001)
            yield k

    reader = _prefetched(frames())
    assert next(reader) == 0  # suspended, its thread reading ahead
    running = [t for t in threading.enumerate() if t.name == "evclust-frames"]
    assert len(running) == 1 and running[0].is_alive()
    stop_background_threads()
    assert not running[0].is_alive()
    reader.close()  # its own cleanup afterwards finds the thread gone
