"""`evclust generalize --pipeline`: what the pipeline semantics (ClustererParams.update_delay, and
the activity against a reference time, activity_reference) cost in accuracy, written as
docs/PIPELINE.md.

One run says little: a change of 10^-4 in one α moves the object records' HOTA by up to a point,
because a scene's few identity decisions flip. So each delay is compared pairwise, on the
defaults and on small perturbations of them, and the page gives the mean change with its
standard error. The held-out test split answers; the tuning split, on which the defaults were
tuned with the sequential update, is shown beside it.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from evclust.clusterer import ClustererParams
from evclust.suite.aggregate import figures
from evclust.suite.report import Configuration, SuiteRun, commands_section, save_page

DELAYS = (1, 2, 4, 8, 16)  # events in flight: the RTL's (1, 2), and the depths a deeper pipeline may take
# The defaults, and each nudged by far less than any tuning step: a fair sample of "the same"
# configuration, over which a delay's effect is averaged.
PERTURBATIONS = {
    "defaults": {},
    "alpha_pos + 1e-4": {"alpha_pos": 0.9844},
    "alpha_size + 1e-4": {"alpha_size": 0.9848},
    "seek_margin + 0.01 px": {"seek_margin": 2.71},
    "alpha_vel_mcm + 1e-4": {"alpha_vel_mcm": 0.9923},
    "r_init + 0.1 px": {"r_init": 18.5},
}
TARGET_POINTS = 0.5  # at most this many HOTA points lost on the test split
LEVELS = (("objects", "what the defaults report (object records)"), ("clusters", "the cluster records below them"))


# The activity against a reference time, against the paper's decay-then-add: {row: (model, the paper's
# run, the mode's run)}. The float model shows the rule (equal in exact arithmetic but at merges),
# also at the RTL's D = 2, where commits are additions in flight; the fixed model its roundings.
REFERENCE_VARIANTS = {
    "float": ("float", "0", "reference"),
    "float, D = 2": ("float", "2", "reference~2"),
    "fixed": ("fixed", "0~fixed", "reference~fixed"),
}
# The filter step's sweep beside the events at one slot an event (the slowest sweep, the RTL's
# cheapest: one swept slot a cycle), against the sweep between two events, each at the same D
# and activity: the paper's update, and the pipelined core's (D = 2, the activity against a
# reference time), in both models.
SWEEP_SLOTS = 1
SWEEP_VARIANTS = {
    "float, D = 0": ("float", "0", "beside"),
    "float, D = 2, referenced": ("float", "reference~2", "beside~reference~2"),
    "fixed, D = 2, referenced": ("fixed", "reference~2~fixed", "beside~reference~2~fixed"),
}
# The runs beyond the delays: {variant: (model, update_delay, activity_reference, sweep_slots_per_event)}.
# (The float paper runs at D = 0 and 2 are the delays' own.)
RUNS = {
    "reference": ("float", 0, True, 0),
    "reference~2": ("float", 2, True, 0),
    "0~fixed": ("fixed", 0, False, 0),
    "reference~fixed": ("fixed", 0, True, 0),
    "beside": ("float", 0, False, SWEEP_SLOTS),
    "beside~reference~2": ("float", 2, True, SWEEP_SLOTS),
    "reference~2~fixed": ("fixed", 2, True, 0),
    "beside~reference~2~fixed": ("fixed", 2, True, SWEEP_SLOTS),
}


def configurations(delays=DELAYS) -> list[Configuration]:
    base = ClustererParams()
    delayed = [Configuration(f"{name}|{d}", base.model_copy(update={**update, "update_delay": d}), "float")
               for name, update in PERTURBATIONS.items() for d in (0, *delays)]  # fmt: skip
    others = [
        Configuration(
            f"{name}|{variant}",
            base.model_copy(update={**update, "update_delay": delay, "activity_reference": reference, "sweep_slots_per_event": sweep}),
            model,
        )
        for name, update in PERTURBATIONS.items()
        for variant, (model, delay, reference, sweep) in RUNS.items()
    ]
    return delayed + others


def _pooled(runs: list[SuiteRun]) -> dict:
    """{(perturbation, variant): {level: pooled figures}}."""
    return {tuple(r.configuration.name.split("|")): {"objects": figures(r.results), "clusters": figures(r.cluster_results)}
            for r in runs}  # fmt: skip


def _pairs(pooled: dict, before: str, after: str, level: str) -> dict:
    pairs = [(pooled[n, before][level], pooled[n, after][level]) for n in PERTURBATIONS]
    out = {key: np.array([100.0 * ((b[key] or 0.0) - (a[key] or 0.0)) for a, b in pairs]) for key in ("HOTA", "recall", "precision")}
    out["base"] = pairs[0]
    return out


def paired_changes(runs: list[SuiteRun]) -> dict:
    """{(delay, level): {"HOTA": per-perturbation HOTA change in points, ..., "base": the defaults' (D = 0, D) figures}}."""
    pooled = _pooled(runs)
    delays = sorted({int(v) for _, v in pooled if v.isdigit() and v != "0"})
    return {(d, level): _pairs(pooled, "0", str(d), level) for d in delays for level, _ in LEVELS}


def reference_changes(runs: list[SuiteRun]) -> dict:
    """{(model, level): the same, the activity against a reference time against the paper's activity}."""
    pooled = _pooled(runs)
    return {
        (row, level): _pairs(pooled, before, after, level) for row, (_, before, after) in REFERENCE_VARIANTS.items() for level, _ in LEVELS
    }


def sweep_changes(runs: list[SuiteRun]) -> dict:
    """{(row, level): the same, the sweep beside the events against the sweep between two events}."""
    pooled = _pooled(runs)
    return {(row, level): _pairs(pooled, before, after, level) for row, (_, before, after) in SWEEP_VARIANTS.items() for level, _ in LEVELS}


def _mean_se(values: np.ndarray) -> str:
    se = values.std(ddof=1) / np.sqrt(values.size) if values.size > 1 else float("nan")
    return f"{values.mean():+.2f} ± {se:.2f}"


def _paired_table(changes: dict, label: str, short: str, pair: str, target: str | None) -> list[str]:
    """The paired changes keyed (row, records) as a table, and with `target` (the held-out split
    only) each row's verdict on the object records."""
    head = f"| {label} | records | HOTA, {pair} (defaults) | HOTA change, mean ± s.e. (points) | per parameter set | recall change | precision change |"
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    for (row, level), c in changes.items():
        a, b = c["base"]
        lines.append(f"| {row} | {level} | {100 * a['HOTA']:.1f} → {100 * b['HOTA']:.1f} % | {_mean_se(c['HOTA'])} | "
                     f"{', '.join(f'{x:+.2f}' for x in c['HOTA'])} | {_mean_se(c['recall'])} | {_mean_se(c['precision'])} |")  # fmt: skip
    if target:
        lines += ["", target, "", f"| {short} | mean change | met |", "|---|---|---|"]
        for (row, level), c in changes.items():
            if level == "objects":
                lines.append(f"| {row} | {c['HOTA'].mean():+.2f} points | {'yes' if c['HOTA'].mean() >= -TARGET_POINTS else 'no'} |")
    return lines


def section(split: str, changes: dict, held_out: bool) -> list[str]:
    target = f"Target: the pipeline costs at most {TARGET_POINTS:g} HOTA points of what the defaults report on this split."
    return _paired_table(changes, "D (events in flight)", "D", "D = 0 → D", target if held_out else None)


def reference_section(changes: dict, held_out: bool) -> list[str]:
    target = f"Target: at most {TARGET_POINTS:g} HOTA points of what the defaults report on this split."
    return _paired_table(changes, "model", "model", "paper's activity → referenced", target if held_out else None)


def sweep_section(changes: dict, held_out: bool) -> list[str]:
    target = f"Target: at most {TARGET_POINTS:g} HOTA points of what the defaults report on this split."
    return _paired_table(changes, "model, update", "model, update", "sweep between events → beside them", target if held_out else None)


def _by_split(by_split: dict, section_of) -> list[str]:
    """A subsection a split, each the split's table by `section_of` (judged on the held-out split only)."""
    lines = []
    for split, changes in by_split.items():
        held_out = split == "test"
        lines += [f"### {split} split{' (held out)' if held_out else ' (the defaults were tuned on it: not a held-out measure)'}", "",
                  *section_of(changes, held_out), ""]  # fmt: skip
    return lines


def write_page(by_split: dict, out: Path, command: str, machine: str, scenes: dict, reference_by_split: dict,
               sweep_by_split: dict) -> str:  # fmt: skip
    """`by_split`: {split: paired_changes(...)}, the test split first; `reference_by_split`:
    {split: reference_changes(...)}; `sweep_by_split`: {split: sweep_changes(...)}."""
    lines = [
        "# Pipeline semantics: what the delayed update costs",
        "",
        f"Generated by `{command}` ({machine}). Do not edit: rerun the command.",
        "",
        "A core that takes one event per clock at a high clock rate reads a slot when the event enters and writes it back "
        "some cycles later. With `update_delay = D` the models say what such a core computes: event n reads the table with "
        "the updates of events up to n − D − 1 committed (a creation at once), each update is a set of increments computed "
        "from the state it read, and the increments are added, in event order, to the slot as it then is (delayed LMS). "
        'A filter step first commits everything in flight. docs/DESIGN.md, "Pipeline semantics", gives the rules; '
        "D = 0 is the paper's sequential update, bit for bit.",
        "",
        "Each row compares the float model at D against D = 0 on the defaults and on five perturbations of them "
        f"({', '.join(n for n in PERTURBATIONS if n != 'defaults')}), pairwise: a single run's HOTA moves by up to a "
        "point with a perturbation that small, so one pair would measure noise. Figures are pooled over each split as in "
        "docs/GENERALIZATION.md.",
        "",
    ]
    for split, changes in by_split.items():
        held_out = split == "test"
        what = ("held out: no parameter, threshold or design rule was chosen on it" if held_out else
                "the split the defaults were tuned on, with the sequential update: not a held-out measure")  # fmt: skip
        lines += [f"## {split} split ({scenes[split]} scenes; {what})", "", *section(split, changes, held_out), ""]
    lines += [
        "## The activity against a reference time",
        "",
        "With `activity_reference` each slot keeps, between filter steps, Ã = A·2^((t − t_ref)/T_half) against the last "
        "step's time t_ref: an event adds its weight 2^((t − t_ref)/T_half), one value per event and the same for every "
        "slot, so the update of the activity is an addition and the decay leaves the per-event recurrence; the step "
        'decays every activity by one factor (docs/DESIGN.md, "Activity against a reference time"). In exact arithmetic '
        "the activity is the paper's, except at merges, where the paper's sweep adds a later slot's activity before it "
        "has decayed it to the step. Each row compares the mode with the paper's activity at the same D (0, or the RTL's "
        "2, where the commits in flight are additions), paired over the same parameter sets, in the float model and in "
        "the fixed model (whose roundings differ: a floored weight per event and one decay per step, instead of a decay "
        "per event).",
        "",
    ]
    lines += _by_split(reference_by_split, reference_section)
    lines += [
        "## The filter step's sweep beside the events",
        "",
        f"With `sweep_slots_per_event = {SWEEP_SLOTS}` a filter step does not stop the events: its sweep runs on beside "
        "them, one slot before each event after the step's, and each event and each swept slot see the table as it then "
        "is (nothing in flight is committed first; a slot the sweep frees voids its updates in flight; a slot's time "
        "never moves back). With the activity against a reference time the reference then stays at the steps, and the "
        "sweep reads each activity as Ã times the step's one decay 2^−((t − t_ref)/T_half), so the step writes no "
        'activity (docs/DESIGN.md, "The sweep beside the events"). A step that comes while a sweep is still open first '
        "finishes it (at N = 16 and a step every 64 events, never). Each row compares it with the sweep between two "
        "events at the same D and activity, paired over the same parameter sets: the paper's update in the float model, "
        "and the pipelined core's (D = 2, referenced) in both models.",
        "",
    ]
    lines += _by_split(sweep_by_split, sweep_section)
    lines += commands_section(("make generalize          # this page, with docs/GENERALIZATION.md",
                               "evclust generalize --pipeline -o docs/PIPELINE.md"))  # fmt: skip
    return save_page(out, lines, "PIPELINE")
