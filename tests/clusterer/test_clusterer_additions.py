"""The one-cluster-per-object additions of the float clusterer (docs/TUNING.md), each against an
answer that follows from its definition, and the fixed model's agreement with them."""

from __future__ import annotations

import numpy as np
import pytest

from evclust.clusterer import ClustererParams, load_params
from evclust.clusterer.layout import ACT, ID, MERGED, PX, PY, UNSUPPORTED, VALID, VI_COUNT, VIX
from evclust.clusterer.run import FloatClusterer
from evclust.events import EVENT_DTYPE
from evclust.fixed.model import FixedClusterer

from testkit import classic_params

W, H, T_FRAME = 64, 48, 10_000.0


def events(rows) -> np.ndarray:
    ev = np.zeros(len(rows), EVENT_DTYPE)
    for i, (t, x, y) in enumerate(rows):
        ev[i] = (t, x, y, 1, 200, 100, 150)
    return ev


def bar(speed_px_per_step=0.25, steps=120, dt=100, length=24, rows=range(18, 30), x0=30.0):
    """A uniform bar moving right: events on its two edges only (one per edge pixel and step)."""
    out = []
    for i in range(steps):
        lead = int(round(x0 + speed_px_per_step * i))
        for y in rows:
            out += [(1000 + dt * i, lead, y), (1000 + dt * i, lead - length, y)]
    return events(out)


def run(params, ev, model=FloatClusterer):
    c = model(params, W, H, T_FRAME)
    out = c.feed(ev)
    return c, out


EDGES = dict(r_init=2.0, seek_margin=2.0, size_gain=2.0, tau_us=2000.0, t_half_us=5000.0, a_valid=3.0, v_min=0.0, filter_every=8)


def test_the_two_edges_of_a_uniform_bar_merge_into_one_cluster_at_its_centre():
    ev = bar()
    apart, _ = run(classic_params(**EDGES), ev)
    live = apart.slots[apart.slots[:, VALID] == 1]
    assert apart.globals[MERGED] == 0 and live.shape[0] >= 2  # clusters on the edges, none between them
    assert np.all(np.abs(live[:, PX] - round(30.0 + 0.25 * 119) + 12) >= 8)
    merged, _ = run(classic_params(**EDGES, merge=True, merge_scale=2.0, merge_v_tol=2.0), ev)
    live = merged.slots[merged.slots[:, VALID] == 1]
    assert merged.globals[MERGED] >= 1 and live.shape[0] == 1
    # The edges are at lead and lead - 24: the bar's centre is 12 px behind the leading edge.
    lead = round(30.0 + 0.25 * 119)
    assert abs(live[0, PX] - (lead - 12)) <= 2.0 and abs(live[0, PY] - 23.5) <= 1.0


def test_objects_that_cross_with_measured_opposite_velocities_are_not_merged():
    # Two blobs on one row moving towards each other at 0.1 px per 100 µs (from x = 8 and 56, they
    # meet at x = 32 after 24 ms): by then both have measured interval velocities of opposite
    # sign, so the overlap alone is not enough.
    rng = np.random.default_rng(3)
    rows = []
    for i in range(1600):
        t = 1000 + 25 * i
        step = (t - 1000) / 100.0
        if i % 2:
            rows.append((t, int(round(8 + 0.1 * step)) + int(rng.integers(-2, 3)), 24 + int(rng.integers(-2, 3))))
        else:
            rows.append((t, int(round(56 - 0.1 * step)) + int(rng.integers(-2, 3)), 24 + int(rng.integers(-2, 3))))
    params = classic_params(**EDGES | {"tau_us": 1000.0}, merge=True, merge_scale=0.0, merge_v_tol=0.5)
    c, _ = run(params, events(rows))
    live = c.slots[c.slots[:, VALID] == 1]
    assert live.shape[0] == 2 and np.sign(live[:, VIX]).tolist() in ([1.0, -1.0], [-1.0, 1.0])  # both went on through
    # The same stream with velocity agreement forced (a huge tolerance) merges them as they meet.
    loose, _ = run(params.model_copy(update={"merge_v_tol": 1e4}), events(rows))
    assert (loose.slots[:, VALID] == 1).sum() == 1 and loose.globals[MERGED] > c.globals[MERGED]


def test_the_survivor_of_a_merge_is_the_cluster_reported_before():
    ev = bar()
    params = classic_params(**EDGES, merge=True, merge_scale=2.0, merge_v_tol=2.0)
    c = FloatClusterer(params, W, H, T_FRAME)
    out = np.concatenate([c.feed(ev[i : i + 8]) for i in range(0, ev.size, 8)])
    reported_ids = set(out[:, 3].astype(int).tolist())
    live = c.slots[c.slots[:, VALID] == 1]
    assert int(live[0, ID]) in reported_ids  # the identity the tracks already carried goes on


def test_an_event_without_support_creates_nothing_and_one_with_support_does():
    params = classic_params(create_support=True, support_cell_bits=1, support_window_us=300.0, v_min=0.0)
    # Two events far apart in space, then one 2 px (one cell) from the second within 300 µs.
    c, _ = run(params, events([(1000, 5, 5), (1100, 40, 30), (1200, 42, 31)]))
    assert c.globals[UNSUPPORTED] == 2 and (c.slots[:, VALID] == 1).sum() == 1
    # The same neighbour 400 µs later is outside the window.
    c, _ = run(params, events([(1000, 5, 5), (1100, 40, 30), (1500, 42, 31)]))
    assert c.globals[UNSUPPORTED] == 3 and (c.slots[:, VALID] == 1).sum() == 0


def test_the_noise_gate_reports_a_dense_blob_and_not_a_cluster_of_noise():
    rng = np.random.default_rng(4)
    rows = []
    for i in range(4000):
        t = 1000 + 2 * i
        if i % 4 == 0:  # a dense 7x7 blob: a quarter of the events on 49 of 3072 pixels
            rows.append((t, 40 + int(rng.integers(-3, 4)), 20 + int(rng.integers(-3, 4))))
        else:
            rows.append((t, int(rng.integers(0, W)), int(rng.integers(0, H))))
    base = classic_params(a_valid=2.0, r_init=3.0, seek_margin=3.0, n_clusters=8, v_min=0.0, filter_every=8)
    _, plain = run(base, events(rows))
    _, gated = run(base.model_copy(update={"noise_gate": 6.0}), events(rows))
    near_blob = lambda out: (np.abs(out[:, 4] - 40) <= 4) & (np.abs(out[:, 5] - 20) <= 4)
    assert (~near_blob(plain)).sum() > 0  # without the gate, noise clusters are reported
    assert near_blob(gated).sum() > 0 and (~near_blob(gated)).sum() < 0.05 * (~near_blob(plain)).sum()


def test_a_scaled_seek_margin_reaches_farther_for_a_larger_cluster():
    # A cluster of half-size 4 (r_init) with S = 1: an event 10 px away is outside S + R = 5,
    # inside S + R + 1.5·max(R) = 11.
    rows = [(1000, 20, 20), (1001, 30, 20)]
    base = classic_params(r_init=4.0, r_min=1.0, seek_margin=1.0, v_min=0.0)
    c, _ = run(base, events(rows))
    assert (c.slots[:, VALID] == 1).sum() == 2
    c, _ = run(base.model_copy(update={"seek_scale": 1.5}), events(rows))
    assert (c.slots[:, VALID] == 1).sum() == 1 and c.slots[c.slots[:, VALID] == 1][0, ACT] > 1.5


def test_times_in_frames_resolve_against_the_frame_period_and_micro_seconds_win():
    p = ClustererParams(t_half_frames=2.0, tau_frames=3.5, support_window_frames=0.25)
    r = p.resolved(20_000.0)
    assert (r.t_half_us, r.tau_us, r.support_window_us) == (40_000.0, 70_000.0, 5_000.0)
    assert ClustererParams(tau_frames=0.33333).resolved(100.0).tau_us == 33.0  # whole µs
    given = ClustererParams(t_half_us=1234.0, tau_us=5678.0).resolved(20_000.0)
    assert (given.t_half_us, given.tau_us) == (1234.0, 5678.0)


def test_the_interval_warm_up_reaches_the_velocity_long_before_the_plain_filter():
    # A blob drifting right at 1 px per τ = 1 ms, i.e. 10 px/frame. Measurements arrive once per
    # τ; with β_vi = 0.05 the plain filter holds 1 - 0.95^n of the velocity after n of them (23 %
    # after 5), the warm-up's running mean all of it after the first.
    rng = np.random.default_rng(6)
    rows = [(1000 + 10 * i, 10 + int(round(i / 100)) + int(rng.integers(-1, 2)), 24 + int(rng.integers(-1, 2))) for i in range(700)]
    params = classic_params(r_init=3.0, seek_margin=3.0, tau_us=1000.0, alpha_vel_int=0.95, v_min=0.0, filter_every=8, a_valid=2.0)
    warm, _ = run(params, events(rows))
    cold, _ = run(params.model_copy(update={"velocity_warm_start": False}), events(rows))
    s_w, s_c = (int(np.flatnonzero(c.slots[:, VALID] == 1)[0]) for c in (warm, cold))
    assert warm.slots[s_w, VI_COUNT] >= 5
    assert abs(warm.slots[s_w, VIX] - 10.0) < 1.5
    assert cold.slots[s_c, VIX] < 0.5 * 10.0


def test_the_paper_preset_is_the_papers_algorithm():
    p, _ = load_params("paper")
    assert (p.gamma_mode, p.palette_vote, p.palette_assign) == ("global", "count", "nearest")
    assert not p.velocity_warm_start and not p.mcm_bias_correction
    assert (p.seek_scale, p.merge, p.noise_gate, p.create_support) == (0.0, False, 0.0, False)
    assert (p.alpha_vel_mcm, p.gamma, p.alpha_vel_int, p.tau_us) == (0.999917, 698.0, 0.86, 150000.0)  # Table 4, traffic


@pytest.mark.parametrize("update", [{}, {"create_support": True}])
def test_the_fixed_model_follows_the_float_model_with_every_addition_on(update):
    # The defaults switch every addition on; on a bar and a noisy blob the fixed model ends with
    # the float model's clusters, within a few of the centre's LSBs.
    ev = bar()
    params = ClustererParams(**update)
    f, fo = run(params, ev)
    x, xo = run(params, ev, model=FixedClusterer)
    assert f.globals[MERGED] == x.globals[MERGED] and len(fo) == len(xo)
    fp = x.table["centre"].frac_bits
    live_f, live_x = f.slots[f.slots[:, VALID] == 1], x.slots[x.slots[:, VALID] == 1]
    assert live_f.shape == live_x.shape
    assert np.allclose(live_f[:, PX], live_x[:, PX] / 2.0**fp, atol=0.05)
    assert np.allclose(fo[:, 4], xo[:, 4], atol=0.05)
