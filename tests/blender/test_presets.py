"""The lookdev presets as assets (addon/preset_assets.py, core/materials/presets.py, assets/)."""
import numpy as np
import pytest

pytestmark = pytest.mark.blender


def _load_library(bpy, names=None):
    from rt_lookdev.addon import preset_assets as presets

    with bpy.data.libraries.load(str(presets.LIBRARY_FILE), link=False, assets_only=True) as (src, dst):
        dst.materials = list(src.materials) if names is None else list(names)
    return list(dst.materials)


def test_shipped_library_holds_every_preset_with_its_catalog(bpy_module, empty_scene):
    """The .blend and the catalog file in assets/ are what scripts/build_presets.py makes from the core's list
    (rebuild them after editing core/materials/presets.py)."""
    from rt_lookdev.addon import preset_assets as presets
    from rt_lookdev.core.materials import presets as core_presets
    from rt_lookdev.core.materials.rt_lit_interface import Features

    assert presets.CATALOG_FILE.read_text() == presets.catalog_text()
    loaded = {m.name: m for m in _load_library(bpy_module)}
    assert set(loaded) == {p.name for p in core_presets.PRESETS}
    for preset in core_presets.PRESETS:
        mat = loaded[preset.name]
        assert mat.asset_data is not None
        assert mat.asset_data.catalog_id == core_presets.CATALOG_IDS[preset.catalog]
        # compared as switches: a library built before the sheen models stores "sheen": False, which reads as
        # "none" (Features keeps old switches' meaning), so it need not be rebuilt for them
        stored = dict(mat[presets.PRESET_KEY]["features"])
        assert Features.from_dict(stored) == preset.features and set(stored) == set(preset.features.as_dict())
        bsdf = next(n for n in mat.node_tree.nodes if n.bl_idname == "ShaderNodeBsdfPrincipled")
        for key, value in preset.principled.items():
            assert np.allclose(np.ravel(bsdf.inputs[key].default_value), np.ravel(value), atol=1e-6), (preset.name, key)
    assert {"Metals", "Dielectrics", "Fabrics"} <= {p.catalog for p in core_presets.PRESETS}


def test_enabling_the_extension_lists_the_library_in_the_asset_browser(bpy_module, empty_scene):
    import rt_lookdev
    from rt_lookdev.addon import preset_assets as presets

    libraries = bpy_module.context.preferences.filepaths.asset_libraries

    def entries():
        return [lib for lib in libraries if lib.name == presets.LIBRARY_NAME]

    assert not entries()
    rt_lookdev.register()
    try:
        (lib,) = entries()
        assert lib.path.rstrip("/") == str(presets.ASSETS_DIR)
        rt_lookdev.unregister()
        rt_lookdev.register()                      # once, however often it is enabled
        assert len(entries()) == 1
    finally:
        rt_lookdev.unregister()
    assert not entries()


def _render(bpy, scene):
    from rt_lookdev.validation.harness.engines import render_cycles_passes

    return render_cycles_passes(scene, (96, 48))["Combined"]


def test_a_dropped_preset_becomes_an_rt_lit_material_that_renders_as_one_converted_in_the_scene(registered, empty_scene):
    """Appending a preset and assigning it converts it at the next depsgraph update, for the scene's lights
    and world: it renders exactly as the same Principled values converted in the scene with the same switches."""
    from rt_lookdev.addon import convert, lookdev_scene, materials
    from rt_lookdev.addon import preset_assets as presets
    from rt_lookdev.core.materials import presets as core_presets

    bpy = registered
    scene = lookdev_scene.new_lookdev_scene("Presets", hdri="studio", view_transform="Standard")
    bpy.context.window.scene = scene               # the handler syncs the active scene
    target = bpy.data.objects["Presets Gold r0.25"]
    for obj in lookdev_scene.lookdev_spheres(scene):
        if obj is not target:
            obj.hide_render = True

    for name in ("RTL Copper", "RTL Cotton", "RTL Skin Wrap"):
        preset = core_presets.by_name(name)
        (appended,) = _load_library(bpy, [name])
        assert presets.PRESET_KEY in appended and not convert.is_rt_lit_material(appended)
        target.material_slots[0].material = appended
        bpy.context.view_layer.update()              # the handler converts it
        assert convert.is_rt_lit_material(appended) and presets.PRESET_KEY not in appended
        assert convert.stored_features(appended) == preset.features
        dropped = _render(bpy, scene)

        by_hand = lookdev_scene.principled_material(name + " by hand", preset.principled)
        convert.principled_to_rt_lit(by_hand, lambda f: materials.ensure_rt_lit_group(f, scene), preset.features)
        node = by_hand.node_tree.nodes["RT Lit"]
        for key, value in preset.rt_lit.items():
            node.inputs[key].default_value = value
        target.material_slots[0].material = by_hand
        reference = _render(bpy, scene)
        assert reference.max() > 0.05
        assert np.array_equal(dropped, reference), name


def test_presets_in_the_library_file_itself_are_not_converted(registered, empty_scene):
    """Only presets in use are converted: the library's own materials (fake users) stay Principled."""
    from rt_lookdev.addon import preset_assets as presets

    loaded = _load_library(registered)
    registered.context.view_layer.update()
    assert all(presets.PRESET_KEY in m for m in loaded)
    assert presets.pending_presets() == []
