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
def _byte(v):
    return np.uint64(np.int64(min(max(v, 0.0), 255.0) + 0.5))


@njit(cache=True, nogil=True, boundscheck=False)
def detect_interval(l0, l1, rgb0, rgb1, ref, th_on, th_off, th_stride, width, t0_us, dt_us, first_pixel, words, m):
    """Emit the events of pixels first_pixel.. as packed records into `words` (2 per event), in
    emission order: row-major, each pixel's events in time order.

    Returns (events written, next pixel to visit). The next pixel is l0.size when the interval is
    done; otherwise the buffer is full, and the caller empties it and calls again from there.
    `m` is the RGB -> YCbCr matrix (an argument, not a global: numba's disk cache freezes globals).
    """
    capacity = words.size // 2
    # The matrix's entries as locals: the compiler cannot tell that the event writes leave m alone.
    # Each YCbCr value is summed in the order m[r,0]·R + m[r,1]·G + m[r,2]·B + m[r,3].
    y_r, y_g, y_b, y_0 = m[0, 0], m[0, 1], m[0, 2], m[0, 3]
    cb_r, cb_g, cb_b, cb_0 = m[1, 0], m[1, 1], m[1, 2], m[1, 3]
    cr_r, cr_g, cr_b, cr_0 = m[2, 0], m[2, 1], m[2, 2], m[2, 3]
    end = l0.size
    n = 0
    for y in range(first_pixel // width, (end + width - 1) // width):  # rows, so no pixel divides
        row = y * width
        row_bits = np.uint64(y) << np.uint64(16)
        for i in range(max(row, first_pixel), min(row + width, end)):
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
            address = np.uint64(i - row) | row_bits | polarity_bits
            # YCbCr is linear in RGB: convert the pixel's two frames once, interpolate per event.
            r0, g0, b0 = rgb0[i, 0], rgb0[i, 1], rgb0[i, 2]
            r1, g1, b1 = rgb1[i, 0], rgb1[i, 1], rgb1[i, 2]
            lum0 = y_r * r0 + y_g * g0 + y_b * b0 + y_0
            cb0 = cb_r * r0 + cb_g * g0 + cb_b * b0 + cb_0
            cr0 = cr_r * r0 + cr_g * g0 + cr_b * b0 + cr_0
            d_lum = (y_r * r1 + y_g * g1 + y_b * b1 + y_0) - lum0
            d_cb = (cb_r * r1 + cb_g * g1 + cb_b * b1 + cb_0) - cb0
            d_cr = (cr_r * r1 + cr_g * g1 + cr_b * b1 + cr_0) - cr0
            for j in range(1, count + 1):
                frac = min(max((r + j * step - start) * inv_span, 0.0), 1.0)
                words[2 * n] = np.uint64(np.int64(t0_us + frac * dt_us + 0.5))
                words[2 * n + 1] = (
                    address
                    | (_byte(lum0 + frac * d_lum) << np.uint64(40))
                    | (_byte(cb0 + frac * d_cb) << np.uint64(48))
                    | (_byte(cr0 + frac * d_cr) << np.uint64(56))
                )
                n += 1
            ref[i] = r + count * step
    return n, end


@njit(cache=True, nogil=True)
def _offset_bound(t0_us, dt_us):
    """The largest t - floor(t0) an event of the interval can have: the kernel's own expression at
    frac = 1 (each of its steps is monotonic in frac, and frac <= 1)."""
    return np.int64(t0_us + 1.0 * dt_us + 0.5) - np.int64(np.floor(t0_us))


@njit(cache=True, nogil=True, boundscheck=False)
def _time_ordered_words(words, starts, counts, t0_us, dt_us, out):
    """Write the packed records of the buffer parts (starts[p], counts[p]) into `out` in order of
    time, ties in part-then-buffer (= emission) order.

    A stable counting sort on t - floor(t0), read from each record's first word, gives exactly
    that in two passes; an interval so long that its histogram would outweigh its events sorts
    (offset, position) keys instead."""
    total = 0
    for p in range(starts.size):
        total += counts[p]
    t_base = np.uint64(np.floor(t0_us))
    bins = _offset_bound(t0_us, dt_us) + 1
    if bins > 4 * total + 65536:
        keys = np.empty(total, np.uint64)
        k = 0
        for p in range(starts.size):
            for j in range(starts[p], starts[p] + counts[p]):
                keys[k] = ((words[2 * j] - t_base) << np.uint64(32)) | np.uint64(j)
                k += 1
        keys.sort()
        for k in range(total):
            j = np.int64(keys[k] & np.uint64(0xFFFFFFFF))
            out[2 * k] = words[2 * j]
            out[2 * k + 1] = words[2 * j + 1]
        return
    next_slot = np.zeros(bins + 1, np.int64)  # events before each time offset, then where the next goes
    for p in range(starts.size):
        for j in range(starts[p], starts[p] + counts[p]):
            next_slot[np.int64(words[2 * j] - t_base) + 1] += 1
    for b in range(bins):
        next_slot[b + 1] += next_slot[b]
    for p in range(starts.size):
        for j in range(starts[p], starts[p] + counts[p]):
            b = np.int64(words[2 * j] - t_base)
            k = next_slot[b]
            next_slot[b] = k + 1
            out[2 * k] = words[2 * j]
            out[2 * k + 1] = words[2 * j + 1]


@njit(cache=True, nogil=True, boundscheck=False)
def join_at_boundary(previous, current):
    """Re-order, in place, the records of two consecutive intervals ((n, 2) uint64 words each) that
    fall on the boundary's microsecond: the last of `previous` and the first of `current` with
    that time, put in (y, x) order, stably. Each interval is ordered on its own; only those can be
    out of (t, y, x) order across the boundary."""
    if previous.shape[0] == 0 or current.shape[0] == 0:
        return
    t = previous[previous.shape[0] - 1, 0]
    if current[0, 0] > t:
        return
    lo = previous.shape[0] - 1
    while lo > 0 and previous[lo - 1, 0] == t:
        lo -= 1
    hi = 0
    while hi < current.shape[0] and current[hi, 0] <= t:
        hi += 1
    n_prev = previous.shape[0] - lo
    tied = np.empty((n_prev + hi, 2), np.uint64)
    tied[:n_prev] = previous[lo:]
    tied[n_prev:] = current[:hi]
    order = np.argsort(tied[:, 1] & np.uint64(0xFFFFFFFF), kind="mergesort")  # word 1's low half is y << 16 | x
    for k in range(n_prev + hi):
        row = tied[order[k]]
        if k < n_prev:
            previous[lo + k] = row
        else:
            current[k - n_prev] = row


class EventBuffer:
    """Room for the events of one call of detect_interval."""

    def __init__(self, capacity: int):
        self.capacity = capacity
        self.words = np.empty(2 * capacity, np.uint64)

    def time_ordered(self, parts: list[tuple[int, int]], t0_us: float, dt_us: float, out: np.ndarray | None = None) -> np.ndarray:
        """The events in the (offset, count) parts of the buffer, made in the interval from t0_us
        lasting dt_us, ordered by time, ties by part and then emission index (= y, then x: parts
        are in row order), written into `out` (as many events as the parts hold) or a new array."""
        starts = np.array([o for o, _ in parts], np.int64)
        counts = np.array([n for _, n in parts], np.int64)
        if out is None:
            out = np.empty(int(counts.sum()), EVENT_DTYPE)
        _time_ordered_words(self.words, starts, counts, float(t0_us), float(dt_us), out.view(np.uint64))
        return out
