"""Frames in, sorted colour events out: observe -> detect (compiled) -> interval effects -> stream effects."""

from __future__ import annotations

import dataclasses
import mmap
import queue
import contextlib
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from collections.abc import Iterable

import numpy as np
from tqdm import tqdm

from evclust.colour import RGB_TO_YCBCR, frame_to_luma
from evclust.errors import EvclustError
from evclust.events.format import EVENT_DTYPE, EventMeta, concat_events, empty_events, sort_events
from evclust.scenes.schema import SensorSpec
from evclust.simulator.effects import Effect, Interval, SensorGeometry
from evclust.simulator.kernel import EventBuffer, detect_interval, join_at_boundary
from evclust.threads import stopped_on_interrupt, worker_threads


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
        return f"{self.meta.source}: {self.frames} frames, {n} events, {rate:.4g} events/s of scene time, wall time {self.wall_s:.2f} s"


def _stage(effects: list[Effect], stage: str) -> list[Effect]:
    return [e for e in effects if e.stage == stage]


def _join_at_boundary(previous: np.ndarray, current: np.ndarray) -> None:
    """Re-order, in place, events of two consecutive intervals that fall on the same microsecond
    (`kernel.join_at_boundary`, on the records' raw words)."""
    join_at_boundary(_words(previous), _words(current))


def _words(events: np.ndarray) -> np.ndarray:
    """An event array's records as (n, 2) uint64 words, in place (a copy would not write back)."""
    if not events.flags.c_contiguous:
        raise ValueError("event records must be contiguous to be re-ordered in place")
    return events.view(np.uint64).reshape(-1, 2)


class _EventArena:
    """A run's events, written in place interval after interval (`Simulator.run` with no interval or
    stream effect), so a run makes no array per interval and no copy at the end.

    Room is reserved in large blocks that never move, so every view handed out stays valid; the
    pages the events never reach are never touched and cost address space only.

    A block is an anonymous mapping of ordinary 4 KiB pages, not a numpy allocation: numpy asks
    the kernel for transparent huge pages on any array over 4 MB, and where THP is in "madvise"
    mode (Debian's and Ubuntu's default) each first write to a 2 MB page may compact memory to find
    one. Events are written once, front to back, and gain nothing from huge pages
    (docs/DESIGN.md, "The event arena's pages")."""

    BLOCK_EVENTS = 1 << 26  # 1 GiB of address space

    def __init__(self):
        self.blocks: list[np.ndarray] = []
        self.filled: list[int] = []

    @staticmethod
    def _block(n: int) -> np.ndarray:
        return np.frombuffer(mmap.mmap(-1, n * EVENT_DTYPE.itemsize), EVENT_DTYPE)  # the array keeps the mapping

    def take(self, n: int) -> np.ndarray:
        if not self.blocks or self.filled[-1] + n > self.blocks[-1].size:
            try:
                self.blocks.append(self._block(max(n, self.BLOCK_EVENTS)))
            except (MemoryError, OSError):  # strict overcommit: reserve what is needed now, and more later
                self.blocks.append(self._block(max(n, 1 << 20)))
            self.filled.append(0)
        start = self.filled[-1]
        self.filled[-1] += n
        return self.blocks[-1][start : start + n]

    def events(self) -> np.ndarray:
        parts = [block[:filled] for block, filled in zip(self.blocks, self.filled)]
        if not parts:
            return empty_events()
        return parts[0] if len(parts) == 1 else concat_events(parts)  # a single block: no copy


class Simulator:
    """The sensor model of SPEC §3 with the effects a scene switched on."""

    def __init__(self, sensor: SensorSpec, geometry: SensorGeometry, effects: list[Effect] = (), threads: int | None = None):
        """`threads`: pixel bands detected in parallel (default: EVCLUST_THREADS, else the cores).
        The events are the same for any number."""
        self.sensor = sensor
        self.geometry = geometry
        self.effects = list(effects)
        observers = _stage(self.effects, "observe")
        if len(observers) > 1:
            raise ValueError("at most one effect may replace how frames are observed")
        self.observer = observers[0] if observers else None
        transfer = _stage(self.effects, "transfer")
        if transfer and sensor.detector != "log":
            raise EvclustError(f'effects.{transfer[0].name}: it bends the log detector\'s curve; set sensor.detector = "log"')
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
        threads = threads or worker_threads()
        # Bands of whole rows, one per thread; a frame too small to be worth splitting stays whole.
        n_bands = max(1, min(threads, geometry.height, n_pixels // (1 << 15)))
        self._set_bands(np.linspace(0, geometry.height, n_bands + 1).round().astype(int))
        self.buffer = EventBuffer(max(1 << 16, n_pixels // 2))
        self.pool = ThreadPoolExecutor(len(self.bands)) if len(self.bands) > 1 else None
        self._arena: _EventArena | None = None
        self._luma_room: tuple[np.ndarray, np.ndarray] | None = None  # frame_to_luma's, reused frame to frame

    def _observe(self, rgb: np.ndarray, level: np.ndarray) -> np.ndarray:
        """Fill `level` (flat float32) with the detector input L; return the (H*W, 3) RGB the
        pixels measure colour from: float32, or a decoded frame's own uint8 where nothing else reads
        it (the detector takes either; a uint8 value is exact in both)."""
        if self.observer is not None:
            intensity, rgb = self.observer.observe(rgb)
        else:
            if self._luma_room is None or self._luma_room[1].shape != rgb.shape[:2]:
                self._luma_room = (np.empty(rgb.shape, np.float32), np.empty(rgb.shape[:2], np.float32))
            intensity = frame_to_luma(rgb, *self._luma_room)  # read before the next frame comes
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
        if rgb.dtype == np.uint8 and not self.interval_effects:  # interval effects read float32
            return np.ascontiguousarray(rgb).reshape(-1, 3)
        return np.ascontiguousarray(rgb, dtype=np.float32).reshape(-1, 3)

    def _detect(self, l0, l1, rgb0, rgb1, ref, t0_us: float) -> np.ndarray:
        """The events of one frame interval, ordered by (t, y, x).

        Each band of rows runs on its own thread (the kernel releases the GIL) into its own part
        of one buffer. The parts, taken in band order, then still hold the events in row-major
        emission order, so one stable sort by time gives the same stream as a single thread."""
        buf = self.buffer
        share = buf.capacity // len(self.bands)

        def band(b):
            lo, hi = self.bands[b]
            return self._kernel(l0, l1, rgb0, rgb1, ref, t0_us, lo, hi, b * share, share)

        results = list(self.pool.map(band, range(len(self.bands)))) if self.pool else [band(0)]
        parts = [(b * share, n) for b, (n, _) in enumerate(results)]
        if all(pixel == hi for (_, pixel), (_, hi) in zip(results, self.bands)):  # every band had room: the usual case
            events = buf.time_ordered(parts, t0_us, self.geometry.t_sample_us, self._room(sum(n for _, n in parts)))
        else:
            chunks = [buf.time_ordered(parts, t0_us, self.geometry.t_sample_us)]
            for b, (_, pixel) in enumerate(results):  # a band that filled its share goes on alone
                hi = self.bands[b][1]
                while pixel < hi:
                    n, pixel = self._kernel(l0, l1, rgb0, rgb1, ref, t0_us, pixel, hi, 0, self.buffer.capacity)
                    if n == 0 and pixel < hi:  # one pixel crosses more levels than the buffer holds
                        self.buffer = EventBuffer(2 * self.buffer.capacity)
                        continue
                    chunks.append(self.buffer.time_ordered([(0, n)], t0_us, self.geometry.t_sample_us))
            joined = sort_events(concat_events(chunks))  # each chunk is in order, not their union
            events = self._room(joined.size)
            events.view(np.uint64)[:] = joined.view(np.uint64)  # as raw words: a record-wise copy is slow
        if self.pool:
            self._balance(events)
        return events

    def _room(self, n: int) -> np.ndarray:
        """Where the next n ordered events go: the run's arena (`run`), or an array of their own."""
        return self._arena.take(n) if self._arena is not None else np.empty(n, EVENT_DTYPE)

    def _kernel(self, l0, l1, rgb0, rgb1, ref, t0_us, first, end, offset, room) -> tuple[int, int]:
        """Detect pixels first..end-1 into buffer slots offset..offset+room-1: (events, next pixel)."""
        buf = self.buffer
        return detect_interval(
            l0[:end], l1[:end], rgb0[:end], rgb1[:end], ref[:end], self.th_on, self.th_off, self.th_stride,
            self.geometry.width, t0_us, self.geometry.t_sample_us, first, buf.words[2 * offset : 2 * (offset + room)],
            RGB_TO_YCBCR,
        )  # fmt: skip

    def _set_bands(self, rows: np.ndarray) -> None:
        w = self.geometry.width
        self.bands = [(int(a) * w, int(b) * w) for a, b in zip(rows[:-1], rows[1:])]  # pixel ranges

    def _balance(self, events: np.ndarray) -> None:
        """Move the band limits so each band would have held an equal share of this interval's
        events: consecutive frames are alike, and events crowd where objects are, not evenly."""
        if events.size < 1000:
            return
        per_row = np.cumsum(np.bincount(events["y"], minlength=self.geometry.height))
        n_bands = len(self.bands)
        cuts = np.searchsorted(per_row, per_row[-1] * np.arange(1, n_bands) / n_bands) + 1
        rows = np.concatenate([[0], cuts, [self.geometry.height]])
        rows = np.maximum.accumulate(np.minimum(rows, self.geometry.height))
        if np.all(np.diff(rows) > 0):  # every band keeps at least one row
            self._set_bands(rows)

    def stream(
        self,
        frames: Iterable[np.ndarray],
        source: str = "",
        total: int | None = None,
        progress: bool = False,
        frame_period_us: float | None = None,
    ) -> SimulationStream:
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
        if self.interval_effects or self.stream_effects:  # they make new arrays of their own
            events = concat_events(stream)
        else:
            self._arena = _EventArena()
            try:
                for _ in stream:  # each interval is made in place, in order, after the one before
                    pass
                events = self._arena.events()
            finally:
                self._arena = None
        return Simulation(events, stream.meta, stream.samples, self.geometry.t_sample_us, stream.wall_s)

    def _observed(self, frames: Iterable[np.ndarray]):
        """(detector input L, measured colour) of each frame, in order."""
        g = self.geometry
        for k, rgb in enumerate(frames):
            if rgb.shape[:2] != (g.height, g.width):
                raise ValueError(f"frame {k} is {rgb.shape[1]}x{rgb.shape[0]}, the sensor is {g.width}x{g.height}")
            level = np.empty(g.width * g.height, np.float32)
            yield level, self._observe(rgb, level)

    def _intervals(self, frames: Iterable[np.ndarray], total: int | None, progress: bool, counter: list[int]):
        """The sorted events of each frame interval, as the interval effects leave them."""
        g = self.geometry
        shape = (g.height, g.width, 3)
        observed = self._observed(frames)
        if self.pool is not None:  # decode and observe the next frames while this one is detected
            observed = _prefetched(observed)
        ref = l_prev = rgb_prev = None
        # Closed here, not when the garbage collector gets to it: an interrupted run stops the
        # reader thread before the interpreter exits, never while the thread is inside OpenCV.
        with contextlib.closing(observed):
            bar = tqdm(observed, total=total, unit="frame", disable=None if progress else True, desc="simulate")
            for k, (level, colour) in enumerate(bar):
                counter[0] = k + 1
                if ref is None:
                    ref = level.astype(np.float64)  # the reference starts at the first frame: no events
                else:
                    t0 = (k - 1) * g.t_sample_us
                    events = self._detect(l_prev, level, rgb_prev, colour, ref, t0)
                    for effect in self.interval_effects:
                        events = effect.interval(
                            events, Interval(k, t0, t0 + g.t_sample_us, rgb_prev.reshape(shape), colour.reshape(shape))
                        )
                    yield events
                l_prev, rgb_prev = level, colour


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


def _prefetched(frames: Iterable[np.ndarray], depth: int = 3):
    """`frames`, read ahead on a thread; an error of the reader is raised here, in order."""
    done = object()
    slots: queue.Queue = queue.Queue(depth)
    stop = threading.Event()

    def read():
        try:
            for frame in frames:
                if stop.is_set():
                    return
                slots.put(frame)
            slots.put(done)
        except BaseException as exc:  # handed to the consumer, which raises it
            slots.put(exc)

    def halt():
        stop.set()
        while reader.is_alive():  # let a reader blocked on a full queue finish
            try:
                slots.get_nowait()
            except queue.Empty:
                reader.join(0.01)

    reader = threading.Thread(target=read, daemon=True, name="evclust-frames")
    reader.start()
    forget = stopped_on_interrupt(halt)  # in case this generator is left suspended
    try:
        while (item := slots.get()) is not done:
            if isinstance(item, BaseException):
                raise item
            yield item
    finally:
        halt()
        forget()


def _joined(intervals) -> np.ndarray:
    chunks = []
    for events in intervals:
        if chunks:
            _join_at_boundary(chunks[-1], events)
        chunks.append(events)
    return concat_events(chunks)
