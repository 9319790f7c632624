"""evclust generalize [--split test] [-o docs/GENERALIZATION.md]: the suite's test split through
the default and the paper's configurations, float and fixed."""

from __future__ import annotations

import platform
import shlex
from pathlib import Path

from evclust.errors import EvclustError


def add_parser(sub) -> None:
    p = sub.add_parser(
        "generalize",
        help="run a split of the generalization suite and write GENERALIZATION.md",
        description=(
            "Generate and simulate the scenes of a split of the generalization suite (kept in --suite-dir for the next "
            "run), track them with the default configuration (float and fixed models) and the paper's (float), score "
            "them (recall, precision, tracks per object, HOTA/MOTA/IDF1 from TrackEval, the paper's accuracy figures), "
            "and write a Markdown page with overall, per-category and per-scene tables and a picture of typical "
            "failures. Runs on a local Dask cluster (one worker per core) or on --scheduler."
        ),
    )
    p.add_argument("--split", default="test", help="suite split (default: test)")
    p.add_argument("--seeds", type=int, nargs="+", metavar="SEED", help="only these seeds of the split (a quick run)")
    p.add_argument("--suite-dir", default="build/suite", metavar="DIR", help="where scenes and events are kept (default: build/suite)")
    p.add_argument("--models", default="float,fixed", help="models of the default configuration (default: float,fixed)")
    p.add_argument(
        "-o", "--output", metavar="MD", help="page to write (default: docs/GENERALIZATION.md; with --pipeline, docs/PIPELINE.md)"
    )
    p.add_argument("--scheduler", metavar="ADDR", help="Dask scheduler address (default: a local cluster)")
    p.add_argument("--workers", type=int, metavar="N", help="local Dask workers (default: one per core)")
    p.add_argument(
        "--ablation",
        action="store_true",
        help="instead: the defaults with each addition beyond the paper off in turn, and the paper's (float model)",
    )
    p.add_argument(
        "--pipeline",
        action="store_true",
        help="instead: what the pipeline semantics (update_delay) cost, paired over small perturbations of the defaults, "
        "on the test and the tuning split (float model; writes docs/PIPELINE.md by default)",
    )
    p.add_argument(
        "--json", metavar="PATH", help="also write every configuration's pooled figures (what it reports, and its clusters') as JSON"
    )
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bars")
    p.set_defaults(run=run)


def run(args) -> int:
    from evclust.run import MODELS
    from evclust.suite import dask_client, split_seeds
    from evclust.suite.report import ablation_configurations, default_configurations, run_configurations, write_figures, write_report

    if args.pipeline:
        return run_pipeline(args)
    seeds = split_seeds(args.split)
    if args.seeds:
        outside = sorted(set(args.seeds) - set(seeds))
        if outside:
            raise EvclustError(f"--seeds {outside[0]}: not in the {args.split} split (seeds {min(seeds)}-{max(seeds)})")
        seeds = tuple(args.seeds)
    models = tuple(m.strip() for m in args.models.split(",") if m.strip())
    unknown = [m for m in models if m not in MODELS]
    if unknown or not models:
        raise EvclustError(f"--models {args.models}: expected some of {', '.join(MODELS)}")
    out = Path(args.output or "docs/GENERALIZATION.md")
    picture = out.parent / "img" / f"{out.stem.lower()}_failures.png"
    command = " ".join(["evclust generalize", f"--split {args.split}", *([f"--seeds {' '.join(map(str, args.seeds))}"] if args.seeds else []),
                        "--ablation" if args.ablation else f"--models {','.join(models)}", f"-o {shlex.quote(str(out))}"])  # fmt: skip
    machine = f"{platform.machine()}, {platform.python_implementation()} {platform.python_version()}"
    configurations = ablation_configurations() if args.ablation else default_configurations(models)
    with dask_client(args.scheduler, args.workers) as client:
        runs = run_configurations(client, Path(args.suite_dir), seeds, configurations, progress=not args.quiet)
    write_report(runs, Path(args.suite_dir), out, args.split, seeds, command, machine, picture,
                 categories_of=("default",) if args.ablation else None,
                 title="Ablation: what each addition beyond the paper buys" if args.ablation else "Generalization",
                 document="ABLATION" if args.ablation else "GENERALIZATION")  # fmt: skip
    if args.json:
        write_figures(runs, Path(args.json))
    print(f"{out}: {len(seeds)} scenes of the {args.split} split, {len(runs)} configurations")
    return 0


def run_pipeline(args) -> int:
    from evclust.suite import dask_client, split_seeds
    from evclust.suite.pipeline import configurations, paired_changes, reference_changes, sweep_changes, write_page
    from evclust.suite.report import run_configurations

    if args.ablation or args.seeds or args.json:
        raise EvclustError("--pipeline runs whole splits on its own: leave out --ablation, --seeds and --json")
    out = Path(args.output or "docs/PIPELINE.md")
    command = f"evclust generalize --pipeline -o {shlex.quote(str(out))}"
    machine = f"{platform.machine()}, {platform.python_implementation()} {platform.python_version()}"
    by_split, reference_by_split, sweep_by_split, scenes = {}, {}, {}, {}
    with dask_client(args.scheduler, args.workers) as client:
        for split in ("test", "tuning"):
            seeds = split_seeds(split)
            runs = run_configurations(client, Path(args.suite_dir), seeds, configurations(), progress=not args.quiet)
            by_split[split], scenes[split] = paired_changes(runs), len(seeds)
            reference_by_split[split] = reference_changes(runs)
            sweep_by_split[split] = sweep_changes(runs)
    write_page(by_split, out, command, machine, scenes, reference_by_split, sweep_by_split)
    print(f"{out}: pipeline semantics on the test and tuning splits")
    return 0
