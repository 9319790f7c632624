"""The registry of sensor effects, in pipeline order. A scene names the ones it wants."""

from __future__ import annotations

from pydantic import ValidationError

from evclust.errors import EvclustError, validation_message
from evclust.simulator.effects.base import Effect, EffectParams, Interval, SensorGeometry
from evclust.simulator.effects.background import BackgroundActivity
from evclust.simulator.effects.bayer import Bayer
from evclust.simulator.effects.hot_pixels import HotPixels
from evclust.simulator.effects.lin_log import LinLog
from evclust.simulator.effects.lowpass import PhotoreceptorLowpass
from evclust.simulator.effects.mismatch import ThresholdMismatch
from evclust.simulator.effects.readout import ReadoutLimit
from evclust.simulator.effects.refractory import Refractory
from evclust.simulator.effects.tdc import TdcQuantisation
from evclust.simulator.effects.tfs import TfsLatency
from evclust.simulator.effects.timestamp import TimestampQuantisation

# Pipeline order follows the physical chain: pixel -> photoreceptor -> change detector -> intensity
# measurement -> timestamp -> readout.
EFFECTS: dict[str, type[Effect]] = {
    cls.name: cls
    for cls in (
        Bayer,
        LinLog,
        PhotoreceptorLowpass,
        ThresholdMismatch,
        BackgroundActivity,
        HotPixels,
        Refractory,
        TdcQuantisation,
        TfsLatency,
        TimestampQuantisation,
        ReadoutLimit,
    )
}

__all__ = ["EFFECTS", "Effect", "EffectParams", "Interval", "SensorGeometry", "build_effects"]


def build_effects(config: dict[str, dict], geometry: SensorGeometry, seed: int) -> list[Effect]:
    """Construct the effects named in `config` (name -> parameters), and only those, in pipeline order."""
    unknown = sorted(set(config) - set(EFFECTS))
    if unknown:
        raise EvclustError(f"effects.{unknown[0]}: unknown effect (known: {', '.join(EFFECTS)})")
    effects = []
    for name, cls in EFFECTS.items():
        if name not in config:
            continue
        raw = config[name]
        if not isinstance(raw, dict):
            raise EvclustError(f"effects.{name}: expected a table of parameters, got {raw!r}")
        try:
            params = cls.Params.model_validate(raw)
        except ValidationError as exc:
            raise EvclustError(validation_message(exc, f"effects.{name}")) from None
        effects.append(cls(params, geometry, seed))
    return effects
