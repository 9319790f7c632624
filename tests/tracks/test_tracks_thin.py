"""One record per cluster per frame (evclust.tracks.thin.PerFrame)."""

from __future__ import annotations

import numpy as np
import pytest

from evclust.tracks import TRACK_DTYPE, TrackFlags
from evclust.tracks.thin import PerFrame

T_FRAME = 1000.0


def records(rows):
    """rows of (t_us, id, x, flags)"""
    out = np.zeros(len(rows), TRACK_DTYPE)
    for i, (t, ident, x, flags) in enumerate(rows):
        out[i]["t_us"], out[i]["id"], out[i]["x"], out[i]["flags"] = t, ident, x, flags
    return out


ROWS = [
    (100, 1, 1.0, TrackFlags.NEW), (100, 2, 2.0, TrackFlags.NEW), (400, 1, 1.5, 0), (999, 2, 2.5, 0),  # frame 0
    (1000, 1, 3.0, 0), (1500, 3, 4.0, TrackFlags.NEW), (1999, 1, 3.5, TrackFlags.BORDER),  # frame 1
    (2000, 3, 5.0, 0),  # frame 2
]  # fmt: skip


def run(chunks):
    got = []
    thinner = PerFrame(got.append, T_FRAME)
    for chunk in chunks:
        thinner.write(chunk)
    thinner.close()
    return np.concatenate(got) if got else np.zeros(0, TRACK_DTYPE)


def test_the_last_record_of_each_cluster_in_each_frame_is_kept_with_its_start():
    got = run([records(ROWS)])
    assert [(int(r["t_us"]), int(r["id"]), float(r["x"])) for r in got] == [
        (400, 1, 1.5), (999, 2, 2.5), (1500, 3, 4.0), (1999, 1, 3.5), (2000, 3, 5.0),
    ]  # fmt: skip
    flags = {(int(r["t_us"]), int(r["id"])): TrackFlags(int(r["flags"])) for r in got}
    # Ids 1 and 2 started in frame 0: their kept records carry NEW; id 3's own record has it.
    assert flags[(400, 1)] == TrackFlags.NEW and flags[(999, 2)] == TrackFlags.NEW and flags[(1500, 3)] == TrackFlags.NEW
    assert flags[(1999, 1)] == TrackFlags.BORDER and flags[(2000, 3)] == 0


@pytest.mark.parametrize("seed", range(5))
def test_the_result_does_not_depend_on_how_the_stream_is_cut(seed):
    rng = np.random.default_rng(seed)
    n = 400
    rows = [(t, int(rng.integers(0, 6)), float(i), int(rng.integers(0, 2))) for i, t in enumerate(np.sort(rng.integers(0, 20_000, n)))]
    whole = run([records(rows)])
    cuts = np.sort(rng.choice(np.arange(1, n), 12, replace=False))
    pieces = np.split(records(rows), cuts)
    assert np.array_equal(run(pieces), whole)
    frames = np.floor(whole["t_us"] / T_FRAME).astype(np.int64)
    pairs = set(zip(frames.tolist(), whole["id"].tolist()))
    assert len(pairs) == whole.size  # one record per (frame, id)
    all_frames = np.floor(records(rows)["t_us"] / T_FRAME).astype(np.int64)
    assert pairs == set(zip(all_frames.tolist(), records(rows)["id"].tolist()))  # and none lost
