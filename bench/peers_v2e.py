#!/usr/bin/env python
"""v2e's event emulator on a folder of PNG frames; run by bench/peers.py in v2e's own environment
(build/peers/v2e-venv: CPU torch). Prints {"wall_s", "events", "frames"} as JSON; the wall time
covers decoding and emulating, not importing torch.

    PYTHONPATH=V2E_SOURCE python bench/peers_v2e.py FRAMES_DIR FPS
"""

import json
import sys
import time
from pathlib import Path

import cv2
import numpy as np


def main() -> int:
    folder, fps = Path(sys.argv[1]), float(sys.argv[2])  # v2e's source checkout on PYTHONPATH (bench/peers.py)
    import torch
    from v2ecore.emulator import EventEmulator

    torch.set_num_threads(1)  # as esim_py: one core (v2e's CPU path is torch's, which could use more)
    paths = sorted(folder.glob("*.png"))
    # Ideal sensor: no threshold spread, leak, shot noise, photoreceptor low-pass or refractory period.
    emulator = EventEmulator(pos_thres=0.2, neg_thres=0.2, sigma_thres=0.0, cutoff_hz=0.0, leak_rate_hz=0.0,
                             shot_noise_rate_hz=0.0, refractory_period_s=0.0, device="cpu")  # fmt: skip
    start = time.perf_counter()
    events = 0
    for k, path in enumerate(paths):
        frame = cv2.imread(str(path), cv2.IMREAD_GRAYSCALE).astype(np.float32)
        out = emulator.generate_events(frame, k / fps)
        events += 0 if out is None else len(out)
    print(json.dumps({"wall_s": time.perf_counter() - start, "events": events, "frames": len(paths)}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
