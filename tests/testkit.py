"""Shared helpers of the tests: small scenes from TOML text, simulating them, the classic clusterer
configuration. A module of its own, imported by name: `conftest` is no importable name with two
conftest.py files (tests/ and tb/) in one run."""

from __future__ import annotations

import numpy as np

from evclust.cli import main
from evclust.scenes import scene_from_toml
from evclust.simulator import simulate_scene

FPS = 100.0  # square_scene's frame rate


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


# The CLI in-process: (exit code, stdout, stderr), and the one-line error every bad input gets.
def run_cli(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def assert_one_line_error(code, err, *fragments):
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("evclust: error: "), err
    assert "Traceback" not in err
    for fragment in fragments:
        assert fragment in lines[0]


def square_scene(legs, start=(40.0, 60.0), colour=(240, 240, 240), bg=(60, 60, 60), width=240, height=120, frames=None, size=20, theta=0.2):
    frames = frames or 1 + sum(n for n, _ in legs)
    leg_text = ", ".join(f"{{ frames = {n}, velocity = [{vx}, {vy}] }}" for n, (vx, vy) in legs)
    return f"""
width = {width}
height = {height}
fps = {FPS}
frames = {frames}
[sensor]
threshold_on = {theta}
threshold_off = {theta}
[background]
colour = [{bg[0]}, {bg[1]}, {bg[2]}]
[[objects]]
id = 1
label = "obj"
size = [{size}, {size}]
colour = [{colour[0]}, {colour[1]}, {colour[2]}]
start = [{start[0]}, {start[1]}]
legs = [{leg_text}]
"""
