"""What a sensor effect is: a stage of the pipeline that a scene switches on by name.

An effect hooks into exactly one place of the pipeline (its `stage`):
- "observe":    replaces how a frame becomes detector input and colour (e.g. a Bayer mosaic);
- "thresholds": gives per-pixel ON/OFF thresholds (e.g. mismatch);
- "interval":   edits or adds events of one frame interval, seeing the frames (e.g. noise);
- "stream":     edits the whole sorted stream (e.g. refractory period, readout limit).
An effect that the scene does not name is never constructed, so it costs nothing.
"""

from __future__ import annotations

import dataclasses
import zlib
from typing import ClassVar

import numpy as np
from pydantic import BaseModel, ConfigDict


class EffectParams(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


@dataclasses.dataclass(frozen=True)
class SensorGeometry:
    width: int
    height: int
    t_frame_us: float


@dataclasses.dataclass
class Interval:
    """One frame interval as the interval stage sees it: frames k-1 and k as the pixels saw them."""

    index: int  # k: the interval ends at frame k
    t0_us: float
    t1_us: float
    rgb0: np.ndarray  # (H, W, 3) float32 RGB, 0..255
    rgb1: np.ndarray


class Effect:
    name: ClassVar[str]
    stage: ClassVar[str]
    Params: ClassVar[type[EffectParams]]

    def __init__(self, params: EffectParams, geometry: SensorGeometry, seed: int):
        self.params = params
        self.geometry = geometry
        # One stream of randomness per effect, independent of which other effects are on.
        self.rng = np.random.default_rng([seed, zlib.crc32(self.name.encode())])

    # Hooks; each effect implements the one of its stage.
    def observe(self, rgb: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(H, W, 3) RGB -> ((H, W) intensity the change detector sees, (H, W, 3) RGB the TFS measures)."""
        raise NotImplementedError

    def thresholds(self, th_on: float, th_off: float) -> tuple[np.ndarray, np.ndarray]:
        raise NotImplementedError

    def interval(self, events: np.ndarray, interval: Interval) -> np.ndarray:
        raise NotImplementedError

    def stream(self, events: np.ndarray) -> np.ndarray:
        raise NotImplementedError
