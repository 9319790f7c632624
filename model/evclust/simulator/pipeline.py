"""Frames in, sorted colour events out: observe -> detect (compiled) -> interval effects -> stream effects."""

from __future__ import annotations

import dataclasses
import time
from typing import Iterable

import numpy as np
from tqdm import tqdm

from evclust.colour import RGB_TO_YCBCR, frame_to_luma
from evclust.errors import EvclustError
from evclust.events.format import EventMeta, concat_events, sort_events
from evclust.scenes.schema import SensorSpec
from evclust.simulator.effects import Effect, Interval, SensorGeometry
from evclust.simulator.kernel import EventBuffer, detect_interval


@dataclasses.dataclass
class Simulation:
    events: np.ndarray | None  # None when the events went to a file as they were made
    meta: EventMeta
    samples: int  # views the sensor saw: frames, or frames and the sub-steps between them
    sample_period_us: float
    wall_s: float
    count: int | None = None  # the number of events, when `events` is None

    @property
    def n_events(self) -> int:
        return len(self.events) if self.events is not None else int(self.count or 0)

    @property
    def scene_s(self) -> float:
        return max(self.samples - 1, 0) * self.sample_period_us / 1e6

    @property
    def frames(self) -> int:
        """Scene frames covered (the sub-steps between frames are not counted)."""
        if self.samples == 0:
            return 0
        return int(round(self.scene_s * 1e6 / (self.meta.t_frame_us or self.sample_period_us))) + 1

    def summary(self) -> str:
        n = self.n_events
        rate = n / self.scene_s if self.scene_s > 0 else 0.0
        return (
            f"{self.meta.source}: {self.frames} frames, {n} events, "
            f"{rate:.4g} events/s of scene time, wall time {self.wall_s:.2f} s"
        )


def _stage(effects: list[Effect], stage: str) -> list[Effect]:
    return [e for e in effects if e.stage == stage]


def _join_at_boundary(previous: np.ndarray, current: np.ndarray) -> None:
    """Re-order, in place, events of two consecutive intervals that fall on the same microsecond.

    Each interval is ordered on its own; only events rounded to the boundary's microsecond can be
    out of (t, y, x) order across it, so only those are sorted again.
    """
    if previous.size == 0 or current.size == 0 or current["t"][0] > previous["t"][-1]:
        return
    t = previous["t"][-1]
    lo = int(np.searchsorted(previous["t"], t))
    hi = int(np.searchsorted(current["t"], t, side="right"))
    tied = concat_events([previous[lo:], current[:hi]])
    tied = tied[np.lexsort((tied["x"], tied["y"]))]
    previous[lo:] = tied[: previous.size - lo]
    current[:hi] = tied[previous.size - lo :]


class Simulator:
    """The sensor model of SPEC §3 with the effects a scene switched on."""

    def __init__(self, sensor: SensorSpec, geometry: SensorGeometry, effects: list[Effect] = ()):
        self.sensor = sensor
        self.geometry = geometry
        self.effects = list(effects)
        observers = _stage(self.effects, "observe")
        if len(observers) > 1:
            raise ValueError("at most one effect may replace how frames are observed")
        self.observer = observers[0] if observers else None
        transfer = _stage(self.effects, "transfer")
        if transfer and sensor.detector != "log":
            raise EvclustError(f"effects.{transfer[0].name}: it bends the log detector's curve; set sensor.detector = \"log\"")
        self.transfer = transfer[0] if transfer else None
        self.photoreceptor = _stage(self.effects, "photoreceptor")
        self.interval_effects = _stage(self.effects, "interval")
        self.stream_effects = _stage(self.effects, "stream")
        mismatch = _stage(self.effects, "thresholds")
        if mismatch:
            on, off = mismatch[0].thresholds(sensor.threshold_on, sensor.threshold_off)
            self.th_on, self.th_off, self.th_stride = on.astype(np.float64), off.astype(np.float64), 1
        else:
            self.th_on = np.array([sensor.threshold_on], dtype=np.float64)
            self.th_off = np.array([sensor.threshold_off], dtype=np.float64)
            self.th_stride = 0
        n_pixels = geometry.width * geometry.height
        self.buffer = EventBuffer(max(1 << 16, n_pixels // 2))

    def _observe(self, rgb: np.ndarray, level: np.ndarray) -> np.ndarray:
        """Fill `level` (flat float32) with the detector input L; return the (H*W, 3) float32 RGB
        the pixels measure colour from."""
        if self.observer is not None:
            intensity, rgb = self.observer.observe(rgb)
        else:
            intensity = frame_to_luma(rgb)
        intensity = np.asarray(intensity, dtype=np.float32).reshape(-1)
        if self.transfer is not None:
            self.transfer.transfer(intensity, level, self.sensor.log_eps)
        elif self.sensor.detector == "log":
            np.add(intensity, np.float32(self.sensor.log_eps), out=level)
            np.log(level, out=level)
        else:
            level[:] = intensity
        for effect in self.photoreceptor:
            effect.photoreceptor(level, intensity)
        return np.ascontiguousarray(rgb, dtype=np.float32).reshape(-1, 3)

    def _detect(self, l0, l1, rgb0, rgb1, ref, t0_us: float) -> np.ndarray:
        """The events of one frame interval, ordered by (t, y, x)."""
        buf = self.buffer
        chunks = []
        pixel = 0
        while pixel < l0.size:
            n, pixel = detect_interval(
                l0, l1, rgb0, rgb1, ref, self.th_on, self.th_off, self.th_stride, self.geometry.width,
                t0_us, self.geometry.t_sample_us, pixel, buf.words, buf.keys, RGB_TO_YCBCR,
            )  # fmt: skip
            if n == 0 and pixel < l0.size:  # one pixel crosses more levels than the buffer holds
                self.buffer = buf = EventBuffer(2 * buf.keys.size)
                continue
            chunks.append(buf.time_ordered(n))
        if len(chunks) == 1:
            return chunks[0]
        # The buffer filled up: each chunk is in order on its own, their union is not.
        return sort_events(concat_events(chunks))

    def stream(
        self,
        frames: Iterable[np.ndarray],
        source: str = "",
        total: int | None = None,
        progress: bool = False,
        frame_period_us: float | None = None,
    ) -> "SimulationStream":
        """Simulate the sensor over `frames`, sampled every geometry.t_sample_us, yielding the
        events interval by interval (iterate the returned stream; its `meta` is known at once).
        `frame_period_us` is the scene's frame period recorded in the metadata (velocities are per
        frame); by default the sampling period. Stream effects see the whole stream, so with one on,
        the events come out at the end, in one piece."""
        g = self.geometry
        meta = EventMeta(width=g.width, height=g.height, source=source, t_frame_us=frame_period_us or g.t_sample_us)
        return SimulationStream(self, frames, meta, total, progress)

    def run(self, frames: Iterable[np.ndarray], source: str = "", total: int | None = None, progress: bool = False,
            frame_period_us: float | None = None) -> Simulation:  # fmt: skip
        """The whole stream in memory: `stream` joined."""
        stream = self.stream(frames, source, total, progress, frame_period_us)
        events = concat_events(stream)
        return Simulation(events, stream.meta, stream.samples, self.geometry.t_sample_us, stream.wall_s)

    def _intervals(self, frames: Iterable[np.ndarray], total: int | None, progress: bool, counter: list[int]):
        """The sorted events of each frame interval, as the interval effects leave them."""
        g = self.geometry
        shape = (g.height, g.width, 3)
        # Two detector-input buffers used in turn: frame k's and frame k-1's.
        levels = [np.empty(g.width * g.height, np.float32) for _ in range(2)]
        ref = rgb_prev = None
        for k, rgb in enumerate(tqdm(frames, total=total, unit="frame", disable=None if progress else True, desc="simulate")):
            if rgb.shape[:2] != (g.height, g.width):
                raise ValueError(f"frame {k} is {rgb.shape[1]}x{rgb.shape[0]}, the sensor is {g.width}x{g.height}")
            counter[0] = k + 1
            level, l_prev = levels[k % 2], levels[(k + 1) % 2]
            colour = self._observe(rgb, level)
            if ref is None:
                ref = level.astype(np.float64)  # the reference starts at the first frame: no events
            else:
                t0 = (k - 1) * g.t_sample_us
                events = self._detect(l_prev, level, rgb_prev, colour, ref, t0)
                for effect in self.interval_effects:
                    events = effect.interval(events, Interval(k, t0, t0 + g.t_sample_us, rgb_prev.reshape(shape), colour.reshape(shape)))
                yield events
            rgb_prev = colour


class SimulationStream:
    """The events of a simulation as they are made: iterate it for chunks in stream order.

    Each interval is held back until the next is made, because events that round to the same
    microsecond at the boundary may need re-ordering across the two (`_join_at_boundary`).
    After iteration, `samples` and `wall_s` describe the run.
    """

    def __init__(self, simulator: Simulator, frames, meta: EventMeta, total: int | None, progress: bool):
        self.simulator, self.frames, self.meta = simulator, frames, meta
        self.total, self.progress = total, progress
        self.samples = 0
        self.wall_s = 0.0

    @property
    def sample_period_us(self) -> float:
        return self.simulator.geometry.t_sample_us

    def __iter__(self):
        start = time.perf_counter()
        counter = [0]
        sim = self.simulator
        intervals = sim._intervals(self.frames, self.total, self.progress, counter)
        try:
            if sim.stream_effects:
                events = _joined(intervals)
                for effect in sim.stream_effects:
                    events = effect.stream(events)
                if events.size:
                    yield events
                return
            held = None
            for events in intervals:
                if held is not None:
                    _join_at_boundary(held, events)
                    if held.size:
                        yield held
                held = events
            if held is not None and held.size:
                yield held
        finally:
            self.samples = counter[0]
            self.wall_s = time.perf_counter() - start


def _joined(intervals) -> np.ndarray:
    chunks = []
    for events in intervals:
        if chunks:
            _join_at_boundary(chunks[-1], events)
        chunks.append(events)
    return concat_events(chunks)
