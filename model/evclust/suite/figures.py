"""The picture grid of typical failures (docs/GENERALIZATION.md): for each kind of failure, the
scene and frame where it is most frequent, drawn as events with the tracker's records over them
(evclust.render.tracks) and the true boxes in white."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

from evclust.run import track_events
from evclust.events import read_events
from evclust.metrics.tracking import FAILURES
from evclust.render.tracks import FrameDrawer, to_canvas
from evclust.scenes.truth import read_truth

TRUTH_BOX = (255, 255, 255)
CAPTIONS = {
    "missed": "missed: no record within the object's radius",
    "off_centre": "off-centre: the nearest record is too far from the centre",
    "fragment": "fragments: more records than objects",
    "ghost": "ghost: a record on no object",
}


def worst_samples(results, per_kind: int = 1) -> list[tuple[str, object, int, int]]:
    """(kind, result, frame, count): for each failure kind, the scene and frame with the most."""
    picks = []
    for j, kind in enumerate(FAILURES):
        best = []
        for r in results:
            if r.failures.size == 0:
                continue
            i = int(np.argmax(r.failures[:, j]))
            best.append((int(r.failures[i, j]), r.name, r, int(r.frames[i])))
        best.sort(key=lambda b: -b[0])
        for count, _, r, frame in best[:per_kind]:
            if count:
                picks.append((kind, r, frame, count))
    return picks


def draw_sample(files, params, frame: int, scale: int = 1) -> np.ndarray:
    """RGB picture of one scene at one frame: a frame period of events, the reported records
    (objects, or clusters without an object layer) of the last filter step, and the true boxes."""
    events, meta = read_events(files.events)
    truth = read_truth(files.truth)
    run = track_events(events, meta, params)
    drawer = FrameDrawer(events, meta, *run.output, scale=scale)
    t = frame * run.meta.t_frame_us
    canvas = drawer.draw(t)
    for row in truth[truth["frame"] == frame]:
        x0, y0 = to_canvas([row["cx"] - row["w"] / 2, row["cy"] - row["h"] / 2], scale)
        x1, y1 = to_canvas([row["cx"] + row["w"] / 2, row["cy"] + row["h"] / 2], scale)
        cv2.rectangle(canvas, (int(x0), int(y0)), (int(x1), int(y1)), TRUTH_BOX, 1, cv2.LINE_AA)
    return cv2.cvtColor(canvas, cv2.COLOR_BGR2RGB)


def failure_grid(results, files_of, params, path: str | Path) -> list[tuple[str, str, int, int]]:
    """Write the grid (one panel per failure kind) to `path`; return what each panel shows."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    picks = worst_samples(results)
    if not picks:
        return []
    cols = 2
    rows = (len(picks) + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(6.5 * cols, 4.4 * rows), squeeze=False)
    for ax in axes.ravel():
        ax.axis("off")
    for ax, (kind, r, frame, count) in zip(axes.ravel(), picks):
        ax.imshow(draw_sample(files_of(r.name), params, frame))
        f = r.facts
        ax.set_title(f"{CAPTIONS[kind]}\n{r.name} frame {frame} ({count}): {f['width']}x{f['height']}, {f['fps']:g} fps, "
                     f"{len(f['objects'])} objects{', codec' if f['codec'] else ''}{', noise' if f['noise'] else ''}",
                     fontsize=9)  # fmt: skip
    legend = "cyan: object boxes, dashed while coasting" if params.objects else "red: cluster boxes; green: seek regions"
    fig.suptitle(f"Typical failures on the test split (white: true boxes; {legend})", fontsize=11)
    fig.tight_layout()
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return [(kind, r.name, frame, count) for kind, r, frame, count in picks]
