"""What the hardware costs: the RTL's co-simulation time per event, and for each hardware
configuration (N, the filters' word lengths, shift-only β) its task accuracy (fixed model),
its cycles per event (RTL under Verilator, bit-exact with the model on the scene's events) and
its area (Yosys synth_xilinx)."""

from __future__ import annotations

import atexit
import dataclasses
import queue
import threading

from evclust.clusterer import ClustererParams
from evclust.run import track_events
from evclust.fixed.formats import build_formats
from evclust.fixed.header import verilog_header
from evclust.report.budget import scene_scores
from evclust.rtl.stream import run_stream


@dataclasses.dataclass(frozen=True)
class HardwareConfig:
    label: str
    slug: str  # build/synth folder name
    n_clusters: int
    formats: dict  # build_formats's options

    def params(self, params: ClustererParams) -> ClustererParams:
        return params.model_copy(update={"n_clusters": self.n_clusters})

    def table(self, params: ClustererParams, meta):
        return build_formats(self.params(params), meta.width, meta.height, params.t_frame_us or meta.t_frame_us, **self.formats)


DEFAULT_LABEL = "N=16 (default)"
# N at the default formats; then, at N = 16, the word-length knob (the guard bits every α filter's
# state keeps beyond 1/β; the default is DEAD_BAND_BITS) and shift-only β.
CONFIGS = (
    HardwareConfig("N=4", "n4", 4, {}),
    HardwareConfig("N=8", "n8", 8, {}),
    HardwareConfig(DEFAULT_LABEL, "n16", 16, {}),
    HardwareConfig("N=16, 3 guard bits", "n16-guard3", 16, {"dead_band_bits": 3}),
    HardwareConfig("N=16, 0 guard bits", "n16-guard0", 16, {"dead_band_bits": 0}),
    HardwareConfig("N=16, shift-only β", "n16-shift", 16, {"beta_shift_only": True}),
)
SHIFT_LABEL = CONFIGS[-1].label
# `--quick` leaves out the word-length knob and N = 8 (three more Verilator builds and fixed-model
# runs); N = 4 and 16 and shift-only β stay, which the quick report's checks need.
QUICK_CONFIGS = tuple(c for c in CONFIGS if "guard" not in c.slug and c.slug != "n8")


# Each slot's α-filtered words, whose fractions the guard bits set: P and P_prev, R, V_MCM and
# its norm, V_RI, the colour (the background is one global, not per slot).
FILTERED_SLOT_WORDS = {"centre": 4, "half_size": 2, "v_mcm": 2, "mcm_norm": 1, "v_int": 2, "colour": 3}


def filtered_slot_bits(table) -> int:
    """Bits of one slot's α-filtered words (layout.SLOT_COLUMNS' PX, PY, PPX, PPY, RX, ...)."""
    return sum(copies * table[name].word_bits for name, copies in FILTERED_SLOT_WORDS.items())


class SynthesisQueue:
    """Yosys runs in background threads while the report's other sections run: one worker at
    first (the other core runs the models), a second once nothing else is left to run. A report
    that ends in an error or Ctrl-C stops its Yosys processes."""

    def __init__(self, jobs: list[tuple[str, str]], heartbeat=None):
        """`jobs`: (label, header) pairs, run in this order."""
        from evclust.rtl.synth import rtl_snapshot, synthesise, yosys_command

        yosys_command()  # no Yosys: fail now, not after the other sections
        self._synthesise, self._heartbeat, self._snapshot = synthesise, heartbeat, rtl_snapshot()
        self._jobs: queue.Queue = queue.Queue()
        for job in jobs:
            self._jobs.put(job)
        self.results: dict[str, dict | Exception] = {}
        self._threads: list[threading.Thread] = []
        self._processes: list = []
        atexit.register(self._stop)
        self.add_worker()

    def add_worker(self) -> None:
        thread = threading.Thread(target=self._work, daemon=True)
        thread.start()
        self._threads.append(thread)

    def _work(self) -> None:
        while True:
            try:
                label, header = self._jobs.get_nowait()
            except queue.Empty:
                return
            try:
                self.results[label] = self._synthesise(
                    header, label, heartbeat=self._heartbeat, snapshot=self._snapshot, on_start=self._processes.append
                )
            except Exception as exc:  # reported in its row as a failure; the queue goes on
                self.results[label] = exc

    def _stop(self) -> None:
        for process in self._processes:
            if process.poll() is None:
                process.kill()

    def wait(self) -> dict[str, dict | Exception]:
        for thread in self._threads:
            thread.join()
        atexit.unregister(self._stop)
        return self.results


def start_synthesis(params: ClustererParams, meta, heartbeat=None) -> SynthesisQueue:
    longest_first = sorted(CONFIGS, key=lambda c: -c.n_clusters)
    return SynthesisQueue([(c.slug, verilog_header(c.table(params, meta))) for c in longest_first], heartbeat)


@dataclasses.dataclass
class ConfigResult:
    config: HardwareConfig
    filtered_slot_bits: int
    scores: dict  # scene: every task metric of the fixed model
    rtl: object | None  # RtlRun on the cycle-count prefix (None when not run)
    area: dict | Exception | None  # Yosys figures, its failure, or None when not synthesised


def evaluate_configs(scenes: dict, rtl_events: int, configs=CONFIGS, progress=None) -> list[ConfigResult]:
    """Each configuration's task accuracy on every scene (fixed model, whole scene) and its
    cycles per event: the first `rtl_events` of the first scene through the RTL under
    Verilator, checked bit for bit against the model."""
    out = []
    first = next(iter(scenes))
    for config in configs:
        scores = {}
        for name, (meta, events, params, _origin, truth) in scenes.items():
            run = track_events(events, meta, config.params(params), model="fixed", **config.formats)
            scores[name] = scene_scores(run, truth)
        meta, events, params, _, _ = scenes[first]
        t_frame = params.t_frame_us or meta.t_frame_us
        rtl = run_stream("verilator", events[:rtl_events], config.params(params), meta.width, meta.height, t_frame, **config.formats)
        out.append(ConfigResult(config, filtered_slot_bits(config.table(params, meta)), scores, rtl, None))
        if progress:
            progress()
    return out


def rtl_runtime(meta, events, params, counts: dict[str, int]) -> dict:
    """{simulator: RtlRun} for the first counts[simulator] events under each simulator; the
    build happens before, outside the timing, on a short stream."""
    t_frame = params.t_frame_us or meta.t_frame_us
    runs = {}
    for sim, count in counts.items():
        run_stream(sim, events[:200], params, meta.width, meta.height, t_frame)
        runs[sim] = run_stream(sim, events[:count], params, meta.width, meta.height, t_frame)
    return runs
