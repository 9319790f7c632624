"""Pipeline semantics (ClustererParams.update_delay = D): event n reads the table with the updates of
events up to n - D - 1 committed, creations at once, and each update lands as increments added to
the slot as it then is. Checked against the delayed-LMS recurrence written out here, and for the
invariants the hardware relies on: a filter step sees every event before it, a new cluster gets
none of its slot's old updates, and a stream cut into pieces gives what it gives whole."""

from __future__ import annotations

import numpy as np
import pytest

from evclust.clusterer import ClustererParams
from evclust.clusterer.layout import ACT, EV_COUNT, MERGED, PX, PY, VALID
from evclust.clusterer.run import FloatClusterer
from evclust.errors import EvclustError
from evclust.events import EVENT_DTYPE
from evclust.fixed.model import FixedClusterer
from evclust.rtl.sources import params_header

from testkit import classic_params

W, H, T_FRAME = 64, 48, 10_000.0
START, TARGET, EVENTS = 20, 24, 40  # a cluster born at x = START, then EVENTS events at x = TARGET


def events(rows) -> np.ndarray:
    ev = np.zeros(len(rows), EVENT_DTYPE)
    for i, (t, x, y) in enumerate(rows):
        ev[i] = (t, x, y, 1, 200, 100, 150)
    return ev


def pull(delay: int, model=FloatClusterer):
    """The cluster's state after the pull, the filter step at the last event committing all."""
    params = classic_params(update_delay=delay, filter_every=EVENTS + 1)
    c = model(params, W, H, T_FRAME)
    c.feed(events([(1000, START, 20)] + [(1001 + i, TARGET, 20) for i in range(EVENTS)]))
    live = np.flatnonzero(c.slots[:, VALID])
    assert live.size == 1
    return c, live[0]


def delayed_lms(delay: int, increment, start, target) -> list:
    """C_m = C_(m-1) + increment(target, C_(m-D-1)): the committed centre after event m (event 0,
    the creation, at once), each event reading the centre D events old."""
    c = [start]
    for m in range(1, EVENTS + 1):
        c.append(c[-1] + increment(target, c[max(m - delay - 1, 0)]))
    return c


@pytest.mark.parametrize("delay", [0, 1, 3, 8])
def test_the_float_centre_follows_the_delayed_lms_recurrence(delay):
    c, s = pull(delay)
    beta = 1.0 - c.params.alpha_pos
    expected = delayed_lms(delay, lambda e, p: beta * (e - p), float(START), float(TARGET))
    assert c.slots[s, PX] == pytest.approx(expected[-1], abs=1e-9)
    assert c.slots[s, PY] == 20.0 and c.slots[s, EV_COUNT] == EVENTS  # every event committed once
    if delay:  # a stale read pulls less per event early on: the delay is visible
        assert abs(expected[-1] - delayed_lms(0, lambda e, p: beta * (e - p), float(START), float(TARGET))[-1]) > 1e-3


@pytest.mark.parametrize("delay", [0, 2, 8])
def test_the_fixed_centre_follows_the_delayed_lms_recurrence_bit_for_bit(delay):
    c, s = pull(delay, FixedClusterer)
    fp, beta, bits = int(c.k.centre_frac), int(c.k.beta_pos), int(c.k.beta_pos_frac)
    # P += floor(((e << F_P) - P) * beta / 2^bits): Python's >> floors as the datapath does.
    expected = delayed_lms(delay, lambda e, p: (((e << fp) - p) * beta) >> bits, START << fp, TARGET)
    assert int(c.slots[s, PX]) == expected[-1]
    assert int(c.slots[s, EV_COUNT]) == EVENTS


@pytest.mark.parametrize("model", [FloatClusterer, FixedClusterer])
def test_a_new_cluster_gets_none_of_its_slots_pending_updates(model):
    # One slot, D = 4: three updates are in flight when a far event evicts the weak cluster.
    params = classic_params(n_clusters=1, update_delay=4, filter_every=5)
    c = model(params, W, H, T_FRAME)
    c.feed(events([(1000, 20, 20), (1001, 22, 20), (1002, 22, 20), (1003, 22, 20), (1004, 50, 40)]))
    scale = 1.0 if model is FloatClusterer else 2.0 ** c.table["centre"].frac_bits
    assert c.slots[0, VALID] == 1 and c.slots[0, PX] / scale == 50.0 and c.slots[0, PY] / scale == 40.0
    assert c.slots[0, EV_COUNT] == 0  # the three updates were the old cluster's
    one = 1.0 if model is FloatClusterer else 2.0 ** c.table["activity"].frac_bits
    assert c.slots[0, ACT] == one  # born at the filter step's time: activity 1


@pytest.mark.parametrize("model", [FloatClusterer, FixedClusterer])
def test_a_stream_in_pieces_gives_what_it_gives_whole(model):
    # The delay line is state: updates in flight at the end of a piece land in the next one.
    rng = np.random.default_rng(3)
    rows = [(1000 + 7 * i, int(x), int(y)) for i, (x, y) in enumerate(zip(rng.normal(30, 4, 3000).clip(0, W - 1),
                                                                         rng.normal(24, 3, 3000).clip(0, H - 1)))]  # fmt: skip
    ev = events(rows)
    params = ClustererParams(update_delay=5, filter_every=64)
    whole = model(params, W, H, T_FRAME)
    out_whole = whole.feed(ev)
    pieces = model(params, W, H, T_FRAME)
    out_pieces = np.concatenate([pieces.feed(ev[lo : lo + 997]) for lo in range(0, ev.size, 997)])
    assert out_whole.shape[0] > 10
    assert np.array_equal(out_whole, out_pieces)
    assert np.array_equal(whole.slots, pieces.slots) and np.array_equal(whole.delay_line, pieces.delay_line)


def test_the_fixed_model_follows_the_float_model_with_the_delay():
    # The bar of tests/clusterer/test_clusterer_additions.py, D = 8: the same merges, centres within a few LSBs.
    rows = []
    for i in range(120):
        lead = int(round(30.0 + 0.25 * i))
        for y in range(18, 30):
            rows += [(1000 + 100 * i, lead, y), (1000 + 100 * i, lead - 24, y)]
    ev = events(rows)
    params = ClustererParams(update_delay=8)
    f, x = FloatClusterer(params, W, H, T_FRAME), FixedClusterer(params, W, H, T_FRAME)
    fo, xo = f.feed(ev), x.feed(ev)
    assert f.globals[MERGED] == x.globals[MERGED] and len(fo) == len(xo) > 0
    fp = x.table["centre"].frac_bits
    live_f, live_x = f.slots[f.slots[:, VALID] == 1], x.slots[x.slots[:, VALID] == 1]
    assert np.allclose(live_f[:, PX], live_x[:, PX] / 2.0**fp, atol=0.05)
    assert not any(x.stats()["saturations"].get(name) for name in ("centre", "colour", "background", "mcm_norm"))


def test_the_rtl_refuses_the_delayed_update_in_one_line():
    with pytest.raises(EvclustError, match="update_delay = 3") as info:
        params_header(ClustererParams(update_delay=3), W, H, T_FRAME)
    assert "\n" not in str(info.value)
