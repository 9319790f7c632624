"""`make demo-video`'s steps on a small synthetic stand-in for vtest.avi: a video file of two
coloured disks crossing a textured background, through the same verbs in the same order."""

from __future__ import annotations

import json

import cv2
import numpy as np

from evclust.cli import main

W, H, FRAMES, FPS = 160, 120, 60, 25.0


def write_avi(path):
    rng = np.random.default_rng(3)
    background = cv2.GaussianBlur(rng.integers(70, 160, (H, W, 3)).astype(np.uint8), (5, 5), 0)
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), FPS, (W, H))
    assert writer.isOpened()
    for k in range(FRAMES):
        frame = background.copy()
        if k >= 20:  # the background model learns the empty scene first, as vtest's reference does
            cv2.circle(frame, (10 + 2 * (k - 20), 40), 11, (40, 40, 220), -1)
            cv2.circle(frame, (150 - 2 * (k - 20), 85), 11, (220, 60, 40), -1)
        writer.write(frame)
    writer.release()


def test_the_demo_video_steps_run_on_a_stand_in(tmp_path, capsys):
    video = tmp_path / "standin.avi"
    write_avi(video)
    tracks, reference, scores = tmp_path / "tracks.parquet", tmp_path / "reference.csv", tmp_path / "scores.json"
    picture, movie = tmp_path / "tracks.png", tmp_path / "tracks.mp4"
    assert main(["track", str(video), "-o", str(tracks), "--per-frame", "-q"]) == 0
    assert main(["reference", str(video), "-o", str(reference), "--warmup", "20", "--min-area", "150", "-q"]) == 0
    assert main(["score", str(tracks), "--truth", str(reference), "--json", str(scores)]) == 0
    assert main(["render", str(video), str(tracks), "-o", str(picture), "-q"]) == 0
    assert main(["render", str(video), str(tracks), "-o", str(movie), "-q"]) == 0
    figures = json.loads(scores.read_text())
    # Two disks on separate rows, always whole in view: each is found in nearly every frame the
    # reference sees it, by one track for its whole crossing (1.5: at most one of the two split
    # once), with no identity switch, its centre within the disk's 11 px radius, and its colour
    # the palette's red or blue.
    assert figures["recall"] > 0.9 and figures["precision"] > 0.9
    assert figures["tracks_per_object"] <= 1.5 and figures["id_switches"] == 0
    assert figures["position_rmse_px"] < 11.0
    assert figures["class_palette_accuracy"] > 0.9
    assert picture.stat().st_size > 0 and movie.stat().st_size > 0
