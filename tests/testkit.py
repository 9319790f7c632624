"""Shared helpers of the tests: small scenes from TOML text, simulating them, the classic clusterer
configuration. A module of its own, imported by name: `conftest` is no importable name with two
conftest.py files (tests/ and tb/) in one run."""

from __future__ import annotations

import numpy as np

from evclust.scenes import scene_from_toml
from evclust.simulator import simulate_scene


# One red square crossing a small sensor: the CLI tests' scene.
GOOD_SCENE = """
width = 40
height = 30
fps = 30
frames = 6
[[objects]]
id = 1
label = "red"
size = [8, 8]
colour = [210, 40, 40]
start = [10, 15]
legs = [{ frames = 5, velocity = [2.0, 0.0] }]
"""


def simulate_toml(text: str, seed: int | None = None):
    return simulate_scene(scene_from_toml(text, "test"), seed=seed)


def pixel_events(events: np.ndarray, x: int, y: int) -> np.ndarray:
    return events[(events["x"] == x) & (events["y"] == y)]


# The configuration the analytic clusterer tests were derived for: the defaults of before the
# generalization suite, with its additions (scaled seek, merging, noise gate) off. The suite's
# defaults are tuned for scenes nobody tuned for; these tests check the paper's mechanisms.
CLASSIC = dict(
    seek_margin=12.0, r_init=10.0, r_min=2.0, r_max=80.0, size_gain=1.5, alpha_pos=0.98, alpha_size=0.99,
    t_half_us=20000.0, a_min=1.0, a_valid=20.0, alpha_vel_mcm=0.9999, gamma_mode="count", alpha_vel_int=0.7,
    tau_us=100000.0, alpha_lum=0.99, alpha_chro=0.99, p_correction=1.0, v_min=0.3, exit_margin=10.0,
    seek_scale=0.0, merge=False, noise_gate=0.0, create_support=False,
)  # fmt: skip


def classic_params(**update):
    from evclust.clusterer import ClustererParams

    return ClustererParams(**{**CLASSIC, **update})
