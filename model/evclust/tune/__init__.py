"""Parameter search for the clusterer with optuna's TPE sampler (the paper used hyperopt's TPE
over 100 parameter sets on a segment of each video, §6.3).

The objective is one number, a sum of the task errors of SPEC §8 (documented in docs/TUNING.md):
velocity (the better method), angle, position, colour, classification and tracking.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from evclust.clusterer import ClustererParams
from evclust.run import track_events
from evclust.events import EventMeta
from evclust.metrics import score

# (name, low, high, scale) of each searched parameter. α parameters are searched as β = 1 - α on a
# log scale: what matters is the memory 1/β, which spans decades.
SEARCH_SPACE = (
    ("seek_margin", 2.0, 60.0, "linear"),
    ("r_init", 3.0, 40.0, "linear"),
    ("size_gain", 1.0, 4.0, "linear"),
    ("beta_pos", 3e-4, 3e-2, "log"),
    ("beta_size", 1e-3, 5e-2, "log"),
    ("t_half_us", 5e3, 3e5, "log"),
    ("a_valid", 5.0, 300.0, "log"),
    ("beta_vel_mcm", 1e-5, 2e-3, "log"),
    ("beta_vel_int", 0.05, 0.9, "log"),
    ("tau_frames", 1.0, 6.0, "linear"),
    ("beta_lum", 1e-4, 5e-2, "log"),
    ("beta_chro", 1e-4, 5e-2, "log"),
    ("p_correction", 0.2, 1.0, "linear"),
    ("luma_weight", 0.2, 2.0, "linear"),
    ("v_min", 0.0, 2.0, "linear"),
    ("exit_margin", 0.0, 20.0, "linear"),
    ("v_exit", 0.5, 6.0, "linear"),
)
CATEGORICAL = (("gamma_mode", ("global", "activity", "count")), ("palette_vote", ("count", "contrast")))


def params_from_trial(values: dict, base: ClustererParams, t_frame_us: float) -> ClustererParams:
    update = {}
    for name, value in values.items():
        if name.startswith("beta_"):
            update["alpha_" + name[len("beta_") :]] = 1.0 - value
        elif name == "tau_frames":
            update["tau_us"] = float(round(value * t_frame_us))  # whole µs: the hardware counts τ in µs
        else:
            update[name] = value
    update["r_max"] = max(base.r_max, update.get("r_init", base.r_init))
    update["r_min"] = min(base.r_min, update.get("r_init", base.r_init))
    return ClustererParams.model_validate({**base.model_dump(), **update})


def objective_value(s) -> float:
    """The sum minimised by the search; a figure that cannot be computed counts as its worst."""
    d = s.to_dict()

    def get(*keys, worst):
        v = d
        for k in keys:
            v = v.get(k) if isinstance(v, dict) else None
        return worst if v is None or (isinstance(v, float) and math.isnan(v)) else float(v)

    # Both velocity methods count: a search that may sacrifice one of them will.
    velocity = (get("mcm", "nrmse", worst=5.0) + get("interval", "nrmse", worst=5.0)) / 2
    angle = (get("mcm", "angular_deg", worst=90.0) + get("interval", "angular_deg", worst=90.0)) / 2 / 90.0
    position = get("position_rmse_px", worst=50.0) / 20.0
    colour = get("luminance", "nrmse", worst=1.0) + get("chrominance", "nrmse", worst=1.0)
    classes = 2.0 * (1.0 - get("class_palette_accuracy", worst=0.0))
    tracking = (1.0 - get("recall", worst=0.0)) + 0.5 * (1.0 - get("precision", worst=0.0))
    return velocity + angle + position + colour + classes + tracking


@dataclasses.dataclass
class TuneResult:
    params: ClustererParams
    value: float
    trials: int
    study: object


def tune(
    events: np.ndarray, meta: EventMeta, truth: np.ndarray, base: ClustererParams, trials: int = 100,
    seed: int = 0, progress: bool = False,
) -> TuneResult:  # fmt: skip
    import optuna

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    t_frame_us = float(base.t_frame_us or meta.t_frame_us)
    base = base.resolved(t_frame_us)  # the search moves times in µs (τ in frames of this stream)
    start = trial_values(base, t_frame_us)
    # Each range grows to hold the starting value, so the first trial is exactly the base set.
    space = [(n, lo if sc == "log" and start[n] <= 0 else min(lo, start[n]), max(hi, start[n]), sc) for n, lo, hi, sc in SEARCH_SPACE]
    start = {n: min(max(start[n], lo), hi) for n, lo, hi, _ in space} | {n: start[n] for n, _ in CATEGORICAL}

    def objective(trial):
        values = {}
        for name, low, high, scale in space:
            values[name] = trial.suggest_float(name, low, high, log=scale == "log")
        for name, choices in CATEGORICAL:
            values[name] = trial.suggest_categorical(name, choices)
        params = params_from_trial(values, base, t_frame_us)
        run = track_events(events, meta, params)
        return objective_value(score(run.tracks, run.meta, truth))

    sampler = optuna.samplers.TPESampler(seed=seed, n_startup_trials=min(20, trials))
    study = optuna.create_study(direction="minimize", sampler=sampler)
    # The starting point: the base parameters, so the search can only improve on them.
    study.enqueue_trial(start)
    study.optimize(objective, n_trials=trials, show_progress_bar=progress)
    best = params_from_trial(study.best_params, base, t_frame_us)
    return TuneResult(best, float(study.best_value), trials, study)


def trial_values(p: ClustererParams, t_frame_us: float) -> dict:
    """The search coordinates of a parameter set (β on its scale, τ in frames)."""
    values = {}
    for name, _, _, _ in SEARCH_SPACE:
        if name.startswith("beta_"):
            values[name] = 1.0 - getattr(p, "alpha_" + name[len("beta_") :])
        elif name == "tau_frames":
            values[name] = p.tau_us / t_frame_us
        else:
            values[name] = getattr(p, name)
    for name, _ in CATEGORICAL:
        values[name] = getattr(p, name)
    return values


def segment(events: np.ndarray, truth: np.ndarray, fraction: float) -> tuple[np.ndarray, np.ndarray]:
    """The first `fraction` of the stream's duration, and the truth rows inside it."""
    if events.size == 0 or fraction >= 1.0:
        return events, truth
    t0, t1 = int(events["t"][0]), int(events["t"][-1])
    end = t0 + fraction * (t1 - t0)
    keep = events["t"] <= end
    return events[keep], truth[truth["t_us"] <= end]


def params_to_toml(p: ClustererParams, header: str = "") -> str:
    """A `[clusterer]` table a person can read: scalars through tomli_w, short arrays and the
    palette inline, one entry a line."""
    import json

    import tomli_w

    lines = ["[clusterer]"]
    for key, value in p.model_dump(mode="json", exclude_none=True).items():
        if key == "palette":
            entries = [f"  {{ name = {json.dumps(e['name'])}, rgb = [{', '.join(f'{c:g}' for c in e['rgb'])}] }}," for e in value]
            lines += ["palette = [", *entries, "]"]
        elif isinstance(value, list):
            lines.append(f"{key} = [{', '.join(json.dumps(v) for v in value)}]")
        else:
            lines.append(tomli_w.dumps({key: value}).strip())
    return (header + "\n" if header else "") + "\n".join(lines) + "\n"
