"""The change detector of every pixel between two frames (SPEC §3), compiled.

Between frames k-1 and k the detector input L is taken as linear in time from L0 to L1, and so is
the colour. Each crossing of L_ref ± n·θ emits one event at its interpolated time with the
interpolated YCbCr, and L_ref moves by the crossed amount. Pixels are visited in row-major order
and a pixel's events come out in time order, so ordering by (time, emission index) gives SPEC §2's
order (time, then y, then x).
"""

from __future__ import annotations

import numba
import numpy as np

from evclust.colour import RGB_TO_YCBCR

_M = RGB_TO_YCBCR  # YCbCr = M[:, :3] · RGB + M[:, 3]; linear, so interpolating RGB interpolates YCbCr


@numba.njit(cache=True, nogil=True, inline="always")
def _channel(row, r, g, b):
    v = _M[row, 0] * r + _M[row, 1] * g + _M[row, 2] * b + _M[row, 3]
    return np.uint8(min(max(v, 0.0), 255.0) + 0.5)


@numba.njit(cache=True, nogil=True, boundscheck=False)
def detect_interval(
    l0, l1, rgb0, rgb1, ref, th_on, th_off, th_stride, width, t0_us, dt_us, first_pixel,
    out_t, out_x, out_y, out_p, out_lum, out_cb, out_cr,
):  # fmt: skip
    """Emit the events of pixels first_pixel.. into the out_* buffers.

    Returns (events written, next pixel to visit). The next pixel is l0.size when the interval is
    done; otherwise the buffers are full, and the caller empties them and calls again from there.
    """
    capacity = out_t.size
    n = 0
    for i in range(first_pixel, l0.size):
        r = ref[i]
        target = l1[i]
        th_up = th_on[i * th_stride]
        th_down = th_off[i * th_stride]
        if target - r >= th_up:
            count = int((target - r) / th_up)
            step = th_up
            polarity = 1
        elif r - target >= th_down:
            count = int((r - target) / th_down)
            step = -th_down
            polarity = -1
        else:
            continue
        # Make the residual pass the very test this pixel faces next, so a static pixel stays silent.
        while abs(target - (r + count * step)) >= abs(step):
            count += 1
        if n + count > capacity:
            return n, i
        start = l0[i]
        span = target - start
        if span == 0.0:  # only float rounding can get here: the crossing is at the frame itself
            span = step
            start = target - step
        y = i // width
        x = i - y * width
        for j in range(1, count + 1):
            frac = min(max((r + j * step - start) / span, 0.0), 1.0)
            red = rgb0[i, 0] + frac * (rgb1[i, 0] - rgb0[i, 0])
            green = rgb0[i, 1] + frac * (rgb1[i, 1] - rgb0[i, 1])
            blue = rgb0[i, 2] + frac * (rgb1[i, 2] - rgb0[i, 2])
            out_t[n] = np.uint64(t0_us + frac * dt_us + 0.5)
            out_x[n] = x
            out_y[n] = y
            out_p[n] = polarity
            out_lum[n] = _channel(0, red, green, blue)
            out_cb[n] = _channel(1, red, green, blue)
            out_cr[n] = _channel(2, red, green, blue)
            n += 1
        ref[i] = r + count * step
    return n, l0.size


def time_order(t: np.ndarray, t0: int) -> np.ndarray:
    """Indices that order one interval's events by time, ties by emission order (= y, then x).

    One packed uint64 key per event and an unstable SIMD sort: faster than a stable argsort.
    """
    key = ((t - np.uint64(t0)) << np.uint64(32)) | np.arange(t.size, dtype=np.uint64)
    return (np.sort(key) & np.uint64(0xFFFFFFFF)).astype(np.intp)
