"""evclust tune SCENE --trials N -o best.toml"""

from __future__ import annotations

from evclust.clusterer import load_params
from evclust.errors import EvclustError, atomic_output
from evclust.scenes.truth import truth_array
from evclust.scenes import load_scene
from evclust.simulator import simulate_scene
from evclust.tune import params_to_toml, segment, tune


def add_parser(sub) -> None:
    p = sub.add_parser(
        "tune",
        help="search clusterer parameters on a scene with optuna's TPE sampler",
        description=(
            "Simulate a scene that has ground truth, keep the first --segment of it, and search the clusterer's "
            "parameters with optuna's TPE sampler (the paper used hyperopt's TPE with 100 sets). The objective is "
            "the sum of task errors described in docs/TUNING.md. The best parameters are written as a TOML "
            "[clusterer] table; the same seed gives the same result."
        ),
    )
    p.add_argument("scene", metavar="SCENE", help="built-in scene name or synthetic scene .toml")
    p.add_argument("-o", "--output", required=True, metavar="BEST.toml", help="parameter file to write")
    p.add_argument("--trials", type=int, default=100, metavar="N", help="parameter sets to try (default 100)")
    p.add_argument("--seed", type=int, default=0, metavar="S", help="sampler seed (default 0)")
    p.add_argument("--segment", type=float, default=0.5, metavar="F", help="fraction of the scene to tune on (default 0.5)")
    p.add_argument("--params", metavar="P", help="starting parameters (.toml or preset; default: the scene's preset)")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    p.set_defaults(run=run)


def run(args) -> int:
    if args.trials < 1:
        raise EvclustError(f"--trials {args.trials}: at least one trial is needed")
    if not 0.0 < args.segment <= 1.0:
        raise EvclustError(f"--segment {args.segment}: must be in (0, 1]")
    scene = load_scene(args.scene)
    if not scene.has_truth or scene.truth_path is not None:
        raise EvclustError(f"{args.scene}: tuning needs a synthetic scene, whose ground truth is exact")
    sim = simulate_scene(scene, progress=not args.quiet)
    truth = truth_array(scene.source.truth())
    base, origin = load_params(args.params, sim.meta.source)
    events, truth = segment(sim.events, truth, args.segment)
    result = tune(events, sim.meta, truth, base, trials=args.trials, seed=args.seed, progress=not args.quiet)
    header = (
        f"# Tuned by: evclust tune {args.scene} --trials {args.trials} --seed {args.seed} --segment {args.segment}\n"
        f"# from {origin}; objective {result.value:.4f} (docs/TUNING.md) on {events.size} events"
    )
    with atomic_output(args.output) as tmp:
        tmp.write_text(params_to_toml(result.params, header))
    print(f"{args.output}: best objective {result.value:.4f} after {args.trials} trials (from {origin})")
    return 0
