"""The float clusterer (the compiled loop behind the model interface every clusterer model
implements: feed(events) -> record rows, stats()) and the record rows as track records."""

from __future__ import annotations

import numpy as np

from evclust.clusterer import float_model
from evclust.clusterer.constants import param_vector
from evclust.clusterer.layout import (
    BG_CB, BG_CR, BG_Y, GLOBAL_COLUMNS, PENDING_COLUMNS, RECORD_COLUMNS, SLOT_COLUMNS, STEP, run_stats, support_shape,
)  # fmt: skip
from evclust.clusterer.params import ClustererParams
from evclust.events.format import loop_columns
from evclust.tracks import TRACK_DTYPE


class FloatClusterer:
    """The float64 reference model: state in the shared layout, the loop compiled."""

    model = "float"

    def __init__(self, params: ClustererParams, width: int, height: int, t_frame_us: float, has_colour: bool = True,
                 precision: np.ndarray | None = None):  # fmt: skip
        """`precision` (evclust.fixed.formats.precision_table) rounds each quantisation point to
        its format: the float model then emulates chosen sources of the fixed model's error."""
        self.params = params = params.resolved(t_frame_us)
        self.precision = precision
        self.k = param_vector(params, width, height, t_frame_us, has_colour)
        self.palette = params.palette_ycbcr()
        self.background_mask = params.background_mask()
        self.slots = np.zeros((params.n_clusters, len(SLOT_COLUMNS)))
        self.hist = np.zeros((params.n_clusters, len(params.palette)), dtype=np.int64)
        self.globals = np.zeros(len(GLOBAL_COLUMNS))
        bg = params.background if params.background is not None else (128.0, 128.0, 128.0)
        self.globals[[BG_Y, BG_CB, BG_CR]] = bg
        self.support = np.full(support_shape(width, height, params.support_cell_bits), -np.inf)
        self.delay_line = np.zeros((params.update_delay + 1, len(PENDING_COLUMNS)))  # the events in flight
        self.held = np.zeros((params.n_clusters, RECORD_COLUMNS))  # the open filter step's records
        self.steps = np.zeros(0)  # the times of the filter steps the last feed completed

    def feed(self, events: np.ndarray) -> np.ndarray:
        """Process events; return the (n, RECORD_COLUMNS) float64 records of the filter steps they
        completed (their times, records or not, in `self.steps`)."""
        every = self.params.filter_every
        # (+ 2: a step opened in the last feed may close in this one)
        out = np.empty(((events.size // every + 2) * self.params.n_clusters, RECORD_COLUMNS))
        steps = np.empty(events.size // every + 2)
        first = self.globals[STEP]
        n = float_model.run_events(
            self.slots, self.hist, self.globals, self.k, self.palette, self.background_mask, self.support, self.delay_line,
            self.held, *loop_columns(events), out, steps, self.precision,
        )  # fmt: skip
        self.steps = steps[: int(self.globals[STEP] - first)]
        return out[:n]

    def stats(self) -> dict:
        return run_stats(self.globals)


def rows_to_records(rows: np.ndarray, dtype: np.dtype) -> np.ndarray:
    """The models' float64 record rows (one column per field, in the dtype's order) as records."""
    records = np.zeros(len(rows), dtype)
    for j, name in enumerate(dtype.names):
        column = rows[:, j]
        records[name] = np.rint(column) if np.issubdtype(dtype[name], np.integer) else column
    return records


def records_to_tracks(rows: np.ndarray) -> np.ndarray:
    return rows_to_records(rows, TRACK_DTYPE)
