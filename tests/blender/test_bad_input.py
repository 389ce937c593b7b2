"""Bad input end to end (docs/robustness.md, "Bad input"): what the user sees and what is kept, for the cases
not covered next to their features: scenes with 0 and 100 lights, lights linked from a library, register /
unregister x 50, undo and redo after Convert, Sync Lights and Sync World, 1 x 1 and tiny world images."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytestmark = pytest.mark.blender


def _reports(capfd):
    return capfd.readouterr().out + capfd.readouterr().err


def _point_light(bpy, scene, name, location):
    obj = bpy.data.objects.new(name, bpy.data.lights.new(name, "POINT"))
    obj.location = location
    scene.collection.objects.link(obj)
    return obj


def _rt_lit_object(bpy, scene, lut_dir, features=None):
    from rt_lookdev.addon import compat, materials

    mat = compat.new_material("Lookdev")
    materials.assign_rt_lit(mat, features, scene, lut_dir)
    mesh = bpy.data.meshes.new("ball")
    obj = bpy.data.objects.new("ball", mesh)
    obj.data.materials.append(mat)
    scene.collection.objects.link(obj)
    return mat


def _light_terms(bpy):
    """Light kinds of the RT Lit groups' last build: the lights each group shades."""
    from rt_lookdev.addon import materials

    return materials.synced_light_kinds()


def test_sync_lights_with_no_lights_and_with_a_hundred(registered, empty_scene, lut_dir, capfd):
    """0 lights: a valid material with no light terms, said so.  100 lights: built, with a warning naming the
    Cycles budget and where the capacities are measured; nothing else changes."""
    bpy = registered
    scene = empty_scene
    mat = _rt_lit_object(bpy, scene, lut_dir)
    assert bpy.ops.rtl.sync_lights() == {'FINISHED'}
    out = _reports(capfd)
    assert "RT Lit: 0 lights [none]" in out
    assert _light_terms(bpy) == []
    for i in range(100):
        _point_light(bpy, scene, f"Light {i:03d}", (i * 0.1, 2.0, 3.0))
    assert bpy.ops.rtl.sync_lights() == {'FINISHED'}
    out = _reports(capfd)
    assert "RT Lit: 100 lights [100 point]" in out      # counted per kind: a list of 100 names was truncated
    from rt_lookdev.core.materials import cycles_capacity
    from rt_lookdev.core.materials.rt_lit_interface import Features

    # the default switches (turquin, cod): their measured Cycles capacity is below 100 lights, or the benchmark's
    # search stopped below 100 (then the warning says how far it was tested)
    capacity, _ = cycles_capacity.light_capacity(Features("turquin", "cod"))
    bound = "tested up to" if cycles_capacity.is_lower_bound(capacity) else "at most"
    assert capacity < 100
    assert "black beyond their shader-stack capacity" in out and f"(turquin, cod) {bound} {capacity}" in out
    assert "docs/benchmarks/rt_lit.md" in out and "truncated" not in out
    assert len(_light_terms(bpy)) == 100
    assert mat.node_tree.nodes.get("RT Lit") is not None or any(n.bl_idname == "ShaderNodeGroup"
                                                                   for n in mat.node_tree.nodes)


def test_lights_linked_from_a_library_are_shaded(registered, empty_scene, relink_from_library):
    """A light object linked from another .blend (a studio rig kept in a library) is shaded like a local one."""
    from rt_lookdev.addon.materials import scene_lights

    bpy = registered
    _point_light(bpy, empty_scene, "Rig Key", (1.0, 2.0, 3.0))
    empty_scene.collection.objects.link(relink_from_library("objects", "Rig Key"))
    assert [(o.name, kind) for o, kind in scene_lights(empty_scene)] == [("Rig Key", "point")]
    assert bpy.ops.rtl.sync_lights() == {'FINISHED'}


def test_register_unregister_fifty_times_leaves_nothing(bpy_module, empty_scene):
    """50 register / unregister cycles: the same types, operators, menus and handlers as before."""
    import rt_lookdev

    def state():
        menus = {name: len(getattr(bpy_module.types, name).draw._draw_funcs)
                 for name in ("TOPBAR_MT_file_export", "VIEW3D_MT_object")
                 if hasattr(getattr(bpy_module.types, name, None), "draw")
                 and hasattr(getattr(bpy_module.types, name).draw, "_draw_funcs")}
        handlers = {name: len(getattr(bpy_module.app.handlers, name)) for name in dir(bpy_module.app.handlers)
                    if not name.startswith("_") and isinstance(getattr(bpy_module.app.handlers, name), list)}
        return set(dir(bpy_module.types)), set(dir(bpy_module.ops.rtl)), menus, handlers

    before = state()
    for _ in range(50):
        rt_lookdev.register()
        rt_lookdev.unregister()
    assert state() == before


def undo_and_redo_convert_and_sync_lights(bpy, lut_dir):
    """The steps of ``test_undo_and_redo_convert_and_sync_lights`` on the open (empty) file, the add-on registered."""
    from rt_lookdev.addon import compat, convert, light_sync

    scene = bpy.context.scene
    mat = compat.new_material("Undoable")
    mesh = bpy.data.meshes.new("ball")
    obj = bpy.data.objects.new("ball", mesh)
    obj.data.materials.append(mat)
    scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    bpy.ops.ed.undo_push(message="before convert")
    # ('EXEC_DEFAULT', True): run as from the interface, which pushes the operator's undo step
    assert bpy.ops.rtl.convert_to_rt_lit('EXEC_DEFAULT', True, target='ACTIVE') == {'FINISHED'}
    assert convert.is_rt_lit_material(bpy.data.materials["Undoable"])
    bpy.ops.ed.undo()
    assert not convert.is_rt_lit_material(bpy.data.materials["Undoable"])
    bpy.ops.ed.redo()
    assert convert.is_rt_lit_material(bpy.data.materials["Undoable"])

    # lights follow undo: the automatic sync (addon/light_sync.py) keeps the groups on the scene's lights
    bpy.ops.ed.undo_push(message="before the light")
    _point_light(bpy, bpy.context.scene, "Key", (1.0, 1.0, 2.0))
    assert bpy.ops.rtl.sync_lights('EXEC_DEFAULT', True) == {'FINISHED'}
    assert len(_light_terms(bpy)) == 1
    assert [o.name for o in light_sync.followed_objects()] == ["Key"]
    bpy.ops.ed.undo()
    # the undo freed the light: the handler holds no object from before it, only objects of the file as it is now
    # (as_pointer reads the Python object's own pointer, not the freed memory)
    assert {o.as_pointer() for o in light_sync.followed_objects()} <= {o.as_pointer() for o in bpy.data.objects}
    bpy.context.view_layer.update()
    assert "Key" not in bpy.data.objects and len(_light_terms(bpy)) == 0
    bpy.ops.ed.redo()
    assert {o.as_pointer() for o in light_sync.followed_objects()} <= {o.as_pointer() for o in bpy.data.objects}
    bpy.context.view_layer.update()
    assert "Key" in bpy.data.objects and len(_light_terms(bpy)) == 1


_UNDO_SNIPPET = r'''
import importlib.util, json, sys
from pathlib import Path
from rt_lookdev import addon
# this test module, loaded from its file (tests are not a package; no sys.path edit)
spec = importlib.util.spec_from_file_location("test_bad_input", sys.argv[2])
test_bad_input = importlib.util.module_from_spec(spec)
spec.loader.exec_module(test_bad_input)
addon.register()
bpy.ops.wm.read_homefile(use_empty=True)
test_bad_input.undo_and_redo_convert_and_sync_lights(bpy, Path(sys.argv[1]))
print("RTL_RESULT " + json.dumps({"done": True}))
'''


def test_undo_and_redo_convert_and_sync_lights(lut_dir, tmp_path):
    """Undo after Convert gives the Principled material back; redo the RT Lit one.  Undo after adding and
    syncing a light removes both; redo brings both back.  In a fresh interpreter: Blender's global undo crashed once
    in C in a CI test worker that had run other modules first (not reproduced in 30 runs here), and a
    crash there ends the whole run; here it fails this test, with the output."""
    from _blender_subprocess import run_snippet

    result, _ = run_snippet(_UNDO_SNIPPET, tmp_path / "user", str(lut_dir), str(Path(__file__)))
    assert result == {"done": True}


@pytest.mark.parametrize("size", [(1, 1), (2, 1), (4, 2)])
def test_tiny_world_images_bake_and_shade(bpy_module, empty_scene, tmp_path, monkeypatch, size):
    """A 1 x 1 (or 2 x 1, 4 x 2) environment image is a constant (or nearly) world: it bakes, its SH is its
    radiance, and its prefiltered levels are finite."""
    from rt_lookdev.addon import compat
    from rt_lookdev.addon import world_sync as world
    from rt_lookdev.core.environment.prefilter import PrefilterSettings

    monkeypatch.setenv(world.CACHE_ENV, str(tmp_path / "env-cache"))
    bpy = bpy_module
    w, h = size
    img = bpy.data.images.new("tiny", w, h, alpha=True, float_buffer=True)
    img.pixels.foreach_set(np.tile([0.5, 0.25, 2.0, 1.0], w * h).astype(np.float32))
    wd = compat.new_world("World")
    empty_scene.world = wd
    env = wd.node_tree.nodes.new("ShaderNodeTexEnvironment")
    env.image = img
    wd.node_tree.links.new(env.outputs["Color"], wd.node_tree.nodes["Background"].inputs["Color"])
    try:
        setup = world.world_setup(wd)
        assert setup.usable, setup.reason
        bake = world.bake_world(empty_scene, settings=PrefilterSettings(16, 8, (0.0, 0.5, 1.0)))
        coeffs = np.asarray(bake.sh_image, np.float64)[:, :3]
        assert np.allclose(coeffs[0] * 0.28209479177387814, (0.5, 0.25, 2.0), rtol=1e-4)   # Y00 = 1/(2 sqrt(pi))
        assert np.allclose(coeffs[1:], 0.0, atol=1e-4)
        from rt_lookdev.core.lut import exr_io

        levels, _ = exr_io.read_table(bake.prefiltered_path)
        assert np.isfinite(levels).all() and np.allclose(levels[..., :3], (0.5, 0.25, 2.0), rtol=1e-3)
        assert world.sync_world(empty_scene, bake=bake) is not None
    finally:
        world.remove_world_group()


def test_undo_and_redo_sync_world(registered, empty_scene, tmp_path, monkeypatch):
    """Undo after Sync World removes the "RTL World" group it built; redo brings it back."""
    from rt_lookdev.addon import compat
    from rt_lookdev.addon import world_sync as world
    from rt_lookdev.core.environment import prefilter

    bpy = registered
    monkeypatch.setenv(world.CACHE_ENV, str(tmp_path / "env-cache"))
    real = prefilter.PrefilterSettings
    small = real(16, 8, (0.0, 0.5, 1.0))
    # the operator bakes with the default settings: keep them small here
    monkeypatch.setattr(prefilter, "PrefilterSettings", lambda *a, **k: real(*a, **k) if a or k else small)
    img = bpy.data.images.new("env", 8, 4, alpha=True, float_buffer=True)
    img.pixels.foreach_set(np.random.default_rng(1).uniform(0.1, 2.0, 8 * 4 * 4).astype(np.float32))
    wd = compat.new_world("World")
    empty_scene.world = wd
    env = wd.node_tree.nodes.new("ShaderNodeTexEnvironment")
    env.image = img
    wd.node_tree.links.new(env.outputs["Color"], wd.node_tree.nodes["Background"].inputs["Color"])
    bpy.ops.ed.undo_push(message="before sync world")
    try:
        assert bpy.ops.rtl.sync_world('EXEC_DEFAULT', True) == {'FINISHED'}
        assert world.WORLD_GROUP in bpy.data.node_groups
        bpy.ops.ed.undo()
        assert world.WORLD_GROUP not in bpy.data.node_groups
        bpy.ops.ed.redo()
        assert world.WORLD_GROUP in bpy.data.node_groups
    finally:
        world.remove_world_group()


def test_sync_lights_names_what_is_not_shaded_and_the_capacity_of_each_feature_set(registered, empty_scene,
                                                                                    lut_dir, capfd, monkeypatch):
    """The Sync report says which light settings RT Lit ignores, and warns with the capacity of each material's
    switches, not a fixed number.  The capacities are set small here (the measured ones, docs/benchmarks/rt_lit.md,
    are checked by tests/core/test_cycles_capacity.py) so that a few lights exceed one set and not the other."""
    from rt_lookdev.addon import compat
    from rt_lookdev.core.materials import cycles_capacity
    from rt_lookdev.core.materials.rt_lit_interface import Features

    monkeypatch.setitem(cycles_capacity.MEASURED, Features("kulla_conty", "wrapped", sheen=True, cloth=True), (3, 3))
    monkeypatch.setitem(cycles_capacity.MEASURED, Features("single", "lambert"), (15, 15))
    bpy = registered
    scene = empty_scene
    _rt_lit_object(bpy, scene, lut_dir, Features("kulla_conty", "wrapped", sheen=True, cloth=True))
    _rt_lit_object(bpy, scene, lut_dir, Features("single", "lambert"))
    key = _point_light(bpy, scene, "Key", (1.0, 2.0, 3.0))
    key.data.shadow_soft_size = 0.1                   # shaded (a sphere light), as exposure and the angle below
    key.data.exposure = 1.0
    key.visible_glossy = False
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.angle = 0.1
    compat.ensure_node_tree(sun.data)
    tree = sun.data.node_tree
    blackbody = tree.nodes.new("ShaderNodeBlackbody")
    emission = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeEmission")
    tree.links.new(blackbody.outputs[0], emission.inputs["Color"])
    scene.collection.objects.link(sun)
    for i in range(2):
        _point_light(bpy, scene, f"Fill {i}", (i, -2.0, 3.0))
    assert bpy.ops.rtl.sync_lights() == {'FINISHED'}
    out = _reports(capfd)
    assert ("not shaded: Key (glossy ray visibility off), Sun (node tree (Color of the Emission node not constant))"
            in out)
    assert "(kulla-conty, wrapped, sheen, cloth) at most 3 lights" in out
    assert "(single, lambert)" not in out.split("capacity")[-1]       # 4 lights are within its 15


def test_sync_lights_warns_in_blender_4_of_materials_black_under_spread_lights(registered, empty_scene, lut_dir,
                                                                               capfd):
    """Blender 4.x: Sync Lights names the materials whose switches overflow Cycles' shader stack under an area light
    with spread (measured: core/materials/cycles_capacity.py, SPREAD_IN_4), and not those that fit; 5.x, which
    renders them all, says nothing of it."""
    import math

    from rt_lookdev.core.materials.rt_lit_interface import Features

    bpy = registered
    scene = empty_scene
    _rt_lit_object(bpy, scene, lut_dir, Features("kulla_conty", "wrapped", sheen=True, cloth=True))
    _rt_lit_object(bpy, scene, lut_dir, Features("turquin", "cod"))
    panel = bpy.data.objects.new("Panel", bpy.data.lights.new("Panel", "AREA"))
    panel.data.shape = "DISK"
    scene.collection.objects.link(panel)
    assert bpy.ops.rtl.sync_lights() == {'FINISHED'}
    assert "light with spread" not in _reports(capfd)                # no spread (180 deg): every set renders
    panel.data.spread = math.radians(40.0)
    assert bpy.ops.rtl.sync_lights() == {'FINISHED'}
    out = _reports(capfd)
    if bpy.app.version < (5, 0, 0):
        warning = out.split("Blender 4.x: RT Lit materials (")[1]
        assert warning.startswith("kulla-conty, wrapped, sheen, cloth) render black in Cycles under an area light "
                                  "with spread (Panel)")
    else:
        assert "light with spread" not in out


def test_lights_stay_in_sync_without_a_button(registered, empty_scene, lut_dir):
    """With the add-on enabled, adding, hiding, excluding, removing a light or changing an area light's shape
    re-syncs RT Lit at the next depsgraph update; moving a light changes nothing to sync."""
    bpy = registered
    scene = empty_scene
    _rt_lit_object(bpy, scene, lut_dir)

    def update():
        bpy.context.view_layer.update()
        return [kind for _, kind in _light_terms(bpy)]

    key = _point_light(bpy, scene, "Key", (1.0, 2.0, 3.0))
    assert update() == ["point"]
    area = bpy.data.objects.new("Panel", bpy.data.lights.new("Panel", "AREA"))
    scene.collection.objects.link(area)
    assert update() == ["point", "quad"]                    # "Key", "Panel" in name order
    area.data.shape = "DISK"
    assert update() == ["point", "disk"]
    area.data.rtl_use_cone = True                           # a light control changes the light's kind
    assert update() == ["point", "disk+cone"]
    area.data.rtl_use_cone = False
    assert update() == ["point", "disk"]
    key.hide_render = True
    assert update() == ["disk"]
    key.hide_render = False
    off = bpy.data.collections.new("Off")
    scene.collection.children.link(off)
    off.objects.link(area)
    scene.collection.objects.unlink(area)
    bpy.context.view_layer.layer_collection.children["Off"].exclude = True
    assert update() == ["point"]
    signature = dict(bpy.data.node_groups["RTL Scene Lights"])["rtl_light_signature"]
    key.location = (5.0, 5.0, 5.0)                           # drivers follow it: no re-sync
    update()
    assert dict(bpy.data.node_groups["RTL Scene Lights"])["rtl_light_signature"] == signature
    bpy.data.objects.remove(key)
    assert update() == []


def test_light_sync_benchmark_writes_its_report(bpy_module, tmp_path, lut_dir):
    """The README's `python scripts/benchmark_light_sync.py` (small here): report and JSON written."""
    from rt_lookdev.validation.benchmarks import light_sync_benchmark
    from rt_lookdev.validation.harness import entry

    out = tmp_path / "light_sync.md"
    result = light_sync_benchmark.run(light_sync_benchmark.parse_args(
        ["--objects", "12", "--lights", "3", "--repeats", "5", "--runs", "2", "--sync-lights", "3", "--sync-runs", "1",
         "--lut-dir", str(lut_dir), "--out", str(out)]), progress=entry.quiet)
    assert out.read_text().startswith("# Automatic light sync") and out.with_suffix(".json").is_file()
    assert "| Sync Lights | 3 lights |" in out.read_text()
    sync = result["sync_sizes"][0]
    assert sync["lights"] == 3 and all(sync[key] > 0.0 for key in light_sync_benchmark.SYNC_FIGURES)
    scene = result["scenes"][0]
    assert scene["objects"] == 12 and scene["resync_adding_a_light_ms"] > 0.0
    for ranges in ("without_ranges", "with_ranges"):
        figures = scene["handler_ms"][ranges]
        assert set(figures) >= set(light_sync_benchmark.UPDATES) and all(figures[k] > 0.0 for k in light_sync_benchmark.UPDATES)
