#!/usr/bin/env python
"""evclust's simulator beside ESIM's (esim_py) and v2e's, on the same frames, paired round by round.

    make bench-peers     # builds the peers into build/peers/ (bench/build_peers.sh), then runs this

The three read the same folder of frames and simulate an ideal sensor at the same contrast
threshold, 0.2 ON and OFF, no refractory period. evclust's log detector is L = ln(Y + 1) with Y in
0..255; esim_py's is ln(I + log_eps) with I in 0..1, so log_eps = 1/255 gives the same L up to a
constant and the same events. evclust also measures each event's colour; the others do not.

Fair terms (bench/peers_run.py): each run is a process of its own, pinned to its cores with every
thread pool sized to match, warmed up, then timed around one call that keeps all events in memory
in the simulator's own form. The frames are uncompressed BMP: decoding a PNG costs each simulator
the same, and on a noisy texture it costs more than simulating (4.2 ms for a 480x270 frame here),
so PNG would time zlib. A round runs evclust on one core, esim_py and v2e on one core (neither has
threads of its own), and evclust on every core, in an order that rotates from round to round; each
ratio is taken within a round, and the table gives the median ratio and its range over the rounds.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

import cv2

ROOT = Path(__file__).resolve().parents[1]
PEERS = ROOT / "build" / "peers"
ESIM_PATH = PEERS / "esim_py"
V2E_PYTHON = PEERS / "v2e-venv" / "bin" / "python"
V2E_SOURCE = PEERS / "src" / "v2e"
START, END = "<!-- bench:peers:start -->", "<!-- bench:peers:end -->"
TARGETS = {"esim_py": 3.0, "v2e": 10.0}  # evclust's speed-up on one core against one core


def frame_folder(video: Path, name: str) -> tuple[Path, int, int, int, float]:
    """The video's frames as uncompressed BMPs in build/peers/frames/<name>/ (written once)."""
    folder = PEERS / "frames" / name
    capture = cv2.VideoCapture(str(video))
    fps = capture.get(cv2.CAP_PROP_FPS) or 30.0
    if not folder.exists() or not any(folder.glob("*.bmp")):
        folder.mkdir(parents=True, exist_ok=True)
        k = 0
        while True:
            ok, frame = capture.read()
            if not ok:
                break
            cv2.imwrite(str(folder / f"{k:05d}.bmp"), frame)
            k += 1
    capture.release()
    paths = sorted(folder.glob("*.bmp"))
    h, w = cv2.imread(str(paths[0])).shape[:2]
    return folder, len(paths), w, h, fps


def run_once(simulator: str, folder: Path, fps: float, cores: int) -> dict:
    python, path = sys.executable, os.environ.get("PYTHONPATH", "")
    if simulator == "esim_py":
        path = f"{ESIM_PATH}:{path}"
    elif simulator == "v2e":
        python, path = str(V2E_PYTHON), str(V2E_SOURCE)  # v2e runs from its source checkout
    done = subprocess.run([python, str(ROOT / "bench" / "peers_run.py"), simulator, str(folder), str(fps), str(cores)],
                          capture_output=True, text=True, env=os.environ | {"PYTHONPATH": path})  # fmt: skip
    if done.returncode:
        raise SystemExit(f"{simulator} failed on {folder.name}:\n{done.stderr.strip()[-2000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def measure(videos: dict[str, Path], rounds: int, cores: int) -> list[str]:
    runs = [("evclust", 1), ("esim_py", 1)] + ([("v2e", 1)] if V2E_PYTHON.exists() else []) + [("evclust", cores)]
    rows = [
        "| video | frames | simulator | cores | frames/s | Mpixel-frames/s | Mevents/s | events | evclust's speed-up, one core each: median (range) | target |",
        "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for name, video in videos.items():
        folder, n, w, h, fps = frame_folder(video, name)
        walls: dict[tuple[str, int], list[float]] = {run: [] for run in runs}
        counts = {}
        for r in range(rounds):
            for run in runs[r % len(runs) :] + runs[: r % len(runs)]:  # the order rotates
                result = run_once(*run[:1], folder, fps, run[1])
                walls[run].append(result["wall_s"])
                counts[run] = result["events"]
                print(f"{name} round {r + 1}: {run[0]} on {run[1]} core(s) {result['wall_s']:.2f} s", flush=True)
        for run in runs:
            wall = statistics.median(walls[run])
            simulator, k = run
            ratio = target = ""
            if simulator != "evclust":
                paired = sorted(a / b for a, b in zip(walls[run], walls[("evclust", 1)]))
                ratio = f"**{statistics.median(paired):.2f}×** ({paired[0]:.2f}–{paired[-1]:.2f})"
                target = f"≥ {TARGETS[simulator]:g}× {'met' if statistics.median(paired) >= TARGETS[simulator] else '**missed**'}"
            elif k > 1:
                paired = sorted(a / b for a, b in zip(walls[("evclust", 1)], walls[run]))
                ratio = f"{statistics.median(paired):.2f}× its one-core run ({paired[0]:.2f}–{paired[-1]:.2f})"
            rows.append(
                f"| {name} ({w}×{h}) | {n} | {simulator} | {k} | {n / wall:.1f} | {w * h * n / wall / 1e6:.1f} "
                f"| {counts[run] / wall / 1e6:.2f} | {counts[run]:,} | {ratio} | {target} |"
            )
            print(rows[-1], flush=True)
    return rows


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--write", metavar="MD")
    args = parser.parse_args()
    if not any(ESIM_PATH.glob("esim_py*.so")):
        raise SystemExit(f"esim_py is not built: `make bench-peers` builds it in {ESIM_PATH} (bench/build_peers.sh)")
    from simulator import VIDEO as PAN_DISKS, ensure_video  # bench/simulator.py: a script's folder is on its path

    ensure_video()
    videos = {"pan_disks": PAN_DISKS, "vtest": ROOT / "build" / "video" / "vtest.avi"}
    videos = {k: v for k, v in videos.items() if v.exists()}
    cores = len(os.sched_getaffinity(0))
    rows = measure(videos, args.rounds, cores)
    cpu = next(
        (line.split(":", 1)[1].strip() for line in Path("/proc/cpuinfo").read_text().splitlines() if line.startswith("model name")), "?"
    )
    load = ", ".join(f"{v:.2f}" for v in os.getloadavg())
    section = "\n".join([
        START, "## The simulator beside ESIM (esim_py) and v2e", "",
        f"Measured {datetime.date.today()} by `make bench-peers` (`bench/peers.py`, each run by `bench/peers_run.py`): "
        f"{cpu}, {os.cpu_count()} cores, load average {load} at the end. {args.rounds} rounds; in each, evclust on one core, "
        "esim_py and v2e on one core, and evclust on every core, in a rotating order, each in a process of its own pinned "
        "to its cores with every thread pool sized to match, warmed up, then timed around one call that keeps every event "
        "in memory in its own form (evclust's event array, esim_py's N×4 matrix, v2e's per-frame arrays joined); imports "
        "are not timed. Ratios are paired within a round: the median and the range over the rounds. Same uncompressed BMP "
        "frames for all, ideal sensor, threshold 0.2 ON and OFF; evclust also measures each event's colour. esim_py is "
        "built from uzh-rpg/rpg_vid2e (esim_py/) against Debian's OpenCV, Eigen and Boost; v2e's EventEmulator "
        "(SensorsINI/v2e) runs on Debian's CPU-only torch 1.13 with no frame interpolation and no noise, and always applies "
        "its lin-log curve, hence its higher event counts.",
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
