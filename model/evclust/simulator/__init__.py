"""The colour event simulator (SPEC §3): a scene's frames through the sensor model.

The names below are loaded when first used (PEP 562): `evclust track events.aedat4` reaches
evclust.simulator.source to open a file, and must not pay for compiling or loading the sensor
effects' compiled code (about 0.3 s) on the way.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from evclust.scenes import Scene
    from evclust.simulator.effects import EFFECTS, SensorGeometry, build_effects
    from evclust.simulator.pipeline import Simulation, SimulationStream, Simulator

_LAZY = {
    "EFFECTS": "evclust.simulator.effects",
    "SensorGeometry": "evclust.simulator.effects",
    "build_effects": "evclust.simulator.effects",
    "Simulation": "evclust.simulator.pipeline",
    "SimulationStream": "evclust.simulator.pipeline",
    "Simulator": "evclust.simulator.pipeline",
}

__all__ = [
    "EFFECTS",
    "Simulation",
    "SimulationStream",
    "Simulator",
    "SensorGeometry",
    "build_effects",
    "make_simulator",
    "simulate_scene",
    "stream_scene",
]


def __getattr__(name: str):
    if name in _LAZY:
        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def make_simulator(scene: Scene, seed: int | None = None) -> Simulator:
    """Build the sensor of `scene`; bad effect names or parameters fail here, before any output."""
    from evclust.errors import EvclustError
    from evclust.simulator.effects import SensorGeometry, build_effects
    from evclust.simulator.pipeline import Simulator

    src = scene.source
    geometry = SensorGeometry(src.width, src.height, src.t_sample_us)
    try:
        effects = build_effects(scene.spec.effects, geometry, scene.spec.seed if seed is None else seed)
    except EvclustError as exc:
        raise EvclustError(f"{scene.label}: {exc}") from None
    return Simulator(scene.spec.sensor, geometry, effects)


def simulate_scene(scene: Scene, seed: int | None = None, progress: bool = False) -> Simulation:
    simulator = make_simulator(scene, seed)
    src = scene.source
    return simulator.run(src.frames(), source=src.source, total=src.n_samples, progress=progress, frame_period_us=src.t_frame_us)


def stream_scene(scene: Scene, seed: int | None = None, progress: bool = False) -> SimulationStream:
    """The events of `scene` interval by interval, for streams larger than memory."""
    simulator = make_simulator(scene, seed)
    src = scene.source
    return simulator.stream(src.frames(), source=src.source, total=src.n_samples, progress=progress, frame_period_us=src.t_frame_us)
