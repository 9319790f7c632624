"""The suite's scenes on disk: generated, written and simulated once, then reused.

Each scene of a split lives in the suite folder as NAME.toml (+ NAME.mp4 for a codec scene),
NAME.json (what it is made of), NAME_truth.csv (exact ground truth) and NAME.npz (its events).
NAME.key holds a hash of the scene and of this package's version: a scene whose key still
matches is not simulated again.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
from pathlib import Path

from evclust import __version__
from evclust.errors import EvclustError, atomic_output
from evclust.events import write_events
from evclust.scenes import load_scene, write_truth
from evclust.choices import SPLITS
from evclust.scenes.generate import GeneratedScene, generate_scene, scene_name, write_scene
from evclust.simulator import simulate_scene


@dataclasses.dataclass(frozen=True)
class SceneFiles:
    name: str
    folder: Path

    @property
    def toml(self) -> Path:
        return self.folder / f"{self.name}.toml"

    @property
    def events(self) -> Path:
        return self.folder / f"{self.name}.npz"

    @property
    def truth(self) -> Path:
        return self.folder / f"{self.name}_truth.csv"

    @property
    def facts(self) -> dict:
        return json.loads((self.folder / f"{self.name}.json").read_text())

    @property
    def key_file(self) -> Path:
        return self.folder / f"{self.name}.key"


def split_seeds(split: str) -> tuple[int, ...]:
    if split not in SPLITS:
        raise EvclustError(f"unknown split '{split}' (the suite has {', '.join(SPLITS)})")
    return SPLITS[split]


def _key(scene: GeneratedScene) -> str:
    text = json.dumps([scene.spec.model_dump(mode="json"), scene.codec, __version__], sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()


def prepare_scene(seed: int, folder: str | Path) -> SceneFiles:
    """Write and simulate the scene of a seed, unless the folder already holds it."""
    files = SceneFiles(scene_name(seed), Path(folder))
    scene = generate_scene(seed)
    key = _key(scene)
    if files.key_file.is_file() and files.key_file.read_text().strip() == key and files.events.is_file() and files.truth.is_file():
        return files
    write_scene(scene, files.folder)
    loaded = load_scene(files.toml)
    result = simulate_scene(loaded)
    write_events(files.events, result.events, result.meta)
    if loaded.truth_path is None:  # a synthetic scene: its truth from the source (a codec scene's came with it)
        write_truth(files.truth, [r for r in loaded.source.truth() if r["frame"] < result.frames])
    with atomic_output(files.key_file) as tmp:
        Path(tmp).write_text(key + "\n")
    return files
