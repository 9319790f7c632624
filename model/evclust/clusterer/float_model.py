"""The floating-point reference clusterer: SPEC §4, event by event, compiled.

Read beside the paper: eq. (1) mean shift, written X += β(f(e) - X) with β = 1 - α; eq. (4)
regular-interval velocity; eq. (5) mean centre motion; eqs. (10)-(11) colour with background
correction; §7.2.2 palette histogram; §6.3 velocity noise filter and exit prediction.
"""

from __future__ import annotations

import math

import numpy as np

from evclust.clusterer.layout import (
    ACT, BG_ACT, BG_CB, BG_CR, BG_T, BG_Y, CCB, CCR, MERGED, UNSUPPORTED, CREATED, CY, DROPPED, EV_COUNT, EVENTS, EVER_REPORTED, EVICTED, EXITED,
    EXPIRED, T_FIRST, FLAG_BORDER, FLAG_MOVING_INT, FLAG_MOVING_MCM, FLAG_NEW, GAMMA, ID, MCM_NORM, NEXT_ID, NOISE, PPX, PPY, PX,
    PD_BG, PD_BG_CB, PD_BG_CR, PD_BG_Y, PD_CCB, PD_CCR, PD_CLASS, PD_CY, PD_LIVE, PD_NORM, PD_PX, PD_PY, PD_RX, PD_RY, PD_SLOT,
    PD_T, PD_VMX, PD_VMY, PD_VOTE, PY, REPORTED, RX, RY, SINCE_FILTER, STEP, SWEEP_DECAY, SWEEP_FORCED, SWEEP_LEFT, SWEEP_PER_FRAME,
    SWEEP_RECORDS, SWEEP_T, T_FILTER, T_LAST, VALID, VI_COUNT, VIX, VIY, VMX, VMY,
)  # fmt: skip
from evclust.jit import njit

LN2 = math.log(2.0)

# Quantisation points: the stores of the signals the formats table gives a format to. With a
# precision table (rows as below) the loop rounds each store to its format, as the fixed model
# does, so one quantisation source at a time can be measured (evclust.report.budget). Without
# one (None) numba compiles the loop without them: the reference model is untouched.
PRECISION_SIGNALS = ("centre", "half_size", "activity", "v_mcm", "mcm_norm", "v_int", "colour", "background", "gamma", "decay_table")
Q_CENTRE, Q_HALF, Q_ACT, Q_VM, Q_NORM, Q_VI, Q_COLOUR, Q_BG, Q_GAMMA, Q_DECAY = range(len(PRECISION_SIGNALS))
P_FRAC, P_LO, P_HI, P_NEAREST = range(4)  # precision columns: fraction bits (-1: exact), range, rounding
GAMMA_GLOBAL, GAMMA_ACTIVITY, GAMMA_COUNT = range(3)


@njit(cache=True, nogil=True, inline="always")
def _q(x, signal, precision):
    """x rounded to its signal's format (floor, or nearest) and saturated; x itself when the
    signal is exact or there is no precision table."""
    if precision is None or precision[signal, P_FRAC] < 0:
        return x
    scale = 2.0 ** precision[signal, P_FRAC]
    v = math.floor(x * scale + 0.5 * precision[signal, P_NEAREST]) / scale
    return min(max(v, precision[signal, P_LO]), precision[signal, P_HI])


@njit(cache=True, nogil=True, inline="always")
def _decayed(activity, dt_us, t_half_us, precision=None):
    """A · 2^(-Δt / T_half); with the decay table quantised, 2^-frac comes from its table entry."""
    if precision is None or precision[Q_DECAY, P_FRAC] < 0:
        return activity * math.exp2(-dt_us / t_half_us)
    u = dt_us / t_half_us
    whole = math.floor(u)
    return activity * math.exp2(-whole) * _q(math.exp2(-(u - whole)), Q_DECAY, precision)


@njit(cache=True, nogil=True, inline="always")
def _weight(G, t, k):
    """Activity against a reference time: an event's weight 2^((t - t_ref)/T_half). The reference
    is the background activity's time G[BG_T], which every slot shares in this mode."""
    return math.exp2((t - G[BG_T]) / k.t_half_us)


@njit(cache=True, nogil=True, inline="always")
def _q_referenced(x, precision, k):
    """Ã rounded as the activity is, and saturated reference_halvings integer bits above its top."""
    if precision is None or precision[Q_ACT, P_FRAC] < 0:
        return x
    scale = 2.0 ** precision[Q_ACT, P_FRAC]
    v = math.floor(x * scale + 0.5 * precision[Q_ACT, P_NEAREST]) / scale
    return min(max(v, precision[Q_ACT, P_LO]), precision[Q_ACT, P_HI] * 2.0**k.reference_halvings)


@njit(cache=True, nogil=True)
def _move_reference(S, G, t, k, precision):
    """Activity against a reference time: every activity (the slots' Ã and the background's) decayed
    from the reference to t, which becomes the reference (a filter step, or an event
    reference_halvings half-lives after it)."""
    dt = t - G[BG_T]
    for s in range(S.shape[0]):
        if S[s, VALID] != 0.0:
            S[s, ACT] = _q(_decayed(S[s, ACT], dt, k.t_half_us, precision), Q_ACT, precision)
    G[BG_ACT] = _q(_decayed(G[BG_ACT], dt, k.t_half_us, precision), Q_ACT, precision)
    G[BG_T] = t


@njit(cache=True, nogil=True, inline="always")
def _gamma(activity, k):
    """γ of eq. (5) from the activity: the paper's global constant, or the cluster's events per
    frame, A·ln2·T_frame/T_half (also the count mode's guess until its first full interval).
    Refreshed at filter steps only: per event, A's steps inside a burst of simultaneous events
    would correlate with where those events pull the centre and bias the estimate."""
    if k.gamma_mode == GAMMA_GLOBAL:
        return k.gamma
    return activity * LN2 * k.t_frame_us / k.t_half_us


@njit(cache=True, nogil=True)
def _nearest_palette(y, cb, cr, palette, luma_w):
    """§7.2.2: the palette entry nearest to a colour, L1 with the luminance weighted."""
    best, best_d = 0, np.inf
    for k in range(palette.shape[0]):
        d = luma_w * abs(y - palette[k, 0]) + abs(cb - palette[k, 1]) + abs(cr - palette[k, 2])
        if d < best_d:
            best, best_d = k, d
    return best


@njit(cache=True, nogil=True)
def _mixing_palette(y, cb, cr, bg_y, bg_cb, bg_cr, palette, background_mask, luma_w, tolerance):
    """§7.2.1 + §7.2.2: the nearest entry among those whose segment from the background colour
    passes within `tolerance` of the event (an edge event mixes background and object); the
    plain nearest entry when no segment does."""
    best, best_d = -1, np.inf
    uy, ucb, ucr = y - bg_y, cb - bg_cb, cr - bg_cr
    for k in range(palette.shape[0]):
        d_end = luma_w * abs(y - palette[k, 0]) + abs(cb - palette[k, 1]) + abs(cr - palette[k, 2])
        if background_mask[k]:
            d_line = d_end  # background entries stand for themselves
        else:
            wy, wcb, wcr = palette[k, 0] - bg_y, palette[k, 1] - bg_cb, palette[k, 2] - bg_cr
            ww = wy * wy + wcb * wcb + wcr * wcr
            q = 0.0 if ww == 0.0 else min(max((uy * wy + ucb * wcb + ucr * wcr) / ww, 0.0), 1.0)
            d_line = luma_w * abs(uy - q * wy) + abs(ucb - q * wcb) + abs(ucr - q * wcr)
        if d_line <= tolerance and d_end < best_d:
            best, best_d = k, d_end
    return best if best >= 0 else _nearest_palette(y, cb, cr, palette, luma_w)


@njit(cache=True, nogil=True, inline="always")
def _margin(S, s, k):
    """The seek margin of a cluster: S, grown by seek_scale·max(Rx, Ry) (beyond the paper)."""
    return k.seek_margin + k.seek_scale * max(S[s, RX], S[s, RY])


@njit(cache=True, nogil=True)
def _seek(S, x, y, k):
    """Step 1: the valid cluster whose box grown by its margin holds the event, nearest in L1;
    ties: lower slot."""
    best, best_d = -1, np.inf
    for s in range(S.shape[0]):
        if S[s, VALID] == 0.0:
            continue
        dx = abs(x - S[s, PX])
        dy = abs(y - S[s, PY])
        m = _margin(S, s, k)
        if dx <= S[s, RX] + m and dy <= S[s, RY] + m:
            d = dx + dy
            if d < best_d:
                best, best_d = s, d
    return best


@njit(cache=True, nogil=True)
def _slot_for_new(S, G, t, k, precision):
    """Step 2: a free slot; if none, the least active slot if its activity is below A_valid."""
    for s in range(S.shape[0]):
        if S[s, VALID] == 0.0:
            return s
    weakest, weakest_a = -1, np.inf
    if k.activity_reference != 0.0:
        # Every Ã has the one reference: the weakest now has the least Ã, and A < A_valid is
        # Ã < A_valid·w with the event's weight w.
        for s in range(S.shape[0]):
            if S[s, ACT] < weakest_a:
                weakest, weakest_a = s, S[s, ACT]
        limit = k.a_valid * _weight(G, t, k)
    else:
        for s in range(S.shape[0]):
            a = _q(_decayed(S[s, ACT], t - S[s, T_LAST], k.t_half_us, precision), Q_ACT, precision)
            if a < weakest_a:
                weakest, weakest_a = s, a
        limit = k.a_valid
    if weakest_a < limit:
        G[EVICTED] += 1
        return weakest
    return -1


@njit(cache=True, nogil=True)
def _create(S, H, G, s, t, x, y, lum, cb, cr, k, precision):
    S[s, :] = 0.0
    S[s, VALID] = 1.0
    S[s, ID] = G[NEXT_ID]
    G[NEXT_ID] += 1
    S[s, PX], S[s, PY] = x, y
    S[s, PPX], S[s, PPY] = x, y
    S[s, RX], S[s, RY] = k.r_init, k.r_init
    S[s, ACT] = _q_referenced(_weight(G, t, k), precision, k) if k.activity_reference != 0.0 else 1.0
    S[s, GAMMA] = _q(_gamma(1.0, k), Q_GAMMA, precision)
    S[s, T_LAST] = t
    S[s, CY], S[s, CCB], S[s, CCR] = lum, cb, cr
    H[s, :] = 0
    G[CREATED] += 1


@njit(cache=True, nogil=True, inline="always")  # the per-event loop's: no call
def _increments(S, G, s, t, x, y, lum, cb, cr, k, palette, background_mask, precision, row):
    """Step 3, read half: the mean-shift update of the chosen cluster as increments computed from
    the state the event reads (the table D events ago in a pipelined core), into `row`."""
    row[PD_LIVE], row[PD_SLOT], row[PD_T] = 1.0, s, t
    px, py = S[s, PX], S[s, PY]
    # Eq. (1) on the centre: P_new = P + β_P (e - P).
    row[PD_PX] = k.beta_pos * (x - px)
    row[PD_PY] = k.beta_pos * (y - py)
    # Size: R += β_R (g_R |e - P| - R), clamped when committed.
    row[PD_RX] = k.beta_size * (k.size_gain * abs(x - px) - S[s, RX])
    row[PD_RY] = k.beta_size * (k.size_gain * abs(y - py) - S[s, RY])
    # Eq. (5), MCM: V += β_vm (γ (P_new - P) - V).
    gamma = S[s, GAMMA]
    px_new, py_new = _q(px + row[PD_PX], Q_CENTRE, precision), _q(py + row[PD_PY], Q_CENTRE, precision)
    row[PD_VMX] = k.beta_vel_mcm * (gamma * (px_new - px) - S[s, VMX])
    row[PD_VMY] = k.beta_vel_mcm * (gamma * (py_new - py) - S[s, VMY])
    # The same filter on a constant 1 gives 1 - α^n: the weight V has gathered since V = 0.
    row[PD_NORM] = k.beta_vel_mcm * (1.0 - S[s, MCM_NORM])
    if k.has_colour != 0.0:
        # Eq. (10): colour mean shift, luminance and chrominance with their own β.
        row[PD_CY] = k.beta_lum * (lum - S[s, CY])
        row[PD_CCB] = k.beta_chro * (cb - S[s, CCB])
        row[PD_CCR] = k.beta_chro * (cr - S[s, CCR])
        # §7.2.2: the event's palette class and vote.
        if k.mixing != 0.0:
            row[PD_CLASS] = _mixing_palette(
                lum, cb, cr, G[BG_Y], G[BG_CB], G[BG_CR], palette, background_mask, k.luma_weight, k.mixing_tolerance
            )
        else:
            row[PD_CLASS] = _nearest_palette(lum, cb, cr, palette, k.luma_weight)
        row[PD_VOTE] = 1.0
        if k.vote_contrast != 0.0:
            row[PD_VOTE] = int(abs(lum - G[BG_Y]) + abs(cb - G[BG_CB]) + abs(cr - G[BG_CR]) + 0.5)


@njit(cache=True, nogil=True, inline="always")  # the per-event loop's: no call
def _commit(S, H, G, row, k, precision):
    """Step 3, write half: an event's increments added to the slot as it is now (in a pipelined
    core, other events' commits may have landed since the event read it); with no delay, the
    paper's update exactly. Then the event's background-colour update (step 4)."""
    if row[PD_LIVE] != 0.0:
        s, t = int(row[PD_SLOT]), row[PD_T]
        if k.activity_reference != 0.0:  # an addition: the event's weight
            S[s, ACT] = _q_referenced(S[s, ACT] + _weight(G, t, k), precision, k)
        else:  # decayed from the slot's own time, plus one
            dt = t - S[s, T_LAST]
            if k.sweep_slots_per_event != 0.0:  # a sweep beside the events may have set a later time: no decay back
                dt = max(dt, 0.0)
            a = _q(_decayed(S[s, ACT], dt, k.t_half_us, precision), Q_ACT, precision) + 1.0
            S[s, ACT] = _q(a, Q_ACT, precision)
        S[s, RX] = min(max(_q(S[s, RX] + row[PD_RX], Q_HALF, precision), k.r_min), k.r_max)
        S[s, RY] = min(max(_q(S[s, RY] + row[PD_RY], Q_HALF, precision), k.r_min), k.r_max)
        S[s, VMX] = _q(S[s, VMX] + row[PD_VMX], Q_VM, precision)
        S[s, VMY] = _q(S[s, VMY] + row[PD_VMY], Q_VM, precision)
        S[s, MCM_NORM] = _q(min(S[s, MCM_NORM] + row[PD_NORM], 1.0), Q_NORM, precision)  # (a weight: at most 1)
        S[s, PX] = _q(S[s, PX] + row[PD_PX], Q_CENTRE, precision)
        S[s, PY] = _q(S[s, PY] + row[PD_PY], Q_CENTRE, precision)
        if k.has_colour != 0.0:
            S[s, CY] = _q(S[s, CY] + row[PD_CY], Q_COLOUR, precision)
            S[s, CCB] = _q(S[s, CCB] + row[PD_CCB], Q_COLOUR, precision)
            S[s, CCR] = _q(S[s, CCR] + row[PD_CCR], Q_COLOUR, precision)
            # Count the event's class; halve all counters when one saturates.
            c, h_max = int(row[PD_CLASS]), np.int64(k.hist_max)
            H[s, c] = min(H[s, c] + np.int64(row[PD_VOTE]), h_max)
            if H[s, c] >= h_max:
                for j in range(H.shape[1]):
                    H[s, j] >>= 1
        S[s, EV_COUNT] += 1.0
        S[s, T_LAST] = max(S[s, T_LAST], t) if k.sweep_slots_per_event != 0.0 else t
        row[PD_LIVE] = 0.0
    if row[PD_BG] != 0.0:
        G[BG_Y] = _q(G[BG_Y] + row[PD_BG_Y], Q_BG, precision)
        G[BG_CB] = _q(G[BG_CB] + row[PD_BG_CB], Q_BG, precision)
        G[BG_CR] = _q(G[BG_CR] + row[PD_BG_CR], Q_BG, precision)
        row[PD_BG] = 0.0


@njit(cache=True, nogil=True)
def _drain(S, H, G, line, k, precision):
    """Commit every event still in the delay line, oldest first (before a filter step)."""
    n = line.shape[0]
    for m in range(n):
        _commit(S, H, G, line[(int(G[EVENTS]) + 1 + m) % n], k, precision)


@njit(cache=True, nogil=True, inline="always")
def _cancel(line, s):
    """A slot taken by a new cluster: the updates still in flight for its old cluster are void."""
    for r in range(line.shape[0]):
        if line[r, PD_LIVE] != 0.0 and line[r, PD_SLOT] == s:
            line[r, PD_LIVE] = 0.0


@njit(cache=True, nogil=True, inline="always")
def _near_border(px, py, k):
    m = k.exit_margin
    return px < m or px > k.width - 1.0 - m or py < m or py > k.height - 1.0 - m


@njit(cache=True, nogil=True, inline="always")
def _mcm_velocity(S, s, k):
    """V_MCM as reported: optionally divided by 1 - α^n, which removes the pull of V's zero start."""
    if k.mcm_correct != 0.0 and S[s, MCM_NORM] > 0.0:
        return S[s, VMX] / S[s, MCM_NORM], S[s, VMY] / S[s, MCM_NORM]
    return S[s, VMX], S[s, VMY]


@njit(cache=True, nogil=True)
def _exiting(S, s, k):
    """§6.3, Fig. 8: near a border, fast enough, heading out within θ_exit of the border normal."""
    px, py = S[s, PX], S[s, PY]
    vx, vy = _mcm_velocity(S, s, k)
    speed = math.hypot(vx, vy)
    if speed < k.v_exit or speed == 0.0:
        return False
    m = k.exit_margin
    limit = speed * k.cos_exit
    # Outward normals: left (-1, 0), right (1, 0), top (0, -1), bottom (0, 1); y grows downwards.
    return (
        (px < m and -vx >= limit)
        or (px > k.width - 1.0 - m and vx >= limit)
        or (py < m and -vy >= limit)
        or (py > k.height - 1.0 - m and vy >= limit)
    )


@njit(cache=True, nogil=True)
def _mergeable(S, s, j, k):
    """Two clusters are one object's when their boxes overlap and their velocities do not
    disagree (a young cluster has none yet), or when their boxes grown by merge_scale times
    their larger half-sizes overlap and both have measured velocities that agree."""
    dx, dy = abs(S[s, PX] - S[j, PX]), abs(S[s, PY] - S[j, PY])
    sx, sy = S[s, RX] + S[j, RX], S[s, RY] + S[j, RY]
    grow = k.merge_scale * (max(S[s, RX], S[s, RY]) + max(S[j, RX], S[j, RY]))
    if dx > sx + grow or dy > sy + grow:
        return False
    measured = S[s, VI_COUNT] >= 2.0 and S[j, VI_COUNT] >= 2.0
    if measured:
        dv = abs(S[s, VIX] - S[j, VIX]) + abs(S[s, VIY] - S[j, VIY])
        fast = max(abs(S[s, VIX]) + abs(S[s, VIY]), abs(S[j, VIX]) + abs(S[j, VIY]))
        return dv <= k.merge_v_tol + k.merge_v_rel * fast
    return dx <= sx and dy <= sy


@njit(cache=True, nogil=True)
def _merge(S, H, G, s, j, k, precision):
    """Slot s absorbs slot j: the centre is the activity-weighted mean (where the two clusters'
    events average), the box covers both boxes, activities and event counts add; identity,
    velocities, colour and histogram are the survivor's (the one reported before, else the more
    active). The previous centre moves with the centre: the jump is not motion."""
    survivor = (
        j if (S[j, EVER_REPORTED] > S[s, EVER_REPORTED]) or (S[j, EVER_REPORTED] == S[s, EVER_REPORTED] and S[j, ACT] > S[s, ACT]) else s
    )
    a_s, a_j = S[s, ACT], S[j, ACT]
    px = _q((a_s * S[s, PX] + a_j * S[j, PX]) / (a_s + a_j), Q_CENTRE, precision)
    py = _q((a_s * S[s, PY] + a_j * S[j, PY]) / (a_s + a_j), Q_CENTRE, precision)
    lo_x, hi_x = min(S[s, PX] - S[s, RX], S[j, PX] - S[j, RX]), max(S[s, PX] + S[s, RX], S[j, PX] + S[j, RX])
    lo_y, hi_y = min(S[s, PY] - S[s, RY], S[j, PY] - S[j, RY]), max(S[s, PY] + S[s, RY], S[j, PY] + S[j, RY])
    # (kept inside the sensor: a young cluster's previous centre may not move out of the view)
    ppx = min(max(S[survivor, PPX] + (px - S[survivor, PX]), 0.0), k.width - 1.0)
    ppy = min(max(S[survivor, PPY] + (py - S[survivor, PY]), 0.0), k.height - 1.0)
    act = _q(a_s + a_j, Q_ACT, precision)
    count = S[s, EV_COUNT] + S[j, EV_COUNT]
    if survivor == j:
        t_last = S[s, T_LAST]
        S[s, :] = S[j, :]
        H[s, :] = H[j, :]
        S[s, T_LAST] = t_last
    S[s, PX], S[s, PY], S[s, PPX], S[s, PPY] = px, py, ppx, ppy
    S[s, RX] = min(_q((hi_x - lo_x) / 2, Q_HALF, precision), k.r_max)
    S[s, RY] = min(_q((hi_y - lo_y) / 2, Q_HALF, precision), k.r_max)
    S[s, ACT], S[s, EV_COUNT] = act, count
    S[j, VALID] = 0.0
    G[MERGED] += 1


@njit(cache=True, nogil=True)
def _step_open(S, G, t, k, precision):
    """A filter step every N_f events, at t: its τ boundaries and the activities' time; the sweep
    of its slots is then to come (all at once, or beside the events: _sweep_slot)."""
    # τ boundaries crossed since the last step: usually 0 or 1, more when events are sparse.
    boundaries = math.floor((t - G[T_FIRST]) / k.tau_us) - math.floor((G[T_FILTER] - G[T_FIRST]) / k.tau_us)
    G[SWEEP_PER_FRAME] = k.t_frame_us / (boundaries * k.tau_us) if boundaries > 0 else -1.0  # T_frame over the time measured
    G[SWEEP_T] = t
    G[T_FILTER] = t
    G[SWEEP_DECAY] = 1.0
    if k.activity_reference != 0.0:
        if k.sweep_slots_per_event == 0.0:
            _move_reference(S, G, t, k, precision)  # every activity decayed to t at once
        else:  # the reference stays: the sweep reads each A as Ã times the step's one decay
            G[SWEEP_DECAY] = math.exp2(-(t - G[BG_T]) / k.t_half_us)
    else:
        G[BG_ACT] = _q(_decayed(G[BG_ACT], t - G[BG_T], k.t_half_us, precision), Q_ACT, precision)
        G[BG_T] = t
    G[SWEEP_LEFT] = S.shape[0]
    G[SWEEP_RECORDS] = 0


@njit(cache=True, nogil=True, inline="always")
def _step_activity(a, G, k, precision):
    """The activity the sweep decides on: as stored, or beside the events against a reference
    time A = Ã·2^-((t - t_ref)/T_half), the step's one decay (not stored)."""
    if k.activity_reference == 0.0 or k.sweep_slots_per_event == 0.0:
        return a
    return _q(a * G[SWEEP_DECAY], Q_ACT, precision)


@njit(cache=True, nogil=True)
def _sweep_slot(S, H, G, s, k, palette, background_mask, line, held, precision):
    """The open step on slot s: decay, free, merge, interval velocity, noise and exit decisions,
    and its record into `held` (the step's records until it closes). A slot the sweep frees
    voids the updates still in flight for it."""
    if S[s, VALID] == 0.0:
        return
    t = G[SWEEP_T]
    per_frame = G[SWEEP_PER_FRAME]
    v_min = k.v_min
    if k.activity_reference != 0.0:
        S[s, T_LAST] = t
    elif S[s, T_LAST] < t or k.sweep_slots_per_event == 0.0:  # (beside the events: no older than t)
        S[s, ACT] = _q(_decayed(S[s, ACT], t - S[s, T_LAST], k.t_half_us, precision), Q_ACT, precision)
        S[s, T_LAST] = t
    act = _step_activity(S[s, ACT], G, k, precision)
    if act < k.a_min:
        S[s, VALID] = 0.0
        _cancel(line, s)
        G[EXPIRED] += 1
        return
    if k.merge != 0.0:  # absorb every later slot that is the same object, lowest first
        j = s + 1
        while j < S.shape[0]:
            if S[j, VALID] != 0.0 and _mergeable(S, s, j, k):
                _merge(S, H, G, s, j, k, precision)
                _cancel(line, j)
                act = _step_activity(S[s, ACT], G, k, precision)
                j = s  # the merged box may now reach a slot passed over
            j += 1
    if k.gamma_mode != GAMMA_COUNT or S[s, VI_COUNT] == 0.0:
        S[s, GAMMA] = _q(_gamma(act, k), Q_GAMMA, precision)
    if per_frame >= 0.0:  # a τ boundary since the last step: an interval is due
        if k.gamma_mode == GAMMA_COUNT and S[s, VI_COUNT] >= 1.0:
            S[s, GAMMA] = _q(S[s, EV_COUNT] * per_frame, Q_GAMMA, precision)  # events per frame since the last boundary
        S[s, EV_COUNT] = 0.0
        # Eq. (4): V_RI += β_vi ((P - P_prev) · T_frame / τ - V_RI); P_prev = P.
        mx = _q((S[s, PX] - S[s, PPX]) * per_frame, Q_VI, precision)
        my = _q((S[s, PY] - S[s, PPY]) * per_frame, Q_VI, precision)
        n = S[s, VI_COUNT]  # full intervals measured before this one, plus one
        if k.warm_start == 0.0 or n >= k.interval_warmup:
            S[s, VIX] = _q(S[s, VIX] + k.beta_vel_int * (mx - S[s, VIX]), Q_VI, precision)
            S[s, VIY] = _q(S[s, VIY] + k.beta_vel_int * (my - S[s, VIY]), Q_VI, precision)
        elif n == 1.0:  # the first full interval: take it as it is
            S[s, VIX], S[s, VIY] = mx, my
        elif n >= 2.0:  # the running mean of the first measurements, until 1/n falls to β
            S[s, VIX] = _q(S[s, VIX] + (mx - S[s, VIX]) / n, Q_VI, precision)
            S[s, VIY] = _q(S[s, VIY] + (my - S[s, VIY]) / n, Q_VI, precision)
        # (VI_COUNT 0: the cluster was born inside this interval; its displacement is partial.)
        S[s, VI_COUNT] = min(n + 1.0, max(k.interval_warmup, 2.0))
        S[s, PPX], S[s, PPY] = S[s, PX], S[s, PY]
    if _exiting(S, s, k):
        S[s, VALID] = 0.0
        _cancel(line, s)
        G[EXITED] += 1
        return
    # The noise decision weighs evidence: the uncorrected V is small until many events agree.
    moving_mcm = math.hypot(S[s, VMX], S[s, VMY]) >= v_min
    vmx, vmy = _mcm_velocity(S, s, k)
    moving_int = math.hypot(S[s, VIX], S[s, VIY]) >= v_min
    reported = act >= k.a_valid and (moving_mcm or moving_int)
    if reported and k.noise_gate > 0.0:
        # Beyond the paper: the background's events spread over the sensor would give the
        # box A_bg·(box area / sensor area); an object's cluster holds noise_gate times more.
        box = (2.0 * math.floor(S[s, RX]) + 1.0) * (2.0 * math.floor(S[s, RY]) + 1.0)  # its pixels
        reported = act * k.width * k.height >= k.noise_gate * _step_activity(G[BG_ACT], G, k, precision) * box
    if act >= k.a_valid and not reported:
        G[NOISE] += 1
    S[s, REPORTED] = 1.0 if reported else 0.0
    if not reported:
        return
    row = held[int(G[SWEEP_RECORDS])]
    row[0], row[1], row[2], row[3] = t, G[STEP], s, S[s, ID]
    row[4], row[5], row[6], row[7], row[8] = S[s, PX], S[s, PY], S[s, RX], S[s, RY], act
    row[9], row[10], row[11], row[12] = vmx, vmy, S[s, VIX], S[s, VIY]
    cls = -1
    row[13], row[14], row[15] = 0.0, 0.0, 0.0  # no colour without TFS data
    if k.has_colour != 0.0:
        # Eq. (11): C_obj = (C - BG) / p + BG, clamped to the byte range.
        row[13] = min(max((S[s, CY] - G[BG_Y]) / k.p_correction + G[BG_Y], 0.0), 255.0)
        row[14] = min(max((S[s, CCB] - G[BG_CB]) / k.p_correction + G[BG_CB], 0.0), 255.0)
        row[15] = min(max((S[s, CCR] - G[BG_CR]) / k.p_correction + G[BG_CR], 0.0), 255.0)
        best = 0
        for j in range(H.shape[1]):
            if not background_mask[j] and H[s, j] > best:
                best, cls = H[s, j], j
    row[16] = cls
    flags = 0
    if S[s, EVER_REPORTED] == 0.0:
        flags |= FLAG_NEW
    if _near_border(S[s, PX], S[s, PY], k):
        flags |= FLAG_BORDER
    if moving_mcm:
        flags |= FLAG_MOVING_MCM
    if moving_int:
        flags |= FLAG_MOVING_INT
    row[17] = flags
    S[s, EVER_REPORTED] = 1.0
    G[SWEEP_RECORDS] += 1


@njit(cache=True, nogil=True)
def _sweep(S, H, G, slots, k, palette, background_mask, line, held, out, n_out, steps, first_step, precision):
    """The open step's next `slots` slots, in slot order; when the last is swept the step closes:
    its records go to `out` and its time to `steps`. Returns the records in `out`."""
    n = S.shape[0]
    while G[SWEEP_LEFT] > 0 and slots > 0:
        _sweep_slot(S, H, G, int(n - G[SWEEP_LEFT]), k, palette, background_mask, line, held, precision)
        G[SWEEP_LEFT] -= 1
        slots -= 1
        if G[SWEEP_LEFT] == 0:  # the step closes
            for r in range(int(G[SWEEP_RECORDS])):
                out[n_out] = held[r]
                n_out += 1
            steps[int(G[STEP] - first_step)] = G[SWEEP_T]
            G[STEP] += 1
    return n_out


@njit(cache=True, nogil=True, inline="always")
def _supported(support, cx, cy, t, window):
    """Beyond the paper: some event of the 3x3 cells around (cx, cy) (map coordinates, border
    included) is at most `window` µs old."""
    for dy in range(-1, 2):
        for dx in range(-1, 2):
            if t - support[cy + dy, cx + dx] <= window:
                return True
    return False


@njit(cache=True, nogil=True)
def run_events(S, H, G, k, palette, background_mask, support, line, held, t_us, xs, ys, lums, cbs, crs, out, steps, precision=None):
    """Feed events through the table; write track records into `out`; return how many. Each
    filter step's time goes into `steps` as it closes, in order (the object layer's clock; G[STEP]
    counts them). With a `precision` table (PRECISION_SIGNALS x 4) each quantisation point rounds to
    its format. `support` is the creation-support map (layout.support_shape), each cell the time
    of its latest event (-inf: none). `line` is the update delay line (D + 1 rows of
    layout.PENDING_COLUMNS): event n reads the table with the updates of events up to n - D - 1
    committed (creations at once). `held` (N x RECORD_COLUMNS) holds the open step's records
    until it closes. With sweep_slots_per_event = 0 every filter step first commits all and
    sweeps every slot before the next event; with R >= 1 the sweep runs beside the events, R
    slots before each event, each after that event's turn to commit; a step (or a move of the
    reference) that comes while a sweep is still open first finishes it at once (G[SWEEP_FORCED])."""
    bits = int(k.support_cell_bits)
    delay = line.shape[0] - 1
    n_out = 0
    first_step = G[STEP]
    every = int(k.filter_every)
    beside = int(k.sweep_slots_per_event)
    n = S.shape[0]
    for i in range(t_us.size):
        t = float(t_us[i])
        x, y = float(xs[i]), float(ys[i])
        lum, cb, cr = float(lums[i]), float(cbs[i]), float(crs[i])
        if G[EVENTS] == 0:
            G[T_FILTER] = t  # the filter-step clock and the τ boundaries start at the first event
            G[T_FIRST] = t
            if k.activity_reference != 0.0:  # so does the activity's reference
                G[BG_T] = t
        if k.activity_reference != 0.0 and t - G[BG_T] > k.reference_halvings * k.t_half_us:
            # Ã would outgrow its headroom: commit what is in flight and move the reference to t.
            if G[SWEEP_LEFT] > 0:
                G[SWEEP_FORCED] += 1
                n_out = _sweep(S, H, G, n, k, palette, background_mask, line, held, out, n_out, steps, first_step, precision)
            _drain(S, H, G, line, k, precision)
            _move_reference(S, G, t, k, precision)
        G[EVENTS] += 1
        row = line[int(G[EVENTS]) % (delay + 1)]  # it holds event n - D - 1: its turn to commit
        if delay > 0:
            _commit(S, H, G, row, k, precision)
        if G[SWEEP_LEFT] > 0:  # the open step's sweep, beside the events
            n_out = _sweep(S, H, G, beside, k, palette, background_mask, line, held, out, n_out, steps, first_step, precision)
        s = _seek(S, x, y, k)
        updated_reported = False
        cx, cy = (int(xs[i]) >> bits) + 1, (int(ys[i]) >> bits) + 1
        if s < 0:
            if k.create_support != 0.0 and not _supported(support, cx, cy, t, k.support_window_us):
                G[UNSUPPORTED] += 1
            else:
                s = _slot_for_new(S, G, t, k, precision)
                if s >= 0:
                    _cancel(line, s)
                    _create(S, H, G, s, t, x, y, lum, cb, cr, k, precision)
                else:
                    G[DROPPED] += 1
        else:
            _increments(S, G, s, t, x, y, lum, cb, cr, k, palette, background_mask, precision, row)
            updated_reported = S[s, REPORTED] != 0.0
        if k.create_support != 0.0:
            support[cy, cx] = t
        # Step 4: events that do not update a reported cluster track the background colour.
        if not updated_reported and k.noise_gate > 0.0:  # the activity of the events no reported cluster takes
            if k.activity_reference != 0.0:
                G[BG_ACT] = _q_referenced(G[BG_ACT] + _weight(G, t, k), precision, k)
            else:
                G[BG_ACT] = _q(_decayed(G[BG_ACT], t - G[BG_T], k.t_half_us, precision), Q_ACT, precision) + 1.0
                G[BG_T] = t
        if k.has_colour != 0.0 and k.background_fixed == 0.0 and not updated_reported:
            row[PD_BG] = 1.0
            row[PD_BG_Y] = k.beta_bg * (lum - G[BG_Y])
            row[PD_BG_CB] = k.beta_bg * (cb - G[BG_CB])
            row[PD_BG_CR] = k.beta_bg * (cr - G[BG_CR])
        if delay == 0:
            _commit(S, H, G, row, k, precision)
        G[SINCE_FILTER] += 1
        if G[SINCE_FILTER] >= every:
            G[SINCE_FILTER] = 0
            if G[SWEEP_LEFT] > 0:  # the last step's sweep is not done: it finishes first
                G[SWEEP_FORCED] += 1
                n_out = _sweep(S, H, G, n, k, palette, background_mask, line, held, out, n_out, steps, first_step, precision)
            if beside == 0:
                _drain(S, H, G, line, k, precision)
            _step_open(S, G, t, k, precision)
            if beside == 0:
                n_out = _sweep(S, H, G, n, k, palette, background_mask, line, held, out, n_out, steps, first_step, precision)
    return n_out
