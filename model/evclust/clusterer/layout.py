"""The cluster-state layout shared by the float and fixed models (and the RTL's table).

One row per slot, one column per field; the float model stores float64, the fixed model integers
in their formats. The palette histogram H[K] is a separate (N, K) array. Globals (counters, the
background colour, the filter-step clock) are one small vector.
"""

from __future__ import annotations

# Slot columns.
(
    VALID, ID, PX, PY, RX, RY, ACT, T_LAST, VMX, VMY, VIX, VIY, PPX, PPY, CY, CCB, CCR, REPORTED,
    EVER_REPORTED, GAMMA, VI_COUNT, MCM_NORM, EV_COUNT, DECAY_RESIDUAL,
) = range(24)  # fmt: skip
SLOT_COLUMNS = (
    "valid", "id", "px", "py", "rx", "ry", "activity", "t_last", "vmx", "vmy", "vix", "viy",
    "p_prev_x", "p_prev_y", "Y", "Cb", "Cr", "reported", "ever_reported", "gamma",
    "interval_updates", "mcm_norm", "events_in_interval",
    "decay_residual",  # fixed model: Δt/T_half not yet applied, below the decay table's step
)  # fmt: skip

# Global columns.
(
    NEXT_ID, BG_Y, BG_CB, BG_CR, SINCE_FILTER, STEP, T_FILTER, EVENTS, CREATED, EVICTED, DROPPED, EXPIRED,
    EXITED, NOISE, T_FIRST, BG_ACT, BG_T, BG_RESIDUAL, MERGED, UNSUPPORTED,
) = range(20)  # fmt: skip
GLOBAL_COLUMNS = (
    "next_id", "bg_Y", "bg_Cb", "bg_Cr", "since_filter", "step", "t_filter", "events",
    "created", "evicted", "dropped", "expired", "exited", "noise", "t_first",  # τ boundaries count from t_first
    "bg_activity", "bg_t_last", "bg_decay_residual",  # the activity of the events no reported cluster takes
    "merged", "unsupported",  # clusters merged into another; events that found no cluster and no support
)  # fmt: skip

# Track-record columns as the models write them (the order of evclust.tracks.TRACK_DTYPE).
RECORD_COLUMNS = 18

# Flags of a record (evclust.tracks.TrackFlags).
FLAG_NEW, FLAG_BORDER, FLAG_MOVING_MCM, FLAG_MOVING_INT = 1, 2, 4, 8


def run_stats(g) -> dict:
    """The counters of a run, from the globals (float or fixed)."""
    return {
        "events": int(g[EVENTS]), "steps": int(g[STEP]), "created": int(g[CREATED]), "evicted": int(g[EVICTED]),
        "dropped": int(g[DROPPED]), "expired": int(g[EXPIRED]), "exited": int(g[EXITED]), "noise_decisions": int(g[NOISE]),
        "merged": int(g[MERGED]), "unsupported": int(g[UNSUPPORTED]),
    }  # fmt: skip


def support_shape(width: int, height: int, cell_bits: int) -> tuple[int, int]:
    """The creation-support map: one cell per 2^cell_bits px square, with a border of one cell
    all round so that every 3x3 neighbourhood lies inside."""
    return ((height - 1) >> cell_bits) + 3, ((width - 1) >> cell_bits) + 3
