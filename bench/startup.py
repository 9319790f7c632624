#!/usr/bin/env python
"""Start-up time of the command line: `evclust --help` and `evclust track --help`, against a bare
`python -c pass` in the same run (the interpreter's own start-up, the floor).

    make bench        # ... .venv/bin/python bench/startup.py --write docs/BENCHMARKS.md
"""

from __future__ import annotations

import argparse
import datetime
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
EVCLUST = ROOT / ".venv" / "bin" / "evclust"
START, END = "<!-- bench:startup:start -->", "<!-- bench:startup:end -->"
TARGET_S = 0.5


def timed(cmd: list[str], repeat: int) -> list[float]:
    walls = []
    for _ in range(repeat):
        start = time.perf_counter()
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
        walls.append(time.perf_counter() - start)
    return walls


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=9)
    parser.add_argument("--write", metavar="MD")
    args = parser.parse_args()
    cases = {
        "python -c pass (the floor)": [sys.executable, "-c", "pass"],
        "evclust --help": [str(EVCLUST), "--help"],
        "evclust track --help": [str(EVCLUST), "track", "--help"],
    }
    rows = ["| command | median | best |", "|---|---:|---:|"]
    for name, cmd in cases.items():
        walls = timed(cmd, args.repeat)
        rows.append(f"| `{name}` | {statistics.median(walls):.3f} s | {min(walls):.3f} s |")
    section = "\n".join([
        START, "## Command-line start-up", "",
        f"Measured {datetime.date.today()} by `.venv/bin/python bench/startup.py --write docs/BENCHMARKS.md` "
        f"(part of `make bench`), {args.repeat} runs each (target: `evclust --help` ≤ {TARGET_S:g} s; 3.2 to 3.5 s "
        "before the verbs imported the library lazily):", "", *rows, "", END,
    ])  # fmt: skip
    print(section)
    if args.write:
        from evclust.documents import write_section

        write_section(Path(args.write), section, START, END)
    return 0


if __name__ == "__main__":
    sys.exit(main())
