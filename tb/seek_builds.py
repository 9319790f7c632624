"""The seek's two builds, shared by the seek's bench (tb/evclust_seek) and its per-slot key's
(tb/evclust_seek_key) and its per-axis window (tb/evclust_seek_window): the defaults with a scaled seek (seek_scale > 0, so the reach grows with
max(Rx, Ry)) at N = 16, and the traffic preset (a fixed margin) at N = 4; the fixed model for
each, the module parameters evclust_core gives the seek for it, and the seek window's definition."""

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
            "window_w": window_bits(f["ev_xy"].word_bits, f["centre"].word_bits, fp),
            "key_w": 1 + f["seek_distance"].word_bits + slot_w}  # fmt: skip


def window_bits(xy_w: int, centre_w: int, fp: int) -> int:
    """{lo, hi, up, nf}: lo and up take the centre's integer bits and one more, hi a pixel, nf P's fraction."""
    return 2 * (centre_w - fp + 1) + xy_w + fp


def window(centre: int, reach: int, xy_w: int, centre_w: int, fp: int) -> int:
    """One axis of a slot's seek window by its definition (rtl/evclust_seek_window.v): the pixels
    lo..hi within `reach` of the centre P (both in P's format), up = ceil(P / 2^fp) and
    nf = -P mod 2^fp, packed {lo, hi, up, nf}. Python's >> floors, so -((-a) >> fp) is a ceiling."""
    lo = max(0, -((reach - centre) >> fp))
    hi = min((1 << xy_w) - 1, (centre + reach) >> fp)
    up = -((-centre) >> fp)
    nf = -centre % (1 << fp)
    lo_w = centre_w - fp + 1
    return (((((lo << xy_w) | hi) << lo_w) | up) << fp) | nf


def slot_windows(model, S, s: int) -> tuple[int, int]:
    """Slot s's seek window per axis as the core stores it when the slot is written: the reach,
    (R << (F_P - F_R)) + the model's `_margin`, about the centre."""
    from evclust.clusterer.layout import PX, PY, RX, RY
    from evclust.fixed import fixed_model

    f = model.table.formats
    fp, xy_w, centre_w = f["centre"].frac_bits, f["ev_xy"].word_bits, f["centre"].word_bits
    up = fp - f["half_size"].frac_bits
    margin = int(fixed_model._margin(S, s, model.k))
    return (window(int(S[s, PX]), (int(S[s, RX]) << up) + margin, xy_w, centre_w, fp),
            window(int(S[s, PY]), (int(S[s, RY]) << up) + margin, xy_w, centre_w, fp))  # fmt: skip
