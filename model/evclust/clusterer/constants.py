"""The float model's constants, named: one float64 record (numba reads `k.t_half_us`) built
from a parameter set, the sensor and the frame period. β = 1 − α for each filter."""

from __future__ import annotations

import math

import numpy as np

from evclust.clusterer.params import GAMMA_MODES, REFERENCE_HALVINGS
from evclust.jit import named_record

FIELDS = (
    "seek_margin", "seek_scale", "r_init", "r_min", "r_max", "size_gain", "t_half_us", "a_min", "a_valid", "filter_every",
    "beta_pos", "beta_size", "beta_vel_mcm", "beta_vel_int", "beta_lum", "beta_chro", "beta_bg",
    "gamma", "gamma_mode", "tau_us", "t_frame_us", "p_correction", "background_fixed", "luma_weight", "hist_max",
    "v_min", "exit_margin", "v_exit", "cos_exit", "width", "height", "has_colour", "warm_start", "mcm_correct",
    "vote_contrast", "mixing", "mixing_tolerance", "merge", "merge_scale", "merge_v_tol", "merge_v_rel", "noise_gate",
    "create_support", "support_cell_bits", "support_window_us", "interval_warmup", "activity_reference", "reference_halvings",
    "sweep_slots_per_event",
)  # fmt: skip
DTYPE = np.dtype([(name, np.float64) for name in FIELDS])


def param_vector(p, width: int, height: int, t_frame_us: float, has_colour: bool) -> np.record:
    """A parameter set (times resolved to µs) as the named constants the compiled loop reads."""
    same = ("seek_margin", "seek_scale", "r_init", "r_min", "r_max", "size_gain", "t_half_us", "a_min", "a_valid", "filter_every",
            "gamma", "tau_us", "p_correction", "luma_weight", "v_min", "exit_margin", "v_exit", "mixing_tolerance", "merge",
            "merge_scale", "merge_v_tol", "merge_v_rel", "noise_gate", "create_support", "support_cell_bits", "support_window_us")  # fmt: skip
    values = {name: getattr(p, name) for name in same}
    values |= {f"beta_{name}": 1 - getattr(p, f"alpha_{name}") for name in ("pos", "size", "vel_mcm", "vel_int", "lum", "chro", "bg")}
    values |= {
        "gamma_mode": GAMMA_MODES.index(p.gamma_mode),
        "t_frame_us": t_frame_us,
        "background_fixed": p.background is not None,
        "hist_max": (1 << p.hist_bits) - 1,
        "cos_exit": math.cos(math.radians(p.theta_exit_deg)),
        "width": width,
        "height": height,
        "has_colour": has_colour,
        "warm_start": p.velocity_warm_start,
        "mcm_correct": p.mcm_bias_correction,
        "vote_contrast": p.palette_vote == "contrast",
        "mixing": p.palette_assign == "mixing",
        "interval_warmup": p.interval_warmup(),
        "activity_reference": p.activity_reference,
        "reference_halvings": REFERENCE_HALVINGS,
        "sweep_slots_per_event": p.sweep_slots_per_event,
    }
    return named_record(DTYPE, values)
