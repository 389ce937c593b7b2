"""The Principled <-> RT Lit mapping without Blender (core/materials/principled_mapping.py): the tables against
RT Lit's interface, and how a value takes the shape of the socket it replaces."""
from __future__ import annotations

import pytest

from rt_lookdev.core.materials.principled_mapping import (FLOAT_TOLERANCE, LINK_ONLY_INPUTS, MAPPED_INPUTS,
                                                          RT_LIT_ONLY_INPUTS, converted_value, values_equal)
from rt_lookdev.core.materials.rt_lit_interface import RT_LIT_INPUTS


def test_the_tables_split_rt_lits_inputs():
    assert set(MAPPED_INPUTS) <= set(RT_LIT_INPUTS) and set(LINK_ONLY_INPUTS) <= set(MAPPED_INPUTS)
    assert set(MAPPED_INPUTS) | set(RT_LIT_ONLY_INPUTS) == set(RT_LIT_INPUTS)
    assert not set(MAPPED_INPUTS) & set(RT_LIT_ONLY_INPUTS)
    assert "Diffuse Roughness" in MAPPED_INPUTS and "Wrap" in RT_LIT_ONLY_INPUTS


@pytest.mark.parametrize("value,target,expected", [
    (0.5, 0.1, 0.5),                                         # float -> float
    (0.5, (0.0, 0.0, 0.0, 1.0), (0.5, 0.5, 0.5, 0.5)),       # float -> colour: every component
    ((0.2, 0.4, 0.6), (0.0, 0.0, 0.0, 1.0), (0.2, 0.4, 0.6, 1.0)),   # vector -> colour: the target's alpha
    ((0.2, 0.4, 0.6, 0.5), (0.0, 0.0, 0.0), (0.2, 0.4, 0.6)),        # colour -> vector: cut
    ((0.2, 0.4, 0.6, 0.5), 0.0, pytest.approx(0.4)),         # colour -> float: the mean of r, g, b
    ((0.3,), 0.0, pytest.approx(0.3)),
])
def test_converted_value_takes_the_targets_shape(value, target, expected):
    assert converted_value(value, target) == expected


def test_values_equal_to_the_tolerance():
    assert values_equal(0.5, 0.5 + FLOAT_TOLERANCE / 2) and not values_equal(0.5, 0.5 + 2 * FLOAT_TOLERANCE)
    assert values_equal((0.1, 0.2), (0.1, 0.2)) and not values_equal((0.1, 0.2), (0.1, 0.2, 0.0))
    assert values_equal(0.5, (0.5,)) and values_equal("MULTI_GGX", "MULTI_GGX") and not values_equal("a", "b")
