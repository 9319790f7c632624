"""The event picture shows what the stream holds."""

from __future__ import annotations

import matplotlib.image as mpimg
import numpy as np

from evclust.events import EVENT_DTYPE, EventMeta
from evclust.render import draw_events


def test_picture_is_written_and_empty_streams_are_drawn_too(tmp_path):
    meta = EventMeta(width=40, height=30, source="unit", t_frame_us=1000.0)
    ev = np.zeros(3, EVENT_DTYPE)
    ev["t"], ev["x"], ev["y"], ev["p"] = [10, 20, 30], [5, 6, 7], [5, 5, 5], [1, -1, 1]
    ev["Y"], ev["Cb"], ev["Cr"] = 200, 128, 128
    for name, events in (("some.png", ev), ("none.png", ev[:0])):
        path = tmp_path / name
        draw_events(events, meta, path)
        image = mpimg.imread(path)
        assert image.ndim == 3 and image.shape[0] > 200 and image.shape[1] > 400
        assert np.ptp(image[..., :3]) > 0.5  # not a blank canvas
