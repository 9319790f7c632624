"""The activity against a reference time (ClustererParams.activity_reference): between filter steps
a slot keeps Ã = A·2^((t - t_ref)/T_half), each event adds its weight 2^((t - t_ref)/T_half), and the
step decays every activity by one factor. Checked against the exact sum of decayed events, against
the paper's decay-then-add (equal in exact arithmetic), and for what the hardware relies on: the
update is an addition, so the delay does not change it, and Ã never outgrows its headroom."""

from __future__ import annotations

import numpy as np
import pytest

from evclust.clusterer import ClustererParams
from evclust.clusterer.params import REFERENCE_HALVINGS
from evclust.clusterer.layout import ACT, BG_T, EVICTED, PX, VALID
from evclust.clusterer.run import FloatClusterer
from evclust.events import EVENT_DTYPE
from evclust.fixed.fixed_model import SIGNALS
from evclust.fixed.model import FixedClusterer
from evclust.rtl.sources import params_header

W, H, T_FRAME, T_HALF = 64, 48, 10_000.0, 5_000.0


def events(rows) -> np.ndarray:
    ev = np.zeros(len(rows), EVENT_DTYPE)
    for i, (t, x, y) in enumerate(rows):
        ev[i] = (t, x, y, 1, 200, 100, 150)
    return ev


def params(**update) -> ClustererParams:
    base = dict(
        activity_reference=True, t_half_us=T_HALF, objects=False, merge=False, noise_gate=0.0, a_min=0.0, v_min=0.0, create_support=False
    )
    return ClustererParams(**{**base, **update})


def one_cluster(times, model, **update):
    """One cluster fed events at `times` (one pixel), a filter step at the last: its activity then."""
    c = model(params(filter_every=len(times), **update), W, H, T_FRAME)
    c.feed(events([(t, 20, 20) for t in times]))
    live = np.flatnonzero(c.slots[:, VALID])
    assert live.size == 1
    scale = 1.0 if model is FloatClusterer else 2.0 ** c.table["activity"].frac_bits
    return c, c.slots[live[0], ACT] / scale


def exact(times) -> float:
    """Σ 2^-((t_step - t_i)/T_half): every event's one, decayed to the step."""
    return sum(2.0 ** -((times[-1] - t) / T_HALF) for t in times)


# Irregular times, with gaps beyond the reference's headroom (4 half-lives) that move it mid-stream.
TIMES = [1000, 1400, 1401, 1401, 5200, 9000, 9001, 31_000, 31_500, 33_000, 80_000, 80_010, 81_000]


def test_the_float_activity_is_the_sum_of_the_decayed_events():
    _, a = one_cluster(TIMES, FloatClusterer)
    assert a == pytest.approx(exact(TIMES), rel=1e-12)


def test_the_fixed_activity_is_within_its_rounding_of_the_exact_sum():
    c, a = one_cluster(TIMES, FixedClusterer)
    lsb = 2.0 ** -c.table["activity"].frac_bits
    # Each weight and each move of the reference floors once (one LSB each, the moves scaled
    # up by up to 2^4 before the step decays them back); the 64-step table's index floors up to
    # 1/64 of a half-life (2^(1/64) - 1 = 1.09 %) and its entries carry 2^-16.
    moves = 3
    bound = exact(TIMES) * (2.0 ** (1 / 64) * (1 + 2.0**-16) - 1) + (len(TIMES) + moves + 1) * lsb
    assert abs(a - exact(TIMES)) <= bound
    assert not c.overflow.any(), dict(zip(SIGNALS, c.overflow))


def test_a_gap_beyond_the_headroom_moves_the_reference_to_the_event():
    c = FloatClusterer(params(filter_every=100), W, H, T_FRAME)
    c.feed(events([(1000, 20, 20), (1000 + 4 * 5000 + 1, 20, 20)]))  # 4 half-lives and 1 µs later
    assert c.globals[BG_T] == 1000 + 4 * 5000 + 1
    s = np.flatnonzero(c.slots[:, VALID])[0]
    assert c.slots[s, ACT] == pytest.approx(1.0 + 2.0 ** -(20_001 / T_HALF), rel=1e-12)  # A itself: Ã at its own reference
    c.feed(events([(1000 + 4 * 5000 + 2, 20, 20)]))  # within the headroom: the reference stays
    assert c.globals[BG_T] == 1000 + 4 * 5000 + 1


@pytest.mark.parametrize("model", [FloatClusterer, FixedClusterer])
def test_with_merges_off_the_records_equal_the_paper_decay_in_exact_arithmetic(model):
    """Three clusters at irregular times, merges off (the sequential mode merges a slot's activity
    before the sweep has decayed it): the same decisions, activities equal to rounding."""
    rng = np.random.default_rng(7)
    rows, t = [], 0
    for _ in range(600):
        t += int(rng.choice([0, 3, 40, 900, 7000]))
        cx, cy = [(10, 10), (40, 12), (30, 36)][rng.integers(3)]
        rows.append((t, cx + rng.integers(-2, 3), cy + rng.integers(-2, 3)))
    runs = {}
    for reference in (False, True):
        c = model(params(activity_reference=reference, filter_every=16, a_valid=1.5), W, H, T_FRAME)
        runs[reference] = c.feed(events(rows))
    paper, referenced = runs[False], runs[True]
    assert paper.shape == referenced.shape and paper.shape[0] > 50
    activity = 8  # the records' activity column; the others are the same decisions and states
    others = [i for i in range(paper.shape[1]) if i != activity]
    if model is FloatClusterer:
        np.testing.assert_allclose(referenced[:, others], paper[:, others], rtol=0, atol=1e-9)
        np.testing.assert_allclose(referenced[:, activity], paper[:, activity], rtol=1e-12)
    else:  # the same decisions (time, step, slot, id, class, flags), the activity rounded two ways:
        # within a few LSBs and the table's 1/64 of a half-life
        decisions = [0, 1, 2, 3, 16, 17]
        np.testing.assert_array_equal(referenced[:, decisions], paper[:, decisions])
        lsb = 2.0 ** -c.table["activity"].frac_bits
        assert np.all(np.abs(referenced[:, activity] - paper[:, activity]) <= 0.011 * paper[:, activity] + 8 * lsb)


@pytest.mark.parametrize("delay", [1, 3, 8])
def test_the_update_is_an_addition_so_the_delay_does_not_change_the_fixed_activity(delay):
    _, a0 = one_cluster(TIMES, FixedClusterer)
    _, a = one_cluster(TIMES, FixedClusterer, update_delay=delay)
    assert a == a0  # bit for bit: additions commute, and moving the reference commits what is in flight first


@pytest.mark.parametrize("model", [FloatClusterer, FixedClusterer])
@pytest.mark.parametrize("gap", [3_000, 9_000])
def test_eviction_decides_as_the_paper_does(model, gap):
    """One slot holding a one-event cluster; an event elsewhere evicts it when its activity has
    decayed below A_valid = 0.5 (after one half-life), not before."""
    decisions = []
    for reference in (False, True):
        c = model(params(activity_reference=reference, n_clusters=1, a_valid=0.5, filter_every=100),
                  W, H, T_FRAME)  # fmt: skip
        c.feed(events([(1000, 10, 10), (1000 + gap, 50, 40)]))
        decisions.append(int(c.globals[EVICTED]))
    assert decisions == [int(gap > T_HALF)] * 2


@pytest.mark.parametrize("on", [False, True])
def test_the_header_builds_the_mode_as_the_parameters_ask(on):
    # The RTL builds the mode (docs/RTL.md): the header carries it as a build option, with Ã's
    # integer bits above A's.
    header = params_header(ClustererParams(activity_reference=on), W, H, T_FRAME)
    assert f"localparam integer ACTIVITY_REFERENCE = {int(on)};" in header
    assert f"localparam integer REFERENCE_HALVINGS = {REFERENCE_HALVINGS};" in header


@pytest.mark.parametrize("halves", range(5))
def test_the_fixed_weight_is_exact_at_whole_half_lives(halves):
    """The fixed weight 2^(m/64) is the decay datapath run back from 2^4: exactly 1 at the reference
    and 2^h after h whole half-lives (a power-of-two T_half makes 1/T_half exact)."""
    c = FixedClusterer(params(filter_every=1000, t_half_us=4096.0), W, H, T_FRAME)
    c.feed(events([(0, 20, 20), (halves * 4096, 20, 20)]))  # the reference is the first event's time, 0
    one = 1 << c.table["activity"].frac_bits
    s = np.flatnonzero(c.slots[:, VALID])[0]
    assert int(c.slots[s, ACT]) == one + (one << halves)


@pytest.mark.parametrize("gap", [4 * 4096 - 10, 4 * 4096 + 10])
def test_float_and_fixed_move_the_reference_at_the_same_event(gap):
    """Just below and just past the headroom (4 half-lives, 1/T_half exact), at D = 2: moving drains
    the delay line, which changes what the next events read, so both models must move at the same
    event (the fixed one compares Δt/T_half unfloored, as the float one does)."""
    centres = []
    for model in (FloatClusterer, FixedClusterer):
        c = model(params(update_delay=2, alpha_pos=0.5, filter_every=4, t_half_us=4096.0), W, H, T_FRAME)
        c.feed(events([(0, 20, 20), (0, 22, 20), (gap, 24, 20)]))
        moved = c.globals[BG_T] == gap
        c.feed(events([(gap + 1, 24, 20)]))  # the step
        s = np.flatnonzero(c.slots[:, VALID])[0]
        scale = 1.0 if model is FloatClusterer else 2.0 ** c.table["centre"].frac_bits
        centres.append((moved, c.slots[s, PX] / scale))
    assert centres[0][0] == (gap > 4 * 4096)
    assert centres[0] == centres[1]
