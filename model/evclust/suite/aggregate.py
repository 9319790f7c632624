"""Figures over many scenes: pooled counts (not means of per-scene ratios), overall and per
category (docs/GENERALIZATION.md).

Object categories come from the ground truth and the generator: small or large (larger side
under SMALL_PX), slow or fast (mean speed under SLOW_PX_PER_FRAME), uniform or textured. Scene
categories: codec or clean, with or without sensor noise. Precision and the TrackEval figures
are properties of a scene's whole output, so they are given per scene category only.
"""

from __future__ import annotations

import numpy as np

from evclust.metrics import tracking
from evclust.tracks import VELOCITY_METHODS

VELOCITY_METHOD_NAMES = tuple(name for methods in VELOCITY_METHODS.values() for name, _, _ in methods)

SMALL_PX = 32.0
SLOW_PX_PER_FRAME = 1.0

OBJECT_CATEGORIES = {
    "small": lambda o, f: o.size < SMALL_PX, "large": lambda o, f: o.size >= SMALL_PX,
    "slow": lambda o, f: o.speed < SLOW_PX_PER_FRAME, "fast": lambda o, f: o.speed >= SLOW_PX_PER_FRAME,
    "uniform": lambda o, f: not f["textured"], "textured": lambda o, f: f["textured"],
}  # fmt: skip
SCENE_CATEGORIES = {
    "codec": lambda r: r.facts["codec"], "clean": lambda r: not r.facts["codec"],
    "noise": lambda r: r.facts["noise"], "no noise": lambda r: not r.facts["noise"],
}  # fmt: skip


def _object_facts(result) -> dict:
    return {o["id"]: o for o in result.facts["objects"]}


def _tracks_per_object(matches_per_scene) -> float | None:
    """Distinct track ids matched to each object (ids are per scene), averaged over the objects."""
    counts = [np.unique(m["track_id"][m["gt_id"] == g]).size for m in matches_per_scene for g in np.unique(m["gt_id"])]
    return float(np.mean(counts)) if counts else None


def figures(results, objects=None, trackeval: bool = True) -> dict:
    """Pooled figures of `results` (SceneResult); with `objects` (a predicate on an object's
    ObjectSummary and its generator facts), over those objects only, without precision."""
    kept_matches = []
    n_objects = n_samples = n_records = 0
    for r in results:
        facts = _object_facts(r)
        keep = {i for i, o in r.objects.items() if objects is None or objects(o, facts[i])}
        n_objects += len(keep)
        n_samples += sum(r.objects[i].samples for i in keep)
        n_records += r.n_records
        kept_matches.append(r.matches[np.isin(r.matches["gt_id"], sorted(keep))])
    kind = results[0].meta.kind if results else "clusters"
    matches = np.concatenate(kept_matches) if kept_matches else np.zeros(0, tracking.match_fields(kind))
    out = {
        "scenes": len(results),
        "objects": n_objects,
        "recall": matches.size / n_samples if n_samples else None,
        "precision": matches.size / n_records if n_records and objects is None else None,
        "tracks_per_object": _tracks_per_object(kept_matches),
    }
    if objects is None and results and trackeval:
        out |= tracking.headline(tracking.combine_sequences([r.trackeval for r in results]))
    if results:
        out |= tracking.accuracy(matches, results[0].meta)
    return out


def best_velocity(f: dict) -> dict:
    """The better velocity method's figures (lower NRMSE, lower angle; each on its own) of a
    figures dict, over the methods its records have: best_velocity_nrmse, best_angle_deg and
    their _steady forms."""

    def low(figure):
        vals = [f.get(f"{m}_{figure}") for m in VELOCITY_METHOD_NAMES if f.get(f"{m}_{figure}") is not None]
        return min(vals) if vals else None

    return f | {
        "best_velocity_nrmse": low("nrmse"), "best_angle_deg": low("angle_deg"),
        "best_velocity_nrmse_steady": low("nrmse_steady"), "best_angle_deg_steady": low("angle_deg_steady"),
    }  # fmt: skip


def by_category(results) -> dict[str, dict]:
    out = {"all": figures(results)}
    for name, keep in SCENE_CATEGORIES.items():
        chosen = [r for r in results if keep(r)]
        if chosen:
            out[name] = figures(chosen)
    for name, keep in OBJECT_CATEGORIES.items():
        out[name] = figures(results, objects=keep)
    return out


def objective(f: dict) -> float:
    """The number the suite's tuning minimises (docs/TUNING.md): HOTA, which weighs detection and
    association alike, four times, then one term per target, each clipped so that one wild
    figure cannot drown the others. The velocity term (the better method's NRMSE, clipped at 2)
    weighs half: its error is a few outliers' (a cluster that lags a fast object at a low frame
    rate), which a small change of parameters moves a lot."""

    def term(value, worst=1.0):
        return worst if value is None or not np.isfinite(value) else float(min(max(value, 0.0), worst))

    velocity = min(term(f.get(f"{m}_nrmse"), 2.0) for m in VELOCITY_METHOD_NAMES)
    angle = min(term(f.get(f"{m}_angle_deg"), 90.0) for m in VELOCITY_METHOD_NAMES) / 90.0
    return (
        4.0 * (1.0 - term(f.get("HOTA"), 1.0)) + (1.0 - term(f.get("recall"), 1.0)) + (1.0 - term(f.get("precision"), 1.0))
        + term((f.get("tracks_per_object") or 2.0) - 1.0) + term(f.get("position_rel_rmse"))
        + 0.5 * velocity + angle + term(f.get("luminance_nrmse")) + 2.0 * term(f.get("chrominance_nrmse"))
        + (1.0 - term(f.get("class_palette"), 1.0))
    )  # fmt: skip
