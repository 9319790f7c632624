"""Ground-truth CSV: one row per visible object per frame."""

from __future__ import annotations

import csv
from pathlib import Path

from evclust.errors import atomic_output
from evclust.scenes.synthetic import TRUTH_COLUMNS


def write_truth(path: str | Path, rows: list[dict]) -> None:
    with atomic_output(path) as tmp:
        with open(tmp, "w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=TRUTH_COLUMNS)
            writer.writeheader()
            writer.writerows(rows)
