"""Where the Verilog is: the repository that holds this package (an editable install)."""

from __future__ import annotations

from pathlib import Path

from evclust.errors import EvclustError

REPO = Path(__file__).resolve().parents[3]
RTL_DIR = REPO / "rtl"
TB_DIR = REPO / "tb" / "evclust_core"
RTL_SOURCES = ("evclust_core.v", "evclust_decay.v", "evclust_palette.v")
RTL_INCLUDES = ("evclust_arith.vh",)
BUILD = REPO / "build"


def require_repository() -> None:
    """A clear error when the package runs outside its repository (a plain wheel install)."""
    missing = [p for p in (RTL_DIR / RTL_SOURCES[0], TB_DIR / "evclust_tb.v") if not p.exists()]
    if missing:
        raise EvclustError(f"{missing[0]}: the RTL is not here; run from a clone of the evclust repository (pip install -e .)")
