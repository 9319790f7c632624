"""The switch cover: a pairwise (all-pairs) cover of the clusterer's switches, each row a parameter
set on a small sensor that the RTL runs against the fixed model in the loop (under Icarus and
Verilator, tb/evclust_core/test_every_configuration.py).

Every pair of values of any two switches appears in at least one row (allpairspy). Each row runs
on a stream that exercises it: `live_stream` picks, deterministically, the first stream on which
the row reports records and on which flipping any one of its switches, alone, changes the fixed
model's records. A switch whose setting the stream cannot see would be co-simulated for nothing.

`make test` co-simulates two rows chosen from the commit hash (`selected_rows`, tb/cosim.py's
rotating subset); `make cosim-full` (EVCLUST_COVER=all) all of them; EVCLUST_COVER_ROWS=3,7 chooses. Rows are numbered in allpairspy's
order, which is deterministic.
"""

from __future__ import annotations

import functools
import hashlib
import os
from typing import NamedTuple

import numpy as np

from cosim import full, group_on_turn, rotating_subset, rotation_key  # full: the tests' switch, imported from here

# The small sensor of tb/cosim.py's "small" configuration.
WIDTH, HEIGHT, T_FRAME_US = 64, 48, 10000.0
N_CLUSTERS = 4
# The stream's background colour (YCbCr): the colour of its noise events, which the learned
# background converges to; the fixed background of the rows that fix it is another.
SCENE_BACKGROUND = (100, 125, 135)
FIXED_BACKGROUND = (90, 120, 140)

# switch: {value's name in the row id: the parameters it sets}. The first value of each is the
# paper's (presets/paper.toml), so row 0, every first value, is the paper's switches.
SWITCHES: dict[str, dict[str, dict]] = {
    "gamma": {"global": {"gamma_mode": "global"}, "activity": {"gamma_mode": "activity"}, "count": {"gamma_mode": "count"}},
    "support": {"nosupport": {"create_support": False},
                "support1px": {"create_support": True, "support_cell_bits": 0},
                "support4px": {"create_support": True, "support_cell_bits": 2}},
    "warm": {"cold": {"velocity_warm_start": False}, "warm": {"velocity_warm_start": True}},
    "mcm": {"mcmraw": {"mcm_bias_correction": False}, "mcmcorr": {"mcm_bias_correction": True}},
    "background": {"bglearned": {"background": None}, "bgfixed": {"background": FIXED_BACKGROUND}},
    "vote": {"votecount": {"palette_vote": "count"}, "votecontrast": {"palette_vote": "contrast"}},
    "assign": {"nearest": {"palette_assign": "nearest"}, "mixing": {"palette_assign": "mixing"}},
    "merge": {"nomerge": {"merge": False}, "merge": {"merge": True}},
    "seek": {"noseek": {"seek_scale": 0.0}, "seek": {"seek_scale": 0.09375}},
    "gate": {"nogate": {"noise_gate": 0.0}, "gate": {"noise_gate": 16.0}},
    "objects": {"noobjects": {"objects": False}, "objects": {"objects": True}},
    "activity": {"owntime": {"activity_reference": False}, "reference": {"activity_reference": True}},
}  # fmt: skip

# The parameters every row shares: the small configuration's (tb/cosim.py), with the background
# made visible in the reported colour (p < 1) and a mixing tolerance at which edge colours are told
# from their nearest entry.
BASE = dict(n_clusters=N_CLUSTERS, a_valid=6.0, p_correction=0.6, mixing_tolerance=30.0)


class Row(NamedTuple):
    index: int
    settings: tuple[str, ...]  # each switch's value name, in SWITCHES's order

    @property
    def values(self) -> dict[str, str]:
        return dict(zip(SWITCHES, self.settings))

    @property
    def name(self) -> str:
        return f"row{self.index:02d}-" + "-".join(self.settings)

    def flipped(self, switch: str, value: str) -> Row:
        return Row(self.index, tuple((self.values | {switch: value}).values()))


@functools.cache
def cover() -> tuple[Row, ...]:
    """The rows, in allpairspy's order (deterministic: the same rows on every run)."""
    from allpairspy import AllPairs

    rows = AllPairs([list(values) for values in SWITCHES.values()])
    return tuple(Row(i, tuple(row)) for i, row in enumerate(rows))


def pairs(rows) -> set[tuple[tuple[str, str], tuple[str, str]]]:
    """Every pair of (switch, value)s the rows hold together."""
    out = set()
    for row in rows:
        items = list(row.values.items())
        out |= {(a, b) for i, a in enumerate(items) for b in items[i + 1 :]}
    return out


def all_pairs() -> set:
    names = list(SWITCHES)
    return {((a, va), (b, vb)) for i, a in enumerate(names) for b in names[i + 1 :] for va in SWITCHES[a] for vb in SWITCHES[b]}


def row_params(row: Row):
    from evclust.vectors.cases import _small_params

    update = dict(BASE)
    for switch, value in row.values.items():
        update |= SWITCHES[switch][value]
    return _small_params(**update)


def cover_stream(seed: int, count: int) -> np.ndarray:
    """Blobs moving at 1.5 to 6 px/frame over noise, as evclust.vectors.stimulus.random_stream, but
    coloured as edges are: each blob a mixture q·entry + (1-q)·background of a palette entry and the
    scene's background (q from 0.3 to 0.8), the noise events the background's colour. The nearest
    entry of such a colour is often another than the mixing rule's, so both rules show."""
    from evclust.clusterer import ClustererParams
    from evclust.events import EVENT_DTYPE

    width, height, t_frame_us = WIDTH, HEIGHT, T_FRAME_US
    rng = np.random.default_rng(seed)
    n_blobs = int(rng.integers(2, 6))
    centre = rng.uniform([0, 0], [width - 1, height - 1], (n_blobs, 2))
    heading = rng.uniform(0, 2 * np.pi, n_blobs)
    speed = rng.uniform(1.5, 6.0, n_blobs) / t_frame_us  # px/µs
    velocity = np.stack([np.cos(heading), np.sin(heading)], axis=1) * speed[:, None]
    radius = rng.uniform(2.0, max(3.0, min(width, height) / 8), n_blobs)
    entries = ClustererParams().palette_ycbcr()
    background = np.array(SCENE_BACKGROUND, np.float64)
    q = rng.uniform(0.3, 0.8, n_blobs)[:, None]
    colour = np.rint(background + q * (entries[rng.integers(0, len(entries), n_blobs)] - background)).astype(np.int64)
    dt = rng.exponential(80.0, count).astype(np.int64)
    dt[rng.random(count) < 0.05] = 0  # bursts: same microsecond
    dt[rng.random(count) < 0.0005] += rng.integers(1_000_000, 3_000_000)  # gaps of seconds
    t = 1000 + np.cumsum(dt)
    which = rng.integers(0, n_blobs, count)
    noise = rng.random(count) < 0.05
    where = centre[which] + velocity[which] * (t - t[0])[:, None]
    where = np.abs(np.mod(where, 2 * np.array([width - 1, height - 1])) - np.array([width - 1, height - 1]))  # bounce
    xy = np.rint(where + rng.uniform(-1, 1, (count, 2)) * radius[which][:, None])
    xy[noise] = rng.uniform([0, 0], [width - 1, height - 1], (int(noise.sum()), 2))
    ycc = colour[which] + rng.integers(-4, 5, (count, 3))
    ycc[noise] = background.astype(np.int64) + rng.integers(-8, 9, (int(noise.sum()), 3))
    ycc = np.clip(ycc, 0, 255)
    events = np.zeros(count, EVENT_DTYPE)
    events["t"] = t
    events["x"] = np.clip(xy[:, 0], 0, width - 1)
    events["y"] = np.clip(xy[:, 1], 0, height - 1)
    events["p"] = np.where(rng.random(count) < 0.5, 1, -1)
    events["Y"], events["Cb"], events["Cr"] = ycc[:, 0], ycc[:, 1], ycc[:, 2]
    return events


def model_run(row: Row, events: np.ndarray) -> tuple[list[int], list[int], dict]:
    """The fixed model's record words, object record words and status counters for a row on a stream."""
    from evclust.fixed.model import FixedClusterer
    from evclust.fixed.registers import model_counters
    from evclust.vectors.write import model_words

    model = FixedClusterer(row_params(row), WIDTH, HEIGHT, T_FRAME_US)
    words = model_words(model, events)
    return words.records, words.objects, model_counters(model.stats(), len(words.records))


def dead_switches(row: Row, events: np.ndarray) -> list[str]:
    """The switch settings that flipping alone leaves the row's records (cluster and object records) unchanged on this stream."""
    records, objects, _ = model_run(row, events)
    return [f"{switch}={value}" for switch, values in SWITCHES.items() for value in values
            if value != row.values[switch] and model_run(row.flipped(switch, value), events)[:2] == (records, objects)]  # fmt: skip


COUNT = 3000  # events per row's stream
TRIES = 40


@functools.cache
def live_stream(row: Row, count: int = COUNT, tries: int = TRIES) -> tuple[int, dict]:
    """(seed, the model's counters) of the first stream of `count` events, from a seed of the row's
    own, that exercises the row: it reports records, and flipping any one switch changes them.
    AssertionError if none of `tries` streams does."""
    base = int.from_bytes(hashlib.sha256(row.name.encode()).digest()[:3], "little")
    tried = []
    for seed in range(base, base + tries):
        events = cover_stream(seed, count)
        records, _, counters = model_run(row, events)
        dead = dead_switches(row, events) if records else ["(no records)"]
        if not dead:
            return seed, counters
        tried.append(f"{seed}: {', '.join(dead)}")
    raise AssertionError(f"{row.name}: none of {tries} streams exercises every switch:\n" + "\n".join(tried))


ROTATING = 1  # rows per `make test` (11 rows: every one in 11 commits on average)


def selected_rows() -> tuple[tuple[Row, ...], str]:
    """(the rows to co-simulate, how they were chosen). EVCLUST_COVER=all: every row;
    EVCLUST_COVER_ROWS=3,7: those; else ROTATING rows drawn from the commit hash when the switch
    cover is on turn (tb/cosim.py: TAKING_TURNS), none when the broken proof is."""
    rows = cover()
    if full():
        return rows, "EVCLUST_COVER=all"
    chosen = os.environ.get("EVCLUST_COVER_ROWS", "").strip()
    if chosen:
        try:
            picked = tuple(rows[int(i)] for i in chosen.split(","))
        except (ValueError, IndexError):
            raise SystemExit(f"EVCLUST_COVER_ROWS={chosen}: expected row numbers from 0 to {len(rows) - 1}, comma-separated") from None
        return picked, f"EVCLUST_COVER_ROWS={chosen}"
    if group_on_turn("checks") != "switch-cover":
        return (), f"not on turn in {rotation_key()[:12]}: the broken proof is (tb/cosim.py: TAKING_TURNS)"
    picked = rotating_subset(len(rows), ROTATING, "")
    return tuple(rows[i] for i in picked), f"rotating subset of {rotation_key()[:12]}: EVCLUST_COVER_ROWS={','.join(map(str, picked))}"
