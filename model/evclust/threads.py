"""How many threads evclust's own parallel work may use: EVCLUST_THREADS, else every core.

One setting for every pool (the simulator's row bands, a folder's image decoders), so that
EVCLUST_THREADS=1 really is one thread, as a one-core benchmark needs."""

from __future__ import annotations

import os


def worker_threads() -> int:
    return int(os.environ.get("EVCLUST_THREADS", 0)) or os.cpu_count() or 1
