"""The float model's constants by name (issue 25)."""

from __future__ import annotations

import pytest

from evclust.clusterer import ClustererParams
from evclust.clusterer import constants


def test_the_fields_are_unique_and_make_the_record():
    assert len(set(constants.FIELDS)) == len(constants.FIELDS)
    assert constants.DTYPE.names == constants.FIELDS


def test_the_float_record_holds_beta_as_one_minus_alpha():
    params = ClustererParams().resolved(33_333.0)
    k = constants.param_vector(params, 346, 260, 33_333.0, False)
    assert k.beta_pos == pytest.approx(1 - params.alpha_pos) and k.t_frame_us == 33_333.0
    assert k.has_colour == 0.0 and k.hist_max == (1 << params.hist_bits) - 1
