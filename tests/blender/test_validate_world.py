"""CI subset of scripts/validate_world.py (``--quick``): the RT Lit World term under one studio HDRI.

One world (forest, rotated by the Mapping node's Euler XYZ (0.3, -0.2, 1.2) rad, strength 1.3), a node
block of Lambert, CoD and F0 = 1 specular spheres (r = 0.25, 0.75) at 24 px per cell, its Cycles closures
at 256 spp x 2 seeds, and the white furnace.  Asserts:

- (a) = (b): node render = numpy evaluation of the same IR, 1e-4 relative where |b| >= 1e-2 and 1e-6
  absolute below (values within 4x their float32 conditioning allowed, as scripts/validate.py);
- furnace: every multiscattering split sum with F0 = 1 (Turquin, Fdez-Aguera in both forms) and Lambert
  give 1 +- 0.005 under a constant white Environment Texture, for r in {0, 0.25, 0.5, 0.75, 1}, node
  render and numpy;
- Lambert vs Cycles Diffuse BSDF: the harness (the Lambert integral summed over the image's texels vs
  Cycles) within noise, which pins the equirect mapping, the Euler rotation and the strength; and the
  L2 SH Lambert within its truncation error (median measured 2.2% here; bound 6%);
- the talk's SH-LTC CoD lobe beats "magnitude only" against the brute force under the SH environment.
Runs in about 25 s on 2 cores (10 s of it the bake of the 1024 x 512 HDRI, skipped when the shared
cache of tests/conftest.py holds it).
"""
from __future__ import annotations

import os

import pytest

pytest.importorskip("OpenEXR")

pytestmark = pytest.mark.blender

LAMBERT_MEDIAN = 0.06          # SH truncation (forest, rotated): measured median 2.2%, mean 4.1%
HARNESS_MEDIAN = 0.025         # texel-sum Lambert vs Cycles at 256 spp x 2: noise (median 1.0-1.1%)


@pytest.fixture(scope="module")
def world_validation(tmp_path_factory, lut_dir, bpy_module):
    from rt_lookdev.validation.checks import world_suite as validate_world

    out = tmp_path_factory.mktemp("validation_world")
    argv = ["--quick", "--no-bake-timing", "--out", str(out), "--lut-dir", str(lut_dir),
            "--harness-lambert-median", str(HARNESS_MEDIAN)]
    if os.environ.get("RTL_ENVIRONMENT_CACHE"):           # tests/conftest.py: the shared bake cache
        argv += ["--cache", os.environ["RTL_ENVIRONMENT_CACHE"]]
    args = validate_world.parse_args(argv)
    return validate_world.run(args, log=lambda s: None), out


def test_outputs_written(world_validation):
    result, out = world_validation
    for name in ("report.json", "report.md", "report.html"):
        assert (out / name).stat().st_size > 0
    for w in result["worlds"]:
        for png in w["png"].values():
            assert (out / png).read_bytes()[:4] == b"\x89PNG"


def test_node_render_equals_numpy(world_validation):
    result, _ = world_validation
    cases = result["worlds"] + [dict(result["furnace"], name="furnace")]
    for case in cases:
        ab = case["ab"]
        assert ab["finite"], case["name"]
        assert ab["max_rel_beyond_float32"] <= 1e-4, (case["name"], ab)
        assert ab["max_abs_near_zero_beyond_float32"] <= 1e-6, (case["name"], ab)


def test_furnace(world_validation):
    result, _ = world_validation
    rows = [r for r in result["furnace"]["variants"] if r["gated"]]
    assert {r["technique"] for r in rows} >= {"lambert", "turquin", "fdez_aguera", "fdez_aguera_radiance"}
    assert {r["roughness"] for r in rows if r["technique"] == "turquin"} == {0.0, 0.25, 0.5, 0.75, 1.0}
    for r in rows:
        assert r["max_abs_dev"] <= 0.005, r


def test_lambert_vs_cycles(world_validation):
    result, _ = world_validation
    (world,) = result["worlds"]
    harness = world["lambert"]["image_vs_cycles"]
    assert harness["median"] <= HARNESS_MEDIAN, harness
    e = next(v for v in world["variants"] if v["technique"] == "lambert")
    assert e["truth_metrics"]["median"] <= LAMBERT_MEDIAN, e["truth_metrics"]


def test_sh_ltc_beats_magnitude_only(world_validation):
    result, _ = world_validation
    (world,) = result["worlds"]
    p = world["cod"]["pooled"]
    assert p["ltc_vs_ref_sh"]["mean"] < p["mag_vs_ref_sh"]["mean"], p
    assert p["node_vs_ltc_numpy"]["max"] <= 1e-4, p["node_vs_ltc_numpy"]


def test_gates_passed(world_validation):
    result, _ = world_validation
    assert result["passed"], [c for c in result["checks"] if not c["ok"]]


#: Issue 33: a plain-colour world (every new file's) against Cycles, RT Lit's Lambert and F = 1 GGX spheres
#: (measured at full size, `python scripts/validate_world.py --node-world plain`: Lambert median 0.00%, GGX
#: medians 0.01-0.09%, p90 <= 0.21%).
PLAIN_MEDIAN = 0.005


@pytest.fixture(scope="module")
def node_worlds(tmp_path_factory, lut_dir, bpy_module):
    """``--quick --node-world plain --node-world mix``: a plain-colour world (baked as a constant, no render) and a
    Mix-node world (baked from Cycles' panoramic render of it)."""
    from rt_lookdev.validation.checks import world_suite as validate_world

    from rt_lookdev.addon import world_sync

    out = tmp_path_factory.mktemp("validation_node_worlds")
    argv = ["--quick", "--no-bake-timing", "--skip-furnace", "--node-world", "plain", "--node-world", "mix",
            "--lambert-image", "256", "--ggx-image", "256",
            "--out", str(out), "--lut-dir", str(lut_dir), "--harness-lambert-median", str(HARNESS_MEDIAN)]
    with pytest.MonkeyPatch.context() as patch:      # the smooth Mix world rendered at 256 x 128: its bake in 2 s
        patch.setattr(world_sync, "RENDER_WIDTH", 256)
        return validate_world.run(validate_world.parse_args(argv), log=lambda s: None)


@pytest.mark.development_release_only
def test_plain_and_mix_worlds_shade_as_cycles(node_worlds):
    """In the development release only (a minute of Cycles; 4.5 renders worlds through the same panoramic camera,
    test_world_setup.py's layout test runs there).  Issue 33: RT Lit objects under a plain-colour world rendered black (Sync World refused it); a Mix-node world
    was refused too.  Both are baked now, and the harness (the baked image's Lambert integral against Cycles'
    Diffuse BSDF) is within noise for each, which pins the render's layout; the plain world's Lambert and GGX
    spheres are within 0.5% of Cycles; (a) node render = (b) numpy."""
    worlds = {w["name"]: w for w in node_worlds["worlds"]}
    assert set(worlds) == {"plain", "mix"}
    assert node_worlds["passed"], [c for c in node_worlds["checks"] if not c["ok"]]
    for world in worlds.values():
        assert world["lambert"]["image_vs_cycles"]["median"] <= HARNESS_MEDIAN, world["name"]
    for v in worlds["plain"]["variants"]:
        if v["technique"] in ("lambert", "ggx"):
            assert v["truth_metrics"]["median"] <= PLAIN_MEDIAN, (v["technique"], v["roughness"], v["truth_metrics"])
    assert worlds["plain"]["source"] == "constant" and worlds["mix"]["source"] == "render"
