"""What a sensor effect is: a stage of the pipeline that a scene switches on by name.

An effect hooks into exactly one place of the pipeline (its `stage`):
- "observe":    replaces how a frame becomes intensity and colour (e.g. a Bayer mosaic);
- "transfer":   replaces the photoreceptor's intensity -> L curve (e.g. lin-log);
- "photoreceptor": filters L over time per pixel (e.g. an intensity-dependent low-pass);
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

from evclust.colour import rgb_to_ycbcr
from evclust.events.format import EVENT_DTYPE, concat_events, sort_events


class EffectParams(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


@dataclasses.dataclass(frozen=True)
class SensorGeometry:
    width: int
    height: int
    t_sample_us: float  # the period of the frames the sensor sees: a frame, or a sub-step of one


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

    def transfer(self, intensity: np.ndarray, level: np.ndarray, log_eps: float) -> None:
        """Flat float32 intensity (0..255) -> detector input L, written into `level`."""
        raise NotImplementedError

    def photoreceptor(self, level: np.ndarray, intensity: np.ndarray) -> None:
        """Filter this sample's L (flat float32) in place; the pixel's intensity beside it."""
        raise NotImplementedError

    def thresholds(self, th_on: float, th_off: float) -> tuple[np.ndarray, np.ndarray]:
        raise NotImplementedError

    def interval(self, events: np.ndarray, interval: Interval) -> np.ndarray:
        raise NotImplementedError

    def stream(self, events: np.ndarray) -> np.ndarray:
        raise NotImplementedError


# ---------------------------------------------------------------------------------------------
# Helpers shared by several effects.


def round_us(t: np.ndarray) -> np.ndarray:
    """Float µs -> uint64 µs, rounding half up as the change detector does."""
    return np.floor(np.asarray(t, dtype=np.float64) + 0.5).astype(np.uint64)


def to_ycbcr_u8(rgb: np.ndarray) -> np.ndarray:
    """(N, 3) RGB 0..255 -> (N, 3) uint8 YCbCr (BT.601 full range), clipped and rounded as the kernel does."""
    return np.floor(np.clip(rgb_to_ycbcr(rgb), 0.0, 255.0) + 0.5).astype(np.uint8)


def poisson_events(
    rng: np.random.Generator, pixels: np.ndarray | int, rate_hz: float, on_fraction: float, interval: Interval
) -> np.ndarray:
    """Independent Poisson trains of `rate_hz` at each pixel over one frame interval.

    `pixels`: flat indices (y·W + x) of the pixels that fire, or an int n for all pixels 0..n-1.
    The total count is Poisson(rate·pixels·Δt); each event picks its pixel uniformly and its time
    uniformly in [t0, t1], which is the same process. An event is ON with probability
    `on_fraction` and carries the pixel's colour linearly interpolated to its time, as a change
    event would. Returned sorted by (t, y, x).
    """
    n_pixels = pixels if isinstance(pixels, (int, np.integer)) else len(pixels)
    span_us = interval.t1_us - interval.t0_us
    n = int(rng.poisson(rate_hz * n_pixels * span_us * 1e-6))
    which = rng.integers(0, n_pixels, n)
    flat = which if isinstance(pixels, (int, np.integer)) else np.asarray(pixels)[which]
    frac = rng.random(n)
    on = rng.random(n) < on_fraction
    width = interval.rgb0.shape[1]
    y, x = np.divmod(flat, width)
    c0 = interval.rgb0[y, x].astype(np.float64)
    rgb = c0 + frac[:, None] * (interval.rgb1[y, x] - c0)
    ev = np.empty(n, dtype=EVENT_DTYPE)
    ev["t"] = round_us(interval.t0_us + frac * span_us)
    ev["x"] = x
    ev["y"] = y
    ev["p"] = np.where(on, 1, -1)
    ycc = to_ycbcr_u8(rgb)
    ev["Y"], ev["Cb"], ev["Cr"] = ycc[:, 0], ycc[:, 1], ycc[:, 2]
    return sort_events(ev)


def add_events(events: np.ndarray, extra: np.ndarray) -> np.ndarray:
    """Two sorted streams -> one sorted stream."""
    if extra.size == 0:
        return events
    if events.size == 0:
        return extra
    return sort_events(concat_events([events, extra]))
