"""Shared helpers: small scenes from TOML text, and simulating them."""

from __future__ import annotations

import numpy as np
import pytest

from evclust.scenes import scene_from_toml
from evclust.simulator import simulate_scene


def simulate_toml(text: str, seed: int | None = None):
    return simulate_scene(scene_from_toml(text, "test"), seed=seed)


def pixel_events(events: np.ndarray, x: int, y: int) -> np.ndarray:
    return events[(events["x"] == x) & (events["y"] == y)]


@pytest.fixture
def simulate():
    return simulate_toml
