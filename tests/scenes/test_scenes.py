"""Scene files, the built-in scenes and their ground truth."""

from __future__ import annotations

import csv

import numpy as np
import pytest

from evclust.errors import EvclustError
from evclust.scenes import TRUTH_COLUMNS, builtin_scenes, load_scene, scene_from_toml, write_truth

TWO_LEGS = """
width = 100
height = 60
fps = 25
frames = 30
[background]
colour = [90, 90, 90]
[[objects]]
id = 7
label = "red"
shape = "ellipse"
size = [10, 6]
colour = [210, 40, 40]
start = [20, 30]
start_frame = 2
legs = [{ frames = 10, velocity = [3.0, 0.0] }, { frames = 12, velocity = [0.0, -4.0] }]
"""


def test_builtin_scenes_are_addressable_by_name_with_the_required_shape():
    names = builtin_scenes()
    assert {"pedestrian", "traffic", "crossing", "slow", "grey_on_grey"} <= set(names)
    ped, traffic = load_scene("pedestrian").spec, load_scene("traffic").spec
    assert (ped.width, ped.height, ped.fps) == (270, 480, 10) and abs(ped.frames - 277) <= 5
    assert (traffic.width, traffic.height, traffic.fps) == (480, 270, 20) and abs(traffic.frames - 291) <= 5
    labels = [o.label for o in traffic.objects]
    assert {label: labels.count(label) for label in set(labels)} == {"red": 1, "blue": 1, "yellow": 1, "white": 5, "grey": 2, "black": 2}
    # Two lanes driving in opposite directions along the vertical axis.
    vy = [o.legs[0].velocity[1] for o in traffic.objects]
    vx = [o.legs[0].velocity[0] for o in traffic.objects]
    assert all(v == 0 for v in vx) and sum(v > 0 for v in vy) == 6 and sum(v < 0 for v in vy) == 6


def test_pedestrian_walks_at_1_to_8_px_per_frame_and_leaves_and_reenters():
    scene = load_scene("pedestrian")
    speeds = [float(np.hypot(*leg.velocity)) for leg in scene.spec.objects[0].legs]
    assert min(speeds) >= 1 and max(speeds) <= 8
    visible = [row["fully_visible"] for row in scene.source.truth()]
    present = {row["frame"] for row in scene.source.truth()}
    gone = [k for k in range(scene.spec.frames) if k not in present]
    assert gone, "the person must leave the view entirely at some point"
    assert max(present) > min(gone), "and come back"
    assert sum(visible) > 0.7 * len(visible)


def test_truth_follows_the_path_with_forward_velocity_and_bt601_colour():
    rows = scene_from_toml(TWO_LEGS).source.truth()
    by_frame = {r["frame"]: r for r in rows}
    assert min(by_frame) == 2  # the object appears at start_frame
    assert by_frame[5]["cx"] == pytest.approx(20 + 3 * 3) and by_frame[5]["vx"] == 3.0
    assert by_frame[12]["cx"] == pytest.approx(50) and by_frame[12]["vy"] == -4.0  # second leg starts at frame 12
    assert by_frame[15]["cy"] == pytest.approx(30 - 4 * 3)
    # BT.601 full range of (210, 40, 40), written out independently of the code's matrix.
    y = 0.299 * 210 + 0.587 * 40 + 0.114 * 40
    cb = 128 + (40 - y) * 0.5 / (1 - 0.114)
    cr = 128 + (210 - y) * 0.5 / (1 - 0.299)
    assert (by_frame[5]["Y"], by_frame[5]["Cb"], by_frame[5]["Cr"]) == pytest.approx((y, cb, cr), abs=2e-3)
    assert (by_frame[5]["w"], by_frame[5]["h"]) == (10, 6)
    assert by_frame[5]["t_us"] == pytest.approx(5 * 40000)


def test_fully_visible_flag_turns_off_at_the_border():
    text = TWO_LEGS.replace("start = [20, 30]", "start = [4, 30]")
    rows = {r["frame"]: r for r in scene_from_toml(text).source.truth()}
    assert rows[2]["fully_visible"] == 0  # x from -1 to 9: partly outside
    assert rows[3]["fully_visible"] == 1  # x from 2 to 12


def test_truth_csv_has_the_documented_columns(tmp_path):
    path = tmp_path / "gt.csv"
    write_truth(path, scene_from_toml(TWO_LEGS).source.truth())
    with open(path) as f:
        reader = csv.DictReader(f)
        assert tuple(reader.fieldnames) == TRUTH_COLUMNS + ("visible",)
        # Present from frame 2 to 24; it leaves through the top once cy + 3 <= -0.5, that is
        # 30 - 4·(k - 12) <= -3.5, so frames 2..20 are visible.
        assert [int(r["frame"]) for r in reader] == list(range(2, 21))


def test_rendered_object_mean_colour_matches_truth():
    scene = scene_from_toml(
        TWO_LEGS.replace('shape = "ellipse"', 'shape = "rectangle"').replace("start = [20, 30]", "start = [20.5, 30.5]")
    )
    frame = scene.source.render(2)
    patch = frame[28:33, 16:25]  # fully inside a 10x6 rectangle centred on (20.5, 30.5)
    assert np.allclose(patch, [210, 40, 40])
    assert np.allclose(frame[0, 0], [90, 90, 90])


@pytest.mark.parametrize(
    "text, fault",
    [
        ("width = 10\nheight = [", "malformed TOML"),
        ("width = 10\nheight = 10\nfps = 10\nframes = 5\ncolour_depth = 3", "colour_depth"),
        ("width = 10\nheight = 10\nfps = 10\nframes = 5\n[sensor]\nthreshold_on = -0.2", "sensor.threshold_on"),
        ("width = 10\nheight = 10\nfps = 10", "frames"),
        (TWO_LEGS.replace("[3.0, 0.0]", "[3.0, 0.0, 1.0]"), "objects.0.legs.0.velocity"),
        (TWO_LEGS.replace("colour = [210, 40, 40]", "colour = [310, 40, 40]"), "objects.0.colour"),
    ],
)
def test_bad_scene_files_fail_with_one_line_naming_the_fault(text, fault):
    with pytest.raises(EvclustError) as err:
        scene_from_toml(text, "bad.toml")
    message = str(err.value)
    assert message.startswith("bad.toml: ") and fault in message and "\n" not in message


def test_unknown_scene_name_lists_the_builtin_ones():
    with pytest.raises(EvclustError, match="unknown scene 'nosuch'.*traffic"):
        load_scene("nosuch")
