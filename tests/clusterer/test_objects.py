"""The object layer (clusterer/objects.py, fixed/objects.py) on directed streams whose answers
follow from its definition: one object for one blob, the edges of a bar grouped, identities kept
through an occlusion, births and deaths on their clocks; and the fixed model's agreement."""

from __future__ import annotations

import math

import numpy as np
import pytest

from evclust.clusterer import ClustererParams
from evclust.clusterer import objects as float_objects
from evclust.clusterer.layout import (
    O_HI_X, O_HI_Y, O_LO_X, O_LO_Y, O_MEMBERS, O_RX, O_RY, O_T_BORN, O_TOL, O_V_WEIGHT, O_VALID, O_VX, O_VY, O_X, O_Y, OBJECT_COLUMNS,
)  # fmt: skip
from evclust.clusterer.objects import DT_FRAMES_MAX, FloatObjects, rate_gain
from evclust.clusterer.run import FloatClusterer, rows_to_records
from evclust.run import rerun_objects, track_events
from evclust.fixed.formats import OBJECT_DT_FRAMES_FRAC, OBJECT_GAIN_FRAC, build_formats
from evclust.fixed.model import FixedClusterer
from evclust.fixed import objects as fixed_objects
from evclust.fixed.objects import _rate_gain, fixed_object_constants
from evclust.tracks import OBJECT_DTYPE, ObjectFlags
from evclust.vectors.cases import CASES, OBJECT_SMALL, _blobs, _object_params

W, H, T_FRAME = OBJECT_SMALL["width"], OBJECT_SMALL["height"], OBJECT_SMALL["t_frame_us"]


def objects_of(params: ClustererParams, events: np.ndarray, model: str = "float") -> np.ndarray:
    if model == "float":
        clusterer = FloatClusterer(params, W, H, T_FRAME)
        layer = FloatObjects(clusterer.params, W, H, T_FRAME)
    else:
        clusterer = FixedClusterer(params, W, H, T_FRAME)
        layer = clusterer.object_layer()
    rows = clusterer.feed(events)
    return rows_to_records(layer.feed(rows, clusterer.steps), OBJECT_DTYPE)


def moving_blob(vx=1.0, vy=0.5, t_end=200_000, seed=0):
    return _blobs([[(1000, t_end, 20, 20, vx, vy, (80, 90, 220))]], t_end, seed=seed)


@pytest.mark.parametrize("model", ["float", "fixed"])
def test_one_blob_at_constant_velocity_is_one_object_that_learns_its_velocity(model):
    objects = objects_of(_object_params(r_init=3.0), moving_blob(1.0, 0.5), model)
    assert np.unique(objects["id"]).size == 1
    assert (objects["flags"] & ObjectFlags.NEW).sum() == 1  # one start
    late = objects[objects["t_us"] > 100_000]
    # The blob's centre at t: (20 + (t - 1000)/10^4, 20 + 0.5 (t - 1000)/10^4) px; its events spread ±2 px.
    frames = (late["t_us"].astype(float) - 1000) / T_FRAME
    assert np.abs(late["x"] - (20 + frames)).max() < 2.5
    assert np.abs(late["y"] - (20 + 0.5 * frames)).max() < 2.5
    assert np.abs(late["vx"] - 1.0).mean() < 0.1 and np.abs(late["vy"] - 0.5).mean() < 0.1


@pytest.mark.parametrize("model", ["float", "fixed"])
def test_the_edges_of_a_uniform_bar_are_one_object_at_its_centre(model):
    case = CASES["object_two_edges"]()
    objects = objects_of(case.params, case.events, model)
    last = objects[objects["step"] == objects["step"].max()]
    assert last.size == 1 and last["members"][0] >= 3  # both edges' clusters
    # The bar's edges at step i: lead = round(30 + 0.05 i) and lead - 12; its centre 6 px behind the lead.
    lead = round(30 + 0.05 * 799)
    assert abs(last["x"][0] - (lead - 6)) <= 1.5
    assert abs(last["vx"][0] - 2.0) < 0.2  # 0.05 px per 250 µs = 2 px/frame


@pytest.mark.parametrize("model", ["float", "fixed"])
def test_an_object_coasts_through_an_occlusion_and_keeps_its_identity(model):
    case = CASES["object_occlusion"]()
    objects = objects_of(case.params, case.events, model)
    moving = objects[objects["y"] < 40]  # (the static blob is at y = 50)
    assert np.unique(moving["id"]).size == 1
    coasting = moving[(moving["flags"] & ObjectFlags.COASTING) != 0]
    assert coasting.size > 0 and (coasting["members"] == 0).all()
    # Reported while coasting for at most object_coast_frames after it was last seen (its cluster
    # outlives the blob's last event at 70 ms by its decay), to within a filter step.
    seen = moving["t_us"][(moving["members"] > 0) & (moving["t_us"] < coasting["t_us"].min())].max()
    assert 70_000 <= seen and coasting["t_us"].max() - seen <= case.params.object_coast_frames * T_FRAME + 1000


@pytest.mark.parametrize("model", ["float", "fixed"])
def test_objects_are_born_after_their_birth_time_and_die_after_their_keep_time(model):
    case = CASES["object_birth_death"]()
    params = case.params
    objects = objects_of(params, case.events, model)
    starts = {int(i): int(objects["t_us"][objects["id"] == i].min()) for i in np.unique(objects["id"])}
    # Blob a starts at 1 ms: its object is reported once it has had members for a frame.
    assert min(starts.values()) >= 1000 + params.object_birth_frames * T_FRAME - 2000
    # The flash (60 to 63 ms at (40, 55)) lasts less than a birth: no object there.
    assert not ((np.abs(objects["x"] - 40) < 5) & (np.abs(objects["y"] - 55) < 5)).any()
    # Blob a stops at 60 ms: its object is reported at most coast frames after it was last seen
    # (its cluster outlives the blob by its decay), to within a filter step; then never again.
    first = objects[objects["id"] == min(starts)]
    seen = first["t_us"][first["members"] > 0].max()
    assert seen >= 60_000 and first["t_us"].max() - seen <= params.object_coast_frames * T_FRAME + 1000
    # Blob c (from 100 ms) takes the slot of a, lost by then: a two-slot table, b's object still reported.
    third = objects[objects["id"] == max(starts)]
    assert starts[max(starts)] > 100_000 and third["slot"][0] == first["slot"][0]


def test_the_rate_gain_is_delta_over_t_squared_up_to_a_power_of_two_at_or_below_one_over_delta():
    assert rate_gain(0.0, 2.0) == 0.0
    assert rate_gain(1.0, 2.0) == pytest.approx(0.25)  # Δ ≤ T: Δ/T²
    assert rate_gain(3.0, 2.0) == 0.25  # Δ > T: 1/Δ = 0.33, rounded down to a power of two
    assert rate_gain(4.0, 2.0) == 0.25
    assert rate_gain(DT_FRAMES_MAX, 1.0) == 2.0**-10


@pytest.mark.parametrize("seen_frames", [0.0, 0.01, 0.5, 1.0, 1.5, 3.0, 7.9, 200.0])
def test_the_fixed_rate_gain_is_the_float_one_quantised(seen_frames):
    params = _object_params(object_rate_frames=1.5)
    table = build_formats(params, W, H, T_FRAME)
    k = fixed_object_constants(table)
    raw = int(seen_frames * 2**OBJECT_DT_FRAMES_FRAC)
    got = _rate_gain(np.int64(raw), k) / 2.0**OBJECT_GAIN_FRAC
    assert got == pytest.approx(rate_gain(raw / 2**OBJECT_DT_FRAMES_FRAC, 1.5), rel=1e-5, abs=2**-20)


@pytest.mark.parametrize("name", ["object_two_edges", "object_crossing", "object_turn", "object_occlusion", "suite_clip"])
def test_the_fixed_object_layer_follows_the_float_one(name):
    # (Not the split and merge cases: built on a decision's edge, they tip a few steps apart.)
    case = CASES[name]()
    f = FloatClusterer(case.params, case.width, case.height, case.t_frame_us)
    x = FixedClusterer(case.params, case.width, case.height, case.t_frame_us)
    ff = rows_to_records(FloatObjects(f.params, case.width, case.height, case.t_frame_us).feed(f.feed(case.events), f.steps), OBJECT_DTYPE)
    xx = rows_to_records(x.object_layer().feed(x.feed(case.events), x.steps), OBJECT_DTYPE)
    assert abs(ff.size - xx.size) <= 0.1 * max(ff.size, 1)
    assert np.unique(ff["id"]).size == np.unique(xx["id"]).size
    # Records of the same step and object: most of them (a birth or a split may come a few steps
    # apart), positions within a pixel, velocities within 0.1 px/frame.
    key = lambda r: (int(r["step"]), int(r["id"]))
    pairs = {key(r): r for r in ff}
    common = [(pairs[key(r)], r) for r in xx if key(r) in pairs]
    assert len(common) >= 0.75 * xx.size
    a, b = np.array([c[0] for c in common], OBJECT_DTYPE), np.array([c[1] for c in common], OBJECT_DTYPE)
    assert np.median(np.hypot(a["x"] - b["x"], a["y"] - b["y"])) < 0.5
    assert np.median(np.hypot(a["vx"] - b["vx"], a["vy"] - b["vy"])) < 0.1


def test_object_records_hold_their_invariants_on_a_suite_clip():
    case = CASES["suite_clip"]()
    x = FixedClusterer(case.params, case.width, case.height, case.t_frame_us)
    layer = x.object_layer()
    objects = rows_to_records(layer.feed(x.feed(case.events), x.steps), OBJECT_DTYPE)
    assert objects.size > 0
    new = (objects["flags"] & ObjectFlags.NEW) != 0
    assert np.unique(objects["id"][new]).size == new.sum() == np.unique(objects["id"]).size  # NEW once per id
    coasting = (objects["flags"] & ObjectFlags.COASTING) != 0
    assert ((objects["members"] == 0) == coasting).all()
    assert (objects["slot"] < case.params.n_objects).all()
    for step in np.unique(objects["step"]):  # one record per object per step
        ids = objects["id"][objects["step"] == step]
        assert np.unique(ids).size == ids.size
    assert np.isfinite(objects["vx"]).all() and math.isfinite(float(objects["x"].mean()))


def _jumping_box(centre_to_px: float, px: float) -> np.ndarray:
    """One object at (20, 20) moving at 1 px/frame along x, seen one frame ago, whose members'
    box now spans x from 35 to 65 (a cluster joined 30 px ahead): no member with a measured
    velocity. In the units of `px` (1: float; 2^F: raw fixed)."""
    O = np.zeros((1, len(OBJECT_COLUMNS)), np.float64 if px == 1 else np.int64)
    O[0, O_VALID], O[0, O_MEMBERS], O[0, O_V_WEIGHT], O[0, O_T_BORN] = 1, 1, -1, -T_FRAME
    O[0, O_X] = O[0, O_Y] = round(20 * centre_to_px)
    O[0, O_RX] = O[0, O_RY] = 5
    O[0, O_LO_X], O[0, O_HI_X] = round(35 * centre_to_px), round(65 * centre_to_px)
    O[0, O_LO_Y], O[0, O_HI_Y] = round(15 * centre_to_px), round(25 * centre_to_px)
    O[0, O_VX] = round(1.0 * px)
    return O


def test_a_box_that_jumps_as_a_cluster_joins_moves_the_velocity_by_its_tolerance_at_most():
    # g_rate over one frame with T_rate = 1 is 1: unclipped, the 30 px residual would give 31 px/frame.
    params = _object_params(object_rate_frames=1.0, object_track_frames=1.0, object_v_tol=0.25, object_v_rel=0.5)
    k = float_objects.object_constants(params, W, H, T_FRAME)
    O = _jumping_box(1.0, 1.0)
    O[0, O_TOL] = 0.25 + 0.5 * 1.0  # the tolerance of 1 px/frame
    float_objects._update(O, 0, float(T_FRAME), k)
    assert O[0, O_VX] == pytest.approx(1.0 + 0.75) and O[0, O_VY] == 0.0
    assert O[0, O_X] == pytest.approx(50.0)  # the centre itself follows the box (gain 1)
    # The fixed model: the same clip, in raw units of the velocity's format.
    table = build_formats(params, W, H, T_FRAME)
    kx = fixed_object_constants(table)
    O = _jumping_box(2.0**kx.fp, 2.0**kx.fv)
    O[0, O_TOL] = fixed_objects._tolerance(O[0, O_VX], O[0, O_VY], kx)
    tol = int(O[0, O_TOL])
    assert tol == pytest.approx(0.75 * 2**kx.fv, abs=2)
    fixed_objects._update(O, 0, np.int64(T_FRAME), kx, np.zeros(8, np.int64))
    assert int(O[0, O_VX]) == 2**kx.fv + tol and int(O[0, O_VY]) == 0


def test_rerunning_the_object_layer_over_a_runs_clusters_is_a_run_with_those_object_parameters():
    case = CASES["object_crossing"]()
    from evclust.events import EventMeta

    meta = EventMeta(width=case.width, height=case.height, t_frame_us=case.t_frame_us)
    first = track_events(case.events, meta, case.params)
    other = case.params.model_copy(update={"object_gate": 4.0, "object_velocity_frames": 1.0, "object_birth_frames": 0.5})
    again = rerun_objects(first, other)
    direct = track_events(case.events, meta, other)
    assert np.array_equal(again.objects, direct.objects) and again.objects.size > 0
    assert not np.array_equal(again.objects, first.objects)  # the parameters made a difference
    assert np.array_equal(again.tracks, first.tracks)
