"""The report's pictures (matplotlib, Agg)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def noise_shares(rows: dict, sources, groups, path: Path, title: str) -> None:
    """Stacked bars: each source's share of the summed noise power, per output group."""
    fig, ax = plt.subplots(figsize=(8, 4.2))
    bottom = np.zeros(len(groups))
    colours = plt.cm.tab20(np.linspace(0, 1, len(sources)))
    for source, colour in zip(sources, colours):
        powers = np.array([rows[source][g].power for g in groups])
        totals = np.array([sum(rows[s][g].power for s in sources) for g in groups])
        share = np.divide(powers, totals, out=np.zeros_like(powers), where=totals > 0)
        ax.bar(groups, share, bottom=bottom, color=colour, label=source)
        bottom += share
    ax.set_ylabel("share of the summed noise power")
    ax.set_title(title)
    ax.legend(bbox_to_anchor=(1.01, 1), loc="upper left", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def error_vs_bits(curves: dict, defaults: dict, path: Path, title: str) -> None:
    """One curve per signal: RMS error of its output against its fraction bits; the dot is the default."""
    fig, ax = plt.subplots(figsize=(8, 4.5))
    for signal, curve in curves.items():
        if not curve:
            continue
        bits, err = zip(*curve)
        err = np.maximum(np.array(err, dtype=float), 1e-12)
        (line,) = ax.semilogy(bits, err, marker=".", label=signal)
        if defaults[signal] in bits:
            ax.semilogy([defaults[signal]], [err[list(bits).index(defaults[signal])]], "o", color=line.get_color(), ms=8, mfc="none")
    ax.set_xlabel("fraction bits of the signal (others exact)")
    ax.set_ylabel("RMS error of its output (px, px/frame or colour units)")
    ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, ncol=2)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def ranges(rows: list[tuple[str, float, float, float, float]], path: Path, title: str) -> None:
    """Per signal: the representable range (light) and the range seen (dark), on a symmetric log axis."""
    fig, ax = plt.subplots(figsize=(8, 0.45 * len(rows) + 1.2))
    for i, (name, lo, hi, seen_lo, seen_hi) in enumerate(rows):
        ax.barh(i, hi - lo, left=lo, color="#cfd8e3", height=0.7)
        ax.barh(i, max(seen_hi - seen_lo, 1e-9), left=seen_lo, color="#2b6cb0", height=0.4)
    ax.set_yticks(range(len(rows)), [r[0] for r in rows])
    ax.set_xscale("symlog", linthresh=1e-2)
    ax.set_xlabel("value (light: the format's range; dark: the range the scene reached)")
    ax.set_title(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
