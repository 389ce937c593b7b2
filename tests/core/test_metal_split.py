"""Metal and dielectric apart (issue 17, item 5): under every light kind a partly metallic surface is the
Metallic mix of its dielectric and its metal, each shaded with its own F0, for the multiple-scattering models
whose compensation is non-linear in F0 (as the World term already was; docs/conventions.md)."""
from __future__ import annotations

import numpy as np
import pytest

from rt_lookdev.core.lut import lookup
from rt_lookdev.core.materials import light_shading, rt_lit
from rt_lookdev.core.materials.rt_lit_interface import SPECULAR_MODELS, Features
from rt_lookdev.validation.harness import grids

KINDS = ("quad", "disk", "point", "spot", "sun")


def _at_metallic(values, m):
    out = dict(values)
    out["Metallic"] = np.full_like(values["Metallic"], m)
    return out


@pytest.mark.parametrize("specular", [s for s in SPECULAR_MODELS if s != "none"])
def test_partly_metallic_is_the_mix_of_dielectric_and_metal(lut_dir, specular):
    """Radiance is linear in Metallic: R(m) = (1 - m) R(0) + m R(1) (the diffuse albedo is base x (1 - m)),
    with each end shaded with its own F0.  A mixed F0 fed to Turquin's 1 + F0 (1 - E)/E breaks it."""
    tables = lookup.LutSet.from_folder(lut_dir)
    material = rt_lit.build_rt_lit(Features(specular, "cod", cloth=True, sheen=True), KINDS)
    values = grids.material_inputs(material, size=24)
    m = np.random.default_rng(3).uniform(0.1, 0.9, values["Metallic"].shape).astype(np.float32)
    got = material.evaluate(_at_metallic(values, 0.0) | {"Metallic": m}, tables, np.float64)["Radiance"]
    dielectric = material.evaluate(_at_metallic(values, 0.0), tables, np.float64)["Radiance"]
    metal = material.evaluate(_at_metallic(values, 1.0), tables, np.float64)["Radiance"]
    want = (1.0 - m)[..., None] * dielectric + m[..., None] * metal
    assert np.all(np.isfinite(got)) and np.abs(want).max() > 0.1
    # float64 evaluation of float32 inputs and constants (Blender's sockets): agreement to ~1e-7 relative;
    # a mixed F0 misses by > 1e-2 (the next test)
    np.testing.assert_allclose(got, want, rtol=1e-6, atol=1e-9)


def test_the_mixed_f0_would_be_wrong_for_turquin(lut_dir):
    """The check above has teeth: shading Turquin with the mixed F0 (what RT Lit's lights did before) differs
    from the mix by more than 1% on a white rough metal-dielectric blend."""
    tables = lookup.LutSet.from_folder(lut_dir)
    features = Features("turquin", "lambert")
    lobe = light_shading.shade_function("sun", features)
    n = np.array([[0.0, 0.0, 1.0]])
    v = np.array([[0.0, np.sin(1.2), np.cos(1.2)]])
    l = np.array([[0.0, -np.sin(0.5), np.cos(0.5)]])
    surface = {"N": n, "V": v, "L": l, "Roughness": np.array([0.9]), "Albedo": np.zeros((1, 3)),
               "Wrap": np.zeros(1), "Sheen Color": np.zeros((1, 3)), "Cloth Weight": np.zeros(1),
               "Cloth Color": np.zeros((1, 3)), "Irradiance": np.ones((1, 3)),
               "Dielectric F0": np.full((1, 3), 0.04), "Metal F0": np.ones((1, 3)), "Metallic": np.array([0.5])}
    split = lobe(tables, **{k: surface[k] for k in lobe.input_sockets})["Radiance"]
    ggx = light_shading.lobes.LOBES["ggx"].punctual(tables, n, v, l, np.array([0.9]))
    mixed_f0 = 0.52
    mixed = (mixed_f0 * ggx["Scale"] + ggx["Bias"]) * (1.0 + mixed_f0 * (1.0 - ggx["E"]) / ggx["E"])
    assert abs(split[0, 0] / mixed[0] - 1.0) > 0.01


@pytest.mark.parametrize("specular,reads", [("single", {"F0"}), ("none", set()),
                                            ("turquin", {"Dielectric F0", "Metal F0", "Metallic"}),
                                            ("kulla_conty", {"Dielectric F0", "Metal F0", "Metallic"})])
def test_each_model_reads_the_f0_it_needs(specular, reads):
    """Single scattering is linear in F0 and keeps the one mixed F0 (fewer nodes); the split models read both."""
    fn = light_shading.shade_function("quad", Features(specular, "lambert"))
    f0_inputs = {"F0", "Dielectric F0", "Metal F0", "Metallic"} & set(fn.input_sockets)
    assert f0_inputs == reads
