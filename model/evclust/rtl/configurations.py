"""The model-in-the-loop configurations the testbenches and the co-simulation benchmark run:
a parameter set on a sensor, as the header the RTL is built with and the configuration the
harness (evclust.rtl.harness) runs a random stream with."""

from __future__ import annotations

from evclust.rtl.sources import params_header

# Model-in-the-loop configurations: two parameter sets whose formats differ (the presets' filters
# set different guard bits, hence different widths), and a small sensor whose parameters switch
# on what the presets leave off (a learning background with the mixing table refreshed at every
# filter step, γ counted per interval, frequent filter steps). Name: (width, height, T_frame).
# "defaults": the default configuration (every one-cluster-per-object addition on, times in
# frames) on a suite-sized sensor, its noise gate lowered from 12.7 to 4 so that the random
# stream's blobs are reported even in a four-slot table.
CONFIGURATIONS = {"traffic": (480, 270, 50000.0), "pedestrian": (270, 480, 40000.0), "small": (64, 48, 10000.0),
                  "defaults": (160, 120, 16666.0)}  # fmt: skip
# Configurations with a test of their own (tb/evclust_core/test_every_configuration.py, which
# chooses its N and stream lengths): "paper", the paper's configuration (presets/paper.toml:
# global γ, nearest-entry votes, velocity filters from zero, none of the one-cluster-per-object
# additions) on the traffic sensor. The switches' other combinations are tb/switch_cover.py's
# pairwise cover, on the small sensor.
OTHER_CONFIGURATIONS = {"paper": (480, 270, 50000.0)}
# The formats table's other shapes (build_formats options), on the traffic parameters: every β a
# power of two, and the narrowest filter states (no guard bits beyond 1/β).
FORMAT_VARIANTS = {"shift_only": {"beta_shift_only": True}, "no_guard_bits": {"dead_band_bits": 0}}


def configuration_params(name: str, n_clusters: int):
    from evclust.clusterer import load_params
    from evclust.vectors.cases import _small_params

    if name == "small":
        return _small_params(n_clusters=n_clusters, gamma_mode="count", a_valid=6.0)
    if name == "defaults":
        from evclust.clusterer import ClustererParams

        return ClustererParams(n_clusters=n_clusters, noise_gate=4.0)
    params, _ = load_params(name)
    return params.model_copy(update={"n_clusters": n_clusters})


def random_config(name: str, n_clusters: int, seed: int, count: int, formats: dict | None = None, params=None, **extra) -> tuple[str, dict]:
    """(header, testbench configuration) of a model-in-the-loop run on configuration `name`'s sensor,
    with its parameters or `params` (then of N = params.n_clusters); `formats` are build_formats's options."""
    formats = formats or {}
    width, height, t_frame = (CONFIGURATIONS | OTHER_CONFIGURATIONS)[name]
    params = params or configuration_params(name, n_clusters)
    n_clusters = params.n_clusters
    t_frame = params.t_frame_us or t_frame
    header = params_header(params, width, height, t_frame, **formats)
    config = {"parameters": params.model_dump(mode="json", exclude_none=True), "n_clusters": n_clusters,
              "width": width, "height": height, "t_frame_us": t_frame, "seed": seed, "count": count,
              "gap": 0, "stall": 0, "formats": formats} | extra  # fmt: skip
    return header, config
