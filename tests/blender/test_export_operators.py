"""File > Export entries, headless: the LUT export operator writes what its options ask for (and refuses
a folder it must not overwrite, with the reason); the scene export operator writes a scene description."""
from __future__ import annotations

import json

import pytest

pytestmark = pytest.mark.blender


def test_export_luts_operator(registered, empty_scene, tmp_path):
    bpy = registered
    out = tmp_path / "engine_luts"
    assert bpy.ops.rtl.export_luts(directory=str(out), formats={"exr", "npz", "glsl"}, precisions={"f16"},
                                   layout="ltc_code") == {"FINISHED"}
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["layout"] == "ltc_code" and manifest["precisions"] == ["f16"]
    assert {"ltc_1_f16.exr", "ltc_2_f16.exr", "rtl_luts_f16.npz", "rtl_luts_f16.glsl"} <= set(manifest["files"])
    assert not any(name.endswith(".dds") for name in manifest["files"])
    busy = tmp_path / "busy"
    busy.mkdir()
    (busy / "mine.txt").write_text("x")
    with pytest.raises(RuntimeError, match="not an earlier LUT export"):
        bpy.ops.rtl.export_luts(directory=str(busy), formats={"npz"}, precisions={"f32"})
    assert sorted(p.name for p in busy.iterdir()) == ["mine.txt"]
    # the menu entry is there while the add-on is registered
    draw_funcs = [f.__name__ for f in bpy.types.TOPBAR_MT_file_export._dyn_ui_initialize()]
    assert "_menu_export" in draw_funcs


def test_export_scene_operator(registered, empty_scene, lut_dir, tmp_path):
    bpy = registered
    from rt_lookdev.core.export import scene as scene_io
    from rt_lookdev.core.materials.rt_lit_interface import Features
    from rt_lookdev.validation.harness import lit_scene

    lit_scene.build([("typical", Features("turquin", "cod"))], kinds=("quad", "sun"), lut_dir=lut_dir)
    assert bpy.ops.rtl.export_scene(directory=str(tmp_path / "scene")) == {"FINISHED"}
    desc = scene_io.read(tmp_path / "scene")
    assert desc.light_kinds == ("quad", "sun") and [o.name for o in desc.objects] == ["typical"]
