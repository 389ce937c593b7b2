"""The specular switch (Features(specular="none")): no GGX lobe, tables or world specular in the material,
and exactly the values the validation used to get by hiding the specular under a black cloth of weight 1."""
from __future__ import annotations

import numpy as np
import pytest

from rt_lookdev.core.ir.numpy_backend import flat_node_count
from rt_lookdev.core.ir.tables import table_names
from rt_lookdev.core.lut import lookup
from rt_lookdev.core.materials import light_shading, rt_lit
from rt_lookdev.core.materials.rt_lit_interface import SPECULAR_MODELS, Features
from rt_lookdev.validation.harness import grids

KINDS = ("quad", "disk", "point", "spot", "sun")


def _hidden_specular(values):
    """The old way: a black cloth of weight 1 over the specular."""
    out = dict(values)
    out["Cloth Weight"] = np.ones_like(values["Cloth Weight"])
    out["Cloth Color"] = np.zeros_like(values["Cloth Color"])
    return out


@pytest.mark.parametrize("diffuse", ["lambert", "cod", "wrapped"])
def test_no_specular_equals_the_specular_hidden_under_a_black_cloth(lut_dir, diffuse):
    tables = lookup.LutSet.from_folder(lut_dir)
    off = rt_lit.build_rt_lit(Features("none", diffuse, sheen=True), KINDS)
    hidden = rt_lit.build_rt_lit(Features("single", diffuse, sheen=True, cloth=True), KINDS)
    values = _hidden_specular(grids.material_inputs(hidden, size=24))
    mine = {k: v for k, v in values.items() if k in dict(off.function.inputs)}
    for dtype in (np.float64, np.float32):
        got = off.evaluate(mine, tables, dtype)["Radiance"]
        want = hidden.evaluate(values, tables, dtype)["Radiance"]
        assert np.all(np.isfinite(got)) and np.abs(want).max() > 0.1
        np.testing.assert_array_equal(got, want)


def test_no_specular_carries_no_specular_nodes_or_tables():
    off = rt_lit.build_rt_lit(Features("none", "lambert"), ("quad", "point"))
    on = rt_lit.build_rt_lit(Features("single", "lambert"), ("quad", "point"))
    assert "ggx" not in light_shading.lobe_keys(Features("none", "lambert"))
    # only the sphere table stays (channel A of ltc_ggx_mag: the LTC integrals' horizon, core/ltc/shading.py) ...
    assert table_names(off.function.outputs) == ["ltc_ggx_mag"]
    # ... and goes with an exact horizon: Lambert's integral then clips the quad
    exact = rt_lit.build_rt_lit(Features("none", "lambert", horizon="exact_quads"), ("quad", "point"))
    assert table_names(exact.function.outputs) == []
    assert {"ltc_ggx_inv", "ggx_one_minus_E"} <= set(table_names(on.function.outputs))
    assert flat_node_count(tuple(off.function.outputs.values())) < 0.5 * flat_node_count(
        tuple(on.function.outputs.values()))


def test_no_specular_is_a_model_with_a_label():
    assert "none" in SPECULAR_MODELS
    assert Features("none", "cod", cloth=True).label() == "no specular, cod, cloth"
    assert Features.from_dict(Features("none", "wrapped").as_dict()) == Features("none", "wrapped")
