"""Events from an event file or straight from a scene: what `track`, `render` and `show` read.

Giving a scene (a built-in name, a scene TOML, a video or an image folder) where an event file is
expected simulates it on the fly, interval by interval, so a video can be tracked without an
event file on disk. Both kinds offer the reader's interface: `meta`, `count`, `chunks()`, `read()`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from evclust.events import EventReader, concat_events
from evclust.events.io import SUFFIXES as EVENT_SUFFIXES

SCENE_SUFFIXES = (".toml",)
VIDEO_SUFFIXES = (".avi", ".mp4", ".mkv", ".mov", ".webm", ".mpg", ".mpeg", ".m4v", ".wmv")


class SceneEvents:
    """A scene simulated as it is read. `count` is unknown until the end (None)."""

    count = None

    def __init__(self, ref: str, seed: int | None = None, progress: bool = False):
        from evclust.scenes import load_scene
        from evclust.simulator import stream_scene

        self.ref = ref
        self.stream = stream_scene(load_scene(ref), seed=seed, progress=progress)
        self.meta = self.stream.meta

    def chunks(self):
        return iter(self.stream)

    def read(self) -> np.ndarray:
        return concat_events(self.chunks())


def is_scene(ref: str | Path) -> bool:
    path = Path(str(ref))
    suffix = path.suffix.lower()
    if suffix in EVENT_SUFFIXES:
        return False
    return suffix in SCENE_SUFFIXES + VIDEO_SUFFIXES or path.is_dir() or (suffix == "" and "/" not in str(ref) and not path.exists())


def open_events(ref: str | Path, progress: bool = False, sensor_size: tuple[int, int] | None = None, polarity: str = "auto"):
    """An EventReader for an event file, else a SceneEvents that simulates the scene.
    `sensor_size` and `polarity` are for event files (EventReader); a scene has its own size."""
    if is_scene(ref):
        from evclust.errors import EvclustError

        if sensor_size is not None or polarity != "auto":
            raise EvclustError(f"{ref}: --sensor-size and --polarity are for event files; a scene or video gives its own")
        return SceneEvents(str(ref), progress=progress)
    return EventReader(ref, sensor_size, polarity)
