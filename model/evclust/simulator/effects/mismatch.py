"""Threshold mismatch: each pixel's ON and OFF thresholds scatter around the nominal ones."""

from __future__ import annotations

from typing import Annotated

import numpy as np
from pydantic import Field

from evclust.simulator.effects.base import Effect, EffectParams


class ThresholdMismatch(Effect):
    """Per-pixel ON/OFF thresholds scattered around the nominal ones with relative spread sigma."""

    name = "threshold_mismatch"
    stage = "thresholds"

    class Params(EffectParams):
        sigma: Annotated[float, Field(gt=0, le=1)] = 0.03  # relative standard deviation of θ
        floor: Annotated[float, Field(gt=0, le=1)] = 0.1  # θ never falls below floor·θ_nominal

    def thresholds(self, th_on: float, th_off: float) -> tuple[np.ndarray, np.ndarray]:
        n = self.geometry.width * self.geometry.height
        p = self.params
        on = th_on * np.maximum(1.0 + p.sigma * self.rng.standard_normal(n), p.floor)
        off = th_off * np.maximum(1.0 + p.sigma * self.rng.standard_normal(n), p.floor)
        return on, off
