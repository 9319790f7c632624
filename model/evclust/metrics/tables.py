"""Plain-text tables in the layout of the paper's Tables 5 and 7, plus a tracking table."""

from __future__ import annotations

from collections.abc import Mapping

from evclust.metrics.scores import Scores

NA = "n/a"
METHOD_NAMES = {"mcm": "MCM", "interval": "Interval", "object": "Object"}


def _num(value, digits: int = 3) -> str:
    return NA if value is None else f"{value:.{digits}f}"


def _pct(value) -> str:
    return NA if value is None else f"{100 * value:.1f}%"


def _deg(value) -> str:
    return NA if value is None else f"{value:.1f}°"


def _range(s: Scores) -> str:
    if s.gt_vx_range is None or s.gt_vy_range is None:
        return NA
    (x0, x1), (y0, y1) = s.gt_vx_range, s.gt_vy_range
    return f"[{x0:.2f}, {x1:.2f}] × [{y0:.2f}, {y1:.2f}]"


def _render(title: str, columns: list[str], rows: list[tuple[str, str, list[str]]]) -> str:
    """rows: (group, measure, one value per column); the group is printed on its first row only."""
    group_w = max([len("Measures")] + [len(g) for g, _, _ in rows])
    measure_w = max(len(m) for _, m, _ in rows)
    widths = [max([len(c)] + [len(r[2][i]) for r in rows]) for i, c in enumerate(columns)]
    lines = [title]
    head = f"{'Measures':<{group_w}}  {'':<{measure_w}}" + "".join(f"  {c:>{w}}" for c, w in zip(columns, widths))
    lines += [head, "-" * len(head)]
    previous = None
    for group, measure, values in rows:
        shown = group if group != previous else ""
        previous = group
        lines.append(f"{shown:<{group_w}}  {measure:<{measure_w}}" + "".join(f"  {v:>{w}}" for v, w in zip(values, widths)))
    return "\n".join(lines)


def format_tables(scores: Scores | Mapping[str, Scores]) -> str:
    """The velocity table (paper's Table 5), the position/colour table (Table 7) and a tracking
    table. One value column per run: a single Scores gives a column named 'value'; a mapping
    {name: Scores} (e.g. one per scene) gives one column per name, in the mapping's order."""
    runs = {"value": scores} if isinstance(scores, Scores) else dict(scores)
    cols = list(runs)
    S = list(runs.values())

    def each(f):
        return [f(s) for s in S]

    velocity = [
        ("Ground Truth Range", "vx × vy [px/Tframe]", each(_range)),
        *(
            row
            for method in S[0].velocity
            for row in (
                (METHOD_NAMES[method], "RMSE [px/Tframe]", each(lambda s, m=method: _num(s.velocity[m].rmse))),
                (METHOD_NAMES[method], "NRMSE", each(lambda s, m=method: _pct(s.velocity[m].nrmse))),
                (METHOD_NAMES[method], "Angular", each(lambda s, m=method: _deg(s.velocity[m].angular_deg))),
            )
        ),  # fmt: skip
    ]
    colour = [
        ("Position", "RMSE [px]", each(lambda s: _num(s.position_rmse_px))),
        ("YCbCr", "RMSE", each(lambda s: _num(s.ycbcr.rmse, 2))),
        ("YCbCr", "NRMSE", each(lambda s: _pct(s.ycbcr.nrmse))),
        ("Luminance", "RMSE", each(lambda s: _num(s.luminance.rmse, 2))),
        ("Luminance", "NRMSE", each(lambda s: _pct(s.luminance.nrmse))),
        ("Chrominance", "RMSE", each(lambda s: _num(s.chrominance.rmse, 2))),
        ("Chrominance", "NRMSE", each(lambda s: _pct(s.chrominance.nrmse))),
        (
            "Classification",
            "direct / palette",
            each(lambda s: f"{_pct(s.class_direct_accuracy)} / {_pct(s.class_palette_accuracy)}"),
        ),
    ]
    tracking = [
        ("Matching", "gate [px]", each(lambda s: f"{s.gate_px:g}")),
        ("Matching", "objects", each(lambda s: "fully visible" if s.fully_visible_only else "all")),
        ("Tracking", "Recall", each(lambda s: _pct(s.recall))),
        ("Tracking", "Precision", each(lambda s: _pct(s.precision))),
        ("Tracking", "ID switches", each(lambda s: str(s.id_switches))),
        ("Tracking", "tracks per object", each(lambda s: "-" if s.tracks_per_object is None else f"{s.tracks_per_object:.2f}")),
        ("Evaluations", "filter steps", each(lambda s: str(s.n_steps))),
        ("Evaluations", "steps with no record", each(lambda s: str(s.n_steps_missing))),
        ("Evaluations", "track records", each(lambda s: str(s.n_track_records))),
        ("Evaluations", "object evaluations", each(lambda s: str(s.n_gt_evaluations))),
        ("Evaluations", "matches", each(lambda s: str(s.n_matches))),
        ("Evaluations", "velocity (|V_gt| > 0)", each(lambda s: str(s.n_velocity_evaluations))),
        ("Evaluations", "colour", each(lambda s: str(s.n_colour_evaluations))),
        ("Evaluations", "classification", each(lambda s: str(s.n_class_evaluations))),
        ("Evaluations", "label not in palette", each(lambda s: str(s.n_labels_not_in_palette))),
    ]
    return "\n\n".join(
        [
            _render("Velocity estimation, as the paper's Table 5", cols, velocity),
            _render("Colour estimation, as the paper's Table 7", cols, colour),
            _render("Tracking (beyond the paper)", cols, tracking),
        ]
    )
