"""The formats table: one source for the fixed model and the RTL header."""

from __future__ import annotations

import math
import shutil
import subprocess
from fractions import Fraction
from pathlib import Path

import pytest
from fxpmath import Fxp

from evclust.fixed.generate import reference_table
from evclust.clusterer import ClustererParams, load_params
from evclust.errors import EvclustError
from evclust.fixed import build_formats, verilog_header
from evclust.fixed.formats import DEAD_BAND_BITS

from testkit import assert_one_line_error, run_cli

HEADER = Path(__file__).resolve().parents[2] / "rtl" / "evclust_params.vh"


def test_the_committed_rtl_header_is_generated_from_the_table():
    assert HEADER.read_text() == verilog_header(reference_table()), "stale: run `make params`"


def test_the_header_is_ascii_and_icarus_compiles_it(tmp_path):
    text = HEADER.read_text()
    assert text.isascii()
    top = tmp_path / "top.v"
    top.write_text('module top;\n`include "evclust_params.vh"\ninitial $display("%0d %0d", N_CLUSTERS, BETA_POS);\nendmodule\n')
    iverilog = shutil.which("iverilog")
    assert iverilog, "Icarus Verilog is part of the machine"
    subprocess.run([iverilog, "-g2012", "-I", str(HEADER.parent), "-o", str(tmp_path / "top.vvp"), str(top)], check=True)
    out = subprocess.run(["vvp", str(tmp_path / "top.vvp")], check=True, capture_output=True, text=True).stdout.split()
    table = reference_table()
    assert out[:2] == [str(table.n_clusters), str(table.constants["beta_pos"].raw)]


def test_every_constant_matches_fxpmath():
    # fxpmath's 'around' is round-half-even, ours is round-half-up: they may differ only on an
    # exact tie, which the test checks with exact arithmetic.
    for const in reference_table().constants.values():
        f = const.fmt
        oracle = int(Fxp(const.value, signed=f.signed, n_word=f.word_bits, n_frac=f.frac_bits, rounding="around", overflow="saturate").val)
        if oracle != const.raw:
            scaled = Fraction(const.value) * 2**f.frac_bits
            assert scaled.denominator == 2 and const.raw == math.floor(scaled + Fraction(1, 2)), const.name


def test_every_word_fits_the_models_int64_arithmetic():
    for fmt in reference_table().formats.values():
        assert fmt.word_bits <= 63, fmt.name
        assert fmt.raw_min <= 0 <= fmt.raw_max


def test_shift_only_betas_are_powers_of_two():
    params, _ = load_params("traffic")
    table = build_formats(params, 480, 270, 50000.0, beta_shift_only=True)
    betas = [c for name, c in table.constants.items() if name.startswith("beta_")]
    assert len(betas) == 7
    for c in betas:
        assert c.raw & (c.raw - 1) == 0 and c.raw > 0, c.name
        # The nearest power of two, but a shift of at least one bit: β <= 1/2.
        exact = 1 - getattr(params, "alpha_" + c.name[len("beta_") :])
        assert c.quantised == 2.0 ** -max(1, round(-math.log2(exact)))


@pytest.mark.parametrize("dead_band_bits", [0, 3])
def test_the_guard_bits_move_every_filtered_signals_fraction_and_nothing_else(dead_band_bits):
    # A filter's state keeps ceil(log2(1/β)) + dead_band_bits fraction bits (the centre the larger
    # of its two filters'), so every filtered signal moves by the change; the rest stay put.
    params, _ = load_params("traffic")
    default = build_formats(params, 480, 270, 50000.0)
    narrow = build_formats(params, 480, 270, 50000.0, dead_band_bits=dead_band_bits)
    filtered = {
        "centre",
        "offset",
        "seek_distance",
        "centre_step",
        "half_size",
        "size_target",
        "v_mcm",
        "mcm_norm",
        "v_int",
        "colour",
        "background",
        "merge_moment",  # activity × centre
        "obj_centre",
        "obj_half",  # the object layer's, in the centre's and the half-size's fraction bits
        "r_init",
        "r_min",
        "r_max",
        "seek_margin",
        "exit_margin",
        "merge_v_tol",
        "object_gate",
    }  # the last seven: constants held in R's, P's and V's formats
    shift = dead_band_bits - DEAD_BAND_BITS
    for name, fmt in default.formats.items():
        moved = narrow[name].frac_bits - fmt.frac_bits
        assert moved == (shift if name in filtered else 0), name
        assert narrow[name].int_bits == fmt.int_bits, name


@pytest.mark.parametrize("dead_band_bits", [-1, 17])
def test_guard_bits_out_of_range_are_refused(dead_band_bits):
    params, _ = load_params("traffic")
    with pytest.raises(EvclustError, match=f"dead_band_bits = {dead_band_bits}: expected 0..16"):
        build_formats(params, 480, 270, 50000.0, dead_band_bits=dead_band_bits)


@pytest.mark.parametrize(
    "update, fragments",
    [
        ({"alpha_vel_mcm": 1 - 1e-9}, ("clusterer.alpha_vel_mcm", "UQ0.")),
        ({"alpha_lum": 0.0}, ("clusterer.alpha_lum", "β = 1")),
        ({"gamma": 5000.0, "gamma_mode": "global"}, ("clusterer.gamma", "saturates UQ12.8", "UQ13.8")),
    ],
)
def test_parameters_a_format_cannot_hold_are_refused(update, fragments):
    params = ClustererParams(**update)
    with pytest.raises(EvclustError) as err:
        build_formats(params, 480, 270, 50000.0)
    message = str(err.value)
    assert "\n" not in message and all(f in message for f in fragments), message


def test_formats_verb_prints_q_range_and_lsb_and_writes_the_header(tmp_path, capsys):
    code, out, err = run_cli(capsys, "formats", "--verilog", str(tmp_path / "p.vh"))
    assert code == 0, err
    assert "UQ9.0" in out and "SQ" in out and "LSB" in out and "range" in out
    assert (tmp_path / "p.vh").read_text() == HEADER.read_text()


def test_formats_verb_refuses_bad_input(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text("[clusterer]\nalpha_pos = 0.0\n")
    code, _, err = run_cli(capsys, "formats", "--params", str(bad))
    assert_one_line_error(code, err, "clusterer.alpha_pos")
    code, _, err = run_cli(capsys, "formats", "--width", "0")
    assert_one_line_error(code, err, "sensor 0x270")


def test_formats_whose_speed_squares_overflow_the_datapath_are_refused():
    with pytest.raises(EvclustError, match=r"clusterer.alpha_vel_mcm: .* its square needs 65 bits, over 63"):
        build_formats(ClustererParams(alpha_vel_mcm=0.999995), 480, 270, 50000.0)


def test_the_rtl_header_refuses_more_clusters_than_the_trace_can_name():
    with pytest.raises(EvclustError, match="the RTL holds at most 256 clusters"):
        verilog_header(build_formats(ClustererParams(n_clusters=257), 480, 270, 50000.0))


def test_a_parameter_set_for_another_build_is_written_within_its_formats():
    from evclust.clusterer import load_params
    from evclust.fixed import registers

    table = reference_table()
    other, _ = load_params("pedestrian")
    writes = dict(registers.register_writes(table, registers.runtime_table(table, other, other.t_frame_us or 40000.0)))
    for field in registers.config_fields(table):
        value = sum(writes[field.address + 4 * i] << (32 * i) for i in range(field.words))
        assert value < 1 << field.width, field.name


# Two stores the fixed model and the RTL do not saturate, because no input reaches their format's
# top: the worst case of every input, for any parameter set the formats table accepts.
_SENSORS = ((64, 48), (480, 270), (1280, 720), (65535, 2))
_PARAMETER_SETS = (
    ClustererParams(), ClustererParams(size_gain=1.0), ClustererParams(size_gain=3.9, r_max=63.0),
    ClustererParams(alpha_vel_mcm=1 - 2**-17, r_max=63.0), ClustererParams(alpha_vel_int=0.1, alpha_size=0.5),
)  # fmt: skip


@pytest.mark.parametrize("dead_band_bits", [0, DEAD_BAND_BITS])
@pytest.mark.parametrize("width, height", _SENSORS)
@pytest.mark.parametrize("params", _PARAMETER_SETS, ids=range(len(_PARAMETER_SETS)))
def test_size_target_and_speed_squared_cannot_overflow(params, width, height, dead_band_bits):
    table = build_formats(params, width, height, 20_000.0, dead_band_bits=dead_band_bits)
    f = table.formats
    # g_R·|e - P|: the largest offset magnitude times the largest gain the size_gain register
    # holds (a run-time value may use its whole format), floored to R's fraction.
    gain = table.constants["size_gain"].fmt
    offset_max = (1 << (f["offset"].int_bits + f["offset"].frac_bits)) - 1
    shift = gain.frac_bits + f["centre"].frac_bits - f["half_size"].frac_bits
    assert (offset_max * ((1 << gain.word_bits) - 1)) >> shift <= f["size_target"].raw_max
    # |V|²: each component clamped to ±(2^V_FULL_BITS - LSB) before squaring, for both velocities.
    for v in ("v_mcm", "v_int"):
        frac = f[v].frac_bits
        full = (1 << (f["v_int"].int_bits + frac)) - 1
        square, shift = 2 * full * full, 2 * frac - f["speed_sq"].frac_bits
        assert (square >> shift if shift >= 0 else square << -shift) <= f["speed_sq"].raw_max, v


@pytest.mark.parametrize("options, message", [({"activity_bits": 0}, "activity_bits = 0"), ({"activity_bits": 18}, "activity_bits = 18"),
                                              ({"interval_count_bits": 21}, "interval_count_bits = 21")])  # fmt: skip
def test_counters_can_be_narrowed_not_widened(options, message):
    with pytest.raises(EvclustError, match=message):
        build_formats(ClustererParams(), 64, 48, 20_000.0, **options)
    narrow = build_formats(ClustererParams(), 64, 48, 20_000.0, activity_bits=8, interval_count_bits=6)
    assert (narrow["activity"].q, narrow["events_in_interval"].q) == ("UQ8.8", "UQ6.0")


def test_a_new_clusters_gamma_that_would_overflow_its_format_is_refused():
    # γ of a one-event cluster is ln2·T_frame/T_half unsaturated: at most γ's 14 integer bits.
    fits = ClustererParams(t_half_us=math.log(2) * 1e6 / 16000)
    build_formats(fits, 64, 48, 1e6)
    with pytest.raises(EvclustError, match="a new cluster's γ"):
        build_formats(fits.model_copy(update={"t_half_us": math.log(2) * 1e6 / 17000}), 64, 48, 1e6)
