"""One scene of the suite through one clusterer model: track, then score (docs/METRICS.md)."""

from __future__ import annotations

import dataclasses
import time

import numpy as np

from evclust.clusterer import ClustererParams, track_events
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
    clusters: "SceneResult | None" = None  # the cluster records' result, when these are object records

    @property
    def recall(self) -> float | None:
        return self.matches.size / self.n_objects if self.n_objects else None

    @property
    def precision(self) -> float | None:
        return self.matches.size / self.n_records if self.n_records else None


def evaluate_scene(files: SceneFiles, params: ClustererParams, model: str = "float", cache: dict | None = None,
                   trackeval: bool = True) -> SceneResult:  # fmt: skip
    """Track one scene and score what the run reports (its object records when the parameters
    have an object layer; its cluster records, scored too, in `.clusters`). `cache` (a dict)
    keeps the scene's events and truth for the next call in this process; trackeval=False skips
    HOTA/MOTA/IDF1 (a tuning loop's speed)."""
    if cache is not None and files.name in cache:
        events, meta, truth = cache[files.name]
    else:
        (events, meta), truth = read_events(files.events), read_truth(files.truth)
        if cache is not None:
            cache[files.name] = (events, meta, truth)
    start = time.perf_counter()
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
