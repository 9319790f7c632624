"""Driving the fixed model: state in the shared layout as raw integers, the loop compiled."""

from __future__ import annotations

import numpy as np

from evclust.clusterer.layout import BG_CB, BG_CR, BG_Y, PENDING_COLUMNS, RECORD_COLUMNS, SLOT_COLUMNS, STEP, run_stats, support_shape
from evclust.clusterer.params import ClustererParams
from evclust.events.format import loop_columns
from evclust.fixed import fixed_model
from evclust.fixed.constants import constant_vector
from evclust.fixed.formats import FormatTable, build_formats, decay_table
from evclust.fixed.registers import runtime_table


# The format each instrumented signal (fixed_model.SIGNALS) is measured in.
SIGNAL_FORMATS = {
    "centre": "centre", "half_size": "half_size", "activity": "activity", "v_mcm": "v_mcm", "mcm_norm": "mcm_norm",
    "v_int": "v_int", "colour": "colour", "background": "background", "gamma": "gamma",
    "events_in_interval": "events_in_interval", "hist": "hist", "centre_step": "centre_step", "speed_sq": "speed_sq",
    "mcm_step": "v_mcm", "size_target": "size_target",
}  # fmt: skip


def _instrumentation(ranges: np.ndarray | None, trace: np.ndarray | None) -> tuple:
    """(ranges, trace) for the loop: both None for a plain run (its own, fast compiled loop);
    otherwise both arrays, the one not asked for empty, so that a traced run and a range-
    instrumented one share the other compiled loop (fixed_model._store)."""
    if ranges is None and trace is None:
        return None, None
    empty = lambda *shape: np.zeros(shape, dtype=np.int64)
    return (empty(0, 2) if ranges is None else ranges), (empty(0) if trace is None else trace)


class FixedClusterer:
    """The bit-accurate model: the same interface as the float one, integer arithmetic inside."""

    model = "fixed"

    def __init__(
        self, params: ClustererParams, width: int, height: int, t_frame_us: float, has_colour: bool = True,
        ranges: bool = False, build: FormatTable | None = None, **format_options,
    ):  # fmt: skip
        self.params = params = params.resolved(t_frame_us)
        # format_options: build_formats's knobs (beta_shift_only: every β a power of two, so each
        # α filter multiplies by shifting; dead_band_bits: the filters' guard bits, the formats
        # table's word-length knob; activity_bits, interval_count_bits: narrower event counters).
        # build: the formats of an RTL built for other parameters, which these are written into
        # at run time (fixed/registers.py): that build's formats with these parameters' constants.
        if build is not None:
            self.table = runtime_table(build, params, t_frame_us)
        else:
            self.table = build_formats(params, width, height, t_frame_us, **format_options)
        self.k = constant_vector(self.table, params, has_colour)
        self.decay = np.asarray(decay_table(self.table), dtype=np.int64)
        self.gains = np.asarray(self.table.warmup_gains, dtype=np.int64)
        self.palette = np.array(
            [[self.table.constants[f"palette_{j}_{c}"].raw for c in ("y", "cb", "cr")] for j in range(len(params.palette))], dtype=np.int64
        )
        self.background_mask = params.background_mask()
        self.slots = np.zeros((params.n_clusters, len(SLOT_COLUMNS)), dtype=np.int64)
        self.hist = np.zeros((params.n_clusters, len(params.palette)), dtype=np.int64)
        self.globals = np.zeros(fixed_model.N_GLOBALS, dtype=np.int64)
        fb = self.table["background"].frac_bits
        bg = params.background if params.background is not None else (128.0, 128.0, 128.0)
        self.globals[[BG_Y, BG_CB, BG_CR]] = [int(round(v * 2**fb)) for v in bg]
        self.support = np.zeros(support_shape(width, height, params.support_cell_bits), dtype=np.int64)
        self.seen = np.zeros(self.support.shape, dtype=np.bool_)
        self.delay_line = np.zeros((params.update_delay + 1, len(PENDING_COLUMNS)), dtype=np.int64)  # the events in flight
        self.held = np.zeros((params.n_clusters, RECORD_COLUMNS))  # the open filter step's records
        self.inv_ww = np.zeros(len(params.palette), dtype=np.int64)
        fixed_model.refresh_mixing(self.globals, self.palette, self.inv_ww, self.k)
        self.overflow = np.zeros(len(fixed_model.SIGNALS), dtype=np.int64)
        # Range instrumentation on request only (the loop skips it when given no rows).
        self.ranges = None
        if ranges:
            self.ranges = np.zeros((len(fixed_model.SIGNALS), 2), dtype=np.int64)
            self.ranges[:, 0], self.ranges[:, 1] = np.iinfo(np.int64).max, np.iinfo(np.int64).min
        self.steps = np.zeros(0, dtype=np.int64)  # the times of the filter steps the last feed completed

    def feed(self, events: np.ndarray, trace: np.ndarray | None = None) -> np.ndarray:
        """Records of the filter steps these events complete; with `trace` (int64, one per event),
        each event's action << 16 | slot (fixed_model.TRACE_*)."""
        every = self.params.filter_every
        # (+ 2: a step opened in the last feed may close in this one)
        out = np.empty(((events.size // every + 2) * self.params.n_clusters, RECORD_COLUMNS))
        steps = np.empty(events.size // every + 2, dtype=np.int64)
        first = self.globals[STEP]
        n = fixed_model.run_events(
            self.slots, self.hist, self.globals, self.k, self.decay, self.gains, self.palette, self.inv_ww, self.background_mask,
            self.support, self.seen, self.delay_line, self.held, *loop_columns(events), out, steps,
            self.overflow, *_instrumentation(self.ranges, trace),
        )  # fmt: skip
        self.steps = steps[: int(self.globals[STEP] - first)]
        return out[:n]

    def object_layer(self):
        """The object layer that follows this model: bit-accurate, in this model's formats."""
        from evclust.fixed.objects import FixedObjects

        return FixedObjects(self.table, self.params)

    def stats(self) -> dict:
        saturations = {name: int(c) for name, c in zip(fixed_model.SIGNALS, self.overflow) if c}
        return run_stats(self.globals) | {"saturations": saturations}

    def range_report(self) -> list[tuple[str, float, float, int]]:
        """(signal, min seen, max seen, saturations) in real units, for `--ranges`."""
        rows = []
        if self.ranges is None:
            return rows
        for j, name in enumerate(fixed_model.SIGNALS):
            lo, hi = self.ranges[j]
            if lo > hi:
                continue
            scale = 2.0 ** -self.table[SIGNAL_FORMATS[name]].frac_bits
            rows.append((name, lo * scale, hi * scale, int(self.overflow[j])))
        return rows
