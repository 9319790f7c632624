"""The report's pictures (matplotlib, Agg)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np


def _save(fig, path: Path) -> None:
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


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
    _save(fig, path)


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
    _save(fig, path)


def ranges(rows: list[tuple[str, float, float, float, float]], path: Path, title: str) -> None:
    """Per signal: the representable range (light) and the range seen (dark), on a symmetric log axis."""
    fig, ax = plt.subplots(figsize=(8, 0.45 * len(rows) + 1.2))
    for i, (_name, lo, hi, seen_lo, seen_hi) in enumerate(rows):
        ax.barh(i, hi - lo, left=lo, color="#cfd8e3", height=0.7)
        ax.barh(i, max(seen_hi - seen_lo, 1e-9), left=seen_lo, color="#2b6cb0", height=0.4)
    ax.set_yticks(range(len(rows)), [r[0] for r in rows])
    ax.set_xscale("symlog", linthresh=1e-2)
    ax.set_xlabel("value (light: the format's range; dark: the range the scene reached)")
    ax.set_title(title)
    _save(fig, path)


def velocity_tradeoff(points, path: Path, title: str) -> None:
    """Steady-state error against convergence time after a turn, one line per method."""
    fig, ax = plt.subplots(figsize=(7.5, 4.5))
    for method in dict.fromkeys(p.method for p in points):
        pts = [p for p in points if p.method == method and p.convergence_frames is not None]
        if not pts:
            continue
        x = [p.convergence_frames for p in pts]
        y = [100 * p.steady_nrmse for p in pts]
        (line,) = ax.plot(x, y, marker="o", label=method)
        for p, xi, yi in zip(pts, x, y):
            ax.annotate(f"{p.alpha:g}", (xi, yi), textcoords="offset points", xytext=(4, 4), fontsize=7, color=line.get_color())
    ax.set_xlabel("frames after a 90° turn until within 10 % of the new velocity")
    ax.set_ylabel("steady-state velocity NRMSE (%)")
    ax.set_yscale("log")
    ax.grid(True, which="both", alpha=0.3)
    ax.set_title(title)
    ax.legend(fontsize=8)
    _save(fig, path)


def _labelled_scatter(ax, labels, x, y, xlabel: str, ylabel: str) -> None:
    """One labelled point per option."""
    ax.scatter(x, y, color="#2b6cb0")
    for label, xi, yi in zip(labels, x, y):
        ax.annotate(label, (xi, yi), textcoords="offset points", xytext=(4, 3), fontsize=7)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(True, alpha=0.3)


def cost_against_accuracy(labels, seconds, accuracy, path: Path, title: str, xlabel: str, ylabel: str) -> None:
    """One point per option: its cost against its task error."""
    fig, ax = plt.subplots(figsize=(7.5, 4.5))
    _labelled_scatter(ax, labels, seconds, accuracy, xlabel, ylabel)
    ax.set_title(title)
    _save(fig, path)


def area_against_accuracy(labels, areas: list[dict], errors, path: Path, title: str, error_label: str) -> None:
    """Left: LUTs and FFs per configuration (DSP count written above); right: LUTs against the
    task error, one labelled point per configuration."""
    fig, (bars, scatter) = plt.subplots(1, 2, figsize=(12, 4.6), gridspec_kw={"width_ratios": [1.3, 1]})
    x = np.arange(len(labels))
    luts = np.array([a["lut"] + a["inv"] for a in areas])
    ffs = np.array([a["ff"] for a in areas])
    bars.bar(x - 0.2, luts, 0.4, label="LUT (+INV)", color="#2b6cb0")
    bars.bar(x + 0.2, ffs, 0.4, label="FF", color="#dd8452")
    for xi, lut, a in zip(x, luts, areas):
        bars.annotate(f"{a['dsp48e1']} DSP", (xi - 0.2, lut), textcoords="offset points", xytext=(0, 3), ha="center", fontsize=7)
    bars.set_xticks(x, labels, rotation=20, ha="right", fontsize=8)
    bars.set_ylabel("cells (Yosys synth_xilinx)")
    bars.legend(fontsize=8)
    bars.grid(True, axis="y", alpha=0.3)
    _labelled_scatter(scatter, labels, luts, errors, "LUT (+INV)", error_label)
    fig.suptitle(title)
    _save(fig, path)


def runtime_bars(labels, ns_per_event, errors, path: Path, title: str, error_name: str) -> None:
    """Horizontal bars of runtime per event (log), each labelled with its model's task error:
    the models' errors are equal or nearly so, their runtimes span decades."""
    fig, ax = plt.subplots(figsize=(8, 0.5 * len(labels) + 1.4))
    y = np.arange(len(labels))[::-1]
    ax.barh(y, ns_per_event, color="#2b6cb0")
    for yi, ns, err in zip(y, ns_per_event, errors):
        ax.annotate(f"{ns:,.0f} ns, {error_name} {err}", (ns, yi), textcoords="offset points", xytext=(4, -3), fontsize=7)
    ax.set_yticks(y, labels, fontsize=8)
    ax.set_xscale("log")
    ax.set_xlim(right=max(ns_per_event) * 60)
    ax.set_xlabel("ns per event (log)")
    ax.set_title(title)
    ax.grid(True, axis="x", alpha=0.3)
    _save(fig, path)
