"""`evclust generalize`: the test split through the default configuration and the paper's, in
the float and the fixed model, written as docs/GENERALIZATION.md with a picture of typical
failures. The test split only reports: nothing here chooses a parameter."""

from __future__ import annotations

import dataclasses
import time
from pathlib import Path

from evclust.clusterer import ClustererParams, load_params
from evclust.scenes.generate import SPLITS
from evclust.suite.aggregate import SCENE_CATEGORIES, SLOW_PX_PER_FRAME, SMALL_PX, best_velocity, by_category, figures
from evclust.suite.evaluate import evaluate_scene
from evclust.suite.figures import failure_grid
from evclust.suite.prepare import SceneFiles, prepare_scene
from evclust.suite.run import map_scenes

# The targets on the test split (float model, no per-scene parameters).
TARGETS = (
    ("recall", ">=", 0.90, "recall"),
    ("precision", ">=", 0.90, "precision"),
    ("tracks_per_object", "<=", 1.2, "tracks per object"),
    ("position_rel_rmse", "<=", 0.15, "position RMSE / half-diagonal"),
    ("best_velocity_nrmse", "<=", 0.15, "velocity NRMSE, better method"),
    ("best_angle_deg", "<=", 10.0, "angular error, better method (°)"),
    ("best_velocity_nrmse_steady", "<=", 0.15, "velocity NRMSE, better method, steady state"),
    ("best_angle_deg_steady", "<=", 10.0, "angular error, better method, steady state (°)"),
    ("luminance_nrmse", "<=", 0.10, "luminance NRMSE"),
    ("chrominance_nrmse", "<=", 0.05, "chrominance NRMSE"),
    ("class_palette", ">=", 0.90, "palette classification"),
)


@dataclasses.dataclass
class Configuration:
    name: str
    params: ClustererParams
    model: str


def default_configurations(models=("float", "fixed")) -> list[Configuration]:
    paper, _ = load_params("paper")
    out = [Configuration("default", ClustererParams(), m) for m in models]
    return out + [Configuration("paper", paper, "float")]


def ablation_configurations() -> list[Configuration]:
    """The defaults with each addition beyond the paper switched off in turn (float model), and
    the paper's configuration: what each addition buys (docs/TUNING.md)."""
    d = ClustererParams()
    off = {
        "no merging": {"merge": False},
        "no scaled seek": {"seek_scale": 0.0},
        "no noise gate": {"noise_gate": 0.0},
        "creation support on" if not d.create_support else "no creation support": {"create_support": not d.create_support},
        "no warm start (plain α filters)": {"velocity_warm_start": False},
        "times in µs (20 ms, 100 ms), not frames": {"t_half_us": 20_000.0, "tau_us": 100_000.0},
    }
    paper, _ = load_params("paper")
    return [Configuration("default", d, "float")] + [Configuration(n, d.model_copy(update=u), "float") for n, u in off.items()] + [
        Configuration("paper", paper, "float")
    ]


_best = best_velocity


def _rule(head: str) -> str:
    return "|" + "|".join(["---"] * (head.count("|") - 1)) + "|"


def _pct(v, digits=1):
    return "n/a" if v is None else f"{100 * v:.{digits}f} %"


def _num(v, digits=2):
    return "n/a" if v is None else f"{v:.{digits}f}"


@dataclasses.dataclass
class SuiteRun:
    configuration: Configuration
    results: list
    wall_s: float


def run_configurations(client, folder: Path, seeds, configurations, progress: bool = True) -> list[SuiteRun]:
    files = map_scenes(client, prepare_scene, seeds, str(folder), desc="prepare", progress=progress)
    runs = []
    for c in configurations:
        start = time.perf_counter()
        results = map_scenes(client, evaluate_scene, files, c.params, c.model, desc=f"{c.name} ({c.model})", progress=progress)
        runs.append(SuiteRun(c, results, time.perf_counter() - start))
    return runs


def _overall_table(runs: list[SuiteRun]) -> list[str]:
    head = ("| configuration | model | recall | precision | tracks/object | HOTA | DetA | AssA | MOTA | IDF1 | ID switches "
            "| position / half-diag. | velocity NRMSE MCM / interval | angle MCM / interval | luminance NRMSE | chrominance NRMSE | palette class |")  # fmt: skip
    lines = [head, _rule(head)]
    for r in runs:
        f = figures(r.results)
        lines.append(
            f"| {r.configuration.name} | {r.configuration.model} | {_pct(f['recall'])} | {_pct(f['precision'])} | {_num(f['tracks_per_object'])} "
            f"| {_pct(f.get('HOTA'))} | {_pct(f.get('DetA'))} | {_pct(f.get('AssA'))} | {_pct(f.get('MOTA'))} | {_pct(f.get('IDF1'))} "
            f"| {f.get('id_switches', 'n/a')} | {_pct(f.get('position_rel_rmse'))} | {_pct(f.get('mcm_nrmse'))} / {_pct(f.get('interval_nrmse'))} "
            f"| {_num(f.get('mcm_angle_deg'), 1)}° / {_num(f.get('interval_angle_deg'), 1)}° | {_pct(f.get('luminance_nrmse'))} "
            f"| {_pct(f.get('chrominance_nrmse'))} | {_pct(f.get('class_palette'))} |"
        )  # fmt: skip
    return lines


def _category_table(run: SuiteRun) -> list[str]:
    cats = by_category(run.results)
    head = "| category | scenes / objects | recall | precision | tracks/object | HOTA | position / half-diag. | best velocity NRMSE | best angle | luminance NRMSE | chrominance NRMSE | palette class |"
    lines = [head, _rule(head)]
    for name, f in cats.items():
        f = _best(f)
        count = f"{f['scenes']} scenes" if name == "all" or name in SCENE_CATEGORIES else f"{f['objects']} objects"
        lines.append(
            f"| {name} | {count} | {_pct(f['recall'])} | {_pct(f['precision'])} | {_num(f['tracks_per_object'])} | {_pct(f.get('HOTA'))} "
            f"| {_pct(f.get('position_rel_rmse'))} | {_pct(f['best_velocity_nrmse'])} | {_num(f['best_angle_deg'], 1)}° "
            f"| {_pct(f.get('luminance_nrmse'))} | {_pct(f.get('chrominance_nrmse'))} | {_pct(f.get('class_palette'))} |"
        )  # fmt: skip
    return lines


def _scene_table(run: SuiteRun) -> list[str]:
    head = "| scene | sensor | fps | frames | objects | background | codec | noise | events | recall | precision | tracks/object | HOTA | IDF1 | position / half-diag. | best velocity NRMSE | palette class |"
    lines = [head, _rule(head)]
    for r in run.results:
        f = _best(figures([r]))
        x = r.facts
        lines.append(
            f"| {r.name} | {x['width']}×{x['height']} | {x['fps']:g} | {x['frames']} | {len(x['objects'])} | {x['background']} "
            f"| {'yes' if x['codec'] else 'no'} | {'yes' if x['noise'] else 'no'} | {r.events:,} | {_pct(f['recall'])} | {_pct(f['precision'])} "
            f"| {_num(f['tracks_per_object'])} | {_pct(f.get('HOTA'))} | {_pct(f.get('IDF1'))} | {_pct(f.get('position_rel_rmse'))} "
            f"| {_pct(f['best_velocity_nrmse'])} | {_pct(f.get('class_palette'))} |"
        )  # fmt: skip
    return lines


def _targets_table(run: SuiteRun) -> list[str]:
    f = _best(figures(run.results))
    lines = ["Steady state: the object moves and had the same velocity one second earlier "
             f"({_pct(f.get('steady_share'))} of the moving evaluations).", "",
             "| target | wanted | measured | met |", "|---|---|---|---|"]
    for key, op, want, label in TARGETS:
        got = f.get(key)
        met = got is not None and (got >= want if op == ">=" else got <= want)
        fmt = (lambda v: _num(v, 1) + "°") if key.startswith("best_angle") else (_num if key == "tracks_per_object" else _pct)
        lines.append(f"| {label} | {op} {fmt(want)} | {fmt(got)} | {'yes' if met else 'no'} |")
    return lines


def _agreement(runs: list[SuiteRun]) -> list[str]:
    """Fixed against float, each figure's difference relative to the float figure."""
    by = {(r.configuration.name, r.configuration.model): figures(r.results) for r in runs}
    if ("default", "float") not in by or ("default", "fixed") not in by:
        return []
    a, b = by[("default", "float")], by[("default", "fixed")]
    keys = ("recall", "precision", "tracks_per_object", "HOTA", "IDF1", "position_rel_rmse", "mcm_nrmse", "interval_nrmse",
            "luminance_nrmse", "chrominance_nrmse", "class_palette")  # fmt: skip
    lines = ["| figure | float | fixed | fixed − float, relative |", "|---|---|---|---|"]
    for k in keys:
        if a.get(k) is None or b.get(k) is None:
            continue
        rel = (b[k] - a[k]) / a[k] if a[k] else 0.0
        lines.append(f"| {k} | {a[k]:.4f} | {b[k]:.4f} | {100 * rel:+.2f} % |")
    return lines


def write_report(runs: list[SuiteRun], folder: Path, out: Path, split: str, seeds, command: str, machine: str,
                 picture: Path | None, categories_of=None, title: str = "Generalization") -> str:  # fmt: skip
    """The page. `categories_of`: the configurations whose category tables are given (default: all)."""
    default = next(r for r in runs if r.configuration.name == "default" and r.configuration.model == "float")
    files_of = lambda name: SceneFiles(name, folder)  # noqa: E731
    panels = failure_grid(default.results, files_of, default.configuration.params, picture) if picture else []
    n_events = sum(r.events for r in default.results)
    n_objects = sum(len(r.facts["objects"]) for r in default.results)
    held_out = (
        f"**No parameter, threshold or design rule was chosen on this split**: the defaults were tuned on the tuning split "
        f"(seeds {min(SPLITS['tuning'])}–{max(SPLITS['tuning'])}, docs/TUNING.md), and the `paper` preset is the paper's."
        if split == "test" else
        "This is the **tuning** split, on which the defaults and the design rules were chosen: its figures are not a held-out "
        "measure (docs/GENERALIZATION.md gives the test split's)."
    )  # fmt: skip
    lines = [
        f"# {title}",
        "",
        f"Generated by `{command}` ({machine}). Do not edit: rerun the command.",
        "",
        f"The **{split}** split of the generated suite: {len(seeds)} scenes (seeds {min(seeds)}–{max(seeds)}), "
        f"{n_objects} objects, {n_events:,} events. Every scene is drawn from its seed by `evclust scenes --generate SEED` "
        "(object size 8–150 px, speed 0.1–12 px/frame, 1–20 objects, uniform and textured objects on uniform, textured "
        "and gradient backgrounds, turns, crossings, occlusions, entries and exits, 10–60 fps, 160×120 to 1280×720; even "
        "seeds through the MPEG-4 codec and back, a third with sensor noise). "
        + held_out,
        "",
        "Figures are pooled over the split (sums of counts, not means of per-scene ratios), with the tracker sampled once "
        "per frame and objects matched at similarity ≥ 0.5 (a record within a quarter of the object's half-diagonal). "
        "Definitions: docs/METRICS.md, \"Tracking metrics\".",
        "",
        "## Overall",
        "",
        *_overall_table(runs),
        "",
    ]
    agreement = _agreement(runs)
    if agreement:
        lines += ["## Fixed against float (default configuration)", "", *agreement, ""]
    lines += ["## Targets (default configuration, float model)", "", *_targets_table(default), ""]
    for r in runs:
        if categories_of is not None and r.configuration.name not in categories_of:
            continue
        lines += [f"## By category: {r.configuration.name}, {r.configuration.model} model", "",
                  f"Objects are small below {SMALL_PX:g} px (larger side), slow below {SLOW_PX_PER_FRAME:g} px/frame (mean speed). "
                  "Precision and HOTA are per scene category only.",
                  "", *_category_table(r), ""]  # fmt: skip
    lines += ["## Per scene: default, float model", "", *_scene_table(default), ""]
    if panels:
        lines += ["## Typical failures", "", f"![Typical failures]({picture.relative_to(out.parent).as_posix()})", ""]
        for kind, name, frame, count in panels:
            lines.append(f"- {kind.replace('_', '-')}: {name}, frame {frame}: {count} in that frame.")
        lines.append("")
    lines += [
        "## Runtime",
        "",
        "| configuration | model | scenes | wall time | events |",
        "|---|---|---|---|---|",
        *(f"| {r.configuration.name} | {r.configuration.model} | {len(r.results)} | {r.wall_s:.1f} s | {sum(x.events for x in r.results):,} |" for r in runs),
        "",
        "## Commands",
        "",
        "```sh",
        "make generalize                                   # this page: the test split, default and paper, float and fixed",
        "evclust scenes --generate 1000 -o scenes/         # one scene of the suite (TOML, truth, video for codec scenes)",
        "evclust scenes --split test -o scenes/            # every scene of a split",
        "evclust tune --suite tuning --trials 400 --storage sqlite:///build/tune.db   # the tuning of the defaults",
        "evclust generalize --split test --scheduler tcp://host:8786 -o GENERALIZATION.md   # on a Dask cluster",
        "```",
        "",
    ]
    text = "\n".join(lines)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(text)
    return text
