"""evclust scenes: the built-in scenes and the sensor effects a scene can switch on."""

from __future__ import annotations

from evclust.scenes import builtin_scenes, load_scene
from evclust.simulator import EFFECTS


def add_parser(sub) -> None:
    p = sub.add_parser(
        "scenes",
        help="list the built-in scenes and the sensor effects",
        description="List the built-in scenes (usable as SCENE anywhere) and the effects a scene file can switch on, with their parameters.",
    )
    p.set_defaults(run=run)


def run(args) -> int:
    print("built-in scenes:")
    for name in builtin_scenes():
        spec = load_scene(name).spec
        print(f"  {name:<14} {spec.width}x{spec.height} {spec.fps:g} fps {spec.frames} frames  {spec.description}")
    print("sensor effects ([effects.NAME] tables of a scene file):")
    for name, cls in EFFECTS.items():
        fields = ", ".join(f"{k}={v.default!r}" for k, v in cls.Params.model_fields.items())
        doc = (cls.__doc__ or "").strip().splitlines()[0] if cls.__doc__ else ""
        print(f"  {name:<23} {fields}  {doc}")
    return 0
