"""Match track records to ground-truth objects at each filter step (docs/METRICS.md).

At each filter step (each distinct `(step, t_us)` of the track file):
- the objects present are the ground-truth rows of frame `k = floor(t_us / t_frame_us)`;
- an object's centre is interpolated linearly in time between its rows of frames k and k+1
  (frame k's centre alone when the object has no row in frame k+1);
- its velocity, colour, label and visibility are frame k's (the forward convention of
  docs/DESIGN.md: frame k's velocity is the motion from k to k+1);
- the step's track records and those objects are paired by the Hungarian algorithm
  (scipy.optimize.linear_sum_assignment) on the Euclidean centre distance, pairs farther apart
  than the gate being forbidden; a pair is kept when its distance is <= gate_px.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from scipy.optimize import linear_sum_assignment

from evclust.choices import DEFAULT_GATE_PX
from evclust.errors import EvclustError
from evclust.scenes.truth import LABEL_CHARS, truth_array
from evclust.tracks import RECORD_DTYPES, VELOCITY_METHODS, TrackMeta, record_kind


MATCH_DTYPE = np.dtype(
    [
        ("step", np.uint32),  # filter step index
        ("t_us", np.uint64),  # time of the filter step
        ("frame", np.int64),  # ground-truth frame k = floor(t_us / t_frame_us)
        ("gt_id", np.int64),  # ground-truth object id
        ("track_id", np.uint32),  # the track record's cluster id
        ("slot", np.uint16),  # the track record's slot
        ("x", np.float64),  # estimated centre, px
        ("y", np.float64),
        ("gt_x", np.float64),  # true centre at t_us (interpolated), px
        ("gt_y", np.float64),
        ("vx_mcm", np.float64),  # estimated velocities, px/frame
        ("vy_mcm", np.float64),
        ("vx_int", np.float64),
        ("vy_int", np.float64),
        ("gt_vx", np.float64),  # true velocity of frame k, px/frame
        ("gt_vy", np.float64),
        ("Y", np.float64),  # estimated object colour
        ("Cb", np.float64),
        ("Cr", np.float64),
        ("gt_Y", np.float64),  # true object colour of frame k
        ("gt_Cb", np.float64),
        ("gt_Cr", np.float64),
        ("class_palette", np.int32),  # the record's class field: palette index, -1 none
        ("class_direct", np.int32),  # nearest non-background palette entry to (Y, Cb, Cr); -1 none
        ("gt_label", f"U{LABEL_CHARS}"),
        ("fully_visible", np.bool_),  # frame k's fully_visible
    ]
)


def velocity_fields(kind: str) -> tuple[str, ...]:
    """The record fields that hold a kind's velocity estimates, (vx, vy) per method."""
    return tuple(f for _, vx, vy in VELOCITY_METHODS[kind] for f in (vx, vy))


def match_dtype(kind: str) -> np.dtype:
    """MATCH_DTYPE for cluster records; for object records the velocity fields are the object's (vx, vy)."""
    if kind == "clusters":
        return MATCH_DTYPE
    fields = [(name, MATCH_DTYPE[name]) for name in MATCH_DTYPE.names if name not in velocity_fields("clusters")]
    at = [name for name, _ in fields].index("gt_vx")
    return np.dtype(fields[:at] + [(f, np.float64) for f in velocity_fields(kind)] + fields[at:])


@dataclasses.dataclass(frozen=True)
class MatchCounts:
    """What the matches alone cannot tell: the sizes of the populations they were drawn from."""

    n_steps: int  # distinct (step, t_us) in the tracks
    n_steps_missing: int  # step numbers 0..max absent from the tracks (no reported cluster then)
    n_track_records: int  # track records that count for precision
    n_gt_evaluations: int  # (filter step, object present) pairs that count for recall
    n_excluded_records: int  # records matched to an object left out by fully_visible_only


def _check_inputs(tracks, meta: TrackMeta, gate_px: float) -> np.ndarray:
    if not isinstance(meta, TrackMeta):
        raise EvclustError(f"track metadata must be a TrackMeta, not {type(meta).__name__}")
    t_frame = float(meta.t_frame_us)
    if not (math.isfinite(t_frame) and t_frame > 0):
        raise EvclustError(f"track metadata: t_frame_us must be a positive number, not {meta.t_frame_us}")
    gate = float(gate_px)
    if not (math.isfinite(gate) and gate > 0):
        raise EvclustError(f"gate must be a positive number of pixels, not {gate_px}")
    tracks = np.asarray(tracks)
    names = tracks.dtype.names or ()
    missing = [name for name in RECORD_DTYPES[record_kind(tracks)].names if name not in names]
    if missing:
        raise EvclustError(f"tracks: missing field(s) {', '.join(missing)}")
    if len(meta.palette_ycbcr) and len(meta.palette_ycbcr) != len(meta.palette):
        raise EvclustError(f"track metadata: palette has {len(meta.palette)} names but {len(meta.palette_ycbcr)} colours")
    return tracks.reshape(-1)


def nearest_palette_class(ycbcr: np.ndarray, meta: TrackMeta) -> np.ndarray:
    """Index of the nearest non-background palette entry to each (Y, Cb, Cr) row, under the
    L1 distance luma_weight·|ΔY| + |ΔCb| + |ΔCr|; ties go to the lower index; -1 when the track
    file has no colour or no non-background entry."""
    ycbcr = np.asarray(ycbcr, dtype=np.float64).reshape(-1, 3)
    out = np.full(len(ycbcr), -1, dtype=np.int32)
    if not meta.has_colour or not meta.palette_ycbcr or len(ycbcr) == 0:
        return out
    background = set(meta.palette_background)
    usable = np.array([i for i, name in enumerate(meta.palette) if name not in background], dtype=np.int64)
    if usable.size == 0:
        return out
    entries = np.asarray(meta.palette_ycbcr, dtype=np.float64)[usable]  # (K, 3)
    weights = np.array([float(meta.luma_weight), 1.0, 1.0])
    distance = (np.abs(ycbcr[:, None, :] - entries[None, :, :]) * weights).sum(axis=2)  # (N, K)
    out[:] = usable[np.argmin(distance, axis=1)]  # argmin returns the first minimum: lower index
    return out


def gated_assignment(cost: np.ndarray, gate: float) -> tuple[np.ndarray, np.ndarray]:
    """Hungarian assignment with pairs beyond the gate forbidden.

    Out-of-gate pairs get a cost larger than any sum of in-gate costs, so the solver first
    maximises the number of in-gate pairs and then minimises their total distance; the
    out-of-gate pairs it is still forced to make are dropped. (Solving on the raw distances
    and dropping afterwards can trade a close pair for two pairs one of which is then dropped.)
    """
    allowed = cost <= gate
    if not allowed.any():
        return np.empty(0, np.int64), np.empty(0, np.int64)
    if allowed.sum(axis=0).max() == 1 and allowed.sum(axis=1).max() == 1:
        # No two in-gate pairs share a row or a column: every optimum holds them all (swapping one
        # in for the two forced pairs it crosses lowers the cost), so the solver's answer is known,
        # rows ascending as it returns them.
        rows, cols = np.nonzero(allowed)
        return rows.astype(np.int64), cols.astype(np.int64)
    big = gate * (min(cost.shape) + 1) + 1.0
    rows, cols = linear_sum_assignment(np.where(allowed, cost, big))
    keep = allowed[rows, cols]
    return rows[keep], cols[keep]


def gated_pairs(a_xy: np.ndarray, a_first: np.ndarray, b_xy: np.ndarray, b_first: np.ndarray, gate: float) -> tuple[np.ndarray, np.ndarray]:
    """gated_assignment in every group at once, on the centre distance: group g pairs the points
    a_xy[a_first[g]:a_first[g + 1]] with b_xy[b_first[g]:b_first[g + 1]] (a_first and b_first end
    with the points' count). Returns the chosen pairs' indices into a_xy and b_xy, group by group,
    each group's as gated_assignment gives them (a ascending).

    All groups' distances come from one vectorised pass; a group where no two in-gate pairs share
    a point takes its in-gate pairs as they are (gated_assignment's own shortcut), and only the
    others are solved one by one."""
    n_a, n_b = np.diff(a_first), np.diff(b_first)
    sizes = n_a * n_b
    group = np.repeat(np.arange(n_a.size), sizes)  # each pair's group, the pairs a-major
    first_pair = np.cumsum(sizes) - sizes
    within = np.arange(group.size) - first_pair[group]
    ia, ib = a_first[:-1][group] + within // n_b[group], b_first[:-1][group] + within % n_b[group]
    cost = np.hypot(a_xy[ia, 0] - b_xy[ib, 0], a_xy[ia, 1] - b_xy[ib, 1])
    allowed = cost <= gate
    a_in, b_in = ia[allowed], ib[allowed]
    crowded = (np.bincount(a_in, minlength=1)[a_in] > 1) | (np.bincount(b_in, minlength=1)[b_in] > 1)
    hard = np.unique(group[allowed][crowded])
    chosen = [np.flatnonzero(allowed & ~np.isin(group, hard))]
    for g in hard.tolist():
        n, m = int(n_a[g]), int(n_b[g])
        rows, cols = gated_assignment(cost[first_pair[g] : first_pair[g] + n * m].reshape(n, m), gate)
        chosen.append(first_pair[g] + rows * m + cols)
    chosen = np.sort(np.concatenate(chosen))
    return ia[chosen], ib[chosen]


def _next_rows(truth: np.ndarray) -> np.ndarray:
    """For each ground-truth row, the row of the same object in the next frame, or -1."""
    order = np.lexsort((truth["frame"], truth["id"]))  # by object, then frame
    frame, obj = truth["frame"][order], truth["id"][order]
    same = obj[1:] == obj[:-1]
    twice = same & (frame[1:] == frame[:-1])
    if twice.any():  # name the first repeat in the file's order
        i = int(np.min(np.maximum(order[:-1], order[1:])[twice]))
        raise EvclustError(f"ground truth: object {int(truth['id'][i])} has two rows for frame {int(truth['frame'][i])}")
    following = np.full(truth.size, -1, np.int64)
    consecutive = same & (frame[1:] == frame[:-1] + 1)
    following[order[:-1][consecutive]] = order[1:][consecutive]
    return following


def match_with_counts(
    tracks: np.ndarray,
    meta: TrackMeta,
    truth,
    gate_px: float = DEFAULT_GATE_PX,
    fully_visible_only: bool = False,
) -> tuple[np.ndarray, MatchCounts]:
    """`match` plus the counts recall and precision need."""
    tracks = _check_inputs(tracks, meta, gate_px)
    truth = truth_array(truth)
    gate = float(gate_px)
    t_frame = float(meta.t_frame_us)

    following = _next_rows(truth)

    # Group the records by filter step, in time order; a file thinned to one record per id per
    # frame (meta.per_frame) by frame, evaluated at the frame's last record time.
    order = np.lexsort((tracks["step"], tracks["t_us"]))
    t_all = tracks["t_us"][order]
    s_all = tracks["step"][order]
    if meta.per_frame:
        s_all = np.floor(t_all / t_frame).astype(np.int64)
        t_all = t_all.copy()
    if order.size:
        changes = np.flatnonzero((s_all[1:] != s_all[:-1]) | ((t_all[1:] != t_all[:-1]) & (not meta.per_frame))) + 1
        bounds = np.r_[0, changes, order.size]
    else:
        bounds = np.zeros(1, np.int64)
    if meta.per_frame:  # each frame's records at the frame's last record time
        for a, b in zip(bounds[:-1], bounds[1:]):
            t_all[a:b] = t_all[b - 1]

    # Each step's objects present, their centres interpolated; then every step's pairing at once.
    starts = bounds[:-1]
    t = t_all[starts].astype(np.float64)
    k = np.floor(t / t_frame).astype(np.int64)
    frac = t / t_frame - k
    by_frame = np.argsort(truth["frame"], kind="stable")
    frames = truth["frame"][by_frame]
    lo, hi = np.searchsorted(frames, k, "left"), np.searchsorted(frames, k, "right")
    counted = truth["fully_visible"][by_frame] if fully_visible_only else np.ones(frames.size, np.int64)
    counted_before = np.r_[0, np.cumsum(counted, dtype=np.int64)]
    n_gt = int(np.sum(counted_before[hi] - counted_before[lo]))
    present = np.repeat(np.arange(starts.size), hi - lo)  # each (step, object present)'s step
    obj = by_frame[lo[present] + np.arange(present.size) - (np.cumsum(hi - lo) - (hi - lo))[present]]
    centre = np.stack([truth["cx"][obj], truth["cy"][obj]], axis=1)
    nxt = following[obj]
    moves = nxt >= 0
    move = frac[present][moves]
    centre[moves, 0] += move * (truth["cx"][nxt[moves]] - centre[moves, 0])
    centre[moves, 1] += move * (truth["cy"][nxt[moves]] - centre[moves, 1])
    est = np.stack([tracks["x"][order], tracks["y"][order]], axis=1).astype(np.float64)
    ia, ib = gated_pairs(est, bounds, centre, np.r_[0, np.cumsum(hi - lo)], gate)
    n_excluded = 0
    if fully_visible_only:
        visible = truth["fully_visible"][obj[ib]]
        n_excluded = int((~visible).sum())
        ia, ib = ia[visible], ib[visible]

    rec, gti = order[ia], obj[ib]
    kind = record_kind(tracks)
    out = np.zeros(rec.size, dtype=match_dtype(kind))
    out["step"] = tracks["step"][rec]
    out["t_us"] = tracks["t_us"][rec]
    out["frame"] = k[present[ib]]
    out["gt_id"] = truth["id"][gti]
    out["track_id"] = tracks["id"][rec]
    out["slot"] = tracks["slot"][rec]
    for name in ("x", "y", *velocity_fields(kind), "Y", "Cb", "Cr"):
        out[name] = tracks[name][rec]
    out["gt_x"], out["gt_y"] = centre[ib, 0], centre[ib, 1]
    out["gt_vx"], out["gt_vy"] = truth["vx"][gti], truth["vy"][gti]
    out["gt_Y"], out["gt_Cb"], out["gt_Cr"] = truth["Y"][gti], truth["Cb"][gti], truth["Cr"][gti]
    out["class_palette"] = tracks["class"][rec]
    out["class_direct"] = nearest_palette_class(np.stack([out["Y"], out["Cb"], out["Cr"]], axis=1), meta)
    out["gt_label"] = truth["label"][gti]
    out["fully_visible"] = truth["fully_visible"][gti]

    # Steps (frames, per_frame) below the last one with no record.
    steps = np.unique(s_all) if tracks.size else np.empty(0, np.uint32)
    counts = MatchCounts(
        n_steps=int(bounds.size - 1),
        n_steps_missing=int(steps[-1]) + 1 - steps.size if steps.size else 0,
        n_track_records=int(tracks.size) - n_excluded,
        n_gt_evaluations=int(n_gt),
        n_excluded_records=n_excluded,
    )
    return out, counts


def match(
    tracks: np.ndarray,
    meta: TrackMeta,
    truth,
    gate_px: float = DEFAULT_GATE_PX,
    fully_visible_only: bool = False,
) -> np.ndarray:
    """One MATCH_DTYPE row per matched (record, ground-truth object) pair, in time order
    (`match_dtype("objects")` for object records).

    tracks: cluster or object records (`evclust.tracks.read_tracks`); meta: their TrackMeta (gives
    t_frame_us, the palette and luma_weight); truth: TRUTH_DTYPE rows (`read_truth`) or dicts
    keyed by TRUTH_COLUMNS. gate_px: pairs farther apart than this are not matched.
    fully_visible_only: drop pairs whose object is not fully inside the sensor in frame k
    (objects are still matched against all objects present, so a cluster on a half-visible
    object is not forced onto a fully visible one).
    """
    return match_with_counts(tracks, meta, truth, gate_px, fully_visible_only)[0]
