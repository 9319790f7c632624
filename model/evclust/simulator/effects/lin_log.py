"""Lin-log photoreceptor: linear in intensity below a light level, logarithmic above."""

from __future__ import annotations

from typing import Annotated

import numpy as np
from pydantic import Field

from evclust.simulator.effects.base import Effect, EffectParams


class LinLog(Effect):
    """Photoreceptor linear below `cutoff` grey levels and logarithmic above (v2e's lin_log)."""

    # Below the cutoff c, L = I·ln(c + ε)/c, so dark pixels stop amplifying their small changes the
    # way a pure logarithm does; above it L = ln(I + ε), the log detector unchanged. The two meet
    # at c. v2e's `lin_log` uses c = 20 DN.

    name = "lin_log"
    stage = "transfer"

    class Params(EffectParams):
        cutoff: Annotated[float, Field(gt=0, le=255)] = 20.0  # grey levels where linear meets log

    def transfer(self, intensity: np.ndarray, level: np.ndarray, log_eps: float) -> None:
        """intensity (flat float32, 0..255) -> level, in place: the detector input L."""
        c = np.float32(self.params.cutoff)
        np.add(intensity, np.float32(log_eps), out=level)
        np.log(level, out=level)
        dark = intensity < c
        level[dark] = intensity[dark] * np.float32(np.log(self.params.cutoff + log_eps) / self.params.cutoff)
