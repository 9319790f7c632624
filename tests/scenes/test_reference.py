"""The frame-based reference for real videos (evclust reference), on videos with known answers."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from evclust.cli import main
from evclust.colour import rgb_to_ycbcr
from evclust.scenes.truth import read_truth

from testkit import assert_one_line_error, run_cli

W, H, FRAMES, WARMUP = 160, 120, 60, 15
RED, BLUE = (220, 40, 40), (40, 60, 220)


def write_video(folder, disks, frames=FRAMES, seed=0):
    """A folder of lossless PNG frames: a static random texture, and from frame WARMUP on (the
    background model has learnt the empty scene, as a camera switched on before anyone walks in)
    disks (start x, y, vx, vy, radius, RGB) moving at constant velocity."""
    folder.mkdir()
    rng = np.random.default_rng(seed)
    background = rng.integers(90, 140, (H, W, 3)).astype(np.uint8)
    background = cv2.GaussianBlur(background, (5, 5), 0)
    for k in range(frames):
        frame = background.copy()
        for x0, y0, vx, vy, r, rgb in disks if k >= WARMUP else ():
            cv2.circle(frame, (int(round(x0 + vx * k)), int(round(y0 + vy * k))), r, rgb, -1, cv2.LINE_8)
        cv2.imwrite(str(folder / f"{k:04d}.png"), cv2.cvtColor(frame, cv2.COLOR_RGB2BGR))
    return folder


def reference(tmp_path, folder, *extra):
    out = tmp_path / "ref.csv"
    args = ["reference", str(folder), "-o", str(out), "--fps", "25", "--warmup", str(WARMUP), "--min-area", "100", "-q", *extra]
    assert main(args) == 0
    return read_truth(out)


def test_one_moving_disk_is_one_object_with_its_velocity_centre_and_colour(tmp_path):
    x0, y0, vx, vy = 20.0, 30.0, 2.0, 1.0
    truth = reference(tmp_path, write_video(tmp_path / "one", [(x0, y0, vx, vy, 12, RED)]))
    frames = np.arange(WARMUP, FRAMES - 1)  # the last frame has no next one to give a velocity
    assert np.array_equal(np.sort(truth["frame"]), frames)
    assert len(set(truth["id"].tolist())) == 1
    k = truth["frame"]
    np.testing.assert_allclose(truth["vx"], vx, atol=0.3)
    np.testing.assert_allclose(truth["vy"], vy, atol=0.3)
    np.testing.assert_allclose(truth["cx"], np.round(x0 + vx * k), atol=1.5)
    np.testing.assert_allclose(truth["cy"], np.round(y0 + vy * k), atol=1.5)
    np.testing.assert_allclose(truth["w"], 25, atol=2)  # a disk of radius 12 spans 25 px
    want = rgb_to_ycbcr(np.array(RED, float))
    for j, name in enumerate(("Y", "Cb", "Cr")):
        assert abs(np.median(truth[name]) - want[j]) < 6, name
    assert set(truth["label"].tolist()) == {"red"}


def test_two_disks_keep_their_own_identities(tmp_path):
    disks = [(20.0, 30.0, 1.5, 0.0, 10, RED), (140.0, 90.0, -1.5, 0.0, 10, BLUE)]
    truth = reference(tmp_path, write_video(tmp_path / "two", disks))
    ids = sorted(set(truth["id"].tolist()))
    assert len(ids) == 2
    for ident in ids:
        rows = truth[truth["id"] == ident]
        going_right = rows["vx"].mean() > 0
        assert np.all((rows["vx"] > 0) == going_right)  # never swapped with the other disk
        assert np.all(np.abs(rows["cy"] - (30 if going_right else 90)) < 1.5)


def test_a_static_scene_has_no_objects(tmp_path):
    truth = reference(tmp_path, write_video(tmp_path / "still", []))
    assert truth.size == 0


def test_score_takes_the_reference_as_truth(tmp_path, capsys):
    folder = write_video(tmp_path / "clip", [(20.0, 30.0, 2.0, 1.0, 12, RED)])
    reference(tmp_path, folder)
    tracks = tmp_path / "tracks.parquet"
    assert main(["track", str(folder), "-o", str(tracks), "-q"]) == 2  # an image folder needs its frame rate: from a scene file
    scene = tmp_path / "clip.toml"
    scene.write_text(f'video = "{folder.name}"\nfps = 25\n')
    assert main(["track", str(scene), "-o", str(tracks), "-q"]) == 0
    code, stdout, err = run_cli(capsys, "score", str(tracks), "--truth", str(tmp_path / "ref.csv"))
    assert code == 0, err
    assert "Recall" in stdout and "tracks per object" in stdout


@pytest.mark.parametrize(
    "args, fragments",
    [
        (["absent.avi"], ("absent.avi", "no such video")),
        (["clip", "--min-area", "0"], ("--min-area 0",)),
        (["clip", "--frames", "1"], ("--frames 1",)),
        (["clip"], ("clip", "frame rate")),  # an image folder without --fps
    ],
)
def test_bad_input_fails_with_one_line_and_no_output(tmp_path, capsys, args, fragments):
    write_video(tmp_path / "clip", [], frames=3)
    args = [str(tmp_path / args[0]), *args[1:]]
    out = tmp_path / "never.csv"
    code, _, err = run_cli(capsys, "reference", *args, "-o", str(out))
    assert_one_line_error(code, err, *fragments)
    assert not out.exists()
