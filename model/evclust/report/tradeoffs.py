"""What accuracy costs in time: the paper's velocity trade-off measured (interval against MCM,
error against convergence time after a turn), and what each simulator effect costs against
what it does to the events and to the task."""

from __future__ import annotations

import dataclasses
import time
from importlib import resources

import numpy as np

from evclust.clusterer import ClustererParams, load_params
from evclust.run import track_events
from evclust.metrics.convergence import converged_after
from evclust.report.budget import best_velocity_nrmse, scene_scores
from evclust.scenes import scene_from_toml
from evclust.scenes.truth import truth_array
from evclust.simulator import simulate_scene
from evclust.simulator.effects import EFFECTS

# A square turning 90° at constant speed: one leg to settle, one to measure the turn.
FPS = 100.0
T_FRAME = 1e6 / FPS
TURN_FRAME, SPEED = 60, 2.0
TURN_SCENE = f"""
width = 480
height = 480
fps = {FPS}
frames = 201
[sensor]
threshold_on = 0.1
threshold_off = 0.1
[background]
colour = [60, 60, 60]
[[objects]]
id = 1
label = "square"
size = [20, 20]
colour = [240, 240, 240]
start = [40.0, 40.0]
legs = [{{ frames = {TURN_FRAME}, velocity = [{SPEED}, 0.0] }}, {{ frames = 140, velocity = [0.0, {SPEED}] }}]
"""
TAU_FRAMES = 4
SWEEPS = {
    "MCM, γ global": ("mcm", {"gamma_mode": "global"}, "alpha_vel_mcm", (0.999, 0.9995, 0.9998, 0.9999, 0.99995)),
    "MCM, γ activity": ("mcm", {"gamma_mode": "activity"}, "alpha_vel_mcm", (0.999, 0.9995, 0.9998, 0.9999, 0.99995)),
    "MCM, γ count": ("mcm", {"gamma_mode": "count"}, "alpha_vel_mcm", (0.999, 0.9995, 0.9998, 0.9999, 0.99995)),
    "interval (RI)": ("int", {}, "alpha_vel_int", (0.2, 0.4, 0.6, 0.8, 0.9)),
}


@dataclasses.dataclass
class VelocityPoint:
    method: str
    alpha: float
    steady_nrmse: float  # before the turn, once settled, and after the turn, once converged
    convergence_frames: float | None  # after the turn, until within 10 % of the new velocity and staying


def velocity_tradeoff(quick: bool = False, progress=None) -> list[VelocityPoint]:
    sim = simulate_scene(scene_from_toml(TURN_SCENE, "turn"))
    points = []
    for label, (method, fixed, knob, values) in SWEEPS.items():
        for alpha in values[1::2] if quick else values:
            params = ClustererParams(v_min=0.0, alpha_pos=0.995, tau_us=TAU_FRAMES * T_FRAME, **fixed, **{knob: alpha})
            tracks = track_events(sim.events, sim.meta, params).tracks
            ids, counts = np.unique(tracks["id"], return_counts=True)
            track = tracks[tracks["id"] == ids[np.argmax(counts)]]
            t = track["t_us"].astype(float)
            v = np.stack([track[f"vx_{method}"], track[f"vy_{method}"]], 1)
            truth = np.where((t < TURN_FRAME * T_FRAME)[:, None], [SPEED, 0.0], [0.0, SPEED])
            window = max(1, int(sim.events.size / (sim.frames - 1) / params.filter_every))
            after = t > TURN_FRAME * T_FRAME
            settled = converged_after(t[after], v[after], np.array([0.0, SPEED]), 0.1, window)
            delay = None if settled is None else (settled - TURN_FRAME * T_FRAME) / T_FRAME
            steady = ((t > 30 * T_FRAME) & (t < TURN_FRAME * T_FRAME)) | (t > (TURN_FRAME + (delay or 140)) * T_FRAME)
            err = np.linalg.norm(v[steady] - truth[steady], axis=1)
            points.append(VelocityPoint(label, alpha, float(np.sqrt(np.mean(err**2)) / SPEED) if err.size else float("nan"), delay))
            if progress:
                progress()
    return points


@dataclasses.dataclass
class EffectPoint:
    effect: str
    simulate_s: float
    ratio: float  # simulation time over the ideal sensor's, timed alternately in the same run
    events: int
    velocity_nrmse: float | None
    chrominance_nrmse: float | None
    palette_accuracy: float | None


def effect_costs(scene: str = "traffic", progress=None, repeats: int = 2) -> list[EffectPoint]:
    """The scene without effects, then with each effect on at its defaults: simulation time
    (best of `repeats`), its ratio to the ideal sensor's (timed alternately with it, so machine
    load cancels), events, and the task on the scene's preset (the defaults if it has none)."""
    base_text = resources.files("evclust.scenes").joinpath("builtin", f"{scene}.toml").read_text()
    params, _ = load_params(None, scene)  # its preset, or the defaults where it has none
    ideal = scene_from_toml(base_text, f"{scene}+ideal")
    simulate_scene(ideal)  # compile outside the timing
    points = []

    def timed(spec):
        start = time.perf_counter()
        sim = simulate_scene(spec)
        return time.perf_counter() - start, sim

    for effect in (None, *EFFECTS):
        text = base_text if effect is None else base_text + f"\n[effects.{effect}]\n"
        spec = scene_from_toml(text, f"{scene}+{effect or 'ideal'}")
        walls, ideal_walls = [], []
        for _ in range(repeats):
            wall, sim = timed(spec)
            walls.append(wall)
            ideal_walls.append(timed(ideal)[0])
        run = track_events(sim.events, sim.meta, params)
        s = scene_scores(run, truth_array(spec.source.truth()))
        points.append(EffectPoint(effect or "none (ideal sensor)", min(walls), min(walls) / min(ideal_walls), int(sim.events.size), best_velocity_nrmse(s),
                                  s["chrominance"]["nrmse"], s["class_palette_accuracy"]))  # fmt: skip
        if progress:
            progress()
    return points
