"""The command line: complete help, one clear line for bad input, no partial output, videos."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import cv2
import numpy as np
import pytest

from evclust.cli import main
from evclust.events import read_events
from evclust.scenes import load_scene

from testkit import GOOD_SCENE, assert_one_line_error, run_cli


@pytest.mark.parametrize("verb", ["simulate", "track", "score", "render", "plot", "show", "scenes"])
def test_every_verb_has_complete_help(capsys, verb):
    assert main([verb, "--help"]) == 0
    text = capsys.readouterr().out
    assert text.startswith(f"usage: evclust {verb}") and len(text.splitlines()) > 4


def test_top_level_help_lists_the_verbs(capsys):
    assert main(["--help"]) == 0
    text = capsys.readouterr().out
    assert all(verb in text for verb in ("simulate", "show", "scenes"))


def test_simulate_writes_events_truth_and_a_summary_line(tmp_path, capsys):
    scene = tmp_path / "s.toml"
    scene.write_text(GOOD_SCENE)
    code, out, err = run_cli(capsys, "simulate", str(scene), "-o", str(tmp_path / "e.h5"), "--truth", str(tmp_path / "gt.csv"), "-q")
    assert code == 0, err
    ev, meta = read_events(tmp_path / "e.h5")
    assert ev.size > 0 and (meta.width, meta.height) == (40, 30)
    assert f"6 frames, {ev.size} events" in out and "events/s of scene time" in out and "wall time" in out
    assert (tmp_path / "gt.csv").read_text().count("\n") == 1 + 6


@pytest.mark.parametrize(
    "scene_text, fragments",
    [
        ("width = 40\nheight = [", ("malformed TOML",)),
        (GOOD_SCENE + "\n[effects.no_such_effect]\nx = 1\n", ("effects.no_such_effect", "unknown effect")),
        (GOOD_SCENE + "\n[effects.threshold_mismatch]\nsigmaa = 0.1\n", ("effects.threshold_mismatch.sigmaa",)),
        (GOOD_SCENE + "\n[effects.threshold_mismatch]\nsigma = -1\n", ("effects.threshold_mismatch.sigma", "greater than 0")),
        (GOOD_SCENE.replace("fps = 30", "fps = 30\nflicker = 2"), ("flicker", "Extra inputs")),
        (GOOD_SCENE.replace("fps = 30", "fps = -3"), ("fps", "greater than 0")),
    ],
)
def test_bad_scene_files_give_one_line_and_no_output(tmp_path, capsys, scene_text, fragments):
    scene = tmp_path / "bad.toml"
    scene.write_text(scene_text)
    out_path = tmp_path / "out" / "e.npz"
    code, _, err = run_cli(capsys, "simulate", str(scene), "-o", str(out_path), "--truth", str(tmp_path / "gt.csv"), "-q")
    assert_one_line_error(code, err, "bad.toml", *fragments)
    assert not out_path.exists() and not (tmp_path / "gt.csv").exists()


def test_unknown_scene_name(tmp_path, capsys):
    code, _, err = run_cli(capsys, "simulate", "highway", "-o", str(tmp_path / "e.npz"))
    assert_one_line_error(code, err, "unknown scene 'highway'", "pedestrian")
    assert list(tmp_path.iterdir()) == []


def test_unreadable_and_empty_videos(tmp_path, capsys):
    garbage = tmp_path / "garbage.mp4"
    garbage.write_bytes(b"\x00\x01 this is not a video" * 100)
    code, _, err = run_cli(capsys, "simulate", str(garbage), "-o", str(tmp_path / "e.npz"))
    assert_one_line_error(code, err, "garbage.mp4", "cannot read a frame")
    empty = tmp_path / "empty.avi"
    writer = cv2.VideoWriter(str(empty), cv2.VideoWriter_fourcc(*"FFV1"), 25, (32, 24))
    writer.release()
    code, _, err = run_cli(capsys, "simulate", str(empty), "-o", str(tmp_path / "e.npz"))
    assert_one_line_error(code, err, "empty.avi")
    empty_folder = tmp_path / "frames"
    empty_folder.mkdir()
    code, _, err = run_cli(capsys, "simulate", str(empty_folder), "-o", str(tmp_path / "e.npz"), "--fps", "10")
    assert_one_line_error(code, err, "holds no images")
    assert not (tmp_path / "e.npz").exists()


def test_out_of_range_options_and_truth_without_source(tmp_path, capsys):
    code, _, err = run_cli(capsys, "simulate", "slow", "-o", str(tmp_path / "e.npz"), "--frames", "1")
    assert_one_line_error(code, err, "--frames 1")
    video = tmp_path / "v.avi"
    _write_video(video, [np.zeros((24, 32, 3), np.uint8)] * 3)
    code, _, err = run_cli(capsys, "simulate", str(video), "-o", str(tmp_path / "e.npz"), "--truth", str(tmp_path / "gt.csv"))
    assert_one_line_error(code, err, "no ground truth")
    assert not (tmp_path / "e.npz").exists()


def test_unwritable_output_is_one_line(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("")
    code, _, err = run_cli(capsys, "simulate", "slow", "-o", str(blocker / "e.npz"), "--frames", "3", "-q")
    assert_one_line_error(code, err)


def _write_video(path, frames_rgb, fps=30):
    h, w = frames_rgb[0].shape[:2]
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"FFV1"), fps, (w, h))
    for frame in frames_rgb:
        writer.write(cv2.cvtColor(frame, cv2.COLOR_RGB2BGR))
    writer.release()


def test_a_video_and_the_same_frames_as_images_give_the_same_events(tmp_path, capsys):
    source = load_scene("crossing").source
    frames = [np.clip(np.rint(source.render(k)), 0, 255).astype(np.uint8) for k in range(40)]
    video = tmp_path / "crossing.avi"
    _write_video(video, frames)
    # The codec is lossless, so both inputs hold exactly the same frames.
    capture = cv2.VideoCapture(str(video))
    decoded = []
    while (ok_frame := capture.read())[0]:
        decoded.append(cv2.cvtColor(ok_frame[1], cv2.COLOR_BGR2RGB))
    assert len(decoded) == len(frames) and all(np.array_equal(a, b) for a, b in zip(decoded, frames))
    folder = tmp_path / "images"
    folder.mkdir()
    for k, frame in enumerate(frames):
        cv2.imwrite(str(folder / f"frame_{k:04d}.png"), cv2.cvtColor(frame, cv2.COLOR_RGB2BGR))
    assert main(["simulate", str(video), "-o", str(tmp_path / "v.npz"), "-q"]) == 0
    assert main(["simulate", str(folder), "-o", str(tmp_path / "i.npz"), "--fps", "30", "-q"]) == 0
    from_video, meta_video = read_events(tmp_path / "v.npz")
    from_images, meta_images = read_events(tmp_path / "i.npz")
    assert from_video.size > 1000
    assert np.array_equal(from_video, from_images)
    assert meta_video.t_frame_us == pytest.approx(meta_images.t_frame_us)


def _console_script() -> str:
    return shutil.which("evclust") or str(Path(sys.executable).parent / "evclust")


def test_console_script_reports_bad_input_without_traceback(tmp_path):
    result = subprocess.run([_console_script(), "simulate", "nosuch", "-o", str(tmp_path / "e.npz")], capture_output=True, text=True)
    assert result.returncode == 2
    assert result.stderr.strip().splitlines() == [
        "evclust: error: unknown scene 'nosuch': built-in scenes are crossing, grey_on_grey, pedestrian, slow, traffic"
    ]


def test_the_console_script_ends_at_once_yet_flushes_all_that_main_printed(capsys):
    # The script leaves by os._exit (evclust.cli.entry): piped and buffered (PYTHONUNBUFFERED
    # unset), the end of the output would be lost without the flush.
    code, out, _ = run_cli(capsys, "formats")
    env = {k: v for k, v in os.environ.items() if k != "PYTHONUNBUFFERED"}
    result = subprocess.run([_console_script(), "formats"], capture_output=True, text=True, env=env)
    assert code == 0 and out.startswith("formats for ")
    assert (result.returncode, result.stdout) == (code, out)


def test_a_video_with_a_truth_csv_beside_it_passes_the_truth_through(tmp_path, capsys):
    video = tmp_path / "clip.avi"
    frames = [np.full((24, 32, 3), v, np.uint8) for v in (40, 40, 200)]
    _write_video(video, frames)
    truth = "frame,t_us,id,cx,cy,w,h,vx,vy,Y,Cb,Cr,label,fully_visible\n0,0,1,5,5,2,2,0,0,40,128,128,grey,1\n"
    (tmp_path / "clip.csv").write_text(truth)
    code, out, err = run_cli(capsys, "simulate", str(video), "-o", str(tmp_path / "e.npz"), "--truth", str(tmp_path / "gt.csv"), "-q")
    assert code == 0, err
    assert (tmp_path / "gt.csv").read_text() == truth
    events, _ = read_events(tmp_path / "e.npz")
    # A full-frame step from grey 40 to 200: ln(201/41) = 1.59 crosses θ = 0.2 seven times per pixel.
    assert events.size == 7 * 24 * 32 and np.all(events["p"] == 1)


def test_help_loads_no_heavy_library():
    """`evclust --help` builds every verb's parser; none may import numpy, numba, OpenCV, matplotlib,
    pydantic or the models (the start-up time is in docs/BENCHMARKS.md)."""
    import subprocess
    import sys

    code = (
        "import sys; from evclust.cli import build_parser; build_parser().format_help(); "
        "heavy = ('numpy', 'numba', 'cv2', 'matplotlib', 'pydantic', 'scipy', 'faery', 'h5py', 'pyarrow'); "
        "print(sorted({m.split('.')[0] for m in sys.modules} & set(heavy)))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"
