"""One record per cluster per frame: the last one, for outputs people look at frame by frame.

The clusterer reports every filter step (every `filter_every` events), so a dense video gives
hundreds of steps per frame and millions of records. `PerFrame` keeps, for each cluster id, its
last record in each frame period (t_us // t_frame_us) and passes those on as the stream goes; the
NEW flag of a dropped first record moves to the kept one, so a track still starts once.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from evclust.tracks.record import TrackFlags


class PerFrame:
    """A track sink that thins records to one per (frame, id) before handing them to `sink`."""

    def __init__(self, sink: Callable[[np.ndarray], None], t_frame_us: float):
        self.sink, self.t_frame_us = sink, float(t_frame_us)
        self.held = None  # records of the latest frame seen: more of that frame may follow
        self.count = 0

    def write(self, tracks: np.ndarray) -> None:
        if tracks.size == 0:
            return
        if self.held is not None:
            tracks = np.concatenate([self.held, tracks])
        frame = self._frame(tracks)
        last = frame[-1]
        done = frame < last
        self.held = tracks[~done]
        if done.any():
            self._emit(tracks[done], frame[done])

    def close(self) -> None:
        if self.held is not None and self.held.size:
            self._emit(self.held, self._frame(self.held))
        self.held = None

    def _frame(self, tracks: np.ndarray) -> np.ndarray:
        return np.floor(tracks["t_us"] / self.t_frame_us).astype(np.int64)

    def _emit(self, tracks: np.ndarray, frame: np.ndarray) -> None:
        key = (frame.astype(np.uint64) << np.uint64(32)) | tracks["id"].astype(np.uint64)
        # The last record of each key, in stream order: unique on the reversed keys finds it.
        _, first_from_end = np.unique(key[::-1], return_index=True)
        keep = np.sort(tracks.size - 1 - first_from_end)
        new = (tracks["flags"] & TrackFlags.NEW) != 0
        if new.any():
            started = np.isin(key[keep], key[new])
            out = tracks[keep]
            out["flags"][started] |= np.uint16(TrackFlags.NEW)
        else:
            out = tracks[keep]
        self.count += out.size
        self.sink(out)
