"""evclust scenes [--generate SEED ... | --split NAME] [-o DIR]: the built-in scenes and the
sensor effects, or scenes of the generalization suite."""

from __future__ import annotations

from pathlib import Path

from evclust.choices import SPLITS
from evclust.errors import EvclustError


def add_parser(sub) -> None:
    p = sub.add_parser(
        "scenes",
        help="list the built-in scenes and the sensor effects, or generate suite scenes",
        description=(
            "Without options: list the built-in scenes (usable as SCENE anywhere) and the effects a scene file can "
            "switch on. --generate SEED writes the generalization suite's scene of that seed (a scene TOML, its exact "
            "ground truth, and for even seeds the MPEG-4 video the codec made of it); --split writes a whole split "
            f"({', '.join(f'{k}: seeds {min(v)}-{max(v)}' for k, v in SPLITS.items())}). docs/GENERALIZATION.md."
        ),
    )
    what = p.add_mutually_exclusive_group()
    what.add_argument("--generate", type=int, nargs="+", metavar="SEED", help="seeds of the scenes to write")
    what.add_argument("--split", choices=sorted(SPLITS), help="write every scene of a split")
    p.add_argument("-o", "--output", metavar="DIR", help="folder to write the scenes into (with --generate or --split)")
    p.set_defaults(run=run)


def run(args) -> int:
    seeds = args.generate if args.generate is not None else (SPLITS[args.split] if args.split else None)
    if seeds is None:
        if args.output:
            raise EvclustError("-o DIR goes with --generate SEED or --split NAME")
        return _list()
    if not args.output:
        raise EvclustError("--generate and --split need -o DIR, the folder to write the scenes into")
    from evclust.scenes.generate import generate_scene, write_scene

    for seed in seeds:
        scene = generate_scene(seed)
        path = write_scene(scene, Path(args.output))
        print(f"{path}: {scene.spec.description}")
    return 0


def _list() -> int:
    from evclust.scenes import builtin_scenes, load_scene
    from evclust.simulator import EFFECTS

    print("built-in scenes:")
    for name in builtin_scenes():
        spec = load_scene(name).spec
        print(f"  {name:<14} {spec.width}x{spec.height} {spec.fps:g} fps {spec.frames} frames  {spec.description}")
    print("sensor effects ([effects.NAME] tables of a scene file):")
    for name, cls in EFFECTS.items():
        fields = ", ".join(f"{k}={v.default!r}" for k, v in cls.Params.model_fields.items())
        doc = (cls.__doc__ or "").strip().splitlines()[0] if cls.__doc__ else ""
        print(f"  {name:<23} {fields}  {doc}")
    print(
        f"generated suite: evclust scenes --generate SEED -o DIR; splits {', '.join(f'{k} (seeds {min(v)}-{max(v)})' for k, v in SPLITS.items())}"
    )
    return 0
