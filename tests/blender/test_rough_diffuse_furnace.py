"""Cycles' rough diffuse is the model RT Lit's "oren_nayar" implements, in the Blender release under test: a small
white-furnace render (validation/checks/rough_diffuse_furnace.py) of a white Diffuse BSDF with Roughness 1 (energy
preserved: 1, where Fujii's Oren-Nayar alone gives 0.78 to 0.94) and a Principled BSDF with Diffuse Roughness 1 and
base colour 0.5 (Cycles' rho x rho_ms, EON's rho_ms is 2.5-6% brighter), bin by bin within the render's noise."""
from __future__ import annotations

import pytest

pytest.importorskip("OpenEXR")

pytestmark = pytest.mark.blender


#: The colour rule of Cycles' rough diffuse per release, measured with this furnace: 4.5 LTS and 5.2 LTS weight EON's
#: multiple scattering by the albedo once more (rho x rho_ms, what RT Lit's "oren_nayar" computes); 5.3 renders EON's
#: own rho_ms, 1-5.5% brighter at rho = 0.5, sigma = 1 than RT Lit (docs/rough_diffuse.md, "Blender 5.3").
COLOUR_RULE = {(4, 5): "cycles", (5, 2): "cycles", (5, 3): "eon"}


def test_furnace_identifies_cycles_rough_diffuse(empty_scene, tmp_path):
    import bpy

    from rt_lookdev.validation.checks import rough_diffuse_furnace as furnace

    cases = (("diffuse rho=1 sigma=1", "diffuse", 1.0, 1.0), ("principled rho=0.5 sigma=1", "principled", 0.5, 1.0))
    res = furnace.measure(cases, resolution=40, samples=16, out_dir=tmp_path, log=lambda s: None)
    white, grey = res["cases"]
    for row in white["bins"]:
        assert row["rendered"] == pytest.approx(1.0, abs=4 * row["se"] + 5e-4)
        assert row["fon"] < row["rendered"] - 0.04
    rule = COLOUR_RULE.get(tuple(bpy.app.version[:2]), "cycles")
    assert grey["best"] == [rule]
    other = "eon" if rule == "cycles" else "cycles"
    for row in grey["bins"]:
        assert row[rule] == pytest.approx(row["rendered"], abs=4 * row["se"] + 5e-4)
        assert abs(row[other] - row["rendered"]) > 0.005
