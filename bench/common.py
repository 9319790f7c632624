"""What every benchmark shares: one core, the machine's description, and its section of
docs/BENCHMARKS.md. Import this module first: it pins every thread pool to one thread before
numpy, numba and OpenCV load."""

from __future__ import annotations

import os

for _var in ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "EVCLUST_THREADS"):
    os.environ[_var] = "1"

import platform  # noqa: E402
import re  # noqa: E402
from pathlib import Path  # noqa: E402

import cv2  # noqa: E402

cv2.setNumThreads(1)

import numba  # noqa: E402
import numpy as np  # noqa: E402

from evclust.documents import write_section  # noqa: E402, F401  (the benchmarks' section writer)


def machine() -> list[str]:
    info = Path("/proc/cpuinfo").read_text() if Path("/proc/cpuinfo").exists() else ""
    model = re.search(r"^model name\s*:\s*(.+)$", info, re.M)
    mhz = re.search(r"^cpu MHz\s*:\s*(.+)$", info, re.M)
    cache = re.search(r"^cache size\s*:\s*(.+)$", info, re.M)
    flags = re.search(r"^flags\s*:\s*(.+)$", info, re.M)
    simd = [f for f in ("avx2", "avx512f", "fma") if flags and f in flags.group(1).split()]
    mem = re.search(r"^MemTotal:\s*(\d+) kB", Path("/proc/meminfo").read_text(), re.M) if Path("/proc/meminfo").exists() else None
    cpu = model.group(1).strip() if model else (platform.processor() or "unknown CPU")
    extra = ", ".join(
        x for x in (f"{float(mhz.group(1)):.0f} MHz" if mhz else "", f"cache {cache.group(1)}" if cache else "", "/".join(simd)) if x
    )
    load = ", ".join(f"{v:.2f}" for v in os.getloadavg())
    return [
        f"- CPU: {cpu} ({extra}); {os.cpu_count()} logical cores; memory {int(mem.group(1)) / 2**20:.1f} GiB" if mem else f"- CPU: {cpu}",
        f"- OS: {platform.platform()}; load average at start {load}",
        f"- Python {platform.python_version()}, numpy {np.__version__}, numba {numba.__version__}, OpenCV {cv2.__version__}",
        f"- One core: NUMBA_NUM_THREADS=OMP_NUM_THREADS=OPENBLAS_NUM_THREADS=MKL_NUM_THREADS=EVCLUST_THREADS=1, cv2.setNumThreads(1); numba threads {numba.config.NUMBA_NUM_THREADS}, OpenCV threads {cv2.getNumThreads()}",
    ]
