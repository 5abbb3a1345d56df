"""``kinestat.cli._output``: number parsing for options and JSON conversion."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from kinestat.cli._output import parse_floats, to_jsonable
from kinestat.errors import InputError


@settings(max_examples=50, deadline=None)
@given(st.lists(st.floats(min_value=-1e12, max_value=1e12), min_size=1, max_size=8))
def test_parse_floats_round_trips_repr(values):
    text = ", ".join(repr(v) for v in values)
    np.testing.assert_array_equal(parse_floats(text, len(values)), values)


def test_blank_inside_a_number_is_an_error_not_a_merge():
    # '1 2' used to lose its blank and read as 12
    with pytest.raises(InputError, match="--q: cannot read"):
        parse_floats("1 2,3,4,5,6,7", 6, "q")


@pytest.mark.parametrize("text, position", [("1,,2,3", 2), ("1,2,3,", 4), (",1,2,3", 1)])
def test_empty_field_is_reported_with_its_position(text, position):
    # an empty field used to be skipped, so '1,,2,3' silently became three numbers
    with pytest.raises(InputError, match=f"--legs: empty value at position {position}"):
        parse_floats(text, 3, "legs")


@pytest.mark.parametrize("huge", ["1.7e308", "-1e200", "1.000001e12"])
def test_a_huge_number_is_refused_naming_its_position(huge):
    # 16 inline numbers of a pose were checked only for finiteness: 1e200 reached the
    # kinematics and overflowed there, far from the option
    with pytest.raises(InputError, match=r"--pose: value 3 .* implausibly large"):
        parse_floats(f"1,0,{huge},4", 4, "pose")
    np.testing.assert_array_equal(parse_floats("1e12,-1e12", 2), [1e12, -1e12])


def test_empty_text_is_zero_numbers():
    with pytest.raises(InputError, match="expected 2 comma-separated numbers, got 0"):
        parse_floats("  ", 2, "x")


def test_to_jsonable_is_valid_json():
    obj = {"a": np.array([1.0, np.inf, -np.inf, np.nan]), "b": np.int64(3), "c": np.bool_(True)}
    out = json.loads(json.dumps(to_jsonable(obj)))
    assert out == {"a": [1.0, "inf", "-inf", "nan"], "b": 3, "c": True}
    assert not any(isinstance(v, float) and math.isnan(v) for v in out["a"])
