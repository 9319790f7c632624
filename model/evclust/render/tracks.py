"""Pictures of tracks over events, like the paper's Fig. 5: one frame (PNG) or a video (MP4).

Each frame shows the events of a sliding time window, drawn in the colour they carry on a dark
background, and over them the records of the latest filter step inside the window (of a file
thinned to one record per frame, each id's latest record in the window). A cluster record shows
its box (red), seek region (green), centre (orange), MCM velocity (blue) and interval velocity
(yellow); an object record its box (cyan; dashed while it coasts), centre and velocity (yellow).
Both carry a swatch of the estimated colour and a label with the id and class.

Frames are drawn with OpenCV on a canvas `scale` times the sensor size. A sensor pixel `i` covers
`[i - 0.5, i + 0.5]` (docs/DESIGN.md); it becomes the canvas pixels `i·K .. i·K + K - 1`, so a
sensor coordinate `u` maps to the canvas coordinate `(u + 0.5)·K - 0.5` (see `to_canvas`).
"""

from __future__ import annotations

import math
from pathlib import Path

import cv2
import numpy as np
from tqdm import tqdm

from evclust import limits
from evclust.colour import ycbcr_to_rgb
from evclust.errors import EvclustError, atomic_output
from evclust.events.format import EventMeta
from evclust.tracks.record import RECORD_DTYPES, ObjectFlags, TrackMeta

DEFAULT_FRAME_US = 33333.0
PNG_SUFFIXES = (".png",)
VIDEO_SUFFIXES = (".mp4",)
# Event and record times are uint64 µs; a time from the command line (a window of 1e300 µs, a
# picture at 1e15 µs) is looked up clamped to [0, 2^63], past every real one.
LAST_TIME = 1 << 63


def _time_key(t_us: float) -> np.uint64:
    """`floor(t_us)` as an event time, clamped to what the uint64 times can hold."""
    return np.uint64(min(max(0, math.floor(t_us)), LAST_TIME))


# BGR, as OpenCV draws.
BACKGROUND = (24, 24, 24)
BOX = (0, 0, 255)  # red: the cluster, centre ± (rx, ry)
SEEK = (0, 255, 0)  # green: the seek region, the box grown by the seek margin
CENTRE = (0, 150, 255)  # orange
V_MCM = (255, 110, 0)  # blue: mean-centre-motion velocity
V_INT = (0, 230, 255)  # yellow: regular-interval velocity (Fig. 7 uses yellow for it too)
OBJECT = (255, 220, 0)  # cyan: an object's box
TEXT = (235, 235, 235)
FOOTER_PX = 16  # a strip below the image for the time and the legend; image rows are untouched


def to_canvas(u, scale: int):
    """Sensor pixel-index coordinate(s) -> nearest canvas pixel index (ints)."""
    return np.floor((np.asarray(u, dtype=np.float64) + 0.5) * scale).astype(np.int64)  # round((u+0.5)K-0.5), halves up


def frame_period(ev_meta: EventMeta, track_meta: TrackMeta | None = None) -> float:
    """The frame period in µs: the event file's, else the track file's, else 30 fps."""
    for value in (ev_meta.t_frame_us, track_meta.t_frame_us if track_meta is not None else None):
        if value:
            return float(value)
    return DEFAULT_FRAME_US


def sort_tracks(tracks: np.ndarray) -> np.ndarray:
    """Cluster or object records ordered by filter step (stable), as the frame lookup needs."""
    tracks = np.asarray(tracks)
    if tracks.dtype not in RECORD_DTYPES.values():
        raise EvclustError(f"records of dtype {tracks.dtype} are not cluster or object records")
    if tracks.size > 1 and np.any(tracks["step"][1:] < tracks["step"][:-1]):
        tracks = tracks[np.argsort(tracks["step"], kind="stable")]
    return tracks


def latest_records(tracks: np.ndarray, t_lo_us: float, t_hi_us: float, per_frame: bool = False) -> np.ndarray:
    """The records of the latest filter step with t_lo < t_us <= t_hi (empty if none); of a file
    thinned per frame (`per_frame`), each id's latest record with t_lo < t_us <= t_hi.

    `tracks` must be ordered by step (see `sort_tracks`); step times never decrease with the step.
    """
    if tracks.size == 0:
        return tracks
    t = tracks["t_us"]
    i = int(np.searchsorted(t, _time_key(t_hi_us), side="right")) - 1
    if i < 0 or float(t[i]) <= t_lo_us:
        return tracks[:0]
    if per_frame:
        lo = int(np.searchsorted(t, _time_key(t_lo_us + 1), side="left"))
        window = tracks[lo : i + 1]
        _, last_from_end = np.unique(window["id"][::-1], return_index=True)
        return window[np.sort(window.size - 1 - last_from_end)]
    step = tracks["step"][i]
    lo, hi = np.searchsorted(tracks["step"], [step, step + 1])
    return tracks[lo:hi]


def busiest_time(ev: np.ndarray, window_us: float) -> float:
    """The end of the window-long bin (from the first event on) that holds the most events; 0 if none."""
    if ev.size == 0:
        return 0.0
    t0, t1 = int(ev["t"][0]), int(ev["t"][-1])
    bins = max(1, math.ceil((t1 - t0 + 1) / window_us))
    edges = t0 + window_us * np.arange(bins + 1)
    counts = np.diff(np.searchsorted(ev["t"], np.minimum(edges, float(LAST_TIME)).astype(np.uint64), side="left"))
    counts[-1] += int(ev.size - counts.sum())  # events at or beyond the last edge
    return float(edges[int(np.argmax(counts)) + 1])


def _events_image(win: np.ndarray, meta: EventMeta, colour: bool) -> np.ndarray:
    """(H, W, 3) uint8 BGR: the window's events on the dark background; the latest event wins."""
    image = np.empty((meta.height, meta.width, 3), np.uint8)
    image[:] = BACKGROUND
    if win.size == 0:
        return image
    if colour:
        ycc = np.stack([win["Y"], win["Cb"], win["Cr"]], axis=1)
        rgb = np.clip(np.rint(ycbcr_to_rgb(ycc)), 0, 255).astype(np.uint8)
        image[win["y"], win["x"]] = rgb[:, ::-1]
    else:  # a DVS-only stream: ON light, OFF mid-blue
        on = win["p"] > 0
        image[win["y"][on], win["x"][on]] = (230, 230, 230)
        image[win["y"][~on], win["x"][~on]] = (200, 120, 60)
    return image


def _put_text(canvas: np.ndarray, text: str, org: tuple[int, int], size: float, colour=TEXT, outline: bool = True) -> None:
    if outline:  # a dark outline keeps the text readable over events
        cv2.putText(canvas, text, org, cv2.FONT_HERSHEY_SIMPLEX, size, (0, 0, 0), 3, cv2.LINE_AA)
    cv2.putText(canvas, text, org, cv2.FONT_HERSHEY_SIMPLEX, size, colour, 1, cv2.LINE_AA)


def _arrow(canvas: np.ndarray, start: np.ndarray, v: tuple[float, float], gain: float, scale: int, colour) -> None:
    vx, vy = v
    if not (math.isfinite(vx) and math.isfinite(vy)) or math.hypot(vx, vy) * gain * scale < 1.0:
        return
    shift = 4  # sub-pixel precision of OpenCV's drawing: 1/16 px
    f = 1 << shift
    end = (start[0] + vx * gain * scale, start[1] + vy * gain * scale)
    p0 = (int(round(start[0] * f)), int(round(start[1] * f)))
    p1 = (int(round(end[0] * f)), int(round(end[1] * f)))
    cv2.arrowedLine(canvas, p0, p1, colour, 1 + scale // 3, cv2.LINE_AA, shift, tipLength=0.25)


def _dashed_rectangle(canvas: np.ndarray, p0: tuple[int, int], p1: tuple[int, int], colour, dash: int) -> None:
    (x0, y0), (x1, y1) = p0, p1
    for a, b, fixed, horizontal in ((x0, x1, y0, True), (x0, x1, y1, True), (y0, y1, x0, False), (y0, y1, x1, False)):
        for u in range(a, b + 1, 2 * dash):
            v = min(u + dash - 1, b)
            cv2.line(canvas, (u, fixed) if horizontal else (fixed, u), (v, fixed) if horizontal else (fixed, v), colour, 1, cv2.LINE_8)


def draw_tracks(canvas: np.ndarray, records: np.ndarray, meta: TrackMeta, scale: int, arrow_frames: float = 5.0) -> None:
    """Draw cluster or object records on a canvas (BGR, `scale` times the sensor), in place.

    Velocities are in px/frame; an arrow shows the displacement over `arrow_frames` frames.
    """
    font = 0.3 + 0.05 * scale
    h, w = canvas.shape[:2]
    objects = meta.kind == "objects"
    for r in records:
        x, y, rx, ry = float(r["x"]), float(r["y"]), float(r["rx"]), float(r["ry"])
        s = 0.0 if objects else float(meta.seek_margin) + float(meta.seek_scale) * max(rx, ry)
        if s > 0:
            x0, y0 = to_canvas([x - rx - s, y - ry - s], scale)
            x1, y1 = to_canvas([x + rx + s, y + ry + s], scale)
            cv2.rectangle(canvas, (int(x0), int(y0)), (int(x1), int(y1)), SEEK, 1, cv2.LINE_8)
        bx0, by0 = (int(v) for v in to_canvas([x - rx, y - ry], scale))
        bx1, by1 = (int(v) for v in to_canvas([x + rx, y + ry], scale))
        centre = (x + 0.5) * scale - 0.5, (y + 0.5) * scale - 0.5
        centre = np.array(centre)
        if objects:
            if int(r["flags"]) & ObjectFlags.COASTING:
                _dashed_rectangle(canvas, (bx0, by0), (bx1, by1), OBJECT, max(2, 2 * scale))
            else:
                cv2.rectangle(canvas, (bx0, by0), (bx1, by1), OBJECT, 1 + scale // 2, cv2.LINE_8)
            _arrow(canvas, centre, (float(r["vx"]), float(r["vy"])), arrow_frames, scale, V_INT)
        else:
            cv2.rectangle(canvas, (bx0, by0), (bx1, by1), BOX, 1, cv2.LINE_8)
            _arrow(canvas, centre, (float(r["vx_int"]), float(r["vy_int"])), arrow_frames, scale, V_INT)
            _arrow(canvas, centre, (float(r["vx_mcm"]), float(r["vy_mcm"])), arrow_frames, scale, V_MCM)
        cv2.circle(canvas, (int(round(centre[0])), int(round(centre[1]))), max(2, scale), CENTRE, -1, cv2.LINE_AA)
        label = f"{int(r['id'])}"
        cls = int(r["class"])
        if 0 <= cls < len(meta.palette):
            label += f" {meta.palette[cls]}"
        elif cls >= 0:
            label += f" #{cls}"
        side = max(6, 4 * scale)
        s_px = int(round(s * scale))  # the label goes above the seek region, or below it at the top
        tx = min(max(bx0 - s_px, 0), max(0, w - 1))
        ty = by0 - s_px - 3 if by0 - s_px - 3 > side + 2 else by1 + s_px + side + 3
        if meta.has_colour:  # swatch of the estimated colour, then the label beside it
            rgb = np.clip(ycbcr_to_rgb([float(r["Y"]), float(r["Cb"]), float(r["Cr"])]), 0, 255)
            bgr = tuple(int(round(c)) for c in rgb[::-1])
            cv2.rectangle(canvas, (tx, ty - side), (tx + side, ty), bgr, -1, cv2.LINE_8)
            cv2.rectangle(canvas, (tx, ty - side), (tx + side, ty), TEXT, 1, cv2.LINE_8)
            tx += side + 3
        _put_text(canvas, label, (tx, ty), font)


class FrameDrawer:
    """Draws frames at chosen times; slicing events and tracks by binary search on sorted time."""

    def __init__(
        self,
        ev: np.ndarray,
        ev_meta: EventMeta,
        tracks: np.ndarray,
        track_meta: TrackMeta,
        window_us: float | None = None,
        scale: int = 2,
        arrow_frames: float = 5.0,
    ):
        if scale < 1 or scale > 16:
            raise EvclustError(f"scale {scale}: must be an integer from 1 to 16")
        if (ev_meta.width, ev_meta.height) != (track_meta.width, track_meta.height):
            raise EvclustError(
                f"the tracks are for a {track_meta.width}x{track_meta.height} sensor, "
                f"the events come from a {ev_meta.width}x{ev_meta.height} one"
            )
        self.period = frame_period(ev_meta, track_meta)
        self.window = float(window_us) if window_us is not None else self.period
        if not self.window > 0:
            raise EvclustError(f"window {window_us} us: must be positive")
        self.ev, self.ev_meta = ev, ev_meta
        self.tracks, self.meta = sort_tracks(tracks), track_meta
        self.scale, self.arrow_frames = int(scale), float(arrow_frames)
        self.colour = bool(ev_meta.has_colour)

    @property
    def size(self) -> tuple[int, int]:
        """(width, height) of a frame in pixels."""
        return self.ev_meta.width * self.scale, self.ev_meta.height * self.scale + FOOTER_PX

    def window_slice(self, t_us: float) -> slice:
        """Events with t_us - window < t <= t_us."""
        lo, hi = np.searchsorted(self.ev["t"], np.array([_time_key(t_us - self.window + 1), _time_key(t_us + 1)]), side="left")
        return slice(int(lo), int(hi))

    def draw(self, t_us: float, events: slice | None = None) -> np.ndarray:
        """One BGR frame (uint8) at time t_us."""
        win = self.ev[events if events is not None else self.window_slice(t_us)]
        image = _events_image(win, self.ev_meta, self.colour)
        k = self.scale
        width, height = self.size
        canvas = np.zeros((height, width, 3), np.uint8)
        canvas[: height - FOOTER_PX] = cv2.resize(image, None, fx=k, fy=k, interpolation=cv2.INTER_NEAREST) if k > 1 else image
        records = latest_records(self.tracks, t_us - self.window, t_us, self.meta.per_frame)
        body = canvas[: height - FOOTER_PX]  # a view: draw_tracks writes into the canvas
        draw_tracks(body, records, self.meta, k, self.arrow_frames)
        if self.meta.kind == "objects":
            pieces = [
                (f"t={t_us / 1e6:.3f}s {win.size} ev {records.size} obj", TEXT),
                ("object (dashed: coasting)", OBJECT),
                (f"V (x{self.arrow_frames:g} frames)", V_INT),
            ]
        else:
            pieces = [
                (f"t={t_us / 1e6:.3f}s {win.size} ev {records.size} tr", TEXT),
                ("box", BOX),
                ("seek", SEEK),
                ("Vmcm", V_MCM),
                (f"Vint (x{self.arrow_frames:g} frames)", V_INT),
            ]
        x = 3
        for text, colour in pieces:  # as many as fit, in their own colours
            (tw, _), _ = cv2.getTextSize(text, cv2.FONT_HERSHEY_SIMPLEX, 0.35, 1)
            if x + tw > width:
                break
            _put_text(canvas, text, (x, height - 4), 0.35, colour, outline=False)
            x += tw + 6
        return canvas


def _check_suffix(path: Path, allowed: tuple[str, ...], what: str) -> None:
    if path.suffix.lower() not in allowed:
        raise EvclustError(f"{path}: a {what} must end in {' or '.join(allowed)}, not '{path.suffix or '(none)'}'")


def render_png(
    ev: np.ndarray,
    ev_meta: EventMeta,
    tracks: np.ndarray,
    track_meta: TrackMeta,
    path: str | Path,
    t_us: float | None = None,
    window_us: float | None = None,
    scale: int = 2,
    arrow_frames: float = 5.0,
) -> float:
    """Write one frame at t_us (default: the end of the busiest window) as a PNG; return its time."""
    path = Path(path)
    _check_suffix(path, PNG_SUFFIXES, "picture")
    drawer = FrameDrawer(ev, ev_meta, tracks, track_meta, window_us, scale, arrow_frames)
    if t_us is None:
        if ev.size:
            t_us = busiest_time(ev, drawer.window)
        else:
            t_us = float(drawer.tracks["t_us"][-1]) if drawer.tracks.size else 0.0
    frame = drawer.draw(float(t_us))
    ok, data = cv2.imencode(".png", frame)
    if not ok:
        raise EvclustError(f"{path}: OpenCV could not encode the picture")
    with atomic_output(path) as tmp:
        tmp.write_bytes(data.tobytes())
    return float(t_us)


def frame_times(ev: np.ndarray, tracks: np.ndarray, period: float, t0_us: float | None, t1_us: float | None) -> np.ndarray:
    """Video frame times: every frame period from t0 to t1, both included.

    Defaults: the first and last frame times (multiples of the period) that cover the events (or
    the tracks when there are no events)."""
    times = ev["t"] if ev.size else (tracks["t_us"] if tracks.size else np.zeros(1, np.uint64))
    first, last = float(times.min()), float(times.max())
    t0 = float(t0_us) if t0_us is not None else math.ceil(first / period) * period
    t1 = float(t1_us) if t1_us is not None else max(t0, math.ceil(last / period) * period)
    if t1 < t0:
        raise EvclustError(f"t1={t1:g} us is before t0={t0:g} us")
    n = int(math.floor((t1 - t0) / period + 1e-9)) + 1
    limits.check("FRAMES", n, f"t0={t0:g} us to t1={t1:g} us every {period:g} us: video frames")
    return t0 + period * np.arange(n)


def render_video(
    ev: np.ndarray,
    ev_meta: EventMeta,
    tracks: np.ndarray,
    track_meta: TrackMeta,
    path: str | Path,
    t0_us: float | None = None,
    t1_us: float | None = None,
    window_us: float | None = None,
    scale: int = 2,
    arrow_frames: float = 5.0,
    progress: bool | None = None,
) -> int:
    """Write an MP4 with one frame per frame period from t0 to t1; return the number of frames.

    progress: None shows a bar on a terminal only (tqdm's disable=None), False never, True always.
    """
    path = Path(path)
    _check_suffix(path, VIDEO_SUFFIXES, "video")
    drawer = FrameDrawer(ev, ev_meta, tracks, track_meta, window_us, scale, arrow_frames)
    times = frame_times(ev, drawer.tracks, drawer.period, t0_us, t1_us)
    width, height = drawer.size
    width_even, height_even = width + width % 2, height + height % 2  # MPEG-4 wants even sizes
    # All window bounds in one binary search over the sorted times.
    lo_t = np.maximum(0, np.floor(times - drawer.window) + 1).astype(np.uint64)
    hi_t = np.maximum(0, np.floor(times) + 1).astype(np.uint64)
    lo = np.searchsorted(ev["t"], lo_t, side="left")
    hi = np.searchsorted(ev["t"], hi_t, side="left")
    fps = 1e6 / drawer.period
    disable = None if progress is None else not progress
    with atomic_output(path) as tmp:
        writer = cv2.VideoWriter(str(tmp), cv2.VideoWriter_fourcc(*"mp4v"), fps, (width_even, height_even))
        if not writer.isOpened():
            raise EvclustError(f"{path}: OpenCV cannot write an MP4 video ('mp4v' codec) here")
        try:
            padded = np.zeros((height_even, width_even, 3), np.uint8)
            for i, t in enumerate(tqdm(times, desc="render", unit="frame", disable=disable)):
                padded[:height, :width] = drawer.draw(float(t), slice(int(lo[i]), int(hi[i])))
                writer.write(padded)
        finally:
            writer.release()
    return int(times.size)
