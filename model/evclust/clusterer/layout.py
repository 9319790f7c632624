"""The cluster-state layout shared by the float and fixed models (and the RTL's table).

One row per slot, one column per field; the float model stores float64, the fixed model integers
in their formats. The palette histogram H[K] is a separate (N, K) array. Globals (counters, the
background colour, the filter-step clock) are one small vector.
"""

from __future__ import annotations

from evclust.tracks.record import ObjectFlags, TrackFlags

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
    SWEEP_LEFT, SWEEP_T, SWEEP_PER_FRAME, SWEEP_DECAY, SWEEP_RECORDS, SWEEP_FORCED,
) = range(26)  # fmt: skip
GLOBAL_COLUMNS = (
    "next_id", "bg_Y", "bg_Cb", "bg_Cr", "since_filter", "step", "t_filter", "events",
    "created", "evicted", "dropped", "expired", "exited", "noise", "t_first",  # τ boundaries count from t_first
    "bg_activity", "bg_t_last", "bg_decay_residual",  # the activity of the events no reported cluster takes
    "merged", "unsupported",  # clusters merged into another; events that found no cluster and no support
    # The filter step's sweep (beside the events: ClustererParams.sweep_slots_per_event): slots
    # left to sweep, the step's time, T_frame over the τ boundaries' time (-1: no boundary since
    # the last step), its decay of Ã (activity_reference), the records it holds so far, and the
    # events at which a sweep had to finish at once.
    "sweep_left", "sweep_t", "sweep_per_frame", "sweep_decay", "sweep_records", "sweep_forced",
)  # fmt: skip

# The update delay line (beyond the paper; ClustererParams.update_delay = D): a pipelined core
# reads a slot when an event enters and writes it back D events later, so each event's update is
# kept as increments computed from the state it read, and committed, in event order, with
# additions. One row per event in flight; a row may hold a slot update, a background-colour
# update, or both.
(
    PD_LIVE, PD_SLOT, PD_T, PD_PX, PD_PY, PD_RX, PD_RY, PD_VMX, PD_VMY, PD_NORM, PD_CY, PD_CCB, PD_CCR, PD_CLASS, PD_VOTE,
    PD_BG, PD_BG_Y, PD_BG_CB, PD_BG_CR,
) = range(19)  # fmt: skip
PENDING_COLUMNS = (
    "live", "slot", "t", "d_px", "d_py", "d_rx", "d_ry", "d_vmx", "d_vmy", "d_mcm_norm", "d_Y", "d_Cb", "d_Cr", "class", "vote",
    "bg_live", "d_bg_Y", "d_bg_Cb", "d_bg_Cr",
)  # fmt: skip


# Track-record columns as the models write them (the order of evclust.tracks.TRACK_DTYPE).
RECORD_COLUMNS = 18

# Flags of a record, as ints for the compiled loops.
FLAG_NEW, FLAG_BORDER, FLAG_MOVING_MCM, FLAG_MOVING_INT = (
    int(f) for f in (TrackFlags.NEW, TrackFlags.BORDER, TrackFlags.MOVING_MCM, TrackFlags.MOVING_INT)
)


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


# Track-record columns by name, as the float and fixed models write them.
(
    R_T, R_STEP, R_SLOT, R_ID, R_X, R_Y, R_RX, R_RY, R_ACT, R_VMX, R_VMY, R_VIX, R_VIY, R_LUM, R_CB, R_CR, R_CLASS, R_FLAGS,
) = range(RECORD_COLUMNS)  # fmt: skip

# The object layer (beyond the paper): one row per object slot. The first block is the object's
# state; the second what the current filter step's member clusters add up to.
(
    O_VALID, O_ID, O_X, O_Y, O_RX, O_RY, O_VX, O_VY, O_LUM, O_CB, O_CR, O_CLASS, O_T_BORN, O_T_SEEN,
    O_CONFIRMED, O_EVER_REPORTED, O_TOL,
    O_MEMBERS, O_CLAIMED, O_OWNER_W, O_LO_X, O_HI_X, O_LO_Y, O_HI_Y, O_V_WEIGHT, O_MEMBER_VX, O_MEMBER_VY,
    O_COLOUR_WEIGHT, O_MEMBER_CLASS, O_MEMBER_LUM, O_MEMBER_CB, O_MEMBER_CR,
) = range(32)  # fmt: skip
OBJECT_COLUMNS = (
    "valid", "id", "x", "y", "rx", "ry", "vx", "vy", "Y", "Cb", "Cr", "class", "t_born", "t_seen",
    "confirmed", "ever_reported", "tolerance",
    "members", "claimed", "owner_weight", "lo_x", "hi_x", "lo_y", "hi_y", "velocity_weight", "member_vx", "member_vy",
    "colour_weight", "member_class", "member_Y", "member_Cb", "member_Cr",
)  # fmt: skip
# Per cluster of a filter step: its velocity as the object layer takes it, whether it is measured,
# its velocity tolerance, its link reaches along x and y, and its group.
CL_VX, CL_VY, CL_MEASURED, CL_TOL, CL_REACH_X, CL_REACH_Y, CL_GROUP = range(7)
CLUSTER_SCRATCH_COLUMNS = 7
# Per group of linked clusters (indexed by its lowest member): its box, activity, the velocity of
# its most active member (with that member's activity, whether it is measured and its tolerance),
# the object its most active member with one joined last step (and that member's activity), and
# the object it joins now.
(
    GR_LO_X, GR_HI_X, GR_LO_Y, GR_HI_Y, GR_WEIGHT, GR_VX, GR_VY, GR_V_WEIGHT, GR_MEASURED, GR_TOL, GR_PREFERRED,
    GR_PREFERRED_WEIGHT, GR_OBJECT,
) = range(13)  # fmt: skip
GROUP_SCRATCH_COLUMNS = 13
# Object-layer globals.
OG_NEXT_ID, OG_T_PREV, OG_STARTED, OG_STEPS, OG_CREATED, OG_CONFIRMED, OG_FREED, OG_UNASSIGNED, OG_MERGED = range(9)
OBJECT_GLOBAL_COLUMNS = ("next_id", "t_prev", "started", "steps", "created", "confirmed", "freed", "unassigned", "merged")
# Object-record columns (the order of evclust.tracks.OBJECT_DTYPE).
(
    OR_T, OR_STEP, OR_SLOT, OR_ID, OR_X, OR_Y, OR_RX, OR_RY, OR_VX, OR_VY, OR_LUM, OR_CB, OR_CR, OR_CLASS, OR_MEMBERS, OR_FLAGS,
) = range(16)  # fmt: skip
OBJECT_RECORD_COLUMNS = 16
# Flags of an object record, as ints for the compiled loops.
OFLAG_NEW, OFLAG_COASTING = int(ObjectFlags.NEW), int(ObjectFlags.COASTING)
