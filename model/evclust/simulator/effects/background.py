"""Background activity: Poisson noise events at every pixel (shot noise and junction leakage)."""

from __future__ import annotations

from typing import Annotated

import numpy as np
from pydantic import Field

from evclust.simulator.effects.base import Effect, EffectParams, Interval, add_events, poisson_events


class BackgroundActivity(Effect):
    """Poisson noise events at every pixel, rate_hz each, carrying the pixel's current colour."""

    name = "background_activity"
    stage = "interval"

    class Params(EffectParams):
        rate_hz: Annotated[float, Field(gt=0, le=1e6)] = 0.1  # noise events per pixel per second
        on_fraction: Annotated[float, Field(ge=0, le=1)] = 0.5  # probability that a noise event is ON

    def interval(self, events: np.ndarray, interval: Interval) -> np.ndarray:
        n_pixels = self.geometry.width * self.geometry.height
        noise = poisson_events(self.rng, n_pixels, self.params.rate_hz, self.params.on_fraction, interval)
        return add_events(events, noise)
