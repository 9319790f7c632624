"""Scenes: TOML files (synthetic or video), the built-in ones by name, and their frame sources."""

from __future__ import annotations

import dataclasses
import tomllib
from importlib import resources
from pathlib import Path

from pydantic import ValidationError

from evclust.errors import EvclustError, read_text, validation_message
from evclust.scenes.schema import SceneSpec, SensorSpec
from evclust.scenes.synthetic import TRUTH_COLUMNS, SyntheticSource
from evclust.scenes.truth import write_truth
from evclust.scenes.video import VideoSource

__all__ = ["Scene", "SceneSpec", "SensorSpec", "load_scene", "scene_from_toml", "builtin_scenes", "write_truth", "TRUTH_COLUMNS"]


@dataclasses.dataclass
class Scene:
    spec: SceneSpec
    source: SyntheticSource | VideoSource
    truth_path: Path | None = None  # a video's ground-truth CSV, if it has one
    label: str = "<scene>"  # how messages name the scene: its file, video or built-in name

    @property
    def has_truth(self) -> bool:
        return isinstance(self.source, SyntheticSource) or self.truth_path is not None


def builtin_scenes() -> list[str]:
    folder = resources.files("evclust.scenes") / "builtin"
    return sorted(p.name[: -len(".toml")] for p in folder.iterdir() if p.name.endswith(".toml"))


def parse_scene(text: str, name: str) -> SceneSpec:
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise EvclustError(f"{name}: malformed TOML: {exc}") from None
    try:
        return SceneSpec.model_validate(data)
    except ValidationError as exc:
        raise EvclustError(f"{name}: {validation_message(exc)}") from None


def scene_from_toml(text: str, name: str = "<scene>", base_dir: Path = Path(".")) -> Scene:
    """A synthetic scene from TOML text (a video scene needs a file: use load_scene)."""
    spec = parse_scene(text, name)
    if spec.video is not None:
        raise EvclustError(f"{name}: scene_from_toml takes synthetic scenes only")
    return Scene(spec, SyntheticSource(spec, base_dir, spec.name or name), label=name)


def load_scene(ref: str | Path, fps: float | None = None, max_frames: int | None = None) -> Scene:
    """A built-in name, a TOML scene file, a video file or a folder of images."""
    ref_str = str(ref)
    path = Path(ref_str)
    if path.suffix.lower() == ".toml":
        if not path.is_file():
            raise EvclustError(f"{path}: no such scene file")
        spec = parse_scene(read_text(path), str(path))
        base = path.parent
        label = str(path)
    elif path.exists():  # a video or a folder of images
        spec = SceneSpec(video=ref_str, fps=fps)
        base = Path(".")
        label = ref_str
    elif path.suffix == "" and "/" not in ref_str:
        if ref_str not in builtin_scenes():
            raise EvclustError(f"unknown scene '{ref_str}': built-in scenes are {', '.join(builtin_scenes())}")
        text = (resources.files("evclust.scenes") / "builtin" / f"{ref_str}.toml").read_text()
        spec = parse_scene(text, f"built-in scene '{ref_str}'")
        base = Path(".")
        label = ref_str
    else:
        raise EvclustError(f"{path}: no such scene file, video or image folder")

    if spec.video is None:
        if max_frames:
            spec = spec.model_copy(update={"frames": min(spec.frames, max_frames)})
        return Scene(spec, SyntheticSource(spec, base, spec.name or label), label=label)
    video = (base / spec.video) if not Path(spec.video).is_absolute() else Path(spec.video)
    source = VideoSource(video, fps=fps or spec.fps, max_frames=max_frames or spec.frames)
    truth = (base / spec.truth) if spec.truth else video.with_suffix(".csv")
    return Scene(spec, source, truth if truth.is_file() and truth != video else None, label=label)
