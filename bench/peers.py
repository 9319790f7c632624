#!/usr/bin/env python
"""evclust's simulator beside ESIM's (esim_py) and v2e's, alternately, on the same frames.

    make bench-peers     # builds esim_py into build/peers/, then runs this

Both read the same folder of PNG frames (each frame decoded by the simulator under test, as
esim_py's `generateFromStampedImageSequence` does) and simulate an ideal sensor at the same
contrast threshold, 0.2 ON and OFF, no refractory period. evclust's log detector is
L = ln(Y + 1) with Y in 0..255; esim_py's is ln(I + log_eps) with I in 0..1, so log_eps = 1/255
gives the same L up to a constant and the same events. evclust also measures each event's colour
(TFS); esim_py does not. Runs alternate (evclust, esim_py, evclust, ...) and the best of --repeat
is kept, so machine noise hits both alike; evclust runs on all cores (bands of rows), esim_py on
one (it has no threads).
"""

from __future__ import annotations

import argparse
import datetime
import os
import sys
import time
from pathlib import Path

import cv2

ROOT = Path(__file__).resolve().parents[1]
PEERS = ROOT / "build" / "peers"
START, END = "<!-- bench:peers:start -->", "<!-- bench:peers:end -->"
THRESHOLD = 0.2
TARGET_RATIO = 3.0


def frame_folder(video: Path, name: str) -> tuple[Path, int, int, int, float]:
    """The video's frames as lossless PNGs in build/peers/frames/<name>/ (written once)."""
    folder = PEERS / "frames" / name
    capture = cv2.VideoCapture(str(video))
    fps = capture.get(cv2.CAP_PROP_FPS) or 30.0
    if not folder.exists() or not any(folder.iterdir()):
        folder.mkdir(parents=True, exist_ok=True)
        k = 0
        while True:
            ok, frame = capture.read()
            if not ok:
                break
            cv2.imwrite(str(folder / f"{k:05d}.png"), frame)
            k += 1
    capture.release()
    paths = sorted(folder.glob("*.png"))
    h, w = cv2.imread(str(paths[0])).shape[:2]
    return folder, len(paths), w, h, fps


def run_evclust(folder: Path, fps: float) -> int:
    from evclust.scenes import load_scene
    from evclust.simulator import stream_scene

    return sum(chunk.size for chunk in stream_scene(load_scene(str(folder), fps=fps)))


def run_esim(folder: Path, fps: float) -> int:
    import esim_py

    paths = [str(p) for p in sorted(folder.glob("*.png"))]
    simulator = esim_py.EventSimulator(THRESHOLD, THRESHOLD, 0.0, 1.0 / 255.0, True)
    return int(simulator.generateFromStampedImageSequence(paths, [k / fps for k in range(len(paths))]).shape[0])


V2E_PYTHON = PEERS / "v2e-venv" / "bin" / "python"
V2E_SOURCE = PEERS / "src" / "v2e"


def run_v2e(folder: Path, fps: float) -> tuple[int, float]:
    """v2e in its own environment; its own timing, so torch's import is not counted."""
    import json
    import subprocess

    env = os.environ | {"PYTHONPATH": str(V2E_SOURCE)}  # v2e runs from its source checkout
    done = subprocess.run([str(V2E_PYTHON), str(ROOT / "bench" / "peers_v2e.py"), str(folder), str(fps)],
                          capture_output=True, text=True, check=True, env=env)  # fmt: skip
    result = json.loads(done.stdout.strip().splitlines()[-1])
    return result["events"], result["wall_s"]


def measure(videos: dict[str, Path], repeat: int) -> list[str]:
    rows = [
        "| video | frames | simulator | frames/s | Mpixel-frames/s | Mevents/s | events | evclust's speed-up over it |",
        "|---|---:|---|---:|---:|---:|---:|---:|",
    ]
    for name, video in videos.items():
        folder, n, w, h, fps = frame_folder(video, name)
        peers = ["evclust", "esim_py"] + (["v2e"] if V2E_PYTHON.exists() else [])
        best = {label: float("inf") for label in peers}
        counts = {}
        run_evclust(folder, fps)  # warm-up: numba's cache, the OS's file cache
        for _ in range(repeat):
            for label in peers:
                start = time.perf_counter()
                if label == "v2e":
                    counts[label], wall = run_v2e(folder, fps)
                else:
                    counts[label] = (run_evclust if label == "evclust" else run_esim)(folder, fps)
                    wall = time.perf_counter() - start
                best[label] = min(best[label], wall)
        for label in peers:
            wall = best[label]
            ratio = "" if label == "evclust" else f"**{wall / best['evclust']:.2f}×**"
            rows.append(
                f"| {name} ({w}×{h}) | {n} | {label} | {n / wall:.1f} | {w * h * n / wall / 1e6:.1f} | {counts[label] / wall / 1e6:.2f} "
                f"| {counts[label]:,} | {ratio} |"
            )
            print(rows[-1], flush=True)
    return rows


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--write", metavar="MD")
    args = parser.parse_args()
    try:
        import esim_py  # noqa: F401  (on PYTHONPATH: make bench-peers builds it in build/peers/esim_py)
    except ImportError:
        raise SystemExit(
            f"esim_py is not importable: `make bench-peers` builds it in {PEERS / 'esim_py'} and runs this with it on PYTHONPATH"
        ) from None
    from simulator import VIDEO as PAN_DISKS, ensure_video  # its `common` pins every pool to one thread: undone below

    os.environ["EVCLUST_THREADS"] = str(os.cpu_count())
    cv2.setNumThreads(os.cpu_count())

    ensure_video()
    videos = {"pan_disks": PAN_DISKS, "vtest": ROOT / "build" / "video" / "vtest.avi"}
    videos = {k: v for k, v in videos.items() if v.exists()}
    rows = measure(videos, args.repeat)
    cpu = next(
        (line.split(":", 1)[1].strip() for line in Path("/proc/cpuinfo").read_text().splitlines() if line.startswith("model name")), "?"
    )
    section = "\n".join([
        START, "## The simulator beside ESIM (esim_py)", "",
        f"Measured {datetime.date.today()} by `make bench-peers` (`bench/peers.py`): {cpu}, {os.cpu_count()} cores. "
        f"Both simulators in one process, alternately, best of {args.repeat}, on the same PNG frames, ideal sensor, "
        f"threshold {THRESHOLD} ON and OFF (target: evclust ≥ {TARGET_RATIO:g}× esim_py's frames/s). evclust also measures "
        "each event's colour; it uses both cores (bands of rows), esim_py one. esim_py is built from "
        "uzh-rpg/rpg_vid2e (esim_py/) against Debian's OpenCV, Eigen and Boost. v2e's EventEmulator (SensorsINI/v2e, CPU torch "
        "on one thread, in its own environment, timed inside its process so torch's import is not counted) has no frame "
        "interpolation and no noise here; it always applies its lin-log curve, hence its higher event counts.",
        "", *rows, "", END,
    ])  # fmt: skip
    print(section)
    if args.write:
        from evclust.documents import write_section
        from evclust.stamps import stamp_for

        write_section(Path(args.write), section, START, END, stamp=stamp_for("BENCHMARKS:peers"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
