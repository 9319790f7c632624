"""Procedural scenes for the generalization suite: one seed, one scene (docs/GENERALIZATION.md).

A seed draws a sensor size, a frame rate, a background (uniform, textured or a gradient), 1 to
20 rigid objects (uniform or textured, 8 to 150 px, 0.1 to 12 px/frame) on paths with turns,
entries, exits, crossings and occlusions, and a sensor. Even seeds go through a lossy video
codec (OpenCV's MPEG-4 writer) and back, so codec noise is in their events; odd seeds are
simulated from the exact renders. Either way the ground truth is exact.

The split is fixed: `SPLITS["tuning"]` may be used to choose parameters and design rules,
`SPLITS["test"]` only to report them.
"""

from __future__ import annotations

import dataclasses
import json
import math
import re
from pathlib import Path

import cv2
import numpy as np
import tomli_w

from evclust.colour import NAMED_COLOURS, rgb_to_ycbcr
from evclust.errors import EvclustError, atomic_output
from evclust.scenes.schema import BackgroundSpec, LegSpec, ObjectSpec, PatchSpec, SceneSpec, SensorSpec
from evclust.scenes.synthetic import SyntheticSource
from evclust.scenes.truth import write_truth

# The fixed split. Disjoint seed ranges: a seed's scene never depends on the split it is in.

SENSOR_SIZES = ((160, 120), (240, 180), (320, 240), (346, 260), (480, 270), (640, 360), (640, 480), (960, 540), (1280, 720))
FRAME_RATES = (10, 15, 20, 25, 30, 50, 60)
SIZE_PX = (8.0, 150.0)  # object size (the larger side), drawn log-uniformly
SPEED_PX = (0.1, 12.0)  # px/frame, drawn log-uniformly
MAX_OBJECTS = 20
MIN_LOG_CONTRAST = 0.35  # |ln(Y_obj + 1) - ln(Y_bg + 1)| over the whole background: above every θ drawn
DURATION_S = (3.0, 8.0)
MIN_FRAMES = 30
MAX_PIXEL_FRAMES = 2e8  # keeps a scene to a few seconds of simulation
NOISE_HZ = (0.01, 0.2)  # background activity per pixel, on a third of the scenes: a modern sensor in fair light
CODEC = ("mp4v", ".mp4")  # OpenCV's MPEG-4 part 2 writer: lossy, in every OpenCV build we ship with


@dataclasses.dataclass(frozen=True)
class GeneratedScene:
    """A drawn scene and what it is made of: the categories the suite reports by."""

    seed: int
    spec: SceneSpec  # the synthetic scene (a codec scene's frames are rendered from it)
    codec: bool
    textured: tuple[bool, ...]  # per object
    noise: bool  # the sensor adds background activity

    @property
    def name(self) -> str:
        return scene_name(self.seed)


def scene_name(seed: int) -> str:
    return f"gen_{seed:04d}"


def _log_uniform(rng, lo: float, hi: float) -> float:
    return float(math.exp(rng.uniform(math.log(lo), math.log(hi))))


def _luma(rgb) -> float:
    return float(rgb_to_ycbcr(np.asarray(rgb, dtype=np.float64))[0])


def _background(rng) -> tuple[BackgroundSpec, tuple[float, float]]:
    """A background and the range of its luma."""
    kind = ("uniform", "texture", "gradient")[int(rng.integers(3))]
    base = rng.uniform(50, 200)
    tint = rng.uniform(-20, 20, 3)
    colour = tuple(float(np.clip(base + t, 0, 255)) for t in tint)
    y = _luma(colour)
    if kind == "uniform":
        return BackgroundSpec(kind="uniform", colour=colour), (y, y)
    if kind == "texture":
        contrast = float(rng.uniform(3, 20))
        spec = BackgroundSpec(kind="texture", colour=colour, contrast=contrast, scale=float(rng.uniform(2, 20)))
        return spec, (max(y - 2 * contrast, 0.0), min(y + 2 * contrast, 255.0))
    end = tuple(float(np.clip(c + rng.uniform(-60, 60), 0, 255)) for c in colour)
    spec = BackgroundSpec(kind="gradient", colour=colour, colour_to=end, angle_deg=float(rng.uniform(0, 360)))
    y_end = _luma(end)
    return spec, (min(y, y_end), max(y, y_end))


COLOUR_JITTER = 12.0  # RGB levels around the palette entry


def _stands_out(rgb, luma_range: tuple[float, float], margin: float = 0.0) -> bool:
    lo, hi = (math.log(v + 1.0) for v in luma_range)
    level = math.log(_luma(rgb) + 1.0)
    return level <= lo - MIN_LOG_CONTRAST - margin or level >= hi + MIN_LOG_CONTRAST + margin


def _usable_entries(luma_range) -> list:
    """Palette entries whose own colour stands out of the background."""
    return [e for e in NAMED_COLOURS if _stands_out(e.rgb, luma_range)]


def _object_colour(rng, luma_range: tuple[float, float]):
    """A palette entry (its name is the label) and its colour jittered, as long as it still
    stands out of the whole background in log contrast."""
    entries = _usable_entries(luma_range)
    entry = entries[int(rng.integers(len(entries)))]
    for _ in range(20):
        rgb = tuple(float(np.clip(c + rng.uniform(-COLOUR_JITTER, COLOUR_JITTER), 0, 255)) for c in entry.rgb)
        if _stands_out(rgb, luma_range):
            return entry.name, rgb
    return entry.name, tuple(float(c) for c in entry.rgb)


def _patches(rng, size: tuple[float, float], rgb) -> list[PatchSpec]:
    """A texture: darker and lighter blobs of the object's own colour, inside its box."""
    patches = []
    w, h = size
    for _ in range(int(rng.integers(4, 11))):
        pw, ph = w * rng.uniform(0.15, 0.4), h * rng.uniform(0.15, 0.4)
        ox, oy = rng.uniform(-(w - pw) / 2, (w - pw) / 2), rng.uniform(-(h - ph) / 2, (h - ph) / 2)
        gain = rng.uniform(0.6, 1.4)
        colour = tuple(float(np.clip(c * gain, 0, 255)) for c in rgb)
        shape = ("rectangle", "ellipse")[int(rng.integers(2))]
        patches.append(PatchSpec(shape=shape, offset=(float(ox), float(oy)), size=(float(pw), float(ph)), colour=colour))
    return patches


def _legs(rng, speed: float, frames: int) -> list[LegSpec]:
    """1 to 3 constant-velocity legs; each turn changes the heading by 30 to 150 degrees and the
    speed by up to a factor of 2 (kept in SPEED_PX)."""
    n = 1 if rng.random() < 0.5 else int(rng.integers(2, 4))
    cuts = np.sort(rng.choice(np.arange(1, frames), size=n - 1, replace=False)) if n > 1 else np.array([], int)
    bounds = np.r_[0, cuts, frames]
    heading = rng.uniform(0, 2 * math.pi)
    legs = []
    for a, b in zip(bounds[:-1], bounds[1:]):
        legs.append(LegSpec(frames=int(b - a), velocity=(float(speed * math.cos(heading)), float(speed * math.sin(heading)))))
        heading += rng.choice((-1, 1)) * math.radians(rng.uniform(30, 150))
        speed = float(np.clip(speed * math.exp(rng.uniform(-math.log(2), math.log(2))), *SPEED_PX))
    return legs


def _start(rng, size, legs, width, height, enters: bool):
    """A start point inside the view, or, for an entry, just outside the border the first leg
    points away from, so the object comes in."""
    w, h = size
    if not enters:
        return (float(rng.uniform(w / 2, width - w / 2)), float(rng.uniform(h / 2, height - h / 2)))
    vx, vy = legs[0].velocity
    if abs(vx) >= abs(vy):
        x = -w / 2 - 1 if vx > 0 else width + w / 2
        return (float(x), float(rng.uniform(h / 2, height - h / 2)))
    y = -h / 2 - 1 if vy > 0 else height + h / 2
    return (float(rng.uniform(w / 2, width - w / 2)), float(y))


def _cross(rng, a: ObjectSpec, b: ObjectSpec, frames: int) -> ObjectSpec:
    """Move b's start so that b passes through a's centre at a frame both are in the scene
    (drawn later, b hides a where they overlap)."""
    first = max(a.start_frame, b.start_frame)
    meet = int(rng.integers(first + (frames - first) // 4, first + max((frames - first) * 3 // 4, 1) + 1))
    point = np.asarray(a.start, dtype=np.float64)
    t = a.start_frame
    for leg in a.legs:  # a's centre at frame `meet`
        step = min(leg.frames, max(meet - t, 0))
        point += step * np.asarray(leg.velocity)
        t += leg.frames
    back = np.zeros(2)
    t = b.start_frame
    for leg in b.legs:  # b's displacement from its start to `meet`
        step = min(leg.frames, max(meet - t, 0))
        back += step * np.asarray(leg.velocity)
        t += leg.frames
    start = point - back
    return b.model_copy(update={"start": (float(start[0]), float(start[1]))})


def generate_scene(seed: int) -> GeneratedScene:
    """The scene of a seed: the same seed gives the same scene on every machine."""
    if seed < 0:
        raise EvclustError(f"scene seed {seed}: expected a non-negative integer")
    rng = np.random.default_rng([seed, 0x5CE4E])
    width, height = SENSOR_SIZES[int(rng.integers(len(SENSOR_SIZES)))]
    fps = float(FRAME_RATES[int(rng.integers(len(FRAME_RATES)))])
    frames = int(round(fps * rng.uniform(*DURATION_S)))
    frames = int(max(MIN_FRAMES, min(frames, MAX_PIXEL_FRAMES // (width * height))))
    background, luma_range = _background(rng)
    while len(_usable_entries(luma_range)) < 2:  # too few colours stand out of it
        background, luma_range = _background(rng)

    n_wanted = 1 + int((MAX_OBJECTS - 1) * rng.random() ** 2)  # few objects more often than many
    max_size = min(SIZE_PX[1], 0.45 * min(width, height))
    objects, textured, area = [], [], 0.0
    for i in range(n_wanted):
        side = _log_uniform(rng, SIZE_PX[0], max(max_size, SIZE_PX[0]))
        aspect = _log_uniform(rng, 0.5, 2.0)
        size = (side, side * aspect) if aspect < 1 else (side / aspect, side)
        if objects and area + size[0] * size[1] > 0.3 * width * height:
            break  # the view is full enough
        label, rgb = _object_colour(rng, luma_range)
        is_textured = bool(rng.random() < 0.5)
        start_frame = 0 if rng.random() < 0.6 else int(rng.integers(0, frames // 2))
        legs = _legs(rng, _log_uniform(rng, *SPEED_PX), frames - 1 - start_frame)
        start = _start(rng, size, legs, width, height, enters=bool(rng.random() < 0.3))
        objects.append(ObjectSpec(
            id=i + 1, label=label, shape=("rectangle", "ellipse")[int(rng.integers(2))],
            size=(float(size[0]), float(size[1])), colour=rgb,
            patches=_patches(rng, size, rgb) if is_textured else [],
            start=start, start_frame=start_frame, legs=legs,
        ))  # fmt: skip
        textured.append(is_textured)
        area += size[0] * size[1]
    if len(objects) >= 2 and rng.random() < 0.5:
        i, j = (int(v) for v in rng.choice(len(objects), size=2, replace=False))
        objects[max(i, j)] = _cross(rng, objects[min(i, j)], objects[max(i, j)], frames)

    noise = bool(rng.random() < 1 / 3)
    effects = {"background_activity": {"rate_hz": round(_log_uniform(rng, *NOISE_HZ), 4)}} if noise else {}
    threshold = round(float(rng.uniform(0.15, 0.3)), 3)
    max_speed = max((math.hypot(*leg.velocity) for o in objects for leg in o.legs), default=1.0)
    codec = seed % 2 == 0
    spec = dict(
        name=scene_name(seed),
        description=f"generated from seed {seed}: {len(objects)} objects, {background.kind} background{', codec' if codec else ''}",
        seed=seed, width=width, height=height, fps=fps, frames=frames,
        # Between frames the sensor sees renders at most 3 px apart (a video has only its frames).
        substeps=1 if codec else int(min(4, max(1, math.ceil(max_speed / 3)))),
        background=background, objects=objects,
        sensor=SensorSpec(threshold_on=threshold, threshold_off=threshold), effects=effects,
    )  # fmt: skip
    # Rounded to what the scene file says, so the file alone rebuilds the scene exactly.
    spec = SceneSpec.model_validate(_rounded(SceneSpec(**spec).model_dump(mode="json")))
    return GeneratedScene(seed, spec, codec, tuple(textured), noise)


def _rounded(value, digits: int = 3):
    if isinstance(value, float):
        return round(value, digits)
    if isinstance(value, dict):
        return {k: _rounded(v, digits) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_rounded(v, digits) for v in value]
    return value


_NUMBER_ARRAY = re.compile(r"\[\n((?:\s+-?[0-9.e+-]+,\n)+)\]")


def _toml(spec: SceneSpec, header: str) -> str:
    data = spec.model_dump(mode="json", exclude_defaults=True)
    text = tomli_w.dumps(data)
    # tomli_w puts each array element on a line of its own; coordinates read better inline.
    text = _NUMBER_ARRAY.sub(lambda m: "[" + ", ".join(v.strip().rstrip(",") for v in m.group(1).splitlines()) + "]", text)
    return f"# {header}\n" + text


def write_scene(scene: GeneratedScene, folder: str | Path) -> Path:
    """Write the scene into `folder`: NAME.toml (a synthetic scene, or for a codec scene a video
    scene pointing at NAME.mp4 and its exact ground truth NAME_truth.csv), and NAME.json, what
    the scene is made of. Returns the TOML's path."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    name = scene.name
    toml_path = folder / f"{name}.toml"
    header = f"evclust scenes --generate {scene.seed}: {scene.spec.description}"
    if scene.codec:
        source = SyntheticSource(scene.spec, folder, name)
        video = folder / f"{name}{CODEC[1]}"
        with atomic_output(video) as tmp:
            # The temporary file keeps the suffix, which tells OpenCV the container.
            writer = cv2.VideoWriter(str(tmp), cv2.VideoWriter_fourcc(*CODEC[0]), scene.spec.fps, (source.width, source.height))
            if not writer.isOpened():
                raise EvclustError(f"{video}: OpenCV cannot open a {CODEC[0]} video writer")
            for k in range(source.n_frames):
                frame = np.clip(np.rint(source.render(k)), 0, 255).astype(np.uint8)
                writer.write(cv2.cvtColor(frame, cv2.COLOR_RGB2BGR))
            writer.release()
        write_truth(folder / f"{name}_truth.csv", source.truth())
        video_spec = SceneSpec(
            name=name, description=scene.spec.description, seed=scene.seed, fps=scene.spec.fps,
            video=video.name, truth=f"{name}_truth.csv", sensor=scene.spec.sensor, effects=scene.spec.effects,
        )  # fmt: skip
        text = _toml(video_spec, header + f" (frames rendered, written through the {CODEC[0]} codec)")
    else:
        text = _toml(scene.spec, header)
    with atomic_output(toml_path) as tmp:
        Path(tmp).write_text(text)
    facts = {
        "seed": scene.seed, "codec": scene.codec, "noise": scene.noise, "width": scene.spec.width,
        "height": scene.spec.height, "fps": scene.spec.fps, "frames": scene.spec.frames,
        "background": scene.spec.background.kind,
        "objects": [
            {"id": o.id, "label": o.label, "size": max(o.size), "speed": max(math.hypot(*leg.velocity) for leg in o.legs),
             "textured": t, "legs": len(o.legs)}
            for o, t in zip(scene.spec.objects, scene.textured)
        ],
    }  # fmt: skip
    with atomic_output(folder / f"{name}.json") as tmp:
        Path(tmp).write_text(json.dumps(facts, indent=1) + "\n")
    return toml_path
