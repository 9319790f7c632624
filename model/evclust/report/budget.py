"""The fixed-point error budget: what each quantisation source adds to the outputs, alone and all
together, against the float model (docs/report/REPORT.md).

A source is one signal of the formats table rounded to its format, the decay table, or the
quantised constants. The float model emulates it: its quantisation points (float_model._q)
round only that signal, everything else stays float64. Errors are measured on the track
records both runs emit at the same filter step for the same object: at each step the records
are paired by centre distance (Hungarian, within PAIR_GATE_PX), as the models' slot and id
numbering may part ways after a creation one of them makes and the other does not.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from evclust.clusterer import ClustererParams
from evclust.run import track_events
from evclust.clusterer.float_model import PRECISION_SIGNALS
from evclust.fixed.formats import FormatTable, build_formats, precision_table
from evclust.metrics.scores import scored_velocity_methods

# Output groups: the record columns each reports, and the format whose LSB measures it; for the
# cluster records, then for the object records.
OUTPUTS = {
    "position": (("x", "y"), "centre"),
    "size": (("rx", "ry"), "half_size"),
    "velocity": (("vx_mcm", "vy_mcm", "vx_int", "vy_int"), "v_int"),
    "colour": (("Y", "Cb", "Cr"), "colour"),
}
OBJECT_OUTPUTS = {
    "position": (("x", "y"), "obj_centre"),
    "size": (("rx", "ry"), "obj_half"),
    "velocity": (("vx", "vy"), "obj_velocity"),
    "colour": (("Y", "Cb", "Cr"), "colour"),
}
SOURCES = (*PRECISION_SIGNALS, "constants")
PAIR_GATE_PX = 2.0


@dataclasses.dataclass
class Error:
    """One source's error on one output group: max |e| in output LSBs, RMS, bias, noise power
    and SQNR (dB) against the float outputs' power."""

    max_lsb: float
    rms: float
    bias: float
    power: float
    sqnr_db: float
    pairs: int


def quantised_constants(params: ClustererParams, table: FormatTable) -> ClustererParams:
    """The parameters as the fixed model holds them: every constant replaced by its quantised value."""
    c = {name: k.quantised for name, k in table.constants.items()}
    update = {f"alpha_{name[5:]}": 1.0 - value for name, value in c.items() if name.startswith("beta_")}
    update |= {"size_gain": c["size_gain"], "t_half_us": 1.0 / c["inv_t_half"], "gamma": c["gamma_global"],
               "p_correction": 1.0 / c["inv_p"], "r_init": c["r_init"], "r_min": c["r_min"], "r_max": c["r_max"]}  # fmt: skip
    for name in ("seek_margin", "exit_margin", "a_min", "a_valid", "mixing_tolerance", "luma_weight"):
        if name in c:
            update[name] = c[name]
    for name in ("v_min", "v_exit"):
        if f"{name}_sq" in c:
            update[name] = math.sqrt(c[f"{name}_sq"])
    if "cos_sq_exit" in c:
        update["theta_exit_deg"] = math.degrees(math.acos(math.sqrt(c["cos_sq_exit"])))
    return params.model_copy(update=update)


def emulate(events, meta, params: ClustererParams, table: FormatTable, sources, frac_bits=None):
    """The float model with `sources` quantised (names of SOURCES); `frac_bits` overrides formats."""
    sources = tuple(sources)
    run_params = quantised_constants(params, table) if "constants" in sources else params
    signals = [s for s in sources if s != "constants"]
    precision = precision_table(table, signals, frac_bits) if signals else None
    return track_events(events, meta, run_params, model="float", precision=precision)


def record_errors(reference: np.ndarray, tracks: np.ndarray, table: FormatTable, outputs: dict = OUTPUTS) -> dict[str, Error]:
    """Each output group's error of `tracks` against `reference`, over the records both emit."""
    ia, ib = paired_records(reference, tracks)
    out = {}
    for group, (columns, fmt) in outputs.items():
        if ia.size == 0:
            out[group] = Error(math.nan, math.nan, math.nan, math.nan, math.nan, 0)
            continue
        a = np.stack([reference[c][ia].astype(np.float64) for c in columns], axis=1).ravel()  # pair by pair, column by column
        b = np.stack([tracks[c][ib].astype(np.float64) for c in columns], axis=1).ravel()
        e = b - a
        power = float(np.mean(e * e))
        signal = float(np.mean(a * a))
        sqnr = math.inf if power == 0 else 10 * math.log10(signal / power) if signal > 0 else -math.inf
        out[group] = Error(float(np.max(np.abs(e))) / table[fmt].lsb, math.sqrt(power), float(np.mean(e)), power, sqnr, int(ia.size))
    return out


def _by_step(records: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The records' indices by step (each step's in file order), the steps, and where each step's
    indices begin (and where the last ends)."""
    order = np.argsort(records["step"], kind="stable")
    steps, first = np.unique(records["step"][order], return_index=True)
    return order, steps, np.r_[first, order.size]


def _steps_taken(order: np.ndarray, first: np.ndarray, taken: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The indices of the taken steps, step after step, and where each step's begin (and the end)."""
    picked = [order[first[g] : first[g + 1]] for g in taken.tolist()]
    return np.concatenate(picked or [np.empty(0, np.int64)]), np.r_[0, np.cumsum(first[taken + 1] - first[taken])]


def paired_records(reference: np.ndarray, tracks: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Indices of the paired (reference record, record): per filter step in step order, Hungarian
    on the centre distance within PAIR_GATE_PX (the metrics' gated assignment)."""
    from evclust.metrics.match import gated_pairs

    order_a, steps_a, first_a = _by_step(reference)
    order_b, steps_b, first_b = _by_step(tracks)
    _, taken_a, taken_b = np.intersect1d(steps_a, steps_b, assume_unique=True, return_indices=True)  # the steps both emit
    ra, bounds_a = _steps_taken(order_a, first_a, taken_a)
    rb, bounds_b = _steps_taken(order_b, first_b, taken_b)
    xy_a, xy_b = (np.stack([r["x"][i], r["y"][i]], axis=1) for r, i in ((reference, ra), (tracks, rb)))
    ia, ib = gated_pairs(xy_a, bounds_a, xy_b, bounds_b, PAIR_GATE_PX)
    return ra[ia], rb[ib]


def budget(events, meta, params: ClustererParams, progress=None) -> dict:
    """Per source, then all together (emulated) and the fixed model itself: errors per output of
    the cluster records. With an object layer, the object records' errors too: the float object
    layer over the emulated clusters (every source quantised), then the fixed model, whose object
    layer adds its own formats."""
    t_frame = params.t_frame_us or meta.t_frame_us
    table = build_formats(params, meta.width, meta.height, t_frame)
    reference = track_events(events, meta, params, model="float")
    rows, object_rows = {}, {}
    for source in (*SOURCES, "all"):
        sources = SOURCES if source == "all" else (source,)
        run = emulate(events, meta, params, table, sources)
        rows[source] = record_errors(reference.tracks, run.tracks, table)
        if source == "all" and params.objects:
            object_rows["all"] = record_errors(reference.objects, run.objects, table, OBJECT_OUTPUTS)
        if progress:
            progress(source)
    fixed = track_events(events, meta, params, model="fixed")
    rows["fixed model"] = record_errors(reference.tracks, fixed.tracks, table)
    if params.objects:
        object_rows["fixed model"] = record_errors(reference.objects, fixed.objects, table, OBJECT_OUTPUTS)
    return {"table": table, "rows": rows, "reference_records": len(reference.tracks), "object_rows": object_rows,
            "reference_objects": 0 if reference.objects is None else len(reference.objects)}  # fmt: skip


def noise_sum_ratio(rows: dict, group: str) -> float:
    """Sum of the sources' noise powers over the all-together power (1: the sources add up)."""
    total = rows["all"][group].power
    parts = sum(rows[s][group].power for s in SOURCES if not math.isnan(rows[s][group].power))
    return parts / total if total > 0 else math.nan


def error_vs_frac_bits(events, meta, params: ClustererParams, signals, offsets) -> dict[str, list[tuple[int, float]]]:
    """Per signal, (fraction bits, RMS error of the signal's output group) as that signal's
    format narrows or widens, every other signal exact; one float reference for all."""
    t_frame = params.t_frame_us or meta.t_frame_us
    table = build_formats(params, meta.width, meta.height, t_frame)
    reference = track_events(events, meta, params, model="float").tracks
    curves = {}
    for signal in signals:
        curves[signal] = []
        for offset in offsets:
            frac = table[signal].frac_bits + offset
            if frac < 0:
                continue
            run = emulate(events, meta, params, table, (signal,), {signal: frac})
            curves[signal].append((frac, record_errors(reference, run.tracks, table)[SIGNAL_GROUP[signal]].rms))
    return curves


# The output group each signal feeds most directly.
SIGNAL_GROUP = {
    "centre": "position", "half_size": "size", "activity": "velocity", "v_mcm": "velocity", "mcm_norm": "velocity",
    "v_int": "velocity", "colour": "colour", "background": "colour", "gamma": "velocity", "decay_table": "velocity",
}  # fmt: skip


# The task metrics a recommended set of formats must keep within tolerance of the float model's:
# each velocity method's (those of the record kind), then these.
TASK_METRICS = (("position_rmse_px",), ("luminance", "nrmse"), ("chrominance", "nrmse"), ("class_palette_accuracy",))


def scene_scores(run, truth, level: str | None = None) -> dict:
    """Every task metric of a tracking run against the scene's ground truth (metrics' dict form),
    on its output (the object records when it has an object layer) or on `level`'s records
    ("clusters" or "objects")."""
    from evclust.metrics.scores import score

    records, meta = {None: run.output, "clusters": (run.tracks, run.meta), "objects": (run.objects, run.object_meta)}[level]
    return score(records, meta, truth).to_dict()


def best_velocity_nrmse(scores: dict) -> float | None:
    """The best velocity method's NRMSE (None when none was scored)."""
    values = [v for m in scored_velocity_methods(scores) if (v := scores[m]["nrmse"]) is not None]
    return min(values) if values else None


def task_scores(run, truth) -> dict:
    s = scene_scores(run, truth)
    out = {}
    paths = [(m, key) for m in scored_velocity_methods(s) for key in ("nrmse", "angular_deg")] + list(TASK_METRICS)
    for path in paths:
        value = s
        for key in path:
            value = value[key]
        out[".".join(path)] = value
    return out


def within(reference: dict, scores: dict, tolerance: float) -> bool:
    """Every task metric within `tolerance` (relative) of the reference's."""
    for name, ref in reference.items():
        value = scores[name]
        if ref is None or value is None:
            if ref is not value:
                return False
            continue
        if abs(value - ref) > tolerance * abs(ref) + 1e-12:
            return False
    return True


@dataclasses.dataclass
class WordLengths:
    default: dict[str, int]  # fraction bits
    recommended: dict[str, int]
    word_bits: dict[str, tuple[int, int]]  # signal -> (default word, recommended word)
    evaluations: int
    defaults_within: bool


def wordlength_search(events, meta, params: ClustererParams, truth, tolerance: float = 0.01, progress=None) -> WordLengths:
    """Greedy: signal by signal, drop fraction bits (steps of 8, 4, 2, 1) while every task metric of
    the emulated model, all sources quantised, stays within `tolerance` of the float model's."""
    t_frame = params.t_frame_us or meta.t_frame_us
    table = build_formats(params, meta.width, meta.height, t_frame)
    reference = task_scores(track_events(events, meta, params, model="float"), truth)
    default = {s: table[s].frac_bits for s in PRECISION_SIGNALS}
    evaluations = 0

    def ok(fracs):
        nonlocal evaluations
        evaluations += 1
        if progress:
            progress()
        return within(reference, task_scores(emulate(events, meta, params, table, SOURCES, fracs), truth), tolerance)

    fracs = dict(default)
    defaults_within = ok(fracs)
    for signal in PRECISION_SIGNALS:
        step = 8
        while step >= 1:
            trial = fracs | {signal: fracs[signal] - step}
            if trial[signal] >= 0 and ok(trial):
                fracs = trial
            else:
                step //= 2
    words = {s: (table[s].word_bits, table[s].word_bits - default[s] + fracs[s]) for s in PRECISION_SIGNALS}
    return WordLengths(default, fracs, words, evaluations, defaults_within)
