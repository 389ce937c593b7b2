"""The area lights' horizon switch (Features.horizon, issue 30): "sphere_table" (the default) keeps the talk's clipless
form, "exact_quads" clips the lobes' LTC integrals at the horizon under quads, "exact" under disks too; measured
against brute force on lights that cross it."""
from __future__ import annotations

import numpy as np
import pytest

from rt_lookdev.core.ir.numpy_backend import flat_node_count
from rt_lookdev.core.ltc import fit, fit_lobes, shading
from rt_lookdev.core.lut import lookup
from rt_lookdev.core.materials import light_shading, lobes, rt_lit
from rt_lookdev.core.materials.rt_lit_interface import HORIZON_MODELS, Features
from rt_lookdev.validation.benchmarks import horizon_benchmark, ltc_random_lights


@pytest.fixture(scope="module")
def tables(lut_dir):
    return lookup.LutSet.from_folder(lut_dir)


def test_features_carry_the_horizon():
    assert Features().horizon == "sphere_table" and set(HORIZON_MODELS) == {"exact_quads", "exact", "sphere_table"}
    assert Features().label() == "turquin, cod"
    assert Features(horizon="exact_quads").label() == "turquin, cod, exact-quads horizon"
    assert Features(horizon="exact").label() == "turquin, cod, exact horizon"
    assert Features.from_dict({"specular": "single", "diffuse": "cod"}).horizon == "sphere_table"  # older materials
    with pytest.raises(ValueError, match="horizon"):
        Features(horizon="clipless")


def test_the_switch_picks_the_lobes_integrals():
    exact, table = (lobes.LOBES["ggx"].function("quad", h) for h in (True, False))
    assert exact.name == "RTL Quad GGX" and table.name == "RTL Quad GGX (Sphere Table Horizon)"
    assert lobes.LOBES["ggx"].function("point", False) is lobes.LOBES["ggx"].function("point", True)
    for horizon, quad, disk in (("exact_quads", True, False), ("exact", True, True), ("sphere_table", False, False)):
        features = Features("single", "cod", horizon=horizon)
        assert [light_shading.exact_horizon(features, k) for k in ("quad", "quad+range", "disk", "sphere")] == [
            quad, quad, disk, disk]
    cost = {h: flat_node_count(tuple(rt_lit.build_rt_lit(Features("single", "cod", horizon=h), ("quad", "disk"))
                                     .function.outputs.values())) for h in HORIZON_MODELS}
    assert cost["exact"] > cost["exact_quads"] > cost["sphere_table"]


@pytest.mark.parametrize("prefix", ["ltc_ggx", "ltc_cod_diffuse"])
def test_exact_horizon_is_closer_under_lights_crossing_it(tables, prefix):
    # the horizon benchmark's seeded quads crossing the horizon (docs/benchmarks/horizon.md, 120 per set: GGX
    # 2.7% / 17% median / p90 -> 0.96% / 3.5%, CoD 4.6% / 22% -> 0.39% / 2.5%)
    lobe = fit_lobes.LOBES[dict(ggx="ggx", cod_diffuse="cod_diffuse")[prefix[4:]]]
    est = {True: [], False: []}
    truth, albedo, theta = [], [], []
    for r, th, v, geom in horizon_benchmark.horizon_lights("quad", 100, True, seed=2031):
        truth.append(ltc_random_lights.true_integral("quad", lambda l, vv, r=r: lobe.eval_cos(l, vv, np.array(r)),
                                                     v, geom)[0])
        albedo.append(float(fit.lobe_integrals(lobe, max(float(v[2]), fit.FIT_MU_MIN), np.array([r]), 1 << 10)[0][0]))
        theta.append(th)
        for exact in est:
            est[exact].append(horizon_benchmark.lobe_estimate(tables, prefix, "quad", geom, v, r, exact))
    stats = {exact: ltc_random_lights.error_stats(est[exact], truth, albedo, theta) for exact in est}
    assert stats[True]["lights_over_10pct"] >= 10
    assert stats[True]["rel_median"] < 0.015 and stats[True]["rel_p90"] < 0.06, stats[True]
    assert stats[True]["rel_p90"] < 0.5 * stats[False]["rel_p90"], stats
    assert stats[True]["abs_over_albedo_p90"] < stats[False]["abs_over_albedo_p90"], stats


def test_lights_carry_their_horizon_into_the_wrapped_image():
    quad = shading.QuadLight(np.array([[1.0, -0.5, -0.5], [1.0, 0.5, -0.5], [1.0, 0.5, 0.5], [1.0, -0.5, 0.5]]),
                             exact_horizon=True)
    image = shading.wrapped_light(quad, np.zeros(3), np.array([0.0, 0.0, 1.0]), 0.3)
    assert image.exact_horizon
