"""The change detector of every pixel between two frames (SPEC §3), compiled.

Between frames k-1 and k the detector input L is taken as linear in time from L0 to L1, and so is
the colour. Each crossing of L_ref ± n·θ emits one event at its interpolated time with the
interpolated YCbCr, and L_ref moves by the crossed amount. Pixels are visited in row-major order
and a pixel's events come out in time order, so ordering by (time, emission index) gives SPEC §2's
order (time, then y, then x).
"""

from __future__ import annotations

import sys

import numpy as np

from evclust.events.format import EVENT_DTYPE
from evclust.jit import njit

# The kernel writes each event as the two little-endian uint64 words of its 16-byte record:
# word 0 = t; word 1 = x | y << 16 | p << 32 | Y << 40 | Cb << 48 | Cr << 56.
assert sys.byteorder == "little"
assert [EVENT_DTYPE.fields[f][1] for f in EVENT_DTYPE.names] == [0, 8, 10, 12, 13, 14, 15]
_ON_BITS = np.uint64(1) << np.uint64(32)
_OFF_BITS = np.uint64(0xFF) << np.uint64(32)  # int8 -1


@njit(cache=True, nogil=True, inline="always")
def _ycbcr(m, row, rgb, i):
    return m[row, 0] * rgb[i, 0] + m[row, 1] * rgb[i, 1] + m[row, 2] * rgb[i, 2] + m[row, 3]


@njit(cache=True, nogil=True, inline="always")
def _byte(v):
    return np.uint64(np.int64(min(max(v, 0.0), 255.0) + 0.5))


@njit(cache=True, nogil=True, boundscheck=False)
def detect_interval(l0, l1, rgb0, rgb1, ref, th_on, th_off, th_stride, width, t0_us, dt_us, first_pixel, words, keys, m):
    """Emit the events of pixels first_pixel.. as packed records into `words` (2 per event), and
    their sort keys ((t - floor(t0)) << 32 | emission index) into `keys`.

    Returns (events written, next pixel to visit). The next pixel is l0.size when the interval is
    done; otherwise the buffers are full, and the caller empties them and calls again from there.
    `m` is the RGB -> YCbCr matrix (an argument, not a global: numba's disk cache freezes globals).
    """
    capacity = keys.size
    t_base = np.uint64(np.floor(t0_us))
    n = 0
    for i in range(first_pixel, l0.size):
        r = ref[i]
        target = l1[i]
        th_up = th_on[i * th_stride]
        th_down = th_off[i * th_stride]
        if target - r >= th_up:
            step = th_up
            polarity_bits = _ON_BITS
        elif r - target >= th_down:
            step = -th_down
            polarity_bits = _OFF_BITS
        else:
            continue
        # Count crossings until the residual fails the very test this pixel faces next, so a
        # static pixel stays silent. Counts are small: stepping beats dividing.
        count = 1
        while abs(target - (r + count * step)) >= abs(step):
            count += 1
        if n + count > capacity:
            return n, i
        start = l0[i]
        span = target - start
        if span == 0.0:  # only float rounding can get here: the crossing is at the frame itself
            span = step
            start = target - step
        inv_span = 1.0 / span
        y = i // width
        address = np.uint64(i - y * width) | (np.uint64(y) << np.uint64(16)) | polarity_bits
        # YCbCr is linear in RGB: convert the pixel's two frames once, interpolate per event.
        lum0, cb0, cr0 = _ycbcr(m, 0, rgb0, i), _ycbcr(m, 1, rgb0, i), _ycbcr(m, 2, rgb0, i)
        d_lum, d_cb, d_cr = _ycbcr(m, 0, rgb1, i) - lum0, _ycbcr(m, 1, rgb1, i) - cb0, _ycbcr(m, 2, rgb1, i) - cr0
        for j in range(1, count + 1):
            frac = min(max((r + j * step - start) * inv_span, 0.0), 1.0)
            t = np.uint64(np.int64(t0_us + frac * dt_us + 0.5))
            words[2 * n] = t
            words[2 * n + 1] = (
                address
                | (_byte(lum0 + frac * d_lum) << np.uint64(40))
                | (_byte(cb0 + frac * d_cb) << np.uint64(48))
                | (_byte(cr0 + frac * d_cr) << np.uint64(56))
            )
            keys[n] = ((t - t_base) << np.uint64(32)) | np.uint64(n)
            n += 1
        ref[i] = r + count * step
    return n, l0.size


@njit(cache=True, nogil=True, boundscheck=False)
def _time_ordered_words(words, keys, starts, counts, out):
    """Write the packed records of the buffer parts (starts[p], counts[p]) into `out` in key order.

    A key is (t - floor(t0)) << 32 | buffer index, so key order is time order, ties in buffer
    (= emission) order. A stable counting sort on the time offset gives exactly that in two
    passes; an interval so long that its histogram would outweigh its events sorts the keys."""
    total = 0
    top = np.uint64(0)
    for p in range(starts.size):
        total += counts[p]
        for j in range(starts[p], starts[p] + counts[p]):
            top = max(top, keys[j] >> np.uint64(32))
    bins = np.int64(top) + 1
    if bins > 4 * total + 65536:
        chosen = np.empty(total, np.uint64)
        k = 0
        for p in range(starts.size):
            for j in range(starts[p], starts[p] + counts[p]):
                chosen[k] = keys[j]
                k += 1
        chosen.sort()
        for k in range(total):
            j = np.int64(chosen[k] & np.uint64(0xFFFFFFFF))
            out[2 * k] = words[2 * j]
            out[2 * k + 1] = words[2 * j + 1]
        return
    next_slot = np.zeros(bins + 1, np.int64)  # events before each time offset, then where the next goes
    for p in range(starts.size):
        for j in range(starts[p], starts[p] + counts[p]):
            next_slot[np.int64(keys[j] >> np.uint64(32)) + 1] += 1
    for b in range(bins):
        next_slot[b + 1] += next_slot[b]
    for p in range(starts.size):
        for j in range(starts[p], starts[p] + counts[p]):
            b = np.int64(keys[j] >> np.uint64(32))
            k = next_slot[b]
            next_slot[b] = k + 1
            out[2 * k] = words[2 * j]
            out[2 * k + 1] = words[2 * j + 1]


class EventBuffer:
    """Room for the events of one call of detect_interval, and their sort keys."""

    def __init__(self, capacity: int):
        self.words = np.empty(2 * capacity, np.uint64)
        self.keys = np.empty(capacity, np.uint64)

    def time_ordered(self, parts: list[tuple[int, int]], out: np.ndarray | None = None) -> np.ndarray:
        """The events in the (offset, count) parts of the buffer, ordered by time, ties by emission
        index (= y, then x: parts are in row order and their keys carry the offset), written into
        `out` (as many events as the parts hold) or a new array."""
        starts = np.array([o for o, _ in parts], np.int64)
        counts = np.array([n for _, n in parts], np.int64)
        if out is None:
            out = np.empty(int(counts.sum()), EVENT_DTYPE)
        _time_ordered_words(self.words, self.keys, starts, counts, out.view(np.uint64))
        return out
