"""Driving a clusterer model over an event stream: the three models (float, fixed, RTL) behind one
name, chunks, progress, the object layer that follows each, records and statistics. This sits
above the models (evclust.clusterer, evclust.fixed, evclust.rtl); none of them imports it."""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Iterable

import numpy as np
from tqdm import tqdm

from evclust.choices import FRAMELESS_PERIOD_US, TRACK_MODELS
from evclust.clusterer.params import ClustererParams
from evclust.clusterer.run import FloatClusterer, records_to_tracks, rows_to_records
from evclust.errors import EvclustError
from evclust.events import EVENT_DTYPE, EventMeta
from evclust.jit import compiled_code
from evclust.tracks import OBJECT_DTYPE, TRACK_DTYPE, VELOCITY_METHODS, TrackMeta

CHUNK = 1 << 18  # events per compiled call: the progress bar's granularity
STEPS_PER_FEED = 1 << 12  # filter steps per object-layer call in rerun_objects (its output buffer is per step)


@dataclasses.dataclass(frozen=True)
class Startup:
    """What a run spent before its first event: making the model's compiled loops ready."""

    seconds: float
    loaded: int  # specialisations taken from numba's disk cache
    compiled: int  # ... and compiled (a first run, or a changed source)
    ahead: int = 0  # functions that ran their ahead-of-time build (evclust.jit.ahead)

    def describe(self) -> str:
        parts = [f"{self.ahead} built ahead of time"] if self.ahead else []
        parts += [f"{self.compiled} compiled"] if self.compiled else []
        parts += [f"{self.loaded} loaded from numba's cache"] if self.loaded else []
        return f"compiled code ready in {self.seconds:.2f} s ({'; '.join(parts) or 'nothing to make'})"


@dataclasses.dataclass
class TrackRun:
    tracks: np.ndarray | None  # cluster records; None when they went to a sink as they came
    meta: TrackMeta
    stats: dict
    wall_s: float
    clusterer: object = None  # the model after the run: its state, and the fixed model's logs
    objects: np.ndarray | None = None  # object records (None: no object layer, or they went to a sink)
    object_meta: TrackMeta | None = None  # their metadata (None: no object layer)
    step_times: np.ndarray | None = None  # every filter step's time, records or not (None: records went to a sink)
    startup: Startup | None = None  # the compiled loops made ready, apart from wall_s (None: the RTL)

    @property
    def output(self) -> tuple[np.ndarray, TrackMeta]:
        """What the run reports: its object records when it has an object layer, else its cluster records."""
        return (self.objects, self.object_meta) if self.object_meta is not None else (self.tracks, self.meta)

    def summary(self) -> str:
        s = self.stats
        rate = s["events"] / self.wall_s if self.wall_s > 0 else float("inf")
        objects = ""
        if "object_records" in s:
            objects = f", {s['object_records']} object records"
            if "objects_created" in s:
                objects += f" ({s['objects_confirmed']} objects confirmed of {s['objects_created']} created)"
        return (
            f"{s['events']} events, {s['steps']} filter steps, {s['records']} cluster records{objects}, "
            f"{s['created']} clusters created ({s['evicted']} by eviction), {s['dropped']} events dropped, "
            f"event loop {self.wall_s:.2f} s, {rate / 1e6:.2f} Mevents/s" + (f"; {self.startup.describe()}" if self.startup else "")
        )


def _fixed_clusterer(*args, **kwargs):
    from evclust.fixed.model import FixedClusterer  # the fixed model reads the parameters' formats table

    return FixedClusterer(*args, **kwargs)


def _rtl_clusterer(*args, **kwargs):
    from evclust.rtl.session import RtlClusterer  # Verilator and cocotb: only when asked for

    return RtlClusterer(*args, **kwargs)


MODELS = dict(zip(TRACK_MODELS, (FloatClusterer, _fixed_clusterer, _rtl_clusterer)))  # names: evclust.choices, for the CLI


def _object_layer(clusterer, params: ClustererParams, model: str, width: int, height: int, t_frame_us: float):
    """The object layer that follows a clusterer model (None when the parameters switch it off):
    the float one, the fixed one, or the RTL's own object unit."""
    if not params.objects:
        return None
    if model == "float":
        from evclust.clusterer.objects import FloatObjects

        return FloatObjects(params, width, height, t_frame_us)
    return clusterer.object_layer()


def track_meta(params: ClustererParams, meta: EventMeta, model: str, t_frame_us: float) -> TrackMeta:
    """What a track file says about the run that wrote it."""
    return TrackMeta(
        width=meta.width,
        height=meta.height,
        t_frame_us=float(t_frame_us),
        source=meta.source,
        model=model,
        palette=params.palette_names,
        palette_ycbcr=tuple(tuple(float(c) for c in e) for e in params.palette_ycbcr()),
        palette_background=tuple(params.palette_background),
        luma_weight=params.luma_weight,
        seek_margin=params.seek_margin,
        seek_scale=params.seek_scale,
        exit_margin=params.exit_margin,
        has_colour=bool(meta.has_colour),
    )


def frameless(meta: EventMeta, params: ClustererParams) -> bool:
    """Whether a run on this stream takes its time constants at FRAMELESS_PERIOD_US."""
    return not (params.t_frame_us or meta.t_frame_us)


def at_frame_period(run: TrackRun, t_frame_us: float) -> TrackRun:
    """The run's records with their velocities in px per `t_frame_us` instead of per the run's own
    frame period, and their metadata saying so: a frameless run scored against a truth in px per
    frame of the scene."""
    scale = t_frame_us / run.meta.t_frame_us

    def convert(records, meta):
        if records is None or meta is None:
            return records, meta
        records = records.copy()
        for _, vx, vy in VELOCITY_METHODS[meta.kind]:
            records[vx] *= scale
            records[vy] *= scale
        return records, dataclasses.replace(meta, t_frame_us=float(t_frame_us))

    tracks, meta = convert(run.tracks, run.meta)
    objects, object_meta = convert(run.objects, run.object_meta)
    return dataclasses.replace(run, tracks=tracks, meta=meta, objects=objects, object_meta=object_meta)


def prepare_run(meta: EventMeta, params: ClustererParams, model: str) -> tuple[ClustererParams, TrackMeta]:
    """Check the model and the frame period; resolve the parameters; the track file's metadata."""
    if model not in MODELS:
        raise EvclustError(f"unknown model '{model}' (available: {', '.join(MODELS)})")
    t_frame_us = params.t_frame_us or meta.t_frame_us or FRAMELESS_PERIOD_US
    params = params.resolved(float(t_frame_us))
    return params, track_meta(params, meta, model, float(t_frame_us))


def track_stream(
    chunks: Iterable[np.ndarray],
    meta: EventMeta,
    params: ClustererParams,
    model: str = "float",
    progress: bool = False,
    total: int | None = None,
    sink: Callable[[np.ndarray], None] | None = None,
    object_sink: Callable[[np.ndarray], None] | None = None,
    **options,
) -> TrackRun:
    """Run a clusterer model, and its object layer when the parameters have one, over a stream
    given in chunks; `options` go to the model (fixed: ranges=True). With a `sink`, each
    chunk's cluster records go to it as they come and the run keeps none (`TrackRun.tracks` is
    None), so memory does not grow with the stream; `object_sink` does the same for the object
    records."""
    params, out_meta = prepare_run(meta, params, model)
    clusterer = MODELS[model](params, meta.width, meta.height, out_meta.t_frame_us, out_meta.has_colour, **options)
    layer = _object_layer(clusterer, params, model, meta.width, meta.height, out_meta.t_frame_us)
    object_meta = dataclasses.replace(out_meta, kind="objects") if layer is not None else None
    startup = _ready(clusterer, layer) if model in ("float", "fixed") else None
    start = time.perf_counter()
    kept, kept_objects, kept_steps, n_records, n_objects = [], [], [], 0, 0
    with tqdm(total=total, unit="ev", unit_scale=True, disable=None if progress else True, desc=f"track ({model})") as bar:
        for chunk in chunks:
            step = getattr(clusterer, "feed_size", CHUNK)  # the RTL takes smaller bites, for the progress bar
            for lo in range(0, chunk.size, step):
                piece = chunk[lo : lo + step]
                rows = clusterer.feed(piece)
                tracks = records_to_tracks(rows)
                n_records += tracks.size
                if sink is None:
                    kept.append(tracks)
                    kept_steps.append(np.asarray(clusterer.steps, np.float64))
                elif tracks.size:
                    sink(tracks)
                if layer is not None:
                    objects = rows_to_records(layer.feed(rows, clusterer.steps), OBJECT_DTYPE)
                    n_objects += objects.size
                    if object_sink is None:
                        kept_objects.append(objects)
                    elif objects.size:
                        object_sink(objects)
                bar.update(piece.size)
    wall = time.perf_counter() - start
    tracks = None if sink is not None else (np.concatenate(kept) if kept else np.zeros(0, TRACK_DTYPE))
    objects = None
    if layer is not None and object_sink is None:
        objects = np.concatenate(kept_objects) if kept_objects else np.zeros(0, OBJECT_DTYPE)
    stats = {**clusterer.stats(), "records": n_records}
    if layer is not None:
        stats |= layer.stats() | {"object_records": n_objects}
    step_times = None if sink is not None else (np.concatenate(kept_steps) if kept_steps else np.zeros(0))
    return TrackRun(tracks, out_meta, stats, wall, clusterer, objects, object_meta, step_times, startup)


def _ready(clusterer, layer) -> Startup:
    """Feed the model, and its object layer, nothing: numba compiles their loops, or loads them
    from its cache, here, so that the event loop's time is the loop's own (a short recording
    would otherwise read as a slow tracker). An empty feed changes no state."""
    before, start = compiled_code(), time.perf_counter()
    rows = clusterer.feed(np.zeros(0, EVENT_DTYPE))
    if layer is not None:
        layer.feed(rows, clusterer.steps)
    ahead, loaded, compiled = (now - then for now, then in zip(compiled_code(), before))
    return Startup(time.perf_counter() - start, loaded, compiled, ahead)


def rerun_objects(run: TrackRun, params: ClustererParams) -> TrackRun:
    """A float run's cluster records through the object layer again, with the object parameters
    of `params` (whose other parameters must be the run's): tuning the object layer alone needs
    the clusters once per scene, not once per trial."""
    if run.meta.model != "float" or run.tracks is None or run.step_times is None:
        raise EvclustError("rerun_objects needs a float run that kept its cluster records and step times")
    from evclust.clusterer.objects import FloatObjects

    params = params.resolved(run.meta.t_frame_us)
    if not params.objects:
        return dataclasses.replace(run, objects=None, object_meta=None)
    rows = np.stack([run.tracks[name].astype(np.float64) for name in TRACK_DTYPE.names], axis=1)
    layer = FloatObjects(params, run.meta.width, run.meta.height, run.meta.t_frame_us)
    start = time.perf_counter()
    bounds = np.searchsorted(run.tracks["step"], np.arange(0, run.step_times.size + STEPS_PER_FEED, STEPS_PER_FEED))
    objects = np.concatenate([rows_to_records(layer.feed(rows[lo:hi], run.step_times[i : i + STEPS_PER_FEED]), OBJECT_DTYPE)
                              for i, lo, hi in zip(range(0, run.step_times.size, STEPS_PER_FEED), bounds, bounds[1:])]
                             or [np.zeros(0, OBJECT_DTYPE)])  # fmt: skip
    stats = {**run.stats, **layer.stats(), "object_records": objects.size}
    return dataclasses.replace(run, objects=objects, object_meta=dataclasses.replace(run.meta, kind="objects"), stats=stats,
                               wall_s=run.wall_s + time.perf_counter() - start)  # fmt: skip


def track_events(
    events: np.ndarray, meta: EventMeta, params: ClustererParams, model: str = "float", progress: bool = False, **options
) -> TrackRun:
    """Run a clusterer model over a whole stream in memory; `options` go to the model."""
    return track_stream([events], meta, params, model, progress, total=events.size, **options)
