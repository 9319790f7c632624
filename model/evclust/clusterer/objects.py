"""The object layer, floating point (beyond the paper; SPEC §4, "Object layer").

The clusters work at event rate and see what events show: edges and texture patches. Objects
are formed at record rate, once per filter step, from the step's reported clusters:

1. **Predict.** Every object moves by its velocity over the time since the last step.
2. **Associate.** Each cluster joins the object it joined last step (same slot, same id) while
   its box stays within that object's gate; otherwise the nearest object whose gate holds it and
   whose velocity agrees with its own (common fate); otherwise it starts a new, tentative object
   that later clusters of the same step may join. An object's gate is its box grown by
   `object_gate` px plus a multiple of its larger half-size, a larger multiple along its motion
   (the leading and trailing edges of one object lie along its motion, an object length apart).
3. **Update.** An object with members measures the extent of their boxes; its centre and
   velocity follow that box centre through a constant-velocity α-β filter whose gains grow
   with the time since the last step (so the filter's time constants are in frames, whatever
   the event rate), and its velocity also follows its members' velocities. Its box, colour and
   class follow the members' (colour from the members that carry a class: an edge mixture with
   the background does not).
4. **Birth and death.** An object is tentative until it has had members for
   `object_birth_frames`; only confirmed objects are reported. An object without members
   coasts on its prediction for up to `object_coast_frames` (a tentative one is dropped at
   once), and is freed when it coasts out of the sensor.

Every step writes one object record per confirmed object (OBJECT_RECORD_COLUMNS, the order of
`evclust.tracks.OBJECT_DTYPE`).
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from evclust.clusterer.layout import (
    O_BEST_CLASS, O_BEST_W, O_CB, O_CLASS, O_CONFIRMED, O_CR, O_EVER_REPORTED, O_HI_X, O_HI_Y, O_ID, O_LO_X, O_LO_Y, O_LUM,
    O_MEMBERS, O_OWNER_W, O_RX, O_RY, O_T_BORN, O_T_SEEN, O_VALID, O_VX, O_VY, O_W, O_WVX, O_WVY, O_X, O_LUM_M, O_CB_M, O_CR_M,
    O_Y, OBJECT_COLUMNS, OBJECT_GLOBAL_COLUMNS, OBJECT_RECORD_COLUMNS, OFLAG_COASTING, OFLAG_NEW, OG_CONFIRMED, OG_CREATED,
    OG_FREED, OG_MERGED, OG_NEXT_ID, OG_STARTED, OG_STEPS, OG_T_PREV, OG_UNASSIGNED, R_ACT, R_CB, R_CLASS, R_CR, R_ID, R_LUM, R_RX, R_RY,
    R_SLOT, R_STEP, R_VIX, R_VIY, R_VMX, R_VMY, R_X, R_Y,
)  # fmt: skip
from evclust.jit import njit

# The object layer's parameters as the compiled step reads them: times in frames, lengths in px.
ObjectConstants = namedtuple(
    "ObjectConstants",
    (
        "t_frame_us",  # µs per frame: the unit of every time below and of the velocities
        "gate",  # px: the margin of every overlap test
        "link_along",  # two clusters along their motion link within this multiple of their larger half-size across it
        "v_tol", "v_rel",  # velocity agreement: L1 difference <= v_tol + v_rel·(the faster L1 speed)
        "track_frames",  # the α-β filter's time constant on the centre
        "rate_frames",  # ... and the time constant of its velocity's pull by the centre's residual
        "velocity_frames",  # the time constant of the velocity's pull towards the members'
        "size_frames", "colour_frames",
        "birth_frames", "coast_frames", "keep_frames",
        "width", "height",
    ),
)


def object_constants(p, width: int, height: int, t_frame_us: float) -> ObjectConstants:
    return ObjectConstants(
        float(t_frame_us), p.object_gate, p.object_link_along, p.object_v_tol, p.object_v_rel,
        p.object_track_frames, p.object_rate_frames, p.object_velocity_frames, p.object_size_frames, p.object_colour_frames,
        p.object_birth_frames, p.object_coast_frames, max(p.object_keep_frames, p.object_coast_frames), float(width), float(height),
    )  # fmt: skip


@njit(cache=True, nogil=True, inline="always")
def cluster_velocity(rows, r):
    """A cluster's velocity as the object layer takes it, and whether it is measured: the
    interval estimate once it has one (exactly 0 before its first full interval), else MCM's."""
    if rows[r, R_VIX] != 0.0 or rows[r, R_VIY] != 0.0:
        return rows[r, R_VIX], rows[r, R_VIY], True
    return rows[r, R_VMX], rows[r, R_VMY], False


@njit(cache=True, nogil=True, inline="always")
def _agree(ax, ay, bx, by, k):
    """Common fate: velocities within v_tol + v_rel times the faster L1 speed."""
    fast = max(abs(ax) + abs(ay), abs(bx) + abs(by))
    return abs(ax - bx) + abs(ay - by) <= k.v_tol + k.v_rel * fast


@njit(cache=True, nogil=True)
def _linked(rows, i, j, vel, k):
    """Two clusters of one object: both measured with agreeing velocities, and their boxes
    overlap once grown by `gate`, across their motion, and along it by `gate` plus link_along
    times their larger half-size across it (the leading and trailing edges of an object lie
    along its motion, about an object length apart); or, unmeasured, their boxes overlap once
    grown by `gate`."""
    dx = abs(rows[i, R_X] - rows[j, R_X])
    dy = abs(rows[i, R_Y] - rows[j, R_Y])
    sx = rows[i, R_RX] + rows[j, R_RX] + k.gate
    sy = rows[i, R_RY] + rows[j, R_RY] + k.gate
    if vel[i, 2] != 0.0 and vel[j, 2] != 0.0:
        if not _agree(vel[i, 0], vel[i, 1], vel[j, 0], vel[j, 1], k):
            return False
        if abs(vel[i, 0] + vel[j, 0]) >= abs(vel[i, 1] + vel[j, 1]):  # moving along x
            sx += k.link_along * max(rows[i, R_RY], rows[j, R_RY])
        else:
            sy += k.link_along * max(rows[i, R_RX], rows[j, R_RX])
    return dx <= sx and dy <= sy


@njit(cache=True, nogil=True, inline="always")
def _box_meets(O, o, lo_x, hi_x, lo_y, hi_y, k):
    """The object's box grown by `gate` overlaps the box [lo_x, hi_x] x [lo_y, hi_y]."""
    return (lo_x <= O[o, O_X] + O[o, O_RX] + k.gate and hi_x >= O[o, O_X] - O[o, O_RX] - k.gate
            and lo_y <= O[o, O_Y] + O[o, O_RY] + k.gate and hi_y >= O[o, O_Y] - O[o, O_RY] - k.gate)  # fmt: skip


@njit(cache=True, nogil=True)
def _clear_members(O, o):
    O[o, O_MEMBERS] = 0.0
    O[o, O_LO_X], O[o, O_LO_Y] = np.inf, np.inf
    O[o, O_HI_X], O[o, O_HI_Y] = -np.inf, -np.inf
    O[o, O_W] = O[o, O_WVX] = O[o, O_WVY] = 0.0
    O[o, O_BEST_W], O[o, O_BEST_CLASS] = 0.0, -1.0


@njit(cache=True, nogil=True)
def _create(O, OG, t, x, y, rx, ry, vx, vy, k):
    """A tentative object in the first free slot, else in place of the lost object (one no longer
    reported) unseen the longest; -1 when there is neither. Its members set its state."""
    free, lost, lost_seen = -1, -1, np.inf
    for o in range(O.shape[0]):
        if O[o, O_VALID] == 0.0:
            free = o
            break
        if (t - O[o, O_T_SEEN]) / k.t_frame_us > k.coast_frames and O[o, O_T_SEEN] < lost_seen:
            lost, lost_seen = o, O[o, O_T_SEEN]
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
    O[o, O_X], O[o, O_Y], O[o, O_RX], O[o, O_RY] = x, y, rx, ry
    O[o, O_VX], O[o, O_VY] = vx, vy
    O[o, O_CLASS] = -1.0
    O[o, O_T_BORN] = O[o, O_T_SEEN] = t
    _clear_members(O, o)
    OG[OG_CREATED] += 1.0
    return o


@njit(cache=True, nogil=True)
def _join(O, o, rows, r, vx, vy):
    """Add a member cluster to its object's sums: box extent, activity-weighted velocity and
    colour (colour only from members with a class), and the most active member's class."""
    a = rows[r, R_ACT]
    O[o, O_MEMBERS] += 1.0
    O[o, O_LO_X] = min(O[o, O_LO_X], rows[r, R_X] - rows[r, R_RX])
    O[o, O_HI_X] = max(O[o, O_HI_X], rows[r, R_X] + rows[r, R_RX])
    O[o, O_LO_Y] = min(O[o, O_LO_Y], rows[r, R_Y] - rows[r, R_RY])
    O[o, O_HI_Y] = max(O[o, O_HI_Y], rows[r, R_Y] + rows[r, R_RY])
    if a > O[o, O_W]:  # the most active member's velocity
        O[o, O_W], O[o, O_WVX], O[o, O_WVY] = a, vx, vy
    if rows[r, R_CLASS] >= 0.0 and a > O[o, O_BEST_W]:  # the most active member with a class: colour and class
        O[o, O_BEST_W], O[o, O_BEST_CLASS] = a, rows[r, R_CLASS]
        O[o, O_LUM_M], O[o, O_CB_M], O[o, O_CR_M] = rows[r, R_LUM], rows[r, R_CB], rows[r, R_CR]


@njit(cache=True, nogil=True, inline="always")
def _gain(dt_frames, frames):
    """The gain of a first-order filter of time constant `frames` over dt_frames, at most 1."""
    return min(dt_frames / frames, 1.0) if frames > 0.0 else 1.0


@njit(cache=True, nogil=True)
def _update(O, o, t, dt_frames, k):
    """Fold the step's members into the object (see the module's docstring, step 3)."""
    zx, zy = 0.5 * (O[o, O_LO_X] + O[o, O_HI_X]), 0.5 * (O[o, O_LO_Y] + O[o, O_HI_Y])
    hx, hy = 0.5 * (O[o, O_HI_X] - O[o, O_LO_X]), 0.5 * (O[o, O_HI_Y] - O[o, O_LO_Y])
    mvx, mvy = O[o, O_WVX], O[o, O_WVY]
    if O[o, O_T_BORN] == t:  # born this step: the measurement as it is
        O[o, O_X], O[o, O_Y], O[o, O_RX], O[o, O_RY] = zx, zy, hx, hy
        O[o, O_VX], O[o, O_VY] = mvx, mvy
    else:
        # α-β: the centre moves towards the measurement, the velocity by the residual's rate.
        ex, ey = zx - O[o, O_X], zy - O[o, O_Y]
        g_pos = _gain(dt_frames, k.track_frames)
        g_rate = _gain(dt_frames, k.rate_frames) / k.rate_frames  # per frame
        g_vel = _gain(dt_frames, k.velocity_frames)
        O[o, O_X] += g_pos * ex
        O[o, O_Y] += g_pos * ey
        O[o, O_VX] += g_rate * ex + g_vel * (mvx - O[o, O_VX])
        O[o, O_VY] += g_rate * ey + g_vel * (mvy - O[o, O_VY])
        g_size = _gain(dt_frames, k.size_frames)
        O[o, O_RX] += g_size * (hx - O[o, O_RX])
        O[o, O_RY] += g_size * (hy - O[o, O_RY])
    if O[o, O_BEST_CLASS] >= 0.0:
        g_col = 1.0 if O[o, O_CLASS] < 0.0 else _gain(dt_frames, k.colour_frames)  # the first colour as it is
        O[o, O_LUM] += g_col * (O[o, O_LUM_M] - O[o, O_LUM])
        O[o, O_CB] += g_col * (O[o, O_CB_M] - O[o, O_CB])
        O[o, O_CR] += g_col * (O[o, O_CR_M] - O[o, O_CR])
        O[o, O_CLASS] = O[o, O_BEST_CLASS]
    O[o, O_T_SEEN] = t


@njit(cache=True, nogil=True)
def object_step(O, OG, slot_obj, slot_id, rows, lo, hi, t, step, k, out, n_out, vel, label, comp):
    """One filter step of the object layer: `rows[lo:hi]` are the step's cluster records (slot
    order). `slot_obj` / `slot_id`: per cluster slot, the object it joined last and the cluster
    id it had then. `vel`, `label`, `comp`: scratch, one row per cluster slot. Writes the
    confirmed objects' records from `out[n_out]`; returns the count."""
    dt_frames = 0.0 if OG[OG_STARTED] == 0.0 else (t - OG[OG_T_PREV]) / k.t_frame_us
    OG[OG_STARTED], OG[OG_T_PREV] = 1.0, t
    OG[OG_STEPS] += 1.0
    n_objects = O.shape[0]
    for o in range(n_objects):  # 1. predict
        if O[o, O_VALID] != 0.0:
            O[o, O_X] += O[o, O_VX] * dt_frames
            O[o, O_Y] += O[o, O_VY] * dt_frames
            _clear_members(O, o)
    m = hi - lo
    # 2. group: clusters linked by common fate, transitively (label: the lowest member's index).
    for i in range(m):
        vel[i, 0], vel[i, 1], measured = cluster_velocity(rows, lo + i)
        vel[i, 2] = 1.0 if measured else 0.0
        label[i] = i
        for j in range(i):
            if label[j] != label[i] and _linked(rows, lo + i, lo + j, vel, k):
                keep, drop = min(label[i], label[j]), max(label[i], label[j])
                for q in range(i + 1):
                    if label[q] == drop:
                        label[q] = keep
    # Each group's box, activity, velocity (its most active member's), and the object its most
    # active member joined last step (comp: lo_x, hi_x, lo_y, hi_y, activity, vx, vy, preferred
    # object, its member's activity, object, velocity member's activity, measured).
    for c in range(m):
        comp[c, 0], comp[c, 2] = np.inf, np.inf
        comp[c, 1], comp[c, 3] = -np.inf, -np.inf
        comp[c, 4] = comp[c, 5] = comp[c, 6] = comp[c, 8] = comp[c, 10] = comp[c, 11] = 0.0
        comp[c, 7] = comp[c, 9] = -1.0
    for i in range(m):
        r, c = lo + i, int(label[i])
        a = rows[r, R_ACT]
        comp[c, 0] = min(comp[c, 0], rows[r, R_X] - rows[r, R_RX])
        comp[c, 1] = max(comp[c, 1], rows[r, R_X] + rows[r, R_RX])
        comp[c, 2] = min(comp[c, 2], rows[r, R_Y] - rows[r, R_RY])
        comp[c, 3] = max(comp[c, 3], rows[r, R_Y] + rows[r, R_RY])
        comp[c, 4] += a
        if a > comp[c, 10]:  # the most active member's velocity, and whether it is measured
            comp[c, 5], comp[c, 6], comp[c, 10], comp[c, 11] = vel[i, 0], vel[i, 1], a, vel[i, 2]
        s = int(rows[r, R_SLOT])
        prev = int(slot_obj[s]) if slot_id[s] == rows[r, R_ID] else -1
        if prev >= 0 and O[prev, O_VALID] != 0.0 and a > comp[c, 8]:
            comp[c, 7], comp[c, 8] = prev, a
    # 3. associate each group with one object. An object continues the group whose most
    # active member joined it last step, the heaviest such group if several claim it, if the
    # object's gate still holds that group. Every other group takes the nearest unclaimed
    # object whose gate holds it and whose velocity agrees, or starts a new one (a split).
    for o in range(n_objects):
        O[o, O_OWNER_W] = 0.0
    for c in range(m):
        if label[c] == c and comp[c, 7] >= 0.0:
            o = int(comp[c, 7])
            if comp[c, 4] > O[o, O_OWNER_W] and _box_meets(O, o, comp[c, 0], comp[c, 1], comp[c, 2], comp[c, 3], k):
                O[o, O_OWNER_W] = comp[c, 4]
    for c in range(m):
        comp[c, 9] = -1.0
        if label[c] != c:
            continue
        o = int(comp[c, 7])
        if o >= 0 and O[o, O_OWNER_W] == comp[c, 4] and O[o, O_MEMBERS] == 0.0:
            comp[c, 9] = o
            O[o, O_MEMBERS] = -1.0  # claimed (members are counted when they join, below)
    for c in range(m):
        if label[c] != c or comp[c, 9] >= 0.0:
            continue
        lo_x, hi_x, lo_y, hi_y = comp[c, 0], comp[c, 1], comp[c, 2], comp[c, 3]
        gvx, gvy = comp[c, 5], comp[c, 6]
        measured = comp[c, 11] != 0.0
        cx, cy = 0.5 * (lo_x + hi_x), 0.5 * (lo_y + hi_y)
        # A fragment inside an object's box (velocity agreeing) is part of it.
        best, best_d = -1, np.inf
        for o in range(n_objects):
            if O[o, O_VALID] != 0.0 and abs(cx - O[o, O_X]) <= O[o, O_RX] and abs(cy - O[o, O_Y]) <= O[o, O_RY] \
                    and (not measured or _agree(gvx, gvy, O[o, O_VX], O[o, O_VY], k)):  # fmt: skip
                d = abs(cx - O[o, O_X]) + abs(cy - O[o, O_Y])
                if d < best_d:
                    best, best_d = o, d
        if best < 0:
            for o in range(n_objects):
                if O[o, O_VALID] != 0.0 and O[o, O_MEMBERS] == 0.0 and O[o, O_OWNER_W] == 0.0 \
                        and _box_meets(O, o, lo_x, hi_x, lo_y, hi_y, k) and (not measured or _agree(gvx, gvy, O[o, O_VX], O[o, O_VY], k)):  # fmt: skip
                    d = abs(cx - O[o, O_X]) + abs(cy - O[o, O_Y])
                    if d < best_d:
                        best, best_d = o, d
        if best < 0:
            best = _create(O, OG, t, cx, cy, 0.5 * (hi_x - lo_x), 0.5 * (hi_y - lo_y), gvx, gvy, k)
        if best >= 0:
            O[best, O_MEMBERS] = -1.0
        comp[c, 9] = best
    for o in range(n_objects):
        if O[o, O_MEMBERS] < 0.0:
            O[o, O_MEMBERS] = 0.0
    for i in range(m):  # every member joins its group's object
        r = lo + i
        o = int(comp[int(label[i]), 9])
        s = int(rows[r, R_SLOT])
        if o < 0:
            OG[OG_UNASSIGNED] += 1.0
        else:
            _join(O, o, rows, r, vel[i, 0], vel[i, 1])
        slot_obj[s], slot_id[s] = o, rows[r, R_ID]
    for o in range(n_objects):  # 4. update
        if O[o, O_VALID] != 0.0 and O[o, O_MEMBERS] > 0.0:
            _update(O, o, t, dt_frames, k)
    # 5. one object inside another (its centre in the other's box, velocities agreeing) is a
    # fragment of it: the older absorbs it, and its clusters follow.
    for o in range(n_objects):
        if O[o, O_VALID] == 0.0 or O[o, O_MEMBERS] == 0.0:
            continue
        for q in range(n_objects):
            if q != o and O[q, O_VALID] != 0.0 and O[q, O_ID] < O[o, O_ID] \
                    and abs(O[o, O_X] - O[q, O_X]) <= O[q, O_RX] and abs(O[o, O_Y] - O[q, O_Y]) <= O[q, O_RY] \
                    and _agree(O[o, O_VX], O[o, O_VY], O[q, O_VX], O[q, O_VY], k):  # fmt: skip
                O[o, O_VALID] = 0.0
                OG[OG_MERGED] += 1.0
                for j in range(slot_obj.size):
                    if slot_obj[j] == o:
                        slot_obj[j] = q
                break
    for o in range(n_objects):  # 6. birth and death, records
        if O[o, O_VALID] == 0.0:
            continue
        if O[o, O_MEMBERS] > 0.0:
            if O[o, O_CONFIRMED] == 0.0 and (t - O[o, O_T_BORN]) / k.t_frame_us >= k.birth_frames:
                O[o, O_CONFIRMED] = 1.0
                OG[OG_CONFIRMED] += 1.0
        else:
            coast = k.keep_frames if O[o, O_CONFIRMED] != 0.0 else k.birth_frames
            outside = O[o, O_X] < 0.0 or O[o, O_Y] < 0.0 or O[o, O_X] > k.width - 1.0 or O[o, O_Y] > k.height - 1.0
            if (t - O[o, O_T_SEEN]) / k.t_frame_us > coast or outside:
                O[o, O_VALID] = 0.0
                OG[OG_FREED] += 1.0
                continue
        if O[o, O_CONFIRMED] == 0.0 or (t - O[o, O_T_SEEN]) / k.t_frame_us > k.coast_frames:
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
def run_steps(O, OG, slot_obj, slot_id, rows, steps, first_step, k, out, vel, label, comp):
    """Every filter step of a chunk: `steps[i]` is the time of step first_step + i, and `rows` the
    chunk's cluster records in step order. Returns the number of object records written."""
    n_out = 0
    r = 0
    for i in range(steps.size):
        step = first_step + i
        lo = r
        while r < rows.shape[0] and rows[r, R_STEP] == step:
            r += 1
        n_out = object_step(O, OG, slot_obj, slot_id, rows, lo, r, steps[i], step, k, out, n_out, vel, label, comp)
    return n_out


class FloatObjects:
    """The object layer's state and its driver: cluster records and step times in, object records out."""

    def __init__(self, params, width: int, height: int, t_frame_us: float):
        self.k = object_constants(params, width, height, t_frame_us)
        self.objects = np.zeros((params.n_objects, len(OBJECT_COLUMNS)))
        self.globals = np.zeros(len(OBJECT_GLOBAL_COLUMNS))
        self.slot_object = np.full(params.n_clusters, -1.0)
        self.slot_id = np.full(params.n_clusters, -1.0)
        self.first_step = 0
        n = params.n_clusters
        self.scratch = (np.zeros((n, 3)), np.zeros(n), np.zeros((n, 12)))  # per cluster: velocity, group, group sums

    def feed(self, rows: np.ndarray, steps: np.ndarray) -> np.ndarray:
        """Object records of the filter steps `steps` (their times), whose cluster records are `rows`."""
        out = np.empty((steps.size * self.objects.shape[0], OBJECT_RECORD_COLUMNS))
        n = run_steps(self.objects, self.globals, self.slot_object, self.slot_id, rows, np.asarray(steps, np.float64),
                      self.first_step, self.k, out, *self.scratch)  # fmt: skip
        self.first_step += steps.size
        return out[:n]

    def stats(self) -> dict:
        g = self.globals
        return {"objects_created": int(g[OG_CREATED]), "objects_confirmed": int(g[OG_CONFIRMED]),
                "objects_freed": int(g[OG_FREED]), "clusters_unassigned": int(g[OG_UNASSIGNED])}  # fmt: skip

