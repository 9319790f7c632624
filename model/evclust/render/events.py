"""A picture of an event stream: polarity, the colour the events carry, and the event rate."""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from evclust.colour import ycbcr_to_rgb
from evclust.errors import EvclustError, atomic_output
from evclust.events.format import EventMeta

MAX_BINS = 2000  # of the event-rate histogram


def _window(ev: np.ndarray, meta: EventMeta, t0_us: float | None, span_us: float | None) -> np.ndarray:
    if ev.size == 0:
        return ev
    span = span_us if span_us is not None else 3 * (meta.t_frame_us or 33333.0)
    if t0_us is None:  # centre the window on the busiest moment
        counts, edges = np.histogram(ev["t"], bins=max(1, int((int(ev["t"][-1]) - int(ev["t"][0])) // span) + 1))
        t0_us = edges[int(np.argmax(counts))]
    lo, hi = np.searchsorted(ev["t"], [t0_us, t0_us + span])
    return ev[lo:hi]


def draw_events(ev: np.ndarray, meta: EventMeta, path: str | Path, t0_us: float | None = None, span_us: float | None = None) -> None:
    """Three panels: ON/OFF events of a time window, the colour those events carry, events per frame."""
    from evclust.render.plots import check_plot_path

    check_plot_path(path)
    if t0_us is not None and not math.isfinite(t0_us):
        raise EvclustError(f"--t0 {t0_us}: a start time in µs must be a finite number")
    if span_us is not None and not 0 < span_us < math.inf:
        raise EvclustError(f"--span {span_us}: the window's length in µs must be positive and finite")
    win = _window(ev, meta, t0_us, span_us)
    polarity = np.full((meta.height, meta.width, 3), 0.5)
    colour = np.zeros((meta.height, meta.width, 3))
    if win.size:
        on = win["p"] > 0
        polarity[win["y"][on], win["x"][on]] = (1.0, 1.0, 1.0)
        polarity[win["y"][~on], win["x"][~on]] = (0.0, 0.0, 0.0)
        if meta.has_colour:
            ycc = np.stack([win["Y"], win["Cb"], win["Cr"]], axis=1).astype(np.float64)
            colour[win["y"], win["x"]] = np.clip(ycbcr_to_rgb(ycc) / 255.0, 0, 1)  # the latest event wins
    tall = meta.height > meta.width
    fig = plt.figure(figsize=(13, 7.5) if tall else (13, 6.5), constrained_layout=True)
    grid = fig.add_gridspec(2, 2, height_ratios=(3, 1))
    window_ms = f"{int(win['t'][0]) / 1e3:.1f}-{int(win['t'][-1]) / 1e3:.1f} ms" if win.size else "no events"
    for col, (image, title) in enumerate(((polarity, "polarity (white ON, black OFF)"), (colour, "colour carried by the events"))):
        ax = fig.add_subplot(grid[0, col])
        ax.imshow(image, interpolation="nearest")
        if col == 1 and not meta.has_colour:
            title = "no colour: DVS events (an event-camera file)"
            ax.text(0.5, 0.5, "no colour", transform=ax.transAxes, ha="center", va="center", color="0.6", fontsize=14)
        ax.set_title(f"{title}\n{window_ms}", fontsize=10)
        ax.set_xlabel("x (px)")
        ax.set_ylabel("y (px)")
    ax = fig.add_subplot(grid[1, :])
    if ev.size:
        # From the first event, not from 0: a camera's clock may start anywhere (a DAVIS writes
        # Unix time). At most MAX_BINS bins: a longer stream gets wider ones.
        first, last = int(ev["t"][0]), int(ev["t"][-1])
        frame = max(meta.t_frame_us or 33333.0, (last - first + 1) / MAX_BINS)
        bins = first + np.arange(0, last - first + 2 * frame, frame)
        for sign, name, colour_ in ((1, "ON", "tab:red"), (-1, "OFF", "tab:blue")):
            sel = ev["p"] == sign
            ax.hist(ev["t"][sel] / 1e6, bins=bins / 1e6, histtype="step", color=colour_, label=name)
        if win.size:
            ax.axvspan(int(win["t"][0]) / 1e6, int(win["t"][-1]) / 1e6, color="0.85", zorder=0, label="window above")
        ax.legend(loc="upper right", fontsize=8)
        ax.set_ylabel("events per frame" if frame == (meta.t_frame_us or 33333.0) else f"events per {frame / 1e3:.4g} ms")
    ax.set_xlabel("time (s)")
    fig.suptitle(f"{meta.source or 'events'}: {ev.size} events, {meta.width}x{meta.height}", fontsize=12)
    with atomic_output(path) as tmp:
        fig.savefig(tmp, dpi=90, format=Path(path).suffix.lstrip(".") or "png")
    plt.close(fig)
