"""Integer arithmetic primitives of the bit-accurate fixed-point model (SPEC §5).

Raw values
    A format is ``(signed, int_bits, frac_bits)``; ``int_bits`` excludes the sign bit, so the
    word is ``signed + int_bits + frac_bits`` bits wide (1..63 here, so that every raw value and
    every documented intermediate fits an int64). A raw integer ``r`` stands for ``r·2^-frac_bits``.
    Raw values are Python ints or numpy int64 scalars; the functions work on scalars.

Rounding codes (`FLOOR`, `NEAREST`, `TRUNC`), used when fractional bits are dropped
    FLOOR    toward -inf: an arithmetic right shift;
    NEAREST  to nearest, ties toward +inf ("round half up"): add half an LSB, then floor.
             This is SystemC's SC_RND and fxpmath's 'nearest_posinf'; it is not numpy's / fxpmath's
             'around', which sends ties to even;
    TRUNC    toward zero (fxpmath's 'trunc').
Overflow codes: `SATURATE` (clip to the format's range) and `WRAP` (two's complement).

Two families
    The plain functions (``shift_round``, ``alpha_step``, ...) run in Python on Python ints or
    numpy integers. Each has a numba twin with the suffix ``_nb`` (``shift_round_nb``, ...),
    compiled with ``@njit(cache=True)`` and taking only ints, bools, floats and int64 arrays, for
    the model's event loop and for other jitted code. The self-contained primitives
    (`raw_limits`, `saturate`, `saturate_flag`, `wrap`, `shift_round`) are one source compiled
    twice; the composite ones (`mul_round`, `quantise`, `alpha_step`, `alpha_step_shift`,
    `decay`) are written twice in a few lines, and the tests check that both families agree.
    Python-only design-time helpers, without a twin: `rounding_code`, `overflow_code`,
    `decay_table`, `decay_error_bound`, `alpha_dead_band`, `guard_bits_needed`. `quantise` is
    exact via Fraction; `quantise_nb` reaches the same integers in float64 arithmetic.

    Within the documented operand ranges both families are exact and equal. Outside them the
    Python family stays exact (Python ints do not overflow) while the numba family wraps at
    64 bits, as the hardware would overflow its wider word: stay inside the ranges.
"""

from __future__ import annotations

import math
from decimal import ROUND_FLOOR, Decimal, localcontext
from fractions import Fraction

import numpy as np

from evclust.errors import EvclustError
from evclust.jit import njit

FLOOR = 0
NEAREST = 1
TRUNC = 2
ROUNDING_CODES = {"floor": FLOOR, "nearest": NEAREST, "trunc": TRUNC}

SATURATE = 0
WRAP = 1
OVERFLOW_CODES = {"saturate": SATURATE, "wrap": WRAP}

MAX_WORD_BITS = 63  # raw values, and the documented intermediates, fit an int64
MAX_SHIFT = 62  # shift_round drops at most 62 bits: 1 << 62 still fits an int64
_TWO63 = 9223372036854775808.0  # 2^63 as a float


def rounding_code(rounding) -> int:
    """The code of a rounding mode given by name ("floor", "nearest", "trunc") or by code."""
    if isinstance(rounding, str):
        if rounding in ROUNDING_CODES:
            return ROUNDING_CODES[rounding]
    elif rounding in (FLOOR, NEAREST, TRUNC) and not isinstance(rounding, bool):
        return int(rounding)
    raise EvclustError(f"unknown rounding mode {rounding!r}; expected one of floor, nearest, trunc")


def overflow_code(overflow) -> int:
    """The code of an overflow mode given by name ("saturate", "wrap") or by code."""
    if isinstance(overflow, str):
        if overflow in OVERFLOW_CODES:
            return OVERFLOW_CODES[overflow]
    elif overflow in (SATURATE, WRAP) and not isinstance(overflow, bool):
        return int(overflow)
    raise EvclustError(f"unknown overflow mode {overflow!r}; expected saturate or wrap")


# --------------------------------------------------------------------------------------------
# Single-source primitives: the same function body runs in Python and, as `*_nb`, in numba.
# They call no other function of this module, and avoid intermediates that overflow an int64.


def raw_limits(signed, int_bits, frac_bits):
    """``(lo, hi)``: the smallest and largest raw integer of a format.

    Signed: ``-2^(i+f) .. 2^(i+f) - 1``; unsigned: ``0 .. 2^(i+f) - 1``. ``int_bits`` or
    ``frac_bits`` may be negative as long as ``int_bits + frac_bits >= 0``; the word
    ``signed + int_bits + frac_bits`` must be 1..63 bits, otherwise `EvclustError`.
    """
    n = int_bits + frac_bits
    word = n + (1 if signed else 0)
    if n < 0 or word < 1 or word > MAX_WORD_BITS:
        raise EvclustError("raw_limits: a format's word must be 1..63 bits with int_bits + frac_bits >= 0")
    if signed:
        return -(1 << n), (1 << n) - 1
    half = 1 << (n - 1)
    return 0, half + (half - 1)  # 2^n - 1 without forming 2^63


def saturate(raw, lo, hi):
    """``raw`` clipped to ``[lo, hi]``. Never wraps."""
    if raw < lo:
        return lo
    if raw > hi:
        return hi
    return raw


def saturate_flag(raw, lo, hi):
    """``(value, saturated)``: `saturate` plus whether it clipped, for the caller's per-signal
    saturation counters (the overflow log)."""
    if raw < lo:
        return lo, True
    if raw > hi:
        return hi, True
    return raw, False


def wrap(raw, word_bits, signed):
    """Two's-complement wrap of ``raw`` to a ``word_bits``-bit word (1..63 bits).

    Unsigned: ``raw mod 2^w``; signed: the representative of ``raw mod 2^w`` in
    ``[-2^(w-1), 2^(w-1))``. Any int64 (any Python int in the Python family) is accepted.
    """
    if word_bits < 1 or word_bits > MAX_WORD_BITS:
        raise ValueError("wrap: word_bits must be 1..63")
    half = 1 << (word_bits - 1)
    v = raw & (half + (half - 1))  # raw mod 2^w, in [0, 2^w)
    if signed and v >= half:
        v = (v - half) - half
    return v


def shift_round(raw, shift, mode):
    """``raw · 2^-shift`` rounded to an integer: drop ``shift`` fractional bits (0..62).

    FLOOR: ``raw >> shift``. NEAREST (round half up): ``(raw + 2^(shift-1)) >> shift``, i.e.
    ``floor(raw/2^shift + 1/2)``. TRUNC: toward zero, ``(raw + 2^shift - 1) >> shift`` when raw < 0.
    ``shift == 0`` returns ``raw`` in every mode. Exact for any int64 raw in FLOOR and TRUNC; NEAREST
    needs ``raw <= 2^63 - 1 - 2^(shift-1)`` (the half-LSB adder must not overflow).
    """
    if shift < 0 or shift > MAX_SHIFT:
        raise ValueError("shift_round: shift must be 0..62")
    if shift == 0:
        return raw
    if mode == FLOOR:
        return raw >> shift
    if mode == NEAREST:
        return (raw + (1 << (shift - 1))) >> shift
    if mode == TRUNC:
        if raw < 0:
            return (raw + ((1 << shift) - 1)) >> shift
        return raw >> shift
    raise ValueError("shift_round: unknown rounding mode code")


raw_limits_nb = njit(cache=True)(raw_limits)
saturate_nb = njit(cache=True)(saturate)
saturate_flag_nb = njit(cache=True)(saturate_flag)
wrap_nb = njit(cache=True)(wrap)
shift_round_nb = njit(cache=True, inline="always")(shift_round)  # inlined: a constant mode folds away


# --------------------------------------------------------------------------------------------
# Multiply and round.


def mul_round(a, b, shift, mode):
    """``a·b · 2^-shift`` rounded with ``mode``: one exact product, one rounding (no double rounding).

    Exact in int64 when ``|a·b| + 2^(shift-1) < 2^63``. A sufficient rule on formats: with
    ``|a| <= 2^ma`` and ``|b| <= 2^mb`` (``m = int_bits + frac_bits``, the magnitude bits, for
    signed and unsigned alike), ``ma + mb <= 62`` -- e.g. two signed 32-bit words, or an unsigned
    24-bit value times an unsigned Q1.37 constant. The product has ``fa + fb`` fractional bits;
    the result ``fa + fb - shift``.
    """
    return shift_round(a * b, shift, mode)


@njit(cache=True)
def mul_round_nb(a, b, shift, mode):
    """numba twin of `mul_round`."""
    return shift_round_nb(a * b, shift, mode)


# --------------------------------------------------------------------------------------------
# Quantising constants.


def _exact(x) -> Fraction | float:
    if isinstance(x, Fraction):
        return x
    if isinstance(x, (bool, np.bool_)):
        return Fraction(int(x))
    if isinstance(x, (int, np.integer)):
        return Fraction(int(x))
    if isinstance(x, Decimal) and x.is_finite():
        return Fraction(x)
    x = float(x)  # float, numpy floats
    if math.isnan(x):
        raise EvclustError("quantise: cannot quantise NaN")
    if math.isinf(x):
        return x
    return Fraction(x)  # exact: every finite double is a dyadic rational


def quantise(x, signed, int_bits, frac_bits, rounding="nearest", overflow="saturate") -> int:
    """The raw integer of the real ``x`` in format ``(signed, int_bits, frac_bits)``, exactly.

    ``x·2^frac_bits`` is formed exactly (``x`` a float, int, Fraction or Decimal; pass
    ``Fraction(1, t_half)`` for an exactly rounded reciprocal), rounded with ``rounding``
    ("floor", "nearest" = round half up, "trunc" = toward zero, or a code), then saturated or
    wrapped with ``overflow``. ±inf saturates to the range's end (and is an error with "wrap");
    NaN is an `EvclustError`. For constants outside the event loop (β, γ, T_frame/τ, 1/p,
    palette colours, 1/T_half); the event loop uses the raw integers.
    """
    r = rounding_code(rounding)
    o = overflow_code(overflow)
    lo, hi = raw_limits(signed, int_bits, frac_bits)
    v = _exact(x)
    if isinstance(v, float):  # ±inf
        if o == WRAP:
            raise EvclustError("quantise: cannot wrap an infinite value")
        return hi if v > 0 else lo
    v = v * 2**frac_bits if frac_bits >= 0 else v / 2**-frac_bits
    if r == FLOOR:
        q = math.floor(v)
    elif r == NEAREST:
        q = math.floor(v + Fraction(1, 2))
    else:
        q = math.trunc(v)
    if o == SATURATE:
        return int(saturate(q, lo, hi))
    return int(wrap(q, int(bool(signed)) + int_bits + frac_bits, bool(signed)))


@njit(cache=True)
def quantise_nb(x, signed, int_bits, frac_bits, rmode, omode):
    """numba twin of `quantise` for a float64 ``x``, with mode codes. Exact (equal to `quantise`)
    for every finite ``x``: scaling by a power of two and floor/trunc are exact in binary floating
    point, a scaling that underflows to 0 is resolved from x's sign, and the half-up test
    compares ``v`` with ``floor(v) + 0.5``, which is exact whenever ``v`` is not an integer
    (|v| < 2^52). Subnormal products that do not reach 0 keep their exact value in float64."""
    lo, hi = raw_limits_nb(signed, int_bits, frac_bits)
    if x != x:
        raise ValueError("quantise: cannot quantise NaN")
    word = int_bits + frac_bits + (1 if signed else 0)
    if omode == WRAP:
        if np.isinf(x):
            raise ValueError("quantise: cannot wrap an infinite value")
        # Drop whole multiples of the wrap period first (exact), so x·2^f cannot overflow; the
        # remainder keeps x's sign, so every rounding mode commutes with the subtraction.
        x = np.fmod(x, 2.0 ** (word - frac_bits))
    elif omode != SATURATE:
        raise ValueError("quantise: unknown overflow mode code")
    v = x * 2.0**frac_bits
    if v == 0.0 and x != 0.0:
        # x·2^f underflowed: the exact value is a tiny non-zero, below one LSB in magnitude.
        r = -1.0 if (rmode == FLOOR and x < 0.0) else 0.0
    elif rmode == FLOOR:
        r = np.floor(v)
    elif rmode == NEAREST:
        r = np.floor(v)
        if v != r and v >= r + 0.5:
            r += 1.0
    elif rmode == TRUNC:
        r = np.trunc(v)
    else:
        raise ValueError("quantise: unknown rounding mode code")
    if omode == SATURATE:
        if r >= _TWO63:
            return hi
        if r < -_TWO63:
            return lo
        return saturate_nb(np.int64(r), lo, hi)
    r = np.fmod(r, 2.0**word)  # exact; |r| < 2^word <= 2^63
    return wrap_nb(np.int64(r), word, signed)


# --------------------------------------------------------------------------------------------
# α filters: X += (u - X)·β.


def alpha_step(x, u, beta_raw, beta_frac_bits, guard_bits, mode):
    """One mean-shift update ``X += (u - X)·β`` (SPEC §4 eq. 1 in hardware form).

    Convention:
    - ``u`` is the input in its format ``F_u`` (``f_u`` fractional bits);
    - ``x`` is the accumulator: the same integer bits as ``F_u`` and ``f_u + g`` fractional bits
      (``g = guard_bits``), so ``u``'s value is ``u << g`` in ``x``'s units;
    - ``β = beta_raw · 2^-B`` with ``B = beta_frac_bits`` (0..62), i.e. ``beta_raw`` is unsigned
      Q0.B, ``0 <= beta_raw <= 2^B``.

    Computes ``d = (u << g) - x`` and returns ``x + round(d·beta_raw · 2^-B)`` -- the product
    term rounded once, with ``mode``. Since ``0 <= β <= 1`` the rounded step lies between 0 and
    ``d``, so the result lies between ``x`` and ``u << g``: it never leaves the accumulator's
    range and never overshoots. Widths: ``d`` needs ``m_u + g + 2`` bits for a signed ``u``
    (``m_u + g + 1`` unsigned; ``m_u = int_bits + frac_bits``), the product ``B`` bits more; exact
    in int64 when ``m_u + g + 1 + B <= 62``.

    Dead band: the step is 0, and the filter stalls, while ``d·β`` rounds to 0 (`alpha_dead_band`):
    ``0 <= d < 1/β`` for FLOOR (one-sided: X comes to rest at or below u), ``-1/(2β) <= d < 1/(2β)``
    for NEAREST, ``|d| < 1/β`` for TRUNC, in accumulator LSBs. Without guard bits that is up to
    ``2^k - 1`` LSBs of ``u`` for β = 2^-k. With ``g >= guard_bits_needed(...)`` (= k for
    β = 2^-k) the band is inside one LSB of ``u``: X comes to rest within 1 LSB of a constant
    input; each further guard bit halves the band (g = k + 6 leaves < 2^-6 LSB).

    Step response: each rounded step is within ``ε`` of the exact ``d·β`` (``ε`` < 1 for FLOOR and
    TRUNC, <= 1/2 for NEAREST), so a step of ``S`` LSBs of ``u`` is within 1 LSB after at most
    ``ln((2^g - ε/β)/(S·2^g - ε/β)) / ln(1-β)`` updates: the exact ``ln(1/S)/ln(1-β)`` plus at most
    ``ln(1 - ε·2^(k-g)) / ln(1-β)`` (``≈ 0.29/β`` for g = k + 2, ``0.016/β`` for g = k + 6).
    Read X out in ``F_u`` with ``shift_round(x, g, mode)``.
    """
    return x + shift_round(((u << guard_bits) - x) * beta_raw, beta_frac_bits, mode)


@njit(cache=True)
def alpha_increment_nb(x, u, beta_raw, beta_frac_bits, guard_bits, mode):
    """What `alpha_step` adds to x: ``round(((u << g) - x) · β)``. A pipelined core computes it
    from the state an event read and adds it to the state as it is when the event commits."""
    return shift_round_nb(((u << guard_bits) - x) * beta_raw, beta_frac_bits, mode)


@njit(cache=True)
def alpha_step_nb(x, u, beta_raw, beta_frac_bits, guard_bits, mode):
    """numba twin of `alpha_step`."""
    return x + alpha_increment_nb(x, u, beta_raw, beta_frac_bits, guard_bits, mode)


def alpha_step_shift(x, u, k, guard_bits, mode):
    """`alpha_step` with ``β = 2^-k``: ``x + round(((u << g) - x) · 2^-k)``, a subtract and a shift,
    no multiplier. Identical to ``alpha_step(x, u, 1, k, guard_bits, mode)``."""
    return x + shift_round((u << guard_bits) - x, k, mode)


@njit(cache=True)
def alpha_step_shift_nb(x, u, k, guard_bits, mode):
    """numba twin of `alpha_step_shift`."""
    return x + shift_round_nb((u << guard_bits) - x, k, mode)


def alpha_dead_band(beta_raw, beta_frac_bits, mode) -> tuple[int, int]:
    """``(d_lo, d_hi)``: the inclusive range of ``d = (u << g) - x`` (accumulator LSBs) on which
    `alpha_step` does not move ``x``. Independent of ``g``; divide by ``2^g`` for LSBs of ``u``."""
    b, B = int(beta_raw), int(beta_frac_bits)
    if b < 1:
        raise EvclustError("alpha_dead_band: β = 0 never moves the filter")
    mode = rounding_code(mode)
    one = 1 << B
    if mode == FLOOR:  # 0 <= d·b < 2^B
        return 0, (one - 1) // b
    if mode == TRUNC:  # |d·b| < 2^B
        return -((one - 1) // b), (one - 1) // b
    if B == 0:  # nearest without a shift: the step is d·b itself
        return 0, 0
    half = one >> 1  # nearest: -2^(B-1) <= d·b < 2^(B-1)
    return -(half // b), (half - 1) // b


def guard_bits_needed(beta_raw, beta_frac_bits, mode) -> int:
    """The fewest guard bits ``g`` for which the dead band lies strictly within one LSB of ``u``
    (``|d| < 2^g``), so that a constant input is approached to within 1 LSB. For ``β = 2^-k`` it is
    ``k`` in every mode."""
    lo, hi = alpha_dead_band(beta_raw, beta_frac_bits, mode)
    return max(-lo, hi).bit_length()


# --------------------------------------------------------------------------------------------
# Activity decay: A · 2^(-Δt/T_half), by a shift and a small table.


def decay_table(table_bits, out_frac_bits) -> np.ndarray:
    """``T[i] = 2^-(i / 2^L)``, ``i = 0 .. 2^L - 1`` (``L = table_bits``, 0..16), as unsigned
    Q1.F raw integers (``F = out_frac_bits``, 0..61), rounded to nearest.

    Values lie in ``(1/2, 1]``: ``T[0] = 2^F`` needs the one integer bit. The entries are computed
    with 80-digit decimal arithmetic (correctly rounded ``exp`` and ``ln``), not libm, so the table
    is the same on every machine. Each entry is within half an LSB of the exact value, i.e.
    relative error below ``2^-F``, and the table is non-increasing with ``T[2^L - 1] >= 2^(F-1)``.
    """
    L, F = int(table_bits), int(out_frac_bits)
    if not 0 <= L <= 16 or not 0 <= F <= 61:
        raise EvclustError("decay_table: table_bits must be 0..16 and out_frac_bits 0..61")
    n = 1 << L
    out = np.empty(n, dtype=np.int64)
    with localcontext() as ctx:
        ctx.prec = 80
        ln2 = Decimal(2).ln()
        scale = Decimal(2) ** F
        for i in range(n):
            v = (-(Decimal(i) / n) * ln2).exp() * scale + Decimal("0.5")
            out[i] = int(v.to_integral_value(rounding=ROUND_FLOOR))
    return out


def decay(a_raw, dt, inv_t_half_raw, inv_frac_bits, table, table_bits, table_frac_bits, mode):
    """``a · 2^(-Δt/T_half)``, division-free, in ``a``'s format.

    Inputs: ``a_raw >= 0`` (any unsigned format); ``dt >= 0`` in µs (integer); ``1/T_half`` as the
    constant ``inv_t_half_raw`` with ``Q = inv_frac_bits`` fractional bits (per µs; unsigned Q0.Q
    for T_half >= 2 µs), e.g. ``quantise(Fraction(1, t_half_us), False, 0, Q)``; ``table = decay_table(L, F)`` with
    ``L = table_bits <= Q`` and ``F = table_frac_bits``.

    Steps (all integer):
    1. ``n = dt · inv_t_half_raw``: Δt/T_half in Q.Q -- a multiply, no division. If T_half is a
       power of two 2^s, ``inv_t_half_raw = 1`` and ``Q = s`` make it free.
    2. ``m = shift_round(n, Q - L, mode)``: Δt/T_half in units of 2^-L;
       ``I = m >> L`` (integer part), ``j = m & (2^L - 1)`` (table index).
    3. ``shift_round(a_raw · T[j], F + I, mode)``: one product, then one shift by the integer part
       and the table's fractional bits together, rounded once. 0 when ``F + I > 62``, which is
       exact (the product is below 2^62).

    Ranges (int64): ``dt·inv_t_half_raw < 2^62`` and ``a_raw · 2^(F+1) < 2^62``.

    Error bound against the exact ``y = a·2^(-Δt/T_half)`` (`decay_error_bound`), in LSBs of ``a``:
    ``|decay - y| <= y·((1 + 2^-F)·2^E - 1) + r`` with
    ``E = Δt·|inv_t_half_raw·2^-Q - 1/T_half| + δ``, where ``δ`` is the index rounding: ``2^-L``
    for FLOOR/TRUNC, ``2^-(L+1)`` for NEAREST, 0 when ``Q = L``; ``2^-F`` bounds the table's
    relative error; ``r`` the final rounding: 1 (FLOOR/TRUNC) or 1/2 (NEAREST). E.g. L = 6,
    F = 16, NEAREST and an exact 1/T_half: relative ``0.55 %`` plus half an LSB. Since ``m`` is
    monotone in ``dt`` and the table non-increasing with ``T[2^L-1] >= T[0]/2``, the result never
    increases with ``dt``, and ``dt = 0`` returns ``a_raw``.
    """
    if dt < 0 or a_raw < 0:
        raise ValueError("decay: a_raw and dt must be >= 0")
    m = shift_round(dt * inv_t_half_raw, inv_frac_bits - table_bits, mode)
    return decay_apply(a_raw, m, table, table_bits, table_frac_bits, mode)


def decay_apply(a_raw, m, table, table_bits, table_frac_bits, mode):
    """``a · 2^-(m / 2^L)``: the integer part of ``m / 2^L`` is a shift, its fraction the table
    entry ``T[m mod 2^L]``; one product, one rounding. 0 when the shift passes 62 bits (exact)."""
    total = (m >> table_bits) + table_frac_bits
    if total > 62:
        return 0
    return shift_round(a_raw * int(table[m & ((1 << table_bits) - 1)]), total, mode)


def decay_steps(dt, residual, inv_t_half_raw, inv_frac_bits, table_bits):
    """Δt/T_half as whole table steps (2^-L half-lives) and the residual below one step.

    ``n = dt·inv_t_half_raw + residual`` (a multiply); the bits below one step are returned, to be
    passed back next time. A stateful decay that floors ``dt·(1/T_half)`` afresh at every event
    loses every decay between events closer than one step; carrying the residual loses none."""
    n = dt * inv_t_half_raw + residual
    drop = inv_frac_bits - table_bits
    return n >> drop, n & ((1 << drop) - 1)


@njit(cache=True)
def decay_nb(a_raw, dt, inv_t_half_raw, inv_frac_bits, table, table_bits, table_frac_bits, mode):
    """numba twin of `decay`; ``table`` an int64 array."""
    if dt < 0 or a_raw < 0:
        raise ValueError("decay: a_raw and dt must be >= 0")
    m = shift_round_nb(dt * inv_t_half_raw, inv_frac_bits - table_bits, mode)
    return decay_apply_nb(a_raw, m, table, table_bits, table_frac_bits, mode)


@njit(cache=True)
def decay_apply_nb(a_raw, m, table, table_bits, table_frac_bits, mode):
    """numba twin of `decay_apply`; ``table`` an int64 array."""
    total = (m >> table_bits) + table_frac_bits
    if total > 62:
        return np.int64(0)
    return shift_round_nb(a_raw * table[m & ((1 << table_bits) - 1)], total, mode)


@njit(cache=True)
def decay_steps_nb(dt, residual, inv_t_half_raw, inv_frac_bits, table_bits):
    """numba twin of `decay_steps`."""
    n = dt * inv_t_half_raw + residual
    drop = inv_frac_bits - table_bits
    return n >> drop, n & ((np.int64(1) << drop) - 1)


def decay_error_bound(a_raw, dt, t_half, inv_t_half_raw, inv_frac_bits, table_bits, table_frac_bits, mode) -> float:
    """The documented bound of `decay`'s error against ``a·2^(-dt/t_half)``, in LSBs of ``a``."""
    mode = rounding_code(mode)
    n = dt / t_half
    inv_err = abs(float(Fraction(int(inv_t_half_raw), 1 << int(inv_frac_bits)) - Fraction(1) / Fraction(t_half)))
    if inv_frac_bits == table_bits:
        idx_err = 0.0
    elif mode == NEAREST:
        idx_err = 2.0 ** -(table_bits + 1)
    else:
        idx_err = 2.0**-table_bits
    e = dt * inv_err + idx_err
    r = 0.5 if mode == NEAREST else 1.0
    if e - n > 1000.0:  # a coarse 1/T_half over a long Δt: no useful bound
        return math.inf
    # y·((1 + 2^-F)·2^E - 1) + r, written so that 2^E cannot overflow while y underflows
    return float(a_raw) * ((1.0 + 2.0**-table_frac_bits) * 2.0 ** (e - n) - 2.0**-n) + r
