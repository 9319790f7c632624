"""How many threads evclust's own parallel work may use: EVCLUST_THREADS, else every core; and
the background threads an interrupted run must stop before the process exits.

One setting for every pool (the simulator's row bands, a folder's image decoders), so that
EVCLUST_THREADS=1 really is one thread, as a one-core benchmark needs."""

from __future__ import annotations

import os
import threading
from collections.abc import Callable

_HALTS: set[Callable[[], None]] = set()
_LOCK = threading.Lock()


def worker_threads() -> int:
    return int(os.environ.get("EVCLUST_THREADS", 0)) or os.cpu_count() or 1


def stopped_on_interrupt(halt: Callable[[], None]) -> Callable[[], None]:
    """Register `halt`, which stops a background thread and returns once it has ended, to be
    called by `stop_background_threads`; returns the function that unregisters it."""
    with _LOCK:
        _HALTS.add(halt)
    return lambda: _HALTS.discard(halt)


def stop_background_threads() -> None:
    """Stop every registered background thread and wait for each: what an interrupted run calls
    before it returns. A daemon thread still inside OpenCV when the interpreter exits brings the
    process down with "terminate called without an active exception" (exit -6, not 130); the
    frame reader of a simulation whose generator is left suspended is one (its own cleanup runs
    only when the generator is closed or collected)."""
    with _LOCK:
        halts = list(_HALTS)
    for halt in halts:
        halt()
