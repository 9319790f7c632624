"""Pictures of tracks: the frame shows the boxes where the records put them, videos have one frame
per frame period, the plots are drawn from match rows, and bad input gets one line."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from evclust.cli import main
from evclust.errors import EvclustError
from evclust.events import EVENT_DTYPE, EventMeta, write_events
from evclust.metrics.match import MATCH_DTYPE
from evclust.render.plots import pick_object, plot_colour, plot_scatter, plot_velocity, presence_gaps
from evclust.render.tracks import latest_records, render_png, render_video, sort_tracks
from evclust.scenes.truth import TRUTH_DTYPE, write_truth
from evclust.tracks import TRACK_DTYPE, TrackMeta, write_tracks

W, H, PERIOD = 64, 48, 10000.0
PALETTE = ("grey", "red", "pavement")
PALETTE_YCBCR = ((128.0, 128.0, 128.0), (76.0, 85.0, 255.0), (110.0, 128.0, 128.0))


def make_events(n_frames: int = 10, per_frame: int = 40, seed: int = 0) -> np.ndarray:
    """Grey-ish events (never pure red or green) spread over n_frames frame periods."""
    rng = np.random.default_rng(seed)
    n = n_frames * per_frame
    ev = np.zeros(n, EVENT_DTYPE)
    ev["t"] = np.sort(rng.integers(1, int(n_frames * PERIOD), n))
    ev["x"], ev["y"] = rng.integers(0, W, n), rng.integers(0, H, n)
    ev["p"] = rng.choice([-1, 1], n)
    ev["Y"], ev["Cb"], ev["Cr"] = rng.integers(60, 200, n), 120 + rng.integers(0, 16, n), 120 + rng.integers(0, 16, n)
    order = np.lexsort((ev["x"], ev["y"], ev["t"]))
    return ev[order]


def record(step: int, t_us: int, x: float, y: float, rx: float, ry: float, **fields) -> np.ndarray:
    r = np.zeros(1, TRACK_DTYPE)
    r["step"], r["t_us"], r["id"], r["slot"] = step, t_us, fields.pop("id", 7), 0
    r["x"], r["y"], r["rx"], r["ry"] = x, y, rx, ry
    r["activity"] = 50.0
    r["Y"], r["Cb"], r["Cr"] = 128.0, 128.0, 128.0  # a grey swatch: neither red nor green
    r["class"] = 0
    for name, value in fields.items():
        r[name] = value
    return r


def track_meta(seek: float = 3.0) -> TrackMeta:
    return TrackMeta(
        width=W,
        height=H,
        t_frame_us=PERIOD,
        source="unit",
        palette=PALETTE,
        palette_ycbcr=PALETTE_YCBCR,
        palette_background=("pavement",),
        seek_margin=seek,
    )


def canvas_px(u: float, k: int) -> int:
    """Sensor pixel i covers canvas pixels i·k .. i·k+k-1: coordinate u lands at (u + 0.5)·k - 0.5."""
    return int(round((u + 0.5) * k - 0.5))


def colour_mask(image: np.ndarray, bgr: str) -> np.ndarray:
    b, g, r = (image[..., i].astype(int) for i in range(3))
    if bgr == "red":
        return (r > 200) & (g < 60) & (b < 60)
    return (g > 200) & (r < 60) & (b < 60)  # green


def test_png_puts_box_and_seek_region_where_the_latest_record_says(tmp_path):
    k, seek = 3, 3.0
    ev = make_events()
    ev_meta = EventMeta(width=W, height=H, source="unit", t_frame_us=PERIOD)
    # One event at a known pixel and colour, in the window.
    marker = np.zeros(1, EVENT_DTYPE)
    marker["t"], marker["x"], marker["y"], marker["p"] = 49990, 5, 40, 1
    marker["Y"], marker["Cb"], marker["Cr"] = 200, 128, 128
    ev = np.concatenate([ev[ev["t"] < 49990], marker, ev[ev["t"] > 49990]])
    tracks = np.concatenate(
        [
            record(3, 44000, 10, 10, 3, 3),  # an older step inside the window: replaced by step 4
            record(4, 48000, 30, 20, 6, 4, vx_mcm=0.0, vy_mcm=0.0),
            record(5, 60000, 50, 30, 5, 5),  # after the frame time: not drawn
        ]
    )
    path = tmp_path / "frame.png"
    assert render_png(ev, ev_meta, tracks, track_meta(seek), path, t_us=50000, scale=k) == 50000
    image = cv2.imread(str(path))
    assert image.shape[0] >= H * k and image.shape[1] == W * k
    body = image[: H * k]

    red = np.argwhere(colour_mask(body, "red"))
    (top, left), (bottom, right) = red.min(axis=0), red.max(axis=0)
    expected = (canvas_px(20 - 4, k), canvas_px(30 - 6, k), canvas_px(20 + 4, k), canvas_px(30 + 6, k))
    assert np.allclose((top, left, bottom, right), expected, atol=1)
    # The red pixels are the box outline: all four edges are complete, the inside is not red.
    assert colour_mask(body[top, left : right + 1], "red").mean() > 0.95
    assert colour_mask(body[bottom, left : right + 1], "red").mean() > 0.95
    assert colour_mask(body[top : bottom + 1, left], "red").mean() > 0.95
    assert colour_mask(body[top : bottom + 1, right], "red").mean() > 0.95
    assert not colour_mask(body[top + 2 : bottom - 1, left + 2 : right - 1], "red").any()

    green = np.argwhere(colour_mask(body, "green"))
    (gtop, gleft), (gbottom, gright) = green.min(axis=0), green.max(axis=0)
    expected = (canvas_px(20 - 4 - seek, k), canvas_px(30 - 6 - seek, k), canvas_px(20 + 4 + seek, k), canvas_px(30 + 6 + seek, k))
    assert np.allclose((gtop, gleft, gbottom, gright), expected, atol=1)
    assert colour_mask(body[gbottom, gleft : gright + 1], "green").mean() > 0.95
    # Neither the older record of step 3 nor the later one of step 5 is drawn.
    assert not colour_mask(body, "red")[: canvas_px(16, k) - 2].any()
    assert not colour_mask(body, "green")[canvas_px(27, k) + 2 :].any()
    # The event is a k×k block of its own colour (BT.601: Y=200, neutral chroma -> grey 200).
    block = body[40 * k : 41 * k, 5 * k : 6 * k].astype(int)
    assert np.all(np.abs(block - 200) <= 1)
    assert np.all(body[0, W * k - 1] == body[0, W * k - 2])  # an empty pixel: the dark background
    assert body[0, W * k - 1].max() < 40


def test_latest_records_picks_the_last_step_of_the_window():
    tracks = sort_tracks(
        np.concatenate(
            [record(2, 300, 1, 1, 1, 1), record(1, 200, 1, 1, 1, 1, id=1), record(1, 200, 1, 1, 1, 1, id=2), record(0, 100, 1, 1, 1, 1)]
        )
    )
    assert list(latest_records(tracks, 150, 250)["id"]) == [1, 2]
    assert list(latest_records(tracks, 0, 299)["step"]) == [1, 1]
    assert latest_records(tracks, 300, 400).size == 0  # the window is (t_lo, t_hi]
    assert latest_records(tracks, 0, 50).size == 0


def test_mp4_has_one_frame_per_period_from_t0_to_t1(tmp_path, capsys):
    ev = make_events(n_frames=12)
    ev_meta = EventMeta(width=W, height=H, source="unit", t_frame_us=PERIOD)
    tracks = np.concatenate([record(i, int((i + 1) * PERIOD) - 5, 10 + 3 * i, 20, 5, 4, vx_mcm=3.0, vx_int=2.5) for i in range(12)])
    events_path, tracks_path = tmp_path / "ev.npz", tmp_path / "tracks.csv"
    write_events(events_path, ev, ev_meta)
    write_tracks(tracks_path, tracks, track_meta())
    out = tmp_path / "out.mp4"
    code = main(["render", str(events_path), str(tracks_path), "-o", str(out), "--t0", "10000", "--t1", "100000", "-q"])
    assert code == 0 and "10 frames" in capsys.readouterr().out
    capture = cv2.VideoCapture(str(out))
    frames = []
    while True:
        ok, frame = capture.read()
        if not ok:
            break
        frames.append(frame)
    capture.release()
    assert len(frames) == 10
    assert frames[0].shape[1] == W * 2 and frames[0].shape[0] >= H * 2
    # Default span: frame times that cover all events, one per period.
    n = render_video(ev, ev_meta, tracks, track_meta(), tmp_path / "all.mp4", scale=1, progress=False)
    assert n == int(np.ceil(int(ev["t"][-1]) / PERIOD)) - int(np.ceil(int(ev["t"][0]) / PERIOD)) + 1


def make_matches() -> tuple[np.ndarray, np.ndarray]:
    """Object 1: 30 evaluations over frames 0-9 and 15-19 (it leaves after frame 9); object 2: 5."""
    frames = np.r_[np.repeat(np.arange(10), 2), np.repeat(np.arange(15, 20), 2)]
    m = np.zeros(frames.size + 5, MATCH_DTYPE)
    m["frame"][: frames.size] = frames
    m["frame"][frames.size :] = np.arange(5)
    m["gt_id"][: frames.size], m["gt_id"][frames.size :] = 1, 2
    m["step"] = np.arange(m.size)
    m["t_us"] = (m["frame"] * PERIOD + 100 * (m["step"] % 2) + 10).astype(np.uint64)
    m["track_id"] = np.where(m["frame"] < 15, 7, 9)
    m["gt_x"], m["gt_y"] = 10 + 2.0 * m["frame"], 20.0
    m["x"], m["y"] = m["gt_x"] + 0.5, m["gt_y"] - 0.5
    m["gt_vx"], m["gt_vy"] = 2.0, 0.0
    m["vx_mcm"], m["vy_mcm"] = 1.8, 0.2
    m["vx_int"], m["vy_int"] = 2.1, -0.1
    m["gt_Y"], m["gt_Cb"], m["gt_Cr"] = 76.0, 85.0, 255.0
    m["Y"], m["Cb"], m["Cr"] = 90.0, 95.0, 220.0
    m["class_palette"] = 1
    m["gt_label"] = "red"
    m["fully_visible"] = True
    truth = np.zeros(15 + 5, TRUTH_DTYPE)
    truth["frame"][:15] = np.r_[np.arange(10), np.arange(15, 20)]
    truth["frame"][15:] = np.arange(5)
    truth["id"][:15], truth["id"][15:] = 1, 2
    return m[np.lexsort((m["step"], m["t_us"]))], truth


def test_plot_writes_each_kind_from_match_rows(tmp_path):
    m, truth = make_matches()
    gt_id, rows = pick_object(m)
    assert gt_id == 1 and rows.size == 30
    assert presence_gaps(truth, 1) == [(9, 15)] and presence_gaps(truth, 2) == []
    images = {}
    for kind in ("velocity", "colour"):
        for axis in ("index", "time"):
            path = tmp_path / f"{kind}_{axis}.png"
            fn = plot_velocity if kind == "velocity" else plot_colour
            extra = {} if kind == "velocity" else {"palette": PALETTE}
            assert fn(m, path, truth=truth, axis=axis, t_frame_us=PERIOD, **extra) == 1
            images[path.name] = cv2.imread(str(path))
    # The scatter needs events inside the cluster's box at its records, and those records.
    ev = make_events(n_frames=20, per_frame=200)
    ev_meta = EventMeta(width=W, height=H, source="unit", t_frame_us=PERIOD)
    tracks = np.concatenate([record(int(r["step"]), int(r["t_us"]), r["x"], r["y"], 8, 8, id=int(r["track_id"])) for r in m])
    path = tmp_path / "scatter.png"
    assert plot_scatter(m, ev, ev_meta, tracks, track_meta(), path, gt_id=1) == 1
    images[path.name] = cv2.imread(str(path))
    for name, image in images.items():
        assert image is not None and image.shape[0] > 300 and image.shape[1] > 600, name
        assert np.ptp(image) > 100, name  # not a blank canvas
    # The exit/re-entry line is drawn in pure red.
    velocity = images["velocity_index.png"].astype(int)
    assert ((velocity[..., 2] > 230) & (velocity[..., 1] < 30) & (velocity[..., 0] < 30)).sum() > 100
    with pytest.raises(EvclustError, match="object 5 has no match"):
        plot_velocity(m, tmp_path / "none.png", gt_id=5)
    with pytest.raises(EvclustError, match="no track record was matched"):
        plot_colour(m[:0], tmp_path / "none.png")
    assert not (tmp_path / "none.png").exists()


def test_plot_cli_matches_tracks_to_truth(tmp_path, capsys):
    rows = [
        dict(frame=f, t_us=f * PERIOD, id=3, cx=10 + 2 * f, cy=20, w=8, h=8, vx=2, vy=0, Y=76, Cb=85, Cr=255, label="red", fully_visible=1)
        for f in range(8)
    ]
    truth_path, tracks_path = tmp_path / "gt.csv", tmp_path / "tracks.csv"
    write_truth(truth_path, rows)
    tracks = np.concatenate(
        [record(i, int(i * PERIOD / 2 + 10), 10 + i + 0.3, 20.2, 4, 4, vx_mcm=1.9, vx_int=2.0, **{"class": 1}) for i in range(16)]
    )
    write_tracks(tracks_path, tracks, track_meta())
    out = tmp_path / "v.png"
    assert main(["plot", str(tracks_path), "--truth", str(truth_path), "-o", str(out)]) == 0
    assert "velocity of object 3 (16 matched evaluations)" in capsys.readouterr().out
    assert cv2.imread(str(out)) is not None


def one_line_error(capsys, argv, *fragments) -> None:
    code = main(argv)
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and lines[0].startswith("evclust: error: "), err
    assert "Traceback" not in err
    for fragment in fragments:
        assert fragment in lines[0], lines[0]


def test_bad_input_gets_one_line_and_no_output(tmp_path, capsys):
    ev_meta = EventMeta(width=W, height=H, source="unit", t_frame_us=PERIOD)
    events_path, tracks_path, truth_path = tmp_path / "ev.npz", tmp_path / "tracks.csv", tmp_path / "gt.csv"
    write_events(events_path, make_events(), ev_meta)
    write_tracks(tracks_path, record(0, 100, 10, 10, 3, 3), track_meta())
    write_truth(truth_path, [])
    out_png, out_mp4 = tmp_path / "o.png", tmp_path / "o.mp4"
    one_line_error(capsys, ["render", str(tmp_path / "nope.npz"), str(tracks_path), "-o", str(out_png)], "nope.npz", "no such event file")
    one_line_error(capsys, ["render", str(events_path), str(tmp_path / "nope.csv"), "-o", str(out_mp4)], "nope.csv", "no such track file")
    one_line_error(capsys, ["render", str(events_path), str(tracks_path), "-o", str(tmp_path / "o.gif")], "o.gif", ".mp4", ".png")
    one_line_error(capsys, ["render", str(events_path), str(tracks_path), "-o", str(out_mp4), "--t0", "5000", "--t1", "10"], "before")
    one_line_error(capsys, ["render", str(events_path), str(tracks_path), "-o", str(out_png), "--window", "0"], "--window")
    one_line_error(capsys, ["render", str(events_path), str(tracks_path), "-o", str(out_png), "--scale", "0"], "--scale")
    small = tmp_path / "small.npz"
    write_events(small, make_events()[:0], EventMeta(width=32, height=32, source="unit", t_frame_us=PERIOD))
    one_line_error(capsys, ["render", str(small), str(tracks_path), "-o", str(out_png)], "64x48", "32x32")
    one_line_error(capsys, ["render", str(tracks_path), str(tracks_path), "-o", str(out_png)], "tracks.csv", "column")
    one_line_error(capsys, ["plot", str(tracks_path), "--truth", str(truth_path), "-o", str(tmp_path / "p.txt")], "p.txt", ".png")
    one_line_error(capsys, ["plot", str(tracks_path), "--truth", str(tmp_path / "nope.csv"), "-o", str(out_png)], "nope.csv")
    one_line_error(capsys, ["plot", str(tracks_path), "--truth", str(truth_path), "-o", str(out_png), "--kind", "scatter"], "--events")
    one_line_error(capsys, ["plot", str(tracks_path), "--truth", str(truth_path), "-o", str(out_png)], "no track record")
    one_line_error(capsys, ["plot", str(events_path), "--truth", str(truth_path), "-o", str(out_png)], "ev.npz")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ev.npz", "gt.csv", "small.npz", "tracks.csv"]
