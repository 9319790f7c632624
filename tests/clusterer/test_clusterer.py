"""The float clusterer (SPEC §4) against answers that follow from the algorithm's definition."""

from __future__ import annotations

import math

import numpy as np
import pytest

from evclust.clusterer import ClustererParams, PaletteEntry, parse_params
from evclust.run import track_events
from evclust.clusterer.run import FloatClusterer
from evclust.errors import EvclustError
from evclust.events import EVENT_DTYPE, EventMeta
from evclust.metrics.convergence import converged_after

from testkit import FPS, classic_params, simulate_toml, square_scene

T_FRAME = 1e6 / FPS


def run(text, **overrides):
    sim = simulate_toml(text)
    params = classic_params(**{"v_min": 0.0, **overrides})
    return sim, track_events(sim.events, sim.meta, params)


def single_track(result):
    ids, counts = np.unique(result.tracks["id"], return_counts=True)
    return result.tracks[result.tracks["id"] == ids[np.argmax(counts)]]


@pytest.mark.parametrize("v", [(2.0, 0.0), (0.0, 2.0), (1.5, 1.5)])
def test_rigid_square_centre_and_both_velocities_converge(v, capsys):
    # Mean shift lags the centre by 1 / (β_P · events per px of travel): about 500 events/px at
    # θ = 0.1, so 0.4 px at β_P = 0.005. The events of one edge share a timestamp and come as a
    # burst of m ≈ 20 at distance d = 10 px, which pulls the centre by about β_P·m·d = 1 px and back.
    # Moving along an axis, one pair of edges makes events; diagonally both pairs burst.
    sim, result = run(
        square_scene([(200, v)], start=(40.0, 40.0), width=480, height=480, theta=0.1), alpha_pos=0.995, alpha_vel_mcm=0.99995
    )
    track = single_track(result)
    t = track["t_us"].astype(float)
    true_x = 40.0 + v[0] * t / T_FRAME  # the square's centre moves linearly
    true_y = 40.0 + v[1] * t / T_FRAME
    settled = t > 20 * T_FRAME
    error = np.stack([track["x"] - true_x, track["y"] - true_y], 1)[settled]
    limit = 1.0 if 0.0 in v else 1.5
    assert np.sqrt(np.mean(np.sum(error**2, axis=1))) <= limit
    assert np.all(np.abs(error.mean(axis=0)) <= limit)
    # Velocity, read per frame: the records of one frame averaged.
    window = max(1, int(sim.events.size / (sim.frames - 1) / ClustererParams().filter_every))
    target = np.array(v)
    t_mcm = converged_after(t, np.stack([track["vx_mcm"], track["vy_mcm"]], 1), target, 0.05, window)
    t_int = converged_after(t, np.stack([track["vx_int"], track["vy_int"]], 1), target, 0.05, window)
    assert t_mcm is not None and t_int is not None
    with capsys.disabled():
        print(f"\n  v={v}: within 5 % from frame {t_mcm / T_FRAME:.1f} (MCM) and {t_int / T_FRAME:.1f} (interval)")
    assert t_mcm < 150 * T_FRAME and t_int < 150 * T_FRAME


def test_a_direction_change_is_followed_within_the_filters_time_constants(capsys):
    before, after = (2.0, 0.0), (0.0, 2.0)
    params = dict(alpha_pos=0.995, alpha_vel_mcm=0.9999, alpha_vel_int=0.8, tau_us=4 * T_FRAME)
    turn_frame = 60
    sim, result = run(square_scene([(turn_frame, before), (140, after)], start=(40.0, 40.0), width=480, height=480, theta=0.1), **params)
    track = single_track(result)
    t = track["t_us"].astype(float)
    events_per_frame = sim.events.size / (sim.frames - 1)
    # MCM: a first-order filter with memory α per event; 5 % is reached after ln(0.05)/ln(α) events.
    mcm_frames = math.log(0.05) / math.log(params["alpha_vel_mcm"]) / events_per_frame
    # Interval: one update per τ with memory α_vi, plus one τ for the displacement to turn.
    int_frames = (math.log(0.05) / math.log(params["alpha_vel_int"]) + 1) * params["tau_us"] / T_FRAME
    # Plus the centre's own lag: 1/β_P events.
    lag_frames = 1 / (1 - params["alpha_pos"]) / events_per_frame
    window = max(1, int(events_per_frame / ClustererParams().filter_every))
    after_turn = t > turn_frame * T_FRAME
    for name, (vx, vy), theory in (("MCM", ("vx_mcm", "vy_mcm"), mcm_frames), ("interval", ("vx_int", "vy_int"), int_frames)):
        estimate = np.stack([track[vx], track[vy]], 1)[after_turn]
        settled = converged_after(t[after_turn], estimate, np.array(after), 0.1, window)
        assert settled is not None
        delay = (settled - turn_frame * T_FRAME) / T_FRAME
        with capsys.disabled():
            print(f"\n  {name}: within 10 % of the new velocity {delay:.1f} frames after the turn (bound {theory + lag_frames:.1f})")
        assert delay <= theory + lag_frames + 2


def noise_stream(rate_per_pixel_hz, width, height, duration_us, seed=0):
    rng = np.random.default_rng(seed)
    n = rng.poisson(rate_per_pixel_hz * width * height * duration_us * 1e-6)
    ev = np.zeros(n, EVENT_DTYPE)
    ev["t"] = np.sort(rng.integers(0, duration_us, n))
    ev["x"] = rng.integers(0, width, n)
    ev["y"] = rng.integers(0, height, n)
    ev["p"] = rng.choice([-1, 1], n)
    ev["Y"], ev["Cb"], ev["Cr"] = 100, 128, 128
    return ev[np.lexsort((ev["x"], ev["y"], ev["t"]))]


def test_pure_background_noise_is_never_reported_when_the_velocity_filter_is_on():
    width, height = 64, 48
    ev = noise_stream(40.0, width, height, 4_000_000)
    meta = EventMeta(width=width, height=height, source="noise", t_frame_us=T_FRAME)
    params = dict(alpha_vel_mcm=0.999, alpha_vel_int=0.9, a_valid=5.0, seek_margin=4.0, r_max=10.0)
    # The filter must be what hides the noise: without it, noise clusters are reported.
    without = track_events(ev, meta, classic_params(v_min=0.0, **params))
    assert without.tracks.size > 0
    # Noise moves a cluster's centre at random: its velocity estimates average to zero, with a
    # spread far below 1 px/frame for these memories.
    with_filter = track_events(ev, meta, classic_params(v_min=1.0, **params))
    assert with_filter.tracks.size == 0


def test_exit_prediction_frees_the_cluster_before_the_object_has_left():
    # A square 20 px wide moving right at 3 px/frame leaves a 240 px view: its left edge passes
    # the border (x = 239.5) when its centre reaches 249.5.
    sim, result = run(square_scene([(80, (3.0, 0.0))], start=(60.0, 60.0)), exit_margin=12.0, v_exit=1.0, v_min=0.2)
    assert result.stats["exited"] >= 1
    track = single_track(result)
    last_t = float(track["t_us"][-1])
    centre_then = 60.0 + 3.0 * last_t / T_FRAME
    assert centre_then < 249.5 - 3.0  # freed while at least one frame of travel is still visible
    assert track["x"][-1] > 240 - 1 - 12.0 - 6.0  # and only near the border


def table_events(points):
    """Events at (t, x, y) with a neutral colour."""
    ev = np.zeros(len(points), EVENT_DTYPE)
    for i, (t, x, y) in enumerate(points):
        ev[i] = (t, x, y, 1, 100, 128, 128)
    return ev


def test_full_table_evicts_the_least_active_cluster_below_a_valid_and_drops_otherwise():
    params = classic_params(n_clusters=2, a_valid=5.0, a_min=0.0, filter_every=10**6, seek_margin=2.0, t_half_us=1e9, r_init=3.0)
    model = FloatClusterer(params, 100, 100, T_FRAME)
    # Slot 0: 6 events at (10, 10) -> activity 6 (no decay). Slot 1: 2 events at (50, 50) -> 2.
    model.feed(table_events([(i, 10, 10) for i in range(6)] + [(10 + i, 50, 50) for i in range(2)]))
    assert model.stats()["created"] == 2
    ids_before = model.slots[:, 1].copy()
    # A far event: the table is full; slot 1 (activity 2 < 5) is the least active and is evicted.
    model.feed(table_events([(20, 90, 90)]))
    s = model.stats()
    assert (s["created"], s["evicted"], s["dropped"]) == (3, 1, 0)
    assert model.slots[0, 1] == ids_before[0] and model.slots[1, 1] == 2  # ids 0, 1 then 2
    assert (model.slots[1, 2], model.slots[1, 3]) == (90.0, 90.0)
    # Feed slot 1 up to activity 6: now both are >= a_valid, so the next far event is dropped.
    model.feed(table_events([(21 + i, 90, 90) for i in range(5)]))
    model.feed(table_events([(40, 30, 70)]))
    s = model.stats()
    assert (s["created"], s["evicted"], s["dropped"]) == (3, 1, 1)


def test_ties_go_to_the_lower_slot():
    params = classic_params(n_clusters=4, seek_margin=10.0, filter_every=10**6, r_init=2.0)
    model = FloatClusterer(params, 100, 100, T_FRAME)
    model.feed(table_events([(0, 20, 20), (1, 40, 20)]))  # two clusters, 20 px apart
    model.feed(table_events([(2, 30, 20)]))  # equidistant: L1 10 from both
    # Slot 0 moved towards the event, slot 1 did not.
    assert model.slots[0, 2] > 20.0 and model.slots[1, 2] == 40.0


def test_palette_class_of_a_uniformly_coloured_object_is_its_colour():
    palette = (
        PaletteEntry(name="red", rgb=(210, 40, 40)),
        PaletteEntry(name="green", rgb=(40, 180, 60)),
        PaletteEntry(name="blue", rgb=(40, 60, 200)),
        PaletteEntry(name="floor", rgb=(20, 20, 20)),
    )
    for colour, name in (((210, 40, 40), "red"), ((40, 180, 60), "green"), ((40, 60, 200), "blue")):
        sim, result = run(square_scene([(60, (2.0, 0.0))], colour=colour, bg=(20, 20, 20)), palette=palette, palette_background=("floor",))
        track = single_track(result)
        late = track[track["t_us"] > 20 * T_FRAME]
        classes = {palette[c].name for c in late["class"]}
        assert classes == {name}


def test_p_correction_recovers_the_object_colour_on_a_uniform_background():
    obj, bg = np.array([200.0, 60.0, 40.0]), np.array([30.0, 50.0, 90.0])
    from evclust.colour import rgb_to_ycbcr

    obj_ycc, bg_ycc = rgb_to_ycbcr(obj), rgb_to_ycbcr(bg)
    sim = simulate_toml(square_scene([(120, (2.0, 0.0))], colour=obj, bg=bg))
    # Events carry mixtures e = q·obj + (1 - q)·bg; the cluster's colour mean tends to the mean
    # mixture, so p is the mean q, which the events themselves tell.
    q = (sim.events["Y"].astype(float) - bg_ycc[0]) / (obj_ycc[0] - bg_ycc[0])
    p = float(np.mean(q))
    assert 0.2 < p < 0.9
    params = classic_params(v_min=0.0, p_correction=p, background=tuple(bg_ycc), alpha_lum=0.999, alpha_chro=0.999)
    result = track_events(sim.events, sim.meta, params)
    track = single_track(result)
    late = track[track["t_us"] > 80 * T_FRAME]
    est = np.stack([late["Y"], late["Cb"], late["Cr"]], 1).mean(axis=0)
    assert np.max(np.abs(est - obj_ycc)) <= 2.0


def test_dvs_only_events_run_with_colour_off():
    sim = simulate_toml(square_scene([(40, (2.0, 0.0))]))
    meta = EventMeta(width=sim.meta.width, height=sim.meta.height, source="dvs", t_frame_us=T_FRAME, has_colour=False)
    result = track_events(sim.events, meta, classic_params(v_min=0.0))
    assert result.tracks.size > 0 and not result.meta.has_colour
    assert np.all(result.tracks["class"] == -1) and not result.tracks["Y"].any()


def test_ids_are_unique_and_increasing_in_creation_order():
    sim, result = run(square_scene([(60, (2.0, 0.0))]))
    first_seen = {}
    for row in result.tracks:
        first_seen.setdefault(int(row["id"]), int(row["step"]))
    ids = sorted(first_seen)
    assert [first_seen[i] for i in ids] == sorted(first_seen[i] for i in ids)


@pytest.mark.parametrize(
    "text, fault",
    [
        ("[clusterer]\nalpha_pos = 1.0", "clusterer.alpha_pos"),
        ("[clusterer]\nalpha_lum = -0.1", "clusterer.alpha_lum"),
        ("[clusterer]\nr_min = -2", "clusterer.r_min"),
        ("[clusterer]\npalette = []", "clusterer.palette"),
        ("[clusterer]\nseek_radius = 3", "seek_radius"),
        ('[clusterer]\nn_clusters = "many"', "clusterer.n_clusters"),
        ('[clusterer]\npalette_background = ["sky"]', "sky"),
        ("[clusterer]\nr_init = 100\nr_max = 50", "r_init"),
        ("[cluster]\nn_clusters = 4", "unknown table or key 'cluster'"),
        ("[clusterer\n", "malformed TOML"),
    ],
)
def test_bad_parameter_files_fail_with_one_line(text, fault):
    with pytest.raises(EvclustError) as err:
        parse_params(text, "p.toml")
    assert str(err.value).startswith("p.toml: ") and fault in str(err.value) and "\n" not in str(err.value)
