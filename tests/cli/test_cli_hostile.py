"""Hostile and careless input to the command line. The promise, checked for every case: exit code
2, one line on stderr, no traceback, no partial or replaced output, and every input unchanged.

Classes here: an output that is an input (by path, by a second path to it, by a hard link or a
symlink), two outputs that are one file, an output that is a folder, special files as outputs
(written in place, never replaced; a full device is an error), and SIGTERM mid-run.
"""

from __future__ import annotations

import hashlib
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from evclust.cli import main

from cosim import full
from testkit import GOOD_SCENE

SCENE = GOOD_SCENE  # the cases below edit it by text


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """A scene, its events and truth, tracks, a score JSON and a parameter file, made once."""
    root = tmp_path_factory.mktemp("hostile")
    (root / "scene.toml").write_text(SCENE)
    (root / "params.toml").write_text("[clusterer]\nn_clusters = 4\n")
    assert main(["simulate", str(root / "scene.toml"), "-o", str(root / "ev.npz"), "--truth", str(root / "gt.csv"), "-q"]) == 0
    assert main(["track", str(root / "ev.npz"), "-o", str(root / "tracks.csv"), "-q"]) == 0
    return root


def snapshot(folder: Path) -> dict:
    """Every file under the folder and its content hash (links by what they point at)."""
    return {str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(folder.rglob("*")) if p.is_file()}


def work_folder(files: Path, tmp_path: Path) -> Path:
    """A copy of the inputs for one case, so a case that destroys one harms no other."""
    for name in ("scene.toml", "params.toml", "ev.npz", "gt.csv", "tracks.csv"):
        (tmp_path / name).write_bytes((files / name).read_bytes())
    (tmp_path / "sub").mkdir()
    os.link(tmp_path / "ev.npz", tmp_path / "ev_hardlink.npz")
    os.symlink(tmp_path / "tracks.csv", tmp_path / "tracks_symlink.csv")
    os.symlink(tmp_path / "gt.csv", tmp_path / "gt_symlink.csv")
    return tmp_path


def assert_refused(capsys, folder: Path, argv: list[str], *fragments: str) -> None:
    before = snapshot(folder)
    code = main(argv)
    out, err = capsys.readouterr()
    lines = err.strip().splitlines()
    assert code == 2, (code, out, err)
    assert len(lines) == 1 and lines[0].startswith("evclust: error: "), err
    assert "Traceback" not in err
    for fragment in fragments:
        assert fragment in lines[0], lines[0]
    assert snapshot(folder) == before, "an input changed or an output was left"


# (argv with {d} for the folder, fragments the error line must hold). Every output here names a
# file the same run reads or writes, directly or through a second path.
OVERWRITES = {
    "track -o = its events": (["track", "{d}/ev.npz", "-o", "{d}/ev.npz"], ["-o", "EVENTS"]),
    "track -o = its events through ./": (["track", "{d}/ev.npz", "-o", "{d}/./ev.npz"], ["is an input"]),
    "track -o = its events through sub/..": (["track", "{d}/ev.npz", "-o", "{d}/sub/../ev.npz"], ["is an input"]),
    "track -o = a hard link to its events": (["track", "{d}/ev.npz", "-o", "{d}/ev_hardlink.npz"], ["is an input"]),
    "track -o = its parameter file": (["track", "{d}/ev.npz", "-o", "{d}/params.toml", "--params", "{d}/params.toml"], ["--params"]),
    "simulate -o = its scene": (["simulate", "{d}/scene.toml", "-o", "{d}/scene.toml"], ["SCENE"]),
    "simulate --truth = its scene": (["simulate", "{d}/scene.toml", "-o", "{d}/new.npz", "--truth", "{d}/scene.toml"], ["--truth"]),
    "simulate --truth = -o": (["simulate", "{d}/scene.toml", "-o", "{d}/new.csv", "--truth", "{d}/new.csv"], ["another output"]),
    "simulate --truth = -o, an existing file": (
        ["simulate", "{d}/scene.toml", "-o", "{d}/gt.csv", "--truth", "{d}/gt.csv"],
        ["another output"],
    ),
    "score --json = its tracks": (["score", "{d}/tracks.csv", "--truth", "{d}/gt.csv", "--json", "{d}/tracks.csv"], ["--json"]),
    "score --json = its truth": (["score", "{d}/tracks.csv", "--truth", "{d}/gt.csv", "--json", "{d}/gt.csv"], ["--json"]),
    "score --json = a symlink to its truth": (
        ["score", "{d}/tracks.csv", "--truth", "{d}/gt.csv", "--json", "{d}/gt_symlink.csv"],
        ["--json"],
    ),
    "score --json = its tracks through a symlink given as tracks": (
        ["score", "{d}/tracks_symlink.csv", "--truth", "{d}/gt.csv", "--json", "{d}/tracks.csv"],
        ["--json"],
    ),
    "show -o = its events": (["show", "{d}/ev.npz", "-o", "{d}/ev.npz"], ["EVENTS"]),
    "render -o = its events": (["render", "{d}/ev.npz", "{d}/tracks.csv", "-o", "{d}/ev.npz"], ["EVENTS"]),
    "render -o = its tracks": (["render", "{d}/ev.npz", "{d}/tracks.csv", "-o", "{d}/tracks.csv"], ["TRACKS"]),
    "plot -o = its tracks": (["plot", "{d}/tracks.csv", "--truth", "{d}/gt.csv", "-o", "{d}/tracks.csv"], ["TRACKS"]),
    "plot -o = its truth": (["plot", "{d}/tracks.csv", "--truth", "{d}/gt.csv", "-o", "{d}/gt.csv"], ["--truth"]),
    "formats --registers = its parameters": (["formats", "--params", "{d}/params.toml", "--registers", "{d}/params.toml"], ["--params"]),
    "formats --c-header = --verilog": (["formats", "--verilog", "{d}/x.vh", "--c-header", "{d}/x.vh"], ["another output"]),
    "formats --verilog = --write-for's file": (
        ["formats", "--write-for", "{d}/params.toml", "--verilog", "{d}/params.toml"],
        ["--write-for"],
    ),
    "tune -o = its parameters": (
        ["tune", "{d}/scene.toml", "--params", "{d}/params.toml", "-o", "{d}/params.toml", "--trials", "1", "-q"],
        ["--params"],
    ),
    "tune -o = its scene": (["tune", "{d}/scene.toml", "-o", "{d}/scene.toml", "--trials", "1", "-q"], ["SCENE"]),
}


@pytest.mark.parametrize("case", sorted(OVERWRITES))
def test_an_output_that_is_an_input_or_another_output_is_refused_before_anything_runs(case, files, tmp_path, capsys):
    folder = work_folder(files, tmp_path)
    argv, fragments = OVERWRITES[case]
    assert_refused(capsys, folder, [a.replace("{d}", str(folder)) for a in argv], *fragments)


@pytest.mark.parametrize("verb", ["track", "show", "simulate"])
def test_a_folder_as_the_output_is_one_line(verb, files, tmp_path, capsys):
    folder = work_folder(files, tmp_path)
    source = {"track": "ev.npz", "show": "ev.npz", "simulate": "scene.toml"}[verb]
    extra = ["-q"] if verb != "show" else []
    assert_refused(capsys, folder, [verb, str(folder / source), "-o", str(folder / "sub"), *extra], "sub")


@pytest.mark.parametrize("argv", [
    ["formats", "--registers", "/dev/null", "--c-header", "/dev/null"],
    ["simulate", "{d}/scene.toml", "-o", "{d}/new.npz", "--truth", "/dev/null", "-q"],
    ["score", "{d}/tracks.csv", "--truth", "{d}/gt.csv", "--json", "/dev/null"],
], ids=["formats, two outputs", "simulate --truth", "score --json"])  # fmt: skip
def test_dev_null_as_an_output_is_written_in_place_and_not_replaced(argv, files, tmp_path, capsys):
    folder = work_folder(files, tmp_path)
    before = os.stat("/dev/null")
    assert main([a.replace("{d}", str(folder)) for a in argv]) == 0
    after = os.stat("/dev/null")
    assert (after.st_ino, after.st_rdev) == (before.st_ino, before.st_rdev)
    assert not any(p.name.startswith(".") for p in Path("/dev").iterdir() if p.name.startswith(".null"))


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="no /dev/full on this system")
@pytest.mark.parametrize("argv", [
    ["formats", "--registers", "/dev/full"],
    ["simulate", "{d}/scene.toml", "-o", "{d}/new.npz", "--truth", "/dev/full", "-q"],
    ["score", "{d}/tracks.csv", "--truth", "{d}/gt.csv", "--json", "/dev/full"],
], ids=["formats", "simulate --truth", "score --json"])  # fmt: skip
def test_a_full_device_is_reported_as_one_line(argv, files, tmp_path, capsys):
    folder = work_folder(files, tmp_path)
    assert_refused(capsys, folder, [a.replace("{d}", str(folder)) for a in argv], "/dev/full")


def test_simulate_writes_both_outputs_or_neither(files, tmp_path, capsys):
    """--truth that cannot be written (its folder is a file): the event file is not left either."""
    folder = work_folder(files, tmp_path)
    assert_refused(
        capsys,
        folder,
        ["simulate", str(folder / "scene.toml"), "-o", str(folder / "new.npz"), "--truth", str(folder / "tracks.csv" / "gt.csv"), "-q"],
    )


@pytest.mark.parametrize("argv", [["--window", "1e300"], ["--t1", "1e15"], ["--window", "1e19", "--t1", "1e19"]], ids=" ".join)
def test_a_picture_at_times_past_every_event_is_drawn_not_an_overflow(files, tmp_path, argv, capsys):
    """Times beyond the uint64 event clock are looked up clamped (they raised OverflowError): the
    picture is written, the size of any other."""
    import cv2

    out, reference = tmp_path / "out.png", tmp_path / "reference.png"
    assert main(["render", str(files / "ev.npz"), str(files / "tracks.csv"), "-o", str(reference), "-q"]) == 0
    assert main(["render", str(files / "ev.npz"), str(files / "tracks.csv"), "-o", str(out), "-q", *argv]) == 0
    assert capsys.readouterr().err == ""
    assert cv2.imread(str(out)).shape == cv2.imread(str(reference)).shape


@pytest.mark.parametrize("length", [244, 255])
def test_an_output_name_as_long_as_the_file_system_allows_is_written(files, tmp_path, length):
    """The temporary file beside it is named within the same limit (it was `.<name>.<random>.csv`,
    past 255 characters, so a legal name was refused)."""
    out = tmp_path / ("t" * (length - 4) + ".csv")
    assert main(["track", str(files / "ev.npz"), "-o", str(out), "-q"]) == 0
    assert [p.name for p in tmp_path.iterdir()] == [out.name] and out.stat().st_size > 0


def _damaged_videos(folder: Path) -> dict[str, bool]:
    """Video files OpenCV or FFmpeg complain about on their own stderr: name -> whether evclust
    still reads frames from it."""
    import cv2
    import numpy as np

    writer = cv2.VideoWriter(str(folder / "whole.avi"), cv2.VideoWriter_fourcc(*"XVID"), 10, (64, 48))
    rng = np.random.default_rng(1)
    for _ in range(30):
        writer.write(rng.integers(0, 255, (48, 64, 3), dtype=np.uint8))
    writer.release()
    whole = (folder / "whole.avi").read_bytes()
    (folder / "cut.avi").write_bytes(whole[: len(whole) * 2 // 3])  # damaged blocks near the end
    (folder / "header.avi").write_bytes(b"RIFF\0\0\0\0AVI LIST" + bytes(range(256)) * 4)  # an AVI that is not one
    (folder / "empty.mp4").write_bytes(b"")  # no moov atom
    return {"cut.avi": True, "header.avi": False, "empty.mp4": False}


def test_a_damaged_video_gives_one_line_or_none_not_the_decoders_own(tmp_path):
    """OpenCV's and FFmpeg's messages (damaged blocks, a missing moov atom, an odd AVI list) were
    printed beside evclust's one line; now only evclust speaks, in a fresh process as a user runs it."""
    env = {k: v for k, v in os.environ.items() if not k.startswith("OPENCV_")}
    for name, readable in _damaged_videos(tmp_path).items():
        run = subprocess.run([sys.executable, "-c", "import sys; from evclust.cli import main; sys.exit(main())", "track", name, "-o", "out.csv",
                              "--per-frame", "-q"], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300)  # fmt: skip
        lines = run.stderr.strip().splitlines()
        if readable:
            assert run.returncode == 0 and lines == [], (name, run.stderr)
        else:
            assert run.returncode == 2 and len(lines) == 1 and lines[0].startswith(f"evclust: error: {name}: "), (name, run.stderr)


def _ignore_sigint():
    signal.signal(signal.SIGINT, signal.SIG_IGN)


# SIGINT as Ctrl-C sends it, and as a job started in the background by a non-interactive shell
# receives it: that job starts with SIGINT ignored, which Python keeps unless told otherwise.
@pytest.mark.parametrize(
    ("sig", "exit_code", "line", "preexec"),
    [
        (signal.SIGTERM, 128 + signal.SIGTERM, "evclust: terminated", None),
        (signal.SIGINT, 130, "evclust: interrupted", None),
        (signal.SIGINT, 130, "evclust: interrupted", _ignore_sigint),
    ],
    ids=["sigterm", "sigint", "sigint-in-background"],
)
def test_a_signal_mid_run_stops_it_at_once_and_leaves_no_temporary_or_partial_file(files, tmp_path, sig, exit_code, line, preexec):
    """A long simulation stopped by SIGTERM or SIGINT: its exit code, one line, within seconds,
    nothing left in the folder."""
    folder = work_folder(files, tmp_path)
    long_scene = (
        SCENE.replace("frames = 6", "frames = 4000")
        .replace("frames = 5,", "frames = 3999,")
        .replace("width = 40", "width = 640")
        .replace("height = 30", "height = 480")
    )
    (folder / "long.toml").write_text(long_scene)
    before = snapshot(folder)
    proc = subprocess.Popen([sys.executable, "-c", "import sys; from evclust.cli import main; sys.exit(main())", "simulate", str(folder / "long.toml"), "-o", str(folder / "long.npz"), "-q"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, preexec_fn=preexec)  # fmt: skip
    deadline = time.monotonic() + 120
    while not any(p.name.startswith(".long.npz") for p in folder.iterdir()):  # the writer has started
        assert proc.poll() is None and time.monotonic() < deadline, proc.communicate()
        time.sleep(0.05)
    proc.send_signal(sig)
    sent = time.monotonic()
    out, err = proc.communicate(timeout=60)
    assert proc.returncode == exit_code, err
    assert time.monotonic() - sent < 10  # the whole 4,000 frames take minutes
    assert err.strip().splitlines() == [line]
    assert snapshot(folder) == before


# ------------------------------------------------------------------------------------------
# Malformed inputs: each case writes its own bad file (name: content as bytes, or a callable
# that writes it) and runs argv; the promise above must hold.


def _npz(path: Path, **arrays) -> None:
    import numpy as np

    with open(path, "wb") as f:
        np.savez(f, **arrays)


def _good_arrays(files: Path) -> dict:
    import numpy as np

    with np.load(files / "ev.npz", allow_pickle=False) as z:
        return {k: z[k] for k in z.files}


def _h5(path: Path, layout: dict) -> None:
    import h5py

    with h5py.File(path, "w") as f:
        for name, value in layout.items():
            if isinstance(value, dict):
                group = f.create_group(name)
                for k, v in value.items():
                    group.attrs[k] = v
            else:
                f[name] = value


def _scene_with(**replace) -> bytes:
    text = SCENE
    for old, new in replace.items():
        text = text.replace(old.replace("_", " "), new)
    return text.encode()


MALFORMED = {
    "zero-byte npz": ({"bad.npz": b""}, ["track", "{d}/bad.npz", "-o", "{d}/out.csv", "-q"]),
    "npz of garbage": ({"bad.npz": b"PK\x03\x04 not a zip at all"}, ["track", "{d}/bad.npz", "-o", "{d}/out.csv", "-q"]),
    "zero-byte h5": ({"bad.h5": b""}, ["track", "{d}/bad.h5", "-o", "{d}/out.csv", "-q"]),
    "h5 without events": ({"bad.h5": lambda p, f: _h5(p, {"other": [1, 2, 3]})}, ["track", "{d}/bad.h5", "-o", "{d}/out.csv", "-q"]),
    "h5 with events as a group": (
        {"bad.h5": lambda p, f: _h5(p, {"events": {"width": 40}})},
        ["track", "{d}/bad.h5", "-o", "{d}/out.csv", "-q"],
    ),
    "zero-byte scene": ({"bad.toml": b""}, ["simulate", "{d}/bad.toml", "-o", "{d}/out.npz", "-q"]),
    "scene not UTF-8": ({"bad.toml": b'width = 40\nlabel = "\xff\xfe"\n'}, ["simulate", "{d}/bad.toml", "-o", "{d}/out.npz", "-q"]),
    "params not UTF-8": (
        {"bad.toml": b"[clusterer]\nn_clusters = \xff\n"},
        ["track", "{d}/ev.npz", "-o", "{d}/out.csv", "--params", "{d}/bad.toml", "-q"],
    ),
    "params of the wrong type": (
        {"bad.toml": b'[clusterer]\nn_clusters = "many"\n'},
        ["track", "{d}/ev.npz", "-o", "{d}/out.csv", "--params", "{d}/bad.toml", "-q"],
    ),
    "params not TOML": ({"bad.toml": b"[clusterer\n"}, ["track", "{d}/ev.npz", "-o", "{d}/out.csv", "--params", "{d}/bad.toml", "-q"]),
    "scene velocity NaN": (
        {"bad.toml": _scene_with(**{"velocity = [2.0, 0.0]": "velocity = [nan, 0.0]"})},
        ["simulate", "{d}/bad.toml", "-o", "{d}/out.npz", "-q"],
    ),
    "scene velocity inf": (
        {"bad.toml": _scene_with(**{"velocity = [2.0, 0.0]": "velocity = [inf, 0.0]"})},
        ["simulate", "{d}/bad.toml", "-o", "{d}/out.npz", "-q"],
    ),
    "scene start NaN": (
        {"bad.toml": _scene_with(**{"start = [10, 15]": "start = [nan, 15]"})},
        ["simulate", "{d}/bad.toml", "-o", "{d}/out.npz", "-q"],
    ),
    "scene size inf": (
        {"bad.toml": _scene_with(**{"size = [8, 8]": "size = [inf, 8]"})},
        ["simulate", "{d}/bad.toml", "-o", "{d}/out.npz", "-q"],
    ),
    "scene size negative": (
        {"bad.toml": _scene_with(**{"size = [8, 8]": "size = [-8, 8]"})},
        ["simulate", "{d}/bad.toml", "-o", "{d}/out.npz", "-q"],
    ),
    "scene colour out of range": (
        {"bad.toml": _scene_with(**{"colour = [210, 40, 40]": "colour = [999, 40, 40]"})},
        ["simulate", "{d}/bad.toml", "-o", "{d}/out.npz", "-q"],
    ),
    "scene width zero": ({"bad.toml": _scene_with(**{"width = 40": "width = 0"})}, ["simulate", "{d}/bad.toml", "-o", "{d}/out.npz", "-q"]),
    "scene fps NaN": ({"bad.toml": _scene_with(**{"fps = 30": "fps = nan"})}, ["simulate", "{d}/bad.toml", "-o", "{d}/out.npz", "-q"]),
    "--fps NaN": ({}, ["simulate", "{d}/scene.toml", "-o", "{d}/out.npz", "--fps", "nan", "-q"]),
    "--fps inf": ({}, ["simulate", "{d}/scene.toml", "-o", "{d}/out.npz", "--fps", "inf", "-q"]),
    "--fps 1e-300": ({}, ["simulate", "{d}/scene.toml", "-o", "{d}/out.npz", "--fps", "1e-300", "-q"]),
    "--seed negative": ({}, ["simulate", "{d}/scene.toml", "-o", "{d}/out.npz", "--seed", "-1", "-q"]),
    "--frame-us NaN": ({}, ["track", "{d}/ev.npz", "-o", "{d}/out.csv", "--frame-us", "nan", "-q"]),
    "--frame-us negative": ({}, ["track", "{d}/ev.npz", "-o", "{d}/out.csv", "--frame-us", "-33333", "-q"]),
    "show to an unknown picture format": ({}, ["show", "{d}/ev.npz", "-o", "{d}/out.xyz"]),
    "show with --span NaN": ({}, ["show", "{d}/ev.npz", "-o", "{d}/out.png", "--span", "nan"]),
    "render with --t1 inf": ({}, ["render", "{d}/ev.npz", "{d}/tracks.csv", "-o", "{d}/out.png", "--t1", "inf", "-q"]),
    "render with --window inf": ({}, ["render", "{d}/ev.npz", "{d}/tracks.csv", "-o", "{d}/out.png", "--window", "inf", "-q"]),
    "render with --scale 0": ({}, ["render", "{d}/ev.npz", "{d}/tracks.csv", "-o", "{d}/out.png", "--scale", "0", "-q"]),
    "render to an unknown format": ({}, ["render", "{d}/ev.npz", "{d}/tracks.csv", "-o", "{d}/out.gif", "-q"]),
    "render with --window NaN": ({}, ["render", "{d}/ev.npz", "{d}/tracks.csv", "-o", "{d}/out.png", "--window", "nan", "-q"]),
    "render with --scale 1e9": ({}, ["render", "{d}/ev.npz", "{d}/tracks.csv", "-o", "{d}/out.png", "--scale", "1e9", "-q"]),
    "score a truth of garbage": ({"bad.csv": b"\x00\x01\x02garbage"}, ["score", "{d}/tracks.csv", "--truth", "{d}/bad.csv"]),
    "score an empty tracks file": ({"bad.csv": b""}, ["score", "{d}/bad.csv", "--truth", "{d}/gt.csv"]),
    "formats --params with tau_us = inf": ({"bad.toml": b"[clusterer]\ntau_us = inf\n"}, ["formats", "--params", "{d}/bad.toml"]),
    "formats --params with NaN": ({"bad.toml": b"[clusterer]\nalpha_pos = nan\n"}, ["formats", "--params", "{d}/bad.toml"]),
    "formats --width NaN-like": ({}, ["formats", "--width", "0"]),
    "fixed model with tau_us = inf": (
        {"bad.toml": b"[clusterer]\ntau_us = inf\n"},
        ["track", "{d}/ev.npz", "-o", "{d}/out.csv", "--model", "fixed", "--params", "{d}/bad.toml", "-q"],
    ),
}


def _npz_meta(meta) -> callable:
    """An event file whose metadata is replaced (a JSON text, or a raw object for the wrong type)."""
    import json

    def write(path: Path, files: Path) -> None:
        arrays = _good_arrays(files)
        good = json.loads(str(arrays["meta"]))
        arrays["meta"] = meta if not isinstance(meta, dict) else __import__("numpy").array(json.dumps(good | meta))
        _npz(path, **arrays)

    return write


def _h5_from_good(attrs: dict | None = None, reshape: str | None = None, group: str | None = None) -> callable:
    """An HDF5 event file from the good events, with attributes replaced, one field reshaped or
    one field a group instead of a dataset."""

    def write(path: Path, files: Path) -> None:
        import h5py

        from evclust.events import read_events, write_events

        events, meta = read_events(files / "ev.npz")
        write_events(path, events, meta)
        with h5py.File(path, "a") as f:
            for key, value in (attrs or {}).items():
                f.attrs[key] = value
            if reshape:
                data = f["events"][reshape][...]
                del f["events"][reshape]
                f["events"][reshape] = data.reshape(1, -1) if data.size else data.reshape(1, 0)
            if group:
                del f["events"][group]
                f["events"].create_group(group).create_dataset("values", data=[1, 2, 3])

    return write


TRACK = ["track", "{d}/bad.npz", "-o", "{d}/out.csv", "-q"]
TRACK_H5 = ["track", "{d}/bad.h5", "-o", "{d}/out.csv", "-q"]
MALFORMED.update(
    {
        "npz meta width a string": ({"bad.npz": _npz_meta({"width": "wide"})}, TRACK),
        "npz meta width negative": ({"bad.npz": _npz_meta({"width": -40})}, TRACK),
        "npz meta width zero": ({"bad.npz": _npz_meta({"width": 0})}, TRACK),
        "npz meta sensor 60000 x 60000": ({"bad.npz": _npz_meta({"width": 60000, "height": 60000})}, TRACK),
        "npz meta t_frame_us negative": ({"bad.npz": _npz_meta({"t_frame_us": -33333.0})}, TRACK),
        "npz meta t_frame_us a list": ({"bad.npz": _npz_meta({"t_frame_us": [1, 2]})}, TRACK),
        "npz meta not JSON": ({"bad.npz": _npz_meta(__import__("numpy").array("{not json"))}, TRACK),
        "npz meta a number array": ({"bad.npz": _npz_meta(__import__("numpy").arange(3))}, TRACK),
        "npz meta JSON list": ({"bad.npz": _npz_meta(__import__("numpy").array("[1, 2]"))}, TRACK),
        "h5 width a string": ({"bad.h5": _h5_from_good({"width": "wide"})}, TRACK_H5),
        "h5 width an array": ({"bad.h5": _h5_from_good({"width": [40, 40]})}, TRACK_H5),
        "h5 height negative": ({"bad.h5": _h5_from_good({"height": -30})}, TRACK_H5),
        "h5 sensor 60000 x 60000": ({"bad.h5": _h5_from_good({"width": 60000, "height": 60000})}, TRACK_H5),
        "h5 field t two-dimensional": ({"bad.h5": _h5_from_good(reshape="t")}, TRACK_H5),
        "h5 field x two-dimensional": ({"bad.h5": _h5_from_good(reshape="x")}, TRACK_H5),
        "h5 field t a group": ({"bad.h5": _h5_from_good(group="t")}, TRACK_H5),
        "h5 field y a group": ({"bad.h5": _h5_from_good(group="y")}, TRACK_H5),
    }
)


# Unbounded work: refused at once, before anything is allocated or drawn.
SIM = ["simulate", "{d}/bad.toml", "-o", "{d}/out.npz", "-q"]
MALFORMED.update(
    {
        "scene 40000 x 25000": ({"bad.toml": _scene_with(**{"width = 40": "width = 40000", "height = 30": "height = 25000"})}, SIM),
        "scene wider than 65535": ({"bad.toml": _scene_with(**{"width = 40": "width = 70000"})}, SIM),
        "scene of 10^12 frames": ({"bad.toml": _scene_with(**{"frames = 6": "frames = 1000000000000"})}, SIM),
        "object of 10^8 px": ({"bad.toml": _scene_with(**{"size = [8, 8]": "size = [10000, 10000]"})}, SIM),
        # The truth file holds a label in 32 characters: a longer one is the scene's fault, not score's.
        "object label of 33 characters": ({"bad.toml": SCENE.replace('label = "red"', f'label = "{"r" * 33}"').encode()}, SIM),
        "sensor threshold 1e-300": ({"bad.toml": (SCENE + "[sensor]\nthreshold_on = 1e-300\n").encode()}, SIM),
        "sensor threshold 0": ({"bad.toml": (SCENE + "[sensor]\nthreshold_off = 0\n").encode()}, SIM),
    }
)


def _video_with_truth(truth: bytes) -> callable:
    """A three-frame video and a truth CSV beside it (the one `simulate --truth` passes through)."""

    def write(path: Path, files: Path) -> None:
        import cv2
        import numpy as np

        writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), 30, (32, 24))
        for v in (40, 40, 200):
            writer.write(np.full((24, 32, 3), v, np.uint8))
        writer.release()
        path.with_suffix(".csv").write_bytes(truth)

    return write


TRUTH_HEADER = b"frame,t_us,id,cx,cy,w,h,vx,vy,Y,Cb,Cr,label,fully_visible\n"
VIDEO = ["simulate", "{d}/clip.avi", "-o", "{d}/out.npz", "--truth", "{d}/out.csv", "-q"]
MALFORMED.update(
    {
        "video truth CSV of garbage": ({"clip.avi": _video_with_truth(b"\x00\x01garbage\n")}, VIDEO),
        "video truth CSV without a column": (
            {"clip.avi": _video_with_truth(TRUTH_HEADER.replace(b",label", b"") + b"0,0,1,5,5,2,2,0,0,40,128,128,1\n")},
            VIDEO,
        ),
        "video truth CSV with NaN": ({"clip.avi": _video_with_truth(TRUTH_HEADER + b"0,0,1,nan,5,2,2,0,0,40,128,128,grey,1\n")}, VIDEO),
        "video truth CSV not UTF-8": ({"clip.avi": _video_with_truth(TRUTH_HEADER + b"0,0,1,5,5,2,2,0,0,40,128,128,gr\xffy,1\n")}, VIDEO),
    }
)


def test_an_interrupted_vector_case_leaves_the_old_case_whole_and_no_half_new_one(tmp_path, monkeypatch):
    """Ctrl-C between a case's files (here: as its manifest is written): the folder holds the
    old case, every file of it, and no temporary folder is left."""
    import json

    from evclust.vectors import write

    write.write_case("palette_tie", tmp_path / "palette_tie")
    before = snapshot(tmp_path)
    assert len(before) == 5  # events, expected, trace, objects, manifest

    def interrupt(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(write.json, "dumps", interrupt)
    with pytest.raises(KeyboardInterrupt):
        write.write_case("palette_tie", tmp_path / "palette_tie")
    monkeypatch.setattr(write.json, "dumps", json.dumps)
    assert snapshot(tmp_path) == before
    assert [p.name for p in tmp_path.iterdir()] == ["palette_tie"]
    (tmp_path / "palette_tie").rename(tmp_path / "gone")
    with pytest.raises(KeyboardInterrupt):
        monkeypatch.setattr(write.json, "dumps", interrupt)
        write.write_case("palette_tie", tmp_path / "palette_tie")
    assert [p.name for p in tmp_path.iterdir()] == ["gone"]  # a new case: absent, not half written


def _image_folder(width: int, height: int) -> callable:
    def write(path: Path, files: Path) -> None:
        import cv2
        import numpy as np

        path.mkdir()
        for k, v in enumerate((40, 200)):
            assert cv2.imwrite(str(path / f"f{k}.png"), np.full((height, width, 3), v, np.uint8))

    return write


MALFORMED.update(
    {
        "images wider than 65535 px": (
            {"wide": _image_folder(70000, 1)},
            ["simulate", "{d}/wide", "--fps", "30", "-o", "{d}/out.npz", "-q"],
        ),
        "images over the pixel limit": (
            {"big": _image_folder(8000, 4300)},
            ["simulate", "{d}/big", "--fps", "30", "-o", "{d}/out.npz", "-q"],
        ),
    }
)


# Options out of range or of the wrong kind, and missing inputs: one line before anything runs.
T = ["track", "{d}/ev.npz", "-o", "{d}/out.csv", "-q"]
MALFORMED.update(
    {
        "no verb": ({}, []),
        "unknown verb": ({}, ["explode"]),
        "track without -o": ({}, ["track", "{d}/ev.npz"]),
        "track of a missing file": ({}, ["track", "{d}/none.npz", "-o", "{d}/out.csv", "-q"]),
        "track of a folder": ({}, ["track", "{d}/sub", "-o", "{d}/out.csv", "-q"]),
        "track --model unknown": ({}, [*T, "--model", "quantum"]),
        "track --params missing": ({}, [*T, "--params", "{d}/none.toml"]),
        "track --params unknown preset": ({}, [*T, "--params", "no_such_preset"]),
        "track --ranges with the float model": ({}, [*T, "--ranges"]),
        "track --frame-us inf": ({}, [*T, "--frame-us", "inf"]),
        "track --frame-us 0": ({}, [*T, "--frame-us", "0"]),
        "track to an unknown format": ({}, ["track", "{d}/ev.npz", "-o", "{d}/out.xls", "-q"]),
        "simulate --frames 1": ({}, ["simulate", "{d}/scene.toml", "-o", "{d}/out.npz", "--frames", "1", "-q"]),
        "simulate --frames -5": ({}, ["simulate", "{d}/scene.toml", "-o", "{d}/out.npz", "--frames", "-5", "-q"]),
        "simulate --frames not a number": ({}, ["simulate", "{d}/scene.toml", "-o", "{d}/out.npz", "--frames", "many", "-q"]),
        "simulate --fps 0": ({}, ["simulate", "{d}/scene.toml", "-o", "{d}/out.npz", "--fps", "0", "-q"]),
        "simulate --fps 1e9": ({}, ["simulate", "{d}/scene.toml", "-o", "{d}/out.npz", "--fps", "1e9", "-q"]),
        "simulate an unknown built-in scene": ({}, ["simulate", "no_such_scene", "-o", "{d}/out.npz", "-q"]),
        "simulate to an unknown format": ({}, ["simulate", "{d}/scene.toml", "-o", "{d}/out.xyz", "-q"]),
        "simulate --evt unknown": ({}, ["simulate", "{d}/scene.toml", "-o", "{d}/out.raw", "--evt", "evt9", "-q"]),
        "simulate --truth for a video without one": (
            {"clip.avi": _video_with_truth(b"")},
            ["simulate", "{d}/clip.avi", "-o", "{d}/out.npz", "--truth", "{d}/t.csv", "-q"],
        ),
        "score without --truth": ({}, ["score", "{d}/tracks.csv"]),
        "score --gate NaN": ({}, ["score", "{d}/tracks.csv", "--truth", "{d}/gt.csv", "--gate", "nan"]),
        "score --gate inf": ({}, ["score", "{d}/tracks.csv", "--truth", "{d}/gt.csv", "--gate", "inf"]),
        "score tracks as truth": ({}, ["score", "{d}/tracks.csv", "--truth", "{d}/tracks.csv"]),
        "score events as tracks": ({}, ["score", "{d}/ev.npz", "--truth", "{d}/gt.csv"]),
        "score a missing truth": ({}, ["score", "{d}/tracks.csv", "--truth", "{d}/none.csv"]),
        "plot --kind unknown": ({}, ["plot", "{d}/tracks.csv", "--truth", "{d}/gt.csv", "-o", "{d}/p.png", "--kind", "pie"]),
        "plot to an unknown format": ({}, ["plot", "{d}/tracks.csv", "--truth", "{d}/gt.csv", "-o", "{d}/p.bmp"]),
        "plot --gate NaN": ({}, ["plot", "{d}/tracks.csv", "--truth", "{d}/gt.csv", "-o", "{d}/p.png", "--gate", "nan"]),
        "plot --gt-id absent": ({}, ["plot", "{d}/tracks.csv", "--truth", "{d}/gt.csv", "-o", "{d}/p.png", "--gt-id", "999"]),
        "show of a missing file": ({}, ["show", "{d}/none.npz", "-o", "{d}/out.png"]),
        "show --t0 NaN": ({}, ["show", "{d}/ev.npz", "-o", "{d}/out.png", "--t0", "nan"]),
        "show --span 0": ({}, ["show", "{d}/ev.npz", "-o", "{d}/out.png", "--span", "0"]),
        "show --span -1": ({}, ["show", "{d}/ev.npz", "-o", "{d}/out.png", "--span", "-1"]),
        "render --arrow-frames -1": ({}, ["render", "{d}/ev.npz", "{d}/tracks.csv", "-o", "{d}/out.png", "--arrow-frames", "-1", "-q"]),
        "render --arrow-frames NaN": ({}, ["render", "{d}/ev.npz", "{d}/tracks.csv", "-o", "{d}/out.png", "--arrow-frames", "nan", "-q"]),
        # 3e10 frames, 224 GiB of frame times alone: refused before anything is allocated.
        "render a video to --t1 1e15": ({}, ["render", "{d}/ev.npz", "{d}/tracks.csv", "-o", "{d}/out.mp4", "--t1", "1e15", "-q"]),
        "render --t1 negative": ({}, ["render", "{d}/ev.npz", "{d}/tracks.csv", "-o", "{d}/out.png", "--t1", "-5", "-q"]),
        "render a missing tracks file": ({}, ["render", "{d}/ev.npz", "{d}/none.csv", "-o", "{d}/out.png", "-q"]),
        "formats --width 0": ({}, ["formats", "--width", "0"]),
        "formats --height -3": ({}, ["formats", "--height", "-3"]),
        "formats --width 70000": ({}, ["formats", "--width", "70000"]),
        "formats --t-frame-us NaN": ({}, ["formats", "--t-frame-us", "nan"]),
        "formats --t-frame-us -1": ({}, ["formats", "--t-frame-us", "-1"]),
        "formats --params missing": ({}, ["formats", "--params", "{d}/none.toml"]),
        "formats --write-for missing": ({}, ["formats", "--write-for", "{d}/none.toml"]),
        "tune --trials 0": ({}, ["tune", "{d}/scene.toml", "-o", "{d}/best.toml", "--trials", "0", "-q"]),
        "tune --segment 0": ({}, ["tune", "{d}/scene.toml", "-o", "{d}/best.toml", "--segment", "0", "-q"]),
        "tune --segment NaN": ({}, ["tune", "{d}/scene.toml", "-o", "{d}/best.toml", "--segment", "nan", "-q"]),
        "vectors --max-events 0": ({}, ["vectors", "-o", "{d}/vec", "--events", "{d}/ev.npz", "--max-events", "0"]),
        "vectors --frame-us inf": ({}, ["vectors", "-o", "{d}/vec", "--events", "{d}/ev.npz", "--frame-us", "inf"]),
        "vectors --events missing": ({}, ["vectors", "-o", "{d}/vec", "--events", "{d}/none.npz"]),
        "vectors --replay without --events": ({}, ["vectors", "-o", "{d}/vec", "--replay", "icarus"]),
        "scenes --generate -1": ({}, ["scenes", "--generate", "-1", "-o", "{d}/sc"]),
        "scenes --split unknown": ({}, ["scenes", "--split", "nowhere", "-o", "{d}/sc"]),
        "reference of a missing video": ({}, ["reference", "{d}/none.avi", "-o", "{d}/ref.csv", "-q"]),
        "reference --min-area -1": (
            {"clip.avi": _video_with_truth(b"")},
            ["reference", "{d}/clip.avi", "-o", "{d}/ref.csv", "--min-area", "-1", "-q"],
        ),
    }
)


@pytest.mark.parametrize("case", sorted(MALFORMED))
def test_malformed_input_is_one_line_and_leaves_nothing(case, files, tmp_path, capsys):
    folder = work_folder(files, tmp_path)
    made, argv = MALFORMED[case]
    for name, content in made.items():
        if callable(content):
            content(folder / name, files)
        else:
            (folder / name).write_bytes(content)
    assert_refused(capsys, folder, [a.replace("{d}", str(folder)) for a in argv])


@pytest.mark.parametrize("model", ["float", "fixed", "rtl"])
def test_event_times_past_2_to_the_32_reach_the_records_whole(model, tmp_path):
    """Events from t = 2^40 µs: the fixed datapath counts 32 bits (2^40 wraps to 0), so its
    records are those of the unshifted stream, with the whole 64-bit time, not its low 32 bits.
    The stream is the first events of `traffic` (seed 1), as in tests/run/test_track_rtl.py, so the
    RTL runs on the build that test makes (one Verilator build for both)."""
    from evclust.events import write_events
    from evclust.scenes import load_scene
    from evclust.simulator import simulate_scene
    from evclust.tracks import read_tracks

    sim = simulate_scene(load_scene("traffic"), seed=1)
    events, meta = sim.events[:40000], sim.meta
    write_events(tmp_path / "early.npz", events, meta)
    shifted = events.copy()
    shifted["t"] += 1 << 40
    write_events(tmp_path / "late.npz", shifted, meta)
    kinds = (("--clusters", ("x", "y", "vx_mcm", "vy_mcm", "Y")), ("--every-step", ("x", "y", "vx", "vy", "Y")))
    if model == "rtl" and not full():  # make test: the cluster records (two co-simulations, not four); make test-full both
        kinds = kinds[:1]
    for kind, fields in kinds:
        for name in ("early", "late"):
            assert main(["track", str(tmp_path / f"{name}.npz"), "-o", str(tmp_path / f"{name}.csv"), "--model", model, kind, "-q"]) == 0
        early, _ = read_tracks(tmp_path / "early.csv")
        late, _ = read_tracks(tmp_path / "late.csv")
        assert early.size > 0 and late.size == early.size, kind
        assert (late["t_us"].astype("int64") == early["t_us"].astype("int64") + (1 << 40)).all()
        for name in fields:
            assert (late[name] == early[name]).all(), (kind, name)
