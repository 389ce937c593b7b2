"""Lights out of range are left out of a material's tree (issue 15: skip what a scene does not need): a light with a
range gives exactly 0 beyond it, so a material whose objects all lie farther gets an RT Lit group without it; the
render is the same, the tree smaller; moving a light or an object re-culls."""
from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("OpenEXR")

pytestmark = pytest.mark.blender


def _scene(bpy, lut_dir, ranged=True):
    """Three spheres 6 m apart, each with its own RT Lit material; a point light with a 3 m range beside each, and
    a sun without one; an orthographic camera."""
    from rt_lookdev.addon import compat, materials
    from rt_lookdev.core.materials.rt_lit_interface import Features
    from rt_lookdev.validation.harness import scene_render

    scene = bpy.context.scene
    mesh = scene_render.uv_sphere_mesh("cull_sphere", 48, 24)
    for i in range(3):
        data = bpy.data.lights.new(f"Point {i}", "POINT")
        data.energy, data.shadow_soft_size = 300.0, 0.0
        data["rtl_use_range"], data["rtl_range"] = ranged, 3.0
        light = bpy.data.objects.new(f"Point {i}", data)
        light.location = (6.0 * i - 6.0, -2.0, 1.0)
        scene.collection.objects.link(light)
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.angle, sun.data.energy = 0.0, 1.0
    scene.collection.objects.link(sun)
    materials.sync_scene_lights(scene)
    for i in range(3):
        mat = compat.new_material(f"Cull {i}")
        materials.assign_rt_lit(mat, Features("turquin", "cod"), scene, lut_dir)
        obj = bpy.data.objects.new(f"Sphere {i}", mesh.copy())
        obj.data.materials.append(mat)
        obj.location = (6.0 * i - 6.0, 0.0, 0.0)
        scene.collection.objects.link(obj)
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.data.type, cam.data.ortho_scale = "ORTHO", 18.0
    cam.location, cam.rotation_euler = (0.0, -20.0, 0.0), (np.pi / 2, 0.0, 0.0)
    scene.collection.objects.link(cam)
    scene.camera = cam
    scene.render.resolution_x, scene.render.resolution_y = 180, 60
    bpy.context.view_layer.update()                  # world matrices, as a depsgraph update leaves them
    materials.rebuild_rt_lit_groups(scene, lut_dir)
    return scene


def _render(scene):
    from rt_lookdev.validation.harness.engines import render_cycles_passes

    return render_cycles_passes(scene, (scene.render.resolution_x, scene.render.resolution_y))["Combined"]


def test_each_material_gets_only_the_lights_that_reach_it(empty_scene, lut_dir):
    import bpy

    from rt_lookdev.addon import materials
    from rt_lookdev.addon.common import LIGHTS_SUBSET_KEY

    scene = _scene(bpy, lut_dir)
    groups = {i: bpy.data.materials[f"Cull {i}"].node_tree.nodes["RT Lit"].node_tree for i in range(3)}
    # lights in name order: Point 0, Point 1, Point 2, Sun
    assert [list(g[LIGHTS_SUBSET_KEY]) for g in groups.values()] == [[0, 3], [1, 3], [2, 3]]
    culled = {i: sum(materials.engine_node_counts(g).values()) for i, g in groups.items()}
    image = _render(scene)

    bpy.ops.wm.read_homefile(use_empty=True)
    scene = _scene(bpy, lut_dir, ranged=False)
    full_group = bpy.data.materials["Cull 0"].node_tree.nodes["RT Lit"].node_tree
    assert LIGHTS_SUBSET_KEY not in full_group
    # without ranges every material shades all four lights
    full = sum(materials.engine_node_counts(full_group).values())
    print(f"nodes per material: culled {culled}, all lights {full}")
    assert max(culled.values()) < 0.75 * full
    assert np.isfinite(image).all() and image.max() > 0.05


def test_culling_changes_no_value_and_follows_moves(empty_scene, lut_dir):
    """A culled light contributes exactly 0 (the window is 0 at and beyond the range), so the culled render equals
    the render with every light in every tree (forced by a range test that never culls); moving a light into reach
    re-culls."""
    import bpy

    from rt_lookdev.addon import materials

    scene = _scene(bpy, lut_dir)
    culled = _render(scene)
    original = materials.material_reach
    try:
        materials.material_reach = lambda scene, records: {}
        materials.rebuild_rt_lit_groups(scene, lut_dir)
        assert all(len(bpy.data.materials[f"Cull {i}"].node_tree.nodes["RT Lit"].node_tree.name.split("[")) == 1
                   for i in range(3))
        everything = _render(scene)
    finally:
        materials.material_reach = original
    print(f"culled vs every light: max |difference| {np.abs(culled - everything).max():.2e}")
    np.testing.assert_allclose(culled, everything, rtol=0, atol=1e-6)
    materials.rebuild_rt_lit_groups(scene, lut_dir)
    assert not materials.lights_out_of_sync(scene)
    bpy.data.objects["Point 0"].location = (0.0, -2.0, 1.0)                # now it reaches sphere 1, not sphere 0
    bpy.context.view_layer.update()
    assert materials.lights_out_of_sync(scene)
    materials.rebuild_rt_lit_groups(scene, lut_dir)
    groups = [bpy.data.materials[f"Cull {i}"].node_tree.nodes["RT Lit"].node_tree.name for i in range(3)]
    assert groups[0].endswith("[lights 3]") and groups[1].endswith("[lights 0, 1, 3]")


def test_the_capacity_warning_counts_the_lights_each_material_shades(empty_scene, lut_dir, monkeypatch):
    """Sync Lights warns when a material shades more lights than its switches hold in Cycles: a culled material
    shades only the lights that reach it, and a group no material uses any more warns for nothing.  The capacity is
    set to 3 here (the measured ones: tests/core/test_cycles_capacity.py)."""
    import bpy

    from rt_lookdev.addon import materials, operators
    from rt_lookdev.core.materials import cycles_capacity
    from rt_lookdev.core.materials.rt_lit_interface import Features

    monkeypatch.setitem(cycles_capacity.MEASURED, Features("turquin", "cod"), (3, 3))
    scene = _scene(bpy, lut_dir)                    # 4 lights; each material shades its point light and the sun
    assert operators._over_capacity(materials.rebuild_rt_lit_groups(scene, lut_dir), 4, False) == ""

    bpy.ops.wm.read_homefile(use_empty=True)
    scene = _scene(bpy, lut_dir, ranged=False)      # no ranges: every material shades all 4
    warning = operators._over_capacity(materials.rebuild_rt_lit_groups(scene, lut_dir), 4, False)
    assert "(turquin, cod) at most 3 lights" in warning


def _groups(bpy):
    return [bpy.data.materials[f"Cull {i}"].node_tree.nodes["RT Lit"].node_tree.name for i in range(3)]


def test_the_automatic_sync_re_culls_when_objects_move_from_the_spheres_it_keeps(registered, empty_scene, lut_dir,
                                                                                  monkeypatch):
    """With the add-on enabled, moving a sphere or a light into or out of a range re-culls at the next depsgraph
    update; the handler keeps each object's sphere between updates (addon/light_sync.py), so a move that changes what
    the lights reach is found without walking the scene, and one that does not change it re-builds nothing."""
    from rt_lookdev.addon import materials, preferences

    bpy = registered
    monkeypatch.setattr(preferences, "lut_directory", lambda context=None: lut_dir)
    _scene(bpy, lut_dir)
    bpy.context.view_layer.update()
    assert [g.rsplit("[", 1)[1] for g in _groups(bpy)] == ["lights 0, 3]", "lights 1, 3]", "lights 2, 3]"]
    walks, rebuilds = [], []
    rendered, rebuild = materials.rendered_objects, materials.rebuild_rt_lit_groups
    monkeypatch.setattr(materials, "rendered_objects", lambda scene: walks.append(1) or rendered(scene))
    monkeypatch.setattr(materials, "rebuild_rt_lit_groups", lambda *a: rebuilds.append(1) or rebuild(*a))

    bpy.data.objects["Sphere 0"].location.z = 0.25                     # still within Point 0's range only
    bpy.data.objects["Point 2"].location.x = 6.5
    bpy.context.view_layer.update()
    assert walks == [] and rebuilds == []                               # followed from the kept spheres

    bpy.data.objects["Sphere 2"].location = (0.0, 0.0, 2.0)            # into Point 1's range, out of Point 2's
    bpy.context.view_layer.update()
    assert rebuilds == [1] and _groups(bpy)[2].endswith("[lights 1, 3]")
    bpy.data.objects["Point 0"].location = (0.0, -2.0, 1.0)             # it now reaches spheres 1 and 2, not 0
    bpy.context.view_layer.update()
    assert rebuilds == [1, 1]
    assert [g.rsplit("[", 1)[1] for g in _groups(bpy)] == ["lights 3]", "lights 0, 1, 3]", "lights 0, 1, 3]"]
    bpy.data.objects["Sphere 2"].location = (6.0, 0.0, 0.0)             # back
    bpy.context.view_layer.update()
    assert _groups(bpy)[2].endswith("[lights 2, 3]") and not materials.lights_out_of_sync(bpy.context.scene)


def test_the_kept_spheres_and_lights_match_a_full_check_after_each_edit(bpy_module, empty_scene, lut_dir, monkeypatch):
    """The handler's kept state (``light_sync._state`` fed by each depsgraph update) gives the light signature and reach
    a full check gives, after every kind of edit: moves, scales, a parent's move, a mesh edit, a light's range, renames,
    material slots, hiding, objects added and removed, collections excluded, a view layer off.  Most are followed
    without a full check (counted)."""
    from rt_lookdev.addon import compat, light_sync, materials
    from rt_lookdev.core.materials.rt_lit_interface import Features

    bpy = bpy_module
    scene = _scene(bpy, lut_dir)
    for light in bpy.data.lights:
        light["rtl_range"] = 3.0
    full_builds, mismatches, seen = [], [], []
    init = light_sync._SceneState.__init__
    monkeypatch.setattr(light_sync._SceneState, "__init__", lambda self, s: full_builds.append(1) or init(self, s))

    def check(scene, depsgraph):
        state = light_sync._state(scene, light_sync.Updates(depsgraph))
        records = materials.scene_lights(scene)
        expected = (materials.light_signature(records), materials.material_reach(scene, records))
        if (state.signature, state.reach()) != expected:
            mismatches.append((seen[-1], (state.signature, state.reach()), expected))

    bpy.app.handlers.depsgraph_update_post.append(check)
    try:
        other = compat.new_material("Other")
        materials.assign_rt_lit(other, Features("single", "lambert"), scene, lut_dir)
        parent = bpy.data.objects.new("Parent", None)
        scene.collection.objects.link(parent)
        edits = {
            "start": lambda: None,
            "sphere moved into a range": lambda: setattr(bpy.data.objects["Sphere 2"], "location", (0.0, 0.0, 2.0)),
            "sphere scaled": lambda: setattr(bpy.data.objects["Sphere 0"], "scale", (2.5, 2.5, 2.5)),
            "light moved": lambda: setattr(bpy.data.objects["Point 1"], "location", (6.0, -2.0, 1.0)),
            "range changed": lambda: (bpy.data.lights["Point 2"].__setitem__("rtl_range", 9.0),
                                      bpy.data.lights["Point 2"].update_tag()),
            "parented": lambda: setattr(bpy.data.objects["Sphere 1"], "parent", parent),
            "parent moved": lambda: setattr(parent, "location", (0.0, 0.0, 20.0)),
            "mesh edited": lambda: _grow(bpy.data.objects["Sphere 1"].data),
            "sphere renamed": lambda: setattr(bpy.data.objects["Sphere 1"], "name", "Sphere One"),
            "light renamed": lambda: setattr(bpy.data.objects["Point 0"], "name", "Point Zero"),
            "material slot": lambda: setattr(bpy.data.objects["Sphere 2"].material_slots[0], "material", other),
            "sphere hidden": lambda: setattr(bpy.data.objects["Sphere 0"], "hide_render", True),
            "sphere added": lambda: _add_sphere(bpy, scene, other),
            "sphere removed": lambda: bpy.data.objects.remove(bpy.data.objects["Sphere One"]),
            "light excluded": lambda: _exclude(bpy, scene, bpy.data.objects["Point 2"]),
            "view layer off": lambda: setattr(scene.view_layers.new("Other layer"), "use", False),
            "selection": lambda: bpy.data.objects["Sphere 2"].select_set(True),
        }
        followed = {}
        for name, edit in edits.items():
            seen.append(name)
            before = len(full_builds)
            edit()
            bpy.context.view_layer.update()
            followed[name] = len(full_builds) == before
    finally:
        bpy.app.handlers.depsgraph_update_post.remove(check)
        light_sync._states.clear()
    assert mismatches == []
    print(f"followed without a full check: {[n for n, f in followed.items() if f]}")
    for name in ("sphere moved into a range", "sphere scaled", "light moved", "range changed", "parent moved",
                 "mesh edited", "sphere renamed", "selection"):
        assert followed[name], name


def _grow(mesh):
    """A mesh edit that moves its bounding box."""
    for vertex in mesh.vertices:
        vertex.co *= 3.0
    mesh.update()


def _add_sphere(bpy, scene, material):
    obj = bpy.data.objects.new("Sphere 3", bpy.data.objects["Sphere 2"].data.copy())
    obj.data.materials[0] = material
    obj.location = (-6.0, 0.0, 1.0)
    scene.collection.objects.link(obj)


def _exclude(bpy, scene, obj):
    off = bpy.data.collections.new("Off")
    scene.collection.children.link(off)
    off.objects.link(obj)
    scene.collection.objects.unlink(obj)
    bpy.context.view_layer.layer_collection.children["Off"].exclude = True
