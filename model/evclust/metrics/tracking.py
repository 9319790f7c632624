"""Tracking metrics a tracking engineer expects (docs/METRICS.md, "Tracking metrics"): the
tracker's output sampled once per frame, objects matched by a similarity normalised by their
size, then HOTA, CLEAR MOT and identity metrics from TrackEval, and beside them tracks per
object and the paper's accuracy figures on the same matches.

Each frame k >= 1 is one sample: the records of the last filter step at or before t_k =
k·t_frame (what the tracker reports at that moment), against the objects of frame k with their
centres interpolated to that step's time. Objects less than `min_visible` in view (border,
occlusion) are "don't care": a record matched to one counts neither for nor against.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from scipy.optimize import linear_sum_assignment

from evclust.metrics.match import nearest_palette_class
from evclust.metrics.scores import class_correct, tracks_per_object  # noqa: F401 (tracks_per_object: re-exported)
from evclust.scenes.truth import truth_array
from evclust.metrics.match import velocity_fields
from evclust.tracks import VELOCITY_METHODS, TrackMeta, record_kind

MIN_VISIBLE = 0.5  # area fraction in view below which an object is "don't care"
MIN_RADIUS_PX = 8.0  # the similarity radius of the smallest objects: a cluster lags a few px
MATCH_SIMILARITY = 0.5  # CLEAR and identity matches, and the accuracy figures: sim >= 0.5


@dataclasses.dataclass
class FramePairs:
    """Per-frame samples and their matches: what the trackeval metrics and the figures share."""

    gt_ids: list  # per sample: care object ids
    track_ids: list  # per sample: record ids kept (not matched to a don't-care object)
    similarity: list  # per sample: (n_gt, n_track) in [0, 1]
    matches: np.ndarray  # one row per pair with similarity >= MATCH_SIMILARITY (MATCH_FIELDS)
    objects: dict  # object id -> ObjectSummary over its care samples
    frames: np.ndarray  # the frame of each sample
    failures: np.ndarray  # (samples, len(FAILURES)): each sample's unmatched objects and records, by kind

    @property
    def n_objects(self) -> int:
        """Object samples that count for recall."""
        return int(sum(a.size for a in self.gt_ids))

    @property
    def n_records(self) -> int:
        """Record samples that count for precision (those on don't-care objects left out)."""
        return int(sum(a.size for a in self.track_ids))


@dataclasses.dataclass(frozen=True)
class ObjectSummary:
    samples: int  # frames in which it counts for recall
    radius: float  # mean similarity radius, px
    speed: float  # mean true speed, px/frame
    size: float  # mean larger side, px


# What an unmatched object or record was: an object with no record within its radius (missed),
# one whose nearest record is within its radius but off-centre (sim < MATCH_SIMILARITY); a record
# within some object's radius that is not its match (a fragment or an off-centre cluster), one
# near no object at all (a ghost).
FAILURES = ("missed", "off_centre", "fragment", "ghost")


def _failures(sim: np.ndarray, gi: np.ndarray, ti: np.ndarray, ok: np.ndarray) -> list[int]:
    matched_g, matched_t = set(gi[ok].tolist()), set(ti[ok].tolist())
    missed = off = fragment = ghost = 0
    for g in range(sim.shape[0]):
        if g not in matched_g:
            if sim.shape[1] == 0 or sim[g].max() == 0:
                missed += 1
            else:
                off += 1
    for t in range(sim.shape[1]):
        if t not in matched_t:
            if sim.shape[0] and sim[:, t].max() > 0:
                fragment += 1
            else:
                ghost += 1
    return [missed, off, fragment, ghost]


def match_fields(kind: str = "clusters") -> np.dtype:
    """One row per frame-sampled match; the velocity fields are the record kind's."""
    return np.dtype([
        ("frame", np.int64), ("gt_id", np.int64), ("track_id", np.int64), ("d", np.float64), ("radius", np.float64),
        *((name, np.float64) for name in velocity_fields(kind)),
        ("gt_vx", np.float64), ("gt_vy", np.float64), ("Y", np.float64), ("Cb", np.float64), ("Cr", np.float64),
        ("gt_Y", np.float64), ("gt_Cb", np.float64), ("gt_Cr", np.float64), ("class_palette", np.int32),
        ("class_direct", np.int32), ("gt_label", "U32"),
        ("steady", np.bool_),  # the object moves, with the velocity it had one second earlier
    ])  # fmt: skip


MATCH_FIELDS = match_fields("clusters")


def velocity_methods(matches: np.ndarray) -> tuple[tuple[str, str, str], ...]:
    """The velocity methods whose estimates a match array holds: (name, vx field, vy field)."""
    names = matches.dtype.names
    return tuple(m for kind in VELOCITY_METHODS for m in VELOCITY_METHODS[kind] if m[1] in names)


def radius(w, h):
    """The similarity radius of an object: its half-diagonal, at least MIN_RADIUS_PX."""
    return np.maximum(np.hypot(w, h) / 2.0, MIN_RADIUS_PX)


def frame_pairs(tracks: np.ndarray, meta: TrackMeta, truth, min_visible: float = MIN_VISIBLE) -> FramePairs:
    truth = truth_array(truth)
    t_frame = float(meta.t_frame_us)
    kind = record_kind(tracks)
    speeds = velocity_fields(kind)
    # Filter steps in order, each with its time: several steps can share a microsecond (a burst
    # of simultaneous events), so a sample takes the last step, not every record of that time.
    order = np.lexsort((tracks["step"], tracks["t_us"]))
    sorted_step = tracks["step"][order].astype(np.int64)
    starts = np.flatnonzero(np.r_[True, sorted_step[1:] != sorted_step[:-1]]) if order.size else np.empty(0, np.int64)
    step_times = tracks["t_us"][order][starts].astype(np.float64)
    bounds = np.r_[starts, order.size]
    by_frame: dict[int, np.ndarray] = {}
    for k in np.unique(truth["frame"]):
        by_frame[int(k)] = np.flatnonzero(truth["frame"] == k)
    where = {(int(f), int(i)): r for r, (f, i) in enumerate(zip(truth["frame"], truth["id"]))}
    second = max(1, int(round(1e6 / t_frame)))  # frames in one second

    def steady(row) -> bool:
        back = where.get((int(truth["frame"][row]) - second, int(truth["id"][row])))
        v = (truth["vx"][row], truth["vy"][row])
        return back is not None and (v[0] or v[1]) and (truth["vx"][back], truth["vy"][back]) == v

    gt_ids, track_ids, sims, rows, frames, failures = [], [], [], [], [], []
    objects: dict[int, list] = {}
    for k in sorted(by_frame):
        if k < 1:
            continue  # no event before frame 1
        objs = by_frame[k]
        t_k = k * t_frame
        j = int(np.searchsorted(step_times, t_k, side="right")) - 1
        if j >= 0:
            t_s = int(step_times[j])
            records = order[bounds[j] : bounds[j + 1]]
        else:
            t_s, records = t_k, np.empty(0, np.int64)
        # True centres at the step's time, interpolated between the rows around it.
        centre = np.stack([truth["cx"][objs], truth["cy"][objs]], axis=1)
        f = t_s / t_frame
        for n, row in enumerate(objs.tolist()):
            k0 = math.floor(f)
            a, b = where.get((k0, int(truth["id"][row]))), where.get((k0 + 1, int(truth["id"][row])))
            if a is not None:
                centre[n] = (truth["cx"][a], truth["cy"][a])
                if b is not None:
                    centre[n, 0] += (f - k0) * (truth["cx"][b] - truth["cx"][a])
                    centre[n, 1] += (f - k0) * (truth["cy"][b] - truth["cy"][a])
        r = radius(truth["w"][objs], truth["h"][objs])
        est = np.stack([tracks["x"][records], tracks["y"][records]], axis=1).astype(np.float64)
        d = np.hypot(centre[:, None, 0] - est[None, :, 0], centre[:, None, 1] - est[None, :, 1])
        sim = np.clip(1.0 - d / r[:, None], 0.0, 1.0)
        care = truth["visible"][objs] >= min_visible
        # Records on a don't-care object leave the sample: matched to it by the same Hungarian
        # assignment over all objects, at any similarity above 0.
        keep = np.ones(records.size, bool)
        if (~care).any() and records.size:
            gi, ti = linear_sum_assignment(-sim)
            drop = (~care[gi]) & (sim[gi, ti] > 0)
            keep[ti[drop]] = False
        sim_c = sim[care][:, keep]
        ids_c = truth["id"][objs][care]
        recs_c = records[keep]
        gt_ids.append(ids_c.astype(np.int64))
        track_ids.append(tracks["id"][recs_c].astype(np.int64))
        sims.append(sim_c)
        for row in objs[care].tolist():
            objects.setdefault(int(truth["id"][row]), []).append(
                (
                    float(radius(truth["w"][row], truth["h"][row])),
                    math.hypot(truth["vx"][row], truth["vy"][row]),
                    max(truth["w"][row], truth["h"][row]),
                )
            )
        gi, ti = linear_sum_assignment(-sim_c) if sim_c.size else (np.empty(0, np.int64), np.empty(0, np.int64))
        ok = sim_c[gi, ti] >= MATCH_SIMILARITY
        frames.append(k)
        failures.append(_failures(sim_c, gi, ti, ok))
        if sim_c.size:
            for g, t in zip(gi[ok].tolist(), ti[ok].tolist()):
                row, rec = objs[care][g], recs_c[t]
                rows.append((
                    k, truth["id"][row], tracks["id"][rec], d[care][:, keep][g, t], r[care][g],
                    *(tracks[name][rec] for name in speeds),
                    truth["vx"][row], truth["vy"][row], tracks["Y"][rec], tracks["Cb"][rec], tracks["Cr"][rec],
                    truth["Y"][row], truth["Cb"][row], truth["Cr"][row], tracks["class"][rec], -1, truth["label"][row],
                    steady(row),
                ))  # fmt: skip
    fields = match_fields(kind)
    matches = np.array(rows, dtype=fields) if rows else np.zeros(0, fields)
    if matches.size:
        matches["class_direct"] = nearest_palette_class(np.stack([matches["Y"], matches["Cb"], matches["Cr"]], axis=1), meta)
    summary = {i: ObjectSummary(len(vals), *(float(np.mean([v[c] for v in vals])) for c in range(3))) for i, vals in objects.items()}
    return FramePairs(
        gt_ids, track_ids, sims, matches, summary, np.array(frames, np.int64), np.array(failures, np.int64).reshape(-1, len(FAILURES))
    )


def trackeval_data(pairs: FramePairs) -> dict:
    """The in-memory sequence TrackEval's metrics take: ids relabelled 0..n-1 on each side."""
    all_gt = np.unique(np.concatenate(pairs.gt_ids)) if pairs.gt_ids else np.empty(0, np.int64)
    all_tr = np.unique(np.concatenate(pairs.track_ids)) if pairs.track_ids else np.empty(0, np.int64)
    return {
        "num_timesteps": len(pairs.gt_ids),
        "num_gt_ids": int(all_gt.size),
        "num_tracker_ids": int(all_tr.size),
        "num_gt_dets": int(sum(a.size for a in pairs.gt_ids)),
        "num_tracker_dets": int(sum(a.size for a in pairs.track_ids)),
        "gt_ids": [np.searchsorted(all_gt, a).astype(int) for a in pairs.gt_ids],
        "tracker_ids": [np.searchsorted(all_tr, a).astype(int) for a in pairs.track_ids],
        "similarity_scores": [s.astype(float) for s in pairs.similarity],
    }


def trackeval_metrics():
    """HOTA, CLEAR (MOTA, precision, recall, ID switches) and Identity (IDF1), matching at
    MATCH_SIMILARITY. Imported here: trackeval pulls in matplotlib and OpenCV."""
    import trackeval

    config = {"THRESHOLD": MATCH_SIMILARITY, "PRINT_CONFIG": False}
    return trackeval.metrics.HOTA(), trackeval.metrics.CLEAR(config), trackeval.metrics.Identity(config)


def evaluate_sequence(pairs: FramePairs) -> dict:
    """TrackEval's per-sequence results, {metric name: its result dict}."""
    data = trackeval_data(pairs)
    return {type(m).__name__: m.eval_sequence(data) for m in trackeval_metrics()}


def combine_sequences(results: list[dict]) -> dict:
    """Pool several sequences' TrackEval results (sums of counts, not means of ratios)."""
    out = {}
    for metric in trackeval_metrics():
        name = type(metric).__name__
        out[name] = metric.combine_sequences({str(i): r[name] for i, r in enumerate(results)})
    return out


def headline(te: dict) -> dict:
    """TrackEval's figures the tables print: HOTA (mean over its α thresholds) with its
    detection and association parts, MOTA, IDF1 and identity switches."""
    hota, clear, ident = te["HOTA"], te["CLEAR"], te["Identity"]
    return {
        "HOTA": float(np.mean(hota["HOTA"])), "DetA": float(np.mean(hota["DetA"])), "AssA": float(np.mean(hota["AssA"])),
        "MOTA": float(clear["MOTA"]), "IDF1": float(ident["IDF1"]), "id_switches": int(clear["IDSW"]),
    }  # fmt: skip


def accuracy(matches: np.ndarray, meta: TrackMeta) -> dict:
    """The paper's figures (Tables 5 and 7) on the frame-sampled matches: position error
    relative to the object's half-diagonal, velocity NRMSE and angle per method, colour NRMSE,
    classification. None where nothing stands under a figure."""
    m = matches
    methods = velocity_methods(m)
    out = {"n_matches": int(m.size)}
    if m.size == 0:
        per_method = [
            f"{name}_{figure}{suffix}" for name, _, _ in methods for figure in ("nrmse", "angle_deg") for suffix in ("", "_steady")
        ]
        return out | dict.fromkeys(("position_rel_rmse", *per_method, "steady_share", "luminance_nrmse", "chrominance_nrmse", "class_palette", "class_direct"))  # fmt: skip
    out["position_rel_rmse"] = float(np.sqrt(np.mean((m["d"] / m["radius"]) ** 2)))
    gt = np.stack([m["gt_vx"], m["gt_vy"]], axis=1)
    moving = np.hypot(gt[:, 0], gt[:, 1]) > 0
    for suffix, chosen in (("", moving), ("_steady", moving & m["steady"])):
        for method, vx, vy in methods:
            est = np.stack([m[vx], m[vy]], axis=1)[chosen]
            g = gt[chosen]
            if g.size == 0:
                out[f"{method}_nrmse{suffix}"] = out[f"{method}_angle_deg{suffix}"] = None
                continue
            rmse = float(np.sqrt(np.mean(((est - g) ** 2).sum(axis=1))))
            out[f"{method}_nrmse{suffix}"] = rmse / float(np.mean(np.hypot(g[:, 0], g[:, 1])))
            norm = np.hypot(est[:, 0], est[:, 1])
            cos = np.where(norm > 0, (est * g).sum(axis=1) / np.maximum(norm * np.hypot(g[:, 0], g[:, 1]), 1e-300), 0.0)
            out[f"{method}_angle_deg{suffix}"] = float(np.degrees(np.arccos(np.clip(cos, -1, 1))).mean())
    out["steady_share"] = float(np.count_nonzero(moving & m["steady"]) / max(1, np.count_nonzero(moving)))
    if meta.has_colour:
        out["luminance_nrmse"] = float(np.sqrt(np.mean((m["Y"] - m["gt_Y"]) ** 2)) / np.mean(m["gt_Y"]))
        chro = np.sqrt(np.mean(((m["Cb"] - m["gt_Cb"]) ** 2 + (m["Cr"] - m["gt_Cr"]) ** 2) / 2))
        out["chrominance_nrmse"] = float(chro / ((np.mean(m["gt_Cb"]) + np.mean(m["gt_Cr"])) / 2))
        out["class_palette"] = float(class_correct(m["class_palette"], m["gt_label"], meta.palette).mean())
        out["class_direct"] = float(class_correct(m["class_direct"], m["gt_label"], meta.palette).mean())
    else:
        out |= {"luminance_nrmse": None, "chrominance_nrmse": None, "class_palette": None, "class_direct": None}
    return out
