"""The seeded scene generator (evclust.scenes.generate), the `visible` ground-truth column and
the gradient background."""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import cv2
import numpy as np
import pytest

from evclust.choices import SPLITS
from evclust.clusterer.params import DEFAULT_PALETTE
from evclust.colour import rgb_to_ycbcr
from evclust.errors import EvclustError
from evclust.scenes import load_scene, scene_from_toml
from evclust.scenes.generate import (
    FRAME_RATES,
    MAX_OBJECTS,
    MIN_LOG_CONTRAST,
    SENSOR_SIZES,
    SIZE_PX,
    SPEED_PX,
    generate_scene,
    write_scene,
)
from evclust.scenes.schema import BackgroundSpec
from evclust.scenes.synthetic import TRUTH_COLUMNS, TRUTH_OPTIONAL, SyntheticSource, make_background
from evclust.scenes.truth import read_truth, truth_array

ALL_SEEDS = tuple(SPLITS["tuning"]) + tuple(SPLITS["test"])
ROUND = 1e-3  # the generator rounds every number of the spec to 3 decimals


@pytest.fixture(scope="module")
def scenes():
    return {seed: generate_scene(seed) for seed in ALL_SEEDS}


def _pixel_frames(scene) -> int:
    s = scene.spec
    return s.width * s.height * s.frames


# ---------------------------------------------------------------------------------------------
# Determinism and the split


def test_the_same_seed_gives_the_same_scene():
    for seed in (0, 1, 7, 1000, 1031):
        a, b = generate_scene(seed), generate_scene(seed)
        assert a.spec == b.spec
        assert (a.codec, a.textured, a.noise, a.name) == (b.codec, b.textured, b.noise, b.name)


def test_different_seeds_give_different_scenes(scenes):
    specs = [scenes[s].spec for s in ALL_SEEDS]
    assert generate_scene(3).spec != generate_scene(4).spec
    # No two seeds of the suite share a scene (names aside: compare what is drawn).
    drawn = [s.model_dump(exclude={"name", "description", "seed"}) for s in specs]
    for i in range(len(drawn)):
        for j in range(i + 1, len(drawn)):
            assert drawn[i] != drawn[j], (ALL_SEEDS[i], ALL_SEEDS[j])


def test_a_negative_seed_is_refused():
    with pytest.raises(EvclustError):
        generate_scene(-1)


def test_the_tuning_and_test_splits_are_disjoint():
    tuning, test = set(SPLITS["tuning"]), set(SPLITS["test"])
    assert tuning.isdisjoint(test)
    assert len(test) >= 30
    assert len(tuning) == len(SPLITS["tuning"]) and len(test) == len(SPLITS["test"])  # no repeats


# ---------------------------------------------------------------------------------------------
# Ranges over every seed of both splits


def test_sensor_frame_rate_and_object_count_are_in_range(scenes):
    for seed, g in scenes.items():
        s = g.spec
        assert (s.width, s.height) in SENSOR_SIZES, seed
        assert s.fps in FRAME_RATES, seed
        assert 1 <= len(s.objects) <= MAX_OBJECTS, seed
        assert len(g.textured) == len(s.objects), seed
        assert s.video is None and s.frames >= 2, seed
        assert len({o.id for o in s.objects}) == len(s.objects), seed


def test_object_sizes_are_in_range_capped_by_the_sensor(scenes):
    for seed, g in scenes.items():
        s = g.spec
        cap = min(SIZE_PX[1], 0.45 * min(s.width, s.height))
        for o in s.objects:
            side = max(o.size)
            assert SIZE_PX[0] - ROUND <= side <= max(cap, SIZE_PX[0]) + ROUND, (seed, o.id, o.size)
            # The smaller side is at least half the larger one (aspect 0.5 .. 2).
            assert min(o.size) >= side / 2 - ROUND, (seed, o.id, o.size)


def test_leg_speeds_are_in_range(scenes):
    for seed, g in scenes.items():
        for o in g.spec.objects:
            assert 1 <= len(o.legs) <= 3
            for leg in o.legs:
                speed = math.hypot(*leg.velocity)
                assert SPEED_PX[0] - 2 * ROUND <= speed <= SPEED_PX[1] + 2 * ROUND, (seed, o.id, leg)


def test_paths_fit_in_the_scene(scenes):
    for seed, g in scenes.items():
        s = g.spec
        for o in s.objects:
            # The last leg ends at the last frame of the scene or before it.
            assert o.start_frame + sum(leg.frames for leg in o.legs) <= s.frames - 1, (seed, o.id)


def test_codec_exactly_for_even_seeds(scenes):
    for seed, g in scenes.items():
        assert g.codec == (seed % 2 == 0), seed
        if g.codec:
            assert g.spec.substeps == 1  # a video has only its frames


def test_every_kind_of_scene_and_object_appears(scenes):
    kinds = {g.spec.background.kind for g in scenes.values()}
    assert kinds == {"uniform", "texture", "gradient"}
    textured = [t for g in scenes.values() for t in g.textured]
    assert any(textured) and not all(textured)
    for g in scenes.values():  # a textured object has patches, a uniform one none
        for o, t in zip(g.spec.objects, g.textured):
            assert bool(o.patches) == t
    assert any(len(o.legs) > 1 for g in scenes.values() for o in g.spec.objects)  # turns


def test_some_object_enters_from_outside_the_view(scenes):
    def outside(o, s):
        x, y = o.start
        return not (-0.5 <= x <= s.width - 0.5 and -0.5 <= y <= s.height - 0.5)

    assert any(outside(o, g.spec) for g in scenes.values() for o in g.spec.objects)


def test_labels_are_palette_names(scenes):
    names = {e.name for e in DEFAULT_PALETTE}
    for seed, g in scenes.items():
        for o in g.spec.objects:
            assert o.label in names, (seed, o.label)


def _log_luma(rgb) -> float:
    return math.log(float(rgb_to_ycbcr(np.asarray(rgb, dtype=np.float64))[0]) + 1.0)


def test_objects_stand_out_of_a_uniform_background(scenes):
    checked = 0
    for seed, g in scenes.items():
        s = g.spec
        if s.background.kind != "uniform":
            continue
        bg = _log_luma(s.background.colour)
        for o in s.objects:
            # 1e-4: the colours were checked before being rounded to 3 decimals.
            assert abs(_log_luma(o.colour) - bg) >= MIN_LOG_CONTRAST - 1e-4, (seed, o.id, o.colour, s.background.colour)
            checked += 1
    assert checked > 0


# ---------------------------------------------------------------------------------------------
# write_scene


def test_a_clean_scene_written_and_read_back_is_the_same_scene(scenes, tmp_path):
    for seed in (seed for seed in ALL_SEEDS if seed % 2 == 1):
        g = scenes[seed]
        toml = write_scene(g, tmp_path / str(seed))
        assert toml == tmp_path / str(seed) / f"{g.name}.toml" and toml.is_file()
        scene = load_scene(toml)
        assert isinstance(scene.source, SyntheticSource)
        assert scene.spec == generate_scene(seed).spec
        assert not (tmp_path / str(seed) / f"{g.name}.mp4").exists()  # a clean scene has no video
        facts = json.loads((tmp_path / str(seed) / f"{g.name}.json").read_text())
        assert facts["codec"] is False and facts["seed"] == seed


def test_a_codec_scene_is_written_as_a_video_with_its_exact_truth(scenes, tmp_path):
    even = [seed for seed in ALL_SEEDS if seed % 2 == 0]
    seed = min(even, key=lambda s: _pixel_frames(scenes[s]))
    g = scenes[seed]
    s = g.spec
    assert s.width * s.height <= 320 * 240  # the smallest one is small: the test stays fast
    toml = write_scene(g, tmp_path)
    name = g.name

    video = tmp_path / f"{name}.mp4"
    assert video.is_file()
    capture = cv2.VideoCapture(str(video))
    assert capture.isOpened()
    frames = []
    while True:
        ok, bgr = capture.read()
        if not ok:
            break
        frames.append(cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB))
    capture.release()
    assert len(frames) == s.frames
    assert all(f.shape == (s.height, s.width, 3) for f in frames)
    # Lossy, but the frames are the scene's renders.
    source = SyntheticSource(s, tmp_path, name)
    for k in (0, s.frames // 2, s.frames - 1):
        err = np.abs(frames[k].astype(np.float64) - np.clip(source.render(k), 0, 255)).mean()
        assert err < 8.0, (k, err)

    truth_csv = tmp_path / f"{name}_truth.csv"
    truth = read_truth(truth_csv)
    expected = truth_array(source.truth())
    assert truth.size == expected.size > 0
    assert np.array_equal(truth["frame"], expected["frame"]) and np.array_equal(truth["id"], expected["id"])
    assert np.allclose(truth["cx"], expected["cx"]) and np.allclose(truth["visible"], expected["visible"])
    assert set(truth["id"].tolist()) <= {o.id for o in s.objects}
    assert truth["frame"].min() >= 0 and truth["frame"].max() <= s.frames - 1
    assert ((truth["visible"] >= 0) & (truth["visible"] <= 1)).all()

    facts = json.loads((tmp_path / f"{name}.json").read_text())
    assert facts["seed"] == seed and facts["codec"] is True and facts["noise"] == g.noise
    assert (facts["width"], facts["height"], facts["fps"], facts["frames"]) == (s.width, s.height, s.fps, s.frames)
    assert facts["background"] == s.background.kind
    assert [o["id"] for o in facts["objects"]] == [o.id for o in s.objects]
    assert [o["label"] for o in facts["objects"]] == [o.label for o in s.objects]
    assert [o["textured"] for o in facts["objects"]] == list(g.textured)
    for fo, o in zip(facts["objects"], s.objects):
        assert fo["size"] == pytest.approx(max(o.size))
        assert fo["legs"] == len(o.legs)
        assert fo["speed"] == pytest.approx(max(math.hypot(*leg.velocity) for leg in o.legs))

    scene = load_scene(toml)
    assert scene.spec.video == video.name and not scene.spec.objects
    assert scene.truth_path is not None and scene.truth_path.resolve() == truth_csv.resolve()
    assert scene.has_truth
    assert (scene.source.width, scene.source.height) == (s.width, s.height)
    assert scene.source.fps == s.fps
    assert scene.spec.sensor == s.sensor and scene.spec.effects == s.effects


# ---------------------------------------------------------------------------------------------
# The `visible` ground-truth column


def _static(id_: int, size, centre, colour="[220, 40, 40]") -> str:
    return f"""
[[objects]]
id = {id_}
label = "red"
size = [{size[0]}, {size[1]}]
colour = {colour}
start = [{centre[0]}, {centre[1]}]
legs = [{{ frames = 2, velocity = [0.0, 0.0] }}]
"""


def _visible(text: str) -> dict[tuple[int, int], float]:
    rows = scene_from_toml(text, "test").source.truth()
    return {(r["frame"], r["id"]): r["visible"] for r in rows}


HEADER = """
width = 100
height = 60
fps = 25
frames = 3
[background]
colour = [90, 90, 90]
"""


def test_an_object_half_outside_the_left_border_is_half_visible():
    # Pixel 0 covers [-0.5, 0.5]: a 20 px square centred on x = -0.5 spans [-10.5, 9.5], half of it
    # in [-0.5, 99.5]. Vertically it is whole ([19.5, 39.5]).
    vis = _visible(HEADER + _static(1, (20, 20), (-0.5, 29.5)))
    assert [vis[(k, 1)] for k in range(3)] == [pytest.approx(0.5, abs=1e-4)] * 3


def test_an_object_inside_the_view_is_fully_visible():
    vis = _visible(HEADER + _static(1, (20, 20), (50, 30)))
    assert [vis[(k, 1)] for k in range(3)] == [pytest.approx(1.0, abs=1e-4)] * 3


def test_a_quarter_in_the_bottom_right_corner():
    # A 20 px square centred on the corner pixel's outer corner (99.5, 59.5): a quarter inside.
    vis = _visible(HEADER + _static(1, (20, 20), (99.5, 59.5)))
    assert vis[(0, 1)] == pytest.approx(0.25, abs=1e-4)


def test_an_object_hidden_by_a_larger_one_drawn_after_it_is_not_visible():
    vis = _visible(HEADER + _static(1, (10, 10), (50, 30)) + _static(2, (30, 30), (50, 30), "[40, 40, 200]"))
    for k in range(3):
        assert vis[(k, 1)] == pytest.approx(0.0, abs=1e-4)
        assert vis[(k, 2)] == pytest.approx(1.0, abs=1e-4)


def test_the_order_decides_who_hides_whom():
    # The same two objects, the small one last: it is in front and fully visible; the large one
    # loses the small one's area, 100 of 900 px.
    vis = _visible(HEADER + _static(2, (30, 30), (50, 30), "[40, 40, 200]") + _static(1, (10, 10), (50, 30)))
    assert vis[(0, 1)] == pytest.approx(1.0, abs=1e-4)
    assert vis[(0, 2)] == pytest.approx(800 / 900, abs=1e-4)


def test_a_square_half_covered_by_a_later_one_is_half_visible():
    # Edges on pixel boundaries: [30.5, 50.5] and [40.5, 60.5], both [20.5, 40.5] vertically.
    vis = _visible(HEADER + _static(1, (20, 20), (40.5, 30.5)) + _static(2, (20, 20), (50.5, 30.5), "[40, 40, 200]"))
    for k in range(3):
        assert vis[(k, 1)] == pytest.approx(0.5, abs=1e-4)
        assert vis[(k, 2)] == pytest.approx(1.0, abs=1e-4)


def test_visibility_follows_a_moving_object_out_of_the_view():
    # A 10 px square moving left by 5 px/frame from centre 14.5 ([9.5, 19.5]): at frame k its left
    # edge is at 9.5 - 5k, so 10, 10, 10, 5, 0 px of its width are inside [-0.5, ...].
    text = (
        HEADER.replace("frames = 3", "frames = 5")
        + """
[[objects]]
id = 1
label = "red"
size = [10, 10]
colour = [220, 40, 40]
start = [14.5, 29.5]
legs = [{ frames = 4, velocity = [-5.0, 0.0] }]
"""
    )
    vis = _visible(text)
    assert vis[(0, 1)] == pytest.approx(1.0, abs=1e-4)
    assert vis[(1, 1)] == pytest.approx(1.0, abs=1e-4)
    assert vis[(2, 1)] == pytest.approx(1.0, abs=1e-4)  # [-0.5, 9.5]: just inside
    assert vis[(3, 1)] == pytest.approx(0.5, abs=1e-4)
    assert (4, 1) not in vis  # wholly outside: no row


# ---------------------------------------------------------------------------------------------
# The gradient background


def test_a_horizontal_gradient_runs_from_colour_to_colour_to():
    lo, hi = (10.0, 200.0, 30.0), (250.0, 20.0, 30.0)
    w, h = 41, 13
    bg = make_background(BackgroundSpec(kind="gradient", colour=lo, colour_to=hi, angle_deg=0), w, h, 0, Path("."))
    assert bg.shape == (h, w, 3)
    assert np.allclose(bg[:, 0], lo, atol=1e-3)
    assert np.allclose(bg[:, -1], hi, atol=1e-3)
    # Not along y: every row is the same.
    assert np.allclose(bg, bg[:1], atol=1e-4)
    # Along x: monotonic towards colour_to in each channel (constant where the ends agree).
    d = np.diff(bg[0], axis=0)  # (w-1, 3)
    assert (d[:, 0] > 0).all() and (d[:, 1] < 0).all() and np.allclose(d[:, 2], 0, atol=1e-4)
    # And linear: the middle column is the mean of the ends.
    assert np.allclose(bg[0, (w - 1) // 2], (np.array(lo) + np.array(hi)) / 2, atol=1e-3)


def test_a_vertical_gradient_changes_along_y_only():
    lo, hi = (0.0, 0.0, 0.0), (255.0, 255.0, 255.0)
    bg = make_background(BackgroundSpec(kind="gradient", colour=lo, colour_to=hi, angle_deg=90), 20, 11, 0, Path("."))
    assert np.allclose(bg[0], lo, atol=1e-3) and np.allclose(bg[-1], hi, atol=1e-3)
    assert np.allclose(bg, bg[:, :1], atol=1e-4)
    assert (np.diff(bg[:, 0, 0]) > 0).all()


def test_a_gradient_scene_loads_and_renders_its_background():
    text = """
width = 30
height = 10
fps = 25
frames = 2
[background]
kind = "gradient"
colour = [0, 0, 0]
colour_to = [240, 120, 60]
"""
    frame = scene_from_toml(text, "test").source.render(0)
    assert np.allclose(frame[:, 0], (0, 0, 0), atol=1e-3)
    assert np.allclose(frame[:, -1], (240, 120, 60), atol=1e-3)


# ---------------------------------------------------------------------------------------------
# Reading the `visible` column


def _row(**over):
    row = {
        "frame": 0, "t_us": 0.0, "id": 1, "cx": 10.0, "cy": 10.0, "w": 4.0, "h": 4.0, "vx": 1.0, "vy": 0.0,
        "Y": 100.0, "Cb": 128.0, "Cr": 128.0, "label": "red", "fully_visible": 1,
    }  # fmt: skip
    row.update(over)
    return row


def _write_csv(path: Path, rows, columns):
    with open(path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=columns)
        writer.writeheader()
        writer.writerows(rows)


def test_a_truth_csv_without_visible_reads_as_fully_visible(tmp_path):
    assert "visible" not in TRUTH_COLUMNS and TRUTH_OPTIONAL == {"visible": 1.0}
    path = tmp_path / "truth.csv"
    _write_csv(path, [_row(frame=0), _row(frame=1, t_us=40000.0)], TRUTH_COLUMNS)
    truth = read_truth(path)
    assert truth.size == 2
    assert truth["visible"].tolist() == [1.0, 1.0]
    # The same from dicts.
    assert truth_array([_row()])["visible"].tolist() == [1.0]


def test_a_truth_csv_with_visible_keeps_its_values(tmp_path):
    path = tmp_path / "truth.csv"
    _write_csv(path, [_row(frame=0, visible=0.25), _row(frame=1, visible=0), _row(frame=2, visible=1)], TRUTH_COLUMNS + ("visible",))
    assert read_truth(path)["visible"].tolist() == [0.25, 0.0, 1.0]


@pytest.mark.parametrize("bad", ["1.5", "-0.1"])
def test_a_visible_value_outside_0_1_is_refused(tmp_path, bad):
    path = tmp_path / "truth.csv"
    _write_csv(path, [_row(frame=0, visible=0.5), _row(frame=1, visible=bad)], TRUTH_COLUMNS + ("visible",))
    with pytest.raises(EvclustError, match="visible"):
        read_truth(path)
    with pytest.raises(EvclustError, match="visible"):
        truth_array([_row(visible=bad)])
