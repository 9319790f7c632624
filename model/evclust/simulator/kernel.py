"""The change detector of every pixel between two frames (SPEC §3), compiled.

Between frames k-1 and k the detector input L is taken as linear in time from L0 to L1, and so is
the colour. Each crossing of L_ref ± n·θ emits one event at its interpolated time with the
interpolated YCbCr, and L_ref moves by the crossed amount. Pixels are visited in row-major order
and a pixel's events come out in time order, so a stable sort on time gives SPEC §2's order
(time, then y, then x).
"""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True, nogil=True, boundscheck=False)
def detect_interval(
    l0, l1, c0, c1, ref, th_on, th_off, th_stride, width, t0_us, dt_us, first_pixel,
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
        if n + count > capacity:
            return n, i
        start = l0[i]
        span = target - start
        y = i // width
        x = i - y * width
        for j in range(1, count + 1):
            level = r + j * step
            frac = (level - start) / span
            frac = min(max(frac, 0.0), 1.0)
            out_t[n] = np.uint64(t0_us + frac * dt_us + 0.5)
            out_x[n] = x
            out_y[n] = y
            out_p[n] = polarity
            out_lum[n] = np.uint8(min(max(c0[i, 0] + frac * (c1[i, 0] - c0[i, 0]), 0.0), 255.0) + 0.5)
            out_cb[n] = np.uint8(min(max(c0[i, 1] + frac * (c1[i, 1] - c0[i, 1]), 0.0), 255.0) + 0.5)
            out_cr[n] = np.uint8(min(max(c0[i, 2] + frac * (c1[i, 2] - c0[i, 2]), 0.0), 255.0) + 0.5)
            n += 1
        ref[i] = r + count * step
    return n, l0.size
