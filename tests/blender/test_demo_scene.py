"""The demo lookdev scene: builds, renders finite, reloads without Python and renders identically,
and its Principled materials survive the round trip through RT Lit."""
from __future__ import annotations


import numpy as np
import pytest

pytest.importorskip("OpenEXR")

pytestmark = pytest.mark.blender


def _principled_values(bsdf):
    out = {}
    for sock in bsdf.inputs:
        if hasattr(sock, "default_value"):
            v = sock.default_value
            out[sock.name] = tuple(v) if hasattr(v, "__len__") else v
    return out


def test_demo_scene_round_trips_and_reloads(empty_scene, lut_dir, tmp_path):
    import bpy

    from rt_lookdev.addon import convert
    from rt_lookdev.addon import demo_scene as build_demo_scene
    from rt_lookdev.validation.harness.engines import render_cycles_passes, render_reloaded

    spheres = build_demo_scene.build_demo_scene(lut_dir, resolution=80)
    scene = bpy.context.scene
    res = (scene.render.resolution_x, scene.render.resolution_y)
    assert len(spheres) == 15 and all(convert.is_rt_lit_material(bpy.data.materials[n]) for n in spheres)
    here = render_cycles_passes(scene, res)["Combined"]
    assert np.isfinite(here).all() and here.max() > 0.5

    blend = tmp_path / "demo.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(blend))
    there, info = render_reloaded(blend, res)
    assert not info["autoexec_fail"]
    print(f"demo reloaded in a fresh process: max |difference| {np.abs(there - here).max():.3g}")
    np.testing.assert_allclose(there, here, rtol=0, atol=1e-5)

    # back to Principled: every input equals what the demo built it with
    for name in spheres:
        mat = bpy.data.materials[name]
        kept = convert.kept_principled(mat.node_tree)
        before = _principled_values(kept)
        result = convert.rt_lit_to_principled(mat)
        assert result.status == "converted"
        bsdf = next(n for n in mat.node_tree.nodes if n.bl_idname == "ShaderNodeBsdfPrincipled")
        after = _principled_values(bsdf)
        for key, value in before.items():
            assert np.allclose(after[key], value, atol=1e-7), (name, key, after[key], value)
        assert not convert.is_rt_lit_material(mat)
    row = build_demo_scene.ROWS[1]
    metal = bpy.data.materials["metal r0.25"].node_tree.nodes
    bsdf = next(n for n in metal if n.bl_idname == "ShaderNodeBsdfPrincipled")
    assert bsdf.inputs["Metallic"].default_value == row[1]["Metallic"]
    assert bsdf.inputs["Roughness"].default_value == pytest.approx(0.25)
