"""Cycles white-furnace check of the GGX energy tables (fast version of scripts/validate_energy.py).

Spheres under a uniform white world, orthographic camera, white Glossy BSDF:
- 'GGX': every pixel is E(mu = N.V, r); per mu bin (mu >= 0.1) the mean of pixel - E from our
  LUT must lie within Z_MAX standard errors (noise estimated from two seeds) plus the small
  systematic floor SYS_TOL, and the overall mean bias below 1e-3;
- 'Multiscatter GGX': every mu bin (mu >= 0.1) averages to 1 +- 0.005.
"""
from __future__ import annotations

import json

import pytest

pytest.importorskip("OpenEXR")

from rt_lookdev.validation.checks import energy_render as ve  # noqa: E402

pytestmark = pytest.mark.blender

ROUGHNESS = (0.25, 1.0)
RESOLUTION = 96        # pixels per sphere cell: ~6000 sphere pixels each
SAMPLES = 128          # per-bin standard errors 1e-4 .. 6e-4 (GGX), far inside 0.005 (MS)


@pytest.fixture(scope="module")
def validation(bpy_module, lut_dir, tmp_path_factory):
    out = tmp_path_factory.mktemp("energy_render")
    res = ve.measure(resolution=RESOLUTION, samples=SAMPLES, roughness=ROUGHNESS, out_dir=out,
                 lut_dir=lut_dir, exact=False, keep_exr=False, log=lambda *a: None)
    print(ve.format_table(res))
    return res, out


def _judged(bins):
    return [b for b in bins if b.get("judged")]


@pytest.mark.parametrize("r", ROUGHNESS)
def test_ggx_pixels_match_energy_table(validation, r):
    res, _ = validation
    e = res["GGX"][f"{r:g}"]
    bins = _judged(e["bins"])
    assert len(bins) == 9 and all(b["n"] >= 100 for b in bins), [b["n"] for b in bins]
    for b in bins:
        bound = ve.Z_MAX * b["se"] + ve.SYS_TOL
        assert abs(b["bias"]) <= bound, (r, b)
    assert abs(e["mean_bias"]) <= ve.ABS_BIAS_TARGET, e["mean_bias"]
    assert e["ok"]


@pytest.mark.parametrize("r", ROUGHNESS)
def test_multiscatter_ggx_is_white(validation, r):
    res, _ = validation
    e = res["MULTI_GGX"][f"{r:g}"]
    for b in _judged(e["bins"]):
        assert abs(b["mean"] - 1.0) <= ve.MS_TOL, (r, b)
        # the bound is meaningful only if the noise is well inside it
        assert b["se"] < ve.MS_TOL / 5, (r, b)
    assert abs(e["mean"] - 1.0) <= ve.MS_TOL
    assert e["ok"]


def test_normal_pass_is_the_sphere_normal(validation):
    """The Normal pass of the 256x128 smooth sphere is the true sphere normal to a fraction of a degree."""
    res, _ = validation
    for check in res["normal_check"].values():
        assert check["angle_deg_mean"] < 0.05, check
        assert abs(check["mu_pass_minus_analytic_mean"]) < 1e-3, check


def test_results_written(validation):
    res, out = validation
    data = json.loads((out / "energy_validation.json").read_text())
    assert data["passed"] is True and res["passed"] is True
    s = data["settings"]
    assert s["samples"] == SAMPLES and s["threads"] == 2 and s["view_transform"] == "Standard"
    assert s["filter"][0] == "GAUSSIAN" and s["filter"][1] <= 0.0101
