"""The fixed model's constants by name (issue 25): its record holds every field once and agrees
with the formats table it is built from; a record refuses values that are not exactly its fields."""

from __future__ import annotations

import numpy as np
import pytest

from evclust.clusterer import ClustererParams
from evclust.fixed import constants as fixed_constants
from evclust.fixed.formats import build_formats
from evclust.jit import named_record


def test_the_fields_are_unique_and_make_the_record():
    assert len(set(fixed_constants.FIELDS)) == len(fixed_constants.FIELDS)
    assert fixed_constants.DTYPE.names == fixed_constants.FIELDS


def test_the_fixed_record_holds_the_tables_raw_constants_and_formats():
    params = ClustererParams().resolved(33_333.0)
    table = build_formats(params, 346, 260, 33_333.0)
    k = fixed_constants.constant_vector(table, params, True)
    for name in ("inv_t_half", "r_min", "r_max", "beta_pos", "seek_margin"):
        assert k[name] == table.constants[name].raw, name
    assert k.beta_pos_frac == table.constants["beta_pos"].fmt.frac_bits
    assert k.centre_frac == table["centre"].frac_bits and k.centre_max == table["centre"].raw_max
    assert (k.width, k.height, k.has_colour) == (346, 260, 1)


def test_a_record_refuses_missing_or_unknown_fields():
    dtype = np.dtype([("a", np.int64), ("b", np.int64)])
    assert named_record(dtype, {"a": 1, "b": 2}).b == 2
    with pytest.raises(ValueError, match=r"missing \['b'\]"):
        named_record(dtype, {"a": 1})
    with pytest.raises(ValueError, match=r"unknown \['c'\]"):
        named_record(dtype, {"a": 1, "b": 2, "c": 3})
