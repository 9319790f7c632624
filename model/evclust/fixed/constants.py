"""The fixed model's constants, named: one int64 record (numba reads `k.r_min`), built from the
formats table and the parameter set. Raw integers in their formats; `*_frac` is a format's
fraction bits, `*_max`/`*_min` its raw range."""

from __future__ import annotations

import numpy as np

from evclust.clusterer.params import GAMMA_MODES, REFERENCE_HALVINGS
from evclust.fixed.formats import NOISE_GATE_FRAC_BITS, SCALE_FRAC_BITS
from evclust.jit import named_record

BETAS = ("beta_pos", "beta_size", "beta_vel_mcm", "beta_vel_int", "beta_lum", "beta_chro", "beta_bg")
STATE_FRACS = (("centre", "centre"), ("half_size", "half_size"), ("activity", "activity"), ("v_mcm", "v_mcm"),
               ("mcm_norm", "mcm_norm"), ("v_int", "v_int"), ("colour", "colour"), ("background", "background"),
               ("gamma", "gamma"), ("speed_sq", "speed_sq"), ("mcm_weight", "mcm_weight"), ("mixing_q", "mixing_q"))  # fmt: skip
FIELDS = (
    # Fraction bits of the state's formats.
    *(f"{name}_frac" for name, _ in STATE_FRACS),
    # Raw ranges a store saturates to.
    "activity_max", "v_mcm_max", "v_mcm_min", "v_int_max", "v_int_min", "gamma_max", "events_in_interval_max",
    "centre_step_min", "centre_step_max", "centre_max", "colour_max", "background_max", "v_int_int_bits",
    # Quantised constants (raw) and their fraction bits where they have their own format.
    *BETAS, *(f"{name}_frac" for name in BETAS),
    "seek_margin", "r_init", "r_min", "r_max", "size_gain", "size_gain_frac", "inv_t_half", "inv_t_half_frac",
    "a_min", "a_valid", "gamma_global", "gamma_per_activity", "gamma_per_activity_frac", "frame_per_tau", "frame_per_tau_frac",
    "inv_p", "inv_p_frac", "luma_weight", "luma_weight_frac", "v_min_sq", "v_exit_sq", "cos_sq_exit", "cos_sq_exit_frac",
    "exit_margin", "mixing_tolerance", "seek_scale", "merge_scale", "merge_v_tol", "merge_v_rel", "scale_frac",
    "noise_gate", "noise_gate_frac", "support_window",
    # Parameters as integers: counts, switches, the sensor.
    "filter_every", "tau_us", "gamma_mode", "background_fixed", "hist_max", "width", "height", "has_colour", "warm_start",
    "mcm_correct", "vote_contrast", "mixing", "merge", "create_support", "support_cell_bits", "interval_warmup",
    # The activity against a reference time: the switch, Ã's halvings of headroom and its raw top.
    "activity_reference", "reference_halvings", "activity_reference_max",
    # The filter step's sweep beside the events: slots swept before each event (0: all at once).
    "sweep_slots_per_event",
)  # fmt: skip
DTYPE = np.dtype([(name, np.int64) for name in FIELDS])


def constant_vector(table, params, has_colour: bool) -> np.record:
    """The formats table and the parameters as the named constants the compiled loop reads."""
    f, c = table.formats, table.constants

    def raw(name, default=0):
        return c[name].raw if name in c else default

    def frac(name):  # an optional constant's fraction bits (0 when the build leaves it out)
        return c[name].fmt.frac_bits if name in c else 0

    values = {f"{name}_frac": f[fmt].frac_bits for name, fmt in STATE_FRACS}
    values |= {name: raw(name) for name in BETAS} | {f"{name}_frac": c[name].fmt.frac_bits for name in BETAS}
    for name in ("seek_margin", "r_init", "r_min", "r_max", "size_gain", "inv_t_half", "a_min", "a_valid", "gamma_global",
                 "gamma_per_activity", "frame_per_tau", "inv_p", "luma_weight", "v_min_sq", "v_exit_sq", "cos_sq_exit",
                 "exit_margin", "mixing_tolerance", "seek_scale", "merge_scale", "merge_v_tol", "merge_v_rel", "noise_gate",
                 "support_window"):  # fmt: skip
        values[name] = raw(name)
    for name in ("size_gain", "inv_t_half", "gamma_per_activity", "frame_per_tau", "inv_p", "luma_weight", "cos_sq_exit"):
        values[f"{name}_frac"] = frac(name)
    values |= {
        "activity_max": f["activity"].raw_max,
        "v_mcm_max": f["v_mcm"].raw_max,
        "v_mcm_min": f["v_mcm"].raw_min,
        "v_int_max": f["v_int"].raw_max,
        "v_int_min": f["v_int"].raw_min,
        "v_int_int_bits": f["v_int"].int_bits,
        "gamma_max": f["gamma"].raw_max,
        "events_in_interval_max": f["events_in_interval"].raw_max,
        "centre_step_min": f["centre_step"].raw_min,
        "centre_step_max": f["centre_step"].raw_max,
        # The tops of the formats a delayed commit saturates to (their bottoms are 0).
        "centre_max": f["centre"].raw_max,
        "colour_max": f["colour"].raw_max,
        "background_max": f["background"].raw_max,
        "scale_frac": SCALE_FRAC_BITS,
        "noise_gate_frac": NOISE_GATE_FRAC_BITS,
        "filter_every": params.filter_every,
        "tau_us": int(round(params.tau_us)),
        "gamma_mode": GAMMA_MODES.index(params.gamma_mode),
        "background_fixed": params.background is not None,
        "hist_max": (1 << params.hist_bits) - 1,
        "width": table.width,
        "height": table.height,
        "has_colour": has_colour,
        "warm_start": params.velocity_warm_start,
        "mcm_correct": params.mcm_bias_correction,
        "vote_contrast": params.palette_vote == "contrast",
        "mixing": params.palette_assign == "mixing",
        "merge": params.merge,
        "create_support": params.create_support,
        "support_cell_bits": params.support_cell_bits,
        "interval_warmup": params.interval_warmup(),
        "activity_reference": params.activity_reference,
        "reference_halvings": REFERENCE_HALVINGS,
        "activity_reference_max": ((f["activity"].raw_max + 1) << REFERENCE_HALVINGS) - 1,
        "sweep_slots_per_event": params.sweep_slots_per_event,
    }
    return named_record(DTYPE, values)
