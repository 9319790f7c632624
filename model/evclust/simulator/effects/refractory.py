"""Refractory period: after an event a pixel stays blind for a while."""

from __future__ import annotations

from typing import Annotated

import numpy as np
from pydantic import Field

from evclust.jit import njit
from evclust.simulator.effects.base import Effect, EffectParams


@njit(cache=True, nogil=True)
def _refractory_keep(t, x, y, width, n_pixels, period_us):
    """keep[i]: event i comes period_us or more after the last kept event of its pixel."""
    last = np.full(n_pixels, -np.inf)
    keep = np.empty(t.size, np.bool_)
    for i in range(t.size):
        pixel = int(y[i]) * width + int(x[i])
        ti = float(t[i])
        if ti - last[pixel] < period_us:
            keep[i] = False
        else:
            keep[i] = True
            last[pixel] = ti
    return keep


class Refractory(Effect):
    """Drops an event that comes less than period_us after the last kept event of its pixel."""

    name = "refractory"
    stage = "stream"

    class Params(EffectParams):
        period_us: Annotated[float, Field(gt=0)] = 1000.0  # dead time after each event, µs

    def stream(self, events: np.ndarray) -> np.ndarray:
        if events.size == 0:
            return events
        g = self.geometry
        keep = _refractory_keep(events["t"], events["x"], events["y"], g.width, g.width * g.height, float(self.params.period_us))
        return events[keep]
