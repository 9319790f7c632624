"""TDC quantisation: the time-to-first-spike of each colour channel read by a time-to-digital converter.

Per channel, intensity I (0..255) integrates in t = k_us·255/I (shared helper integration_time_us).
A `bits`-bit TDC counts steps of t_max_us/(2^bits - 1): codes 0 .. 2^bits-2 cover [0, t_max_us) and
the all-ones code is the overflow, "no spike by t_max_us", which reads 0 (dark clipping). A code
reads back as the middle of its time bin, I' = k_us·255/((code + 1/2)·step), clipped to 255. So a
channel takes at most 2^bits values, bright ones coarsely (ΔI/I ≈ step/t) and dark ones finely.
"""

from __future__ import annotations

from typing import Annotated

import numpy as np
from pydantic import Field, ValidationInfo, field_validator

from evclust.colour import RGB_TO_YCBCR, YCBCR_TO_RGB
from evclust.jit import njit, vectorize
from evclust.simulator.effects.base import Effect, EffectParams


# integration_time_us lives here, beside the compiled code that calls it: numba's on-disk cache
# only notices edits to the calling function's own file. TFS latency imports it from here.
@vectorize(["float64(float64, float64, float64)"], cache=True, nopython=True)
def integration_time_us(intensity, k_us, t_max_us):
    """Time-to-first-spike of the TFS pixel: the integration time k_us·255/I, capped at t_max_us.

    I is the intensity in 0..255: full scale (255) integrates in k_us, half scale in 2·k_us, and a
    pixel darker than k_us·255/t_max_us has not spiked by t_max_us (the cap; I <= 0 never spikes).
    Shared by the TFS latency (when the event is stamped) and the TDC (what intensity it reads).
    A ufunc: it takes arrays from Python and scalars inside compiled loops.
    """
    # No branch on I <= 0: a tiny floor keeps the division finite and the cap does the rest.
    return min(k_us * 255.0 / max(intensity, 1e-12), t_max_us)


@vectorize(["float64(float64, float64, float64, int64)"], cache=True, nopython=True)
def tdc_read(intensity, k_us, t_max_us, bits):
    """An intensity 0..255 -> what the TFS pixel and its `bits`-bit TDC read back, 0..255."""
    t = integration_time_us(intensity, k_us, t_max_us)
    if t >= t_max_us:
        return 0.0
    last = (1 << bits) - 2  # the highest code that is a time; 2^bits - 1 is the overflow
    step = t_max_us / (last + 1)
    code = min(np.floor(t / step), last)
    return min(k_us * 255.0 / ((code + 0.5) * step), 255.0)


@njit(cache=True, nogil=True, boundscheck=False)
def _requantise(lum, cb, cr, to_rgb, to_ycc, k_us, t_max_us, bits):
    """In place: YCbCr -> RGB, each channel through the TDC, -> YCbCr (rounded as the change detector does).

    The BT.601 matrices come in as arguments: numba's disk cache would freeze a module global."""
    for i in range(lum.size):
        r = _read_channel(to_rgb, 0, lum[i], cb[i], cr[i], k_us, t_max_us, bits)
        g = _read_channel(to_rgb, 1, lum[i], cb[i], cr[i], k_us, t_max_us, bits)
        b = _read_channel(to_rgb, 2, lum[i], cb[i], cr[i], k_us, t_max_us, bits)
        lum[i] = _byte(to_ycc[0, 0] * r + to_ycc[0, 1] * g + to_ycc[0, 2] * b + to_ycc[0, 3])
        cb[i] = _byte(to_ycc[1, 0] * r + to_ycc[1, 1] * g + to_ycc[1, 2] * b + to_ycc[1, 3])
        cr[i] = _byte(to_ycc[2, 0] * r + to_ycc[2, 1] * g + to_ycc[2, 2] * b + to_ycc[2, 3])


@njit(cache=True, nogil=True, inline="always")
def _read_channel(to_rgb, c, lum, cb, cr, k_us, t_max_us, bits):
    v = to_rgb[c, 0] * lum + to_rgb[c, 1] * cb + to_rgb[c, 2] * cr + to_rgb[c, 3]
    return tdc_read(min(max(v, 0.0), 255.0), k_us, t_max_us, bits)


@njit(cache=True, nogil=True, inline="always")
def _byte(v):
    return np.uint8(min(max(v, 0.0), 255.0) + 0.5)


class TdcQuantisation(Effect):
    """Each RGB channel read as a bits-bit integration time: coarse bright levels, dark clipped to 0."""

    name = "tdc_quantisation"
    stage = "stream"

    class Params(EffectParams):
        bits: Annotated[int, Field(ge=1, le=16)] = 8  # TDC word; the all-ones code means "no spike by t_max"
        k_us: Annotated[float, Field(gt=0)] = 100.0  # integration time of full scale (255), µs
        t_max_us: Annotated[float, Field(gt=0)] = 2550.0  # TDC range, µs; darker than 255·k/t_max reads 0

        @field_validator("t_max_us")
        @classmethod
        def _covers_full_scale(cls, v: float, info: ValidationInfo) -> float:
            k = info.data.get("k_us")
            if k is not None and v <= k:
                raise ValueError(f"t_max_us must exceed k_us ({k:g}), or even full scale would read dark")
            return v

    @property
    def step_us(self) -> float:
        """One TDC count, µs."""
        return self.params.t_max_us / ((1 << self.params.bits) - 1)

    def quantise(self, intensity: np.ndarray) -> np.ndarray:
        """Intensities 0..255 (any shape) -> what the pixel reads back, 0..255 (float)."""
        p = self.params
        return tdc_read(np.asarray(intensity, dtype=np.float64), p.k_us, p.t_max_us, p.bits)

    def stream(self, events: np.ndarray) -> np.ndarray:
        out = events.copy()
        if out.size:
            lum, cb, cr = (np.ascontiguousarray(out[f]) for f in ("Y", "Cb", "Cr"))
            p = self.params
            _requantise(lum, cb, cr, YCBCR_TO_RGB, RGB_TO_YCBCR, float(p.k_us), float(p.t_max_us), int(p.bits))
            out["Y"], out["Cb"], out["Cr"] = lum, cb, cr
        return out
