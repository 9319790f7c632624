"""Tuning over the generalization suite's tuning split (docs/TUNING.md): one configuration for
every scene, chosen on the tuning split only.

The study lives in an optuna RDB storage: SQLite by default, so a search can stop and resume;
a PostgreSQL URL lets workers on many machines join one study. Trials run in parallel on Dask
workers (a local cluster by default, a scheduler address to scale out), each worker holding the
split's events in memory and pulling trials from the shared study.
"""

from __future__ import annotations

import dataclasses
import math
import time
import warnings
from pathlib import Path

from tqdm import tqdm

from evclust.clusterer import ClustererParams
from evclust.errors import EvclustError

# (name, low, high, scale) of each searched parameter; α parameters as β = 1 - α, times in frames.
SUITE_SPACE = (
    ("seek_margin", 1.0, 30.0, "log"),
    ("seek_scale", 0.0, 1.0, "linear"),
    ("r_init", 1.0, 20.0, "log"),
    ("size_gain", 1.0, 2.5, "linear"),
    ("beta_pos", 1e-3, 1e-1, "log"),
    ("beta_size", 1e-3, 1e-1, "log"),
    ("t_half_frames", 0.2, 8.0, "log"),
    ("a_valid", 2.0, 100.0, "log"),
    ("a_min", 0.1, 2.0, "log"),
    ("merge_scale", 0.0, 2.5, "linear"),
    ("merge_v_tol", 0.1, 3.0, "log"),
    ("merge_v_rel", 0.0, 1.0, "linear"),
    ("noise_gate", 0.0, 20.0, "linear"),
    ("v_min", 0.01, 1.0, "log"),
    ("tau_frames", 1.0, 10.0, "log"),
    ("beta_vel_int", 0.05, 0.95, "log"),
    ("beta_vel_mcm", 1e-5, 1e-2, "log"),
    ("beta_lum", 1e-3, 1e-1, "log"),
    ("beta_chro", 1e-3, 1e-1, "log"),
    ("p_correction", 0.3, 1.0, "linear"),
    ("exit_margin", 0.0, 20.0, "linear"),
    ("support_window_frames", 0.005, 1.0, "log"),
    ("gamma", 10.0, 2000.0, "log"),
    # The object layer (clusterer/objects.py).
    ("object_gate", 0.0, 20.0, "linear"),
    ("object_link_along", 0.0, 6.0, "linear"),
    ("object_v_tol", 0.05, 2.0, "log"),
    ("object_v_rel", 0.0, 1.0, "linear"),
    ("object_track_frames", 0.1, 10.0, "log"),
    ("object_rate_frames", 1.0, 50.0, "log"),
    ("object_velocity_frames", 0.1, 20.0, "log"),
    ("object_size_frames", 0.1, 10.0, "log"),
    ("object_colour_frames", 0.1, 20.0, "log"),
    ("object_birth_frames", 0.0, 5.0, "linear"),
    ("object_coast_frames", 0.0, 10.0, "linear"),
    ("object_keep_frames", 1.0, 100.0, "log"),
)
# Scales the fixed model holds in steps of 1/64 (formats.SCALE_FRAC_BITS): searched on that grid,
# so that the float and the fixed model use the same value.
ON_SCALE_GRID = ("seek_scale", "merge_scale", "merge_v_rel", "object_link_along", "object_v_rel")
SUITE_CATEGORICAL = (
    ("merge", (True, False)),
    ("create_support", (True, False)),
    ("support_cell_bits", (0, 1, 2)),
    ("gamma_mode", ("global", "activity", "count")),
    ("palette_vote", ("count", "contrast")),
)


def params_from_values(values: dict, base: ClustererParams) -> ClustererParams:
    update = {}
    for name, value in values.items():
        if name.startswith("beta_"):
            update["alpha_" + name[len("beta_") :]] = 1.0 - value
        else:
            update[name] = value
    update["r_min"] = min(base.r_min, update.get("r_init", base.r_init))
    update["a_min"] = min(update.get("a_min", base.a_min), update.get("a_valid", base.a_valid))
    return ClustererParams.model_validate({**base.model_dump(), **update})


def values_of(p: ClustererParams) -> dict:
    """The search coordinates of a parameter set (β for α; frames as they are given)."""
    values = {}
    for name, lo, _hi, _ in SUITE_SPACE:
        v = 1.0 - getattr(p, "alpha_" + name[len("beta_") :]) if name.startswith("beta_") else getattr(p, name)
        values[name] = v if v is not None else lo
    for name, _ in SUITE_CATEGORICAL:
        values[name] = getattr(p, name)
    return values


def searched(only: str | None = None) -> tuple[tuple, tuple]:
    """The continuous and the categorical parameters searched: all, or those whose names start with `only`."""
    keep = (lambda name: True) if not only else (lambda name: name.startswith(only))
    return tuple(s for s in SUITE_SPACE if keep(s[0])), tuple(s for s in SUITE_CATEGORICAL if keep(s[0]))


def suggest(trial, base: ClustererParams, only: str | None = None) -> ClustererParams:
    space, categorical = searched(only)
    values = {}
    for name, low, high, scale in space:
        step = 1 / 64 if name in ON_SCALE_GRID else None
        values[name] = trial.suggest_float(name, low, high, log=scale == "log", step=step)
    for name, choices in categorical:
        values[name] = trial.suggest_categorical(name, list(choices))
    return params_from_values(values, base)


_EVENTS_CACHE: dict = {}
_CLUSTER_RUNS: dict = {}  # per scene and cluster parameters: a search of the object layer alone runs the clusters once


def split_objective(folder: str, seeds: tuple[int, ...], params: ClustererParams, objects_only: bool = False) -> tuple[float, dict]:
    """The suite objective of one parameter set on the given scenes (their events kept in this
    process between trials), and the pooled figures. `objects_only`: the trials differ only in
    the object layer's parameters, so each scene's clusters are run once and kept."""
    from evclust.suite.aggregate import figures, objective
    from evclust.suite.evaluate import evaluate_scene
    from evclust.suite.prepare import SceneFiles
    from evclust.scenes.generate import scene_name

    runs = _CLUSTER_RUNS if objects_only else None
    results = [evaluate_scene(SceneFiles(scene_name(s), Path(folder)), params, cache=_EVENTS_CACHE, cluster_runs=runs) for s in seeds]
    f = figures(results)
    return objective(f), f


def _worker(
    storage: str, study_name: str, folder: str, seeds, base: ClustererParams, trials: int, seed: int, only: str | None = None
) -> int:
    """One Dask task: pull `trials` trials from the shared study."""
    import optuna

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    warnings.filterwarnings("ignore", category=optuna.exceptions.ExperimentalWarning)  # multivariate TPE
    sampler = optuna.samplers.TPESampler(seed=seed, n_startup_trials=25, multivariate=True, constant_liar=True)
    study = optuna.load_study(study_name=study_name, storage=storage, sampler=sampler)

    def objective(trial):
        value, f = split_objective(folder, seeds, suggest(trial, base, only), objects_only=bool(only) and only.startswith("object_"))
        for key in (
            "HOTA",
            "IDF1",
            "recall",
            "precision",
            "tracks_per_object",
            "position_rel_rmse",
            "interval_nrmse",
            "mcm_nrmse",
            "object_nrmse",
        ):
            trial.set_user_attr(key, f.get(key))
        return value if math.isfinite(value) else 1e9

    study.optimize(objective, n_trials=trials)
    return trials


@dataclasses.dataclass
class SuiteTuneResult:
    params: ClustererParams
    value: float
    trials: int
    study_name: str
    storage: str


def tune_suite(
    client, folder: str | Path, seeds: tuple[int, ...], base: ClustererParams, trials: int, storage: str,
    study_name: str, seed: int = 0, progress: bool = True, only: str | None = None,
) -> SuiteTuneResult:  # fmt: skip
    """Search `trials` more trials of the study (created if new, with `base` as its first trial),
    spread over the client's workers; `only`: just the parameters whose names start with it
    (the rest as in `base`)."""
    if not any(searched(only)):
        raise EvclustError(f"--only {only}: no searched parameter starts with it")
    import optuna

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    if storage.startswith("sqlite:///"):
        Path(storage[len("sqlite:///") :]).parent.mkdir(parents=True, exist_ok=True)
    try:
        study = optuna.create_study(study_name=study_name, storage=storage, direction="minimize", load_if_exists=True)
    except Exception as exc:  # a bad URL, an unreachable database
        raise EvclustError(f"optuna storage {storage}: {exc}") from None
    if not study.trials:
        space, categorical = searched(only)
        names = {s[0] for s in space + categorical}
        study.enqueue_trial(
            {k: v for k, v in values_of(base).items() if k in names}
        )  # the starting point: the search can only improve on it
    workers = max(1, len(client.scheduler_info()["workers"]))
    shares = [trials // workers + (1 if i < trials % workers else 0) for i in range(workers)]
    done_before = len(study.trials)
    futures = [client.submit(_worker, storage, study_name, str(folder), tuple(seeds), base, n, seed + i, only, pure=False)
               for i, n in enumerate(shares) if n]  # fmt: skip
    with tqdm(total=trials, desc=f"tune {study_name}", unit="trial", disable=None if progress else True) as bar:
        while not all(f.done() for f in futures):
            time.sleep(2.0)
            n = len(optuna.load_study(study_name=study_name, storage=storage).trials) - done_before
            bar.update(max(0, min(n, trials) - bar.n))
            try:
                best = study.best_value
                bar.set_postfix(best=f"{best:.3f}")
            except ValueError:
                pass
        for f in futures:
            f.result()  # a worker's exception, raised here
    study = optuna.load_study(study_name=study_name, storage=storage)
    best = params_from_values(study.best_params, base)
    return SuiteTuneResult(best, float(study.best_value), len(study.trials), study_name, storage)
