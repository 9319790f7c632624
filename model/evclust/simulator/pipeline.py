"""Frames in, sorted colour events out: observe -> detect (compiled) -> interval effects -> stream effects."""

from __future__ import annotations

import dataclasses
import time
from typing import Iterable

import numpy as np
from tqdm import tqdm

from evclust.colour import frame_to_ycbcr
from evclust.events.format import EVENT_DTYPE, EventMeta
from evclust.scenes.schema import SensorSpec
from evclust.simulator.effects import Effect, Interval, SensorGeometry
from evclust.simulator.kernel import detect_interval


@dataclasses.dataclass
class Simulation:
    events: np.ndarray
    meta: EventMeta
    frames: int
    wall_s: float

    @property
    def scene_s(self) -> float:
        return max(self.frames - 1, 0) * (self.meta.t_frame_us or 0.0) / 1e6

    def summary(self) -> str:
        n = len(self.events)
        rate = n / self.scene_s if self.scene_s > 0 else 0.0
        return (
            f"{self.meta.source}: {self.frames} frames, {n} events, "
            f"{rate:.4g} events/s of scene time, wall time {self.wall_s:.2f} s"
        )


def _stage(effects: list[Effect], stage: str) -> list[Effect]:
    return [e for e in effects if e.stage == stage]


def _in_order(ev: np.ndarray) -> bool:
    if ev.size < 2:
        return True
    t = ev["t"]
    key = ev["y"].astype(np.int64) * 65536 + ev["x"]
    return bool(np.all((t[1:] > t[:-1]) | ((t[1:] == t[:-1]) & (key[1:] >= key[:-1]))))


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
        self.buffer = np.empty(max(1 << 16, n_pixels // 2), dtype=EVENT_DTYPE)

    def _observe(self, rgb: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Detector input L (flat float32) and colour planes (H*W, 3) float32 of one frame."""
        if self.observer is not None:
            intensity, ycc = self.observer.observe(rgb)
        else:
            ycc = frame_to_ycbcr(rgb)
            intensity = ycc[..., 0]
        intensity = np.ascontiguousarray(intensity, dtype=np.float32).reshape(-1)
        if self.sensor.detector == "log":
            level = np.log(intensity + np.float32(self.sensor.log_eps))
        else:
            level = intensity
        return level, ycc.reshape(-1, 3)

    def _detect(self, l0, l1, c0, c1, ref, t0_us: float) -> np.ndarray:
        buf = self.buffer
        chunks = []
        pixel = 0
        while pixel < l0.size:
            n, pixel = detect_interval(
                l0, l1, c0, c1, ref, self.th_on, self.th_off, self.th_stride, self.geometry.width,
                t0_us, self.geometry.t_frame_us, pixel,
                buf["t"], buf["x"], buf["y"], buf["p"], buf["Y"], buf["Cb"], buf["Cr"],
            )  # fmt: skip
            chunks.append(buf[:n].copy())
        events = chunks[0] if len(chunks) == 1 else np.concatenate(chunks)
        return events[np.argsort(events["t"], kind="stable")]

    def run(self, frames: Iterable[np.ndarray], source: str = "", total: int | None = None, progress: bool = False) -> Simulation:
        start = time.perf_counter()
        g = self.geometry
        chunks = []
        ref = l_prev = c_prev = None
        k = -1
        for k, rgb in enumerate(tqdm(frames, total=total, unit="frame", disable=not progress, desc="simulate")):
            if rgb.shape[:2] != (g.height, g.width):
                raise ValueError(f"frame {k} is {rgb.shape[1]}x{rgb.shape[0]}, the sensor is {g.width}x{g.height}")
            level, ycc = self._observe(rgb)
            if ref is None:
                ref = level.astype(np.float64)  # the reference starts at the first frame: no events
            else:
                t0 = (k - 1) * g.t_frame_us
                events = self._detect(l_prev, level, c_prev, ycc, ref, t0)
                for effect in self.interval_effects:
                    events = effect.interval(events, Interval(k, t0, t0 + g.t_frame_us, c_prev.reshape(g.height, g.width, 3), ycc.reshape(g.height, g.width, 3)))
                chunks.append(events)
            l_prev, c_prev = level, ycc
        events = np.concatenate(chunks) if chunks else np.zeros(0, EVENT_DTYPE)
        if not _in_order(events):  # equal microseconds on both sides of a frame boundary
            events = events[np.lexsort((events["x"], events["y"], events["t"]))]
        for effect in self.stream_effects:
            events = effect.stream(events)
        meta = EventMeta(width=g.width, height=g.height, source=source, t_frame_us=g.t_frame_us)
        return Simulation(events, meta, k + 1, time.perf_counter() - start)
