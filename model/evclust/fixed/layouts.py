"""The stream words' layouts: the fields of an event, a track record, an object record and a
trace entry, each (name, width, signed[, fraction bits]), MSB first. The formats table sizes
them; the header writer (header.py) gives the RTL their LSBs, and evclust.vectors.pack packs
the golden vectors with them."""

from __future__ import annotations

import math

from evclust.fixed.formats import FormatTable

# (name, width, signed) per field; events and trace have fixed layouts apart from the coordinates.
TRACE_FIELDS = (("action", 3, False), ("slot", 8, False))
TRACE_ACTIONS = ("update", "create", "evict", "drop", "unsupported")  # what an event did: the action field's codes, in order


def event_fields(table: FormatTable):
    xy = table["ev_xy"].word_bits
    return (("t", 32, False), ("x", xy, False), ("y", xy, False), ("on", 1, False), ("Y", 8, False), ("Cb", 8, False), ("Cr", 8, False))


def record_fields(table: FormatTable):
    """The track record as the RTL emits it: raw values in their formats."""
    f = table.formats
    slot_bits = max(1, math.ceil(math.log2(table.n_clusters)))
    return (
        ("t_us", 32, False, 0), ("step", 32, False, 0), ("slot", slot_bits, False, 0), ("id", 32, False, 0),
        ("x", f["centre"].word_bits, False, f["centre"].frac_bits), ("y", f["centre"].word_bits, False, f["centre"].frac_bits),
        ("rx", f["half_size"].word_bits, False, f["half_size"].frac_bits), ("ry", f["half_size"].word_bits, False, f["half_size"].frac_bits),
        ("activity", f["activity"].word_bits, False, f["activity"].frac_bits),
        ("vx_mcm", f["v_mcm"].word_bits, True, f["v_mcm"].frac_bits), ("vy_mcm", f["v_mcm"].word_bits, True, f["v_mcm"].frac_bits),
        ("vx_int", f["v_int"].word_bits, True, f["v_int"].frac_bits), ("vy_int", f["v_int"].word_bits, True, f["v_int"].frac_bits),
        ("Y", f["colour"].word_bits, False, f["colour"].frac_bits), ("Cb", f["colour"].word_bits, False, f["colour"].frac_bits),
        ("Cr", f["colour"].word_bits, False, f["colour"].frac_bits),
        ("class", 8, True, 0), ("flags", 4, False, 0),
    )  # fmt: skip


def object_fields(table: FormatTable):
    """The object record as the RTL's object unit emits it: raw values in their formats."""
    f = table.formats
    options = dict(table.options)
    slot_bits = max(1, math.ceil(math.log2(options["N_OBJECTS"])))
    members_bits = max(1, table.n_clusters.bit_length())
    return (
        ("t_us", 32, False, 0), ("step", 32, False, 0), ("slot", slot_bits, False, 0), ("id", 32, False, 0),
        ("x", f["obj_centre"].word_bits, True, f["obj_centre"].frac_bits), ("y", f["obj_centre"].word_bits, True, f["obj_centre"].frac_bits),
        ("rx", f["obj_half"].word_bits, False, f["obj_half"].frac_bits), ("ry", f["obj_half"].word_bits, False, f["obj_half"].frac_bits),
        ("vx", f["obj_velocity"].word_bits, True, f["obj_velocity"].frac_bits), ("vy", f["obj_velocity"].word_bits, True, f["obj_velocity"].frac_bits),
        ("Y", f["colour"].word_bits, False, f["colour"].frac_bits), ("Cb", f["colour"].word_bits, False, f["colour"].frac_bits),
        ("Cr", f["colour"].word_bits, False, f["colour"].frac_bits),
        ("class", 8, True, 0), ("members", members_bits, False, 0), ("flags", 2, False, 0),
    )  # fmt: skip
