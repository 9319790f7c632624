"""track and tune from the command line: outputs, reproducibility and bad input."""

from __future__ import annotations

import dataclasses

import h5py
import numpy as np
import pytest

from evclust.cli import main
from evclust.choices import FRAMELESS_PERIOD_US
from evclust.events import read_events, write_events
from evclust.tracks import read_tracks

from testkit import assert_one_line_error, run_cli


@pytest.fixture(scope="module")
def crossing_events(tmp_path_factory):
    folder = tmp_path_factory.mktemp("crossing")
    assert main(["simulate", "crossing", "-o", str(folder / "e.npz"), "--truth", str(folder / "gt.csv"), "-q"]) == 0
    return folder


def test_track_writes_records_and_a_summary(crossing_events, capsys):
    out = crossing_events / "tracks.csv"
    code, stdout, err = run_cli(capsys, "track", str(crossing_events / "e.npz"), "-o", str(out), "-q")
    assert code == 0, err
    tracks, meta = read_tracks(out)
    events, _ = read_events(crossing_events / "e.npz")
    assert tracks.size > 0 and meta.model == "float" and meta.width == 160
    assert f"{events.size} events" in stdout and "Mevents/s" in stdout and "parameters from defaults" in stdout
    # Records come in filter-step order, inside the sensor.
    assert np.all(np.diff(tracks["step"].astype(np.int64)) >= 0)
    assert np.all((tracks["x"] >= 0) & (tracks["x"] < 160) & (tracks["y"] >= 0) & (tracks["y"] < 120))


@pytest.mark.parametrize(
    "text, fragments",
    [
        ("[clusterer]\nalpha_pos = 1.5\n", ("clusterer.alpha_pos", "less than 1")),
        ("[clusterer]\nsize_gian = 2\n", ("size_gian", "Extra inputs")),
        ("[clusterer]\npalette = []\n", ("clusterer.palette",)),
        ("[clusterer]\nr_max = -3\n", ("clusterer.r_max", "greater than 0")),
    ],
)
def test_track_refuses_bad_parameter_files(crossing_events, capsys, text, fragments):
    params = crossing_events / "bad.toml"
    params.write_text(text)
    out = crossing_events / "never.csv"
    code, _, err = run_cli(capsys, "track", str(crossing_events / "e.npz"), "-o", str(out), "--params", str(params), "-q")
    assert_one_line_error(code, err, "bad.toml", *fragments)
    assert not out.exists()


def test_track_runs_dvs_only_files_with_colour_off(crossing_events, capsys):
    events, meta = read_events(crossing_events / "e.npz")
    dvs = crossing_events / "dvs.h5"
    with h5py.File(dvs, "w") as f:
        for name in ("t", "x", "y", "p"):
            f.create_dataset(f"events/{name}", data=events[name])
        f.attrs["width"], f.attrs["height"], f.attrs["t_frame_us"] = meta.width, meta.height, meta.t_frame_us
    code, _, err = run_cli(capsys, "track", str(dvs), "-o", str(crossing_events / "dvs.csv"), "-q")
    assert code == 0, err
    tracks, tmeta = read_tracks(crossing_events / "dvs.csv")
    assert not tmeta.has_colour and tracks.size > 0 and np.all(tracks["class"] == -1)


def test_tune_is_reproducible_under_a_seed(tmp_path, capsys):
    outputs = []
    for name in ("a.toml", "b.toml"):
        code, _, err = run_cli(
            capsys, "tune", "crossing", "--trials", "4", "--seed", "7", "--segment", "0.5", "-o", str(tmp_path / name), "-q"
        )
        assert code == 0, err
        outputs.append((tmp_path / name).read_text())
    assert outputs[0] == outputs[1]
    # And the result is a parameter file `track` accepts.
    assert "[clusterer]" in outputs[0] and "# Tuned by: evclust tune crossing" in outputs[0]


@pytest.mark.parametrize(
    "args, fragment",
    [
        (["--trials", "0"], "--trials 0"),
        (["--segment", "1.5"], "--segment 1.5"),
        (["--params", "nosuch"], "unknown parameter set 'nosuch'"),
    ],
)
def test_tune_refuses_bad_options(tmp_path, capsys, args, fragment):
    code, _, err = run_cli(capsys, "tune", "crossing", "-o", str(tmp_path / "x.toml"), "-q", *args)
    assert_one_line_error(code, err, fragment)
    assert not (tmp_path / "x.toml").exists()


@pytest.mark.parametrize("model", ["float", "fixed"])
@pytest.mark.parametrize("fmt", ["aedat4", "raw"])
def test_camera_recordings_track_with_colour_off_as_the_same_dvs_stream_in_hdf5(crossing_events, capsys, fmt, model):
    events, meta = read_events(crossing_events / "e.npz")
    dvs_h5 = crossing_events / "dvs_ref.h5"
    if not dvs_h5.exists():
        write_events(dvs_h5, _without_colour(events), dataclasses.replace(meta, has_colour=False))
    recording = crossing_events / f"e.{fmt}"
    assert main(["simulate", "crossing", "-o", str(recording), "-q"]) == 0
    frame = str(meta.t_frame_us)
    out, ref = crossing_events / f"{fmt}_{model}.parquet", crossing_events / f"dvs_ref_{model}.parquet"
    code, stdout, err = run_cli(capsys, "track", str(recording), "-o", str(out), "--frame-us", frame, "--model", model, "-q")
    assert code == 0, err
    assert main(["track", str(dvs_h5), "-o", str(ref), "--frame-us", frame, "--model", model, "-q"]) == 0
    got, got_meta = read_tracks(out)
    want, _ = read_tracks(ref)
    assert not got_meta.has_colour and got.size > 0 and np.array_equal(got, want)
    assert np.all(got["class"] == -1) and not got["Y"].any()


def test_a_recording_without_frame_period_is_tracked_at_the_frameless_period_and_says_so(crossing_events, capsys):
    recording = crossing_events / "noframe.raw"
    assert main(["simulate", "crossing", "-o", str(recording), "-q"]) == 0
    out, given = crossing_events / "noframe.parquet", crossing_events / "given.parquet"
    code, stdout, err = run_cli(capsys, "track", str(recording), "-o", str(out), "-q")
    assert code == 0, err
    assert "no frame period in the file: the time constants are taken at 40,000 µs (25 fps" in stdout and "x25 for px/s" in stdout
    # The same as giving that period: nothing else changes.
    code, stdout, err = run_cli(capsys, "track", str(recording), "-o", str(given), "--frame-us", str(FRAMELESS_PERIOD_US), "-q")
    assert code == 0 and "no frame period" not in stdout, err
    (got, got_meta), (want, want_meta) = read_tracks(out), read_tracks(given)
    assert got_meta.t_frame_us == want_meta.t_frame_us == FRAMELESS_PERIOD_US and got.size > 0 and np.array_equal(got, want)


def test_parquet_and_csv_track_files_hold_the_same_records(crossing_events, capsys):
    csv_out, pq_out = crossing_events / "same.csv", crossing_events / "same.parquet"
    for out in (csv_out, pq_out):
        assert main(["track", str(crossing_events / "e.npz"), "-o", str(out), "-q"]) == 0
    from_csv, csv_meta = read_tracks(csv_out)
    from_pq, pq_meta = read_tracks(pq_out)
    assert csv_meta == pq_meta and from_csv.size == from_pq.size > 0
    for name in from_pq.dtype.names:  # the CSV keeps 6 significant digits; Parquet every bit
        np.testing.assert_allclose(from_csv[name], from_pq[name], rtol=1e-5, atol=1e-9, err_msg=name)
    code, stdout, err = run_cli(capsys, "score", str(pq_out), "--truth", str(crossing_events / "gt.csv"))
    assert code == 0, err


def test_streamed_tracking_does_not_depend_on_the_chunking(crossing_events):
    from evclust.clusterer import ClustererParams
    from evclust.run import track_events
    from evclust.run import track_stream
    from evclust.events import EventReader

    reader = EventReader(crossing_events / "e.npz")
    whole = track_events(reader.read(), reader.meta, ClustererParams())
    pieces = []
    streamed = track_stream(reader.chunks(size=777), reader.meta, ClustererParams(), sink=pieces.append)
    assert streamed.tracks is None and whole.tracks.size > 0
    assert np.array_equal(np.concatenate(pieces), whole.tracks) and streamed.stats == whole.stats


@pytest.mark.parametrize("name, fragment", [("t.json", "unknown track file type '.json'"), ("t.parquet", "")])
def test_track_files_refuse_garbage_and_unknown_types(tmp_path, capsys, name, fragment):
    path = tmp_path / name
    path.write_bytes(b"PAR1 not really")
    code, _, err = run_cli(capsys, "score", str(path), "--truth", str(path))
    assert_one_line_error(code, err, name, fragment or "not a readable Parquet file")


def _without_colour(events):
    dvs = events.copy()
    for name in ("Y", "Cb", "Cr"):
        dvs[name] = 0
    return dvs


def test_a_scene_tracks_on_the_fly_as_its_event_file_does(crossing_events, capsys):
    direct, via_file = crossing_events / "direct.parquet", crossing_events / "via_file.parquet"
    code, stdout, err = run_cli(capsys, "track", "crossing", "-o", str(direct), "-q")
    assert code == 0, err
    assert main(["track", str(crossing_events / "e.npz"), "-o", str(via_file), "-q"]) == 0
    got, got_meta = read_tracks(direct)
    want, want_meta = read_tracks(via_file)
    assert got.size > 0 and np.array_equal(got, want) and got_meta == want_meta


def test_render_draws_from_the_scene_as_from_its_event_file(crossing_events, capsys):
    tracks = crossing_events / "tracks.csv"
    assert main(["track", str(crossing_events / "e.npz"), "-o", str(tracks), "-q"]) == 0
    pictures = []
    for events in ("crossing", str(crossing_events / "e.npz")):
        out = crossing_events / f"r_{len(pictures)}.png"
        assert main(["render", events, str(tracks), "-o", str(out), "-q"]) == 0
        pictures.append(out.read_bytes())
    assert pictures[0] == pictures[1]


@pytest.mark.parametrize(
    "name, content, fragments",
    [
        ("bad.aedat4", b"garbage" * 40, ("bad.aedat4", "not a readable event-camera file")),
        ("bad.raw", b"% evt 3.0\n% end\n" + b"\x00" * 64, ("bad.raw", "no sensor size", "--sensor-size WxH")),
        ("bad.h5", b"not hdf5 at all", ("bad.h5", "not a readable HDF5 file")),
    ],
)
def test_track_refuses_unreadable_event_files_and_writes_nothing(tmp_path, capsys, name, content, fragments):
    bad = tmp_path / name
    bad.write_bytes(content)
    out = tmp_path / "never.parquet"
    code, _, err = run_cli(capsys, "track", str(bad), "-o", str(out), "--frame-us", "1000", "-q")
    assert_one_line_error(code, err, *fragments)
    assert not out.exists() and sorted(p.name for p in tmp_path.iterdir()) == [name]


@pytest.mark.parametrize(
    "args, fragments",
    [
        (["--frame-us", "0"], ("--frame-us 0",)),
        (["--frame-us", "-5"], ("--frame-us -5",)),
        (["-o", "tracks.json"], ("tracks.json", "unknown track file type '.json'")),
    ],
)
def test_track_refuses_bad_options_and_writes_nothing(crossing_events, tmp_path, capsys, args, fragments):
    args = [str(tmp_path / a) if a.endswith(".json") else a for a in args]
    output = [] if "-o" in args else ["-o", str(tmp_path / "never.parquet")]
    code, _, err = run_cli(capsys, "track", str(crossing_events / "e.npz"), *output, *args, "-q")
    assert_one_line_error(code, err, *fragments)
    assert list(tmp_path.iterdir()) == []


def test_simulate_refuses_an_unknown_event_format_and_writes_nothing(tmp_path, capsys):
    code, _, err = run_cli(capsys, "simulate", "crossing", "-o", str(tmp_path / "e.evt"), "-q")
    assert_one_line_error(code, err, "e.evt", "unknown event file type '.evt'")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("version", ["evt2", "evt3"])
def test_simulate_writes_the_evt_version_asked_for(tmp_path, version):
    out = tmp_path / "e.raw"
    assert main(["simulate", "crossing", "-o", str(out), "--evt", version, "-q"]) == 0
    header = out.read_bytes()[:64].decode(errors="replace")
    assert f"format {version.upper()}" in header
    events, _ = read_events(out)
    assert main(["simulate", "crossing", "-o", str(tmp_path / "e.npz"), "-q"]) == 0
    want, _ = read_events(tmp_path / "e.npz")
    for name in ("t", "x", "y", "p"):
        assert np.array_equal(events[name], want[name])
