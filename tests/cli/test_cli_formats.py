"""track, render and show on the text and camera formats: --sensor-size, --polarity, one-line refusals."""

from __future__ import annotations

import pytest

from evclust.cli import main
from evclust.events import EventMeta, read_events, write_events
from evclust.tracks import read_tracks

from testkit import assert_one_line_error, run_cli


@pytest.fixture(scope="module")
def crossing(tmp_path_factory):
    """The crossing scene's events, in ECD text and in DAT (both without colour)."""
    folder = tmp_path_factory.mktemp("formats")
    assert main(["simulate", "crossing", "-o", str(folder / "e.npz"), "-q"]) == 0
    ev, meta = read_events(folder / "e.npz")
    dvs = EventMeta(width=meta.width, height=meta.height, source="crossing")
    for name in ("events.txt", "e.dat"):
        write_events(folder / name, ev, dvs)
    return folder, meta


def test_track_and_render_ecd_text_with_sensor_size(crossing, capsys):
    folder, meta = crossing
    size = f"{meta.width}x{meta.height}"
    tracks = folder / "tracks.csv"
    code, out, err = run_cli(
        capsys, "track", str(folder / "events.txt"), "-o", str(tracks), "--sensor-size", size, "--frame-us", "33333", "-q"
    )
    assert code == 0, err
    records, track_meta = read_tracks(tracks)
    assert len(records) > 0 and (track_meta.width, track_meta.height) == (meta.width, meta.height)
    code, out, err = run_cli(capsys, "render", str(folder / "events.txt"), str(tracks), "-o", str(folder / "f.png"), "--sensor-size", size)
    assert code == 0, err
    code, out, err = run_cli(capsys, "show", str(folder / "e.dat"), "-o", str(folder / "s.png"))
    assert code == 0 and "events drawn" in out, err


@pytest.mark.parametrize(
    "args, fragments",
    [
        ([], ("events.txt", "no sensor size", "--sensor-size WxH")),
        (["--sensor-size", "40x30"], ("events.txt", "line ", "is outside the 40x30 sensor")),
        (["--sensor-size", "160"], ("--sensor-size", "'160' is not a sensor size WxH")),
        (["--sensor-size", "160x120", "--polarity", "pm1"], ("events.txt", "line 1", "'pm1' convention")),
    ],
)
def test_track_refuses_text_events_in_one_line_and_writes_nothing(crossing, tmp_path, capsys, args, fragments):
    folder, _ = crossing
    code, _, err = run_cli(capsys, "track", str(folder / "events.txt"), "-o", str(tmp_path / "t.csv"), "--frame-us", "33333", *args, "-q")
    assert_one_line_error(code, err, *fragments)
    assert list(tmp_path.iterdir()) == []


def test_options_for_event_files_are_refused_on_a_scene(tmp_path, capsys):
    code, _, err = run_cli(capsys, "track", "crossing", "-o", str(tmp_path / "t.csv"), "--sensor-size", "10x10", "-q")
    assert_one_line_error(code, err, "crossing", "--sensor-size and --polarity are for event files")
