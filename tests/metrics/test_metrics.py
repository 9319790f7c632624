"""Metrics: hand-built tracks and truth, expected figures worked out by hand (docs/METRICS.md)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from evclust.cli import main
from evclust.errors import EvclustError
from evclust.metrics import MATCH_DTYPE, format_tables, match, nearest_palette_class, score
from evclust.metrics.match import gated_assignment
from evclust.scenes import TRUTH_COLUMNS, scene_from_toml, write_truth
from evclust.scenes.truth import read_truth, truth_array
from evclust.tracks import TRACK_DTYPE, TrackMeta, write_tracks

T = 1000.0  # frame period of the hand-built cases, µs

PALETTE = ("red", "blue", "grey")
PALETTE_YCBCR = ((80.0, 90.0, 240.0), (40.0, 240.0, 110.0), (110.0, 128.0, 128.0))


def make_meta(**changes) -> TrackMeta:
    base = dict(
        width=200,
        height=100,
        t_frame_us=T,
        palette=PALETTE,
        palette_ycbcr=PALETTE_YCBCR,
        palette_background=("grey",),
        luma_weight=1.0,
        has_colour=True,
    )
    base.update(changes)
    return TrackMeta(**base)


def make_tracks(*records: dict) -> np.ndarray:
    """Records with defaults: a cluster at rest with the truth's default colour."""
    out = np.zeros(len(records), dtype=TRACK_DTYPE)
    for i, r in enumerate(records):
        row = dict(
            slot=0,
            id=1,
            x=0.0,
            y=0.0,
            rx=5.0,
            ry=5.0,
            activity=10.0,
            vx_mcm=0.0,
            vy_mcm=0.0,
            vx_int=0.0,
            vy_int=0.0,
            Y=100.0,
            Cb=120.0,
            Cr=140.0,
            flags=0,
        )
        row["class"] = -1
        row.update(r)
        for name in TRACK_DTYPE.names:
            out[name][i] = row[name]
    return out


def gt_row(frame: int, id: int, cx: float, cy: float, **changes) -> dict:
    row = dict(
        frame=frame,
        t_us=frame * T,
        id=id,
        cx=cx,
        cy=cy,
        w=10.0,
        h=10.0,
        vx=0.0,
        vy=0.0,
        Y=100.0,
        Cb=120.0,
        Cr=140.0,
        label="red",
        fully_visible=1,
    )
    row.update(changes)
    return row


def static_object(frames, id=1, cx=50.0, cy=50.0, **changes) -> list[dict]:
    return [gt_row(k, id, cx, cy, **changes) for k in frames]


# ---------------------------------------------------------------------------------------------
# position and time alignment


def test_constant_offset_3_4_gives_position_rmse_5():
    truth = static_object(range(5))
    tracks = make_tracks(*[dict(t_us=k * 1000 + 200, step=k, x=53.0, y=54.0) for k in range(4)])
    s = score(tracks, make_meta(), truth)
    assert s.position_rmse_px == pytest.approx(5.0)
    assert s.n_matches == 4 and s.recall == 1.0 and s.precision == 1.0


def test_ground_truth_centre_is_interpolated_in_time_and_the_rest_comes_from_frame_k():
    # Object moves x: 10 (frame 0) -> 20 (frame 1) -> 20 (frame 2); its velocity changes at frame 1.
    truth = [
        gt_row(0, 1, 10.0, 30.0, vx=10.0, Y=60.0, label="red"),
        gt_row(1, 1, 20.0, 40.0, vx=0.0, Y=70.0, label="blue"),
        gt_row(2, 1, 20.0, 40.0, vx=0.0, Y=80.0, label="blue"),
    ]
    tracks = make_tracks(
        dict(t_us=250, step=0, x=0.0, y=0.0),  # frame 0, a quarter of the way to frame 1
        dict(t_us=999, step=1, x=0.0, y=0.0),  # still frame 0
        dict(t_us=1000, step=2, x=0.0, y=0.0),  # exactly frame 1
        dict(t_us=2600, step=3, x=0.0, y=0.0),  # frame 2: no frame 3 row, frame 2's centre
    )
    m = match(tracks, make_meta(), truth, gate_px=100)
    assert m.dtype == MATCH_DTYPE
    assert m["frame"].tolist() == [0, 0, 1, 2]
    assert m["gt_x"] == pytest.approx([12.5, 10 + 0.999 * 10, 20.0, 20.0])
    assert m["gt_y"] == pytest.approx([32.5, 30 + 0.999 * 10, 40.0, 40.0])
    assert m["gt_vx"].tolist() == [10.0, 10.0, 0.0, 0.0]  # frame k's velocity, not interpolated
    assert m["gt_Y"].tolist() == [60.0, 60.0, 70.0, 80.0]
    assert m["gt_label"].tolist() == ["red", "red", "blue", "blue"]


def test_a_track_on_the_interpolated_centre_has_zero_position_error():
    truth = [gt_row(0, 1, 10.0, 10.0), gt_row(1, 1, 14.0, 18.0)]
    tracks = make_tracks(dict(t_us=500, step=0, x=12.0, y=14.0))
    assert score(tracks, make_meta(), truth).position_rmse_px == pytest.approx(0.0, abs=1e-12)


# ---------------------------------------------------------------------------------------------
# velocity


def rotate(v, degrees):
    a = math.radians(degrees)
    return (v[0] * math.cos(a) - v[1] * math.sin(a), v[0] * math.sin(a) + v[1] * math.cos(a))


def test_velocity_rotated_by_a_known_angle_gives_that_angle_and_the_chord_as_error():
    # Step 0: V_gt = (2, 0), MCM rotated by +30 deg.  Step 1: V_gt = (0, 4), MCM rotated by -60 deg.
    # Step 2: V_gt = 0: skipped by the velocity figures.  Interval estimates are 0: 90 deg each.
    truth = [gt_row(0, 1, 50, 50, vx=2.0), gt_row(1, 1, 50, 50, vy=4.0), gt_row(2, 1, 50, 50)]
    e0, e1 = rotate((2.0, 0.0), 30), rotate((0.0, 4.0), -60)
    tracks = make_tracks(
        dict(t_us=100, step=0, x=50, y=50, vx_mcm=e0[0], vy_mcm=e0[1]),
        dict(t_us=1100, step=1, x=50, y=50, vx_mcm=e1[0], vy_mcm=e1[1]),
        dict(t_us=2100, step=2, x=50, y=50, vx_mcm=7.0, vy_mcm=7.0, vx_int=7.0),
    )
    s = score(tracks, make_meta(), truth)
    # |R(θ)v - v| = 2|v| sin(θ/2): 4 sin 15° and 8 sin 30° = 4
    chord0, chord1 = 4 * math.sin(math.radians(15)), 4.0
    rmse = math.sqrt((chord0**2 + chord1**2) / 2)
    assert s.n_velocity_evaluations == 2
    assert s.mcm.angular_deg == pytest.approx(45.0)  # mean of 30 and 60
    assert s.mcm.rmse == pytest.approx(rmse)
    assert s.mcm.nrmse == pytest.approx(rmse / 3.0)  # mean |V_gt| = (2 + 4) / 2
    assert s.interval.angular_deg == pytest.approx(90.0)
    assert s.interval.rmse == pytest.approx(math.sqrt((4 + 16) / 2))
    assert s.interval.nrmse == pytest.approx(math.sqrt(10) / 3)
    # the range covers every matched evaluation, the resting one included
    assert s.gt_vx_range == (0.0, 2.0) and s.gt_vy_range == (0.0, 4.0)


def test_opposite_velocity_is_180_degrees():
    truth = [gt_row(0, 1, 50, 50, vx=1.0, vy=1.0)]
    tracks = make_tracks(dict(t_us=0, step=0, x=50, y=50, vx_int=-3.0, vy_int=-3.0))
    s = score(tracks, make_meta(), truth)
    assert s.interval.angular_deg == pytest.approx(180.0)
    assert s.interval.rmse == pytest.approx(4 * math.sqrt(2))


# ---------------------------------------------------------------------------------------------
# colour and classification


def test_known_colour_offsets_give_known_rmse_and_nrmse():
    # Object 1: truth (100, 120, 140), estimate off by (+10, -6, +8).
    # Object 2: truth (50, 100, 200), estimate exact.
    truth = [gt_row(0, 1, 20, 50, Y=100, Cb=120, Cr=140), gt_row(0, 2, 150, 50, Y=50, Cb=100, Cr=200)]
    tracks = make_tracks(
        dict(t_us=10, step=0, id=1, x=20, y=50, Y=110, Cb=114, Cr=148),
        dict(t_us=10, step=0, id=2, slot=1, x=150, y=50, Y=50, Cb=100, Cr=200),
    )
    s = score(tracks, make_meta(), truth)
    assert s.n_colour_evaluations == 2
    assert s.luminance.rmse == pytest.approx(math.sqrt(100 / 2))
    assert s.luminance.nrmse == pytest.approx(math.sqrt(50) / 75)  # mean gt Y = 75
    # chrominance: mean over evaluations of (36 + 64) / 2, then (0 + 0) / 2
    assert s.chrominance.rmse == pytest.approx(math.sqrt(25))
    assert s.chrominance.nrmse == pytest.approx(5 / 140)  # mean of gt Cb and Cr = (110 + 170) / 2
    # all three: (100 + 36 + 64) / 3 and 0
    assert s.ycbcr.rmse == pytest.approx(math.sqrt(200 / 6))
    assert s.ycbcr.nrmse == pytest.approx(math.sqrt(200 / 6) / ((75 + 110 + 170) / 3))


def test_colour_is_skipped_without_colour():
    truth = [gt_row(0, 1, 20, 50)]
    tracks = make_tracks(dict(t_us=10, step=0, x=20, y=50, Y=0, Cb=0, Cr=0))
    s = score(tracks, make_meta(has_colour=False), truth)
    assert s.luminance.rmse is None and s.ycbcr.nrmse is None and s.class_direct_accuracy is None
    assert s.n_colour_evaluations == 0 and s.position_rmse_px == 0.0
    assert "n/a" in [line for line in format_tables(s).splitlines() if line.startswith("Luminance")][0]


def test_class_right_three_times_out_of_four_is_75_percent():
    truth = static_object(range(4), label="red")
    red, blue = PALETTE_YCBCR[0], PALETTE_YCBCR[1]
    tracks = make_tracks(
        # palette: red, red, blue, red     direct: blue, red, red, red
        dict(t_us=0, step=0, x=50, y=50, **{"class": 0}, Y=blue[0], Cb=blue[1], Cr=blue[2]),
        dict(t_us=1000, step=1, x=50, y=50, **{"class": 0}, Y=red[0] + 5, Cb=red[1], Cr=red[2]),
        dict(t_us=2000, step=2, x=50, y=50, **{"class": 1}, Y=red[0], Cb=red[1] - 5, Cr=red[2]),
        dict(t_us=3000, step=3, x=50, y=50, **{"class": 0}, Y=red[0], Cb=red[1], Cr=red[2] + 5),
    )
    m = match(tracks, make_meta(), truth)
    assert m["class_palette"].tolist() == [0, 0, 1, 0]
    assert m["class_direct"].tolist() == [1, 0, 0, 0]
    s = score(tracks, make_meta(), truth)
    assert s.class_palette_accuracy == 0.75 and s.class_direct_accuracy == 0.75
    assert s.n_class_evaluations == 4 and s.n_labels_not_in_palette == 0
    line = [line for line in format_tables(s).splitlines() if line.startswith("Classification")][0]
    assert "75.0% / 75.0%" in line


def test_no_class_and_unknown_label_are_wrong():
    truth = static_object(range(2), label="purple")
    tracks = make_tracks(dict(t_us=0, step=0, x=50, y=50, **{"class": -1}), dict(t_us=1000, step=1, x=50, y=50, **{"class": 0}))
    s = score(tracks, make_meta(), truth)
    assert s.class_palette_accuracy == 0.0 and s.n_labels_not_in_palette == 2


def test_direct_class_uses_weighted_l1_and_never_a_background_entry():
    meta = make_meta(palette=("A", "B", "bg"), palette_ycbcr=((0, 128, 128), (100, 118, 128), (60, 128, 128)), palette_background=("bg",))
    colour = np.array([[60.0, 128.0, 128.0]])  # exactly the background entry
    # L1 with weight 1: A = 60, B = 40 + 10 = 50 -> B.  Weight 0.1: A = 6, B = 4 + 10 = 14 -> A.
    assert nearest_palette_class(colour, meta).tolist() == [1]
    assert nearest_palette_class(colour, dataclass_replace(meta, luma_weight=0.1)).tolist() == [0]
    # a tie goes to the lower index: (50, 123, 128) is 50 + 5 from A and 50 + 5 from B
    assert nearest_palette_class(np.array([[50.0, 123.0, 128.0]]), meta).tolist() == [0]


def dataclass_replace(meta, **changes):
    import dataclasses

    return dataclasses.replace(meta, **changes)


# ---------------------------------------------------------------------------------------------
# matching, gate, tracking figures


def test_identity_switches_count_changes_of_track_id_per_object():
    # Object 1 is matched to ids 5, 5, 7, (nothing), 7, 5  -> switches 5->7 and 7->5: 2.
    # Object 2 is matched to id 9 throughout: 0.
    truth = static_object(range(6), id=1, cx=30, cy=50) + static_object(range(6), id=2, cx=150, cy=50)
    ids_1 = [5, 5, 7, None, 7, 5]
    records = []
    for k, tid in enumerate(ids_1):
        records.append(dict(t_us=k * 1000 + 1, step=k, id=9, slot=1, x=150, y=50))
        if tid is not None:
            records.append(dict(t_us=k * 1000 + 1, step=k, id=tid, slot=0, x=31, y=50))
    s = score(make_tracks(*records), make_meta(), truth)
    assert s.id_switches == 2
    assert s.tracks_per_object == pytest.approx((2 + 1) / 2)  # object 1: ids {5, 7}; object 2: {9}
    assert s.n_matches == 11 and s.n_gt_evaluations == 12
    assert s.recall == pytest.approx(11 / 12) and s.precision == 1.0


def test_the_gate_drops_far_pairs_and_counts_them_against_recall_and_precision():
    truth = static_object(range(2), cx=50, cy=50)
    tracks = make_tracks(
        dict(t_us=0, step=0, x=65, y=70),  # 25 px away: (15, 20)
        dict(t_us=1000, step=1, x=51, y=50),  # 1 px away
    )
    wide = score(tracks, make_meta(), truth, gate_px=25.0)  # kept: the gate is inclusive
    assert wide.n_matches == 2 and wide.position_rmse_px == pytest.approx(math.sqrt((625 + 1) / 2))
    narrow = score(tracks, make_meta(), truth, gate_px=24.9)
    assert narrow.n_matches == 1 and narrow.position_rmse_px == pytest.approx(1.0)
    assert narrow.recall == 0.5 and narrow.precision == 0.5
    assert match(tracks, make_meta(), truth, gate_px=24.9)["step"].tolist() == [1]


def test_hungarian_gets_a_crossing_right_where_greedy_nearest_does_not():
    # Objects A (id 1) at x=45 moving right and B (id 2) at x=55 moving left, about to cross.
    # Track 20 follows B but has overshot to x=49; track 10 follows A and lags at x=40.
    # Greedy nearest pairs 20-A (4 px) first, then 10-B (15 px): total 19.
    # The optimal assignment is 20-B (6 px) + 10-A (5 px): total 11.
    truth = [gt_row(0, 1, 45, 50, vx=2.0), gt_row(0, 2, 55, 50, vx=-2.0)]
    tracks = make_tracks(
        dict(t_us=0, step=0, id=20, slot=0, x=49, y=50),
        dict(t_us=0, step=0, id=10, slot=1, x=40, y=50),
    )
    m = match(tracks, make_meta(), truth)
    assert sorted(zip(m["gt_id"].tolist(), m["track_id"].tolist())) == [(1, 10), (2, 20)]
    assert score(tracks, make_meta(), truth).position_rmse_px == pytest.approx(math.sqrt((25 + 36) / 2))


def test_out_of_gate_pairs_do_not_steal_an_in_gate_match():
    # Gate 10. A at 0, B at 100. T1 at 1 (1 px from A, 99 from B); T2 at -9 (9 px from A, 109 from B).
    # Unconstrained minimum: T1-B + T2-A = 108 < T1-A + T2-B = 110, then T1-B is dropped: A gets the
    # 9 px track. With out-of-gate pairs forbidden A gets T1 at 1 px, and T2 stays unmatched.
    truth = [gt_row(0, 1, 0, 50), gt_row(0, 2, 100, 50)]
    tracks = make_tracks(dict(t_us=0, step=0, id=1, x=1, y=50), dict(t_us=0, step=0, id=2, slot=1, x=-9, y=50))
    m = match(tracks, make_meta(), truth, gate_px=10)
    assert list(zip(m["gt_id"].tolist(), m["track_id"].tolist())) == [(1, 1)]


def _match_step_by_step(tracks, meta, truth, gate):
    """The matching rule of docs/METRICS.md spelled out one filter step at a time: the oracle of
    match()'s all-steps-at-once pairing."""
    truth = truth_array(truth)
    row_of = {(int(f), int(i)): r for r, (f, i) in enumerate(zip(truth["frame"], truth["id"]))}
    pairs = []
    for step in sorted(set(zip(tracks["t_us"].tolist(), tracks["step"].tolist()))):
        records = np.flatnonzero((tracks["t_us"] == step[0]) & (tracks["step"] == step[1]))
        k = math.floor(step[0] / meta.t_frame_us)
        frac = step[0] / meta.t_frame_us - k
        objs = np.flatnonzero(truth["frame"] == k)
        centres = []
        for o in objs:
            nxt = row_of.get((k + 1, int(truth["id"][o])))
            c = np.array([truth["cx"][o], truth["cy"][o]])
            centres.append(c if nxt is None else c + frac * (np.array([truth["cx"][nxt], truth["cy"][nxt]]) - c))
        if not objs.size:
            continue
        cost = np.array([[math.dist((float(tracks["x"][r]), float(tracks["y"][r])), c) for c in centres] for r in records])
        rows, cols = gated_assignment(cost, gate)
        pairs += [(int(tracks["id"][records[i]]), int(truth["id"][objs[j]]), step[0]) for i, j in zip(rows, cols)]
    return pairs


@pytest.mark.parametrize("seed", range(4))
def test_all_steps_at_once_pair_as_step_by_step_does_on_crowded_random_scenes(seed):
    # Objects close together and records scattered around them, so that many steps have a record
    # within the gate of two objects (or an object with two records): the pairing must still be
    # each step's own gated Hungarian assignment, step by step.
    rng = np.random.default_rng(seed)
    truth = [gt_row(k, i, 40 + 6 * i + k * rng.uniform(-1, 1), 50 + rng.uniform(-3, 3)) for k in range(12) for i in range(4)
             if rng.uniform() < 0.85]  # fmt: skip
    records, step = [], 0
    for k in range(11):
        for t in sorted(rng.uniform(k * T, (k + 1) * T, 2).round()):
            for r in range(rng.integers(0, 6)):
                records.append(dict(t_us=int(t), step=step, id=r + 1, slot=r, x=rng.uniform(35, 70), y=rng.uniform(44, 56)))
            step += 1
    tracks = make_tracks(*records)
    m = match(tracks, make_meta(), truth, gate_px=5.0)
    pairs = list(zip(m["track_id"].tolist(), m["gt_id"].tolist(), m["t_us"].tolist()))
    assert pairs == _match_step_by_step(tracks, make_meta(), truth, 5.0)
    assert len(m) > 20


def test_an_object_twice_in_one_frame_is_named_where_it_first_repeats():
    truth = [gt_row(0, 1, 10, 10), gt_row(1, 2, 20, 20), gt_row(1, 1, 11, 10), gt_row(1, 2, 21, 20), gt_row(0, 1, 12, 10)]
    tracks = make_tracks(dict(t_us=0, step=0, x=10, y=10))
    with pytest.raises(EvclustError, match="object 2 has two rows for frame 1"):
        match(tracks, make_meta(), truth)


def test_fully_visible_only_leaves_out_partly_visible_objects_from_every_count():
    # Object 1 fully visible, object 2 partly visible (at the border); 2 steps; one spurious track.
    truth = static_object(range(2), id=1, cx=50, cy=50) + static_object(range(2), id=2, cx=2, cy=50, fully_visible=0)
    records = [dict(t_us=5, step=0, id=99, slot=2, x=150, y=90)]
    for k in range(2):
        records += [dict(t_us=k * 1000 + 5, step=k, id=1, x=50, y=50), dict(t_us=k * 1000 + 5, step=k, id=2, slot=1, x=4, y=50)]
    tracks = make_tracks(*records)
    every = score(tracks, make_meta(), truth)
    assert (every.n_matches, every.n_track_records, every.n_gt_evaluations) == (4, 5, 4)
    assert every.precision == 0.8 and every.position_rmse_px == pytest.approx(math.sqrt(2))
    visible = score(tracks, make_meta(), truth, fully_visible_only=True)
    assert (visible.n_matches, visible.n_track_records, visible.n_gt_evaluations) == (2, 3, 2)
    assert visible.precision == pytest.approx(2 / 3) and visible.recall == 1.0
    assert visible.position_rmse_px == 0.0
    assert match(tracks, make_meta(), truth, fully_visible_only=True)["fully_visible"].all()


def test_steps_missing_from_the_track_file_are_counted():
    truth = static_object(range(10))
    tracks = make_tracks(dict(t_us=2000, step=2, x=50, y=50), dict(t_us=7000, step=7, x=50, y=50))
    s = score(tracks, make_meta(), truth)
    assert s.n_steps == 2 and s.n_steps_missing == 6  # steps 0, 1, 3, 4, 5, 6


def test_empty_tracks_give_no_figures_not_an_error():
    s = score(make_tracks(), make_meta(), static_object(range(3)))
    assert s.n_matches == 0 and s.position_rmse_px is None and s.mcm.rmse is None and s.recall is None
    assert s.precision is None
    json.dumps(s.to_dict(), allow_nan=False)
    assert "n/a" in format_tables(s)


def test_perfect_tracks_of_a_synthetic_scene_score_zero_error():
    scene = scene_from_toml(
        """
        width = 120
        height = 80
        fps = 25
        frames = 12
        [[objects]]
        id = 1
        label = "red"
        size = [10, 10]
        colour = [210, 40, 40]
        start = [30, 40]
        legs = [{ frames = 11, velocity = [3.0, 1.0] }]
        [[objects]]
        id = 2
        label = "blue"
        size = [10, 10]
        colour = [40, 60, 200]
        start = [90, 40]
        legs = [{ frames = 11, velocity = [-3.0, -1.0] }]
        """
    )
    truth = scene.source.truth()
    velocity = {1: (3.0, 1.0), 2: (-3.0, -1.0)}
    start = {1: (30.0, 40.0), 2: (90.0, 40.0)}
    records = []
    for k in range(11):  # a step a quarter frame after every frame but the last
        for obj, (vx, vy) in velocity.items():
            row = next(r for r in truth if r["frame"] == k and r["id"] == obj)
            x, y = start[obj][0] + vx * (k + 0.25), start[obj][1] + vy * (k + 0.25)
            records.append(
                dict(
                    t_us=k * 40000 + 10000,
                    step=k,
                    id=obj,
                    slot=obj,
                    x=x,
                    y=y,
                    vx_mcm=vx,
                    vy_mcm=vy,
                    vx_int=vx,
                    vy_int=vy,
                    Y=row["Y"],
                    Cb=row["Cb"],
                    Cr=row["Cr"],
                    **{"class": obj - 1},
                )
            )
    meta = make_meta(width=120, height=80, t_frame_us=40000.0)
    s = score(make_tracks(*records), meta, truth)
    assert s.n_matches == 22 and s.recall == 1.0 and s.precision == 1.0 and s.id_switches == 0
    assert s.position_rmse_px < 1e-3
    assert s.mcm.rmse == pytest.approx(0.0, abs=1e-9) and s.interval.angular_deg == pytest.approx(0.0, abs=1e-4)
    assert s.ycbcr.rmse == pytest.approx(0.0, abs=1e-9)
    assert s.class_palette_accuracy == 1.0
    assert s.gt_vx_range == (-3.0, 3.0) and s.gt_vy_range == (-1.0, 1.0)


def test_format_tables_has_the_papers_rows_and_one_column_per_run():
    truth = static_object(range(2), vx=1.0)
    a = score(make_tracks(dict(t_us=0, step=0, x=53, y=54, vx_mcm=1.0)), make_meta(), truth)
    b = score(make_tracks(dict(t_us=0, step=0, x=50, y=50, vx_mcm=1.0)), make_meta(), truth)
    text = format_tables({"sceneA": a, "sceneB": b})
    lines = text.splitlines()
    for heading in (
        "Ground Truth Range",
        "MCM",
        "Interval",
        "Position",
        "YCbCr",
        "Luminance",
        "Chrominance",
        "Classification",
        "Recall",
        "Precision",
        "ID switches",
    ):
        assert any(heading in line for line in lines), heading
    position = next(line for line in lines if line.startswith("Position"))
    assert position.split()[-2:] == ["5.000", "0.000"]
    assert "sceneA" in text and "sceneB" in text
    velocity_rows = [line.split()[0] for line in text.split("\n\n")[0].splitlines()[3:] if line and not line.startswith(" ")]
    assert velocity_rows == ["Ground", "MCM", "Interval"]


# ---------------------------------------------------------------------------------------------
# files and command line


def test_truth_round_trips_through_the_csv(tmp_path):
    rows = static_object(range(2), cx=1.5, cy=2.25, label="green", fully_visible=0) + [gt_row(0, 7, 3, 4, vx=-0.5)]
    write_truth(tmp_path / "gt.csv", rows)
    truth = read_truth(tmp_path / "gt.csv")
    assert truth.dtype.names == TRUTH_COLUMNS + ("visible",) and truth.size == 3 and truth["visible"].tolist() == [1.0] * 3
    assert truth["cx"].tolist() == [1.5, 1.5, 3.0] and truth["label"].tolist() == ["green", "green", "red"]
    assert truth["fully_visible"].tolist() == [False, False, True] and truth["vx"][2] == -0.5
    assert np.array_equal(truth, truth_array(rows))


def _csv(tmp_path, text, name="gt.csv"):
    path = tmp_path / name
    path.write_text(text)
    return path


HEADER = ",".join(TRUTH_COLUMNS)
GOOD_LINE = "0,0,1,10,10,4,4,1,0,100,120,140,red,1"


@pytest.mark.parametrize(
    "text, fragments",
    [
        ("", ("line 1", "empty file")),
        (HEADER.replace(",vy", "") + "\n", ("line 1", "missing column(s) vy")),
        (HEADER.replace("Cb", "cb").replace(",label", "") + "\n", ("line 1", "Cb, label")),
        (HEADER + "\n" + GOOD_LINE + "\n0,0,2,ten,10,4,4,1,0,100,120,140,red,1\n", ("line 3", "column cx", "'ten' is not a number")),
        (HEADER + "\n" + GOOD_LINE + "\n0,0,2,10,nan,4,4,1,0,100,120,140,red,1\n", ("line 3", "column cy", "finite")),
        (HEADER + "\n1.5,0,1,10,10,4,4,1,0,100,120,140,red,1\n", ("line 2", "column frame", "integer")),
        (HEADER + "\n" + GOOD_LINE + "\n0,0,1,10,10,4,4\n", ("line 3", "7 values")),
        (HEADER + "\n" + GOOD_LINE + "\n\n" + GOOD_LINE + "\n", ("line 4", "object 1", "frame 0", "line 2")),
        (HEADER + "\n0,0,1,10,10,4,4,1,0,100,120,140,red,maybe\n", ("line 2", "fully_visible")),
    ],
)
def test_bad_truth_files_raise_one_line_naming_file_line_and_fault(tmp_path, text, fragments):
    path = _csv(tmp_path, text)
    with pytest.raises(EvclustError) as err:
        read_truth(path)
    message = str(err.value)
    assert len(message.splitlines()) == 1 and message.startswith(str(path))
    for fragment in fragments:
        assert fragment in message, message


def test_missing_truth_file(tmp_path):
    with pytest.raises(EvclustError, match="no such ground-truth file"):
        read_truth(tmp_path / "nope.csv")


def test_bad_gate_is_refused():
    with pytest.raises(EvclustError, match="gate"):
        score(make_tracks(), make_meta(), [], gate_px=0)


def run_cli(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def _files(tmp_path):
    truth = static_object(range(4))
    tracks = make_tracks(*[dict(t_us=k * 1000 + 200, step=k, x=53.0, y=54.0, **{"class": 0}) for k in range(4)])
    write_truth(tmp_path / "gt.csv", truth)
    write_tracks(tmp_path / "tracks.csv", tracks, make_meta(source="hand"))
    return tmp_path / "tracks.csv", tmp_path / "gt.csv"


def test_cli_prints_the_tables_and_writes_json(tmp_path, capsys):
    tracks, truth = _files(tmp_path)
    code, out, err = run_cli(capsys, "score", tracks, "--truth", truth, "--json", tmp_path / "out" / "s.json", "--gate", 12)
    assert code == 0, err
    position = next(line for line in out.splitlines() if line.startswith("Position"))
    assert position.split()[-1] == "5.000"
    doc = json.loads((tmp_path / "out" / "s.json").read_text())
    assert doc["position_rmse_px"] == pytest.approx(5.0) and doc["gate_px"] == 12.0
    assert doc["class_palette_accuracy"] == 1.0 and doc["mcm"]["rmse"] is None  # truth at rest
    assert doc["source"] == "hand" and doc["truth"].endswith("gt.csv")
    assert [p.name for p in (tmp_path / "out").iterdir()] == ["s.json"]  # no temporary left behind


def test_cli_help_is_complete(capsys):
    assert main(["score", "--help"]) == 0
    text = capsys.readouterr().out
    for option in ("TRACKS", "--truth", "--json", "--gate", "--fully-visible", "default: 30"):
        assert option in text


def assert_one_line_error(code, err, *fragments):
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("evclust: error: "), err
    for fragment in fragments:
        assert fragment in lines[0], lines[0]


def test_cli_bad_inputs_give_one_line_exit_2_and_no_json(tmp_path, capsys):
    tracks, truth = _files(tmp_path)
    out_json = tmp_path / "s.json"
    code, _, err = run_cli(capsys, "score", tmp_path / "none.csv", "--truth", truth, "--json", out_json)
    assert_one_line_error(code, err, "none.csv")
    code, _, err = run_cli(capsys, "score", tracks, "--truth", tmp_path / "none_gt.csv", "--json", out_json)
    assert_one_line_error(code, err, "none_gt.csv", "no such ground-truth file")
    lines = tracks.read_text().splitlines()
    lines[1] = lines[1].replace(",vx_mcm", "")
    broken = _csv(tmp_path, "\n".join(lines) + "\n", "broken_tracks.csv")
    code, _, err = run_cli(capsys, "score", broken, "--truth", truth, "--json", out_json)
    assert_one_line_error(code, err, "broken_tracks.csv", "vx_mcm")
    bad_truth = _csv(tmp_path, HEADER.replace(",label", "") + "\n", "bad_gt.csv")
    code, _, err = run_cli(capsys, "score", tracks, "--truth", bad_truth, "--json", out_json)
    assert_one_line_error(code, err, "bad_gt.csv", "line 1", "label")
    assert not out_json.exists()
    code, _, err = run_cli(capsys, "score", tracks, "--truth", truth, "--gate", "-3")
    assert_one_line_error(code, err, "--gate")  # a usage error: one line too
