"""BT.601 full-range (JPEG) RGB <-> YCbCr, the one colour conversion of the project."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np


class NamedColour(NamedTuple):
    name: str
    rgb: tuple[int, int, int]


# The colours the built-in palette names (the clusterer's default palette) and the generated
# scenes paint their objects in, so that a scene's truth names a palette entry.
NAMED_COLOURS = (
    NamedColour("black", (30, 30, 30)),
    NamedColour("grey", (128, 128, 128)),
    NamedColour("white", (235, 235, 235)),
    NamedColour("red", (200, 30, 30)),
    NamedColour("green", (40, 170, 60)),
    NamedColour("blue", (30, 60, 180)),
    NamedColour("yellow", (230, 200, 40)),
)

# Rows: Y, Cb, Cr; last column: offset. Coefficients of ITU-T T.871 (JFIF).
RGB_TO_YCBCR = np.array(
    [
        [0.299, 0.587, 0.114, 0.0],
        [-0.168736, -0.331264, 0.5, 128.0],
        [0.5, -0.418688, -0.081312, 128.0],
    ],
    dtype=np.float64,
)
YCBCR_TO_RGB = np.array(
    [
        [1.0, 0.0, 1.402, -1.402 * 128.0],
        [1.0, -0.344136, -0.714136, (0.344136 + 0.714136) * 128.0],
        [1.0, 1.772, 0.0, -1.772 * 128.0],
    ],
    dtype=np.float64,
)


def rgb_to_ycbcr(rgb: np.ndarray) -> np.ndarray:
    """(..., 3) RGB in 0..255 -> (..., 3) float YCbCr, unclipped."""
    rgb = np.asarray(rgb, dtype=np.float64)
    return rgb @ RGB_TO_YCBCR[:, :3].T + RGB_TO_YCBCR[:, 3]


def ycbcr_to_rgb(ycc: np.ndarray) -> np.ndarray:
    ycc = np.asarray(ycc, dtype=np.float64)
    return ycc @ YCBCR_TO_RGB[:, :3].T + YCBCR_TO_RGB[:, 3]


def frame_to_luma(rgb: np.ndarray, rgb_f32: np.ndarray | None = None, out: np.ndarray | None = None) -> np.ndarray:
    """An (H, W, 3) RGB frame -> (H, W) float32 Y; the only plane the change detector needs.
    OpenCV's RGB->GRAY weights are BT.601's (0.299, 0.587, 0.114), and it is the fastest path.
    OpenCV is imported here, not with the module: `track` needs the colour tables, not OpenCV.

    `rgb_f32` ((H, W, 3) float32) and `out` ((H, W) float32) are optional room to reuse from frame
    to frame: the float32 copy of a uint8 frame is the largest array made per frame, and fresh
    memory costs a page fault per 4 KiB."""
    import cv2

    if rgb_f32 is not None and rgb.dtype != np.float32:
        np.copyto(rgb_f32, rgb, casting="unsafe")  # uint8 -> float32 is exact
        rgb = rgb_f32
    return cv2.cvtColor(np.ascontiguousarray(rgb, dtype=np.float32), cv2.COLOR_RGB2GRAY, dst=out)


def frame_to_ycbcr(rgb: np.ndarray) -> np.ndarray:
    """An (H, W, 3) float32 RGB frame -> (H, W, 3) float32 YCbCr planes; fast path for the simulator."""
    import cv2

    return cv2.transform(np.ascontiguousarray(rgb, dtype=np.float32), RGB_TO_YCBCR.astype(np.float32))
