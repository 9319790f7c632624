"""TFS latency: the event is stamped when the intensity measurement ends, later for darker pixels."""

from __future__ import annotations

from typing import Annotated

import numpy as np
from pydantic import Field, ValidationInfo, field_validator

from evclust.events import sort_events
from evclust.simulator.effects.base import Effect, EffectParams, round_us
from evclust.simulator.effects.tdc import integration_time_us


class TfsLatency(Effect):
    """Each event is stamped at the end of its luminance integration, t + k_us·255/Y (at most t_max_us)."""

    name = "tfs_latency"
    stage = "stream"

    class Params(EffectParams):
        k_us: Annotated[float, Field(gt=0)] = 100.0  # integration time of full scale (Y = 255), µs
        t_max_us: Annotated[float, Field(gt=0)] = 2550.0  # longest integration (the TDC range), µs

        @field_validator("t_max_us")
        @classmethod
        def _covers_full_scale(cls, v: float, info: ValidationInfo) -> float:
            k = info.data.get("k_us")
            if k is not None and v < k:
                raise ValueError(f"t_max_us must be at least k_us ({k:g})")
            return v

    def stream(self, events: np.ndarray) -> np.ndarray:
        if events.size == 0:
            return events
        latency = integration_time_us(events["Y"].astype(np.float64), self.params.k_us, self.params.t_max_us)
        out = events.copy()
        out["t"] = round_us(events["t"].astype(np.float64) + latency)
        return sort_events(out)
