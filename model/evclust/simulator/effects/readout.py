"""Readout limit: events queue in a FIFO read out at a fixed rate; a full FIFO drops them."""

from __future__ import annotations

from typing import Annotated, Literal

import numpy as np
from pydantic import Field

from evclust.events import sort_events
from evclust.jit import njit
from evclust.simulator.effects.base import Effect, EffectParams, round_us


@njit(cache=True, nogil=True)
def _fifo(t, depth, service_us):
    """Serve events (sorted by arrival time t) through a FIFO of `depth` places, one every service_us.

    The FIFO holds every event not yet read out, including the one being read. An event leaves at
    departure = max(its arrival, the previous departure) + service_us, and its place is free from
    that instant on. An event that arrives when all `depth` places are taken is dropped.
    Returns (kept mask, departure time in µs of each kept event).
    """
    n = t.size
    keep = np.zeros(n, np.bool_)
    departure = np.zeros(n, np.float64)
    queue = np.empty(depth, np.float64)  # ring buffer of the departure times of queued events
    head = 0
    count = 0
    last = -np.inf
    for i in range(n):
        ti = float(t[i])
        while count > 0 and queue[head] <= ti:
            head += 1
            if head == depth:
                head = 0
            count -= 1
        if count == depth:
            continue
        d = max(ti, last) + service_us
        tail = head + count
        if tail >= depth:
            tail -= depth
        queue[tail] = d
        count += 1
        last = d
        keep[i] = True
        departure[i] = d
    return keep, departure


class ReadoutLimit(Effect):
    """A FIFO of fifo_depth events read out at rate_ev_s: events that find it full are dropped."""

    name = "readout_limit"
    stage = "stream"

    class Params(EffectParams):
        rate_ev_s: Annotated[float, Field(gt=0)] = 1e6  # readout bandwidth, events per second
        fifo_depth: Annotated[int, Field(ge=1, le=1 << 24)] = 256  # events the FIFO holds, incl. the one being read
        # "arrival": the time stamped before readout (so timestamp_quantisation, which runs before
        # this effect, still holds); "readout": the departure time, as an AER periphery stamps.
        timestamp: Literal["arrival", "readout"] = "arrival"

    def stream(self, events: np.ndarray) -> np.ndarray:
        if events.size == 0:
            return events
        p = self.params
        keep, departure = _fifo(events["t"], p.fifo_depth, 1e6 / p.rate_ev_s)
        out = events[keep]
        if p.timestamp == "readout":
            out["t"] = round_us(departure[keep])
            # Departures are increasing; only when service is under 1 µs can two share a microsecond.
            if out.size > 1 and np.any(out["t"][1:] == out["t"][:-1]):
                out = sort_events(out)
        return out
