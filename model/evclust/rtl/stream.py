"""A stream of events through the RTL and the fixed model side by side, compared bit for bit:
the RTL as a clusterer whose output is proven equal to the fixed model's, with its cycles and
its co-simulation time."""

from __future__ import annotations

import dataclasses
import hashlib
import time

import numpy as np

from evclust.clusterer import ClustererParams
from evclust.errors import atomic_output
from evclust.rtl.cosim import run
from evclust.paths import BUILD
from evclust.rtl.sources import params_header, require_rtl


@dataclasses.dataclass(frozen=True)
class RtlRun:
    simulator: str
    events: int
    records: int
    cycles: int  # core clock cycles, counted by the harness
    filter_cycles: int  # of which filter sweeps (filter_active high)
    filter_steps: int
    stream_s: float  # time in the stream: loading batches, simulating, reading records back
    total_s: float  # the whole co-simulation: simulator start, the model and the comparison too
    object_busy_cycles: int = 0  # cycles the object unit worked on a step
    object_wait_cycles: int = 0  # filter-step cycles the core waited for the object unit
    # Clock edges from the one that takes an event to the one that writes its slot.
    latency_min: int = 0
    latency_max: int = 0
    latency_sum: int = 0

    @property
    def latency_mean(self) -> float:
        return self.latency_sum / self.events

    @property
    def cycles_per_event(self) -> float:
        return self.cycles / self.events


def run_stream(
    sim: str, events: np.ndarray, params: ClustererParams, width: int, height: int, t_frame_us: float,
    gap: int = 0, stall: int = 0, **formats,
) -> RtlRun:  # fmt: skip
    """Run `events` through the RTL built for these parameters (and `formats`, the options of
    `build_formats`) under `sim`, checking every record and trace word against the fixed model.
    A mismatch raises AssertionError naming the first differing field."""
    require_rtl()
    header = params_header(params, width, height, t_frame_us, **formats)
    data = np.ascontiguousarray(events)
    digest = hashlib.sha256(data.tobytes()).hexdigest()[:16]
    path = BUILD / "streams" / f"events-{digest}.npy"
    if not path.exists():
        path.parent.mkdir(parents=True, exist_ok=True)
        with atomic_output(path) as tmp:
            with open(tmp, "wb") as f:
                np.save(f, data)
    config = {
        "parameters": params.model_dump(mode="json", exclude_none=True), "n_clusters": params.n_clusters,
        "width": width, "height": height, "t_frame_us": t_frame_us, "seed": 1, "count": int(data.size),
        "gap": gap, "stall": stall, "events": str(path), "formats": formats,
    }  # fmt: skip
    start = time.perf_counter()
    result = run(sim, header, "model_in_the_loop", config)
    total = time.perf_counter() - start
    return RtlRun(sim, result["events"], result["records"], result["cycles"], result["filter_cycles"], result["filter_steps"], result["wall_s"], total,
                  result.get("object_busy_cycles", 0), result.get("object_wait_cycles", 0),
                  result.get("latency_min") or 0, result.get("latency_max", 0), result.get("latency_sum", 0))  # fmt: skip
