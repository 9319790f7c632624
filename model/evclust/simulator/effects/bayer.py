"""Bayer mosaic: one colour filter per pixel instead of three stacked photodiodes."""

from __future__ import annotations

from typing import Literal

import cv2
import numpy as np

from evclust.simulator.effects.base import Effect, EffectParams

_CHANNEL = {"R": 0, "G": 1, "B": 2}
# OpenCV names a Bayer layout after the second row's second and third pixels, so its code for a
# pattern whose top-left 2x2 block is RGGB is "BG" (checked by tests/simulator/test_effects.py).
_OPENCV_CODE = {
    "RGGB": cv2.COLOR_BayerBG2RGB,
    "BGGR": cv2.COLOR_BayerRG2RGB,
    "GRBG": cv2.COLOR_BayerGB2RGB,
    "GBRG": cv2.COLOR_BayerGR2RGB,
}
_SCALE = 256.0  # 0..255 -> 16-bit mosaic, so the demosaic keeps 8 fractional bits


class Bayer(Effect):
    """Colour filter array: each pixel sees one of R, G, B; colour comes from a bilinear demosaic."""

    name = "bayer"
    stage = "observe"

    class Params(EffectParams):
        pattern: Literal["RGGB", "BGGR", "GRBG", "GBRG"] = "RGGB"  # top-left 2x2 block, row by row

    def __init__(self, params, geometry, seed):
        super().__init__(params, geometry, seed)
        p = params.pattern
        block = np.array([[_CHANNEL[p[0]], _CHANNEL[p[1]]], [_CHANNEL[p[2]], _CHANNEL[p[3]]]])
        h, w = geometry.height, geometry.width
        self.filter = np.tile(block, ((h + 1) // 2, (w + 1) // 2))[:h, :w]  # (H, W) channel index
        self._rows, self._cols = np.indices((h, w))
        self._code = _OPENCV_CODE[p]

    def observe(self, rgb: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        # The change detector of a pixel sees only the light through its own filter.
        intensity = rgb[self._rows, self._cols, self.filter].astype(np.float32)
        mosaic = np.clip(intensity * _SCALE + 0.5, 0, 65535).astype(np.uint16)
        if min(mosaic.shape) < 2:  # OpenCV needs a 2x2 block at least
            return intensity, np.repeat(intensity[..., None], 3, axis=2)
        demosaiced = cv2.cvtColor(mosaic, self._code).astype(np.float32) * np.float32(1.0 / _SCALE)
        return intensity, demosaiced
