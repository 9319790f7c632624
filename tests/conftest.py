"""Shared helpers: small scenes from TOML text, and simulating them."""

from __future__ import annotations

import numpy as np
import pytest

from evclust.scenes import scene_from_toml
from evclust.simulator import make_simulator


def simulate_toml(text: str, seed: int | None = None):
    scene = scene_from_toml(text)
    return make_simulator(scene, seed).run(scene.source.frames(), source="test")


def pixel_events(events: np.ndarray, x: int, y: int) -> np.ndarray:
    return events[(events["x"] == x) & (events["y"] == y)]


@pytest.fixture
def simulate():
    return simulate_toml
