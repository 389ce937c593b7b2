"""Light shadows on RT Lit (addon/shadows.py): Heitz, Hill & McGuire 2018's ratio estimator in a Cycles F12
render.  A floor under a box that hangs in the air (seen by shadow rays only, so the camera looking straight down
sees the floor's shadow): the umbra goes dark, the lit floor keeps the RT Lit value, two lights are shadowed each by
its own ratio; disable removes everything; the setup survives save and reload."""
from __future__ import annotations

import time

import numpy as np
import pytest

from rt_lookdev.validation.harness import exr_images
from rt_lookdev.validation.harness.render_setup import configure_cycles_measurement

pytest.importorskip("OpenEXR")

pytestmark = pytest.mark.blender

RES = 48                    # pixels; the camera sees the floor square [-2, 2]^2
HALF = 2.0
BOX = (0.0, 0.0, 1.0)       # the occluder's centre; half size 0.3
BOX_HALF = 0.3


def _pixel_xy():
    """World (x, y) of each pixel centre of the top-down orthographic camera (row 0 = top = +y)."""
    c = -HALF + (np.arange(RES) + 0.5) * 2 * HALF / RES
    return np.meshgrid(c, -c)


def _scene(bpy, lut_dir, lights):
    """Floor (RT Lit), a box occluder at ``BOX`` (invisible to the camera), ``lights`` [(name, type, location,
    power, size)] in a collection of their own, an orthographic camera straight down; lights synced."""
    from rt_lookdev.addon import light_sync, materials
    from rt_lookdev.core.materials.rt_lit_interface import Features

    scene = bpy.context.scene
    configure_cycles_measurement(scene, samples=4, seed=3, threads=2)
    scene.cycles.max_bounces = 0
    world = bpy.data.worlds.new("Black")
    world.color = (0.0, 0.0, 0.0)
    scene.world = world
    r = scene.render
    r.resolution_x = r.resolution_y = RES
    r.resolution_percentage = 100
    r.dither_intensity = 0.0
    bpy.ops.mesh.primitive_plane_add(size=2 * HALF + 1.0)
    floor = bpy.context.object
    floor.name = "Floor"
    bpy.ops.mesh.primitive_cube_add(size=2 * BOX_HALF, location=BOX)
    box = bpy.context.object
    box.name = "Box"
    box.visible_camera = False
    collection = bpy.data.collections.new("Lights")
    scene.collection.children.link(collection)
    for name, kind, location, power, size in lights:
        data = bpy.data.lights.new(name, kind)
        data.energy = power
        if kind == "AREA":
            data.size = size
        else:
            data.shadow_soft_size = size
        obj = bpy.data.objects.new(name, data)
        obj.location = location
        collection.objects.link(obj)
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    camera.data.type = "ORTHO"
    camera.data.ortho_scale = 2 * HALF
    camera.location = (0.0, 0.0, 6.0)
    scene.collection.objects.link(camera)
    scene.camera = camera
    light_sync.sync_lights(scene, lut_dir)
    material = bpy.data.materials.new("Floor RT Lit")
    materials.assign_rt_lit(material, Features(), scene=scene, lut_dir=lut_dir)
    material.node_tree.nodes["RT Lit"].inputs["Base Color"].default_value = (0.8, 0.8, 0.8, 1.0)
    floor.data.materials.append(material)
    box.data.materials.append(material)
    return scene


def _render(bpy, scene, path):
    """{"final": the composited image (or the beauty without shadows), pass name: image} of one F12 render to a
    multilayer EXR; and the seconds it took."""
    from rt_lookdev.addon import compat

    compat.set_exr_output(scene.render.image_settings, multilayer=True)
    scene.render.filepath = str(path)
    t0 = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    seconds = time.perf_counter() - t0
    ch = exr_images.read_channels(path)
    out = {}
    for key in ch:
        layer, name, c = key.rsplit(".", 2) if key.count(".") >= 2 else ("", *key.split("."))
        if c == "R":
            out[f"{layer}.{name}"] = np.stack([ch[f"{layer}.{name}.{k}"] for k in "RGB"], axis=-1)
    out["final"] = out.get("Composite.Combined", out.get(f"{scene.view_layers[0].name}.Combined"))
    return out, seconds


def _regions():
    x, y = _pixel_xy()
    far = np.maximum(np.abs(x), np.abs(y))
    return far < 0.25, (far > 0.95) & (far < 1.9)    # umbra of a light above the box, fully lit floor


def test_umbra_is_dark_and_lit_floor_keeps_rt_lit(empty_scene, lut_dir, tmp_path):
    import bpy

    from rt_lookdev.addon import shadows

    scene = _scene(bpy, lut_dir, [("Key", "AREA", (0.0, 0.0, 3.0), 300.0, 0.4)])
    plain, t_plain = _render(bpy, scene, tmp_path / "plain.exr")
    shadows.enable_shadows(scene)
    assert shadows.shadows_enabled(scene)
    shaded, t_shadows = _render(bpy, scene, tmp_path / "shadows.exr")
    ref, got = plain["final"], shaded["final"]
    assert np.all(np.isfinite(got))
    umbra, lit = _regions()
    level = ref[lit].mean()
    assert level > 0.1 and ref[umbra].min() > 0.5 * level           # unshadowed RT Lit lights the umbra
    rel = np.abs(got - ref)[lit] / ref[lit]
    print(f"umbra max {got[umbra].max() / level:.3g} of the lit level; lit rel. error median "
          f"{np.median(rel):.3g}, max {rel.max():.3g}; F12 {t_plain:.2f} s without, {t_shadows:.2f} s with shadows")
    assert got[umbra].max() < 0.01 * level
    assert np.median(rel) < 2e-3 and rel.max() < 0.05                # OIDN: 0 / 0.030 measured (4 spp)
    # the beauty layer's Combined is the unshadowed render, and its AOV is that light's part
    beauty = f"{scene.view_layers[0].name}"
    np.testing.assert_allclose(shaded[f"{beauty}.Combined"], ref, rtol=1e-5, atol=1e-6)
    np.testing.assert_allclose(shaded[f"{beauty}.RTL Light 0"], ref, rtol=1e-4, atol=1e-6)
    # without the denoiser, S and U share their samples: where nothing blocks the light the ratio is 1 exactly
    shadows.enable_shadows(scene, samples=4, denoise=False)
    raw, t_raw = _render(bpy, scene, tmp_path / "raw.exr")
    rel = np.abs(raw["final"] - ref)[lit] / ref[lit]
    print(f"no denoiser: umbra max {raw['final'][umbra].max() / level:.3g}, lit max rel. error {rel.max():.3g}, "
          f"F12 {t_raw:.2f} s")
    assert np.all(np.isfinite(raw["final"]))
    assert raw["final"][umbra].max() < 1e-4 * level and rel.max() < 1e-5


def test_each_light_has_its_own_ratio(empty_scene, lut_dir, tmp_path):
    import bpy

    from rt_lookdev.addon import shadows

    # "Key" above the box (its umbra below it), "Side" low at the side: nothing blocks it on the floor
    scene = _scene(bpy, lut_dir, [("Key", "AREA", (0.0, 0.0, 3.0), 300.0, 0.4),
                                  ("Side", "POINT", (0.0, -3.0, 1.0), 3000.0, 0.1)])
    shadows.enable_shadows(scene)
    out, _ = _render(bpy, scene, tmp_path / "two.exr")
    layer = scene.view_layers[0].name
    key, side, beauty, got = (out[f"{layer}.RTL Light 0"], out[f"{layer}.RTL Light 1"], out[f"{layer}.Combined"],
                              out["final"])
    umbra, lit = _regions()
    assert np.all(np.isfinite(got))
    assert key[umbra].min() > side[umbra].max() > 0.05 * key[umbra].min()    # both lights matter there
    per_light = np.abs(got - side)[umbra] / side[umbra]
    # one ratio for the sum of the two lights would give (Key + Side) * S_side / (U_key + U_side)
    s_side, u = out["RTL Probe S.Combined_s_1"], out["RTL Probe U.Combined_u_0"] + out["RTL Probe U.Combined_u_1"]
    summed = np.abs(beauty * s_side / u - side)[umbra] / side[umbra]
    lit_error = np.abs(got - beauty)[lit] / beauty[lit]
    print(f"umbra: |final - Side| / Side median {np.median(per_light):.3g} max {per_light.max():.3g} "
          f"(one summed ratio: median {np.median(summed):.3g}); lit: median {np.median(lit_error):.3g} "
          f"max {lit_error.max():.3g}")
    assert np.median(per_light) < 0.01 and per_light.max() < 0.05
    assert np.median(summed) > 5 * np.median(per_light)
    assert np.median(lit_error) < 2e-3 and lit_error.max() < 0.05


def _state(bpy, scene):
    """What enable / disable may change, by name."""
    from rt_lookdev.addon import compat

    def names(collection):
        return sorted(x.name for x in collection)

    return {"view layers": names(scene.view_layers),
            "aovs": {vl.name: names(vl.aovs) for vl in scene.view_layers},
            "light groups": {vl.name: names(vl.lightgroups) for vl in scene.view_layers},
            "excluded": {vl.name: sorted(c.name for c in vl.layer_collection.children if c.exclude)
                         for vl in scene.view_layers},
            "objects": names(bpy.data.objects), "lights": names(bpy.data.lights),
            "collections": names(bpy.data.collections), "materials": names(bpy.data.materials),
            "node groups": names(bpy.data.node_groups), "compositor": compat.compositor_tree(scene) is not None,
            "aov nodes": sorted(n.aov_name for ng in bpy.data.node_groups if ng.bl_idname == "ShaderNodeTree"
                                for n in ng.nodes if n.bl_idname == "ShaderNodeOutputAOV"),
            "use_compositing": scene.render.use_compositing, "properties": sorted(scene.keys())}


def test_disable_removes_everything_enable_is_idempotent_and_reload_renders(empty_scene, lut_dir, tmp_path):
    import bpy

    from rt_lookdev.addon import compat, light_sync, shadows

    scene = _scene(bpy, lut_dir, [("Key", "AREA", (0.0, 0.0, 3.0), 300.0, 0.4)])
    scene.render.use_compositing = False
    before = _state(bpy, scene)
    shadows.enable_shadows(scene, samples=2)
    once = _state(bpy, scene)
    assert set(once["view layers"]) - set(before["view layers"]) == {"RTL Probe S", "RTL Probe U"}
    assert len(once["objects"]) == len(before["objects"]) + 2 and once["compositor"]
    assert not before["aov nodes"] and once["aov nodes"] == ["RTL Light 0"]     # in the Cycles tree only
    shadows.enable_shadows(scene, samples=2)
    assert _state(bpy, scene) == once
    light_sync.sync_lights(scene, lut_dir)                  # Sync Lights rebuilds the copies: the same state
    assert _state(bpy, scene) == once
    assert shadows.shadow_settings(scene)["samples"] == 2
    scene.render.engine = "BLENDER_WORKBENCH"
    with pytest.raises(shadows.ShadowError):                # a refused enable changes nothing
        shadows.enable_shadows(scene)
    assert _state(bpy, scene) == once
    shadows.disable_shadows(scene)
    assert _state(bpy, scene) == before
    with pytest.raises(shadows.ShadowError):
        shadows.enable_shadows(scene)
    assert _state(bpy, scene) == before
    scene.render.engine = "CYCLES"
    tree, _ = compat.new_compositor(scene, "The user's")    # a compositor of the user's is not edited: refused
    with pytest.raises(shadows.ShadowError, match="compositor"):
        shadows.enable_shadows(scene)
    compat.remove_compositor(scene, tree)
    scene.render.use_compositing = False
    assert _state(bpy, scene) == before
    shadows.enable_shadows(scene, samples=2)
    blend = tmp_path / "shadows.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(blend))
    bpy.ops.wm.open_mainfile(filepath=str(blend))
    scene = bpy.context.scene
    assert shadows.shadows_enabled(scene) and _state(bpy, scene) == once
    out, _ = _render(bpy, scene, tmp_path / "reloaded.exr")
    umbra, lit = _regions()
    ref = out[f"{scene.view_layers[0].name}.Combined"]
    assert np.all(np.isfinite(out["final"]))
    assert out["final"][umbra].max() < 0.01 * ref[lit].mean() < 0.01 * ref[umbra].min() * 2
    shadows.disable_shadows(scene)
    assert not shadows.shadows_enabled(scene) and _state(bpy, scene) == before
    shadows.disable_shadows(scene)                          # nothing to do


def test_copies_follow_their_light_and_stay_in_their_layer(empty_scene, lut_dir):
    import bpy

    from rt_lookdev.addon import shadows

    scene = _scene(bpy, lut_dir, [("Key", "AREA", (0.0, 0.0, 3.0), 300.0, 0.4)])
    shadows.enable_shadows(scene)
    key = scene.objects["Key"]
    key.location = (0.5, 0.2, 2.5)
    key.data.size, key.data.energy = 0.9, 77.0
    seen = {}
    for layer in scene.view_layers:
        with bpy.context.temp_override(view_layer=layer):
            depsgraph = bpy.context.evaluated_depsgraph_get()
        depsgraph.update()
        seen[layer.name] = {o.name: (tuple(round(v, 5) for v in o.matrix_world.translation), round(o.data.size, 5),
                                     round(o.data.energy, 3), o.data.use_shadow, o.lightgroup)
                            for o in depsgraph.objects if o.type == "LIGHT"}
    moved = ((0.5, 0.2, 2.5), 0.9, 77.0)
    assert seen == {"ViewLayer": {"Key": (*moved, True, "")},           # the originals: in the user's layer only
                    "RTL Probe S": {"Key (s_0)": (*moved, True, "s_0")},
                    "RTL Probe U": {"Key (u_0)": (*moved, False, "u_0")}}


def test_enable_on_a_scene_made_in_this_session(empty_scene, lut_dir):
    """A scene made by ``bpy.data.scenes.new`` (New Lookdev Scene makes one) has view layers without a layer
    collection until they are synced (Blender 5.2): enabling shadows there syncs them (it raised AttributeError)."""
    import bpy

    from rt_lookdev.addon import light_sync, materials, shadows
    from rt_lookdev.core.materials.rt_lit_interface import Features

    scene = bpy.data.scenes.new("Made Here")
    scene.render.engine = "CYCLES"
    light = bpy.data.objects.new("Key", bpy.data.lights.new("Key", "POINT"))
    light.location = (0.0, 0.0, 2.0)
    scene.collection.objects.link(light)
    mesh = bpy.data.meshes.new("Plane")
    mesh.from_pydata([(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], [], [(0, 1, 2, 3)])
    plane = bpy.data.objects.new("Plane", mesh)
    scene.collection.objects.link(plane)
    light_sync.sync_lights(scene, lut_dir)
    material = bpy.data.materials.new("Plane RT Lit")
    materials.assign_rt_lit(material, Features(), scene=scene, lut_dir=lut_dir)
    mesh.materials.append(material)
    if bpy.app.version >= (5, 0):          # the case (5.2.3; 4.5.15 has synced the layer by now)
        assert scene.view_layers[0].layer_collection is None
    shadows.enable_shadows(scene, lut_dir=lut_dir)
    try:
        assert shadows.shadows_enabled(scene)
        assert {name for _, name, *_ in shadows.PROBES} <= set(scene.view_layers.keys())
    finally:
        shadows.disable_shadows(scene, lut_dir)
    assert set(scene.view_layers.keys()) == {"ViewLayer"} and not shadows.shadows_enabled(scene)


def test_operators_turn_shadows_on_and_off_and_the_twin_leaves_the_copies_out(registered, empty_scene, lut_dir):
    """Enable / Disable RT Lit Shadows (the RT Lookdev panel's buttons): poll says why not (another engine, shadows
    already off), enable reports and sets up the probes, the path-traced twin made then lights its copies with the
    scene's lights only (the probes' light copies render in the probe layers, not in the twin), disable undoes it."""
    import bpy

    from rt_lookdev.addon import lookdev_scene, shadows
    from rt_lookdev.addon.common import SHADOW_COPY_KEY

    scene = _scene(bpy, lut_dir, [("Key", "AREA", (0.0, 0.0, 3.0), 200.0, 0.4)])
    assert not bpy.ops.rtl.disable_shadows.poll()
    engine = scene.render.engine
    scene.render.engine = "BLENDER_WORKBENCH"
    assert not bpy.ops.rtl.enable_shadows.poll()
    scene.render.engine = engine
    assert bpy.ops.rtl.enable_shadows(samples=2, denoise=False) == {'FINISHED'}
    assert shadows.shadow_settings(scene) == {"samples": 2, "denoise": False, "beauty": "ViewLayer", "world": False}
    assert shadows.shadowed_lights(scene) == [0]
    twin = lookdev_scene.add_path_traced_twin(scene)
    assert not [o.name for o in twin.objects if SHADOW_COPY_KEY in o]
    assert [o.name for o in twin.objects if o.type == "LIGHT"] == ["Key"]
    assert bpy.ops.rtl.disable_shadows() == {'FINISHED'}
    assert not shadows.shadows_enabled(scene) and not bpy.ops.rtl.disable_shadows.poll()


def test_world_shadows_darken_the_floor_and_disable_restores(empty_scene, lut_dir, tmp_path):
    """``enable_shadows(world=True)`` on the floor study lit by the world alone: the beauty still renders (a tree
    rebuilt with the "World Irradiance" output once unlinked the Cycles Shader of the RT Lit group: a black beauty),
    the floor gets darker (the spheres' shadows and SH's too bright zenith irradiance: docs/shadows.md), and disable
    puts the world's light group and the trees back (the render bit-identical); a saved file re-opens with the world
    shadowed (the same render)."""
    import bpy

    from rt_lookdev.addon import light_sync, lookdev_scene, materials, shadows
    from rt_lookdev.core.materials.rt_lit_interface import Features
    from rt_lookdev.validation.checks import lookdev_twin

    scene = lookdev_scene.new_lookdev_scene("WR", Features(), view_transform="Standard", lut_dir=lut_dir, floor=True)
    for obj in [o for o in scene.objects if o.type == "LIGHT"]:
        bpy.data.objects.remove(obj)
    light_sync.sync_lights(scene, lut_dir)
    floor = scene.objects["WR Floor"]
    for i, obj in enumerate(lookdev_scene.lookdev_spheres(scene), start=1):
        obj.pass_index = i
    res = (48, 30)
    plain, index, _ = lookdev_twin.render_measurement(scene, res, 1, 0, tmp_path)
    with pytest.raises(shadows.ShadowError):
        shadows.enable_shadows(scene, lut_dir=lut_dir, world=False)     # no light, the world not asked: nothing to do
    assert not shadows.shadows_enabled(scene)
    shadows.enable_shadows(scene, samples=4, denoise=False, lut_dir=lut_dir)
    assert shadows.shadow_settings(scene)["world"] is True
    assert scene.world.lightgroup == shadows.WORLD_LIGHT_GROUP
    shaded, index_s, _ = lookdev_twin.render_measurement(scene, res, 1, 0, tmp_path)
    on_floor = (index == floor.pass_index) & (index_s == floor.pass_index)
    assert on_floor.sum() > 100
    assert np.all(np.isfinite(shaded))
    ratio = shaded[on_floor].mean(-1) / plain[on_floor].mean(-1)
    print(f"floor ratio p10/p50/p90 {np.percentile(ratio, [10, 50, 90])}")
    assert 0.4 < np.median(ratio) < 0.95
    blend = tmp_path / "world_shadows.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(blend))
    bpy.ops.wm.open_mainfile(filepath=str(blend))
    scene = bpy.data.scenes["WR"]
    reloaded, _, _ = lookdev_twin.render_measurement(scene, res, 1, 0, tmp_path)
    np.testing.assert_allclose(reloaded, shaded, rtol=1e-5, atol=1e-6)
    shadows.disable_shadows(scene, lut_dir)
    assert scene.world.lightgroup == ""
    for ng in bpy.data.node_groups:
        if ng.name.endswith("[Cycles]"):
            assert "World Irradiance" not in [i.name for i in ng.interface.items_tree]
    again, index_d, _ = lookdev_twin.render_measurement(scene, res, 1, 0, tmp_path)
    np.testing.assert_allclose(again, plain, rtol=1e-5, atol=1e-6)
    assert materials.world_shadows_on(scene) is False


def _ao_nodes(tree):
    return [n for n in tree.nodes if n.bl_idname == "ShaderNodeAmbientOcclusion"]


def test_world_shadows_take_the_place_of_world_occlusion_in_cycles_only(empty_scene, lut_dir):
    """With the world shadowed, the Cycles trees drop ``Features.occlusion`` (the ratio occludes the world: AO as
    well would occlude it twice), EEVEE's keep it; without the world option, and after disable, Cycles' AO is back."""
    import bpy

    from rt_lookdev.addon import lookdev_scene, shadows
    from rt_lookdev.core.materials.rt_lit_interface import Features

    scene = lookdev_scene.new_lookdev_scene("AO", Features(occlusion="cones_clipped"), view_transform="Standard",
                                            lut_dir=lut_dir, resolution=(32, 16))

    def trees(engine):
        found = [ng for ng in bpy.data.node_groups if ng.name.startswith("RT Lit (") and ng.name.endswith(f"[{engine}]")]
        assert found
        return found

    assert all(_ao_nodes(t) for t in trees("Cycles")) and all(_ao_nodes(t) for t in trees("EEVEE"))
    shadows.enable_shadows(scene, samples=1, denoise=False, lut_dir=lut_dir)
    assert shadows.shadow_settings(scene)["world"] is True
    assert not any(_ao_nodes(t) for t in trees("Cycles")) and all(_ao_nodes(t) for t in trees("EEVEE"))
    shadows.enable_shadows(scene, samples=1, denoise=False, lut_dir=lut_dir, world=False)
    assert shadows.shadow_settings(scene)["world"] is False and scene.world.lightgroup == ""
    assert all(_ao_nodes(t) for t in trees("Cycles"))
    shadows.enable_shadows(scene, samples=1, denoise=False, lut_dir=lut_dir)
    shadows.disable_shadows(scene, lut_dir)
    assert all(_ao_nodes(t) for t in trees("Cycles")) and all(_ao_nodes(t) for t in trees("EEVEE"))
