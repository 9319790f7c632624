"""Random event streams for model-in-the-loop co-simulation: moving coloured blobs over noise,
with the stream's hard parts mixed in (bursts at one microsecond, gaps of seconds, border
hugging, and more objects than a small table holds)."""

from __future__ import annotations

import numpy as np

from evclust.events import EVENT_DTYPE


def random_stream(seed: int, count: int, width: int, height: int, t_frame_us: float, mean_dt_us: float = 80.0) -> np.ndarray:
    """`count` events, reproducible from `seed`, in time order. Blobs move at 1.5 to 6 px/frame
    and the event rate keeps each above a typical reporting activity, so the clusterer creates,
    reports, evicts and loses clusters."""
    rng = np.random.default_rng(seed)
    n_blobs = int(rng.integers(2, 6))
    centre = rng.uniform([0, 0], [width - 1, height - 1], (n_blobs, 2))
    heading = rng.uniform(0, 2 * np.pi, n_blobs)
    speed = rng.uniform(1.5, 6.0, n_blobs) / t_frame_us  # px/us
    velocity = np.stack([np.cos(heading), np.sin(heading)], axis=1) * speed[:, None]
    radius = rng.uniform(2.0, max(3.0, min(width, height) / 8), n_blobs)
    colour = rng.integers(0, 256, (n_blobs, 3))
    dt = rng.exponential(mean_dt_us, count).astype(np.int64)
    dt[rng.random(count) < 0.05] = 0  # bursts: same microsecond
    dt[rng.random(count) < 0.0005] += rng.integers(1_000_000, 3_000_000)  # gaps of seconds
    t = 1000 + np.cumsum(dt)
    events = np.zeros(count, EVENT_DTYPE)
    events["t"] = t
    which = rng.integers(0, n_blobs, count)
    noise = rng.random(count) < 0.05
    where = centre[which] + velocity[which] * (t - t[0])[:, None]
    where = np.abs(np.mod(where, 2 * np.array([width - 1, height - 1])) - np.array([width - 1, height - 1]))  # bounce
    offset = rng.uniform(-1, 1, (count, 2)) * radius[which][:, None]
    xy = np.rint(where + offset)
    xy[noise] = rng.uniform([0, 0], [width - 1, height - 1], (int(noise.sum()), 2))
    events["x"] = np.clip(xy[:, 0], 0, width - 1)
    events["y"] = np.clip(xy[:, 1], 0, height - 1)
    events["p"] = np.where(rng.random(count) < 0.5, 1, -1)
    ycc = colour[which] + rng.integers(-6, 7, (count, 3))
    ycc[noise] = rng.integers(0, 256, (int(noise.sum()), 3))
    ycc = np.clip(ycc, 0, 255)
    events["Y"], events["Cb"], events["Cr"] = ycc[:, 0], ycc[:, 1], ycc[:, 2]
    return events
