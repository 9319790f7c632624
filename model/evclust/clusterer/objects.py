"""The object layer, floating point (beyond the paper; SPEC §4, "Object layer"; docs/OBJECTS.md).

The clusters work at event rate and see what events show: edges and texture patches. Objects
are formed at record rate, once per filter step, from the step's reported clusters:

1. **Predict.** Every object moves by its velocity over the time Δt since the last step.
2. **Group.** Two clusters belong together (common fate) when both have measured velocities
   that agree and their boxes overlap once grown by `object_gate` px, and along their motion
   (once it is known: their speed above their velocity tolerance) by `object_link_along` times
   their larger half-size across it (the leading and trailing edges of a uniform object lie along
   its motion, an object length apart); or, with a velocity not yet measured, when their boxes
   overlap once grown by the gate. Groups are the links' transitive closure.
3. **Associate.** A group continues the object its most active member joined last step (same
   slot, same cluster id) when that object's box grown by the gate still meets the group's box;
   when several groups claim one object, the most active keeps it. Any other group joins the
   nearest object whose box holds its centre (a fragment of it), else the nearest unclaimed
   object whose grown box meets it, velocities agreeing; else it starts a tentative object.
4. **Update.** An object with members measures the extent of their boxes; its centre follows
   that box's centre through a constant-velocity α-β filter, and its velocity follows both the
   centre's residual and its most active member's measured velocity (an interval estimate; the
   MCM guess of a young cluster is no measurement). Each gain is min(Δ/T, 1), Δ the time since
   the object was last seen and T in frames, so the filters' memory is in time, whatever the event
   rate and however long it coasted; the residual's gain on the velocity is Δ/T², at most 1/Δ,
   and what it adds to the velocity in one step is clipped to the velocity's tolerance.
   Its half-size, colour and class follow its members' (colour and class from its most active
   member that has a class: an edge mixture with the background has none).
5. **Merge.** An object whose centre lies in an older object's box, velocities agreeing, is a
   fragment of it: the older absorbs it and its clusters follow.
6. **Birth and death.** An object is tentative until it has had members for
   `object_birth_frames`; only confirmed objects are reported. An object without members
   coasts on its prediction and is reported for `object_coast_frames`, then kept unreported
   until `object_keep_frames` for its clusters to come back (its slot goes first to a new
   object); a tentative one is kept for its birth time. An object that coasts out of the sensor
   is freed.

Every step writes one object record per confirmed object that is not lost (OBJECT_RECORD_COLUMNS,
the order of `evclust.tracks.OBJECT_DTYPE`). The fixed model (evclust.fixed.objects) computes the
same steps in the same order in integer arithmetic; the RTL (rtl/evclust_objects.v) follows it.
"""

from __future__ import annotations

import math
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
    R_STEP, R_VIX, R_VIY, R_VMX, R_VMY, R_X, R_Y,
)  # fmt: skip
from evclust.jit import njit

DT_MAX_US = (1 << 24) - 1  # Δt saturates here (16.8 s): every gain is 1 long before, and the hardware counts 24 bits
DT_FRAMES_MAX = 1024.0 - 2.0**-24  # ... and so does Δt in frames


def object_time_us(p, name: str, t_frame_us: float) -> int:
    """The birth, coast or keep time (`name`) in whole µs, keep at least coast, at most DT_MAX_US
    (Δt saturates there, and an object unseen that long is gone)."""
    frames = getattr(p, f"object_{name}_frames") if name != "keep" else max(p.object_keep_frames, p.object_coast_frames)
    return min(round(frames * t_frame_us), DT_MAX_US)


# The object layer's parameters as the compiled step reads them.
ObjectConstants = namedtuple(
    "ObjectConstants",
    (
        "t_frame_us",  # µs per frame: the unit of the velocities and of the filters' time constants
        "gate",  # px: the margin of every overlap test
        "link_along",  # clusters along their motion link within this multiple of their larger half-size across it
        "v_tol",
        "v_rel",  # velocity agreement: L1 difference <= v_tol + v_rel·(the faster L1 speed)
        "track_frames",  # the α-β filter's time constant on the centre
        "rate_frames",  # ... and on the velocity, by the centre's residual
        "velocity_frames",  # the velocity's pull towards its most active member's
        "size_frames",
        "colour_frames",
        "birth_us",
        "coast_us",
        "keep_us",  # times of birth, coasting (reported) and keeping (not), µs
        "width",
        "height",
    ),
)


def object_constants(p, width: int, height: int, t_frame_us: float) -> ObjectConstants:
    """The constants of a parameter set (p resolved to µs); the times in whole µs, as the hardware
    counts them (`object_time_us`)."""
    return ObjectConstants(
        float(t_frame_us), p.object_gate, p.object_link_along, p.object_v_tol, p.object_v_rel,
        p.object_track_frames, p.object_rate_frames, p.object_velocity_frames, p.object_size_frames, p.object_colour_frames,
        *(float(object_time_us(p, name, t_frame_us)) for name in ("birth", "coast", "keep")), float(width), float(height),
    )  # fmt: skip


@njit(cache=True, nogil=True, inline="always")
def cluster_velocity(rows, r):
    """A cluster's velocity as the object layer takes it, and whether it is measured: the
    interval estimate once it has one (exactly 0 before its first full interval), else MCM's."""
    if rows[r, R_VIX] != 0.0 or rows[r, R_VIY] != 0.0:
        return rows[r, R_VIX], rows[r, R_VIY], True
    return rows[r, R_VMX], rows[r, R_VMY], False


@njit(cache=True, nogil=True, inline="always")
def _tolerance(vx, vy, k):
    """The velocity difference a velocity tolerates: v_tol + v_rel·|V|₁ (two velocities agree
    within the larger of their tolerances, that is v_tol + v_rel times the faster speed)."""
    return k.v_tol + k.v_rel * (abs(vx) + abs(vy))


@njit(cache=True, nogil=True, inline="always")
def _agree(ax, ay, a_tol, bx, by, b_tol):
    return abs(ax - bx) + abs(ay - by) <= max(a_tol, b_tol)


@njit(cache=True, nogil=True)
def _linked(rows, i, j, C, k):
    """Step 2's test for the step's clusters i and j (their records and scratch rows)."""
    dx = abs(rows[i, R_X] - rows[j, R_X])
    dy = abs(rows[i, R_Y] - rows[j, R_Y])
    sx = rows[i, R_RX] + rows[j, R_RX] + k.gate
    sy = rows[i, R_RY] + rows[j, R_RY] + k.gate
    if C[i, CL_MEASURED] != 0.0 and C[j, CL_MEASURED] != 0.0:
        if not _agree(C[i, CL_VX], C[i, CL_VY], C[i, CL_TOL], C[j, CL_VX], C[j, CL_VY], C[j, CL_TOL]):
            return False
        # Along their motion, once it is known: their speeds (summed) above their tolerance (doubled).
        along_x, along_y = abs(C[i, CL_VX] + C[j, CL_VX]), abs(C[i, CL_VY] + C[j, CL_VY])
        if along_x + along_y > 2.0 * max(C[i, CL_TOL], C[j, CL_TOL]):
            if along_x >= along_y:  # along x: the edges are apart in x
                sx += max(C[i, CL_REACH_Y], C[j, CL_REACH_Y])
            else:
                sy += max(C[i, CL_REACH_X], C[j, CL_REACH_X])
    return dx <= sx and dy <= sy


@njit(cache=True, nogil=True, inline="always")
def _box_meets(O, o, G, g, k):
    """The object's box grown by the gate meets the group's box."""
    return (G[g, GR_LO_X] <= O[o, O_X] + O[o, O_RX] + k.gate and G[g, GR_HI_X] >= O[o, O_X] - O[o, O_RX] - k.gate
            and G[g, GR_LO_Y] <= O[o, O_Y] + O[o, O_RY] + k.gate and G[g, GR_HI_Y] >= O[o, O_Y] - O[o, O_RY] - k.gate)  # fmt: skip


@njit(cache=True, nogil=True, inline="always")
def _gain(dt_frames, frames):
    """min(Δt/T, 1): the gain of a first-order filter of time constant T frames over Δt."""
    return min(dt_frames / frames, 1.0)


@njit(cache=True, nogil=True)
def _clear_members(O, o):
    O[o, O_MEMBERS] = O[o, O_CLAIMED] = O[o, O_OWNER_W] = 0.0
    O[o, O_LO_X], O[o, O_LO_Y] = np.inf, np.inf
    O[o, O_HI_X], O[o, O_HI_Y] = -np.inf, -np.inf
    O[o, O_V_WEIGHT] = -1.0  # any member's activity beats it: the first member's velocity is taken
    O[o, O_COLOUR_WEIGHT] = 0.0  # a member with a class and an activity of 0 gives no colour


@njit(cache=True, nogil=True)
def _create(O, OG, G, g, t, k):
    """A tentative object for group g in the first free slot, else in place of the lost object
    unseen the longest; -1 when every slot holds a reported or tentative object."""
    free, lost, lost_for = -1, -1, -1.0
    for o in range(O.shape[0]):
        if O[o, O_VALID] == 0.0:
            free = o
            break
        unseen = t - O[o, O_T_SEEN]
        if O[o, O_CONFIRMED] != 0.0 and unseen > k.coast_us and unseen > lost_for:
            lost, lost_for = o, unseen
    if free < 0:
        if lost < 0:
            return -1
        free = lost
        OG[OG_FREED] += 1.0
    o = free
    O[o, :] = 0.0
    O[o, O_VALID] = 1.0
    O[o, O_ID] = OG[OG_NEXT_ID]
    OG[OG_NEXT_ID] += 1.0
    O[o, O_X], O[o, O_Y] = 0.5 * (G[g, GR_LO_X] + G[g, GR_HI_X]), 0.5 * (G[g, GR_LO_Y] + G[g, GR_HI_Y])
    O[o, O_RX], O[o, O_RY] = 0.5 * (G[g, GR_HI_X] - G[g, GR_LO_X]), 0.5 * (G[g, GR_HI_Y] - G[g, GR_LO_Y])
    O[o, O_VX], O[o, O_VY], O[o, O_TOL] = G[g, GR_VX], G[g, GR_VY], G[g, GR_TOL]
    O[o, O_CLASS] = -1.0
    O[o, O_T_BORN] = O[o, O_T_SEEN] = t
    _clear_members(O, o)
    OG[OG_CREATED] += 1.0
    return o


@njit(cache=True, nogil=True)
def _join(O, o, rows, r, C, c):
    """Add a member cluster to its object's step sums: its box to the extent, its velocity if it
    is the most active member yet, its colour and class if it is the most active with a class."""
    a = rows[r, R_ACT]
    O[o, O_MEMBERS] += 1.0
    O[o, O_LO_X] = min(O[o, O_LO_X], rows[r, R_X] - rows[r, R_RX])
    O[o, O_HI_X] = max(O[o, O_HI_X], rows[r, R_X] + rows[r, R_RX])
    O[o, O_LO_Y] = min(O[o, O_LO_Y], rows[r, R_Y] - rows[r, R_RY])
    O[o, O_HI_Y] = max(O[o, O_HI_Y], rows[r, R_Y] + rows[r, R_RY])
    if C[c, CL_MEASURED] != 0.0 and a > O[o, O_V_WEIGHT]:  # (the velocity of one not measured is MCM's early guess)
        O[o, O_V_WEIGHT], O[o, O_MEMBER_VX], O[o, O_MEMBER_VY] = a, C[c, CL_VX], C[c, CL_VY]
    if rows[r, R_CLASS] >= 0.0 and a > O[o, O_COLOUR_WEIGHT]:
        O[o, O_COLOUR_WEIGHT], O[o, O_MEMBER_CLASS] = a, rows[r, R_CLASS]
        O[o, O_MEMBER_LUM], O[o, O_MEMBER_CB], O[o, O_MEMBER_CR] = rows[r, R_LUM], rows[r, R_CB], rows[r, R_CR]


@njit(cache=True, nogil=True, inline="always")
def rate_gain(seen_frames, rate_frames):
    """The velocity's gain on the centre's residual after Δ frames, per frame: Δ/T², but no more
    than the residual over Δ itself (1/Δ, rounded down to a power of two, as the hardware shifts)."""
    if seen_frames <= 0.0:
        return 0.0
    return min(seen_frames / (rate_frames * rate_frames), 2.0 ** -math.ceil(math.log2(seen_frames)))


@njit(cache=True, nogil=True)
def _update(O, o, t, k):
    """Step 4 for one object with members. The gains run over Δ, the time since the object was
    last seen (one step, unless it coasted): its residual has built up over all of it."""
    zx, zy = 0.5 * (O[o, O_LO_X] + O[o, O_HI_X]), 0.5 * (O[o, O_LO_Y] + O[o, O_HI_Y])
    hx, hy = 0.5 * (O[o, O_HI_X] - O[o, O_LO_X]), 0.5 * (O[o, O_HI_Y] - O[o, O_LO_Y])
    seen = min(min(t - O[o, O_T_SEEN], DT_MAX_US) / k.t_frame_us, DT_FRAMES_MAX)
    measured = O[o, O_V_WEIGHT] >= 0.0  # a member with a measured velocity
    if O[o, O_T_BORN] == t:  # born this step: the measurement as it is
        O[o, O_X], O[o, O_Y], O[o, O_RX], O[o, O_RY] = zx, zy, hx, hy
        if measured:
            O[o, O_VX], O[o, O_VY] = O[o, O_MEMBER_VX], O[o, O_MEMBER_VY]
    else:
        # α-β: the centre moves towards the measurement, the velocity by the residual's rate
        # (clipped to the velocity's tolerance: a box that grows as a member joins is no motion),
        # and towards its most active member's measured velocity.
        ex, ey = zx - O[o, O_X], zy - O[o, O_Y]
        lim = O[o, O_TOL]
        g_pos = _gain(seen, k.track_frames)
        g_rate = rate_gain(seen, k.rate_frames)
        g_vel = _gain(seen, k.velocity_frames) if measured else 0.0
        g_size = _gain(seen, k.size_frames)
        O[o, O_X] += g_pos * ex
        O[o, O_Y] += g_pos * ey
        O[o, O_VX] += min(max(g_rate * ex, -lim), lim) + g_vel * (O[o, O_MEMBER_VX] - O[o, O_VX])
        O[o, O_VY] += min(max(g_rate * ey, -lim), lim) + g_vel * (O[o, O_MEMBER_VY] - O[o, O_VY])
        O[o, O_RX] += g_size * (hx - O[o, O_RX])
        O[o, O_RY] += g_size * (hy - O[o, O_RY])
    if O[o, O_COLOUR_WEIGHT] > 0.0:
        g_col = 1.0 if O[o, O_CLASS] < 0.0 else _gain(seen, k.colour_frames)  # the first colour as it is
        O[o, O_LUM] += g_col * (O[o, O_MEMBER_LUM] - O[o, O_LUM])
        O[o, O_CB] += g_col * (O[o, O_MEMBER_CB] - O[o, O_CB])
        O[o, O_CR] += g_col * (O[o, O_MEMBER_CR] - O[o, O_CR])
        O[o, O_CLASS] = O[o, O_MEMBER_CLASS]
    O[o, O_TOL] = _tolerance(O[o, O_VX], O[o, O_VY], k)
    O[o, O_T_SEEN] = t


@njit(cache=True, nogil=True)
def object_step(O, OG, slot_obj, slot_id, rows, lo, hi, t, step, k, out, n_out, C, G):
    """One filter step at time t: `rows[lo:hi]` are its cluster records (slot order). `slot_obj`,
    `slot_id`: per cluster slot, the object it joined last and its cluster id then. `C`, `G`:
    scratch (CLUSTER_SCRATCH_COLUMNS, GROUP_SCRATCH_COLUMNS), a row per cluster slot. Writes the
    reported objects' records from `out[n_out]`; returns the count."""
    dt_frames = 0.0 if OG[OG_STARTED] == 0.0 else min(min(t - OG[OG_T_PREV], DT_MAX_US) / k.t_frame_us, DT_FRAMES_MAX)
    OG[OG_STARTED], OG[OG_T_PREV] = 1.0, t
    OG[OG_STEPS] += 1.0
    n_objects = O.shape[0]
    for o in range(n_objects):  # 1. predict
        if O[o, O_VALID] != 0.0:
            O[o, O_X] += O[o, O_VX] * dt_frames
            O[o, O_Y] += O[o, O_VY] * dt_frames
            _clear_members(O, o)
    m = hi - lo
    step_rows = rows[lo:hi]
    for i in range(m):  # 2. group: the links' transitive closure, labelled by the lowest member
        C[i, CL_VX], C[i, CL_VY], measured = cluster_velocity(step_rows, i)
        C[i, CL_MEASURED] = 1.0 if measured else 0.0
        C[i, CL_TOL] = _tolerance(C[i, CL_VX], C[i, CL_VY], k)
        C[i, CL_REACH_X] = k.link_along * step_rows[i, R_RX]
        C[i, CL_REACH_Y] = k.link_along * step_rows[i, R_RY]
        C[i, CL_GROUP] = i
        for j in range(i):
            if C[j, CL_GROUP] != C[i, CL_GROUP] and _linked(step_rows, i, j, C, k):
                keep, drop = min(C[i, CL_GROUP], C[j, CL_GROUP]), max(C[i, CL_GROUP], C[j, CL_GROUP])
                for q in range(i + 1):
                    if C[q, CL_GROUP] == drop:
                        C[q, CL_GROUP] = keep
    for g in range(m):
        G[g, GR_LO_X] = G[g, GR_LO_Y] = np.inf
        G[g, GR_HI_X] = G[g, GR_HI_Y] = -np.inf
        G[g, GR_WEIGHT] = G[g, GR_PREFERRED_WEIGHT] = 0.0
        G[g, GR_V_WEIGHT] = -1.0
        G[g, GR_PREFERRED] = G[g, GR_OBJECT] = -1.0
    for i in range(m):  # each group's box, activity, velocity and preferred object
        g, r = int(C[i, CL_GROUP]), lo + i
        a = rows[r, R_ACT]
        G[g, GR_LO_X] = min(G[g, GR_LO_X], rows[r, R_X] - rows[r, R_RX])
        G[g, GR_HI_X] = max(G[g, GR_HI_X], rows[r, R_X] + rows[r, R_RX])
        G[g, GR_LO_Y] = min(G[g, GR_LO_Y], rows[r, R_Y] - rows[r, R_RY])
        G[g, GR_HI_Y] = max(G[g, GR_HI_Y], rows[r, R_Y] + rows[r, R_RY])
        G[g, GR_WEIGHT] += a
        if a > G[g, GR_V_WEIGHT]:
            G[g, GR_V_WEIGHT], G[g, GR_VX], G[g, GR_VY] = a, C[i, CL_VX], C[i, CL_VY]
            G[g, GR_MEASURED], G[g, GR_TOL] = C[i, CL_MEASURED], C[i, CL_TOL]
        s = int(rows[r, R_SLOT])
        prev = int(slot_obj[s]) if slot_id[s] == rows[r, R_ID] else -1
        if prev >= 0 and O[prev, O_VALID] != 0.0 and a > G[g, GR_PREFERRED_WEIGHT]:
            G[g, GR_PREFERRED], G[g, GR_PREFERRED_WEIGHT] = prev, a
    # 3. associate: each object goes to the most active group that continues it ...
    for g in range(m):
        o = int(G[g, GR_PREFERRED])
        if C[g, CL_GROUP] == g and o >= 0 and G[g, GR_WEIGHT] > O[o, O_OWNER_W] and _box_meets(O, o, G, g, k):
            O[o, O_OWNER_W] = G[g, GR_WEIGHT]
    for g in range(m):
        o = int(G[g, GR_PREFERRED])
        if C[g, CL_GROUP] == g and o >= 0 and O[o, O_CLAIMED] == 0.0 and O[o, O_OWNER_W] == G[g, GR_WEIGHT]:
            G[g, GR_OBJECT], O[o, O_CLAIMED] = o, 1.0
    # ... every other group to an object it is a fragment of, or the nearest unclaimed one it meets, or a new one.
    for g in range(m):
        if C[g, CL_GROUP] != g or G[g, GR_OBJECT] >= 0.0:
            continue
        cx, cy = 0.5 * (G[g, GR_LO_X] + G[g, GR_HI_X]), 0.5 * (G[g, GR_LO_Y] + G[g, GR_HI_Y])
        measured = G[g, GR_MEASURED] != 0.0
        best, best_d = -1, np.inf
        for o in range(n_objects):
            if O[o, O_VALID] != 0.0 and abs(cx - O[o, O_X]) <= O[o, O_RX] and abs(cy - O[o, O_Y]) <= O[o, O_RY] \
                    and (not measured or _agree(G[g, GR_VX], G[g, GR_VY], G[g, GR_TOL], O[o, O_VX], O[o, O_VY], O[o, O_TOL])):  # fmt: skip
                d = abs(cx - O[o, O_X]) + abs(cy - O[o, O_Y])
                if d < best_d:
                    best, best_d = o, d
        if best < 0:
            for o in range(n_objects):
                if O[o, O_VALID] != 0.0 and O[o, O_CLAIMED] == 0.0 and O[o, O_OWNER_W] == 0.0 and _box_meets(O, o, G, g, k) \
                        and (not measured or _agree(G[g, GR_VX], G[g, GR_VY], G[g, GR_TOL], O[o, O_VX], O[o, O_VY], O[o, O_TOL])):  # fmt: skip
                    d = abs(cx - O[o, O_X]) + abs(cy - O[o, O_Y])
                    if d < best_d:
                        best, best_d = o, d
        if best < 0:
            best = _create(O, OG, G, g, t, k)
        if best >= 0:
            O[best, O_CLAIMED] = 1.0
        G[g, GR_OBJECT] = best
    for i in range(m):  # every member joins its group's object
        r = lo + i
        o = int(G[int(C[i, CL_GROUP]), GR_OBJECT])
        s = int(rows[r, R_SLOT])
        if o < 0:
            OG[OG_UNASSIGNED] += 1.0
        else:
            _join(O, o, rows, r, C, i)
        slot_obj[s], slot_id[s] = o, rows[r, R_ID]
    for o in range(n_objects):  # 4. update
        if O[o, O_VALID] != 0.0 and O[o, O_MEMBERS] > 0.0:
            _update(O, o, t, k)
    for o in range(n_objects):  # 5. merge: an object inside an older one is a fragment of it
        if O[o, O_VALID] == 0.0 or O[o, O_MEMBERS] == 0.0:
            continue
        for q in range(n_objects):
            if q != o and O[q, O_VALID] != 0.0 and O[q, O_ID] < O[o, O_ID] \
                    and abs(O[o, O_X] - O[q, O_X]) <= O[q, O_RX] and abs(O[o, O_Y] - O[q, O_Y]) <= O[q, O_RY] \
                    and _agree(O[o, O_VX], O[o, O_VY], O[o, O_TOL], O[q, O_VX], O[q, O_VY], O[q, O_TOL]):  # fmt: skip
                O[o, O_VALID] = 0.0
                OG[OG_MERGED] += 1.0
                for j in range(slot_obj.size):
                    if slot_obj[j] == o:
                        slot_obj[j] = q
                break
    for o in range(n_objects):  # 6. birth and death, records
        if O[o, O_VALID] == 0.0:
            continue
        unseen = t - O[o, O_T_SEEN]
        if O[o, O_MEMBERS] > 0.0:
            if O[o, O_CONFIRMED] == 0.0 and t - O[o, O_T_BORN] >= k.birth_us:
                O[o, O_CONFIRMED] = 1.0
                OG[OG_CONFIRMED] += 1.0
        else:
            outside = O[o, O_X] < 0.0 or O[o, O_Y] < 0.0 or O[o, O_X] > k.width - 1.0 or O[o, O_Y] > k.height - 1.0
            if unseen > (k.keep_us if O[o, O_CONFIRMED] != 0.0 else k.birth_us) or outside:
                O[o, O_VALID] = 0.0
                OG[OG_FREED] += 1.0
                continue
        if O[o, O_CONFIRMED] == 0.0 or unseen > k.coast_us:
            continue  # tentative, or lost: kept, not reported
        row = out[n_out]
        row[0], row[1], row[2], row[3] = t, step, o, O[o, O_ID]
        row[4], row[5], row[6], row[7] = O[o, O_X], O[o, O_Y], O[o, O_RX], O[o, O_RY]
        row[8], row[9] = O[o, O_VX], O[o, O_VY]
        row[10], row[11], row[12], row[13] = O[o, O_LUM], O[o, O_CB], O[o, O_CR], O[o, O_CLASS]
        row[14] = O[o, O_MEMBERS]
        flags = 0
        if O[o, O_EVER_REPORTED] == 0.0:
            flags |= OFLAG_NEW
        if O[o, O_MEMBERS] == 0.0:
            flags |= OFLAG_COASTING
        row[15] = flags
        O[o, O_EVER_REPORTED] = 1.0
        n_out += 1
    return n_out


@njit(cache=True, nogil=True)
def run_steps(O, OG, slot_obj, slot_id, rows, steps, first_step, k, out, C, G):
    """Every filter step of a chunk: `steps[i]` is the time of step first_step + i, and `rows` the
    chunk's cluster records in step order. Returns the number of object records written."""
    n_out = 0
    r = 0
    for i in range(steps.size):
        step = first_step + i
        lo = r
        while r < rows.shape[0] and rows[r, R_STEP] == step:
            r += 1
        n_out = object_step(O, OG, slot_obj, slot_id, rows, lo, r, steps[i], step, k, out, n_out, C, G)
    return n_out


class FloatObjects:
    """The object layer's state and its driver: cluster records and step times in, object records out."""

    def __init__(self, params, width: int, height: int, t_frame_us: float):
        self.k = object_constants(params, width, height, t_frame_us)
        self.objects = np.zeros((params.n_objects, len(OBJECT_COLUMNS)))
        self.globals = np.zeros(len(OBJECT_GLOBAL_COLUMNS))
        self.slot_object = np.full(params.n_clusters, -1.0)
        self.slot_id = np.full(params.n_clusters, -1.0)
        self.scratch = (np.zeros((params.n_clusters, CLUSTER_SCRATCH_COLUMNS)), np.zeros((params.n_clusters, GROUP_SCRATCH_COLUMNS)))
        self.first_step = 0

    def feed(self, rows: np.ndarray, steps: np.ndarray) -> np.ndarray:
        """Object records of the filter steps `steps` (their times), whose cluster records are `rows`."""
        out = np.empty((steps.size * self.objects.shape[0], OBJECT_RECORD_COLUMNS))
        n = run_steps(self.objects, self.globals, self.slot_object, self.slot_id, rows, np.asarray(steps, np.float64),
                      self.first_step, self.k, out, *self.scratch)  # fmt: skip
        self.first_step += steps.size
        return out[:n]

    def stats(self) -> dict:
        g = self.globals
        return {"objects_created": int(g[OG_CREATED]), "objects_confirmed": int(g[OG_CONFIRMED]), "objects_freed": int(g[OG_FREED]),
                "objects_merged": int(g[OG_MERGED]), "clusters_unassigned": int(g[OG_UNASSIGNED])}  # fmt: skip
