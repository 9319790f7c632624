"""Photoreceptor low-pass: a pixel's bandwidth grows with its light, so dark pixels lag."""

from __future__ import annotations

import math
from typing import Annotated

import numpy as np
from pydantic import Field

from evclust.simulator.effects.base import Effect, EffectParams


class PhotoreceptorLowpass(Effect):
    """First-order low-pass of L per pixel with a cut-off that scales with the pixel's light (v2e's)."""

    # f_3dB = cutoff_hz·(I + 20)/275: a full-white pixel has cutoff_hz, a black one 7 % of it. Each
    # sample moves the filtered L by ε = min(1, (I + 20)/275 · Δt·2π·cutoff_hz) of the way to the
    # new L, as v2e's `low_pass_filter` does.

    name = "photoreceptor_lowpass"
    stage = "photoreceptor"

    class Params(EffectParams):
        cutoff_hz: Annotated[float, Field(gt=0, le=1e6)] = 200.0  # a full-white pixel's 3 dB bandwidth

    def __init__(self, params, geometry, seed):
        super().__init__(params, geometry, seed)
        self.filtered = None  # the filtered L of every pixel, from the first sample on
        self.rate = np.float32(geometry.t_sample_us * 1e-6 * 2.0 * math.pi * params.cutoff_hz / 275.0)

    def photoreceptor(self, level: np.ndarray, intensity: np.ndarray) -> None:
        """Replace `level` (flat float32) by its low-passed value, in place."""
        if self.filtered is None:
            self.filtered = level.copy()  # a sensor switched on in steady state
            return
        eps = np.minimum((intensity + np.float32(20.0)) * self.rate, np.float32(1.0))
        self.filtered += eps * (level - self.filtered)
        np.copyto(self.filtered, level, where=eps >= 1.0)  # a pixel faster than the sampling follows exactly
        level[:] = self.filtered
