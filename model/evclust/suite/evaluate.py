"""One scene of the suite through one clusterer model: track, then score (docs/METRICS.md)."""

from __future__ import annotations

import dataclasses
import json
import time

import numpy as np

from evclust.clusterer import ClustererParams
from evclust.run import track_events
from evclust.run import rerun_objects
from evclust.run.track import at_frame_period
from evclust.errors import EvclustError
from evclust.events import read_events
from evclust.metrics import tracking
from evclust.scenes.truth import read_truth
from evclust.suite.prepare import SceneFiles


@dataclasses.dataclass
class SceneResult:
    name: str
    facts: dict  # the generator's description of the scene (NAME.json)
    model: str
    events: int
    wall_s: float  # tracking only
    stats: dict  # the clusterer's counters
    trackeval: dict | None  # TrackEval's per-sequence results (None: not computed)
    n_objects: int  # object samples that count for recall
    n_records: int  # record samples that count for precision
    matches: np.ndarray  # tracking.MATCH_FIELDS
    objects: dict  # object id -> tracking.ObjectSummary
    meta: object  # the track file's TrackMeta (palette, colour)
    frames: np.ndarray  # the frame of each sample
    failures: np.ndarray  # per sample, unmatched objects and records by kind (tracking.FAILURES)
    clusters: SceneResult | None = None  # the cluster records' result, when these are object records

    @property
    def recall(self) -> float | None:
        return self.matches.size / self.n_objects if self.n_objects else None

    @property
    def precision(self) -> float | None:
        return self.matches.size / self.n_records if self.n_records else None


def _cluster_key(name: str, params: ClustererParams) -> tuple[str, str]:
    """A scene and the parameters its clusters depend on (all but the object layer's)."""
    keep = {k: v for k, v in params.model_dump(mode="json").items() if k != "objects" and not k.startswith("object_")}
    return name, json.dumps(keep, sort_keys=True)


def evaluate_scene(files: SceneFiles, params: ClustererParams, model: str = "float", cache: dict | None = None,
                   trackeval: bool = True, cluster_runs: dict | None = None, withhold_frame: bool = False) -> SceneResult:  # fmt: skip
    """Track one scene and score what the run reports (its object records when the parameters
    have an object layer; its cluster records, scored too, in `.clusters`). `cache` (a dict)
    keeps the scene's events and truth for the next call in this process; trackeval=False skips
    HOTA/MOTA/IDF1 (a tuning loop's speed). `cluster_runs` (a dict; float model) keeps each
    scene's cluster run per cluster parameter set, so that a call that changes only the object
    layer's parameters runs the object layer alone. `withhold_frame`: the tracker is not told the
    scene's frame period (a camera's stream has none, evclust.choices.FRAMELESS_PERIOD_US), and its
    velocities are scored converted to px per frame of the scene."""
    if cache is not None and files.name in cache:
        events, meta, truth = cache[files.name]
    else:
        (events, meta), truth = read_events(files.events), read_truth(files.truth)
        if cache is not None:
            cache[files.name] = (events, meta, truth)
    start = time.perf_counter()
    if cluster_runs is not None and model == "float":
        key = _cluster_key(files.name, params)
        if key not in cluster_runs:
            cluster_runs[key] = track_events(events, meta, params.model_copy(update={"objects": False}), model=model)
        run = rerun_objects(cluster_runs[key], params)
    elif withhold_frame:
        if params.t_frame_us:
            raise EvclustError("withhold_frame: these parameters set t_frame_us themselves")
        run = track_events(events, dataclasses.replace(meta, t_frame_us=None), params, model=model)
        run = at_frame_period(run, meta.t_frame_us)
    else:
        run = track_events(events, meta, params, model=model)
    wall = time.perf_counter() - start

    def result(records, records_meta) -> SceneResult:
        pairs = tracking.frame_pairs(records, records_meta, truth)
        return SceneResult(
            name=files.name, facts=files.facts, model=model, events=int(events.size), wall_s=wall, stats=run.stats,
            trackeval=tracking.evaluate_sequence(pairs) if trackeval else None, n_objects=pairs.n_objects, n_records=pairs.n_records,
            matches=pairs.matches, objects=pairs.objects, meta=records_meta, frames=pairs.frames, failures=pairs.failures,
        )  # fmt: skip

    out = result(*run.output)
    if run.object_meta is not None:
        out.clusters = result(run.tracks, run.meta)
    return out
