"""The vector cases: clips of built-in scenes and directed hard cases.

Each builder returns the events and what the run needs. Clip windows were found once by search
(the smallest clip from which the fixed model creates clusters and predicts an exit); the scenes
are deterministic, so the slices stay valid.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from evclust.clusterer import ClustererParams, PaletteEntry, load_params
from evclust.events import EVENT_DTYPE
from evclust.scenes import load_scene
from evclust.simulator import simulate_scene


@dataclasses.dataclass
class Case:
    description: str
    events: np.ndarray
    width: int
    height: int
    t_frame_us: float
    params: ClustererParams
    source: str
    seed: int = 0


def _events(rows) -> np.ndarray:
    ev = np.zeros(len(rows), EVENT_DTYPE)
    for i, row in enumerate(rows):
        t, x, y, lum, cb, cr = row
        ev[i] = (t, x, y, 1, lum, cb, cr)
    return ev


def _clip(scene: str, start: int, count: int, what: str) -> Case:
    sim = simulate_scene(load_scene(scene))
    params, _ = load_params(scene)
    return Case(
        f"{count} events of the built-in `{scene}` scene from event {start}: {what}",
        sim.events[start : start + count], sim.meta.width, sim.meta.height, sim.meta.t_frame_us, params, scene,
        load_scene(scene).spec.seed,
    )  # fmt: skip


SMALL = dict(width=64, height=48, t_frame_us=10_000.0)


def _small_params(**update) -> ClustererParams:
    base = dict(v_min=0.0, a_valid=3.0, filter_every=8, r_init=4.0, r_max=16.0, seek_margin=4.0, t_half_us=20_000.0, tau_us=20_000.0)
    return ClustererParams(**{**base, **update})


def traffic_clip() -> Case:
    return _clip("traffic", 134900, 12000, "creations, filter steps, reported tracks and an exit prediction")


def pedestrian_clip() -> Case:
    return _clip("pedestrian", 77778, 9000, "creations, filter steps, reported tracks and an exit prediction")


def timestamp_wrap() -> Case:
    # A blob drifting right; its timestamps cross 2^32 µs in the middle.
    rng = np.random.default_rng(11)
    t0 = (1 << 32) - 600 * 50
    rows = [(t0 + 50 * i, 10 + i // 40 + int(rng.integers(-2, 3)), 24 + int(rng.integers(-2, 3)), 180, 100, 150) for i in range(1200)]
    return Case("a drifting blob whose 32-bit timestamps wrap in the middle of the stream", _events(rows), **SMALL, params=_small_params(), source="directed")


def table_full() -> Case:
    # Six spots for a four-slot table: evictions while the old clusters are weak, drops once all are strong.
    spots = [(5, 5), (58, 5), (5, 42), (58, 42), (32, 24), (20, 30)]
    rows = []
    t = 1000
    for rnd in range(12):
        for j, (x, y) in enumerate(spots):
            for _ in range(3 + 2 * (j % 2) + rnd):
                rows.append((t, x, y, 200, 128, 128))
                t += 7
    return Case("six spots fighting for a four-slot table: creations, evictions and drops", _events(rows), **SMALL,
                params=_small_params(n_clusters=4, a_valid=6.0, t_half_us=2000.0), source="directed")  # fmt: skip


def saturating_corners() -> Case:
    corners = [(0, 0), (63, 0), (0, 47), (63, 47)]
    rows = [(1000 + 2 * i, *corners[i % 4], 255 * (i % 2), 255 * ((i // 2) % 2), 0) for i in range(2000)]
    return Case("events at the four corners with extreme colours", _events(rows), **SMALL, params=_small_params(), source="directed")


def one_pixel() -> Case:
    rows = [(1000 + (i // 10), 31, 23, 40 + (i % 200), 128, 128) for i in range(3000)]
    return Case("every event on one pixel, ten per microsecond", _events(rows), **SMALL, params=_small_params(), source="directed")


def bursts() -> Case:
    rows = []
    t = 1000
    for burst in range(10):
        rows += [(t, 20 + burst, 20, 200, 110, 140)] * 200  # 200 events with Δt = 0
        t += 5000
    return Case("bursts of 200 events at the same microsecond", _events(rows), **SMALL, params=_small_params(), source="directed")


def gaps() -> Case:
    rows = []
    t = 1000
    for k in range(6):
        rows += [(t + i, 30 + k, 20, 150, 128, 128) for i in range(64)]
        t += 3_000_000  # three seconds of silence
    return Case("clusters separated by gaps of three seconds", _events(rows), **SMALL, params=_small_params(), source="directed")


def borders() -> Case:
    rows = []
    t = 1000
    for i in range(1600):
        x = min(63, i // 20)  # a blob sliding along the top edge to the right border
        rows.append((t, x, int(i % 3), 220, 90, 170))
        t += 40
    return Case("a blob along the top border that leaves through the right border", _events(rows), **SMALL,
                params=_small_params(exit_margin=6.0, v_exit=0.2), source="directed")  # fmt: skip


def palette_tie() -> Case:
    palette = (PaletteEntry(name="low", rgb=(100, 100, 100)), PaletteEntry(name="high", rgb=(140, 140, 140)))
    rows = [(1000 + 5 * i, 30 + (i % 5), 20 + (i % 3), 120, 128, 128) for i in range(800)]  # Y = 120: equidistant
    return Case("event colours exactly between two palette entries: the tie goes to the lower index", _events(rows), **SMALL,
                params=_small_params(palette=palette, palette_assign="nearest", palette_vote="count", background=(0.0, 128.0, 128.0)),
                source="directed")  # fmt: skip


CASES = {
    "traffic_clip": traffic_clip,
    "pedestrian_clip": pedestrian_clip,
    "timestamp_wrap": timestamp_wrap,
    "table_full": table_full,
    "saturating_corners": saturating_corners,
    "one_pixel": one_pixel,
    "bursts": bursts,
    "gaps": gaps,
    "borders": borders,
    "palette_tie": palette_tie,
}
