"""The real-time backend end to end: a Blender scene with every light kind and a studio HDRI world,
exported (addon/scene_export.py) and drawn by the standalone GLSL renderer, equals Cycles' render of its
RT Lit node groups (targets of validation/checks/demo_measure: median <= 1e-4, p99 <= 1e-3 relative); the
export refuses a scene it cannot describe, saying what to change."""
from __future__ import annotations

import numpy as np
import pytest

from rt_lookdev.validation.harness import lit_scene as rt_lit_scene

pytest.importorskip("OpenEXR")

pytestmark = [pytest.mark.blender, pytest.mark.glsl]


@pytest.fixture
def gl_available():
    from rt_lookdev.validation.harness import glsl_runner

    ok, why = glsl_runner.available()
    if not ok:
        pytest.skip(why)


def test_exported_scene_draws_like_cycles(empty_scene, gl_available, lut_dir, tmp_path):
    from rt_lookdev.addon import scene_export
    from rt_lookdev.core.materials.rt_lit_interface import Features
    from rt_lookdev.validation.checks.demo_measure import GLSL_MEDIAN_TOL, GLSL_P99_TOL
    from rt_lookdev.validation.harness.engines import compare, render_cycles_passes
    from rt_lookdev.validation.harness.realtime_render import RealtimeRenderer

    scene = rt_lit_scene.build([("all", Features("kulla_conty", "wrapped", sheen=True, cloth=True)),
                                ("typical", Features("turquin", "cod"))], resolution=64, hdri="forest", lut_dir=lut_dir)
    node = scene.objects["all"].data.materials[0].node_tree.nodes["RT Lit"]
    for k, v in {"Base Color": (0.7, 0.3, 0.2, 1.0), "Metallic": 0.3, "Roughness": 0.35, "Wrap": 0.4,
                 "Sheen Weight": 0.6, "Cloth Weight": 0.5}.items():
        node.inputs[k].default_value = v
    size = (scene.render.resolution_x, scene.render.resolution_y)
    cycles = render_cycles_passes(scene, size)["Combined"]
    desc = scene_export.export_scene(scene, tmp_path / "export", lut_dir)
    assert desc.light_kinds == ("disk", "point", "quad", "spot", "sun")
    assert desc.materials["all"].inputs["Wrap"] == pytest.approx(0.4) and desc.world is not None
    with RealtimeRenderer(desc) as renderer:
        image = renderer.render()
    stats = compare(cycles, image, positive_floor=1e-3)
    covered = (cycles.max(-1) > 0) != (image.max(-1) > 0)
    print(f"GLSL vs Cycles: median {stats['median']:.2e}, p99 {stats['p99']:.2e}, max {stats['max']:.2e}; "
          f"{covered.sum()} pixels covered by one only")
    assert np.isfinite(image).all() and stats["count"] > 3000
    assert stats["median"] <= GLSL_MEDIAN_TOL and stats["p99"] <= GLSL_P99_TOL
    assert covered.sum() <= 0.005 * (cycles.max(-1) > 0).sum()


def test_the_web_viewer_draws_the_exported_scene_like_cycles(empty_scene, lut_dir, tmp_path):
    """Issue 32, item 3: the scene above, exported as a web bundle (core/export/web_scene.py) and drawn by the viewer
    (engines/viewer, plain WebGL2) in headless Chromium on SwiftShader, against Cycles' render of its RT Lit node
    groups: median <= 1e-3, p99 <= 1e-2 relative (the issue's targets; GLSL ES has no `precise`, so the driver may
    fuse and reorder what the GLSL 4.50 renderer above keeps in numpy's order)."""
    import os

    from rt_lookdev.addon import scene_export
    from rt_lookdev.core.export import web_scene
    from rt_lookdev.core.materials.rt_lit_interface import Features
    from rt_lookdev.validation.harness import three_browser
    from rt_lookdev.validation.harness.engines import compare, render_cycles_passes

    why = three_browser.missing()
    if why:
        if os.environ.get("CI", "").lower() == "true":
            pytest.fail(f"{why} (CI installs it: .ci/run, scripts/env.sh)")
        pytest.skip(why)
    scene = rt_lit_scene.build([("all", Features("kulla_conty", "wrapped", sheen=True, cloth=True)),
                                ("typical", Features("turquin", "cod"))], resolution=64, hdri="forest", lut_dir=lut_dir)
    size = (scene.render.resolution_x, scene.render.resolution_y)
    cycles = render_cycles_passes(scene, size)["Combined"]
    desc = scene_export.export_scene(scene, tmp_path / "export", lut_dir)
    draw = web_scene.write_web(tmp_path / "web", desc)
    assert len(draw["programs"]) == 2 and [o["name"] for o in draw["objects"]] == [o.name for o in desc.objects]
    image, info = three_browser.render_viewer(tmp_path / "web")
    stats = compare(cycles, image, positive_floor=1e-3)
    covered = (cycles.max(-1) > 0) != (image.max(-1) > 0)
    print(f"viewer ({info['renderer']}) vs Cycles: median {stats['median']:.2e}, p99 {stats['p99']:.2e}, "
          f"max {stats['max']:.2e}; {covered.sum()} pixels covered by one only")
    assert np.isfinite(image).all() and stats["count"] > 3000
    assert stats["median"] <= 1e-3 and stats["p99"] <= 1e-2
    assert covered.sum() <= 0.005 * (cycles.max(-1) > 0).sum()


def test_export_refuses_what_it_cannot_describe(empty_scene, lut_dir, tmp_path):
    import bpy

    from rt_lookdev.addon import scene_export
    from rt_lookdev.core.materials.rt_lit_interface import Features

    scene = rt_lit_scene.build([("typical", Features("turquin", "cod"))], kinds=("quad",), lut_dir=lut_dir)
    folder = tmp_path / "export"
    cam = scene.camera
    scene.camera = None
    with pytest.raises(scene_export.SceneExportError, match="no camera"):
        scene_export.export_scene(scene, folder)
    scene.camera = cam
    cam.data.type = "PANO"
    with pytest.raises(scene_export.SceneExportError, match="PANO"):
        scene_export.export_scene(scene, folder)
    cam.data.type = "ORTHO"
    extra = bpy.data.objects.new("Extra Sun", bpy.data.lights.new("Extra Sun", "SUN"))
    scene.collection.objects.link(extra)
    with pytest.raises(scene_export.SceneExportError, match="Sync Lights"):
        scene_export.export_scene(scene, folder)
    bpy.data.objects.remove(extra)
    assert not folder.exists()                     # nothing written by a refused export
    desc = scene_export.export_scene(scene, folder)
    assert [o.name for o in desc.objects] == ["typical"] and desc.light_kinds == ("quad",)
