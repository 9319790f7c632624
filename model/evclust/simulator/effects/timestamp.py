"""Timestamp quantisation: the timestamp counter ticks every step_us."""

from __future__ import annotations

from typing import Annotated

import numpy as np
from pydantic import Field

from evclust.events import sort_events
from evclust.simulator.effects.base import Effect, EffectParams


class TimestampQuantisation(Effect):
    """Timestamps floored to a multiple of step_us, as by a coarser timestamp counter."""

    name = "timestamp_quantisation"
    stage = "stream"

    class Params(EffectParams):
        step_us: Annotated[int, Field(ge=1)] = 1000  # timestamp resolution, µs

    def stream(self, events: np.ndarray) -> np.ndarray:
        if events.size == 0:
            return events
        step = np.uint64(self.params.step_us)
        out = events.copy()
        out["t"] = (events["t"] // step) * step
        # Flooring keeps time order; events that now share a tick must be ordered by y, then x.
        return sort_events(out)
