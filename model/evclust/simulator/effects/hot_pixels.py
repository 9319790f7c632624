"""Hot pixels: a few pixels, chosen once, fire on their own at a high rate."""

from __future__ import annotations

from typing import Annotated

import numpy as np
from pydantic import Field

from evclust.errors import EvclustError
from evclust.simulator.effects.base import Effect, EffectParams, Interval, add_events, poisson_events


class HotPixels(Effect):
    """A fixed set of `count` pixels, drawn once, each firing a Poisson train of rate_hz."""

    name = "hot_pixels"
    stage = "interval"

    class Params(EffectParams):
        count: Annotated[int, Field(ge=1)] = 10  # number of hot pixels
        rate_hz: Annotated[float, Field(gt=0, le=1e6)] = 100.0  # events per second at each hot pixel
        on_fraction: Annotated[float, Field(ge=0, le=1)] = 1.0  # leakage drifts one way: ON by default

    def __init__(self, params, geometry, seed):
        super().__init__(params, geometry, seed)
        n_pixels = geometry.width * geometry.height
        if params.count > n_pixels:
            raise EvclustError(f"effects.{self.name}.count: {params.count} hot pixels on a sensor of {n_pixels} pixels")
        # Flat indices y·W + x, drawn once: the same pixels stay hot for the whole run.
        self.pixels = np.sort(self.rng.choice(n_pixels, size=params.count, replace=False))

    def interval(self, events: np.ndarray, interval: Interval) -> np.ndarray:
        hot = poisson_events(self.rng, self.pixels, self.params.rate_hz, self.params.on_fraction, interval)
        return add_events(events, hot)
