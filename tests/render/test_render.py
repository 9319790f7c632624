"""The event picture shows what the stream holds, pixel for pixel: ON events white and OFF events
black on the polarity panel's grey, each event's colour on the colour panel."""

from __future__ import annotations

import matplotlib.image as mpimg
import numpy as np

from evclust.colour import rgb_to_ycbcr
from evclust.events import EVENT_DTYPE, EventMeta
from evclust.render import draw_events

W, H = 40, 30
RED = (200, 30, 30)


def half_and_half() -> np.ndarray:
    """One event on every pixel within a frame: ON on the left half, OFF on the right, all red."""
    y, x = np.mgrid[0:H, 0:W]
    ev = np.zeros(W * H, EVENT_DTYPE)
    ev["t"] = np.arange(W * H) // 4
    ev["x"], ev["y"] = x.ravel(), y.ravel()
    ev["p"] = np.where(ev["x"] < W // 2, 1, -1)
    ev["Y"], ev["Cb"], ev["Cr"] = np.rint(rgb_to_ycbcr(np.array(RED, np.float64))).astype(int)
    return ev


def masks(image: np.ndarray) -> dict[str, np.ndarray]:
    rgb = image[..., :3]
    top = np.zeros(rgb.shape[:2], bool)
    top[: int(0.7 * rgb.shape[0])] = True  # the two image panels; the rate histogram is below
    left = np.zeros_like(top)
    left[:, : rgb.shape[1] // 2] = True
    return {
        "grey": top & left & np.all(np.abs(rgb - 0.5) < 0.03, axis=-1),
        "black": top & left & np.all(rgb < 0.03, axis=-1),
        "red": top & ~left & (rgb[..., 0] > 0.7) & (rgb[..., 1] < 0.25) & (rgb[..., 2] < 0.25),
    }


def test_the_picture_draws_on_and_off_and_the_events_colour_where_they_are(tmp_path):
    meta = EventMeta(width=W, height=H, source="unit", t_frame_us=1000.0)
    pictures = {}
    for name, events in (("some", half_and_half()), ("none", half_and_half()[:0])):
        draw_events(events, meta, tmp_path / f"{name}.png")
        pictures[name] = masks(mpimg.imread(tmp_path / f"{name}.png"))
    some, none = pictures["some"], pictures["none"]
    panel = none["grey"].sum()  # without events the polarity panel is all grey
    assert panel > 20_000
    assert some["grey"].sum() < 0.01 * panel  # every pixel had an event: no grey left
    # The OFF half is black: half the panel more black pixels than the axes' lines and text...
    new_black = some["black"] & ~none["black"]
    assert 0.4 * panel < new_black.sum() < 0.6 * panel
    # ...and it lies on the panel's right: its pixels' mean column right of the panel's centre.
    assert np.nonzero(new_black)[1].mean() > np.nonzero(none["grey"])[1].mean()
    # The colour panel shows the events' red over its whole image, and nothing red without events.
    assert some["red"].sum() > 0.9 * panel and none["red"].sum() == 0


def test_an_empty_stream_is_drawn_too(tmp_path):
    meta = EventMeta(width=W, height=H, source="unit", t_frame_us=1000.0)
    draw_events(half_and_half()[:0], meta, tmp_path / "none.png")
    image = mpimg.imread(tmp_path / "none.png")
    assert image.ndim == 3 and image.shape[0] > 200 and image.shape[1] > 400
