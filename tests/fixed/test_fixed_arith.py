"""Property tests of the fixed-point arithmetic primitives (evclust.fixed.arith).

Oracles: exact integer / Fraction arithmetic everywhere, and fxpmath as an independent
implementation. fxpmath's rounding names: our "floor" is its 'floor', our "trunc" its 'trunc'
(toward zero), and our "nearest" (round half up) its 'nearest_posinf' (SystemC SC_RND, new in
fxpmath 0.4.10); its 'around' is numpy's round-half-even and does not match (see
`test_fxpmath_around_is_half_even_not_half_up`). fxpmath converts Fxp to Fxp and ints through
float64, so it is used as an oracle only where values stay below 2^53 in magnitude.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest
from fxpmath import Fxp
from hypothesis import HealthCheck, assume, example, given, settings
from hypothesis import strategies as st
from numba import njit

from evclust.errors import EvclustError
from evclust.fixed import arith as A
from evclust.fixed.arith import FLOOR, NEAREST, SATURATE, TRUNC, WRAP

MODES = {"floor": FLOOR, "nearest": NEAREST, "trunc": TRUNC}
FXP_ROUNDING = {"floor": "floor", "nearest": "nearest_posinf", "trunc": "trunc"}
I64_MIN, I64_MAX = -(2**63), 2**63 - 1
EXACT_FLOAT = 2**53

MANY = settings(max_examples=1500, deadline=None, suppress_health_check=[HealthCheck.too_slow])
SOME = settings(max_examples=600, deadline=None, suppress_health_check=[HealthCheck.too_slow])
FEW = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def exact_round(v: Fraction, mode: int) -> int:
    """The rounding rules, stated on exact rationals."""
    if mode == FLOOR:
        return math.floor(v)
    if mode == NEAREST:
        return math.floor(v + Fraction(1, 2))
    return math.trunc(v)


def fx_raw(raw: int, signed: bool, n_word: int, n_frac: int) -> Fxp:
    x = Fxp(None, signed=signed, n_word=n_word, n_frac=n_frac)
    x.set_val(int(raw), raw=True)
    return x


def fx_val(fxp: Fxp) -> int:
    return int(np.asarray(fxp.val).item())


# fxpmath scales 1e300 by 2^f in float64 and warns on the overflow and on inf - inf (its
# saturated result is still right).
pytestmark = [
    pytest.mark.filterwarnings("ignore:overflow encountered:RuntimeWarning"),
    pytest.mark.filterwarnings("ignore:invalid value encountered:RuntimeWarning"),
]

mode_names = st.sampled_from(sorted(MODES))


@st.composite
def formats(draw, max_word=63, min_frac=-4):
    signed = draw(st.booleans())
    frac = draw(st.integers(min_frac, 48))
    int_bits = draw(st.integers(max(-4, -frac), 48))
    word = int(signed) + int_bits + frac
    assume(1 <= word <= max_word and int_bits + frac >= 0)
    return signed, int_bits, frac


@st.composite
def format_and_float(draw, max_word=63):
    signed, i, f = draw(formats(max_word=max_word))
    lo, hi = A.raw_limits(signed, i, f)
    scale = 2.0**-f
    kind = draw(st.integers(0, 4))
    if kind == 0:  # anywhere around the range
        span = 2.0 ** (i + 2)
        x = draw(st.floats(-span, span, allow_nan=False, allow_infinity=False))
    elif kind == 1:  # exact ties: (k + 1/2) LSB
        k = draw(st.integers(max(lo - 3, -(2**50)), min(hi + 3, 2**50)))
        x = (k + 0.5) * scale
    elif kind == 2:  # on and next to the lattice
        k = draw(st.integers(max(lo - 3, -(2**52)), min(hi + 3, 2**52)))
        x = float(k) * scale
        x = draw(st.sampled_from([x, math.nextafter(x, math.inf), math.nextafter(x, -math.inf)]))
    elif kind == 3:  # the range's ends and just beyond
        x = draw(st.sampled_from([lo, hi, hi + 0.5, hi + 1, lo - 0.5, lo - 1, (hi + 1) * 2, lo * 2 - 1])) * scale
    else:
        x = draw(st.sampled_from([0.0, -0.0, 5e-324, -5e-324, 1e300, -1e300, 0.5, -0.5, 1.5, -1.5]))
    return signed, i, f, float(x)


# ---------------------------------------------------------------------------------------------
# Codes and limits


def test_mode_codes_and_names():
    assert len({FLOOR, NEAREST, TRUNC}) == 3 and len({SATURATE, WRAP}) == 2
    for name, code in MODES.items():
        assert A.rounding_code(name) == code == A.rounding_code(code)
    assert A.overflow_code("saturate") == SATURATE and A.overflow_code("wrap") == WRAP
    for bad in ("round", "Floor", 7, None, True):
        with pytest.raises(EvclustError):
            A.rounding_code(bad)
    with pytest.raises(EvclustError):
        A.overflow_code("clip")


@MANY
@given(formats())
def test_raw_limits_match_fxpmath(fmt):
    signed, i, f = fmt
    lo, hi = A.raw_limits(signed, i, f)
    assert (lo, hi) == A.raw_limits_nb(signed, i, f)
    n = i + f
    assert (lo, hi) == ((-(2**n), 2**n - 1) if signed else (0, 2**n - 1))
    word = int(signed) + i + f
    big = Fxp(1e300, signed=signed, n_word=word, n_frac=f, overflow="saturate")
    small = Fxp(-1e300, signed=signed, n_word=word, n_frac=f, overflow="saturate")
    assert (fx_val(small), fx_val(big)) == (lo, hi)


@pytest.mark.parametrize("fmt", [(True, 63, 0), (False, 64, 0), (True, -3, 2), (False, 0, 0), (True, 40, 30)])
def test_raw_limits_reject_bad_formats(fmt):
    with pytest.raises(EvclustError):
        A.raw_limits(*fmt)
    with pytest.raises(EvclustError):
        A.raw_limits_nb(*fmt)


# ---------------------------------------------------------------------------------------------
# 1. quantise against fxpmath


@MANY
@given(format_and_float(), mode_names, st.sampled_from(["saturate", "wrap"]))
@example((True, 7, 0, 2.5), "nearest", "saturate")  # ties go up: 3, not numpy's even 2
@example((True, 7, 0, -2.5), "nearest", "saturate")  # -2, not -3
@example((True, 7, 0, 0.49999999999999994), "nearest", "saturate")  # the classic x + 0.5 trap
@example((True, 7, 0, -2.75), "trunc", "saturate")
@example((False, 8, 0, -1.0), "floor", "saturate")
def test_quantise_matches_fxpmath_and_exact_rule(case, rounding, overflow):
    signed, i, f, x = case
    lo, hi = A.raw_limits(signed, i, f)
    word = int(signed) + i + f
    got = A.quantise(x, signed, i, f, rounding=rounding, overflow=overflow)
    assert isinstance(got, int)

    q = exact_round(Fraction(x) * Fraction(2) ** f, MODES[rounding])
    if overflow == "saturate":
        want = min(max(q, lo), hi)
    else:
        off = (hi + 1) if signed else 0
        want = (q + off) % (2**word) - off
    assert got == want

    assert got == A.quantise_nb(x, signed, i, f, MODES[rounding], A.overflow_code(overflow))

    # fxpmath goes through float64: it wraps inexactly above 2^53, and a product x·2^f that
    # underflows to 0 loses x's sign (the exact rule above covers both).
    underflows = x != 0.0 and x * 2.0**f == 0.0
    if (overflow == "saturate" or abs(x) * 2.0**f < EXACT_FLOAT) and not underflows:
        ref = Fxp(x, signed=signed, n_word=word, n_frac=f, rounding=FXP_ROUNDING[rounding], overflow=overflow)
        assert got == fx_val(ref)


def test_fxpmath_around_is_half_even_not_half_up():
    """Why "nearest" is not compared with fxpmath's 'around': that is round-half-even."""
    around = [fx_val(Fxp(x, signed=True, n_word=8, n_frac=0, rounding="around")) for x in (0.5, 1.5, 2.5, -2.5)]
    half_up = [A.quantise(x, True, 7, 0, "nearest") for x in (0.5, 1.5, 2.5, -2.5)]
    posinf = [fx_val(Fxp(x, signed=True, n_word=8, n_frac=0, rounding="nearest_posinf")) for x in (0.5, 1.5, 2.5, -2.5)]
    assert around == [0, 2, 2, -2]
    assert half_up == posinf == [1, 2, 3, -2]


def test_quantise_special_inputs():
    assert A.quantise(math.inf, True, 7, 8) == 2**15 - 1
    assert A.quantise(-math.inf, False, 7, 8) == 0
    assert A.quantise_nb(math.inf, True, 7, 8, NEAREST, SATURATE) == 2**15 - 1
    assert A.quantise_nb(-math.inf, True, 7, 8, NEAREST, SATURATE) == -(2**15)
    with pytest.raises(EvclustError):
        A.quantise(math.nan, True, 7, 8)
    with pytest.raises(EvclustError):
        A.quantise(math.inf, True, 7, 8, overflow="wrap")
    with pytest.raises(ValueError):
        A.quantise_nb(math.nan, True, 7, 8, NEAREST, SATURATE)
    # exact rationals and numpy scalars
    assert A.quantise(Fraction(1, 3), False, 0, 4, "floor") == 5
    assert A.quantise(Fraction(1, 3), False, 0, 4, "nearest") == 5
    assert A.quantise(Fraction(11, 32), False, 0, 4, "nearest") == 6  # 5.5 ties up
    assert A.quantise(np.float32(1.25), True, 3, 2) == 5 == A.quantise(np.int64(5), True, 5, 0)


# ---------------------------------------------------------------------------------------------
# 2. shift_round, mul_round, saturate against exact arithmetic and fxpmath

INT64_EXTREMES = [I64_MIN, I64_MIN + 1, -(2**62), -1, 0, 1, 2**62, I64_MAX - 1, I64_MAX]
raws = st.one_of(
    st.integers(I64_MIN, I64_MAX),
    st.integers(-(2**53) + 1, 2**53 - 1),
    st.integers(-(2**16), 2**16),
    st.sampled_from(INT64_EXTREMES),
)


@MANY
@given(raws, st.integers(0, 62), mode_names)
@example(-7, 1, "trunc")
@example(-5, 1, "nearest")
@example(I64_MIN, 62, "trunc")
@example(I64_MAX, 62, "floor")
def test_shift_round_exact_and_fxpmath(raw, shift, rounding):
    mode = MODES[rounding]
    if mode == NEAREST:  # documented range: the half-LSB adder must not overflow
        raw = min(raw, I64_MAX - (1 << shift >> 1))
    want = exact_round(Fraction(raw, 2**shift), mode)
    got = A.shift_round(raw, shift, mode)
    assert got == want
    assert A.shift_round_nb(raw, shift, mode) == want
    assert A.shift_round(np.int64(raw), shift, mode) == want
    if abs(raw) < EXACT_FLOAT:
        ref = Fxp(fx_raw(raw, True, 64, shift), signed=True, n_word=64, n_frac=0, rounding=FXP_ROUNDING[rounding])
        assert fx_val(ref) == want


def test_shift_round_rejects_bad_arguments():
    for fn in (A.shift_round, A.shift_round_nb):
        with pytest.raises(ValueError):
            fn(5, -1, FLOOR)
        with pytest.raises(ValueError):
            fn(5, 63, FLOOR)
        with pytest.raises(ValueError):
            fn(5, 2, 3)
        assert fn(-5, 0, 3) == -5  # shift 0 is the identity whatever the mode


@st.composite
def mul_operands(draw):
    sa, sb = draw(st.booleans()), draw(st.booleans())
    ma = draw(st.integers(0, 62))
    mb = draw(st.integers(0, 62 - ma))
    lo_a, hi_a = (-(2**ma), 2**ma - 1) if sa else (0, 2**ma - 1)
    lo_b, hi_b = (-(2**mb), 2**mb - 1) if sb else (0, 2**mb - 1)
    a = draw(st.one_of(st.integers(lo_a, hi_a), st.sampled_from([lo_a, hi_a, 0])))
    b = draw(st.one_of(st.integers(lo_b, hi_b), st.sampled_from([lo_b, hi_b, 0])))
    fa, fb = draw(st.integers(0, ma)), draw(st.integers(0, mb))
    return (sa, ma, fa, a), (sb, mb, fb, b)


@MANY
@given(mul_operands(), st.integers(0, 62), mode_names)
def test_mul_round_exact_and_fxpmath(ops, shift, rounding):
    (sa, ma, fa, a), (sb, mb, fb, b) = ops
    mode = MODES[rounding]
    want = exact_round(Fraction(a * b, 2**shift), mode)
    assert A.mul_round(a, b, shift, mode) == want
    assert A.mul_round_nb(a, b, shift, mode) == want
    wa, wb = ma + int(sa), mb + int(sb)
    if shift <= fa + fb and abs(a * b) < EXACT_FLOAT and wa >= 1 and wb >= 1:
        p = fx_raw(a, sa, wa, fa) * fx_raw(b, sb, wb, fb)  # fxpmath's full-precision product
        ref = Fxp(p, signed=True, n_word=64, n_frac=fa + fb - shift, rounding=FXP_ROUNDING[rounding])
        assert fx_val(ref) == want


@MANY
@given(raws, formats(max_word=63, min_frac=0))
def test_saturate_exact_and_fxpmath(raw, fmt):
    signed, i, f = fmt
    lo, hi = A.raw_limits(signed, i, f)
    want = min(max(raw, lo), hi)
    assert A.saturate(raw, lo, hi) == want == A.saturate_nb(raw, lo, hi)
    flag = not lo <= raw <= hi
    assert A.saturate_flag(raw, lo, hi) == (want, flag) == A.saturate_flag_nb(raw, lo, hi)
    if abs(raw) < EXACT_FLOAT:
        word = int(signed) + i + f
        ref = Fxp(fx_raw(raw, True, 64, f), signed=signed, n_word=word, n_frac=f, overflow="saturate")
        assert fx_val(ref) == want


# ---------------------------------------------------------------------------------------------
# 5. saturate never wraps; wrap is two's complement


@pytest.mark.parametrize("signed", [True, False])
@pytest.mark.parametrize("word", [1, 2, 8, 16, 31, 32, 33, 62, 63])
def test_saturate_never_wraps_at_the_extremes(signed, word):
    lo, hi = A.raw_limits(signed, word - int(signed), 0)
    over = [hi + 1, hi + 2, 2 * hi + 1, I64_MAX]
    under = [lo - 1, lo - 2, I64_MIN] if lo > I64_MIN else [I64_MIN]
    for sat in (A.saturate_flag, A.saturate_flag_nb):
        for r in over:
            if r <= I64_MAX:
                assert sat(r, lo, hi) == (hi, r > hi)
        for r in under:
            assert sat(r, lo, hi) == (lo, r < lo)
        assert sat(hi, lo, hi) == (hi, False) and sat(lo, lo, hi) == (lo, False)
    if hi + 1 <= I64_MAX:  # where wrapping would have gone instead
        assert A.wrap(hi + 1, word, signed) == lo
        assert A.saturate(hi + 1, lo, hi) == hi


@MANY
@given(
    st.one_of(raws, st.integers(-(2**100), 2**100)),
    st.integers(1, 63),
    st.booleans(),
)
def test_wrap_is_twos_complement(raw, word, signed):
    off = 2 ** (word - 1) if signed else 0
    want = (raw + off) % 2**word - off
    got = A.wrap(raw, word, signed)
    assert got == want
    lo, hi = A.raw_limits(signed, word - int(signed), 0)
    assert lo <= got <= hi
    if I64_MIN <= raw <= I64_MAX:
        assert A.wrap_nb(raw, word, signed) == want
        if abs(raw) < EXACT_FLOAT:
            ref = Fxp(int(raw), signed=signed, n_word=word, n_frac=0, overflow="wrap")
            assert fx_val(ref) == want


def test_wrap_exhaustive_small_words():
    for word in (1, 2, 3, 4):
        for raw in range(-40, 41):
            assert A.wrap(raw, word, False) == raw % 2**word
            s = A.wrap(raw, word, True)
            assert -(2 ** (word - 1)) <= s < 2 ** (word - 1) and (s - raw) % 2**word == 0
            # the bit pattern: the low `word` bits of the int64 two's-complement representation
            assert np.int64(raw).astype(np.uint64) & np.uint64(2**word - 1) == s % 2**word
    with pytest.raises(ValueError):
        A.wrap(3, 0, True)
    with pytest.raises(ValueError):
        A.wrap_nb(3, 64, True)


# ---------------------------------------------------------------------------------------------
# 3. α filters


@st.composite
def alpha_cases(draw):
    signed = draw(st.booleans())
    m_u = draw(st.integers(1, 24))
    g = draw(st.integers(0, 20))
    B = draw(st.integers(0, 62 - (m_u + g + 1)))
    beta_raw = draw(st.one_of(st.integers(0, 2**B), st.sampled_from([0, 1, 2**B])))
    lo, hi = (-(2**m_u), 2**m_u - 1) if signed else (0, 2**m_u - 1)
    u = draw(st.one_of(st.integers(lo, hi), st.sampled_from([lo, hi])))
    xlo, xhi = lo << g, ((hi + 1) << g) - 1
    x = draw(st.one_of(st.integers(xlo, xhi), st.sampled_from([xlo, xhi])))
    return x, u, beta_raw, B, g, (xlo, xhi)


@MANY
@given(alpha_cases(), mode_names)
def test_alpha_step_exact_rule_and_convexity(case, rounding):
    x, u, beta_raw, B, g, (xlo, xhi) = case
    mode = MODES[rounding]
    target = u * 2**g
    want = x + exact_round(Fraction((target - x) * beta_raw, 2**B), mode)
    got = A.alpha_step(x, u, beta_raw, B, g, mode)
    assert got == want == A.alpha_step_nb(x, u, beta_raw, B, g, mode)
    assert min(x, target) <= got <= max(x, target)  # never overshoots, so never leaves the range
    assert xlo <= got <= xhi
    if beta_raw == 1:
        assert A.alpha_step_shift(x, u, B, g, mode) == got == A.alpha_step_shift_nb(x, u, B, g, mode)
    if beta_raw >= 1:  # the step is 0 exactly on the dead band
        d_lo, d_hi = A.alpha_dead_band(beta_raw, B, mode)
        assert (got == x) == (d_lo <= target - x <= d_hi)


@pytest.mark.parametrize("rounding", sorted(MODES))
@pytest.mark.parametrize("k", [0, 1, 5, 14, 16])
def test_dead_band_and_guard_bits_for_power_of_two_beta(rounding, k):
    band = A.alpha_dead_band(1, k, rounding)
    expected = {
        "floor": (0, 2**k - 1),
        "nearest": (-(2 ** (k - 1)), 2 ** (k - 1) - 1) if k else (0, 0),
        "trunc": (-(2**k) + 1, 2**k - 1),
    }[rounding]
    assert band == expected
    assert A.guard_bits_needed(1, k, rounding) == k


@njit
def _run_to_rest(x, u, beta_raw, B, g, mode, max_iter):
    """Iterate the filter on a constant input until it stops moving. Returns (x, steps to the
    first |u - X| < 1 LSB of u (-1: never), steps to rest (-1: not within max_iter), whether |u - X|
    never grew)."""
    target = u << g
    lsb = 1 << g
    settle = -1
    monotone = True
    d_prev = abs(target - x)
    for n in range(max_iter):
        d = abs(target - x)
        if d > d_prev:
            monotone = False
        d_prev = d
        if settle < 0 and d < lsb:
            settle = n
        x1 = A.alpha_step_nb(x, u, beta_raw, B, g, mode)
        if x1 == x:
            return x, settle, n, monotone
        x = x1
    return x, settle, -1, monotone


# The paper's Table 4 β (4e-4, 8e-5) as the formats table quantises them (Q0.(ceil(-log2 β) + 8)),
# and the powers of two of the brief.
BETAS = {
    "2^-14": (1, 14),
    "2^-16": (1, 16),
    "4e-4": (A.quantise(4e-4, False, 0, 20), 20),
    "8e-5": (A.quantise(8e-5, False, 0, 22), 22),
}
U_FMT = (True, 12, 8)  # the input: a signed Q12.8, 2^20 LSBs either side of 0


@pytest.mark.parametrize("rounding", sorted(MODES))
@pytest.mark.parametrize("beta", sorted(BETAS))
def test_alpha_constant_input_converges_within_one_lsb(beta, rounding):
    """With g = guard_bits_needed (k for β = 2^-k) the filter comes to rest within 1 LSB of a
    constant input from anywhere in range: it never stalls in a dead band wider than that."""
    beta_raw, B = BETAS[beta]
    mode = MODES[rounding]
    g = A.guard_bits_needed(beta_raw, B, rounding)
    assert g == math.ceil(-math.log2(beta_raw / 2**B)) or beta_raw != 1
    lo, hi = A.raw_limits(*U_FMT)
    rng = np.random.default_rng(7)
    starts = [lo << g, ((hi + 1) << g) - 1, 0]
    for u in [hi, lo, 0, 1, -1, *rng.integers(lo, hi, 3).tolist()]:
        for x0 in starts + [(u << g) + s for s in (1, -1, 1 << g, -(1 << g), 3 << (g + 4))]:
            x, settle, rest, monotone = _run_to_rest(x0, u, beta_raw, B, g, mode, 20_000_000)
            d = (u << g) - x
            assert rest >= 0 and settle >= 0 and monotone
            assert abs(d) < 1 << g  # within 1 LSB of u
            d_lo, d_hi = A.alpha_dead_band(beta_raw, B, rounding)
            assert d_lo <= d <= d_hi  # at rest only inside the dead band
            assert A.alpha_step(x, u, beta_raw, B, g, mode) == x


@pytest.mark.parametrize("rounding", sorted(MODES))
@pytest.mark.parametrize("k", [14, 16])
def test_alpha_without_guard_bits_stalls(k, rounding):
    """Why the guard bits exist: with g = 0 the filter freezes 2^(k-1)..2^k - 1 LSBs away."""
    mode = MODES[rounding]
    u, far = 0, 1 << 20
    x, _, rest, _ = _run_to_rest(far, u, 1, k, 0, mode, 20_000_000)  # approach from above (d < 0)
    d_lo, d_hi = A.alpha_dead_band(1, k, rounding)
    assert rest >= 0 and x - u == (0 if mode == FLOOR else -d_lo)  # stuck at the band's edge
    x, _, rest, _ = _run_to_rest(-far, u, 1, k, 0, mode, 20_000_000)  # from below (d > 0)
    assert rest >= 0 and u - x == d_hi
    assert d_hi >= 2 ** (k - 1) - 1  # thousands of LSBs away, not 1
    # The same start with g = k comes to rest within 1 LSB.
    x, _, _, _ = _run_to_rest(-far << k, u, 1, k, k, mode, 20_000_000)
    assert abs((u << k) - x) < 1 << k


def _step_bounds(d0: int, target: int, beta: float, eps: float) -> tuple[float, float, float]:
    """Steps n to reach |d| < target from |d0|: theory, and the rigorous bracket with rounding.

    Exactly, |d_n| = |d0|·(1-β)^n, so n_th = ln(target/|d0|)/ln(1-β) = ln(LSB/step)/ln(1-β).
    Each rounded step differs from (u - X)·β by less than ε (1 for floor and trunc, 1/2 for
    nearest), so with c = ε/β: |d_n| - c <= (1-β)^n (|d0| - c) and |d_n| + c >= (1-β)^n (|d0| + c),
    which bracket the first n with |d_n| < target between n_lo and n_hi (target > c).
    """
    c = eps / beta
    l1b = math.log1p(-beta)
    n_th = math.log(target / d0) / l1b
    n_hi = math.log((target - c) / (d0 - c)) / l1b
    n_lo = math.log((target + c) / (d0 + c)) / l1b
    return n_th, n_lo, n_hi


@pytest.mark.parametrize("extra", [2, 6])
@pytest.mark.parametrize("rounding", sorted(MODES))
@pytest.mark.parametrize("k", [14, 16])
def test_alpha_step_response_settles_within_theory(k, rounding, extra):
    """A step of S LSBs settles (|u - X| < 1 LSB) in ln(LSB/S)/ln(1-β) steps plus a slack that
    rounding explains: with g = k + e guard bits the per-step rounding error (< 1 accumulator LSB)
    adds at most ln(1 - ε·2^-e)/ln(1-β) steps, i.e. 0.29/β for e = 2 (floor) and 0.016/β for
    e = 6 (the formats table's DEAD_BAND_BITS), and it cannot settle faster than the bracket's
    lower end."""
    mode = MODES[rounding]
    beta = 2.0**-k
    g = k + extra
    eps = 0.5 if mode == NEAREST else 1.0
    for step in (2**8, 2**12, 2**20 - 1):
        for sign in (1, -1):
            u, x0 = 0, -sign * (step << g)
            x, settle, rest, monotone = _run_to_rest(x0, u, 1, k, g, mode, 50_000_000)
            assert rest >= 0 and monotone
            n_th, n_lo, n_hi = _step_bounds(step << g, 1 << g, beta, eps)
            assert math.floor(n_lo) + 1 <= settle <= math.floor(n_hi) + 1
            assert n_hi - n_th <= -math.log1p(-eps * 2.0**-extra) / -math.log1p(-beta) + 1e-6
            assert settle <= n_th + 0.3 / beta  # the slack, spelled out for e >= 2
            assert abs(x - (u << g)) < 1 << g


# ---------------------------------------------------------------------------------------------
# 4. Activity decay


@pytest.mark.parametrize("F", [0, 8, 16, 24, 40, 61])
@pytest.mark.parametrize("L", [0, 1, 4, 6, 8])
def test_decay_table_is_correctly_rounded(L, F):
    table = A.decay_table(L, F)
    n = 1 << L
    assert table.dtype == np.int64 and table.shape == (n,)
    assert table[0] == 2**F
    assert np.all(np.diff(table) <= 0) and table[-1] >= 2 ** (F - 1)
    for i, t in enumerate(table.tolist()):
        # Exact, in integers: 2^(F - i/n) lies in [t - 1/2, t + 1/2)  <=>
        # (2t - 1)^n <= 2^(F·n - i + n) < (2t + 1)^n.
        p = 2 ** (F * n - i + n)
        assert (2 * t - 1) ** n <= p < (2 * t + 1) ** n
        assert abs(t - 2.0 ** (F - i / n)) <= 0.5 + 2.0 ** (F - 50)
        if F <= 24:  # fxpmath through float64 is exact enough here
            ref = Fxp(2.0 ** (-i / n), signed=False, n_word=F + 1, n_frac=F, rounding="nearest_posinf")
            assert fx_val(ref) == t


def test_decay_table_rejects_bad_sizes():
    for args in ((-1, 8), (17, 8), (4, 62), (4, -1)):
        with pytest.raises(EvclustError):
            A.decay_table(*args)


@st.composite
def decay_cases(draw):
    L = draw(st.integers(0, 8))
    F = draw(st.sampled_from([8, 12, 16, 20, 28, 36]))
    a_bits = draw(st.integers(1, 61 - F))
    a = draw(st.one_of(st.integers(0, 2**a_bits - 1), st.just(2**a_bits - 1)))
    t_half = draw(st.one_of(st.integers(1, 10_000_000), st.sampled_from([1, 1000, 4096, 50_000, 10**7])))
    q_extra = draw(st.sampled_from([0, 8, 16, 24]))
    Q = max(L, math.ceil(math.log2(t_half)) + q_extra)
    dt = draw(
        st.one_of(
            st.integers(0, 2**32 - 1),
            st.floats(0, 70).map(lambda h: int(h * t_half)),
            st.sampled_from([0, 1, t_half, 2 * t_half, 2**32 - 1]),
        )
    )
    return a, dt, t_half, Q, L, F


_TABLES = {(L, F): A.decay_table(L, F) for L in range(9) for F in (8, 12, 16, 20, 28, 36)}


@MANY
@given(decay_cases(), mode_names)
def test_decay_within_documented_bound(case, rounding):
    a, dt, t_half, Q, L, F = case
    mode = MODES[rounding]
    inv = A.quantise(Fraction(1, t_half), False, 1, Q)
    assume(dt * inv < 2**62)
    table = _TABLES[(L, F)]
    got = A.decay(a, dt, inv, Q, table, L, F, mode)
    assert got == A.decay_nb(a, dt, inv, Q, table, L, F, mode)
    exact = a * 2.0 ** (-dt / t_half)
    bound = A.decay_error_bound(a, dt, t_half, inv, Q, L, F, mode)
    assert abs(got - exact) <= bound * (1 + 1e-12) + 1e-9
    assert 0 <= got <= a


@SOME
@given(decay_cases(), st.integers(0, 2**20), mode_names)
def test_decay_never_grows_with_elapsed_time(case, more, rounding):
    a, dt, t_half, Q, L, F = case
    mode = MODES[rounding]
    inv = A.quantise(Fraction(1, t_half), False, 1, Q)
    assume((dt + more) * inv < 2**62)
    table = _TABLES[(L, F)]
    assert A.decay(a, dt + more, inv, Q, table, L, F, mode) <= A.decay(a, dt, inv, Q, table, L, F, mode)
    assert A.decay(a, 0, inv, Q, table, L, F, mode) == a


@SOME
@given(st.integers(0, 2**30), st.integers(0, 20), st.integers(0, 40), st.integers(0, 8), mode_names)
def test_decay_power_of_two_half_life_is_a_shift(a, s, halvings, L, rounding):
    """T_half = 2^s: 1/T_half is raw 1 in Q0.s, and whole half-lives are exactly a shift."""
    assume(L <= s)
    mode = MODES[rounding]
    F = 16
    got = A.decay(a, halvings << s, 1, s, _TABLES[(L, F)], L, F, mode)
    assert got == A.shift_round(a, halvings, mode)
    assert A.decay_error_bound(a, halvings << s, 2**s, 1, s, L, F, mode) >= 0.5


def test_decay_bound_example_from_the_docstring():
    # L = 6, F = 16, nearest, exact 1/T_half: relative (1 + 2^-16)·2^(2^-7) - 1 = 0.55 %
    rel = (1 + 2.0**-16) * 2.0 ** (2.0**-7) - 1
    assert 0.0054 < rel < 0.0056
    b = A.decay_error_bound(10_000, 0, 4096, 1, 12, 6, 16, NEAREST)
    assert b == pytest.approx(10_000 * rel + 0.5)
    with pytest.raises(ValueError):
        A.decay(-1, 5, 1, 12, _TABLES[(6, 16)], 6, 16, NEAREST)


# ---------------------------------------------------------------------------------------------
# Every numba variant compiles and runs inside a jitted caller.


@njit
def _call_every_numba_variant(table):
    lo, hi = A.raw_limits_nb(True, 7, 8)
    s = A.saturate_nb(100_000, lo, hi)
    sf, flag = A.saturate_flag_nb(-100_000, lo, hi)
    w = A.wrap_nb(200, 8, True)
    r = A.shift_round_nb(-7, 1, TRUNC)
    m = A.mul_round_nb(-3, 5, 1, NEAREST)
    q = A.quantise_nb(2.5, True, 7, 0, NEAREST, SATURATE)
    x = A.alpha_step_nb(0, 100, 1, 4, 4, FLOOR)
    xs = A.alpha_step_shift_nb(0, 100, 4, 4, FLOOR)
    d = A.decay_nb(1000, 4096, 1, 12, table, 6, 16, NEAREST)
    return lo, hi, s, sf, flag, w, r, m, q, x, xs, d


def test_every_numba_variant_compiles_in_njit():
    table = A.decay_table(6, 16)
    got = _call_every_numba_variant(table)
    want = (
        *A.raw_limits(True, 7, 8),
        A.saturate(100_000, -(2**15), 2**15 - 1),
        *A.saturate_flag(-100_000, -(2**15), 2**15 - 1),
        A.wrap(200, 8, True),
        A.shift_round(-7, 1, TRUNC),
        A.mul_round(-3, 5, 1, NEAREST),
        A.quantise(2.5, True, 7, 0),
        A.alpha_step(0, 100, 1, 4, 4, FLOOR),
        A.alpha_step_shift(0, 100, 4, 4, FLOOR),
        A.decay(1000, 4096, 1, 12, table, 6, 16, NEAREST),
    )
    assert got == want == (-(2**15), 2**15 - 1, 2**15 - 1, -(2**15), True, -56, -3, -7, 3, 100, 100, 500)


@SOME
@given(st.lists(st.integers(0, 5000), min_size=1, max_size=40), st.integers(1, 2**20), st.integers(20, 40))
def test_decay_steps_carrying_the_residual_lose_no_time(pieces, inv, frac):
    # Cutting Δt into pieces and carrying the residual gives exactly the steps of the whole Δt,
    # in both families; flooring each piece afresh would lose up to one step per piece.
    whole, whole_rest = A.decay_steps(sum(pieces), 0, inv, frac, 6)
    steps, rest = 0, 0
    for dt in pieces:
        m, rest = A.decay_steps(dt, rest, inv, frac, 6)
        steps += m
    assert (steps, rest) == (whole, whole_rest)
    m_nb, rest_nb, total = 0, 0, 0
    for dt in pieces:
        m_nb, rest_nb = A.decay_steps_nb(dt, rest_nb, inv, frac, 6)
        total += m_nb
    assert (total, rest_nb) == (whole, whole_rest)
