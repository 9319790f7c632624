"""The seek's two builds, shared by the seek's bench (tb/evclust_seek) and its per-slot key's
(tb/evclust_seek_key): the defaults with a scaled seek (seek_scale > 0, so the reach grows with
max(Rx, Ry)) at N = 16, and the traffic preset (a fixed margin) at N = 4; the fixed model for
each, and the module parameters evclust_core gives the seek for it."""

from __future__ import annotations

BUILDS = {"scaled_seek": (160, 120, 16666.0, 16), "traffic": (480, 270, 50000.0, 4)}


def build_params(name: str):
    from cosim import configuration_params

    width, height, t_frame, n = BUILDS[name]
    if name == "scaled_seek":
        from evclust.clusterer import ClustererParams

        return ClustererParams(n_clusters=n, seek_scale=0.75, seek_margin=4.0), width, height, t_frame
    return configuration_params(name, n), width, height, t_frame


def model_for(name: str):
    from evclust.fixed.model import FixedClusterer

    params, width, height, t_frame = build_params(name)
    return FixedClusterer(params, width, height, t_frame), width, height


def widths(name: str) -> dict:
    """The core's widths for the module's parameters: REACH_W as evclust_core computes it."""
    from evclust.rtl.sources import params_header

    model, _, _ = model_for(name)
    f, c = model.table.formats, model.table.constants
    fp, fr, r_w = f["centre"].frac_bits, f["half_size"].frac_bits, f["half_size"].word_bits
    scale_w = c["seek_scale"].fmt.word_bits if "seek_scale" in c else 1
    scale_f = c["seek_scale"].fmt.frac_bits if "seek_scale" in c else 0
    scaled = scale_w + r_w + max(0, fp - scale_f - fr)
    base = max(r_w + fp - fr, c["seek_margin"].fmt.word_bits)
    n = model.params.n_clusters
    slot_w = max(1, (n - 1).bit_length())
    params, width, height, t_frame = build_params(name)
    return {"header": params_header(params, width, height, t_frame), "n": n, "xy_w": f["ev_xy"].word_bits,
            "centre_w": f["centre"].word_bits, "reach_w": max(base, scaled) + 2, "slot_w": slot_w,
            "key_w": 1 + f["seek_distance"].word_bits + slot_w}  # fmt: skip
