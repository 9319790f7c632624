"""Where the Verilog is: the repository that holds this package (an editable install)."""

from __future__ import annotations

from pathlib import Path

from evclust.errors import EvclustError

REPO = Path(__file__).resolve().parents[3]
RTL_DIR = REPO / "rtl"
TB_DIR = REPO / "tb" / "evclust_core"
RTL_SOURCES = (
    "evclust_axis.v",
    "evclust_core.v",
    "evclust_objects.v",
    "evclust_regs.v",
    "evclust_decay.v",
    "evclust_palette.v",
    "evclust_udiv.v",
    "evclust_top2.v",
    "evclust_pipediv.v",
    "evclust_slot_ram.v",
    "evclust_seek_key.v",
    "evclust_seek.v",
    "evclust_merge_search.v",
    "evclust_update.v",
    "evclust_commit.v",
    "evclust_stage_reg.v",
)
RTL_INCLUDES = ("evclust_arith.vh", "evclust_increments.vh", "evclust_require.vh")
BUILD = REPO / "build"


def require_repository() -> None:
    """A clear error when the package runs outside its repository (a plain wheel install)."""
    missing = [p for p in (RTL_DIR / RTL_SOURCES[0], TB_DIR / "evclust_tb.v") if not p.exists()]
    if missing:
        raise EvclustError(f"{missing[0]}: the RTL is not here; run from a clone of the evclust repository (pip install -e .)")


RTL_UPDATE_DELAYS = (0, 1, 2)  # the pipeline semantics evclust_core implements (its UPDATE_DELAY)


def require_rtl_semantics(params) -> None:
    """Refuse a parameter set whose pipeline semantics the RTL does not implement."""
    if params.update_delay not in RTL_UPDATE_DELAYS:
        raise EvclustError(f"clusterer: update_delay = {params.update_delay}, but the RTL implements update_delay "
                           f"{' or '.join(map(str, RTL_UPDATE_DELAYS))}; the float and fixed models run any delay")  # fmt: skip


def params_header(params, width: int, height: int, t_frame_us: float, **formats) -> str:
    """evclust_params.vh for a parameter set on a sensor (`formats`: build_formats's options)."""
    from evclust.fixed.formats import build_formats
    from evclust.fixed.header import verilog_header

    require_rtl_semantics(params)
    return verilog_header(build_formats(params, width, height, t_frame_us, **formats))
