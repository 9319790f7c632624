"""The object layer, bit-accurate: clusterer/objects.py's six steps in integer arithmetic, one
operation per line, each in its format of the formats table (docs/OBJECTS.md is the datapath).

It runs over the fixed clusterer's record stream, as the RTL's object unit (rtl/evclust_objects.v)
runs behind the core's record port: the records' raw fields in, one step at a time, and the time
of each filter step. Raw int64 values throughout; floor rounding (an arithmetic right shift)
wherever bits are dropped; every store that can leave its format saturates and is counted. The
32-bit time wraps by design, as the core's; the time between steps saturates at 2^24 - 1 µs.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from evclust.clusterer.layout import (
    CL_GROUP, CL_MEASURED, CL_REACH_X, CL_REACH_Y, CL_TOL, CL_VX, CL_VY, CLUSTER_SCRATCH_COLUMNS, GR_HI_X, GR_HI_Y, GR_LO_X,
    GR_LO_Y, GR_MEASURED, GR_OBJECT, GR_PREFERRED, GR_PREFERRED_WEIGHT, GR_TOL, GR_V_WEIGHT, GR_VX, GR_VY, GR_WEIGHT,
    GROUP_SCRATCH_COLUMNS, O_CB, O_CLAIMED, O_CLASS, O_COLOUR_WEIGHT, O_CONFIRMED, O_CR, O_EVER_REPORTED, O_HI_X, O_HI_Y, O_ID,
    O_LO_X, O_LO_Y, O_LUM, O_MEMBER_CB, O_MEMBER_CLASS, O_MEMBER_CR, O_MEMBER_LUM, O_MEMBER_VX, O_MEMBER_VY, O_MEMBERS,
    O_OWNER_W, O_RX, O_RY, O_T_BORN, O_T_SEEN, O_TOL, O_V_WEIGHT, O_VALID, O_VX, O_VY, O_X, O_Y, OBJECT_COLUMNS,
    OBJECT_GLOBAL_COLUMNS, OBJECT_RECORD_COLUMNS, OFLAG_COASTING, OFLAG_NEW, OG_CONFIRMED, OG_CREATED, OG_FREED, OG_MERGED,
    OG_NEXT_ID, OG_STARTED, OG_STEPS, OG_T_PREV, OG_UNASSIGNED, R_ACT, R_CB, R_CLASS, R_CR, R_ID, R_LUM, R_RX, R_RY, R_SLOT,
    R_STEP, R_VIX, R_VIY, R_VMX, R_VMY, R_X, R_Y, RECORD_COLUMNS,
)  # fmt: skip
from evclust.fixed.formats import OBJECT_DT_FRAMES_FRAC, OBJECT_GAIN_FRAC, OBJECT_INV_T_FRAC, SCALE_FRAC_BITS, FormatTable
from evclust.jit import njit

TIME_MASK = (1 << 32) - 1
ID_MASK = (1 << 32) - 1
NONE = np.int64(-1)
FAR = np.int64(1) << 62  # larger than any distance

# Saturating signals of the object layer (their counts: FixedObjects.stats()["saturations"]).
OBJECT_SIGNALS = ("obj_centre", "obj_velocity")
S_OBJ_CENTRE, S_OBJ_VELOCITY = range(len(OBJECT_SIGNALS))

# The formats table as the compiled step reads it: fraction bits, raw constants, limits.
FixedObjectConstants = namedtuple(
    "FixedObjectConstants",
    (
        "fp",
        "fr",
        "fv",
        "fvi",
        "fvm",
        "fa",
        "fc",  # fraction bits: centre, half-size, object velocity, v_int, v_mcm, activity, colour
        "inv_t_frame",
        "inv_t_frame_frac",  # 1/T_frame per µs
        "gate",
        "link_along",
        "v_tol",
        "v_rel",  # centre's, SCALE_FRAC_BITS, obj_velocity's, SCALE_FRAC_BITS
        "inv_track",
        "inv_rate",
        "inv_velocity",
        "inv_size",
        "inv_colour",  # 1/T per frame, OBJECT_INV_T_FRAC
        "birth_us",
        "coast_us",
        "keep_us",
        "dt_max",
        "dt_frames_max",
        "last_x",
        "last_y",  # the last column and row, in the centre's format
        "centre_min",
        "centre_max",
        "velocity_min",
        "velocity_max",
    ),
)


def fixed_object_constants(table: FormatTable) -> FixedObjectConstants:
    f, c = table.formats, table.constants
    return FixedObjectConstants(
        f["obj_centre"].frac_bits, f["obj_half"].frac_bits, f["obj_velocity"].frac_bits, f["v_int"].frac_bits, f["v_mcm"].frac_bits,
        f["activity"].frac_bits, f["colour"].frac_bits,
        c["inv_t_frame"].raw, c["inv_t_frame"].fmt.frac_bits,
        c["object_gate"].raw, c["object_link_along"].raw, c["object_v_tol"].raw, c["object_v_rel"].raw,
        c["object_inv_track"].raw, c["object_inv_rate"].raw, c["object_inv_velocity"].raw, c["object_inv_size"].raw,
        c["object_inv_colour"].raw,
        c["object_birth_us"].raw, c["object_coast_us"].raw, c["object_keep_us"].raw, f["obj_dt"].raw_max, f["obj_dt_frames"].raw_max,
        (table.width - 1) << f["obj_centre"].frac_bits, (table.height - 1) << f["obj_centre"].frac_bits,
        f["obj_centre"].raw_min, f["obj_centre"].raw_max, f["obj_velocity"].raw_min, f["obj_velocity"].raw_max,
    )  # fmt: skip


@njit(cache=True, nogil=True, inline="always")
def _align(raw, from_frac, to_frac):
    """Change the fraction bits of a raw value (floor when dropping)."""
    if to_frac >= from_frac:
        return raw << (to_frac - from_frac)
    return raw >> (from_frac - to_frac)


@njit(cache=True, nogil=True, inline="always")
def _saturate(value, lo, hi, signal, log):
    if value < lo:
        log[signal] += 1
        return lo
    if value > hi:
        log[signal] += 1
        return hi
    return value


@njit(cache=True, nogil=True, inline="always")
def _gain(dt_frames, inv_t):
    """min(Δt·(1/T), 1) in obj_gain (UQ1.24)."""
    return min((dt_frames * inv_t) >> OBJECT_INV_T_FRAC, np.int64(1) << OBJECT_GAIN_FRAC)


@njit(cache=True, nogil=True, inline="always")
def _tolerance(vx, vy, k):
    """v_tol + floor(v_rel·|V|₁), obj_tolerance: the larger of two such is v_tol + floor(v_rel·(the faster speed))."""
    return k.v_tol + ((k.v_rel * (abs(vx) + abs(vy))) >> SCALE_FRAC_BITS)


@njit(cache=True, nogil=True, inline="always")
def _agree(ax, ay, a_tol, bx, by, b_tol):
    return abs(ax - bx) + abs(ay - by) <= max(a_tol, b_tol)


@njit(cache=True, nogil=True, inline="always")
def _box_meets(O, o, G, g, k):
    """The object's box grown by the gate meets the group's box (centre format)."""
    up = k.fp - k.fr
    rx, ry = O[o, O_RX] << up, O[o, O_RY] << up
    return (G[g, GR_LO_X] <= O[o, O_X] + rx + k.gate and G[g, GR_HI_X] >= O[o, O_X] - rx - k.gate
            and G[g, GR_LO_Y] <= O[o, O_Y] + ry + k.gate and G[g, GR_HI_Y] >= O[o, O_Y] - ry - k.gate)  # fmt: skip


@njit(cache=True, nogil=True)
def _linked(R, i, j, C, k):
    """clusterer/objects.py's link test on raw records (half-sizes in the centre's format): dx
    against rx_i + rx_j plus the gate, plus the larger precomputed reach along the pair's motion."""
    dx = abs(R[i, R_X] - R[j, R_X])
    dy = abs(R[i, R_Y] - R[j, R_Y])
    sx = R[i, R_RX] + R[j, R_RX] + k.gate
    sy = R[i, R_RY] + R[j, R_RY] + k.gate
    if C[i, CL_MEASURED] != 0 and C[j, CL_MEASURED] != 0:
        if not _agree(C[i, CL_VX], C[i, CL_VY], C[i, CL_TOL], C[j, CL_VX], C[j, CL_VY], C[j, CL_TOL]):
            return False
        along_x, along_y = abs(C[i, CL_VX] + C[j, CL_VX]), abs(C[i, CL_VY] + C[j, CL_VY])
        if along_x + along_y > 2 * max(C[i, CL_TOL], C[j, CL_TOL]):
            if along_x >= along_y:
                sx += max(C[i, CL_REACH_Y], C[j, CL_REACH_Y])
            else:
                sy += max(C[i, CL_REACH_X], C[j, CL_REACH_X])
    return dx <= sx and dy <= sy


@njit(cache=True, nogil=True)
def _clear_members(O, o):
    O[o, O_MEMBERS] = O[o, O_CLAIMED] = O[o, O_OWNER_W] = 0
    O[o, O_LO_X] = O[o, O_LO_Y] = FAR
    O[o, O_HI_X] = O[o, O_HI_Y] = -FAR
    O[o, O_V_WEIGHT] = NONE  # any member's activity beats it: the first member's velocity is taken
    O[o, O_COLOUR_WEIGHT] = 0  # a member with a class and an activity of 0 gives no colour


@njit(cache=True, nogil=True)
def _create(O, OG, G, g, t, k):
    """A tentative object for group g: the first free slot, else the lost object unseen the
    longest (ties: the lower slot); -1 when there is neither."""
    free, lost, lost_for = NONE, NONE, NONE
    for o in range(O.shape[0]):
        if O[o, O_VALID] == 0:
            free = o
            break
        unseen = (t - O[o, O_T_SEEN]) & TIME_MASK
        if O[o, O_CONFIRMED] != 0 and unseen > k.coast_us and unseen > lost_for:
            lost, lost_for = o, unseen
    if free < 0:
        if lost < 0:
            return NONE
        free = lost
        OG[OG_FREED] += 1
    o = free
    O[o, :] = 0
    O[o, O_VALID] = 1
    O[o, O_ID] = OG[OG_NEXT_ID]
    OG[OG_NEXT_ID] = (OG[OG_NEXT_ID] + 1) & ID_MASK
    O[o, O_X] = (G[g, GR_LO_X] + G[g, GR_HI_X]) >> 1
    O[o, O_Y] = (G[g, GR_LO_Y] + G[g, GR_HI_Y]) >> 1
    O[o, O_RX] = (G[g, GR_HI_X] - G[g, GR_LO_X]) >> (1 + k.fp - k.fr)
    O[o, O_RY] = (G[g, GR_HI_Y] - G[g, GR_LO_Y]) >> (1 + k.fp - k.fr)
    O[o, O_VX], O[o, O_VY], O[o, O_TOL] = G[g, GR_VX], G[g, GR_VY], G[g, GR_TOL]
    O[o, O_CLASS] = NONE
    O[o, O_T_BORN] = O[o, O_T_SEEN] = t
    _clear_members(O, o)
    OG[OG_CREATED] += 1
    return o


@njit(cache=True, nogil=True)
def _join(O, o, R, i, C):
    """Add member cluster i (its half-sizes already in the centre's format) to the object's step sums."""
    a = R[i, R_ACT]
    O[o, O_MEMBERS] += 1
    O[o, O_LO_X] = min(O[o, O_LO_X], R[i, R_X] - R[i, R_RX])
    O[o, O_HI_X] = max(O[o, O_HI_X], R[i, R_X] + R[i, R_RX])
    O[o, O_LO_Y] = min(O[o, O_LO_Y], R[i, R_Y] - R[i, R_RY])
    O[o, O_HI_Y] = max(O[o, O_HI_Y], R[i, R_Y] + R[i, R_RY])
    if C[i, CL_MEASURED] != 0 and a > O[o, O_V_WEIGHT]:
        O[o, O_V_WEIGHT], O[o, O_MEMBER_VX], O[o, O_MEMBER_VY] = a, C[i, CL_VX], C[i, CL_VY]
    if R[i, R_CLASS] >= 0 and a > O[o, O_COLOUR_WEIGHT]:
        O[o, O_COLOUR_WEIGHT], O[o, O_MEMBER_CLASS] = a, R[i, R_CLASS]
        O[o, O_MEMBER_LUM], O[o, O_MEMBER_CB], O[o, O_MEMBER_CR] = R[i, R_LUM], R[i, R_CB], R[i, R_CR]


@njit(cache=True, nogil=True, inline="always")
def _dt_frames(dt, k):
    """Δt (µs, saturated) in frames, obj_dt_frames, saturated."""
    return min((dt * k.inv_t_frame) >> (k.inv_t_frame_frac - OBJECT_DT_FRAMES_FRAC), k.dt_frames_max)


@njit(cache=True, nogil=True, inline="always")
def _rate_gain(seen, k):
    """clusterer/objects.rate_gain: min(Δ/T_rate², 2^-ceil(log2 Δ)), per frame, in obj_gain's
    fraction bits; the power of two from the bit length of Δ's raw value."""
    if seen == 0:
        return np.int64(0)
    n, x = 0, seen - 1
    while x > 0:  # n = ceil(log2(seen)) for the raw value
        x >>= 1
        n += 1
    bound = np.int64(1) << (OBJECT_GAIN_FRAC + OBJECT_DT_FRAMES_FRAC - n)
    return min((_gain(seen, k.inv_rate) * k.inv_rate) >> OBJECT_INV_T_FRAC, bound)


@njit(cache=True, nogil=True)
def _update(O, o, t, k, log):
    """Step 4: the gains over Δ, the time since the object was last seen (obj_gain)."""
    down = 1 + k.fp - k.fr
    zx = (O[o, O_LO_X] + O[o, O_HI_X]) >> 1
    zy = (O[o, O_LO_Y] + O[o, O_HI_Y]) >> 1
    hx = (O[o, O_HI_X] - O[o, O_LO_X]) >> down
    hy = (O[o, O_HI_Y] - O[o, O_LO_Y]) >> down
    seen = _dt_frames(min((t - O[o, O_T_SEEN]) & TIME_MASK, k.dt_max), k)
    g_pos = _gain(seen, k.inv_track)
    g_rate = _rate_gain(seen, k)
    g_vel = _gain(seen, k.inv_velocity)
    g_size = _gain(seen, k.inv_size)
    g_col = _gain(seen, k.inv_colour)
    measured = O[o, O_V_WEIGHT] >= 0
    if O[o, O_T_BORN] == t:
        O[o, O_X], O[o, O_Y], O[o, O_RX], O[o, O_RY] = zx, zy, hx, hy
        if measured:
            O[o, O_VX], O[o, O_VY] = O[o, O_MEMBER_VX], O[o, O_MEMBER_VY]
    else:
        if not measured:
            g_vel = 0
        ex = zx - O[o, O_X]
        ey = zy - O[o, O_Y]
        O[o, O_X] += (g_pos * ex) >> OBJECT_GAIN_FRAC
        O[o, O_Y] += (g_pos * ey) >> OBJECT_GAIN_FRAC
        lim = O[o, O_TOL]  # obj_tolerance, the velocity's fraction
        rate_x = min(max(_align(g_rate * ex, OBJECT_GAIN_FRAC + k.fp, k.fv), -lim), lim)
        rate_y = min(max(_align(g_rate * ey, OBJECT_GAIN_FRAC + k.fp, k.fv), -lim), lim)
        vx = O[o, O_VX] + rate_x + ((g_vel * (O[o, O_MEMBER_VX] - O[o, O_VX])) >> OBJECT_GAIN_FRAC)
        vy = O[o, O_VY] + rate_y + ((g_vel * (O[o, O_MEMBER_VY] - O[o, O_VY])) >> OBJECT_GAIN_FRAC)
        O[o, O_VX] = _saturate(vx, k.velocity_min, k.velocity_max, S_OBJ_VELOCITY, log)
        O[o, O_VY] = _saturate(vy, k.velocity_min, k.velocity_max, S_OBJ_VELOCITY, log)
        O[o, O_RX] += (g_size * (hx - O[o, O_RX])) >> OBJECT_GAIN_FRAC
        O[o, O_RY] += (g_size * (hy - O[o, O_RY])) >> OBJECT_GAIN_FRAC
    if O[o, O_COLOUR_WEIGHT] > 0:
        g = (np.int64(1) << OBJECT_GAIN_FRAC) if O[o, O_CLASS] < 0 else g_col  # the first colour as it is
        O[o, O_LUM] += (g * (O[o, O_MEMBER_LUM] - O[o, O_LUM])) >> OBJECT_GAIN_FRAC
        O[o, O_CB] += (g * (O[o, O_MEMBER_CB] - O[o, O_CB])) >> OBJECT_GAIN_FRAC
        O[o, O_CR] += (g * (O[o, O_MEMBER_CR] - O[o, O_CR])) >> OBJECT_GAIN_FRAC
        O[o, O_CLASS] = O[o, O_MEMBER_CLASS]
    O[o, O_TOL] = _tolerance(O[o, O_VX], O[o, O_VY], k)
    O[o, O_T_SEEN] = t


@njit(cache=True, nogil=True)
def cluster_velocity(R, i, k, log):
    """A cluster's velocity in obj_velocity and whether it is measured: V_int (non-zero once
    measured), else V_MCM; each aligned to F_V (floor) and saturated."""
    if R[i, R_VIX] != 0 or R[i, R_VIY] != 0:
        vx, vy, measured = _align(R[i, R_VIX], k.fvi, k.fv), _align(R[i, R_VIY], k.fvi, k.fv), 1
    else:
        vx, vy, measured = _align(R[i, R_VMX], k.fvm, k.fv), _align(R[i, R_VMY], k.fvm, k.fv), 0
    vx = _saturate(vx, k.velocity_min, k.velocity_max, S_OBJ_VELOCITY, log)
    vy = _saturate(vy, k.velocity_min, k.velocity_max, S_OBJ_VELOCITY, log)
    return vx, vy, measured


@njit(cache=True, nogil=True)
def object_step(O, OG, slot_obj, slot_id, R, t_full, step, k, out, n_out, C, G, log):
    """One filter step: `R` its cluster records as raw integers (RECORD_COLUMNS, slot order),
    `t_full` its whole time (the datapath counts the low 32 bits). As clusterer/objects.py's
    object_step, in the same order; writes the reported objects' records (real units) from
    out[n_out] and returns the count."""
    t = t_full & TIME_MASK
    dt = 0 if OG[OG_STARTED] == 0 else min((t - OG[OG_T_PREV]) & TIME_MASK, k.dt_max)
    OG[OG_STARTED], OG[OG_T_PREV] = 1, t
    OG[OG_STEPS] += 1
    dt_frames = _dt_frames(dt, k)
    n_objects = O.shape[0]
    move = OBJECT_DT_FRAMES_FRAC + k.fv - k.fp  # V·Δt has F_V + F_DT fraction bits; the centre F_P
    for o in range(n_objects):  # 1. predict
        if O[o, O_VALID] != 0:
            O[o, O_X] = _saturate(O[o, O_X] + ((O[o, O_VX] * dt_frames) >> move), k.centre_min, k.centre_max, S_OBJ_CENTRE, log)
            O[o, O_Y] = _saturate(O[o, O_Y] + ((O[o, O_VY] * dt_frames) >> move), k.centre_min, k.centre_max, S_OBJ_CENTRE, log)
            _clear_members(O, o)
    m = R.shape[0]
    up = k.fp - k.fr
    for i in range(m):  # the half-sizes in the centre's format, as the box edges and the gate are
        R[i, R_RX] <<= up
        R[i, R_RY] <<= up
    for i in range(m):  # 2. group
        C[i, CL_VX], C[i, CL_VY], C[i, CL_MEASURED] = cluster_velocity(R, i, k, log)
        C[i, CL_TOL] = _tolerance(C[i, CL_VX], C[i, CL_VY], k)
        C[i, CL_REACH_X] = (k.link_along * R[i, R_RX]) >> SCALE_FRAC_BITS
        C[i, CL_REACH_Y] = (k.link_along * R[i, R_RY]) >> SCALE_FRAC_BITS
        C[i, CL_GROUP] = i
        for j in range(i):
            if C[j, CL_GROUP] != C[i, CL_GROUP] and _linked(R, i, j, C, k):
                keep, drop = min(C[i, CL_GROUP], C[j, CL_GROUP]), max(C[i, CL_GROUP], C[j, CL_GROUP])
                for q in range(i + 1):
                    if C[q, CL_GROUP] == drop:
                        C[q, CL_GROUP] = keep
    for g in range(m):
        G[g, GR_LO_X] = G[g, GR_LO_Y] = FAR
        G[g, GR_HI_X] = G[g, GR_HI_Y] = -FAR
        G[g, GR_WEIGHT] = G[g, GR_PREFERRED_WEIGHT] = 0
        G[g, GR_V_WEIGHT] = NONE
        G[g, GR_PREFERRED] = G[g, GR_OBJECT] = NONE
    for i in range(m):
        g = C[i, CL_GROUP]
        a = R[i, R_ACT]
        G[g, GR_LO_X] = min(G[g, GR_LO_X], R[i, R_X] - R[i, R_RX])
        G[g, GR_HI_X] = max(G[g, GR_HI_X], R[i, R_X] + R[i, R_RX])
        G[g, GR_LO_Y] = min(G[g, GR_LO_Y], R[i, R_Y] - R[i, R_RY])
        G[g, GR_HI_Y] = max(G[g, GR_HI_Y], R[i, R_Y] + R[i, R_RY])
        G[g, GR_WEIGHT] += a
        if a > G[g, GR_V_WEIGHT]:
            G[g, GR_V_WEIGHT], G[g, GR_VX], G[g, GR_VY] = a, C[i, CL_VX], C[i, CL_VY]
            G[g, GR_MEASURED], G[g, GR_TOL] = C[i, CL_MEASURED], C[i, CL_TOL]
        s = R[i, R_SLOT]
        prev = slot_obj[s] if slot_id[s] == R[i, R_ID] else NONE
        if prev >= 0 and O[prev, O_VALID] != 0 and a > G[g, GR_PREFERRED_WEIGHT]:
            G[g, GR_PREFERRED], G[g, GR_PREFERRED_WEIGHT] = prev, a
    for g in range(m):  # 3. associate
        o = G[g, GR_PREFERRED]
        if C[g, CL_GROUP] == g and o >= 0 and G[g, GR_WEIGHT] > O[o, O_OWNER_W] and _box_meets(O, o, G, g, k):
            O[o, O_OWNER_W] = G[g, GR_WEIGHT]
    for g in range(m):
        o = G[g, GR_PREFERRED]
        if C[g, CL_GROUP] == g and o >= 0 and O[o, O_CLAIMED] == 0 and O[o, O_OWNER_W] == G[g, GR_WEIGHT]:
            G[g, GR_OBJECT], O[o, O_CLAIMED] = o, 1
    for g in range(m):
        if C[g, CL_GROUP] != g or G[g, GR_OBJECT] >= 0:
            continue
        cx = (G[g, GR_LO_X] + G[g, GR_HI_X]) >> 1
        cy = (G[g, GR_LO_Y] + G[g, GR_HI_Y]) >> 1
        measured = G[g, GR_MEASURED] != 0
        best, best_d = NONE, FAR
        for o in range(n_objects):
            if O[o, O_VALID] != 0 and abs(cx - O[o, O_X]) <= O[o, O_RX] << up and abs(cy - O[o, O_Y]) <= O[o, O_RY] << up \
                    and (not measured or _agree(G[g, GR_VX], G[g, GR_VY], G[g, GR_TOL], O[o, O_VX], O[o, O_VY], O[o, O_TOL])):  # fmt: skip
                d = abs(cx - O[o, O_X]) + abs(cy - O[o, O_Y])
                if d < best_d:
                    best, best_d = o, d
        if best < 0:
            for o in range(n_objects):
                if O[o, O_VALID] != 0 and O[o, O_CLAIMED] == 0 and O[o, O_OWNER_W] == 0 and _box_meets(O, o, G, g, k) \
                        and (not measured or _agree(G[g, GR_VX], G[g, GR_VY], G[g, GR_TOL], O[o, O_VX], O[o, O_VY], O[o, O_TOL])):  # fmt: skip
                    d = abs(cx - O[o, O_X]) + abs(cy - O[o, O_Y])
                    if d < best_d:
                        best, best_d = o, d
        if best < 0:
            best = _create(O, OG, G, g, t, k)
        if best >= 0:
            O[best, O_CLAIMED] = 1
        G[g, GR_OBJECT] = best
    for i in range(m):
        o = G[C[i, CL_GROUP], GR_OBJECT]
        s = R[i, R_SLOT]
        if o < 0:
            OG[OG_UNASSIGNED] += 1
        else:
            _join(O, o, R, i, C)
        slot_obj[s], slot_id[s] = o, R[i, R_ID]
    for o in range(n_objects):  # 4. update
        if O[o, O_VALID] != 0 and O[o, O_MEMBERS] > 0:
            _update(O, o, t, k, log)
    for o in range(n_objects):  # 5. merge
        if O[o, O_VALID] == 0 or O[o, O_MEMBERS] == 0:
            continue
        for q in range(n_objects):
            if q != o and O[q, O_VALID] != 0 and O[q, O_ID] < O[o, O_ID] \
                    and abs(O[o, O_X] - O[q, O_X]) <= O[q, O_RX] << up and abs(O[o, O_Y] - O[q, O_Y]) <= O[q, O_RY] << up \
                    and _agree(O[o, O_VX], O[o, O_VY], O[o, O_TOL], O[q, O_VX], O[q, O_VY], O[q, O_TOL]):  # fmt: skip
                O[o, O_VALID] = 0
                OG[OG_MERGED] += 1
                for j in range(slot_obj.size):
                    if slot_obj[j] == o:
                        slot_obj[j] = q
                break
    for o in range(n_objects):  # 6. birth and death, records
        if O[o, O_VALID] == 0:
            continue
        unseen = (t - O[o, O_T_SEEN]) & TIME_MASK
        if O[o, O_MEMBERS] > 0:
            if O[o, O_CONFIRMED] == 0 and ((t - O[o, O_T_BORN]) & TIME_MASK) >= k.birth_us:
                O[o, O_CONFIRMED] = 1
                OG[OG_CONFIRMED] += 1
        else:
            outside = O[o, O_X] < 0 or O[o, O_Y] < 0 or O[o, O_X] > k.last_x or O[o, O_Y] > k.last_y
            if unseen > (k.keep_us if O[o, O_CONFIRMED] != 0 else k.birth_us) or outside:
                O[o, O_VALID] = 0
                OG[OG_FREED] += 1
                continue
        if O[o, O_CONFIRMED] == 0 or unseen > k.coast_us:
            continue
        row = out[n_out]
        row[0], row[1], row[2], row[3] = t_full, step, o, O[o, O_ID]
        row[4], row[5] = O[o, O_X] / 2.0**k.fp, O[o, O_Y] / 2.0**k.fp
        row[6], row[7] = O[o, O_RX] / 2.0**k.fr, O[o, O_RY] / 2.0**k.fr
        row[8], row[9] = O[o, O_VX] / 2.0**k.fv, O[o, O_VY] / 2.0**k.fv
        row[10], row[11], row[12] = O[o, O_LUM] / 2.0**k.fc, O[o, O_CB] / 2.0**k.fc, O[o, O_CR] / 2.0**k.fc
        row[13], row[14] = O[o, O_CLASS], O[o, O_MEMBERS]
        flags = 0
        if O[o, O_EVER_REPORTED] == 0:
            flags |= OFLAG_NEW
        if O[o, O_MEMBERS] == 0:
            flags |= OFLAG_COASTING
        row[15] = flags
        O[o, O_EVER_REPORTED] = 1
        n_out += 1
    return n_out


@njit(cache=True, nogil=True)
def run_steps(O, OG, slot_obj, slot_id, raw, steps, first_step, k, out, C, G, log):
    """Every filter step of a chunk: `steps[i]` is the whole time of step first_step + i, `raw`
    the chunk's cluster records as raw integers in step order. Returns the number of object records."""
    n_out = 0
    r = 0
    for i in range(steps.size):
        step = first_step + i
        lo = r
        while r < raw.shape[0] and raw[r, R_STEP] == step:
            r += 1
        n_out = object_step(O, OG, slot_obj, slot_id, raw[lo:r].copy(), steps[i], step, k, out, n_out, C, G, log)
    return n_out


def record_scales(table: FormatTable) -> np.ndarray:
    """2^frac of each record column: a fixed model's record row times these is its raw record."""
    f = table.formats
    scale = np.ones(RECORD_COLUMNS)
    for columns, name in (((R_X, R_Y), "centre"), ((R_RX, R_RY), "half_size"), ((R_ACT,), "activity"), ((R_VMX, R_VMY), "v_mcm"),
                          ((R_VIX, R_VIY), "v_int"), ((R_LUM, R_CB, R_CR), "colour")):  # fmt: skip
        for col in columns:
            scale[col] = 2.0 ** f[name].frac_bits
    return scale


class FixedObjects:
    """The bit-accurate object layer: the fixed clusterer's records and step times in, object records out."""

    def __init__(self, table: FormatTable, params):
        self.k = fixed_object_constants(table)
        self.scale = record_scales(table)
        n = params.n_clusters
        self.objects = np.zeros((params.n_objects, len(OBJECT_COLUMNS)), dtype=np.int64)
        self.globals = np.zeros(len(OBJECT_GLOBAL_COLUMNS), dtype=np.int64)
        self.slot_object = np.full(n, -1, dtype=np.int64)
        self.slot_id = np.full(n, -1, dtype=np.int64)
        self.scratch = (np.zeros((n, CLUSTER_SCRATCH_COLUMNS), np.int64), np.zeros((n, GROUP_SCRATCH_COLUMNS), np.int64))
        self.overflow = np.zeros(len(OBJECT_SIGNALS), dtype=np.int64)
        self.first_step = 0

    def raw_records(self, rows: np.ndarray) -> np.ndarray:
        """The fixed clusterer's record rows as the raw integers of the record word (exactly: the
        rows are whole numbers of their LSBs)."""
        raw = np.rint(rows * self.scale).astype(np.int64)
        raw[:, 0] = rows[:, 0].astype(np.int64)  # the whole time, not rounded through a float scale
        return raw

    def feed(self, rows: np.ndarray, steps: np.ndarray) -> np.ndarray:
        out = np.empty((steps.size * self.objects.shape[0], OBJECT_RECORD_COLUMNS))
        n = run_steps(self.objects, self.globals, self.slot_object, self.slot_id, self.raw_records(rows),
                      np.asarray(steps, np.int64), self.first_step, self.k, out, *self.scratch, self.overflow)  # fmt: skip
        self.first_step += steps.size
        return out[:n]

    def stats(self) -> dict:
        g = self.globals
        saturations = {name: int(c) for name, c in zip(OBJECT_SIGNALS, self.overflow) if c}
        return {"objects_created": int(g[OG_CREATED]), "objects_confirmed": int(g[OG_CONFIRMED]), "objects_freed": int(g[OG_FREED]),
                "objects_merged": int(g[OG_MERGED]), "clusters_unassigned": int(g[OG_UNASSIGNED]),
                "object_saturations": saturations}  # fmt: skip
