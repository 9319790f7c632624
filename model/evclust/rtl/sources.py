"""Where the Verilog is, and where its builds go.

Two places hold the RTL, looked for in this order:
- the copy a wheel carries, evclust/rtl/hdl/ beside this module (setup.py copies the repository's
  rtl/ and tb/evclust_core/evclust_tb.v there, keeping their layout);
- the repository that holds this package (an editable install, `pip install -e .`), whose rtl/ is
  read directly, so an edit there is seen without reinstalling.
The builds (co-simulation, streams, synthesis) go to evclust.paths.BUILD: $EVCLUST_BUILD_DIR,
the checkout's build/, or the user's cache folder.
"""

from __future__ import annotations

from pathlib import Path

from evclust.errors import EvclustError
from evclust.paths import IN_CHECKOUT, REPO

PACKAGED = Path(__file__).resolve().parent / "hdl"  # a wheel's copy (setup.py)
# The wheel's copy first, else the checkout's; neither: require_rtl says so.
HDL_ROOT = PACKAGED if (PACKAGED / "rtl").is_dir() or not IN_CHECKOUT else REPO
RTL_DIR = HDL_ROOT / "rtl"
TB_DIR = HDL_ROOT / "tb" / "evclust_core"
RTL_SOURCES = (
    "evclust_axis.v",
    "evclust_core.v",
    "evclust_objects.v",
    "evclust_regs.v",
    "evclust_decay.v",
    "evclust_decay_apply.v",
    "evclust_reference.v",
    "evclust_palette.v",
    "evclust_udiv.v",
    "evclust_top2.v",
    "evclust_pipediv.v",
    "evclust_slot_ram.v",
    "evclust_seek_window.v",
    "evclust_seek_key.v",
    "evclust_seek.v",
    "evclust_merge_search.v",
    "evclust_update.v",
    "evclust_commit.v",
    "evclust_stage_reg.v",
)
RTL_INCLUDES = ("evclust_arith.vh", "evclust_increments.vh", "evclust_require.vh", "evclust_core_enums.vh", "evclust_objects_enums.vh")


def require_rtl() -> None:
    """A one-line error when neither the wheel's copy nor a checkout's rtl/ holds the Verilog."""
    missing = [p for p in (RTL_DIR / RTL_SOURCES[0], TB_DIR / "evclust_tb.v") if not p.exists()]
    if missing:
        raise EvclustError(f"{missing[0]}: the RTL is not here, nor in a repository checkout; install evclust from its "
                           f"repository (pip install . packages rtl/; pip install -e . reads it)")  # fmt: skip


def require_repository() -> None:
    """A clear error when a step needs the repository itself (synthesis and timing: its git history
    and folders), not only the RTL a wheel carries."""
    if not IN_CHECKOUT:
        raise EvclustError(f"{REPO}: not a clone of the evclust repository; synthesis and timing run from one (pip install -e .)")
    require_rtl()


RTL_UPDATE_DELAYS = (0, 1, 2)  # the pipeline semantics evclust_core implements (its UPDATE_DELAY)


def require_rtl_semantics(params) -> None:
    """Refuse a parameter set whose pipeline semantics the RTL does not implement."""
    if params.sweep_slots_per_event != 0:
        raise EvclustError(f"clusterer: sweep_slots_per_event = {params.sweep_slots_per_event}, but the RTL sweeps a filter step "
                           f"between two events (0); the float and fixed models run the sweep beside the events")  # fmt: skip
    if params.update_delay not in RTL_UPDATE_DELAYS:
        raise EvclustError(f"clusterer: update_delay = {params.update_delay}, but the RTL implements update_delay "
                           f"{' or '.join(map(str, RTL_UPDATE_DELAYS))}; the float and fixed models run any delay")  # fmt: skip


def params_header(params, width: int, height: int, t_frame_us: float, **formats) -> str:
    """evclust_params.vh for a parameter set on a sensor (`formats`: build_formats's options)."""
    from evclust.fixed.formats import build_formats
    from evclust.fixed.header import verilog_header

    require_rtl_semantics(params)
    return verilog_header(build_formats(params, width, height, t_frame_us, **formats))
