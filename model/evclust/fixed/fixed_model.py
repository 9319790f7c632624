"""The bit-accurate fixed-point clusterer: SPEC §4 in integer arithmetic, one operation per line,
each result in its format of the formats table (docs/FIXED_POINT.md is the datapath, step by step).

Raw int64 values throughout; floor rounding (an arithmetic shift) wherever bits are dropped;
every store saturates to its format and counts it in the overflow log, except the 32-bit time,
which wraps by design. The state layout is the float model's (clusterer/layout.py).
"""

from __future__ import annotations

import numpy as np

from evclust.clusterer.layout import (
    ACT, BG_ACT, BG_CB, BG_CR, BG_RESIDUAL, BG_T, BG_Y, CCB, CCR, CREATED, CY, DROPPED, EV_COUNT, EVENTS, EVER_REPORTED, EVICTED,
    MERGED, UNSUPPORTED,
    DECAY_RESIDUAL, EXITED, EXPIRED, GLOBAL_COLUMNS, T_FIRST, FLAG_BORDER, FLAG_MOVING_INT, FLAG_MOVING_MCM, FLAG_NEW, GAMMA, ID, MCM_NORM,
    NEXT_ID, NOISE, PD_BG, PD_BG_CB, PD_BG_CR, PD_BG_Y, PD_CCB, PD_CCR, PD_CLASS, PD_CY, PD_LIVE, PD_NORM, PD_PX, PD_PY, PD_RX,
    PD_RY, PD_SLOT, PD_T, PD_VMX, PD_VMY, PD_VOTE, PPX, PPY, PX, PY, REPORTED, RX, RY, SINCE_FILTER, STEP, SWEEP_DECAY,
    SWEEP_FORCED, SWEEP_LEFT, SWEEP_PER_FRAME, SWEEP_RECORDS, SWEEP_T, T_FILTER, T_LAST, VALID, VI_COUNT, VIX, VIY, VMX, VMY,
)  # fmt: skip
from evclust.fixed.arith import FLOOR, NEAREST, alpha_increment_nb, alpha_step_nb, decay_apply_nb, decay_nb, decay_steps_nb
from evclust.fixed.formats import DECAY_FRAC_BITS, DECAY_TABLE_BITS
from evclust.fixed.layouts import TRACE_ACTIONS
from evclust.jit import njit

TIME_MASK = (1 << 32) - 1
# Globals beyond the float model's: the τ phase (µs since the last boundary).
TAU_PHASE = len(GLOBAL_COLUMNS)
N_GLOBALS = TAU_PHASE + 1

# Signals of the overflow log and the range instrumentation.
SIGNALS = (
    "centre", "half_size", "activity", "v_mcm", "mcm_norm", "v_int", "colour", "background", "gamma",
    "events_in_interval", "hist", "centre_step", "speed_sq", "mcm_step", "size_target",
)  # fmt: skip
(
    S_CENTRE, S_HALF, S_ACT, S_VM, S_NORM, S_VI, S_COLOUR, S_BG, S_GAMMA, S_EVCOUNT, S_HIST, S_STEP,
    S_SPEED, S_MCM_IN, S_SIZE_TARGET,
) = range(len(SIGNALS))  # fmt: skip


@njit(cache=True, nogil=True)
def _store(value, lo, hi, signal, log, ranges):
    """Saturate to [lo, hi] and count a saturation; with range instrumentation on (`ranges` a row
    per signal), also keep the value's range before saturation. None compiles a loop without
    instrumentation (the fast one: an array the loop may write keeps the compiler from holding
    state in registers; it ran 2.1 times slower). An array with no rows is instrumentation off in
    the instrumented loop, which traced runs share: one compilation (a minute and a half) less."""
    if ranges is not None and ranges.shape[0] != 0:
        if value < ranges[signal, 0]:
            ranges[signal, 0] = value
        if value > ranges[signal, 1]:
            ranges[signal, 1] = value
    if value < lo:
        log[signal] += 1
        return lo
    if value > hi:
        log[signal] += 1
        return hi
    return value


@njit(cache=True, nogil=True)
def _seen(value, signal, ranges):
    """Range instrumentation of a value that cannot leave its format (an α filter's result lies
    between its state and its input, both in range): no saturation logic, just min/max."""
    if ranges is not None and ranges.shape[0] != 0:
        if value < ranges[signal, 0]:
            ranges[signal, 0] = value
        if value > ranges[signal, 1]:
            ranges[signal, 1] = value
    return value


@njit(cache=True, nogil=True)
def _align(raw, from_frac, to_frac):
    """Change the fraction bits of a raw value (floor when dropping)."""
    if to_frac >= from_frac:
        return raw << (to_frac - from_frac)
    return raw >> (from_frac - to_frac)


@njit(cache=True, nogil=True, inline="always")
def _later(a, b):
    """a is later than b on the wrapping 32-bit clock (within half its period: beside the events,
    with the paper's activity, a slot's events more than 2^31 µs apart are taken out of order)."""
    d = (a - b) & TIME_MASK
    return d != 0 and d < (np.int64(1) << 31)


@njit(cache=True, nogil=True)
def _decayed(a, dt, k, table):
    """For comparisons only (eviction): the activity decayed to now, the slot left unchanged."""
    return decay_nb(a, dt, k.inv_t_half, k.inv_t_half_frac, table, DECAY_TABLE_BITS, DECAY_FRAC_BITS, FLOOR)


@njit(cache=True, nogil=True, inline="always")
def _decay_slot(S, s, t, k, table):
    """Decay the slot's activity to t, carrying the residual; t becomes its reference time."""
    m, S[s, DECAY_RESIDUAL] = decay_steps_nb(
        (t - S[s, T_LAST]) & TIME_MASK, S[s, DECAY_RESIDUAL], k.inv_t_half, k.inv_t_half_frac, DECAY_TABLE_BITS
    )
    S[s, ACT] = decay_apply_nb(S[s, ACT], m, table, DECAY_TABLE_BITS, DECAY_FRAC_BITS, FLOOR)
    S[s, T_LAST] = t


@njit(cache=True, nogil=True, inline="always")
def _decay_background(G, t, k, table):
    """The background's activity decayed to t, as a slot's (its residual carried)."""
    m, G[BG_RESIDUAL] = decay_steps_nb((t - G[BG_T]) & TIME_MASK, G[BG_RESIDUAL], k.inv_t_half, k.inv_t_half_frac, DECAY_TABLE_BITS)
    G[BG_ACT] = decay_apply_nb(G[BG_ACT], m, table, DECAY_TABLE_BITS, DECAY_FRAC_BITS, FLOOR)
    G[BG_T] = t


@njit(cache=True, nogil=True)
def _reference_span(G, t, k):
    """Activity against a reference time: Δt/T_half from the reference to t, the reference's residual
    included, unfloored (in 1/T_half's fraction bits). The reference is the background activity's
    time G[BG_T], which every slot shares in this mode."""
    return ((t - G[BG_T]) & TIME_MASK) * k.inv_t_half + G[BG_RESIDUAL]


@njit(cache=True, nogil=True)
def _reference_passed(G, t, k):
    """More than reference_halvings half-lives since the reference: Ã would outgrow its headroom."""
    return _reference_span(G, t, k) > (k.reference_halvings << k.inv_t_half_frac)


@njit(cache=True, nogil=True, inline="always")
def _weight(G, t, k, table):
    """An event's weight 2^(m/64) in the activity's format, m its steps since the reference (at most
    reference_halvings·64): 2^reference_halvings decayed by the steps left to that top, so the
    decay's own table and shift make it. Exactly 1 at the reference, 2^reference_halvings at the top."""
    top = k.reference_halvings << DECAY_TABLE_BITS
    highest = (np.int64(1) << k.activity_frac) << k.reference_halvings
    m = _reference_span(G, t, k) >> (k.inv_t_half_frac - DECAY_TABLE_BITS)  # whole table steps
    return decay_apply_nb(highest, top - m, table, DECAY_TABLE_BITS, DECAY_FRAC_BITS, FLOOR)


@njit(cache=True, nogil=True)
def _move_reference(S, G, t, k, table, log, ranges):
    """Every activity (the slots' Ã and the background's) decayed from the reference to t by the
    same steps (one multiply by inv_t_half, one residual) and saturated to the activity's format; t
    becomes the reference. At a filter step, or first at an event reference_halvings half-lives on."""
    m, G[BG_RESIDUAL] = decay_steps_nb((t - G[BG_T]) & TIME_MASK, G[BG_RESIDUAL], k.inv_t_half, k.inv_t_half_frac, DECAY_TABLE_BITS)
    for s in range(S.shape[0]):
        if S[s, VALID] != 0:
            a = decay_apply_nb(S[s, ACT], m, table, DECAY_TABLE_BITS, DECAY_FRAC_BITS, FLOOR)
            S[s, ACT] = _store(a, 0, k.activity_max, S_ACT, log, ranges)
    a = decay_apply_nb(G[BG_ACT], m, table, DECAY_TABLE_BITS, DECAY_FRAC_BITS, FLOOR)
    G[BG_ACT] = _store(a, 0, k.activity_max, S_ACT, log, ranges)
    G[BG_T] = t


@njit(cache=True, nogil=True)
def _gamma_from_activity(a, k):
    if k.gamma_mode == 0:
        return k.gamma_global
    return (a * k.gamma_per_activity) >> (
        k.activity_frac + k.gamma_per_activity_frac - k.gamma_frac
    )  # A · ln2·T_frame/T_half, in γ's format


@njit(cache=True, nogil=True)
def _margin(S, s, k):
    """The seek margin in P's format: S + seek_scale·max(Rx, Ry), the product floored."""
    return k.seek_margin + _align(k.seek_scale * max(S[s, RX], S[s, RY]), k.scale_frac + k.half_size_frac, k.centre_frac)


@njit(cache=True, nogil=True)
def _seek(S, x, y, k):
    """Step 1: the candidate nearest in L1; ties go to the lower slot. R is brought to P's
    fraction bits with one fixed shift (hoisted out of the loop)."""
    best, best_d = -1, np.int64(1) << 62
    up = k.centre_frac - k.half_size_frac  # the formats table gives the centre at least R's fraction bits
    for s in range(S.shape[0]):
        if S[s, VALID] == 0:
            continue
        dx = abs(x - S[s, PX])
        dy = abs(y - S[s, PY])
        m = _margin(S, s, k)
        if dx <= (S[s, RX] << up) + m and dy <= (S[s, RY] << up) + m:
            d = dx + dy
            if d < best_d:
                best, best_d = s, d
    return best


@njit(cache=True, nogil=True)
def _nearest_palette(ey, ecb, ecr, palette, k):
    """Integer L1 with the luminance weighted; distances in units of 2^-F_w."""
    best, best_d = 0, np.int64(1) << 62
    fw = k.luma_weight_frac
    for j in range(palette.shape[0]):
        d = k.luma_weight * abs(ey - palette[j, 0]) + ((abs(ecb - palette[j, 1]) + abs(ecr - palette[j, 2])) << fw)
        if d < best_d:
            best, best_d = j, d
    return best


@njit(cache=True, nogil=True)
def _mixing_palette(ey, ecb, ecr, bg, palette, inv_ww, background_mask, k):
    """The mixing rule (docs/FIXED_POINT.md): q in Q0.16 from a precomputed 1/|w|², then the
    L1 residual against the tolerance; distances in units of 2^-F_w."""
    fw, fq = k.luma_weight_frac, k.mixing_q_frac
    tol = k.mixing_tolerance << fw
    uy, ucb, ucr = ey - bg[0], ecb - bg[1], ecr - bg[2]
    best, best_d = -1, np.int64(1) << 62
    for j in range(palette.shape[0]):
        d_end = k.luma_weight * abs(ey - palette[j, 0]) + ((abs(ecb - palette[j, 1]) + abs(ecr - palette[j, 2])) << fw)
        if background_mask[j]:
            d_line = d_end
        else:
            wy, wcb, wcr = palette[j, 0] - bg[0], palette[j, 1] - bg[1], palette[j, 2] - bg[2]
            dot = uy * wy + ucb * wcb + ucr * wcr
            q = 0 if dot <= 0 else min((dot * inv_ww[j]) >> fq, np.int64(1) << fq)  # mixing_q
            ry, rcb, rcr = (uy << fq) - q * wy, (ucb << fq) - q * wcb, (ucr << fq) - q * wcr
            d_line = (k.luma_weight * abs(ry) + ((abs(rcb) + abs(rcr)) << fw)) >> fq
        if d_line <= tol and d_end < best_d:
            best, best_d = j, d_end
    return best if best >= 0 else _nearest_palette(ey, ecb, ecr, palette, k)


@njit(cache=True, nogil=True)
def palette_vote(lum, cb, cr, G, k):
    """The event's vote: 1, or with contrast votes |e - BG|₁ from the exact background, rounded half up."""
    if k.vote_contrast == 0:
        return np.int64(1)
    fb = k.background_frac
    return (abs((lum << fb) - G[BG_Y]) + abs((cb << fb) - G[BG_CB]) + abs((cr << fb) - G[BG_CR]) + (np.int64(1) << (fb - 1))) >> fb


@njit(cache=True, nogil=True)
def refresh_mixing(G, palette, inv_ww, k):
    """1/|palette_j - BG|² in Q0.32 (integer colours): a division per entry, at filter steps only."""
    fb = k.background_frac
    for j in range(palette.shape[0]):
        wy = palette[j, 0] - (G[BG_Y] >> fb)
        wcb = palette[j, 1] - (G[BG_CB] >> fb)
        wcr = palette[j, 2] - (G[BG_CR] >> fb)
        ww = wy * wy + wcb * wcb + wcr * wcr
        inv_ww[j] = 0 if ww == 0 else (np.int64(1) << 32) // ww


@njit(cache=True, nogil=True)
def _create(S, H, G, s, t, ex, ey, lum, cb, cr, k, table):
    S[s, :] = 0
    S[s, VALID] = 1
    S[s, ID] = G[NEXT_ID]
    G[NEXT_ID] = (G[NEXT_ID] + 1) & TIME_MASK  # 32-bit id, wraps by design
    x, y = ex << k.centre_frac, ey << k.centre_frac
    S[s, PX], S[s, PY], S[s, PPX], S[s, PPY] = x, y, x, y
    S[s, RX], S[s, RY] = k.r_init, k.r_init
    one = np.int64(1) << k.activity_frac
    S[s, ACT] = _weight(G, t, k, table) if k.activity_reference != 0 else one
    S[s, GAMMA] = _gamma_from_activity(one, k)
    S[s, T_LAST] = t
    S[s, CY], S[s, CCB], S[s, CCR] = lum << k.colour_frac, cb << k.colour_frac, cr << k.colour_frac
    H[s, :] = 0
    G[CREATED] += 1


@njit(cache=True, nogil=True, inline="always")  # the per-event loop's: no call
def _increments(S, G, s, t, ex, ey, lum, cb, cr, k, palette, inv_ww, background_mask, log, ranges, row):
    """Step 3, read half: the slot's update as increments from the state the event reads (in a
    pipelined core, the table D events ago), into the delay-line row."""
    fp, fr = k.centre_frac, k.half_size_frac
    row[PD_LIVE], row[PD_SLOT], row[PD_T] = 1, s, t
    # 3b. Centre: P += β_P (e - P), the event in P's format with all its fraction bits as guard.
    px, py = S[s, PX], S[s, PY]
    row[PD_PX] = alpha_increment_nb(px, ex, k.beta_pos, k.beta_pos_frac, fp, FLOOR)
    row[PD_PY] = alpha_increment_nb(py, ey, k.beta_pos, k.beta_pos_frac, fp, FLOOR)
    # 3c. Size: R += β_R (g_R |e - P| - R); the clamp when committed.
    gx = (abs((ex << fp) - px) * k.size_gain) >> (k.size_gain_frac + fp - fr)
    gy = (abs((ey << fp) - py) * k.size_gain) >> (k.size_gain_frac + fp - fr)
    # No saturation: |e - P| < 2^coord and g_R < 2^bits(g_R), so the product fits size_target.
    gx = _seen(gx, S_SIZE_TARGET, ranges)
    gy = _seen(gy, S_SIZE_TARGET, ranges)
    row[PD_RX] = alpha_increment_nb(S[s, RX], gx, k.beta_size, k.beta_size_frac, 0, FLOOR)
    row[PD_RY] = alpha_increment_nb(S[s, RY], gy, k.beta_size, k.beta_size_frac, 0, FLOOR)
    # 3d. MCM: V += β_vm (γ (P_new - P) - V); the same filter on 1 gives the bias-correction weight.
    step_x = _store(row[PD_PX], k.centre_step_min, k.centre_step_max, S_STEP, log, ranges)
    step_y = _store(row[PD_PY], k.centre_step_min, k.centre_step_max, S_STEP, log, ranges)
    ux = _store(_align(S[s, GAMMA] * step_x, k.gamma_frac + fp, k.v_mcm_frac), k.v_mcm_min, k.v_mcm_max, S_MCM_IN, log, ranges)
    uy = _store(_align(S[s, GAMMA] * step_y, k.gamma_frac + fp, k.v_mcm_frac), k.v_mcm_min, k.v_mcm_max, S_MCM_IN, log, ranges)
    # Rounded to nearest: V's input is at V's own LSB, so a floor would drift one way.
    row[PD_VMX] = alpha_increment_nb(S[s, VMX], ux, k.beta_vel_mcm, k.beta_vel_mcm_frac, 0, NEAREST)
    row[PD_VMY] = alpha_increment_nb(S[s, VMY], uy, k.beta_vel_mcm, k.beta_vel_mcm_frac, 0, NEAREST)
    # w = 1 - α^n: the same filter on the integer 1, with all of w's fraction bits as guard.
    row[PD_NORM] = alpha_increment_nb(S[s, MCM_NORM], 1, k.beta_vel_mcm, k.beta_vel_mcm_frac, k.mcm_norm_frac, NEAREST)
    if k.has_colour != 0:
        # 3e. Colour: three α filters, the event's byte with all of C's fraction bits as guard.
        fc = k.colour_frac
        row[PD_CY] = alpha_increment_nb(S[s, CY], lum, k.beta_lum, k.beta_lum_frac, fc, FLOOR)
        row[PD_CCB] = alpha_increment_nb(S[s, CCB], cb, k.beta_chro, k.beta_chro_frac, fc, FLOOR)
        row[PD_CCR] = alpha_increment_nb(S[s, CCR], cr, k.beta_chro, k.beta_chro_frac, fc, FLOOR)
        # 3f. Palette vote: the event's class and weight.
        fb = k.background_frac
        bg = (G[BG_Y] >> fb, G[BG_CB] >> fb, G[BG_CR] >> fb)
        if k.mixing != 0:
            row[PD_CLASS] = _mixing_palette(lum, cb, cr, bg, palette, inv_ww, background_mask, k)
        else:
            row[PD_CLASS] = _nearest_palette(lum, cb, cr, palette, k)
        row[PD_VOTE] = palette_vote(lum, cb, cr, G, k)


@njit(cache=True, nogil=True, inline="always")  # the per-event loop's: no call
def _commit(S, H, G, row, k, table, log, ranges):
    """Step 3, write half: the increments added to the slot as it is now, each saturated to its
    format (with no delay the state read is the state now, and no saturation can act: the paper's
    update exactly). 3a, the activity: decayed from the slot's own reference time, plus one (in
    event order, so exact whatever the delay); against a reference time, plus the event's weight.
    Then the event's background-colour update."""
    if row[PD_LIVE] != 0:
        s, t = row[PD_SLOT], row[PD_T]
        if k.activity_reference != 0:  # an addition: the event's weight
            S[s, ACT] = _store(S[s, ACT] + _weight(G, t, k, table), 0, k.activity_reference_max, S_ACT, log, ranges)
            S[s, T_LAST] = t
        else:  # decayed from the slot's own time, plus one
            # (a sweep beside the events may have set a later time: no decay back)
            if k.sweep_slots_per_event == 0 or not _later(S[s, T_LAST], t):
                _decay_slot(S, s, t, k, table)
            S[s, ACT] = _store(S[s, ACT] + (np.int64(1) << k.activity_frac), 0, k.activity_max, S_ACT, log, ranges)
        S[s, RX] = _seen(min(max(S[s, RX] + row[PD_RX], k.r_min), k.r_max), S_HALF, ranges)
        S[s, RY] = _seen(min(max(S[s, RY] + row[PD_RY], k.r_min), k.r_max), S_HALF, ranges)
        S[s, VMX] = _store(S[s, VMX] + row[PD_VMX], k.v_mcm_min, k.v_mcm_max, S_VM, log, ranges)
        S[s, VMY] = _store(S[s, VMY] + row[PD_VMY], k.v_mcm_min, k.v_mcm_max, S_VM, log, ranges)
        S[s, MCM_NORM] = _store(S[s, MCM_NORM] + row[PD_NORM], 0, np.int64(1) << k.mcm_norm_frac, S_NORM, log, ranges)  # w <= 1
        S[s, PX] = _store(S[s, PX] + row[PD_PX], 0, k.centre_max, S_CENTRE, log, ranges)
        S[s, PY] = _store(S[s, PY] + row[PD_PY], 0, k.centre_max, S_CENTRE, log, ranges)
        if k.has_colour != 0:
            S[s, CY] = _store(S[s, CY] + row[PD_CY], 0, k.colour_max, S_COLOUR, log, ranges)
            S[s, CCB] = _store(S[s, CCB] + row[PD_CCB], 0, k.colour_max, S_COLOUR, log, ranges)
            S[s, CCR] = _store(S[s, CCR] + row[PD_CCR], 0, k.colour_max, S_COLOUR, log, ranges)
            # Saturating by design (SPEC §4): reaching the top halves every counter, so not an overflow.
            c = row[PD_CLASS]
            H[s, c] = min(_seen(H[s, c] + row[PD_VOTE], S_HIST, ranges), k.hist_max)
            if H[s, c] >= k.hist_max:
                for j in range(H.shape[1]):
                    H[s, j] >>= 1
        S[s, EV_COUNT] = _store(S[s, EV_COUNT] + 1, 0, k.events_in_interval_max, S_EVCOUNT, log, ranges)
        row[PD_LIVE] = 0
    if row[PD_BG] != 0:
        G[BG_Y] = _store(G[BG_Y] + row[PD_BG_Y], 0, k.background_max, S_BG, log, ranges)
        G[BG_CB] = _store(G[BG_CB] + row[PD_BG_CB], 0, k.background_max, S_BG, log, ranges)
        G[BG_CR] = _store(G[BG_CR] + row[PD_BG_CR], 0, k.background_max, S_BG, log, ranges)
        row[PD_BG] = 0


@njit(cache=True, nogil=True)
def _drain(S, H, G, line, k, table, log, ranges):
    """Commit every event still in the delay line, oldest first (before a filter step)."""
    n = line.shape[0]
    for m in range(n):
        _commit(S, H, G, line[(G[EVENTS] + 1 + m) % n], k, table, log, ranges)


@njit(cache=True, nogil=True, inline="always")
def _cancel(line, s):
    """A slot taken by a new cluster: the updates still in flight for its old cluster are void."""
    for r in range(line.shape[0]):
        if line[r, PD_LIVE] != 0 and line[r, PD_SLOT] == s:
            line[r, PD_LIVE] = 0


@njit(cache=True, nogil=True)
def _slot_for_new(S, G, t, k, table):
    for s in range(S.shape[0]):
        if S[s, VALID] == 0:
            return s
    weakest, weakest_a = -1, np.int64(1) << 62
    if k.activity_reference != 0:
        # Every Ã has the one reference: the weakest now has the least Ã (no multiply per slot),
        # and A < A_valid is Ã < A_valid·w, compared with the activity's fraction bits twice.
        for s in range(S.shape[0]):
            if S[s, ACT] < weakest_a:
                weakest, weakest_a = s, S[s, ACT]
        evict = (weakest_a << k.activity_frac) < k.a_valid * _weight(G, t, k, table)
    else:
        for s in range(S.shape[0]):
            a = _decayed(S[s, ACT], (t - S[s, T_LAST]) & TIME_MASK, k, table)
            if a < weakest_a:
                weakest, weakest_a = s, a
        evict = weakest_a < k.a_valid
    if evict:
        G[EVICTED] += 1
        return weakest
    return -1


@njit(cache=True, nogil=True)
def _near(px, py, k):
    m = k.exit_margin
    hi_x = ((k.width - 1) << k.centre_frac) - m
    hi_y = ((k.height - 1) << k.centre_frac) - m
    return px < m, px > hi_x, py < m, py > hi_y


@njit(cache=True, nogil=True)
def _speed_sq(vx, vy, frac, k):
    """|V|² in the speed_sq format from a velocity with `frac` fraction bits. Each component is
    first clamped to full scale (±2^V_FULL_BITS px/frame), so the squares fit an int64."""
    full = (np.int64(1) << (k.v_int_int_bits + frac)) - 1
    vx = min(max(vx, -full), full)
    vy = min(max(vy, -full), full)
    return _align(vx * vx + vy * vy, 2 * frac, k.speed_sq_frac)


@njit(cache=True, nogil=True, inline="always")
def _corrected(colour, background, k):
    """Eq. (11): BG + (C - BG)·(1/p), in C's format, clamped to the byte range."""
    bg = _align(background, k.background_frac, k.colour_frac)
    obj = bg + (((colour - bg) * k.inv_p) >> k.inv_p_frac)
    return min(max(obj, 0), np.int64(255) << k.colour_frac)


@njit(cache=True, nogil=True)
def _mergeable(S, s, j, k):
    """As the float model's: boxes that overlap (velocities not disagreeing), or boxes grown by
    merge_scale·max(R) that overlap with measured velocities that agree. In P's format; the
    grown reach and the relative velocity tolerance floored."""
    up = k.centre_frac - k.half_size_frac
    dx, dy = abs(S[s, PX] - S[j, PX]), abs(S[s, PY] - S[j, PY])
    sx, sy = (S[s, RX] + S[j, RX]) << up, (S[s, RY] + S[j, RY]) << up
    grow = _align(k.merge_scale * (max(S[s, RX], S[s, RY]) + max(S[j, RX], S[j, RY])), k.scale_frac + k.half_size_frac, k.centre_frac)
    if dx > sx + grow or dy > sy + grow:
        return False
    if S[s, VI_COUNT] >= 2 and S[j, VI_COUNT] >= 2:
        dv = abs(S[s, VIX] - S[j, VIX]) + abs(S[s, VIY] - S[j, VIY])
        fast = max(abs(S[s, VIX]) + abs(S[s, VIY]), abs(S[j, VIX]) + abs(S[j, VIY]))
        return dv <= k.merge_v_tol + ((k.merge_v_rel * fast) >> k.scale_frac)
    return dx <= sx and dy <= sy


@njit(cache=True, nogil=True)
def _merge(S, H, G, s, j, k, log, ranges):
    """Slot s absorbs slot j (the float model's _merge): the centre is the activity-weighted
    mean, floored (the sweep's one division); the box covers both boxes; activities and
    event counts add, saturated; the survivor's identity, velocities, colour and histogram."""
    up = k.centre_frac - k.half_size_frac
    survivor = (
        j if (S[j, EVER_REPORTED] > S[s, EVER_REPORTED]) or (S[j, EVER_REPORTED] == S[s, EVER_REPORTED] and S[j, ACT] > S[s, ACT]) else s
    )
    a_s, a_j = S[s, ACT], S[j, ACT]
    weight = a_s + a_j
    px, py = S[s, PX], S[s, PY]
    if weight > 0:
        px = (a_s * S[s, PX] + a_j * S[j, PX]) // weight
        py = (a_s * S[s, PY] + a_j * S[j, PY]) // weight
    lo_x = min(S[s, PX] - (S[s, RX] << up), S[j, PX] - (S[j, RX] << up))
    hi_x = max(S[s, PX] + (S[s, RX] << up), S[j, PX] + (S[j, RX] << up))
    lo_y = min(S[s, PY] - (S[s, RY] << up), S[j, PY] - (S[j, RY] << up))
    hi_y = max(S[s, PY] + (S[s, RY] << up), S[j, PY] + (S[j, RY] << up))
    # The previous centre moves with the centre, kept inside the sensor (as the float model).
    ppx = min(max(S[survivor, PPX] + (px - S[survivor, PX]), 0), (k.width - 1) << k.centre_frac)
    ppy = min(max(S[survivor, PPY] + (py - S[survivor, PY]), 0), (k.height - 1) << k.centre_frac)
    act = _store(a_s + a_j, 0, k.activity_max, S_ACT, log, ranges)
    count = _store(S[s, EV_COUNT] + S[j, EV_COUNT], 0, k.events_in_interval_max, S_EVCOUNT, log, ranges)
    if survivor == j:  # its state, with s's decay reference (s is decayed to now)
        t_last, residual = S[s, T_LAST], S[s, DECAY_RESIDUAL]
        S[s, :] = S[j, :]
        H[s, :] = H[j, :]
        S[s, T_LAST], S[s, DECAY_RESIDUAL] = t_last, residual
    S[s, PX], S[s, PY], S[s, PPX], S[s, PPY] = px, py, ppx, ppy
    S[s, RX] = min((hi_x - lo_x) >> (up + 1), k.r_max)
    S[s, RY] = min((hi_y - lo_y) >> (up + 1), k.r_max)
    S[s, ACT], S[s, EV_COUNT] = act, count
    S[j, VALID] = 0
    G[MERGED] += 1


@njit(cache=True, nogil=True, inline="always")
def _box_pixels(S, s, k):
    """The pixels of a cluster's box, (2·floor(Rx) + 1)·(2·floor(Ry) + 1)."""
    return (2 * (S[s, RX] >> k.half_size_frac) + 1) * (2 * (S[s, RY] >> k.half_size_frac) + 1)


@njit(cache=True, nogil=True)
def _step_open(S, G, t_whole, k, table, log, ranges):
    """A filter step at the event time t_whole (the datapath's clock is its low 32 bits): its τ
    boundaries and the activities' time; the sweep of its slots is to come (_sweep_slot)."""
    t = t_whole & TIME_MASK
    # τ boundaries since the last step, from a phase counter (no division of the wrapping time).
    phase = G[TAU_PHASE] + ((t - G[T_FILTER]) & TIME_MASK)
    boundaries = phase // k.tau_us
    G[TAU_PHASE] = phase - boundaries * k.tau_us
    # T_frame/(n·τ), Q?.F_fpt (it floors to 0 after a long gap); -1: no interval due
    G[SWEEP_PER_FRAME] = k.frame_per_tau // boundaries if boundaries > 0 else -1
    G[SWEEP_T] = t_whole
    G[T_FILTER] = t
    G[SWEEP_DECAY] = 0
    if k.activity_reference != 0:
        if k.sweep_slots_per_event == 0:
            _move_reference(S, G, t, k, table, log, ranges)  # every activity decayed to t at once
        else:  # the reference stays: the step's decay steps from it, its residual included, for the sweep to apply
            G[SWEEP_DECAY], _ = decay_steps_nb((t - G[BG_T]) & TIME_MASK, G[BG_RESIDUAL], k.inv_t_half, k.inv_t_half_frac,
                                               DECAY_TABLE_BITS)  # fmt: skip
    else:
        _decay_background(G, t, k, table)
    G[SWEEP_LEFT] = S.shape[0]
    G[SWEEP_RECORDS] = 0


@njit(cache=True, nogil=True, inline="always")
def _step_activity(a, G, k, table, log, ranges):
    """The activity the sweep decides on: as stored, or beside the events against a reference
    time Ã decayed by the step's steps (a product, not stored), saturated as a move would."""
    if k.activity_reference == 0 or k.sweep_slots_per_event == 0:
        return a
    return _store(decay_apply_nb(a, G[SWEEP_DECAY], table, DECAY_TABLE_BITS, DECAY_FRAC_BITS, FLOOR), 0, k.activity_max, S_ACT, log, ranges)


@njit(cache=True, nogil=True)
def _sweep_slot(S, H, G, s, k, table, gains, background_mask, line, held, log, ranges):
    """The open step on slot s (the float model's _sweep_slot), its record into `held`. A slot
    the sweep frees voids the updates still in flight for it."""
    if S[s, VALID] == 0:
        return
    t = G[SWEEP_T] & TIME_MASK
    per_frame = G[SWEEP_PER_FRAME]
    fp, fv, fw, fi, fc = k.centre_frac, k.v_mcm_frac, k.mcm_norm_frac, k.v_int_frac, k.colour_frac
    sensor = k.width * k.height
    if k.activity_reference != 0:
        S[s, T_LAST] = t
    elif k.sweep_slots_per_event == 0 or not _later(S[s, T_LAST], t):  # (beside the events: no older than t)
        _decay_slot(S, s, t, k, table)
    act = _step_activity(S[s, ACT], G, k, table, log, ranges)
    if act < k.a_min:
        S[s, VALID] = 0
        _cancel(line, s)
        G[EXPIRED] += 1
        return
    if k.merge != 0:  # absorb every later slot that is the same object, lowest first
        j = s + 1
        while j < S.shape[0]:
            if S[j, VALID] != 0 and _mergeable(S, s, j, k):
                _merge(S, H, G, s, j, k, log, ranges)
                _cancel(line, j)
                act = _step_activity(S[s, ACT], G, k, table, log, ranges)
                j = s
            j += 1
    if k.gamma_mode != 2 or S[s, VI_COUNT] == 0:
        S[s, GAMMA] = _store(_gamma_from_activity(act, k), 0, k.gamma_max, S_GAMMA, log, ranges)
    if per_frame >= 0:  # a τ boundary since the last step: an interval is due
        if k.gamma_mode == 2 and S[s, VI_COUNT] >= 1:
            g = (S[s, EV_COUNT] * per_frame) >> (k.frame_per_tau_frac - k.gamma_frac)
            S[s, GAMMA] = _store(g, 0, k.gamma_max, S_GAMMA, log, ranges)
        S[s, EV_COUNT] = 0
        mx = _store(_align((S[s, PX] - S[s, PPX]) * per_frame, fp + k.frame_per_tau_frac, fi), k.v_int_min, k.v_int_max, S_VI, log, ranges)
        my = _store(_align((S[s, PY] - S[s, PPY]) * per_frame, fp + k.frame_per_tau_frac, fi), k.v_int_min, k.v_int_max, S_VI, log, ranges)
        n = S[s, VI_COUNT]
        if k.warm_start == 0 or n >= k.interval_warmup:
            S[s, VIX] = alpha_step_nb(S[s, VIX], mx, k.beta_vel_int, k.beta_vel_int_frac, 0, FLOOR)
            S[s, VIY] = alpha_step_nb(S[s, VIY], my, k.beta_vel_int, k.beta_vel_int_frac, 0, FLOOR)
        elif n == 1:
            S[s, VIX], S[s, VIY] = mx, my
        elif n >= 2:  # the warm-up's running mean: gain 1/n from the table
            S[s, VIX] = alpha_step_nb(S[s, VIX], mx, gains[n], k.beta_vel_int_frac, 0, FLOOR)
            S[s, VIY] = alpha_step_nb(S[s, VIY], my, gains[n], k.beta_vel_int_frac, 0, FLOOR)
        S[s, VI_COUNT] = min(n + 1, max(k.interval_warmup, 2))
        S[s, PPX], S[s, PPY] = S[s, PX], S[s, PY]
    # The reported MCM velocity: V / w, the sweep's one division.
    vmx, vmy = S[s, VMX], S[s, VMY]
    w_cut = S[s, MCM_NORM] >> (fw - k.mcm_weight_frac)  # w in mcm_weight's format: V·2^F fits an int64
    if k.mcm_correct != 0 and w_cut > 0:
        # Saturated: early on (w small) V/w can leave V's format, which the record must hold.
        vmx = _store((S[s, VMX] << k.mcm_weight_frac) // w_cut, k.v_mcm_min, k.v_mcm_max, S_VM, log, ranges)
        vmy = _store((S[s, VMY] << k.mcm_weight_frac) // w_cut, k.v_mcm_min, k.v_mcm_max, S_VM, log, ranges)
    # Exit prediction on the squared speed (no square root).
    # No saturation: each component is clamped below 2^V_FULL_BITS, so the sum fits speed_sq.
    speed_sq = _seen(_speed_sq(vmx, vmy, fv, k), S_SPEED, ranges)
    left, right, top, bottom = _near(S[s, PX], S[s, PY], k)
    if speed_sq >= k.v_exit_sq and speed_sq > 0:
        limit = (speed_sq * k.cos_sq_exit) >> k.cos_sq_exit_frac
        if (left and vmx < 0 and _speed_sq(vmx, 0, fv, k) >= limit) or (right and vmx > 0 and _speed_sq(vmx, 0, fv, k) >= limit) \
                or (top and vmy < 0 and _speed_sq(0, vmy, fv, k) >= limit) or (bottom and vmy > 0 and _speed_sq(0, vmy, fv, k) >= limit):  # fmt: skip
            S[s, VALID] = 0
            _cancel(line, s)
            G[EXITED] += 1
            return
    moving_mcm = _speed_sq(S[s, VMX], S[s, VMY], fv, k) >= k.v_min_sq
    moving_int = _speed_sq(S[s, VIX], S[s, VIY], fi, k) >= k.v_min_sq
    reported = act >= k.a_valid and (moving_mcm or moving_int)
    if reported and k.noise_gate != 0:  # A·W·H >= γ_n·A_bg·box, γ_n in Q.4
        # (against a reference time Ã and the background's Ã have one reference: beside the
        # events the step's decay cancels, so they compare as stored)
        gate = S[s, ACT] if k.activity_reference != 0 else act
        reported = (gate * sensor) << k.noise_gate_frac >= k.noise_gate * G[BG_ACT] * _box_pixels(S, s, k)
    if act >= k.a_valid and not reported:
        G[NOISE] += 1
    S[s, REPORTED] = 1 if reported else 0
    if not reported:
        return
    row = held[G[SWEEP_RECORDS]]
    row[0], row[1], row[2], row[3] = G[SWEEP_T], G[STEP], s, S[s, ID]  # a record keeps the event's whole time
    row[4], row[5] = S[s, PX] / 2.0**fp, S[s, PY] / 2.0**fp
    row[6], row[7] = S[s, RX] / 2.0**k.half_size_frac, S[s, RY] / 2.0**k.half_size_frac
    row[8] = act / 2.0**k.activity_frac
    row[9], row[10] = vmx / 2.0**fv, vmy / 2.0**fv
    row[11], row[12] = S[s, VIX] / 2.0**fi, S[s, VIY] / 2.0**fi
    cls = -1
    row[13], row[14], row[15] = 0.0, 0.0, 0.0
    if k.has_colour != 0:
        # Eq. (11): C_obj = BG + (C - BG)·(1/p), clamped to the byte range.
        row[13] = _corrected(S[s, CY], G[BG_Y], k) / 2.0**fc
        row[14] = _corrected(S[s, CCB], G[BG_CB], k) / 2.0**fc
        row[15] = _corrected(S[s, CCR], G[BG_CR], k) / 2.0**fc
        best = 0
        for j in range(H.shape[1]):
            if not background_mask[j] and H[s, j] > best:
                best, cls = H[s, j], j
    row[16] = cls
    flags = 0
    if S[s, EVER_REPORTED] == 0:
        flags |= FLAG_NEW
    if left or right or top or bottom:
        flags |= FLAG_BORDER
    if moving_mcm:
        flags |= FLAG_MOVING_MCM
    if moving_int:
        flags |= FLAG_MOVING_INT
    row[17] = flags
    S[s, EVER_REPORTED] = 1
    G[SWEEP_RECORDS] += 1


@njit(cache=True, nogil=True)
def _sweep(S, H, G, slots, k, table, gains, palette, inv_ww, background_mask, line, held, out, n_out, steps, first_step, log, ranges):
    """The open step's next `slots` slots, in slot order; when the last is swept the step closes:
    the mixing rule follows the background, the records go to `out` and the time to `steps`."""
    n = S.shape[0]
    while G[SWEEP_LEFT] > 0 and slots > 0:
        _sweep_slot(S, H, G, n - G[SWEEP_LEFT], k, table, gains, background_mask, line, held, log, ranges)
        G[SWEEP_LEFT] -= 1
        slots -= 1
        if G[SWEEP_LEFT] == 0:  # the step closes
            if k.mixing != 0 and k.background_fixed == 0:
                refresh_mixing(G, palette, inv_ww, k)
            for r in range(G[SWEEP_RECORDS]):
                out[n_out] = held[r]
                n_out += 1
            steps[G[STEP] - first_step] = G[SWEEP_T]
            G[STEP] += 1
    return n_out


# Trace actions (golden vectors): what each event did, and to which slot. An unsupported event
# found no cluster and no support to create one.
TRACE_UPDATE, TRACE_CREATE, TRACE_EVICT, TRACE_DROP, TRACE_UNSUPPORTED = (
    TRACE_ACTIONS.index(a) for a in ("update", "create", "evict", "drop", "unsupported")
)


@njit(cache=True, nogil=True, inline="always")
def _supported(support, seen, cx, cy, t, window):
    """Some cell of the 3x3 around (cx, cy) had an event at most `window` µs ago (mod 2^32)."""
    for dy in range(-1, 2):
        for dx in range(-1, 2):
            if seen[cy + dy, cx + dx] and ((t - support[cy + dy, cx + dx]) & TIME_MASK) <= window:
                return True
    return False


@njit(cache=True, nogil=True)
def run_events(S, H, G, k, table, gains, palette, inv_ww, background_mask, support, seen, line, held, t_us, xs, ys, lums, cbs, crs, out,
               steps, log, ranges, trace):  # fmt: skip
    """Feed events; write records into `out` and each filter step's time (the 32-bit
    datapath's clock wraps, the step keeps the whole event time) into `steps`; with a `trace`
    (int64, one per event; None or empty for none), write each event's action << 16 | slot there;
    `ranges` as `_store` takes it. `support` holds each map cell's latest event time (32-bit),
    `seen` whether it has one; `line` is the update delay line
    (D + 1 rows of layout.PENDING_COLUMNS), `held` the open step's records, and the sweep beside
    the events (sweep_slots_per_event) runs as in the float model."""
    n_out = 0
    delay = line.shape[0] - 1
    first_step = G[STEP]
    fb = k.background_frac
    bits = k.support_cell_bits
    beside = k.sweep_slots_per_event
    n = S.shape[0]
    for i in range(t_us.size):
        t = np.int64(t_us[i]) & TIME_MASK  # the 32-bit timestamp counter
        ex, ey = np.int64(xs[i]), np.int64(ys[i])
        lum, cb, cr = np.int64(lums[i]), np.int64(cbs[i]), np.int64(crs[i])
        if G[EVENTS] == 0:
            G[T_FILTER] = t
            G[T_FIRST] = t
            G[TAU_PHASE] = 0  # τ boundaries count from the first event, as in the float model
            if k.activity_reference != 0:  # so does the activity's reference
                G[BG_T], G[BG_RESIDUAL] = t, 0
        if k.activity_reference != 0 and _reference_passed(G, t, k):
            # Ã would outgrow its headroom: commit what is in flight and move the reference to t.
            if G[SWEEP_LEFT] > 0:  # an open sweep finishes first
                G[SWEEP_FORCED] += 1
                n_out = _sweep(S, H, G, n, k, table, gains, palette, inv_ww, background_mask, line, held, out, n_out, steps, first_step,
                               log, ranges)  # fmt: skip
            _drain(S, H, G, line, k, table, log, ranges)
            _move_reference(S, G, t, k, table, log, ranges)
        G[EVENTS] += 1
        row = line[G[EVENTS] % (delay + 1)]  # it holds event n - D - 1: its turn to commit
        if delay > 0:
            _commit(S, H, G, row, k, table, log, ranges)
        if G[SWEEP_LEFT] > 0:  # the open step's sweep, beside the events
            n_out = _sweep(S, H, G, beside, k, table, gains, palette, inv_ww, background_mask, line, held, out, n_out, steps, first_step,
                           log, ranges)  # fmt: skip
        s = _seek(S, ex << k.centre_frac, ey << k.centre_frac, k)
        updated_reported = False
        action = TRACE_UPDATE
        cx, cy = (ex >> bits) + 1, (ey >> bits) + 1
        if s < 0 and k.create_support != 0 and not _supported(support, seen, cx, cy, t, k.support_window):
            G[UNSUPPORTED] += 1
            action = TRACE_UNSUPPORTED
        elif s < 0:
            evicted_before = G[EVICTED]
            s = _slot_for_new(S, G, t, k, table)
            if s >= 0:
                _cancel(line, s)
                _create(S, H, G, s, t, ex, ey, lum, cb, cr, k, table)
                action = TRACE_EVICT if G[EVICTED] > evicted_before else TRACE_CREATE
            else:
                G[DROPPED] += 1
                action = TRACE_DROP
        else:
            _increments(S, G, s, t, ex, ey, lum, cb, cr, k, palette, inv_ww, background_mask, log, ranges, row)
            updated_reported = S[s, REPORTED] != 0
        if trace is not None and trace.size != 0:
            trace[i] = (action << 16) | max(s, 0)
        if k.create_support != 0:
            support[cy, cx] = t
            seen[cy, cx] = True
        if not updated_reported and k.noise_gate != 0:  # the background's activity: read by the noise gate only
            if k.activity_reference != 0:
                G[BG_ACT] = _store(G[BG_ACT] + _weight(G, t, k, table), 0, k.activity_reference_max, S_ACT, log, ranges)
            else:
                _decay_background(G, t, k, table)
                G[BG_ACT] = _store(G[BG_ACT] + (np.int64(1) << k.activity_frac), 0, k.activity_max, S_ACT, log, ranges)
        if k.has_colour != 0 and k.background_fixed == 0 and not updated_reported:
            row[PD_BG] = 1
            row[PD_BG_Y] = alpha_increment_nb(G[BG_Y], lum, k.beta_bg, k.beta_bg_frac, fb, FLOOR)
            row[PD_BG_CB] = alpha_increment_nb(G[BG_CB], cb, k.beta_bg, k.beta_bg_frac, fb, FLOOR)
            row[PD_BG_CR] = alpha_increment_nb(G[BG_CR], cr, k.beta_bg, k.beta_bg_frac, fb, FLOOR)
        if delay == 0:
            _commit(S, H, G, row, k, table, log, ranges)
        G[SINCE_FILTER] += 1
        if G[SINCE_FILTER] >= k.filter_every:
            G[SINCE_FILTER] = 0
            if G[SWEEP_LEFT] > 0:  # the last step's sweep is not done: it finishes first
                G[SWEEP_FORCED] += 1
                n_out = _sweep(S, H, G, n, k, table, gains, palette, inv_ww, background_mask, line, held, out, n_out, steps, first_step,
                               log, ranges)  # fmt: skip
            if beside == 0:
                _drain(S, H, G, line, k, table, log, ranges)
            _step_open(S, G, np.int64(t_us[i]), k, table, log, ranges)
            if beside == 0:
                n_out = _sweep(S, H, G, n, k, table, gains, palette, inv_ww, background_mask, line, held, out, n_out, steps, first_step,
                               log, ranges)  # fmt: skip
    return n_out
