#!/usr/bin/env python
"""Speed of the colour event simulator on one core, in Mpixel-frames/s and Mevents/s.

    make bench        # = .venv/bin/python bench/simulator.py --write docs/BENCHMARKS.md

Cases: the built-in `traffic` scene and a generated 480x270, 200-frame video (a panning texture
and moving coloured disks, stored losslessly in build/bench/), each with the ideal sensor and with
noise effects on. For each case:

- simulator:  frames already rendered / decoded in memory; times make_simulator + Simulator.run;
- end to end: what `evclust simulate` does before writing the file: load the scene, render or
              decode every frame, simulate (writing the event file is not included);
- baseline:   (ideal cases) a plain vectorised-numpy version of the same ideal detector, on the
              same in-memory frames, timed in the same run so the ratio is robust to machine noise;
- effects:    each noise effect alone, to show what it adds to the ideal run.

One warm-up run (numba JIT / cache load), then --repeat timed runs: median and best wall time.
Mpixel-frames/s = W*H*frames / wall / 1e6; Mev/s = events / wall / 1e6.
"""

from __future__ import annotations

import common  # first: pins every thread pool to one core

import argparse
import dataclasses
import datetime
import statistics
import sys
import time
from pathlib import Path
from collections.abc import Callable

import cv2
import numpy as np
from tqdm import tqdm

from evclust.colour import RGB_TO_YCBCR
from evclust.events.format import EVENT_DTYPE
from evclust.scenes import Scene, load_scene
from evclust.scenes.synthetic import SyntheticSource
from evclust.scenes.video import VideoSource
from evclust.simulator import EFFECTS, make_simulator, simulate_scene

ROOT = Path(__file__).resolve().parents[1]
VIDEO = ROOT / "build" / "bench" / "pan_disks.avi"
VIDEO_W, VIDEO_H, VIDEO_FRAMES, VIDEO_FPS = 480, 270, 200, 30.0
START, END = "<!-- bench:simulator:start -->", "<!-- bench:simulator:end -->"
TARGET_MPX, TARGET_MEV = 150.0, 3.0

# "Noise on": the effects the benchmark switches on, with their parameters.
NOISE = {
    "threshold_mismatch": {"sigma": 0.03},
    "background_activity": {"rate_hz": 0.5},
    "hot_pixels": {"count": 20, "rate_hz": 1000.0},
    "refractory": {"period_us": 1000.0},
}


# --------------------------------------------------------------------------------------------
# The benchmark video: generated deterministically, stored losslessly (HuffYUV in AVI).


def video_frames() -> list[np.ndarray]:
    """200 frames, BGR uint8: a smooth texture panning (3, 1) px/frame, six coloured disks on
    straight paths, bouncing off the borders, drawn anti-aliased at sub-pixel positions."""
    rng = np.random.default_rng(2024)
    pan = np.array([3, 1])
    ch, cw = VIDEO_H + pan[1] * VIDEO_FRAMES + 1, VIDEO_W + pan[0] * VIDEO_FRAMES + 1
    fine = cv2.GaussianBlur(rng.standard_normal((ch, cw)).astype(np.float32), (0, 0), 3.0)
    coarse = cv2.GaussianBlur(rng.standard_normal((ch, cw)).astype(np.float32), (0, 0), 25.0)
    fine /= fine.std()
    coarse /= coarse.std()
    grey = 110.0 + 14.0 * fine + 30.0 * coarse  # fine grain over large, softer blotches
    tint = np.array([0.92, 1.0, 1.08], np.float32)  # BGR: a slightly warm ground
    canvas = np.clip(grey[..., None] * tint, 0, 255).astype(np.uint8)

    colours = [(40, 40, 220), (60, 200, 40), (220, 80, 30), (30, 210, 230), (200, 40, 200), (230, 220, 40)]  # BGR
    radius = np.array([28.0, 22.0, 34.0, 18.0, 25.0, 30.0])
    pos = np.column_stack([rng.uniform(60, VIDEO_W - 60, 6), rng.uniform(50, VIDEO_H - 50, 6)])
    angle = np.linspace(0.3, 0.3 + 2 * np.pi, 6, endpoint=False)
    speed = np.array([4.0, 6.5, 3.0, 8.0, 5.0, 2.5])
    vel = np.column_stack([np.cos(angle), np.sin(angle)]) * speed[:, None]

    shift = 4  # sub-pixel positions: coordinates in 1/16 px
    frames = []
    for k in range(VIDEO_FRAMES):
        x0, y0 = pan * k
        frame = canvas[y0 : y0 + VIDEO_H, x0 : x0 + VIDEO_W].copy()
        for c, r, p in zip(colours, radius, pos):
            centre = tuple(int(round(v * (1 << shift))) for v in p)
            cv2.circle(frame, centre, int(round(r * (1 << shift))), c, -1, cv2.LINE_AA, shift)
        frames.append(frame)
        pos += vel
        for d, limit in ((0, VIDEO_W), (1, VIDEO_H)):
            low, high = pos[:, d] < radius, pos[:, d] > limit - radius
            vel[low | high, d] *= -1
            pos[low, d] = 2 * radius[low] - pos[low, d]
            pos[high, d] = 2 * (limit - radius[high]) - pos[high, d]
    return frames


def decode(path: Path) -> list[np.ndarray]:
    capture = cv2.VideoCapture(str(path))
    frames = []
    while True:
        ok, frame = capture.read()
        if not ok:
            break
        frames.append(frame)
    capture.release()
    return frames


def same_frames(a: list[np.ndarray], b: list[np.ndarray]) -> bool:
    return len(a) == len(b) and all(x.shape == y.shape and np.array_equal(x, y) for x, y in zip(a, b))


def ensure_video() -> str:
    """Write the video unless an identical one is there; check that it decodes bit-exactly.

    HuffYUV (BGR24) is lossless and decodes ~3x faster than FFV1 with OpenCV's FFmpeg, so the
    end-to-end figure measures less of the codec and more of the simulator."""
    source = video_frames()
    if VIDEO.is_file() and same_frames(decode(VIDEO), source):
        return "reused the file already there, after checking it"
    VIDEO.parent.mkdir(parents=True, exist_ok=True)
    writer = cv2.VideoWriter(str(VIDEO), cv2.VideoWriter_fourcc(*"HFYU"), VIDEO_FPS, (VIDEO_W, VIDEO_H))
    if not writer.isOpened():
        raise SystemExit(f"bench: OpenCV cannot write HuffYUV video to {VIDEO}")
    for frame in source:
        writer.write(frame)
    writer.release()
    if not same_frames(decode(VIDEO), source):
        raise SystemExit(f"bench: {VIDEO} does not decode to the frames written: the codec is not lossless here")
    return "wrote the file"


# --------------------------------------------------------------------------------------------
# The baseline: the same ideal detector, written as straightforward vectorised numpy.


def baseline_simulate(frames: list[np.ndarray], scene: Scene) -> np.ndarray:
    sensor = scene.spec.sensor
    width = scene.source.width
    dt = scene.source.t_sample_us  # the period of the frames the sensor sees (sub-steps included)
    th_on, th_off = float(sensor.threshold_on), float(sensor.threshold_off)
    luma = RGB_TO_YCBCR[0, :3].astype(np.float32)
    to_ycc, offset = RGB_TO_YCBCR[:, :3].T, RGB_TO_YCBCR[:, 3]
    chunks = []
    ref = prev_level = prev_rgb = None
    for k, frame in enumerate(frames):
        rgb = frame.reshape(-1, 3)
        level = rgb @ luma
        level = np.log(level + np.float32(sensor.log_eps)) if sensor.detector == "log" else level
        if ref is None:
            ref = level.astype(np.float64)
            prev_level, prev_rgb = level, rgb
            continue
        t0 = (k - 1) * dt
        diff = level - ref
        count = np.zeros(ref.size, np.int64)
        on, off = diff >= th_on, -diff >= th_off
        count[on] = np.floor(diff[on] / th_on)
        count[off] = np.floor(-diff[off] / th_off)
        idx = np.flatnonzero(count)
        cnt = count[idx]
        step = np.where(on[idx], th_on, -th_off)
        r = ref[idx]
        l1 = level[idx].astype(np.float64)
        l0 = prev_level[idx].astype(np.float64)
        span = l1 - l0
        flat = span == 0.0
        span[flat], l0[flat] = step[flat], l1[flat] - step[flat]
        c0, c1 = prev_rgb[idx].astype(np.float64), rgb[idx].astype(np.float64)
        ts, pix, pol, yccs = [], [], [], []
        for j in range(1, int(cnt.max(initial=0)) + 1):
            m = np.flatnonzero(cnt >= j)
            frac = np.clip((r[m] + j * step[m] - l0[m]) / span[m], 0.0, 1.0)
            colour = c0[m] + frac[:, None] * (c1[m] - c0[m])
            ts.append((t0 + frac * dt + 0.5).astype(np.uint64))
            pix.append(idx[m])
            pol.append(np.sign(step[m]).astype(np.int8))
            yccs.append((np.clip(colour @ to_ycc + offset, 0.0, 255.0) + 0.5).astype(np.uint8))
        ref[idx] = r + cnt * step
        prev_level, prev_rgb = level, rgb
        if not ts:
            continue
        t, p_idx = np.concatenate(ts), np.concatenate(pix)
        order = np.lexsort((p_idx, t))
        ev = np.empty(t.size, EVENT_DTYPE)
        ev["t"] = t[order]
        p_idx = p_idx[order]
        ev["y"], ev["x"] = np.divmod(p_idx, width)
        ev["p"] = np.concatenate(pol)[order]
        ycc = np.concatenate(yccs)[order]
        ev["Y"], ev["Cb"], ev["Cr"] = ycc[:, 0], ycc[:, 1], ycc[:, 2]
        chunks.append(ev)
    return np.concatenate(chunks) if chunks else np.zeros(0, EVENT_DTYPE)


# --------------------------------------------------------------------------------------------
# Timing.


@dataclasses.dataclass
class Timing:
    walls: list[float]
    events: int

    @property
    def median(self) -> float:
        return statistics.median(self.walls)

    @property
    def best(self) -> float:
        return min(self.walls)


def timed(label: str, fn: Callable[[], int], repeat: int) -> Timing:
    fn()  # warm-up: numba compiles or loads its cache, OpenCV and the OS settle
    walls, counts = [], set()
    for _ in tqdm(range(repeat), desc=label, unit="run", leave=False, file=sys.stderr):
        start = time.perf_counter()
        n = fn()
        walls.append(time.perf_counter() - start)
        counts.add(n)
    if len(counts) != 1:
        raise SystemExit(f"bench: {label}: event count changed between runs: {sorted(counts)}")
    return Timing(walls, counts.pop())


def with_effects(scene: Scene, effects: dict) -> Scene:
    """The same scene with sensor effects switched on (as an [effects] table in its file would)."""
    spec = scene.spec.model_copy(update={"effects": effects})
    src = scene.source
    if isinstance(src, SyntheticSource):
        source = SyntheticSource(spec, Path("."), src.source)
    else:
        source = VideoSource(src.path, fps=src.fps, max_frames=src.max_frames)
    return Scene(spec, source, scene.truth_path)


@dataclasses.dataclass
class Case:
    name: str
    noisy: bool
    width: int
    height: int
    frames: int
    sim: Timing
    e2e: Timing
    base: Timing | None = None
    check: str = ""

    @property
    def px(self) -> float:
        return self.width * self.height * self.frames


def run_case(name: str, load: Callable[[], Scene], frames: list[np.ndarray], noisy: bool, effects: dict, repeat: int) -> Case:
    make = (lambda: with_effects(load(), effects)) if noisy else load
    scene = make()
    src = scene.source

    def simulate() -> int:
        return len(make_simulator(scene).run(frames, source=src.source, total=len(frames)).events)

    def end_to_end() -> int:
        s = make()
        return len(simulate_scene(s).events)

    kind = "noisy" if noisy else "ideal"
    case = Case(name, noisy, src.width, src.height, len(frames), timed(f"{name} {kind}: simulator", simulate, repeat),
                timed(f"{name} {kind}: end to end", end_to_end, repeat))  # fmt: skip
    if not noisy:
        case.base = timed(f"{name} {kind}: numpy baseline", lambda: len(baseline_simulate(frames, scene)), repeat)
        ours = make_simulator(scene).run(frames).events
        theirs = baseline_simulate(frames, scene)
        same = ""
        if len(ours) == len(theirs):
            fields = list(EVENT_DTYPE.names)
            same = (f"; as sets of records {np.mean(np.sort(ours, order=fields) == np.sort(theirs, order=fields)):.4%} identical "
                    "(the baseline does not re-order events tied on a frame-boundary microsecond, so its order differs there)")  # fmt: skip
        case.check = f"evclust {len(ours):,} events, baseline {len(theirs):,} (difference {len(theirs) - len(ours):+d}){same}"
    return case


@dataclasses.dataclass
class EffectCost:
    scene: str
    effect: str
    events: int
    wall: Timing


def effect_costs(name: str, load: Callable[[], Scene], frames: list[np.ndarray], effects: dict, repeat: int) -> list[EffectCost]:
    """Each noise effect alone, simulator with frames in memory: what it adds to the ideal run."""
    costs = []
    for effect, params in effects.items():
        scene = with_effects(load(), {effect: params})
        t = timed(f"{name}: {effect} alone", lambda scene=scene: len(make_simulator(scene).run(frames).events), repeat)
        costs.append(EffectCost(name, effect, t.events, t))
    return costs


# --------------------------------------------------------------------------------------------
# Report.


def rate_cells(px: float, events: int, t: Timing) -> str:
    return (f"{t.median:.3f} | {t.best:.3f} | {px / t.median / 1e6:.1f} | {px / t.best / 1e6:.1f} | "
            f"{events / t.median / 1e6:.2f} | {events / t.best / 1e6:.2f}")  # fmt: skip


def case_table(c: Case) -> list[str]:
    kind = "noisy" if c.noisy else "ideal"
    lines = [
        f"#### {c.name}, {kind} sensor: {c.frames} frames of {c.width}×{c.height}, {c.sim.events:,} events",
        "",
        "| run | median wall s | best wall s | Mpx-frames/s (median) | Mpx-frames/s (best) | Mev/s (median) | Mev/s (best) |",
        "|---|---:|---:|---:|---:|---:|---:|",
        f"| simulator (frames in memory) | {rate_cells(c.px, c.sim.events, c.sim)} |",
        f"| end to end (load + {'render' if c.name == 'traffic' else 'decode'} + simulate) | {rate_cells(c.px, c.e2e.events, c.e2e)} |",
    ]
    if c.base is not None:
        lines.append(f"| numpy baseline (frames in memory) | {rate_cells(c.px, c.base.events, c.base)} |")
        lines += ["", f"evclust / baseline speed (median): **{c.base.median / c.sim.median:.1f}×**. Same work: {c.check}."]
    lines.append("")
    return lines


def cost_model(cases: list[Case]) -> list[str]:
    """Fit wall = a·pixel-frames + b·events through the two ideal cases (simulator, median)."""
    ideal = [c for c in cases if not c.noisy]
    if len(ideal) != 2:
        return []
    m = np.array([[c.px, c.sim.events] for c in ideal], dtype=np.float64)
    w = np.array([c.sim.median for c in ideal])
    if abs(np.linalg.det(m / m.max(axis=0))) < 1e-3:
        return []
    a, b = np.linalg.solve(m, w)
    if a <= 0 or b <= 0:
        return []
    budget = 1e-6 / TARGET_MPX  # s per pixel-frame at the target
    limit = (budget - a) / b if budget > a else 0.0
    return [
        "",
        f"Cost model through the two ideal cases: wall ≈ {a * 1e9:.2f} ns per pixel-frame + {b * 1e9:.1f} ns per event. "
        f"At that rate ≥ {TARGET_MPX:.0f} Mpx-frames/s holds up to {limit:.3f} events per pixel-frame; "
        + ", ".join(f"{c.name} makes {c.sim.events / c.px:.3f}" for c in ideal)
        + ".",
    ]


def report(cases: list[Case], costs: list[EffectCost], video_note: str, repeat: int, effects: dict, missing: list[str]) -> str:
    now = datetime.datetime.now().astimezone().strftime("%Y-%m-%d %H:%M %Z")
    lines = [
        START,
        "## Simulator speed",
        "",
        f"Command: `make bench` (= `.venv/bin/python bench/simulator.py --write docs/BENCHMARKS.md`), run {now}.",
        "",
        "Machine:",
        "",
        *common.machine(),
        "",
        "Method: one warm-up run, then "
        f"{repeat} timed runs of each; wall time by `time.perf_counter`. Mpx-frames/s = W·H·frames / wall / 10⁶, "
        "Mev/s = events / wall / 10⁶. *Simulator*: frames already rendered or decoded in memory as float32 RGB, "
        "timing `make_simulator` + `Simulator.run`. *End to end*: what `evclust simulate` does before writing "
        "its file: load the scene, render (traffic) or decode (video) every frame, simulate; writing the event "
        "file is not timed. *Numpy baseline*: the same ideal detector (log luma per frame, "
        "floor(|L1 − Lref|/θ) crossings per pixel, a loop over the crossing index with masks for the "
        "interpolated times and YCbCr, then a sort), written as plain vectorised numpy in `bench/simulator.py`.",
        "",
        "Cases: `traffic` (built-in scene, 480×270, 291 frames at 20 fps, θ = 0.3) and "
        "`video`: 480×270, 200 frames at 30 fps, a smooth texture (fine grain over large soft blotches) panning "
        "3 px/frame right and 1 px/frame down, with six coloured disks (radius 18–34 px, 2.5–8 px/frame) bouncing "
        "off the borders; generated by `bench/simulator.py` into `build/bench/pan_disks.avi` (HuffYUV, lossless: "
        f"the decoded frames are checked equal to the generated ones; this run {video_note}) and read through "
        "OpenCV as `evclust simulate build/bench/pan_disks.avi` would (default sensor, θ = 0.2).",
        "",
        "Noisy sensor: effects "
        + ", ".join(f"`{k}` ({', '.join(f'{p} = {v}' for p, v in v.items())})" for k, v in effects.items())
        + "."
        + (f" Not available in this build, so left out: {', '.join(f'`{m}`' for m in missing)}." if missing else ""),
        "",
        "### Summary (simulator, frames in memory, median of the runs)",
        "",
        "| case | frames | size | events | events per pixel-frame | median wall s | best wall s | Mpx-frames/s | Mev/s | end to end Mpx-frames/s | end to end Mev/s |",
        "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for c in cases:
        lines.append(
            f"| {c.name} {'noisy' if c.noisy else 'ideal'} | {c.frames} | {c.width}×{c.height} | {c.sim.events:,} | {c.sim.events / c.px:.4f} | "
            f"{c.sim.median:.3f} | {c.sim.best:.3f} | {c.px / c.sim.median / 1e6:.1f} | {c.sim.events / c.sim.median / 1e6:.2f} | "
            f"{c.px / c.e2e.median / 1e6:.1f} | {c.e2e.events / c.e2e.median / 1e6:.2f} |"
        )
    lines += ["", "### Target", ""]
    for c in cases:
        if c.noisy:
            continue
        mpx, mev = c.px / c.sim.median / 1e6, c.sim.events / c.sim.median / 1e6
        ok = mpx >= TARGET_MPX and mev >= TARGET_MEV
        e_mpx, e_mev = c.px / c.e2e.median / 1e6, c.e2e.events / c.e2e.median / 1e6
        e_ok = e_mpx >= TARGET_MPX and e_mev >= TARGET_MEV
        lines.append(
            f"- {c.name}, ideal sensor, one core: simulator {mpx:.1f} Mpx-frames/s and {mev:.2f} Mev/s against "
            f"≥ {TARGET_MPX:.0f} and ≥ {TARGET_MEV:.0f}: **{'PASS' if ok else 'FAIL'}**"
            f"{'' if mpx >= TARGET_MPX else ' (Mpx-frames/s short)'}{'' if mev >= TARGET_MEV else ' (Mev/s short)'}; "
            f"end to end (for information) {e_mpx:.1f} Mpx-frames/s and {e_mev:.2f} Mev/s: {'pass' if e_ok else 'fail'}."
        )
    lines += cost_model(cases)
    lines += [
        "",
        "For scale, the project's brief quotes a C++ DVS simulator (no colour) at about 76 Mpx-frames/s and 1.5 Mev/s on this class of machine; that simulator is not run here. "
        "Mev/s depends on how many events a scene makes per pixel, so it is reported per scene.",
        "",
        "### Per case",
        "",
    ]
    for c in cases:
        lines += case_table(c)
    if costs:
        ideal = {c.name: c for c in cases if not c.noisy}
        lines += [
            "### Noise effects one at a time (simulator, frames in memory, median)",
            "",
            "| case | effect | events | median wall s | added to ideal s | Mpx-frames/s | Mev/s |",
            "|---|---|---:|---:|---:|---:|---:|",
        ]
        for e in costs:
            c = ideal[e.scene]
            lines.append(
                f"| {e.scene} | `{e.effect}` | {e.events:,} | {e.wall.median:.3f} | {e.wall.median - c.sim.median:+.3f} | "
                f"{c.px / e.wall.median / 1e6:.1f} | {e.events / e.wall.median / 1e6:.2f} |"
            )
        lines.append("")
    lines.append(END)
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--write", metavar="FILE.md", help="replace the simulator section of this Markdown file")
    parser.add_argument("--repeat", type=int, default=5, metavar="N", help="timed runs per measurement (default 5)")
    args = parser.parse_args(argv)
    if args.repeat < 1:
        parser.error("--repeat must be at least 1")

    effects = {k: v for k, v in NOISE.items() if k in EFFECTS}
    missing = [k for k in NOISE if k not in EFFECTS]
    if missing:
        print(f"bench: effects not available, left out of the noisy runs: {', '.join(missing)}", file=sys.stderr)

    video_note = ensure_video()
    print(f"bench: {video_note}", file=sys.stderr)

    def traffic() -> Scene:
        return load_scene("traffic")

    def video() -> Scene:
        return load_scene(str(VIDEO))

    cases, costs = [], []
    for name, load in (("traffic", traffic), ("video", video)):
        frames = list(tqdm(load().source.frames(), desc=f"{name}: frames to memory", unit="frame", leave=False, file=sys.stderr))
        for noisy in (False, True):
            cases.append(run_case(name, load, frames, noisy, effects, args.repeat))
        if len(effects) > 1:
            costs += effect_costs(name, load, frames, effects, args.repeat)

    text = report(cases, costs, video_note, args.repeat, effects, missing)
    print(text, end="")
    if args.write:
        from evclust.stamps import stamp_for

        common.write_section(Path(args.write), text, START, END, stamp=stamp_for("BENCHMARKS:simulator"))
        print(f"bench: wrote {args.write}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
