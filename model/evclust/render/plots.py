"""Plots of one tracked object against its ground truth, after the paper's figures:

- `plot_velocity` (Fig. 7): vy on top, vx below; ground truth blue, MCM green, interval yellow
  (cluster records) or the object's velocity green (object records);
- `plot_colour` (Fig. 10): Y, Cb, Cr; estimate green, ground truth blue;
- `plot_scatter` (Fig. 9): the colours of the events inside the matched cluster's box, as a Cb–Cr
  and a Y–Cb scatter with the palette entries marked, and the cluster's content at one record.

They take the rows of `evclust.metrics.match` (one per matched track record / object pair). A red
vertical line marks where the object left the field of view and came back: a gap in the frames
for which the ground truth has a row for it.
"""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from evclust.choices import PLOT_AXES, PLOT_KINDS
from evclust.colour import ycbcr_to_rgb
from evclust.errors import EvclustError, atomic_output
from evclust.events.format import EventMeta
from evclust.metrics.tracking import velocity_methods
from evclust.tracks.record import TrackMeta

PLOT_SUFFIXES = (".png", ".svg", ".pdf")
KINDS, AXES = PLOT_KINDS, PLOT_AXES
GT_COLOUR = "tab:blue"
MCM_COLOUR = "tab:green"
INT_COLOUR = "#e6b800"  # yellow, dark enough to read on white
EST_COLOUR = "tab:green"
EXIT_COLOUR = "red"
_MATCH_FIELDS = ("step", "t_us", "frame", "gt_id", "track_id", "gt_vx", "gt_vy", "Y", "Cb", "Cr", "gt_Y", "gt_Cb", "gt_Cr")
# Each velocity method's line: (label, colour, width).
METHOD_LINES = {"mcm": ("MCM", MCM_COLOUR, 1.0), "interval": ("interval", INT_COLOUR, 1.4), "object": ("object", EST_COLOUR, 1.4)}


def check_plot_path(path: str | Path) -> Path:
    path = Path(path)
    if path.suffix.lower() not in PLOT_SUFFIXES:
        raise EvclustError(f"{path}: a plot must end in {', '.join(PLOT_SUFFIXES)}, not '{path.suffix or '(none)'}'")
    return path


def pick_object(matches: np.ndarray, gt_id: int | None = None) -> tuple[int, np.ndarray]:
    """(gt_id, its match rows in time order). Default: the object with the most matches."""
    names = matches.dtype.names or ()
    missing = [name for name in _MATCH_FIELDS if name not in names]
    if missing or not velocity_methods(matches):
        raise EvclustError(f"matches: missing field(s) {', '.join(missing) or 'of a velocity'}")
    if matches.size == 0:
        raise EvclustError("no track record was matched to a ground-truth object")
    ids, counts = np.unique(matches["gt_id"], return_counts=True)
    if gt_id is None:
        gt_id = int(ids[int(np.argmax(counts))])  # ties: the lowest id
    elif gt_id not in ids.tolist():
        shown = ", ".join(f"{int(i)} ({int(c)})" for i, c in zip(ids[:12], counts[:12]))
        raise EvclustError(f"object {gt_id} has no match; matched objects (matches): {shown}")
    rows = matches[matches["gt_id"] == gt_id]
    rows = rows[np.lexsort((rows["track_id"], rows["step"], rows["t_us"]))]
    return int(gt_id), rows


def presence_gaps(truth: np.ndarray | None, gt_id: int) -> list[tuple[int, int]]:
    """(last frame seen, first frame seen again) for each time the object left the field of view."""
    if truth is None or truth.size == 0:
        return []
    frames = np.unique(truth["frame"][truth["id"] == gt_id])
    jumps = np.flatnonzero(np.diff(frames) > 1)
    return [(int(frames[j]), int(frames[j + 1])) for j in jumps]


def _x_values(rows: np.ndarray, axis: str) -> tuple[np.ndarray, str]:
    if axis == "index":
        return np.arange(rows.size, dtype=np.float64), "evaluation (filter step with a match)"
    if axis == "time":
        return rows["t_us"].astype(np.float64) / 1e6, "time (s)"
    raise EvclustError(f"unknown x axis '{axis}' (use {' or '.join(AXES)})")


def _with_breaks(x: np.ndarray, y: np.ndarray, frames: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Insert NaN where the matched frames jump by more than one, so lines do not bridge gaps."""
    cut = np.flatnonzero(np.diff(frames) > 1) + 1
    if cut.size == 0:
        return x, y
    return np.insert(x.astype(np.float64), cut, np.nan), np.insert(y.astype(np.float64), cut, np.nan)


def _mark_events(axes, rows: np.ndarray, x: np.ndarray, axis: str, gaps, t_frame_us: float | None) -> None:
    """Red lines at exits and re-entries; dotted grey lines where the matched track id changes."""
    for ax in axes:
        labelled = False
        for last, again in gaps:
            if axis == "index":
                j = int(np.searchsorted(rows["frame"], last, side="right"))  # first row after the exit
                i = int(np.searchsorted(rows["frame"], again))  # first row after the re-entry
                if j == 0 or i >= rows.size:
                    continue  # the gap is outside the matched stretch
                positions = [(x[j - 1] + x[j]) / 2] + ([(x[i - 1] + x[i]) / 2] if i > j else [])
            else:
                period = t_frame_us or _frame_guess(rows)
                positions = [(last + 1) * period / 1e6, again * period / 1e6]
            for p in positions:
                ax.axvline(p, color=EXIT_COLOUR, lw=1.5, label=None if labelled else "exit / re-entry")
                labelled = True
        change = np.flatnonzero(rows["track_id"][1:] != rows["track_id"][:-1]) + 1
        if change.size > 30:  # too many to read; the title lists the ids
            continue
        for k, c in enumerate(change):
            ax.axvline(
                (x[c - 1] + x[c]) / 2 if axis == "index" else x[c], color="0.5", lw=0.8, ls=":", label="track id change" if k == 0 else None
            )


def _frame_guess(rows: np.ndarray) -> float:
    """t_frame from the rows themselves (t_us / frame), when no metadata is given."""
    ok = rows["frame"] > 0
    return float(np.median(rows["t_us"][ok].astype(np.float64) / rows["frame"][ok])) if ok.any() else 1e6


def _rmse(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.sqrt(np.mean((a.astype(np.float64) - b) ** 2))) if a.size else float("nan")


def _save(fig, path: Path) -> None:
    try:
        with atomic_output(path) as tmp:
            fig.savefig(tmp, dpi=100, format=path.suffix.lower().lstrip("."))
    finally:
        plt.close(fig)


def _subtitle(rows: np.ndarray, gt_id: int) -> str:
    ids = np.unique(rows["track_id"])
    shown = ", ".join(str(int(i)) for i in ids[:6]) + (", ..." if ids.size > 6 else "")
    return f"object {gt_id}: {rows.size} evaluations, track id(s) {shown}"


def plot_velocity(
    matches: np.ndarray,
    path: str | Path,
    gt_id: int | None = None,
    truth: np.ndarray | None = None,
    axis: str = "index",
    t_frame_us: float | None = None,
    title: str = "",
) -> int:
    """Fig. 7: vy (top) and vx (bottom) of one object, px/frame. Returns the object id drawn."""
    path = check_plot_path(path)
    gt_id, rows = pick_object(matches, gt_id)
    x, xlabel = _x_values(rows, axis)
    fig, axes = plt.subplots(2, 1, figsize=(11, 6.5), sharex=True, constrained_layout=True)
    for ax, c in zip(axes, ("y", "x")):
        gt = rows[f"gt_v{c}"]
        ax.plot(*_with_breaks(x, gt, rows["frame"]), color=GT_COLOUR, lw=2.0, label="ground truth", zorder=3)
        for method, vx, vy in velocity_methods(rows):
            name, colour, lw = METHOD_LINES[method]
            values = rows[vx if c == "x" else vy]
            ax.plot(*_with_breaks(x, values, rows["frame"]), color=colour, lw=lw, label=f"{name} (RMSE {_rmse(values, gt):.3g})", zorder=2)
        ax.set_ylabel(f"v{c} (px/frame)")
        ax.grid(alpha=0.3)
    _mark_events(axes, rows, x, axis, presence_gaps(truth, gt_id), t_frame_us)
    for ax in axes:
        ax.legend(loc="upper left", bbox_to_anchor=(1.005, 1.0), fontsize=8, frameon=False)  # outside: never over data
    axes[0].set_title("velocity y-component", fontsize=10)
    axes[1].set_title("velocity x-component", fontsize=10)
    axes[1].set_xlabel(xlabel)
    fig.suptitle(f"{title + ': ' if title else ''}{_subtitle(rows, gt_id)}", fontsize=11)
    _save(fig, path)
    return gt_id


def _class_summary(rows: np.ndarray, palette: tuple[str, ...]) -> str:
    if not palette:
        return ""
    cls = rows["class_palette"]
    names = np.array([palette[c] if 0 <= c < len(palette) else "" for c in cls.tolist()])
    accuracy = float(np.mean(names == rows["gt_label"])) if rows.size else float("nan")
    values, counts = np.unique(names[names != ""], return_counts=True)
    top = values[int(np.argmax(counts))] if values.size else "none"
    labels = np.unique(rows["gt_label"])
    return f"; label {'/'.join(labels.tolist()) or '?'}, classified mostly '{top}', accuracy {100 * accuracy:.0f}%"


def plot_colour(
    matches: np.ndarray,
    path: str | Path,
    gt_id: int | None = None,
    truth: np.ndarray | None = None,
    axis: str = "index",
    t_frame_us: float | None = None,
    palette: tuple[str, ...] = (),
    title: str = "",
) -> int:
    """Fig. 10: Y, Cb and Cr of one object; estimate green, ground truth blue. Returns the object id."""
    path = check_plot_path(path)
    gt_id, rows = pick_object(matches, gt_id)
    x, xlabel = _x_values(rows, axis)
    fig, axes = plt.subplots(3, 1, figsize=(11, 7.5), sharex=True, constrained_layout=True)
    for ax, name, long in zip(axes, ("Y", "Cb", "Cr"), ("luminance Y", "chrominance Cb", "chrominance Cr")):
        est, gt = rows[name], rows[f"gt_{name}"]
        ax.plot(*_with_breaks(x, gt, rows["frame"]), color=GT_COLOUR, lw=2.0, label="ground truth", zorder=3)
        ax.plot(*_with_breaks(x, est, rows["frame"]), color=EST_COLOUR, lw=1.2, label=f"estimate (RMSE {_rmse(est, gt):.3g})")
        ax.set_ylabel(name)
        ax.set_title(long, fontsize=10)
        ax.grid(alpha=0.3)
    _mark_events(axes, rows, x, axis, presence_gaps(truth, gt_id), t_frame_us)
    for ax in axes:
        ax.legend(loc="upper left", bbox_to_anchor=(1.005, 1.0), fontsize=8, frameon=False)  # outside: never over data
    axes[-1].set_xlabel(xlabel)
    fig.suptitle(f"{title + ': ' if title else ''}{_subtitle(rows, gt_id)}{_class_summary(rows, palette)}", fontsize=11)
    _save(fig, path)
    return gt_id


def cluster_events(rows: np.ndarray, events: np.ndarray, tracks: np.ndarray, period_us: float) -> tuple[np.ndarray, np.ndarray]:
    """Indices of the events inside the matched cluster's box at its records, and each row's record.

    For a record at filter step time t, the events counted are those in (t_prev, t], t_prev being
    the previous filter step time in the track file (at most one frame period earlier), that fall
    inside the box centre ± (rx, ry). Returns (event indices, record index per row; -1: none).
    """
    key = (tracks["step"].astype(np.uint64) << np.uint64(32)) | tracks["id"].astype(np.uint64)
    order = np.argsort(key, kind="stable")
    want = (rows["step"].astype(np.uint64) << np.uint64(32)) | rows["track_id"].astype(np.uint64)
    if order.size:
        pos = np.clip(np.searchsorted(key[order], want), 0, order.size - 1)
        rec = np.where(key[order][pos] == want, order[pos], -1)
    else:
        rec = np.full(rows.size, -1, np.int64)
    step_times = np.unique(tracks["t_us"]).astype(np.float64)
    t_ev = events["t"]
    chunks = []
    for r in rec.tolist():
        if r < 0:
            continue
        t = float(tracks["t_us"][r])
        j = int(np.searchsorted(step_times, t)) - 1
        lo_t = max(step_times[j] if j >= 0 else -math.inf, t - period_us)
        lo, hi = np.searchsorted(t_ev, np.array([max(0, math.floor(lo_t) + 1), math.floor(t) + 1], np.uint64))
        if hi <= lo:
            continue
        win = events[lo:hi]
        x, y, rx, ry = (float(tracks[f][r]) for f in ("x", "y", "rx", "ry"))
        inside = (np.abs(win["x"] - x) <= rx) & (np.abs(win["y"] - y) <= ry)
        chunks.append(lo + np.flatnonzero(inside))
    index = np.unique(np.concatenate(chunks)) if chunks else np.empty(0, np.int64)
    return index, rec


def plot_scatter(
    matches: np.ndarray,
    events: np.ndarray,
    ev_meta: EventMeta,
    tracks: np.ndarray,
    track_meta: TrackMeta,
    path: str | Path,
    gt_id: int | None = None,
    max_points: int = 40000,
    title: str = "",
) -> int:
    """Fig. 9: the colours of the events inside the matched cluster's box at its records.

    Panels: Cb–Cr and Y–Cb scatters, one point per event in its own colour, the palette entries
    marked and named (squares: background entries), the mean estimate and mean ground truth; and
    the cluster's content at its busiest record. Returns the object id drawn.
    """
    from evclust.render.tracks import FrameDrawer, to_canvas

    path = check_plot_path(path)
    if not ev_meta.has_colour:
        raise EvclustError("the event file carries no colour (DVS only): there is nothing to scatter")
    if (ev_meta.width, ev_meta.height) != (track_meta.width, track_meta.height):
        raise EvclustError(
            f"the tracks are for a {track_meta.width}x{track_meta.height} sensor, "
            f"the events come from a {ev_meta.width}x{ev_meta.height} one"
        )
    gt_id, rows = pick_object(matches, gt_id)
    period = float(ev_meta.t_frame_us or track_meta.t_frame_us or 33333.0)
    index, rec = cluster_events(rows, events, tracks, period)
    if index.size > max_points:
        index = np.sort(np.random.default_rng(0).choice(index, max_points, replace=False))
    pts = events[index]
    ycc = np.stack([pts["Y"], pts["Cb"], pts["Cr"]], axis=1).astype(np.float64)
    rgb = np.clip(ycbcr_to_rgb(ycc) / 255.0, 0, 1)

    fig = plt.figure(figsize=(15, 6.2), constrained_layout=True)
    grid = fig.add_gridspec(1, 3, width_ratios=(1, 1, 0.9))
    entries = np.asarray(track_meta.palette_ycbcr, dtype=np.float64).reshape(-1, 3)
    background = set(track_meta.palette_background)
    est = np.array([rows["Y"].mean(), rows["Cb"].mean(), rows["Cr"].mean()])
    gt = np.array([rows["gt_Y"].mean(), rows["gt_Cb"].mean(), rows["gt_Cr"].mean()])
    for col, (i, j) in enumerate(((1, 2), (1, 0))):  # (Cb, Cr), (Cb, Y)
        names = ("Y", "Cb", "Cr")
        ax = fig.add_subplot(grid[0, col])
        ax.set_facecolor("0.88")
        ax.scatter(ycc[:, i], ycc[:, j], c=rgb, s=4, linewidths=0, alpha=0.6, rasterized=True)
        for k, name in enumerate(track_meta.palette[: len(entries)]):
            face = np.clip(ycbcr_to_rgb(entries[k]) / 255.0, 0, 1)
            ax.scatter(
                entries[k, i],
                entries[k, j],
                s=110,
                c=[face],
                edgecolors="black",
                linewidths=1.2,
                marker="s" if name in background else "o",
                zorder=3,
            )
            ax.annotate(
                name + (" (bg)" if name in background else ""),
                (entries[k, i], entries[k, j]),
                xytext=(6, 5),
                textcoords="offset points",
                fontsize=8,
                zorder=4,
            )
        ax.scatter(est[i], est[j], s=180, marker="*", c=EST_COLOUR, edgecolors="black", zorder=5, label="estimate (mean)")
        ax.scatter(gt[i], gt[j], s=120, marker="X", c=GT_COLOUR, edgecolors="black", zorder=5, label="ground truth (mean)")
        ax.set_xlim(0, 255)
        ax.set_ylim(0, 255)
        ax.set_aspect("equal")
        ax.set_xlabel(names[i])
        ax.set_ylabel(names[j])
        ax.set_title(f"{names[j]} against {names[i]}: {index.size} events", fontsize=10)
        ax.legend(loc="lower right", fontsize=8)

    ax = fig.add_subplot(grid[0, 2])
    ok = rec >= 0
    if ok.any():  # the cluster at its busiest record (the most events inside its box)
        scale = 4
        recs = rec[ok]
        sizes = []
        t_ev = events["t"]
        for r in recs.tolist():
            t = float(tracks["t_us"][r])
            lo, hi = np.searchsorted(t_ev, np.array([max(0, math.floor(t - period) + 1), math.floor(t) + 1], np.uint64))
            win = events[lo:hi]
            sizes.append(
                int(((np.abs(win["x"] - tracks["x"][r]) <= tracks["rx"][r]) & (np.abs(win["y"] - tracks["y"][r]) <= tracks["ry"][r])).sum())
            )
        r = int(recs[int(np.argmax(sizes))])
        # This record alone over the events of one frame period before it.
        drawer = FrameDrawer(events, ev_meta, tracks[r : r + 1], track_meta, window_us=period, scale=scale, arrow_frames=2.0)
        frame = drawer.draw(float(tracks["t_us"][r]))
        pad = float(track_meta.seek_margin) + 4
        x0, y0 = to_canvas([tracks["x"][r] - tracks["rx"][r] - pad, tracks["y"][r] - tracks["ry"][r] - pad], scale)
        x1, y1 = to_canvas([tracks["x"][r] + tracks["rx"][r] + pad, tracks["y"][r] + tracks["ry"][r] + pad], scale)
        body_h = ev_meta.height * scale
        crop = frame[max(0, y0) : min(body_h, y1 + 1), max(0, x0) : min(frame.shape[1], x1 + 1), ::-1]
        ax.imshow(crop, interpolation="nearest")
        ax.set_title(f"cluster {int(tracks['id'][r])} at t={int(tracks['t_us'][r]) / 1e6:.3f} s", fontsize=10)
    else:
        ax.text(0.5, 0.5, "no track record found", ha="center", va="center", transform=ax.transAxes)
    ax.set_xticks([])
    ax.set_yticks([])
    fig.suptitle(f"{title + ': ' if title else ''}event colours of {_subtitle(rows, gt_id)}", fontsize=11)
    _save(fig, path)
    return gt_id
