"""The talk's light controls on Blender lights (issue 17, item 4; addon/light_controls.py): range, cone falloff at
the projector apex, quad-to-spot fallback.  Switching a control changes the light's kind; the numbers are driven
from the light's custom properties, so RT Lit follows edits, and a saved file renders the same with Python auto-run
off; Cycles renders the falloffs as numpy computes them."""
from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("OpenEXR")

pytestmark = pytest.mark.blender

RANGE = {"rtl_use_range": True, "rtl_range": 5.5}
CONE = {"rtl_use_cone": True, "rtl_cone_inner": math.radians(60.0), "rtl_cone_outer": math.radians(80.0)}
FALLBACK = {"rtl_spot_fallback": True, "rtl_cone_inner": math.radians(100.0), "rtl_cone_outer": math.radians(120.0)}


def _case():
    from rt_lookdev.validation.checks import suite_cases as suite

    lights = [suite.LightSpec("quad", (1.5, -3.2, 1.6), 400.0, 1.6, 1.0, controls={**RANGE, **CONE}),
              suite.LightSpec("disk", (-2.5, -2.0, 1.0), 300.0, 1.0, controls=CONE),
              suite.LightSpec("point", (0.0, -2.5, 2.5), 300.0, controls=RANGE),
              suite.LightSpec("quad", (-1.0, -3.0, -1.5), 500.0, 1.2, 0.8, controls=dict(FALLBACK, rtl_use_range=True,
                                                                                        rtl_range=7.0))]
    variants = [suite.Variant("dielectric", 0.4), suite.Variant("cod", 0.6), suite.Variant("metal", 0.3)]
    return suite.Case("controls", lights, variants, columns=3)


def _passes_and_numpy(scene, case, tables):
    from rt_lookdev.validation.checks import suite_scene
    from rt_lookdev.validation.harness.engines import render_cycles_passes

    res = (scene.render.resolution_x, scene.render.resolution_y)
    passes = render_cycles_passes(scene, res)
    index = suite_scene.sphere_index(case, passes["Position"], passes["Normal"])
    objects = [scene.objects[f"RTL_val_sphere_{i}"] for i in range(len(case.variants))]
    b = suite_scene.numpy_radiance(scene, case.variants, objects, passes, index, tables)
    return passes["Combined"].astype(np.float64), b, index >= 0


def test_controls_choose_the_kind(empty_scene, registered):
    import bpy

    from rt_lookdev.addon import light_controls, materials

    data = bpy.data.lights.new("L", "AREA")
    obj = bpy.data.objects.new("L", data)
    assert materials.light_kind(obj) == "quad"
    data.rtl_use_range = True
    assert materials.light_kind(obj) == "quad+range"
    data.rtl_use_cone = True
    assert materials.light_kind(obj) == "quad+cone+range"
    data.rtl_spot_fallback = True                  # the fallback has its cone built in
    assert materials.light_kind(obj) == "quad_spot+range"
    data.shape = "DISK"                           # no fallback for disks
    assert materials.light_kind(obj) == "disk+cone+range"
    sun = bpy.data.objects.new("S", bpy.data.lights.new("S", "SUN"))
    sun.data.rtl_use_range = True                 # no range for the sun
    assert materials.light_kind(sun) == "sun_disk"    # Blender's sun has an angle (0.53 deg)
    sun.data.angle = 0.0
    assert materials.light_kind(sun) == "sun"
    # the panel's poll and the stored values the drivers read
    assert light_controls.value(data, "rtl_cone_outer") == pytest.approx(math.radians(100.0))
    light_controls.store_driven_values(data)
    assert set(light_controls.DRIVEN) <= set(data.keys())


def test_controls_render_like_numpy_follow_edits_and_reload_without_python(empty_scene, lut_dir, tables, tmp_path):
    import bpy

    from rt_lookdev.addon import materials
    from rt_lookdev.validation.checks import suite_cases as suite
    from rt_lookdev.validation.checks import suite_metrics
    from rt_lookdev.validation.checks import suite_scene
    from rt_lookdev.validation.harness.engines import render_reloaded

    case = _case()
    scene, _ = suite_scene.build_scene(case, 40, 48, 24, lut_dir)
    kinds = [kind for _, kind in materials.scene_lights(scene)]
    assert kinds == ["quad+cone+range", "disk+cone", "point+range", "quad_spot+range"]
    a, b, hit = _passes_and_numpy(scene, case, tables)
    metrics = suite_metrics.ab_metrics(a, b, hit)
    print(f"controls: (a) vs (b) max rel {metrics['max_rel']:.2e}, max abs near 0 {metrics['max_abs_near_zero']:.2e}")
    assert metrics["finite"] and b[hit].max() > 0.1
    assert metrics["max_rel"] <= 1e-4 and metrics["max_abs_near_zero"] <= 1e-6
    # the falloffs do something: without them (the same lights plain) the image differs
    plain = [suite.LightSpec(s.kind, s.location, s.energy, s.size, s.size_y) for s in case.lights]
    scene_plain, _ = suite_scene.build_scene(suite.Case("plain", plain, case.variants, columns=3), 40, 48, 24, lut_dir)
    _, b_plain, _ = _passes_and_numpy(scene_plain, case, tables)
    assert np.abs(b_plain - b)[hit].max() > 0.05

    scene, _ = suite_scene.build_scene(case, 40, 48, 24, lut_dir)
    # an edit of a driven control needs no sync: the drivers carry it
    bpy.data.lights["L0_quad"]["rtl_range"] = 3.0
    bpy.data.lights["L1_disk"]["rtl_cone_outer"] = math.radians(50.0)
    bpy.context.view_layer.update()
    a2, b2, _ = _passes_and_numpy(scene, case, tables)
    assert np.abs(b2 - b)[hit].max() > 0.05
    assert suite_metrics.ab_metrics(a2, b2, hit)["max_rel"] <= 1e-4
    blend = tmp_path / "controls.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(blend))
    there, info = render_reloaded(blend, (scene.render.resolution_x, scene.render.resolution_y))
    assert info["drivers"] > 0 and info["simple"] and info["valid"] and not info["autoexec_fail"]
    np.testing.assert_allclose(there, a2, rtol=0, atol=1e-5)
