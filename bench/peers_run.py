#!/usr/bin/env python
"""One simulator, one timed run, in a process of its own; run by bench/peers.py, so that each side
gets the same treatment and its own thread settings.

    python bench/peers_run.py {evclust,esim_py,v2e} FRAMES_DIR FPS CORES

The process is pinned to the first CORES cores, and every thread pool it may start (numba, OpenMP,
BLAS, OpenCV, torch, evclust's bands and decoders) is sized to CORES, before any of them loads.
A warm-up on the first frames (numba's cache, torch's start-up, the OS's file cache), then one
timed run that keeps every event in memory in the simulator's own form: evclust's event array,
esim_py's N x 4 matrix, v2e's per-frame arrays joined. Prints {"wall_s", "events", "frames"} as
JSON; imports are not timed. esim_py and evclust run in evclust's environment, v2e in its own
(bench/build_peers.sh), each with its package on PYTHONPATH.
"""

import json
import os
import sys
import time
from pathlib import Path

THRESHOLD = 0.2  # ON and OFF: the ideal sensor of the comparison
WARM_UP_FRAMES = 3


def pin(cores: int) -> None:
    os.sched_setaffinity(0, set(sorted(os.sched_getaffinity(0))[:cores]))
    for var in ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "EVCLUST_THREADS",
                "OPENCV_FOR_THREADS_NUM"):  # fmt: skip
        os.environ[var] = str(cores)


def evclust(paths: list[Path], fps: float):
    """The ideal sensor is the default one; detector L = ln(Y + 1), Y in 0..255."""
    from evclust.scenes import load_scene
    from evclust.simulator import simulate_scene

    folder = str(paths[0].parent)

    def run(frames: int | None):
        return simulate_scene(load_scene(folder, fps=fps, max_frames=frames)).events

    return run


def esim_py(paths: list[Path], fps: float):
    """log_eps = 1/255 with I in 0..1 gives ln(Y + 1) up to a constant: the same events as evclust."""
    import esim_py

    names = [str(p) for p in paths]
    stamps = [k / fps for k in range(len(paths))]

    def run(frames: int | None):
        n = frames or len(names)
        simulator = esim_py.EventSimulator(THRESHOLD, THRESHOLD, 0.0, 1.0 / 255.0, True)
        return simulator.generateFromStampedImageSequence(names[:n], stamps[:n])

    return run


def v2e(paths: list[Path], fps: float):
    """Ideal sensor: no threshold spread, leak, shot noise, photoreceptor low-pass or refractory
    period. v2e has no frame reader of its own for this: frames are read as esim_py reads them."""
    import cv2
    import numpy as np
    import torch
    from v2ecore.emulator import EventEmulator

    torch.set_num_threads(len(os.sched_getaffinity(0)))
    cv2.setNumThreads(len(os.sched_getaffinity(0)))

    def run(frames: int | None):
        emulator = EventEmulator(pos_thres=THRESHOLD, neg_thres=THRESHOLD, sigma_thres=0.0, cutoff_hz=0.0,
                                 leak_rate_hz=0.0, shot_noise_rate_hz=0.0, refractory_period_s=0.0, device="cpu")  # fmt: skip
        out = []
        for k, path in enumerate(paths[: frames or len(paths)]):
            frame = cv2.imread(str(path), cv2.IMREAD_GRAYSCALE).astype(np.float32)
            events = emulator.generate_events(frame, k / fps)
            if events is not None:
                out.append(events)
        return np.concatenate(out) if out else np.empty((0, 4))

    return run


SIMULATORS = {"evclust": evclust, "esim_py": esim_py, "v2e": v2e}


def main() -> int:
    name, folder, fps, cores = sys.argv[1], Path(sys.argv[2]), float(sys.argv[3]), int(sys.argv[4])
    pin(cores)
    paths = sorted(folder.iterdir())
    run = SIMULATORS[name](paths, fps)
    run(WARM_UP_FRAMES)
    start = time.perf_counter()
    events = run(None)
    wall = time.perf_counter() - start
    print(json.dumps({"wall_s": wall, "events": len(events), "frames": len(paths)}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
