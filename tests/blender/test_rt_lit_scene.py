"""The RT Lit material in a scene: every light kind and a studio HDRI world through drivers, against
numpy; lights and world that move or change; save and reload without Python; folding by scene
content."""
from __future__ import annotations


import numpy as np
import pytest

from rt_lookdev.validation.harness import lit_scene as rt_lit_scene
from rt_lookdev.validation.harness.engines import render_cycles_passes, render_reloaded

pytest.importorskip("OpenEXR")

pytestmark = pytest.mark.blender

RTOL, ATOL, NEAR_ZERO = 1e-4, 1e-6, 1e-2


def _features():
    from rt_lookdev.core.materials.rt_lit_interface import Features

    return [("all", Features("kulla_conty", "wrapped", sheen=True, cloth=True)),
            ("typical", Features("turquin", "cod"))]


def _render_and_compare(scene, tables):
    p = render_cycles_passes(scene, (scene.render.resolution_x, scene.render.resolution_y))
    ref, hit = rt_lit_scene.numpy_radiance(scene, p, tables)
    got = p["Combined"]
    assert np.all(np.isfinite(got)) and np.all(np.isfinite(ref))
    err = np.abs(got - ref)
    big = np.abs(ref) >= NEAR_ZERO
    rel = float((err[big] / np.abs(ref[big])).max())
    absolute = float(err[~big].max())
    print(f"{hit.sum()} pixels, max {ref.max():.3g}: max rel {rel:.3g}, max abs near 0 {absolute:.3g}")
    assert hit.sum() > 1000 and ref.max() > 0.1
    assert rel <= RTOL and absolute <= ATOL
    return got, hit


def _set_material_values(scene):
    """Non-default material inputs, so every lobe and colour path carries weight."""
    values = {"all": {"Base Color": (0.7, 0.3, 0.2, 1.0), "Metallic": 0.3, "Roughness": 0.35, "Wrap": 0.4,
                      "Sheen Weight": 0.6, "Cloth Weight": 0.5, "Cloth Color": (0.5, 0.9, 0.6, 1.0)},
              "typical": {"Base Color": (0.2, 0.4, 0.9, 1.0), "Roughness": 0.6, "Specular IOR Level": 0.7}}
    for mat_name, vals in values.items():
        node = scene.objects[mat_name].data.materials[0].node_tree.nodes["RT Lit"]
        for k, v in vals.items():
            node.inputs[k].default_value = v


HDRI = "forest"        # the demo scene's: its bake is cached once per test session


def test_rt_lit_renders_like_numpy_and_follows_light_edits(empty_scene, lut_dir, tables):
    scene = rt_lit_scene.build(_features(), hdri=HDRI, lut_dir=lut_dir)
    _set_material_values(scene)
    before, hit = _render_and_compare(scene, tables)
    # move and resize lights: drivers carry the change, no sync needed
    quad, ellipse, spot = (scene.objects[n] for n in ("Quad", "Ellipse", "Spot"))
    quad.location = (2.4, -1.0, 2.2)
    rt_lit_scene.aim(quad)
    quad.scale = (1.5, 0.5, 1.0)
    ellipse.data.size = 2.0
    spot.data.energy = 800.0
    spot.data.spot_size = 1.3
    scene.objects["Sun"].data.color = (1.0, 0.5, 0.25)
    nodes = scene.world.node_tree.nodes
    nodes["Background"].inputs["Strength"].default_value = 1.3
    nodes["Mapping"].inputs["Rotation"].default_value = (0.4, -0.3, 2.5)
    after, _ = _render_and_compare(scene, tables)
    changed = np.abs(after - before).max(axis=-1) > 1e-3
    assert changed[hit].mean() > 0.3


def test_scene_reloads_without_python_and_renders_identically(empty_scene, lut_dir, tmp_path):
    import bpy

    scene = rt_lit_scene.build(_features(), hdri=HDRI, lut_dir=lut_dir)
    _set_material_values(scene)
    scene.world.node_tree.nodes["Mapping"].inputs["Rotation"].default_value = (0.0, 0.2, -1.0)
    res = (scene.render.resolution_x, scene.render.resolution_y)
    here = render_cycles_passes(scene, res)["Combined"]
    blend = tmp_path / "rt_lit.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(blend))
    there, info = render_reloaded(blend, res)
    assert info["drivers"] > 0 and info["simple"] and info["valid"] and not info["autoexec_fail"]
    print(f"max |reloaded - original| = {np.abs(there - here).max():.3g}")
    np.testing.assert_allclose(there, here, rtol=0, atol=1e-5)   # across processes: <= 8e-7 measured


def test_groups_carry_only_what_the_scene_and_material_need(empty_scene, lut_dir):
    import bpy

    from rt_lookdev.addon.node_emit import MAX_GROUP_NODES, tree_node_counts
    from rt_lookdev.core.materials.rt_lit_interface import Features, rt_lit_group_name

    scene = rt_lit_scene.build([("plain", Features("single", "lambert"))], kinds=("quad", "sun"), lut_dir=lut_dir)
    ng = bpy.data.node_groups[rt_lit_group_name(Features("single", "lambert"))]
    names = set(tree_node_counts(ng))
    assert any("Quad" in n for n in names) and any("Sun" in n for n in names)
    assert not any("Disk" in n or "Spot" in n or "Point" in n for n in names)     # no such lights
    assert not any(w in n for n in names for w in ("Sheen", "Cloth", "Kulla", "CoD", "Wrapped", "World",
                                                   "Environment"))         # no world image either
    assert not any(i.name.startswith("RTL_env_") for i in bpy.data.images)
    assert max(tree_node_counts(ng).values()) <= MAX_GROUP_NODES
    # a light added later joins after a sync; the group is rebuilt in place
    data = bpy.data.lights.new("Late", "POINT")
    data.shadow_soft_size = 0.0
    late = bpy.data.objects.new("Late", data)
    late.location = (0.0, -3.0, 0.0)
    scene.collection.objects.link(late)
    before = render_cycles_passes(scene, (48, 48))["Combined"]
    from rt_lookdev.addon.operators import RTL_OT_sync_lights

    bpy.utils.register_class(RTL_OT_sync_lights)
    try:
        assert bpy.ops.rtl.sync_lights() == {"FINISHED"}
    finally:
        bpy.utils.unregister_class(RTL_OT_sync_lights)
    assert any("Point" in n for n in tree_node_counts(ng))
    after = render_cycles_passes(scene, (48, 48))["Combined"]
    assert after.sum() > before.sum()


def test_lights_outside_the_render_are_not_shaded(empty_scene):
    """Lights disabled in renders, in a collection disabled in renders, or in a collection excluded from the
    view layer are left out (they used to be shaded: only the object's own hide_render was checked)."""
    import bpy

    from rt_lookdev.addon.materials import scene_lights

    scene = empty_scene

    def light(name, collection):
        obj = bpy.data.objects.new(name, bpy.data.lights.new(name, "POINT"))
        collection.objects.link(obj)
        return obj

    light("A shown", scene.collection)
    light("B hidden", scene.collection).hide_render = True
    off = bpy.data.collections.new("Off in renders")
    scene.collection.children.link(off)
    off.hide_render = True
    light("C in a collection off in renders", off)
    excluded = bpy.data.collections.new("Excluded")
    scene.collection.children.link(excluded)
    light("D in an excluded collection", excluded)
    bpy.context.view_layer.layer_collection.children["Excluded"].exclude = True
    assert [o.name for o, _ in scene_lights(scene)] == ["A shown"]
    bpy.context.view_layer.layer_collection.children["Excluded"].exclude = False
    assert [o.name for o, _ in scene_lights(scene)] == ["A shown", "D in an excluded collection"]


def test_more_lights_than_a_block_render_like_numpy_and_resync_only_what_changed(empty_scene, lut_dir, tables):
    """More lights than one block (``core.materials.rt_lit.LIGHT_BLOCK``): the RT Lit trees shade them in nested
    "RTL Lights" groups and render what numpy computes.  Sync Lights with nothing changed keeps the lights group; a
    light deleted and another made under its name gets drivers that read the new one, and the render is the same."""
    import bpy

    from rt_lookdev.addon import light_sync
    from rt_lookdev.core.materials.rt_lit import LIGHT_BLOCK

    def add_point(i):
        data = bpy.data.lights.new(f"Extra {i}", "POINT")
        data.energy, data.shadow_soft_size, data.color = 40.0 + 10.0 * i, 0.0, (1.0, 0.6 + 0.03 * i, 0.4)
        obj = bpy.data.objects.new(f"Extra {i}", data)
        obj.location = (2.5 * np.cos(0.7 * i), -2.5, 2.5 * np.sin(0.7 * i))
        scene.collection.objects.link(obj)

    scene = rt_lit_scene.build(_features()[1:], lut_dir=lut_dir)
    node = scene.objects["typical"].data.materials[0].node_tree.nodes["RT Lit"]
    node.inputs["Base Color"].default_value, node.inputs["Roughness"].default_value = (0.2, 0.4, 0.9, 1.0), 0.45
    extras = LIGHT_BLOCK + 4 - len([o for o in scene.objects if o.type == "LIGHT"])
    for i in range(extras):
        add_point(i)
    light_sync.sync_lights(scene, lut_dir)
    blocks = {n.node_tree.name for ng in bpy.data.node_groups for n in ng.nodes
              if n.bl_idname == "ShaderNodeGroup" and n.node_tree is not None and n.node_tree.name.startswith("RTL Lights")}
    assert len(blocks) >= 2                    # a full block and the rest
    before, _ = _render_and_compare(scene, tables)

    kept = bpy.data.node_groups["RTL Scene Lights"].session_uid
    light_sync.sync_lights(scene, lut_dir)
    assert bpy.data.node_groups["RTL Scene Lights"].session_uid == kept

    bpy.data.objects.remove(scene.objects["Extra 0"])
    add_point(0)
    light_sync.sync_lights(scene, lut_dir)
    lights_group = bpy.data.node_groups["RTL Scene Lights"]
    assert lights_group.session_uid != kept
    targets = {v.targets[0].id for fc in lights_group.animation_data.drivers for v in fc.driver.variables}
    assert None not in targets
    targets = {t for t in targets if t.name.startswith("Extra 0")}
    assert targets <= {scene.objects["Extra 0"], scene.objects["Extra 0"].data}
    after, _ = _render_and_compare(scene, tables)
    np.testing.assert_allclose(after, before, rtol=0, atol=1e-6)
