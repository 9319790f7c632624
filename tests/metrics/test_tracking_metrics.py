"""Tracking metrics (evclust.metrics.tracking) and the suite's pooled figures
(evclust.suite.aggregate), on hand-made tracks and ground truth with known answers."""

from __future__ import annotations

import math

import numpy as np
import pytest

from evclust.clusterer.params import DEFAULT_PALETTE
from evclust.colour import rgb_to_ycbcr
from evclust.metrics import tracking
from evclust.metrics.tracking import (
    FAILURES,
    MATCH_SIMILARITY,
    MIN_RADIUS_PX,
    accuracy,
    evaluate_sequence,
    frame_pairs,
    headline,
    radius,
    tracks_per_object,
)
from evclust.scenes.synthetic import TRUTH_COLUMNS
from evclust.scenes.truth import truth_array
from evclust.suite import aggregate
from evclust.suite.evaluate import SceneResult
from evclust.tracks import TRACK_DTYPE, TrackMeta

T_FRAME = 40000  # µs: 25 frames/s, an integer so that k·t_frame is an exact record time
NAMES = tuple(e.name for e in DEFAULT_PALETTE)
PALETTE_YCC = {e.name: tuple(float(v) for v in rgb_to_ycbcr(np.asarray(e.rgb, dtype=np.float64))) for e in DEFAULT_PALETTE}
META = TrackMeta(
    width=200, height=100, t_frame_us=float(T_FRAME), palette=NAMES,
    palette_ycbcr=tuple(PALETTE_YCC[n] for n in NAMES), has_colour=True,
)  # fmt: skip


# ---------------------------------------------------------------------------------------------
# Builders


def obj(id_, frames, start, velocity=(0.0, 0.0), size=(20.0, 20.0), label="red", visible=1.0):
    """Truth rows of an object on a constant-velocity path over `frames` (an iterable of k)."""
    y, cb, cr = PALETTE_YCC[label]
    rows = []
    for k in frames:
        rows.append({
            "frame": k, "t_us": k * T_FRAME, "id": id_,
            "cx": start[0] + k * velocity[0], "cy": start[1] + k * velocity[1], "w": size[0], "h": size[1],
            "vx": velocity[0], "vy": velocity[1], "Y": y, "Cb": cb, "Cr": cr, "label": label,
            "fully_visible": 1, "visible": visible,
        })  # fmt: skip
    assert set(rows[0]) == set(TRUTH_COLUMNS) | {"visible"}
    return rows


def rec(t_us, id_, x, y, v=(0.0, 0.0), v_int=None, label="red", dycc=(0.0, 0.0, 0.0), cls=None):
    """One track record."""
    r = np.zeros(1, TRACK_DTYPE)
    r["t_us"], r["id"], r["x"], r["y"] = t_us, id_, x, y
    r["rx"] = r["ry"] = 5.0
    r["vx_mcm"], r["vy_mcm"] = v
    r["vx_int"], r["vy_int"] = v if v_int is None else v_int
    ycc = np.asarray(PALETTE_YCC[label]) + np.asarray(dycc)
    r["Y"], r["Cb"], r["Cr"] = ycc
    r["class"] = NAMES.index(label) if cls is None else cls
    r["step"] = t_us // 1000
    return r


def on_object(rows, id_=None, dx=0.0, dy=0.0, frames=None, **kw):
    """A record per frame k >= 1 at k·t_frame, on the object's centre (plus dx, dy), with its
    velocity; id_ defaults to the object's id."""
    out = []
    for row in rows:
        k = row["frame"]
        if k < 1 or (frames is not None and k not in frames):
            continue
        kw.setdefault("v", (row["vx"], row["vy"]))
        kw.setdefault("label", row["label"])
        out.append(rec(k * T_FRAME, row["id"] if id_ is None else id_, row["cx"] + dx, row["cy"] + dy, **kw))
    return out


def tracks(*lists):
    records = [r for lst in lists for r in lst]
    return np.concatenate(records) if records else np.zeros(0, TRACK_DTYPE)


def failures(pairs) -> dict[str, int]:
    return dict(zip(FAILURES, pairs.failures.sum(axis=0).tolist()))


def recall(pairs):
    return pairs.matches.size / pairs.n_objects


def precision(pairs):
    return pairs.matches.size / pairs.n_records


N = 21  # frames 0..20: 20 samples (k >= 1)


# ---------------------------------------------------------------------------------------------
# A perfect tracker


def test_a_perfect_tracker_scores_perfectly():
    a = obj(1, range(N), (30.0, 40.0), (2.0, 0.5), label="red")
    b = obj(2, range(N), (160.0, 60.0), (-1.5, -1.0), size=(12.0, 30.0), label="blue")
    pairs = frame_pairs(tracks(on_object(a), on_object(b)), META, a + b)
    # The same from the truth as a structured array.
    again = frame_pairs(tracks(on_object(a), on_object(b)), META, truth_array(a + b))
    assert np.array_equal(again.matches, pairs.matches)

    assert pairs.n_objects == pairs.n_records == 2 * (N - 1)
    assert pairs.frames.tolist() == list(range(1, N))
    assert recall(pairs) == 1.0 and precision(pairs) == 1.0
    assert tracks_per_object(pairs.matches) == 1.0
    assert failures(pairs) == dict.fromkeys(FAILURES, 0)
    assert np.allclose(pairs.matches["d"], 0.0)

    h = headline(evaluate_sequence(pairs))
    assert h["HOTA"] == pytest.approx(1.0) and h["DetA"] == pytest.approx(1.0) and h["AssA"] == pytest.approx(1.0)
    assert h["MOTA"] == pytest.approx(1.0) and h["IDF1"] == pytest.approx(1.0)
    assert h["id_switches"] == 0

    acc = accuracy(pairs.matches, META)
    assert acc["n_matches"] == 2 * (N - 1)
    assert acc["position_rel_rmse"] == pytest.approx(0.0, abs=1e-12)
    assert acc["mcm_nrmse"] == pytest.approx(0.0, abs=1e-12) and acc["interval_nrmse"] == pytest.approx(0.0, abs=1e-12)
    assert acc["mcm_angle_deg"] == pytest.approx(0.0, abs=1e-5) and acc["interval_angle_deg"] == pytest.approx(0.0, abs=1e-5)
    assert acc["luminance_nrmse"] == pytest.approx(0.0, abs=1e-12) and acc["chrominance_nrmse"] == pytest.approx(0.0, abs=1e-12)
    assert acc["class_palette"] == 1.0 and acc["class_direct"] == 1.0

    s = pairs.objects
    assert set(s) == {1, 2}
    assert s[1].samples == s[2].samples == N - 1
    assert s[1].speed == pytest.approx(math.hypot(2.0, 0.5)) and s[2].size == pytest.approx(30.0)
    assert s[1].radius == pytest.approx(math.hypot(20, 20) / 2) and s[2].radius == pytest.approx(math.hypot(12, 30) / 2)


# ---------------------------------------------------------------------------------------------
# Failures: fragments, misses, ghosts, off-centre records


def test_a_second_off_centre_record_on_an_object_is_a_fragment():
    a = obj(1, range(N), (50.0, 50.0), (1.0, 0.0))
    r = radius(20.0, 20.0)  # 14.14 px
    off = on_object(a, id_=7, dx=0.7 * r)  # similarity 0.3: within the radius, not a match
    pairs = frame_pairs(tracks(on_object(a), off), META, a)
    assert 0 < 1 - 0.7 < MATCH_SIMILARITY
    assert recall(pairs) == 1.0
    assert precision(pairs) == pytest.approx(0.5)
    assert pairs.n_records == 2 * (N - 1)
    assert failures(pairs) == {"missed": 0, "off_centre": 0, "fragment": N - 1, "ghost": 0}
    assert set(pairs.matches["track_id"].tolist()) == {1}  # the centred record is the match


def test_an_object_without_a_record_is_missed_and_a_record_far_from_all_is_a_ghost():
    a = obj(1, range(N), (40.0, 50.0))
    b = obj(2, range(N), (160.0, 50.0))
    ghost = [rec(k * T_FRAME, 9, 100.0, 95.0) for k in range(1, N)]  # > 45 px from both
    pairs = frame_pairs(tracks(on_object(a), ghost), META, a + b)
    assert failures(pairs) == {"missed": N - 1, "off_centre": 0, "fragment": 0, "ghost": N - 1}
    assert recall(pairs) == pytest.approx(0.5) and precision(pairs) == pytest.approx(0.5)
    assert pairs.failures.tolist() == [[1, 0, 0, 1]] * (N - 1)  # per sample
    h = headline(evaluate_sequence(pairs))
    # MOTA = 1 - (FN + FP + IDSW) / GT = 1 - (20 + 20) / 40
    assert h["MOTA"] == pytest.approx(0.0)


def test_an_object_whose_only_record_is_off_centre():
    a = obj(1, range(N), (50.0, 50.0))
    r = radius(20.0, 20.0)
    pairs = frame_pairs(tracks(on_object(a, dy=0.6 * r)), META, a)  # similarity 0.4
    assert pairs.matches.size == 0
    f = failures(pairs)
    assert f["off_centre"] == N - 1 and f["missed"] == 0 and f["ghost"] == 0
    assert f["fragment"] == N - 1  # the record is near an object, not its match
    acc = accuracy(pairs.matches, META)
    assert acc["n_matches"] == 0 and acc["position_rel_rmse"] is None and acc["mcm_nrmse"] is None


def test_no_tracks_at_all():
    a = obj(1, range(N), (50.0, 50.0))
    pairs = frame_pairs(np.zeros(0, TRACK_DTYPE), META, a)
    assert pairs.n_records == 0 and pairs.n_objects == N - 1 and pairs.matches.size == 0
    assert failures(pairs) == {"missed": N - 1, "off_centre": 0, "fragment": 0, "ghost": 0}
    assert tracks_per_object(pairs.matches) is None


# ---------------------------------------------------------------------------------------------
# Identity


def test_an_identity_switch_halfway():
    a = obj(1, range(N), (20.0, 50.0), (3.0, 0.0))
    half = (N - 1) // 2  # 10 samples each
    first = on_object(a, id_=4, frames=set(range(1, half + 1)))
    second = on_object(a, id_=5, frames=set(range(half + 1, N)))
    pairs = frame_pairs(tracks(first, second), META, a)
    assert recall(pairs) == 1.0 and precision(pairs) == 1.0
    assert tracks_per_object(pairs.matches) == 2.0
    te = evaluate_sequence(pairs)
    assert te["CLEAR"]["IDSW"] == 1
    h = headline(te)
    assert h["id_switches"] == 1
    assert h["MOTA"] == pytest.approx(1 - 1 / (N - 1))
    # IDF1: the object's best single track covers half its samples.
    assert h["IDF1"] == pytest.approx(0.5)
    # HOTA: DetA 1; each match's association score is 10 / (20 + 10 - 10) = 0.5.
    assert h["DetA"] == pytest.approx(1.0) and h["AssA"] == pytest.approx(0.5)
    assert h["HOTA"] == pytest.approx(math.sqrt(0.5))


# ---------------------------------------------------------------------------------------------
# The similarity radius


def test_radius_is_the_half_diagonal_at_least_the_minimum():
    assert radius(30.0, 40.0) == pytest.approx(25.0)
    assert radius(16.0, 12.0) == pytest.approx(10.0)
    assert radius(4.0, 4.0) == MIN_RADIUS_PX
    assert radius(1.0, 2.0) == MIN_RADIUS_PX
    assert np.allclose(radius(np.array([30.0, 2.0]), np.array([40.0, 2.0])), [25.0, MIN_RADIUS_PX])


@pytest.mark.parametrize(
    "size, r",
    [((30.0, 40.0), 25.0), ((4.0, 4.0), MIN_RADIUS_PX)],
)
def test_a_record_at_half_the_radius_matches_and_a_farther_one_does_not(size, r):
    a = obj(1, range(N), (100.0, 50.0), size=size)
    assert MATCH_SIMILARITY == 0.5
    at = frame_pairs(tracks(on_object(a, dx=r / 2)), META, a)
    assert at.matches.size == N - 1  # similarity exactly 0.5
    assert np.allclose(at.matches["d"], r / 2) and np.allclose(at.matches["radius"], r)
    assert np.allclose(at.similarity[0], 0.5)
    beyond = frame_pairs(tracks(on_object(a, dx=r / 2 + 0.05)), META, a)
    assert beyond.matches.size == 0
    assert failures(beyond)["off_centre"] == N - 1
    outside = frame_pairs(tracks(on_object(a, dx=r + 0.05)), META, a)  # no similarity at all
    assert failures(outside) == {"missed": N - 1, "off_centre": 0, "fragment": 0, "ghost": N - 1}


# ---------------------------------------------------------------------------------------------
# Sampling: the last filter step at or before each frame time, centres interpolated to it


def test_each_frame_samples_the_last_step_at_or_before_it():
    v = 4.0
    a = obj(1, range(N), (20.0, 50.0), (v, 0.0))
    recs = []
    for k in range(1, N):
        t = k * T_FRAME - T_FRAME // 4  # the last step before frame k, at k - 1/4
        recs.append(rec(t, 1, 20.0 + v * (k - 0.25), 50.0, v=(v, 0.0)))  # on the interpolated centre
        recs.append(rec(t - T_FRAME // 2, 8, 190.0, 95.0))  # an earlier step: never sampled
    pairs = frame_pairs(tracks(recs), META, a)
    assert pairs.n_records == N - 1 and recall(pairs) == 1.0 and precision(pairs) == 1.0
    assert np.allclose(pairs.matches["d"], 0.0, atol=1e-9)
    assert failures(pairs)["ghost"] == 0


def test_frames_before_the_first_step_see_no_record():
    a = obj(1, range(N), (50.0, 50.0))
    late = [rec(k * T_FRAME, 1, 50.0, 50.0) for k in range(5, N)]
    pairs = frame_pairs(tracks(late), META, a)
    assert failures(pairs)["missed"] == 4  # frames 1..4
    assert pairs.matches.size == N - 5 and pairs.n_records == N - 5


def test_frame_zero_is_not_a_sample():
    a = obj(1, range(3), (50.0, 50.0))
    pairs = frame_pairs(tracks([rec(0, 1, 50.0, 50.0)], on_object(a)), META, a)
    assert pairs.frames.tolist() == [1, 2] and pairs.n_objects == 2


# ---------------------------------------------------------------------------------------------
# Don't care


def test_a_record_on_an_object_mostly_out_of_view_counts_for_nothing():
    a = obj(1, range(N), (50.0, 50.0), (1.0, 0.0))
    b = obj(2, range(N), (150.0, 50.0), visible=0.4)  # below MIN_VISIBLE: don't care
    c = obj(3, range(N), (150.0, 15.0), visible=0.3)  # don't care, no record: not missed either
    assert tracking.MIN_VISIBLE == 0.5
    pairs = frame_pairs(tracks(on_object(a), on_object(b)), META, a + b + c)
    assert pairs.n_objects == N - 1 and pairs.n_records == N - 1
    assert recall(pairs) == 1.0 and precision(pairs) == 1.0
    assert set(pairs.matches["gt_id"].tolist()) == {1}
    assert set(pairs.objects) == {1}
    assert failures(pairs) == dict.fromkeys(FAILURES, 0)
    h = headline(evaluate_sequence(pairs))
    assert h["MOTA"] == pytest.approx(1.0) and h["HOTA"] == pytest.approx(1.0)


def test_an_object_exactly_half_visible_still_counts():
    b = obj(2, range(N), (150.0, 50.0), visible=0.5)
    pairs = frame_pairs(np.zeros(0, TRACK_DTYPE), META, b)
    assert pairs.n_objects == N - 1 and failures(pairs)["missed"] == N - 1


# ---------------------------------------------------------------------------------------------
# Accuracy figures


def test_accuracy_of_constant_errors():
    a = obj(1, range(N), (20.0, 50.0), (2.0, 0.0), size=(30.0, 40.0), label="red")  # radius 25
    s30 = (math.cos(math.radians(30)), math.sin(math.radians(30)))
    recs = on_object(a, dy=3.0, v=(2.0, 2.0), v_int=(2 * s30[0], 2 * s30[1]), dycc=(10.0, 3.0, -4.0))
    pairs = frame_pairs(tracks(recs), META, a)
    acc = accuracy(pairs.matches, META)
    assert acc["n_matches"] == N - 1
    assert acc["position_rel_rmse"] == pytest.approx(3.0 / 25.0)
    # MCM: error (0, 2) on a speed of 2; 45 degrees off.
    assert acc["mcm_nrmse"] == pytest.approx(1.0)
    assert acc["mcm_angle_deg"] == pytest.approx(45.0)
    # Interval: the true velocity turned by 30 degrees; error 2·2·sin(15°) on a speed of 2.
    assert acc["interval_nrmse"] == pytest.approx(2 * math.sin(math.radians(15)))
    assert acc["interval_angle_deg"] == pytest.approx(30.0)
    y, cb, cr = PALETTE_YCC["red"]
    assert acc["luminance_nrmse"] == pytest.approx(10.0 / y)
    assert acc["chrominance_nrmse"] == pytest.approx(math.sqrt((9 + 16) / 2) / ((cb + cr) / 2))
    assert acc["class_palette"] == 1.0 and acc["class_direct"] == 1.0  # still nearest to red


def test_accuracy_of_wrong_classes_and_without_colour():
    a = obj(1, range(N), (20.0, 50.0), (2.0, 0.0), label="red")
    half = (N - 1) // 2
    recs = on_object(a, frames=set(range(1, half + 1))) + on_object(a, frames=set(range(half + 1, N)), cls=NAMES.index("blue"))
    pairs = frame_pairs(tracks(recs), META, a)
    assert accuracy(pairs.matches, META)["class_palette"] == pytest.approx(0.5)
    plain = TrackMeta(width=200, height=100, t_frame_us=float(T_FRAME), palette=NAMES, has_colour=False)
    acc = accuracy(frame_pairs(tracks(recs), plain, a).matches, plain)
    assert acc["luminance_nrmse"] is None and acc["class_palette"] is None and acc["mcm_nrmse"] == pytest.approx(0.0)


def test_a_still_object_has_no_velocity_figure():
    a = obj(1, range(N), (50.0, 50.0))
    acc = accuracy(frame_pairs(tracks(on_object(a, v=(0.5, 0.0))), META, a).matches, META)
    assert acc["mcm_nrmse"] is None and acc["interval_angle_deg"] is None
    assert acc["position_rel_rmse"] == pytest.approx(0.0)


# ---------------------------------------------------------------------------------------------
# Pooled figures over scenes, and the tuning objective


def _result(name, pairs, textured: bool) -> SceneResult:
    return SceneResult(
        name=name, facts={"objects": [{"id": i, "textured": textured} for i in pairs.objects], "codec": False, "noise": False},
        model="float", events=0, wall_s=0.0, stats={}, trackeval=evaluate_sequence(pairs),
        n_objects=pairs.n_objects, n_records=pairs.n_records, matches=pairs.matches, objects=pairs.objects,
        meta=META, frames=pairs.frames, failures=pairs.failures,
    )  # fmt: skip


def _two_scenes():
    # Scene A: one object, 10 samples, all tracked. Scene B: two objects, 30 samples each; the
    # second tracked throughout, the first only in frames 1..10. (The second one's records make
    # a filter step at every frame, so the first one's last record is not sampled again later.)
    a = obj(1, range(11), (30.0, 50.0), (2.0, 0.0))
    b1 = obj(1, range(31), (30.0, 50.0), (2.0, 0.0))
    b2 = obj(2, range(31), (150.0, 20.0), (-1.0, 1.0))
    pa = frame_pairs(tracks(on_object(a)), META, a)
    pb = frame_pairs(tracks(on_object(b1, frames=set(range(1, 11))), on_object(b2)), META, b1 + b2)
    return _result("a", pa, textured=True), _result("b", pb, textured=False)


def test_figures_pool_counts_over_scenes():
    ra, rb = _two_scenes()
    assert ra.recall == 1.0 and rb.recall == pytest.approx(40 / 60)
    f = aggregate.figures([ra, rb])
    assert f["scenes"] == 2 and f["objects"] == 3
    assert f["recall"] == pytest.approx(50 / 70)  # matches over object samples, pooled
    assert f["recall"] != pytest.approx((ra.recall + rb.recall) / 2)  # not the mean of the recalls
    assert f["precision"] == pytest.approx(1.0)
    assert f["tracks_per_object"] == 1.0
    assert f["MOTA"] == pytest.approx(1 - 20 / 70)
    assert f["IDF1"] == pytest.approx(2 * 50 / (2 * 50 + 0 + 20))
    assert f["id_switches"] == 0
    assert f["n_matches"] == 50 and f["position_rel_rmse"] == pytest.approx(0.0)


def test_figures_over_a_category_of_objects():
    ra, rb = _two_scenes()
    textured = aggregate.figures([ra, rb], objects=aggregate.OBJECT_CATEGORIES["textured"])
    assert textured["objects"] == 1 and textured["recall"] == pytest.approx(1.0) and textured["precision"] is None
    uniform = aggregate.figures([ra, rb], objects=aggregate.OBJECT_CATEGORIES["uniform"])
    assert uniform["objects"] == 2 and uniform["recall"] == pytest.approx(40 / 60)
    # All three objects are 20 px and move at 1.4 px/frame or more: small and fast.
    assert aggregate.figures([ra, rb], objects=aggregate.OBJECT_CATEGORIES["small"])["recall"] == pytest.approx(50 / 70)
    assert aggregate.figures([ra, rb], objects=aggregate.OBJECT_CATEGORIES["fast"])["recall"] == pytest.approx(50 / 70)
    assert aggregate.figures([ra, rb], objects=aggregate.OBJECT_CATEGORIES["large"])["recall"] is None
    assert aggregate.figures([ra, rb], objects=aggregate.OBJECT_CATEGORIES["slow"])["objects"] == 0


def test_the_objective_is_zero_when_perfect_and_grows_as_recall_drops():
    ra, rb = _two_scenes()
    perfect = aggregate.figures([ra])
    assert perfect["recall"] == 1.0 and perfect["precision"] == 1.0
    assert aggregate.objective(perfect) == pytest.approx(0.0, abs=1e-6)
    # Recall 5/7; the per-sample errors stay zero, HOTA drops below 1 with the detections missed.
    pooled = aggregate.figures([ra, rb])
    assert 0.0 < pooled["HOTA"] < 1.0
    assert aggregate.objective(pooled) == pytest.approx(4 * (1 - pooled["HOTA"]) + (1 - 50 / 70), abs=1e-6)
    worse = dict(pooled, recall=0.25)  # recall alone weighs once
    assert aggregate.objective(worse) == pytest.approx(aggregate.objective(pooled) + (50 / 70 - 0.25), abs=1e-6)
    assert aggregate.objective(perfect) < aggregate.objective(pooled) < aggregate.objective(worse)


def test_a_frame_without_a_new_step_samples_the_last_records_again():
    # One filter step, at frame 1: what the tracker reports stays its output at every later frame.
    a = obj(1, range(N), (50.0, 50.0))
    pairs = frame_pairs(tracks([rec(T_FRAME, 1, 50.0, 50.0)]), META, a)
    assert pairs.n_records == N - 1 and pairs.matches.size == N - 1
    assert pairs.matches["frame"].tolist() == list(range(1, N))
