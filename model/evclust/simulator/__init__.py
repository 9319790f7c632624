"""The colour event simulator (SPEC §3): a scene's frames through the sensor model."""

from __future__ import annotations

from evclust.errors import EvclustError
from evclust.scenes import Scene
from evclust.simulator.effects import EFFECTS, SensorGeometry, build_effects
from evclust.simulator.pipeline import Simulation, SimulationStream, Simulator

__all__ = [
    "EFFECTS",
    "Simulation",
    "SimulationStream",
    "Simulator",
    "stream_scene",
    "SensorGeometry",
    "build_effects",
    "make_simulator",
    "simulate_scene",
]


def make_simulator(scene: Scene, seed: int | None = None) -> Simulator:
    """Build the sensor of `scene`; bad effect names or parameters fail here, before any output."""
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
