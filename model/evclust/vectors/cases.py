"""The vector cases: clips of built-in scenes and directed hard cases.

Each builder returns the events and what the run needs. Clip windows were found once by search
(the smallest clip from which the fixed model creates clusters and predicts an exit); the scenes
are deterministic, so the slices stay valid.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np

from evclust.choices import FRAMELESS_PERIOD_US
from evclust.clusterer import ClustererParams, PaletteEntry, load_params
from evclust.events import EVENT_DTYPE
from evclust.scenes import load_scene
from evclust.simulator import simulate_scene


@dataclasses.dataclass
class Case:
    description: str
    events: np.ndarray
    width: int
    height: int
    t_frame_us: float
    params: ClustererParams
    source: str
    seed: int = 0
    formats: dict = dataclasses.field(default_factory=dict)  # build_formats's knobs, for a narrowed build


def _events(rows) -> np.ndarray:
    ev = np.zeros(len(rows), EVENT_DTYPE)
    for i, row in enumerate(rows):
        t, x, y, lum, cb, cr = row
        ev[i] = (t, x, y, 1, lum, cb, cr)
    return ev


def _clip(scene: str, start: int, count: int, what: str) -> Case:
    sim = simulate_scene(load_scene(scene))
    params, _ = load_params(scene)
    return Case(
        f"{count} events of the built-in `{scene}` scene from event {start}: {what}",
        sim.events[start : start + count], sim.meta.width, sim.meta.height, sim.meta.t_frame_us, params, scene,
        load_scene(scene).spec.seed,
    )  # fmt: skip


SMALL = dict(width=64, height=48, t_frame_us=10_000.0)


# The parameters the directed cases were written with: the defaults of before the
# one-cluster-per-object additions, which each case switches on itself when it tests one.
_WRITTEN_WITH = dict(
    r_min=2.0, size_gain=1.5, alpha_pos=0.98, alpha_size=0.99, a_min=1.0, alpha_vel_mcm=0.9999, gamma_mode="count",
    alpha_vel_int=0.7, alpha_lum=0.99, alpha_chro=0.99, p_correction=1.0, exit_margin=10.0,
    seek_scale=0.0, merge=False, noise_gate=0.0, create_support=False,
)  # fmt: skip


def _small_params(**update) -> ClustererParams:
    base = dict(v_min=0.0, a_valid=3.0, filter_every=8, r_init=4.0, r_max=16.0, seek_margin=4.0, t_half_us=20_000.0, tau_us=20_000.0)
    return ClustererParams(**{**_WRITTEN_WITH, **base, **update})


def traffic_clip() -> Case:
    return _clip("traffic", 134900, 12000, "creations, filter steps, reported tracks and an exit prediction")


def pedestrian_clip() -> Case:
    return _clip("pedestrian", 77778, 9000, "creations, filter steps, reported tracks and an exit prediction")


def timestamp_wrap() -> Case:
    # A blob drifting right; its timestamps cross 2^32 µs in the middle.
    rng = np.random.default_rng(11)
    t0 = (1 << 32) - 600 * 50
    rows = [(t0 + 50 * i, 10 + i // 40 + int(rng.integers(-2, 3)), 24 + int(rng.integers(-2, 3)), 180, 100, 150) for i in range(1200)]
    return Case(
        "a drifting blob whose 32-bit timestamps wrap in the middle of the stream",
        _events(rows),
        **SMALL,
        params=_small_params(),
        source="directed",
    )


def table_full() -> Case:
    # Six spots for a four-slot table: evictions while the old clusters are weak, drops once all are strong.
    spots = [(5, 5), (58, 5), (5, 42), (58, 42), (32, 24), (20, 30)]
    rows = []
    t = 1000
    for rnd in range(12):
        for j, (x, y) in enumerate(spots):
            for _ in range(3 + 2 * (j % 2) + rnd):
                rows.append((t, x, y, 200, 128, 128))
                t += 7
    return Case("six spots fighting for a four-slot table: creations, evictions and drops", _events(rows), **SMALL,
                params=_small_params(n_clusters=4, a_valid=6.0, t_half_us=2000.0), source="directed")  # fmt: skip


def saturating_corners() -> Case:
    corners = [(0, 0), (63, 0), (0, 47), (63, 47)]
    rows = [(1000 + 2 * i, *corners[i % 4], 255 * (i % 2), 255 * ((i // 2) % 2), 0) for i in range(2000)]
    return Case("events at the four corners with extreme colours", _events(rows), **SMALL, params=_small_params(), source="directed")


def saturation_counts() -> Case:
    # A build with narrow event counters (activity UQ8.8, events in a τ UQ6.0) and γ from the
    # activity (ln2·T_frame/T_half = 69 events/frame per unit): a burst of 400 events at one
    # microsecond saturates the activity and the τ count, then γ at the next filter step. Then
    # events alternating 34 px apart in a window of R + S = 37 px with β_P = 0.5: the first
    # centre step (17 px) saturates high, every γ·step after it (γ ~10^4) saturates the MCM input,
    # and the centre's swings over τ = 2 ms at T_frame/τ = 100 saturate the interval velocity.
    rows = [(1000, 44 + i % 3, 36 + i % 2, 200, 90, 160) for i in range(400)]
    rows += [(1500 + 20 * i, 5 if i % 2 == 0 else 39, 20, 200, 90, 160) for i in range(600)]
    # The same mirrored, after 100 ms in which the others expire: the first step saturates low.
    rows += [(113_500 + 20 * i, 58 if i % 2 == 0 else 24, 8, 200, 90, 160) for i in range(600)]
    params = _small_params(alpha_pos=0.5, r_init=30.0, r_max=31.0, seek_margin=7.0, exit_margin=1.0, gamma_mode="activity",
                           t_half_us=2000.0, tau_us=2000.0, alpha_vel_mcm=0.99, n_clusters=4)  # fmt: skip
    return Case("narrow event counters and a 1 s frame period: the activity, the events in a τ, γ, the centre step, the MCM "
                "input and the interval velocity saturate", _events(rows), 64, 48, 200_000.0, params, "directed",
                formats={"activity_bits": 8, "interval_count_bits": 6})  # fmt: skip


def saturation_mcm() -> Case:
    # Spots racing 8 px per event right, down, left and up, γ = 4095 (global) and β_vm = 2^-17,
    # which leaves V_MCM 14 integer bits: every γ·step saturates the MCM input from a cluster's
    # first update, so V/w, the bias-corrected velocity, lands on or past the format's end (top
    # or bottom, x or y) and saturates too. Each run starts ~30 px from where the last ended, after
    # 150 ms of silence (7.5 half-lives): the last run's cluster expires at the first filter step,
    # and each run is a new cluster whose velocity has one sign.
    paths = (
        [(x, 8) for x in range(2, 61, 8)], [(30, y) for y in range(2, 47, 8)],
        [(x, 40) for x in range(60, 1, -8)], [(30, y) for y in range(46, 1, -8)],
    )  # fmt: skip
    rows, t = [], 1000
    for run in range(40):
        for x, y in paths[run % 4]:
            rows.append((t, x, y, 200, 90, 160))
            t += 50
        t += 150_000
    params = _small_params(alpha_pos=0.5, r_init=12.0, seek_margin=4.0, exit_margin=1.0, gamma_mode="global", gamma=4095.0,
                           alpha_vel_mcm=1 - 2**-17, n_clusters=4, filter_every=4)  # fmt: skip
    return Case("spots racing at 8 px per event in four directions with γ = 4095: the MCM input and the bias-corrected MCM velocity "
                "saturate; each run's cluster expires in the silence after it", _events(rows), **SMALL, params=params,
                source="directed")  # fmt: skip


def expire_evict_recreate() -> Case:
    # A two-slot table, T_half = 2 ms. Spots A and B fill it; after 6 ms of silence C evicts the
    # weaker; after 40 ms more, D evicts C (the table is still full: expiry waits for a filter
    # step), the filter step then expires B, and A returns into B's freed slot; E finds both
    # slots strong and is dropped.
    rows, t = [], 1000

    def spot(x, y, count):
        nonlocal t
        for i in range(count):
            rows.append((t, x + i % 2, y + i // 2 % 2, 200, 90, 160))
            t += 10

    spot(10, 10, 48)
    spot(50, 10, 48)
    t += 6000
    spot(30, 38, 48)
    t += 40_000
    for x, y in ((10, 38), (10, 10), (50, 38)):
        spot(x, y, 24)
    return Case("a two-slot table: evictions of a weak cluster, an expiry, a re-creation in the freed slot, then drops", _events(rows),
                **SMALL, params=_small_params(n_clusters=2, t_half_us=2000.0, a_valid=6.0), source="directed")  # fmt: skip


def one_pixel() -> Case:
    rows = [(1000 + (i // 10), 31, 23, 40 + (i % 200), 128, 128) for i in range(3000)]
    return Case("every event on one pixel, ten per microsecond", _events(rows), **SMALL, params=_small_params(), source="directed")


def bursts() -> Case:
    rows = []
    t = 1000
    for burst in range(10):
        rows += [(t, 20 + burst, 20, 200, 110, 140)] * 200  # 200 events with Δt = 0
        t += 5000
    return Case("bursts of 200 events at the same microsecond", _events(rows), **SMALL, params=_small_params(), source="directed")


def gaps() -> Case:
    rows = []
    t = 1000
    for k in range(6):
        rows += [(t + i, 30 + k, 20, 150, 128, 128) for i in range(64)]
        # Three seconds of silence (150 tau boundaries), once 45 minutes: more boundaries than
        # T_frame / (n tau) resolves (2^FRAME_PER_TAU_W), so the frame period per boundary is 0.
        t += 2_700_000_000 if k == 3 else 3_000_000
    return Case("clusters separated by gaps of three seconds and one of 45 minutes", _events(rows), **SMALL, params=_small_params(),
                source="directed")  # fmt: skip


def borders() -> Case:
    rows = []
    t = 1000
    for i in range(1600):
        x = min(63, i // 20)  # a blob sliding along the top edge to the right border
        rows.append((t, x, int(i % 3), 220, 90, 170))
        t += 40
    return Case("a blob along the top border that leaves through the right border", _events(rows), **SMALL,
                params=_small_params(exit_margin=6.0, v_exit=0.2), source="directed")  # fmt: skip


def palette_tie() -> Case:
    palette = (PaletteEntry(name="low", rgb=(100, 100, 100)), PaletteEntry(name="high", rgb=(140, 140, 140)))
    rows = [(1000 + 5 * i, 30 + (i % 5), 20 + (i % 3), 120, 128, 128) for i in range(800)]  # Y = 120: equidistant
    return Case("event colours exactly between two palette entries: the tie goes to the lower index", _events(rows), **SMALL,
                params=_small_params(palette=palette, palette_assign="nearest", palette_vote="count", background=(0.0, 128.0, 128.0)),
                source="directed")  # fmt: skip


def no_class() -> Case:
    # Contrast votes against a fixed background: a blob of the background's own colour casts
    # votes of 0, so its histogram stays empty and its records carry no class (-1); a second blob
    # of another colour is classed as usual.
    rows = []
    for i in range(800):
        own = i % 2 == 0
        rows.append((1000 + 5 * i, (15 if own else 45) + i % 3, 24 + (i // 3) % 3, *((128, 128, 128) if own else (200, 90, 160))))
    return Case("a blob of the background's colour: contrast votes of 0, records with no class", _events(rows), **SMALL,
                params=_small_params(palette_vote="contrast", background=(128.0, 128.0, 128.0)), source="directed")  # fmt: skip


def _bar(x0: float, speed: float, steps: int, dt: int, rows: range, length: int, t0: int = 1000):
    """Events of a uniform bar `length` px long moving right at `speed` px per step: its leading
    and trailing edges only, one event per edge pixel and step (a uniform object's events)."""
    out = []
    for i in range(steps):
        lead = int(round(x0 + speed * i))
        for y in rows:
            out.append((t0 + dt * i, lead, y, 200, 90, 160))
            out.append((t0 + dt * i, lead - length, y, 200, 90, 160))
    return out


def merge_edges() -> Case:
    # A 24 px bar: its two edges start two clusters, which merge once their interval velocities,
    # measured over 2 ms (the warm-up's running mean, α_vel_int = 0.9), agree (the reach of
    # merge_scale·max(R) spans the bar).
    rows = _bar(x0=30, speed=0.25, steps=120, dt=100, rows=range(18, 30), length=24)
    return Case("the two edges of a uniform bar: two clusters, merged once their velocities agree", _events(rows), **SMALL,
                params=_small_params(merge=True, merge_scale=2.0, merge_v_tol=2.0, merge_v_rel=0.25, r_init=2.0, seek_margin=2.0,
                                     size_gain=2.0, tau_us=2000.0, t_half_us=5000.0, alpha_vel_int=0.9), source="directed")  # fmt: skip


def merge_overlap() -> Case:
    # Two blobs side by side grow until their boxes overlap; young (no velocity measured yet),
    # they merge on the overlap alone. The later blob is the more active: it survives.
    rng = np.random.default_rng(5)
    rows = []
    for i in range(900):
        left = i % 3 == 0
        cx = 22 if left else 38
        rows.append((1000 + 4 * i, cx + int(rng.integers(-5, 6)), 24 + int(rng.integers(-5, 6)), 120 if left else 220, 128, 128))
    return Case("two growing blobs whose boxes come to overlap: a merge on overlap, the more active survives", _events(rows), **SMALL,
                params=_small_params(merge=True, merge_scale=0.0, r_init=2.0, seek_margin=1.0, size_gain=2.0, tau_us=1_000_000.0),
                source="directed")  # fmt: skip


def scaled_seek() -> Case:
    # Events spread over a 30 px square reach a cluster whose margin grows with its size.
    rng = np.random.default_rng(8)
    rows = [(1000 + 3 * i, 32 + int(rng.integers(-15, 16)), 24 + int(rng.integers(-15, 16)), 180, 100, 150) for i in range(1500)]
    return Case("a wide blob caught by a seek margin that grows with the cluster", _events(rows), **SMALL,
                params=_small_params(seek_scale=0.75, seek_margin=1.0, r_init=2.0, size_gain=1.5), source="directed")  # fmt: skip


def noise_gate() -> Case:
    # A dense blob in sparse noise: the noise gate reports the blob, not the noise clusters.
    rng = np.random.default_rng(9)
    rows = []
    for i in range(3000):
        if i % 4 == 0:
            rows.append((1000 + 2 * i, 40 + int(rng.integers(-3, 4)), 20 + int(rng.integers(-3, 4)), 230, 100, 140))
        else:
            rows.append((1000 + 2 * i, int(rng.integers(0, 64)), int(rng.integers(0, 48)), 90, 128, 128))
    return Case("a dense blob in noise: clusters reported only above noise_gate times the background's activity", _events(rows), **SMALL,
                params=_small_params(noise_gate=6.0, a_valid=2.0, r_init=3.0, seek_margin=3.0, n_clusters=8), source="directed")  # fmt: skip


def creation_support() -> Case:
    # Isolated noise events create nothing; events with a neighbour within 300 µs start clusters.
    rng = np.random.default_rng(10)
    rows = []
    t = 1000
    for i in range(1500):
        if i % 5 == 0:  # a small cluster of events: supported by its neighbours
            rows.append((t, 12 + int(rng.integers(0, 3)), 12 + int(rng.integers(0, 3)), 200, 128, 128))
        else:
            rows.append((t, int(rng.integers(0, 64)), int(rng.integers(0, 48)), 60, 128, 128))
        t += 37
    return Case("isolated events find no support; neighbouring ones start a cluster (2x2 px cells, 300 µs)", _events(rows), **SMALL,
                params=_small_params(create_support=True, support_cell_bits=1, support_window_us=300.0), source="directed")  # fmt: skip


# ---------------------------------------------------------------------------------------------
# The object layer's cases: blobs whose paths give each behaviour in a few hundred events. The
# object layer's times are short (birth 1 frame, coast 2, keep 6) so that each shows within a
# case; the clusters have measured velocities after τ = 2 frames. A filter step every 16 events
# (a few per frame) gives the object layer all the steps it needs, at half the RTL cycles of 8.

OBJECT_SMALL = dict(width=96, height=64, t_frame_us=10_000.0)


def _object_params(**update) -> ClustererParams:
    base = dict(filter_every=16, t_half_us=4000.0, object_gate=2.0, object_link_along=3.0, object_v_tol=0.4, object_v_rel=0.3, object_track_frames=1.0,
                object_rate_frames=3.0, object_velocity_frames=2.0, object_size_frames=1.0, object_colour_frames=1.0,
                object_birth_frames=1.0, object_coast_frames=2.0, object_keep_frames=6.0, n_objects=8)  # fmt: skip
    return _small_params(**{**base, **update})


def _blobs(paths, t_end: int, dt: int = 50, radius: int = 2, seed: int = 0, t0: int = 1000) -> np.ndarray:
    """Events of blobs: each path a list of legs (t_from, t_to, x, y, vx, vy, colour), positions
    in px at t_from and velocities in px per frame (OBJECT_SMALL's 10 ms); every dt µs, one event
    of each blob alive, within `radius` px of its centre, in turn."""
    rng = np.random.default_rng(seed)
    rows = []
    for t in range(t0, t_end, dt):
        for legs in paths:
            for t_from, t_to, x, y, vx, vy, colour in legs:
                if t_from <= t < t_to:
                    frames = (t - t_from) / OBJECT_SMALL["t_frame_us"]
                    cx, cy = x + vx * frames + rng.integers(-radius, radius + 1), y + vy * frames + rng.integers(-radius, radius + 1)
                    if 0 <= cx < OBJECT_SMALL["width"] and 0 <= cy < OBJECT_SMALL["height"]:
                        rows.append((t, int(round(cx)), int(round(cy)), *colour))
    return _events(rows)


RED, BLUE, GREEN = (80, 90, 220), (60, 200, 110), (150, 60, 70)


def object_two_edges() -> Case:
    # A uniform bar 12 px long moving right at 2 px/frame: its leading and trailing edges make
    # clusters (no merging), which the object layer groups into one object by their common
    # motion, the link reaching along it.
    rows = _bar(x0=30, speed=0.05, steps=800, dt=250, rows=range(22, 30), length=12)
    return Case("the two edges of a uniform bar: clusters on each edge, one object (the link along their motion)", _events(rows),
                **OBJECT_SMALL, params=_object_params(r_init=2.0, seek_margin=2.0, size_gain=2.0, alpha_vel_int=0.7), source="directed")  # fmt: skip


def object_split() -> Case:
    # Two blobs side by side move together (one object), then part: one keeps the object, the
    # other starts its own.
    a = [(1000, 60_000, 20, 30, 1.0, 0.0, RED), (60_000, 160_000, 26, 30, 1.0, -1.5, RED)]
    b = [(1000, 60_000, 26, 30, 1.0, 0.0, RED), (60_000, 160_000, 32, 30, 1.0, 1.5, RED)]
    return Case("two blobs moving as one object, then parting: the object splits", _blobs([a, b], 160_000, seed=1), **OBJECT_SMALL,
                params=_object_params(r_init=3.0), source="directed")  # fmt: skip


def object_crossing() -> Case:
    # Two blobs on crossing paths with opposite velocities: two objects. Where the blobs meet,
    # the clusters take each other's events (the seek's nearest cluster), and the objects follow
    # their clusters: the case exercises the crossing, whatever the identities do.
    a = [(1000, 400_000, 20, 20, 1.0, 0.2, RED)]
    b = [(1000, 400_000, 70, 26, -1.0, 0.0, BLUE)]
    return Case("two blobs crossing with opposite velocities: two objects, each following its cluster through the crossing",
                _blobs([a, b], 400_000, dt=100, seed=2),
                **OBJECT_SMALL, params=_object_params(r_init=3.0), source="directed")  # fmt: skip


def object_turn() -> Case:
    # A blob that turns by 90° and then back: one object, its velocity following the turns.
    legs = [(1000, 60_000, 10, 50, 1.2, 0.0, GREEN), (60_000, 120_000, 17.08, 50, 0.0, -1.2, GREEN),
            (120_000, 180_000, 17.08, 42.92, 1.2, 0.0, GREEN)]  # fmt: skip
    return Case("a blob turning by 90° and back: one object, its velocity turning", _blobs([legs], 180_000, seed=3), **OBJECT_SMALL,
                params=_object_params(r_init=3.0), source="directed")  # fmt: skip


def object_occlusion() -> Case:
    # A blob moving right goes silent for 30 ms (an occluder) and reappears further along: its
    # cluster expires, its object coasts (a static blob's events keep the filter steps coming),
    # drops out of the records after 2 frames, and takes the new cluster when it comes: the same
    # identity.
    legs = [(1000, 70_000, 10, 30, 1.0, 0.0, BLUE), (100_000, 200_000, 20, 30, 1.0, 0.0, BLUE)]
    still = [(1000, 200_000, 80, 50, 0.0, 0.0, RED)]  # a static blob: its events keep the filter steps coming
    return Case("a blob hidden for 3 frames: its cluster expires, its object coasts and keeps its identity", _blobs([legs, still], 200_000, dt=100, seed=4),
                **OBJECT_SMALL, params=_object_params(r_init=3.0), source="directed")  # fmt: skip


def object_birth_death() -> Case:
    # Three blobs one after another for a two-slot object table: each is born after a frame,
    # dies when it stops (its object kept 6 frames, unreported after 2), and the third takes the
    # slot of the first, lost; a flash of 3 ms starts a tentative object that is never reported.
    a = [(1000, 60_000, 15, 15, 0.8, 0.5, RED)]
    b = [(30_000, 120_000, 70, 20, -0.8, 0.6, GREEN)]
    flash = [(60_000, 63_000, 40, 55, 0.0, 0.0, BLUE)]
    c = [(100_000, 260_000, 20, 50, 0.7, -0.6, BLUE)]
    return Case("births, deaths, a flash never confirmed, and a lost object's slot taken in a two-slot object table",
                _blobs([a, b, flash, c], 300_000, seed=5), **OBJECT_SMALL,
                params=_object_params(r_init=3.0, n_objects=2), source="directed")  # fmt: skip


def object_merge() -> Case:
    # A textured object as two patches that start apart: two objects, until the second's centre
    # lies in the first's box: the older absorbs it.
    a = [(1000, 150_000, 30, 30, 0.5, 0.0, RED)]
    b = [(20_000, 150_000, 36, 31, 0.5, 0.0, RED)]
    return Case("an object's second patch starts its own object, then lies inside the first: absorbed", _blobs([a, b], 150_000, radius=3,
                seed=6), **OBJECT_SMALL, params=_object_params(r_init=4.0, object_gate=0.0, object_link_along=0.0), source="directed")  # fmt: skip


def suite_clip() -> Case:
    # A clip of a generalization-suite scene through the default configuration: scaled seek,
    # merging, the noise gate and the warm-up of the interval velocity together.
    from evclust.scenes.generate import generate_scene, scene_name
    from evclust.scenes import Scene
    from evclust.scenes.synthetic import SyntheticSource

    seed = 27  # clean (an odd seed): no codec between the renders and the sensor; 14 objects at 60 fps
    spec = generate_scene(seed).spec
    sim = simulate_scene(Scene(spec, SyntheticSource(spec, Path("."), scene_name(seed))))
    return Case(f"10000 events of the suite's scene {scene_name(seed)} (tuning split) through the default configuration: "
                "merges, the noise gate, the interval warm-up", sim.events[40_000:50_000], sim.meta.width, sim.meta.height,
                sim.meta.t_frame_us, ClustererParams(), f"evclust scenes --generate {seed}", seed)  # fmt: skip


def _pipelined(case: Case, what: str, delay: int) -> Case:
    """A case with the pipeline semantics of a core that commits each update `delay` events later
    (update_delay, docs/DESIGN.md "Pipeline semantics")."""
    return dataclasses.replace(case, description=f"{case.description}; update_delay = {delay}: {what}",
                               params=case.params.model_copy(update={"update_delay": delay}))  # fmt: skip


def pipelined_traffic() -> Case:
    return _pipelined(traffic_clip(), "every update committed two events later (its second half a stage behind), creations "
                                      "split around a commit, two commits draining before each filter step", delay=2)  # fmt: skip


def pipelined_table_full() -> Case:
    return _pipelined(table_full(), "evictions and drops with an update in flight", delay=1)


def pipelined_eviction_voids() -> Case:
    # One slot. A spot's last two updates are still in flight when, after 8 ms of silence, a far
    # event evicts the spot's weak cluster: both updates are void, and the new cluster starts clean.
    rows, t = [], 1000
    for x, y, count, gap in ((10, 10, 40, 8000), (50, 38, 40, 8000), (20, 30, 40, 0)):
        for i in range(count):
            rows.append((t, x + i % 2, y + i // 2 % 2, 200, 90, 160))
            t += 10
        t += gap
    return Case("a one-slot table whose cluster is evicted while its last two updates are in flight, twice; update_delay = 2",
                _events(rows), **SMALL, params=_small_params(n_clusters=1, t_half_us=2000.0, a_valid=6.0, filter_every=64,
                                                             update_delay=2), source="directed")  # fmt: skip


def _referenced(case: Case, what: str, delay: int | None = None) -> Case:
    """A case with the activity kept against a reference time (activity_reference, docs/DESIGN.md
    "Activity against a reference time"), at the case's own update delay or `delay`."""
    update = {"activity_reference": True} | ({} if delay is None else {"update_delay": delay})
    return dataclasses.replace(case, description=f"{case.description}; activity_reference: {what}",
                               params=case.params.model_copy(update=update))  # fmt: skip


def reference_suite_clip() -> Case:
    return _referenced(suite_clip(), "every event adds its weight, each filter step decays every activity once (merges read "
                                     "the absorbed slot decayed, the noise gate the background's decayed activity)")  # fmt: skip


def reference_pipelined_traffic() -> Case:
    return _referenced(pipelined_traffic(), "the weights travel with the updates in flight")


def reference_table_full() -> Case:
    return _referenced(pipelined_table_full(), "the weakest slot is the least Ã, evicted when Ã < A_valid times the event's weight")


def reference_moves() -> Case:
    # Two spots at a time out of five, pausing for 3 to 12 half-lives between filter steps: the
    # event after a long pause first moves the reference (draining the two updates in flight), so
    # Ã keeps within its headroom. The four-slot table evicts, and the noise gate reads the
    # background's activity.
    rng = np.random.default_rng(12)
    spots = [(8, 8), (56, 8), (8, 40), (56, 40), (32, 24)]
    rows, t = [], 1000
    for burst in range(30):
        pair = (spots[burst % 5], spots[(burst + 2) % 5])
        for i in range(20 + 7 * (burst % 3)):
            x, y = pair[i % 2]
            rows.append((t, x + int(rng.integers(-2, 3)), y + int(rng.integers(-2, 3)), 200, 90, 160))
            t += 15
        t += 2000 * (3 + 3 * (burst % 4))  # 3, 6, 9 or 12 half-lives of 2 ms
    return Case("two of five spots at a time, pausing 3 to 12 half-lives between filter steps; activity_reference, "
                "update_delay = 2: the event after a long pause moves the reference first, draining the updates in flight; "
                "evictions from a full table; the noise gate", _events(rows), **SMALL,
                params=_small_params(n_clusters=4, t_half_us=2000.0, a_valid=3.0, a_min=0.25, filter_every=64, noise_gate=2.0,
                                     activity_reference=True, update_delay=2), source="directed")  # fmt: skip


def file_case(path: str | Path, max_events: int, params: ClustererParams, t_frame_us: float | None = None) -> Case:
    """The first `max_events` events of any event file, as a case a team replays against the RTL."""
    from evclust.errors import EvclustError
    from evclust.events import EventReader, concat_events

    reader = EventReader(path)
    meta = reader.meta
    if not meta.has_colour:
        raise EvclustError(
            f"{path}: DVS-only events (no colour): the RTL is built with the colour datapath, so its vectors need "
            "colour events; track the file with the float or fixed model instead"
        )
    t_frame_us = t_frame_us or params.t_frame_us or meta.t_frame_us or FRAMELESS_PERIOD_US  # as `track` takes it
    pieces, n = [], 0
    for chunk in reader.chunks():
        pieces.append(chunk[: max_events - n])
        n += pieces[-1].size
        if n >= max_events:
            break
    events = concat_events(pieces)
    if events.size == 0:
        raise EvclustError(f"{path}: no events")
    return Case(f"the first {events.size} events of {Path(path).name}", events, meta.width, meta.height,
                float(t_frame_us), params, str(path))  # fmt: skip


CASES = {
    "traffic_clip": traffic_clip,
    "pedestrian_clip": pedestrian_clip,
    "timestamp_wrap": timestamp_wrap,
    "table_full": table_full,
    "saturating_corners": saturating_corners,
    "saturation_counts": saturation_counts,
    "saturation_mcm": saturation_mcm,
    "expire_evict_recreate": expire_evict_recreate,
    "one_pixel": one_pixel,
    "bursts": bursts,
    "gaps": gaps,
    "borders": borders,
    "palette_tie": palette_tie,
    "no_class": no_class,
    "merge_edges": merge_edges,
    "merge_overlap": merge_overlap,
    "scaled_seek": scaled_seek,
    "noise_gate": noise_gate,
    "creation_support": creation_support,
    "suite_clip": suite_clip,
    "object_two_edges": object_two_edges,
    "object_split": object_split,
    "object_crossing": object_crossing,
    "object_turn": object_turn,
    "object_occlusion": object_occlusion,
    "object_birth_death": object_birth_death,
    "object_merge": object_merge,
    "pipelined_traffic": pipelined_traffic,
    "pipelined_table_full": pipelined_table_full,
    "pipelined_eviction_voids": pipelined_eviction_voids,
    "reference_suite_clip": reference_suite_clip,
    "reference_pipelined_traffic": reference_pipelined_traffic,
    "reference_table_full": reference_table_full,
    "reference_moves": reference_moves,
}
