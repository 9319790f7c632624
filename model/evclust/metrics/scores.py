"""Task metrics from the matches: the paper's Tables 5 and 7 plus tracking figures (docs/METRICS.md)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from evclust.metrics.match import DEFAULT_GATE_PX, MatchCounts, match_with_counts
from evclust.tracks import VELOCITY_METHODS, TrackMeta


@dataclasses.dataclass(frozen=True)
class VelocityScores:
    """One velocity method's errors over the matches whose true speed is not zero."""

    rmse: float | None  # px/frame: sqrt(mean(|V_est - V_gt|^2))
    nrmse: float | None  # rmse / mean |V_gt|, a fraction (0.181 is 18.1 %)
    angular_deg: float | None  # mean angle between V_est and V_gt, degrees; |V_est| = 0 counts 90


@dataclasses.dataclass(frozen=True)
class ColourError:
    rmse: float | None  # 8-bit levels
    nrmse: float | None  # rmse / mean of the true components involved, a fraction


@dataclasses.dataclass(frozen=True)
class Scores:
    """All figures of one run. None where a figure has no evaluation to stand on (no match, no
    colour, zero denominator). NRMSE, accuracies, recall and precision are fractions."""

    gate_px: float
    fully_visible_only: bool
    # how many evaluations each figure rests on
    n_steps: int  # filter steps in the track file (distinct step, t_us)
    n_steps_missing: int  # step numbers below the last one with no record in the file
    n_track_records: int
    n_gt_evaluations: int  # (filter step, object present) pairs
    n_matches: int
    n_velocity_evaluations: int  # matches with |V_gt| > 0
    n_colour_evaluations: int
    n_class_evaluations: int
    n_labels_not_in_palette: int  # class evaluations whose true label names no palette entry
    # Table 7: position
    position_rmse_px: float | None
    # Table 5: velocity
    gt_vx_range: tuple[float, float] | None  # [min, max] of the true vx over the matches
    gt_vy_range: tuple[float, float] | None
    velocity: dict[str, VelocityScores]  # per method of the record kind: mcm and interval, or object
    # Table 7: colour and classification
    has_colour: bool
    ycbcr: ColourError
    luminance: ColourError
    chrominance: ColourError
    class_direct_accuracy: float | None
    class_palette_accuracy: float | None
    # tracking
    recall: float | None  # matched object evaluations / object evaluations
    precision: float | None  # matched track records / track records
    id_switches: int
    tracks_per_object: float | None  # distinct track ids matched to each object matched at all

    NO_VELOCITY = VelocityScores(None, None, None)

    @property
    def mcm(self) -> VelocityScores:
        return self.velocity.get("mcm", self.NO_VELOCITY)

    @property
    def interval(self) -> VelocityScores:
        return self.velocity.get("interval", self.NO_VELOCITY)

    def to_dict(self) -> dict:
        """Plain JSON-ready dict (nested for the velocity and colour groups, each velocity method
        under its own name; tuples as lists)."""

        def plain(value):
            if isinstance(value, dict):
                return {k: plain(v) for k, v in value.items()}
            if isinstance(value, (tuple, list)):
                return [plain(v) for v in value]
            if isinstance(value, float) and not math.isfinite(value):
                return None
            return value

        out = dataclasses.asdict(self)
        out |= out.pop("velocity")
        return plain(out)


def scored_velocity_methods(scores: dict) -> list[str]:
    """The velocity methods a score dict (Scores.to_dict) holds: those of its record kind, in order."""
    return [name for methods in VELOCITY_METHODS.values() for name, *_ in methods if name in scores]


def _ratio(num: float, den: float) -> float | None:
    return float(num) / float(den) if den else None


def _rms(squares: np.ndarray) -> float | None:
    return float(np.sqrt(np.mean(squares))) if squares.size else None


def _velocity(est: np.ndarray, gt: np.ndarray) -> VelocityScores:
    """est, gt: (N, 2), already restricted to |gt| > 0."""
    if gt.shape[0] == 0:
        return VelocityScores(None, None, None)
    err2 = ((est - gt) ** 2).sum(axis=1)
    rmse = float(np.sqrt(err2.mean()))
    gt_norm = np.hypot(gt[:, 0], gt[:, 1])
    est_norm = np.hypot(est[:, 0], est[:, 1])
    moving = est_norm > 0
    cosine = np.zeros(gt.shape[0])  # |V_est| = 0: cosine 0, i.e. 90 degrees
    cosine[moving] = (est[moving] * gt[moving]).sum(axis=1) / (est_norm[moving] * gt_norm[moving])
    angle = np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0)))
    return VelocityScores(rmse, _ratio(rmse, gt_norm.mean()), float(angle.mean()))


def tracks_per_object(matches: np.ndarray) -> float | None:
    """Distinct track ids matched to each object, averaged over the objects matched at all."""
    if matches.size == 0:
        return None
    per = {}
    for g, t in zip(matches["gt_id"].tolist(), matches["track_id"].tolist()):
        per.setdefault(g, set()).add(t)
    return float(np.mean([len(v) for v in per.values()]))


def _id_switches(matches: np.ndarray) -> int:
    """Per object, the number of times the matched track id changes between consecutive matched
    evaluations (in time order), summed over objects."""
    if matches.size == 0:
        return 0
    order = np.lexsort((matches["step"], matches["t_us"], matches["gt_id"]))
    gt = matches["gt_id"][order]
    tid = matches["track_id"][order]
    same_object = gt[1:] == gt[:-1]
    return int(np.count_nonzero(same_object & (tid[1:] != tid[:-1])))


def class_correct(classes: np.ndarray, labels: np.ndarray, palette) -> np.ndarray:
    """An evaluation is correct when its class names the ground-truth label; -1 (no class) never is."""
    classes = np.asarray(classes)
    valid = (classes >= 0) & (classes < len(palette))
    names = np.array(list(palette) or [""], dtype=object)[np.where(valid, classes, 0)]
    return valid & (names == np.asarray(labels).astype(object))


def scores_from_matches(matches: np.ndarray, counts: MatchCounts, meta: TrackMeta, gate_px: float, fully_visible_only: bool) -> Scores:
    m = matches
    n = int(m.size)

    position = _rms((m["x"] - m["gt_x"]) ** 2 + (m["y"] - m["gt_y"]) ** 2)

    gt_v = np.stack([m["gt_vx"], m["gt_vy"]], axis=1)
    moving = np.hypot(gt_v[:, 0], gt_v[:, 1]) > 0
    velocity = {name: _velocity(np.stack([m[vx], m[vy]], axis=1)[moving], gt_v[moving]) for name, vx, vy in VELOCITY_METHODS[meta.kind]}
    vx_range = (float(m["gt_vx"].min()), float(m["gt_vx"].max())) if n else None
    vy_range = (float(m["gt_vy"].min()), float(m["gt_vy"].max())) if n else None

    none = ColourError(None, None)
    ycbcr = luminance = chrominance = none
    n_colour = 0
    direct = palette_acc = None
    n_class = n_unknown = 0
    if meta.has_colour and n:
        n_colour = n
        dY, dCb, dCr = m["Y"] - m["gt_Y"], m["Cb"] - m["gt_Cb"], m["Cr"] - m["gt_Cr"]
        lum = _rms(dY**2)
        chro = _rms((dCb**2 + dCr**2) / 2)
        full = _rms((dY**2 + dCb**2 + dCr**2) / 3)
        luminance = ColourError(lum, _ratio(lum, m["gt_Y"].mean()))
        chrominance = ColourError(chro, _ratio(chro, (m["gt_Cb"].mean() + m["gt_Cr"].mean()) / 2))
        ycbcr = ColourError(full, _ratio(full, (m["gt_Y"].mean() + m["gt_Cb"].mean() + m["gt_Cr"].mean()) / 3))
        if meta.palette:

            def correct(cls: np.ndarray) -> np.ndarray:
                return class_correct(cls, m["gt_label"], meta.palette)

            n_class = n
            n_unknown = int(np.count_nonzero(~np.isin(m["gt_label"], np.array(meta.palette, dtype=m["gt_label"].dtype))))
            direct = float(np.count_nonzero(correct(m["class_direct"]))) / n
            palette_acc = float(np.count_nonzero(correct(m["class_palette"]))) / n

    return Scores(
        gate_px=float(gate_px),
        fully_visible_only=bool(fully_visible_only),
        n_steps=counts.n_steps,
        n_steps_missing=counts.n_steps_missing,
        n_track_records=counts.n_track_records,
        n_gt_evaluations=counts.n_gt_evaluations,
        n_matches=n,
        n_velocity_evaluations=int(np.count_nonzero(moving)),
        n_colour_evaluations=n_colour,
        n_class_evaluations=n_class,
        n_labels_not_in_palette=n_unknown,
        position_rmse_px=position,
        gt_vx_range=vx_range,
        gt_vy_range=vy_range,
        velocity=velocity,
        has_colour=bool(meta.has_colour),
        ycbcr=ycbcr,
        luminance=luminance,
        chrominance=chrominance,
        class_direct_accuracy=direct,
        class_palette_accuracy=palette_acc,
        recall=_ratio(n, counts.n_gt_evaluations),
        precision=_ratio(n, counts.n_track_records),
        id_switches=_id_switches(m),
        tracks_per_object=tracks_per_object(m),
    )


def score(
    tracks: np.ndarray,
    meta: TrackMeta,
    truth,
    gate_px: float = DEFAULT_GATE_PX,
    fully_visible_only: bool = False,
) -> Scores:
    """Match (see `match`) and compute every figure of docs/METRICS.md."""
    matches, counts = match_with_counts(tracks, meta, truth, gate_px, fully_visible_only)
    return scores_from_matches(matches, counts, meta, gate_px, fully_visible_only)
