"""evclust tune SCENE --trials N -o best.toml, or evclust tune --suite SPLIT (the suite's defaults)"""

from __future__ import annotations

from evclust.errors import EvclustError, atomic_output


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
    p.add_argument("scene", metavar="SCENE", nargs="?", help="built-in scene name or synthetic scene .toml")
    p.add_argument(
        "--suite", metavar="SPLIT", help="tune one configuration over a split of the generalization suite instead (docs/TUNING.md)"
    )
    p.add_argument(
        "--storage",
        default="sqlite:///build/tune_suite.db",
        metavar="URL",
        help="--suite: optuna RDB storage; a PostgreSQL URL lets workers on many machines share the study (default: sqlite:///build/tune_suite.db)",
    )
    p.add_argument("--study", default="suite", metavar="NAME", help="--suite: study name; an existing study resumes (default: suite)")
    p.add_argument("--suite-dir", default="build/suite", metavar="DIR", help="--suite: where scenes and events are kept")
    p.add_argument("--scheduler", metavar="ADDR", help="--suite: Dask scheduler address (default: a local cluster)")
    p.add_argument("--workers", type=int, metavar="N", help="--suite: local Dask workers (default: one per core)")
    p.add_argument("-o", "--output", required=True, metavar="BEST.toml", help="parameter file to write")
    p.add_argument("--trials", type=int, default=100, metavar="N", help="parameter sets to try (default 100)")
    p.add_argument("--seed", type=int, default=0, metavar="S", help="sampler seed (default 0)")
    p.add_argument("--segment", type=float, default=0.5, metavar="F", help="fraction of the scene to tune on (default 0.5)")
    p.add_argument("--params", metavar="P", help="starting parameters (.toml or preset; default: the scene's preset)")
    p.add_argument(
        "--only",
        metavar="PREFIX",
        help="--suite: search only the parameters whose names start with PREFIX (object_: "
        "the object layer alone, each scene's clusters run once per worker)",
    )
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    p.set_defaults(run=run)


def run(args) -> int:
    if args.trials < 1:
        raise EvclustError(f"--trials {args.trials}: at least one trial is needed")
    if args.suite:
        if args.scene:
            raise EvclustError(f"give a SCENE or --suite {args.suite}, not both")
        return _run_suite(args)
    if not args.scene:
        raise EvclustError("give a SCENE to tune on, or --suite SPLIT")
    if args.only:
        raise EvclustError("--only works with --suite")
    if not 0.0 < args.segment <= 1.0:
        raise EvclustError(f"--segment {args.segment}: must be in (0, 1]")
    from evclust.clusterer import load_params
    from evclust.scenes import load_scene
    from evclust.scenes.truth import truth_array
    from evclust.simulator import simulate_scene
    from evclust.tune import params_to_toml, segment, tune

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


def _run_suite(args) -> int:
    from pathlib import Path

    from evclust.clusterer import load_params
    from evclust.suite import dask_client, prepare_split, split_seeds
    from evclust.tune import params_to_toml
    from evclust.tune.suite import tune_suite

    seeds = split_seeds(args.suite)
    if args.suite != "tuning":
        print(f"evclust: warning: tuning on the '{args.suite}' split: its figures are no longer a held-out measure", flush=True)
    base, origin = load_params(args.params)
    with dask_client(args.scheduler, args.workers) as client:
        prepare_split(client, args.suite, args.suite_dir, progress=not args.quiet)
        result = tune_suite(client, Path(args.suite_dir), seeds, base, args.trials, args.storage, args.study, seed=args.seed,
                            progress=not args.quiet, only=args.only)  # fmt: skip
    only = f" --only {args.only}" if args.only else ""
    header = (
        f"# Tuned by: evclust tune --suite {args.suite} --trials {args.trials} --seed {args.seed} --study {args.study}{only}\n"
        f"# from {origin}; suite objective {result.value:.4f} (docs/TUNING.md) after {result.trials} trials in {args.storage}"
    )
    with atomic_output(args.output) as tmp:
        tmp.write_text(params_to_toml(result.params, header))
    print(f"{args.output}: best suite objective {result.value:.4f}, study '{args.study}' has {result.trials} trials (from {origin})")
    return 0
