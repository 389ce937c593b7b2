"""The path-traced twin of a scene an artist made, not only of New Lookdev Scene (issue 27, item 4): every material
slot of an object gets the Principled twin of its RT Lit material, objects without one stay as they are, instanced
collections are twinned, and the copies get their originals' light linking (addon/lookdev_scene.py)."""
from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("OpenEXR")

pytestmark = pytest.mark.blender

FEATURES = {"specular": "single", "diffuse": "lambert"}
#: Object name -> pass index of the objects the camera sees (2 x 2 quads in a 16 x 16 render).
SEEN = {"Multi": 1, "Plain": 2, "Excluded": 3, "Lit": 4}


def _quad(bpy, name, halves=False):
    """A 1.6 m square in the XZ plane facing -Y (the camera); two polygons when ``halves`` (left: material index 0,
    right: 1)."""
    a = 0.8
    mesh = bpy.data.meshes.new(name)
    if halves:
        mesh.from_pydata([(-a, 0, -a), (0, 0, -a), (a, 0, -a), (a, 0, a), (0, 0, a), (-a, 0, a)], [],
                         [(0, 1, 4, 5), (1, 2, 3, 4)])
        mesh.polygons[1].material_index = 1
    else:
        mesh.from_pydata([(-a, 0, -a), (a, 0, -a), (a, 0, a), (-a, 0, a)], [], [(0, 1, 2, 3)])
    mesh.update()
    return mesh


def _mix_material(bpy, name, color):
    """Mix Shader of a Diffuse and a Glossy BSDF: a material that is not RT Lit."""
    from rt_lookdev.addon import compat

    mat = compat.new_material(name)
    nt = mat.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    diffuse = nt.nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = color
    glossy = nt.nodes.new("ShaderNodeBsdfGlossy")
    glossy.inputs["Roughness"].default_value = 0.4
    mix = nt.nodes.new("ShaderNodeMixShader")
    mix.inputs["Fac"].default_value = 0.2
    nt.links.new(diffuse.outputs[0], mix.inputs[1])
    nt.links.new(glossy.outputs[0], mix.inputs[2])
    nt.links.new(mix.outputs[0], out.inputs["Surface"])
    return mat


def _object(bpy, scene, name, data, location, pass_index=0):
    obj = bpy.data.objects.new(name, data)
    obj.location = location
    obj.pass_index = pass_index
    if scene is not None:
        scene.collection.objects.link(obj)
    return obj


def _link(collection, obj, state):
    """Put ``obj`` in the light-linking ``collection`` with ``state``."""
    collection.objects.link(obj)
    collection.collection_objects[list(collection.objects).index(obj)].light_linking.link_state = state


def _link_child(collection, child, state):
    collection.children.link(child)
    collection.collection_children[list(collection.children).index(child)].light_linking.link_state = state


def _entries(collection):
    """{object or child collection name: link state} of a light-linking collection's own entries."""
    out = {o.name: e.light_linking.link_state for o, e in zip(collection.objects, collection.collection_objects)}
    children = zip(collection.children, collection.collection_children)
    out.update({c.name: e.light_linking.link_state for c, e in children})
    return out


def _rt_lit(bpy, scene, lut_dir, name, color):
    from rt_lookdev.addon import convert, lookdev_scene, materials
    from rt_lookdev.core.materials.rt_lit_interface import Features

    mat = lookdev_scene.principled_material(name, {"Base Color": color, "Roughness": 0.5})
    convert.principled_to_rt_lit(mat, lambda f: materials.ensure_rt_lit_group(f, scene, lut_dir), Features(**FEATURES))
    return mat


def _build(bpy, lut_dir):
    """The scene of the issue: one point light "Key" in front of four quads seen by the camera,
    "Multi" (slot 0 the Mix Shader material "Mix", slot 1 RT Lit "Red"), "Plain" ("Mix" only), "Excluded" (RT Lit
    "Blue" on the mesh "Quad") and "Lit" (the same mesh, its slot linked to the object: RT Lit "Green"); out of view
    "Bare" (no material) and "Prop Instancer", an empty instancing the collection "Prop" ("Prop Red": "Red",
    "Prop Mix": "Mix").  Key's receiver collection excludes "Excluded" and, through the child collection "Unlit",
    "Plain"; its blocker collection excludes "Multi" and "Lit" through "No Shadows" and includes "Lit" itself (the
    object's own entry wins).  No world, 0 bounces: each pixel is Key's direct light."""
    from rt_lookdev.addon import lookdev_scene, materials

    scene = bpy.context.scene
    scene.world = None
    lookdev_scene.configure_lookdev_render(scene, "Standard")
    scene.render.resolution_x = scene.render.resolution_y = 16
    key = lookdev_scene.light("Key", "POINT", 1000.0, (0.0, -4.0, 0.0), (0.0, 0.0, 0.0), scene.collection,
                              shadow_soft_size=0.0)
    materials.sync_scene_lights(scene)
    red = _rt_lit(bpy, scene, lut_dir, "Red", (0.8, 0.1, 0.1, 1.0))
    green = _rt_lit(bpy, scene, lut_dir, "Green", (0.1, 0.8, 0.1, 1.0))
    blue = _rt_lit(bpy, scene, lut_dir, "Blue", (0.1, 0.1, 0.8, 1.0))
    mix = _mix_material(bpy, "Mix", (0.6, 0.6, 0.6, 1.0))

    multi = _object(bpy, scene, "Multi", _quad(bpy, "Multi", halves=True), (-1.0, 0.0, 1.0), SEEN["Multi"])
    multi.data.materials.append(mix)
    multi.data.materials.append(red)
    plain = _object(bpy, scene, "Plain", _quad(bpy, "Plain"), (1.0, 0.0, 1.0), SEEN["Plain"])
    plain.data.materials.append(mix)
    quad = _quad(bpy, "Quad")
    quad.materials.append(blue)
    excluded = _object(bpy, scene, "Excluded", quad, (-1.0, 0.0, -1.0), SEEN["Excluded"])
    lit = _object(bpy, scene, "Lit", quad, (1.0, 0.0, -1.0), SEEN["Lit"])
    lit.material_slots[0].link = "OBJECT"
    lit.material_slots[0].material = green
    _object(bpy, scene, "Bare", _quad(bpy, "Bare"), (10.0, 0.0, 10.0))
    prop = bpy.data.collections.new("Prop")
    prop.objects.link(_object(bpy, None, "Prop Red", _quad(bpy, "Prop Red"), (0.0, 0.0, 0.0)))
    prop.objects["Prop Red"].data.materials.append(red)
    prop.objects.link(_object(bpy, None, "Prop Mix", _quad(bpy, "Prop Mix"), (2.0, 0.0, 0.0)))
    prop.objects["Prop Mix"].data.materials.append(mix)
    instancer = _object(bpy, scene, "Prop Instancer", None, (-10.0, 0.0, 10.0))
    instancer.instance_type = "COLLECTION"
    instancer.instance_collection = prop

    receivers = bpy.data.collections.new("Key Receivers")
    key.light_linking.receiver_collection = receivers
    _link(receivers, excluded, "EXCLUDE")
    unlit = bpy.data.collections.new("Unlit")
    unlit.objects.link(plain)
    _link_child(receivers, unlit, "EXCLUDE")
    blockers = bpy.data.collections.new("Key Blockers")
    key.light_linking.blocker_collection = blockers
    no_shadows = bpy.data.collections.new("No Shadows")
    no_shadows.objects.link(multi)
    no_shadows.objects.link(lit)
    _link_child(blockers, no_shadows, "EXCLUDE")
    _link(blockers, lit, "INCLUDE")

    cam = lookdev_scene.ortho_camera("Camera", (0.0, -10.0, 0.0), (0.5 * math.pi, 0.0, 0.0), 4.0, scene.collection)
    scene.camera = cam
    bpy.context.view_layer.update()
    return scene


def _data(bpy):
    """Names of the file's objects, collections, materials and scenes, and the light-linking entries."""
    return {"objects": set(bpy.data.objects.keys()), "collections": set(bpy.data.collections.keys()),
            "materials": set(bpy.data.materials.keys()), "scenes": set(bpy.data.scenes.keys()),
            "linking": {name: _entries(bpy.data.collections[name]) for name in ("Key Receivers", "Key Blockers")}}


def _add_twin(bpy, scene, **options):
    with bpy.context.temp_override(scene=scene):
        return bpy.ops.rtl.add_path_traced_twin('EXEC_DEFAULT', **options)


@pytest.fixture
def twin_setup(registered, empty_scene, lut_dir):
    bpy = registered
    scene = _build(bpy, lut_dir)
    before = _data(bpy)
    assert _add_twin(bpy, scene, samples=16) == {'FINISHED'}
    return bpy, scene, bpy.data.scenes[scene.name + " Path Traced"], before


def _copies(twin):
    from rt_lookdev.addon.lookdev_scene import TWIN_SOURCE_KEY

    return {o[TWIN_SOURCE_KEY]: o for o in twin.objects if TWIN_SOURCE_KEY in o.keys()}


def _assert_principled_twin(twin_material, rt_lit_material):
    """``twin_material`` is Principled, not RT Lit, with the RT Lit material's values."""
    from rt_lookdev.addon import convert

    assert twin_material is not rt_lit_material and twin_material.name == rt_lit_material.name + " Path Traced"
    assert not convert.is_rt_lit_material(twin_material)
    surface = twin_material.node_tree.get_output_node("CYCLES").inputs["Surface"]
    bsdf = surface.links[0].from_node
    assert bsdf.bl_idname == "ShaderNodeBsdfPrincipled"
    rt = convert.find_rt_lit_node(rt_lit_material)
    for key in ("Base Color", "Roughness", "Metallic"):
        assert np.allclose(np.ravel(bsdf.inputs[key].default_value), np.ravel(rt.inputs[key].default_value))


def test_twin_has_every_object_and_every_slot_twinned(twin_setup):
    """Every rendered object is in the twin: a copy where some slot is RT Lit (each such slot gets the Principled
    twin, the other slots keep their material), the object itself otherwise; one twin per RT Lit material."""
    bpy, scene, twin, _ = twin_setup
    copies = _copies(twin)
    assert set(copies) == {"Multi", "Excluded", "Lit", "Prop Instancer"}
    assert {o.name for o in twin.objects if o not in copies.values()} == {"Plain", "Bare", "Key", "Camera"}
    for name, copy in copies.items():
        original = bpy.data.objects[name]
        assert copy.data == original.data                   # the mesh is shared (Excluded and Lit share one)
        assert len(copy.material_slots) == len(original.material_slots)
        for slot, source in zip(copy.material_slots, original.material_slots):
            if source.material.name in ("Red", "Green", "Blue"):
                _assert_principled_twin(slot.material, source.material)
            else:
                assert slot.material == source.material
    mats = bpy.data.materials
    assert [s.material for s in copies["Multi"].material_slots] == [mats["Mix"], mats["Red Path Traced"]]
    assert copies["Lit"].material_slots[0].material == mats["Green Path Traced"]
    assert copies["Excluded"].material_slots[0].material == mats["Blue Path Traced"]
    # the originals are untouched: still RT Lit, "Lit" still linked to its object
    assert bpy.data.objects["Lit"].material_slots[0].link == "OBJECT"
    assert [s.material.name for s in bpy.data.objects["Multi"].material_slots] == ["Mix", "Red"]
    # the instanced collection is twinned: its RT Lit object copied, the other kept
    instanced = copies["Prop Instancer"].instance_collection
    assert instanced is not None and instanced != bpy.data.collections["Prop"]
    by_name = {o.name: o for o in instanced.objects}
    assert "Prop Mix" in by_name and by_name["Prop Mix"] == bpy.data.objects["Prop Mix"]
    (red_copy,) = [o for o in instanced.objects if o.name != "Prop Mix"]
    assert red_copy.material_slots[0].material == mats["Red Path Traced"]    # one twin for "Red"
    assert [o.name for o in bpy.data.collections["Prop"].objects] == ["Prop Red", "Prop Mix"]


def test_twin_copies_get_the_light_linking_of_their_originals(twin_setup):
    """Each copy is in the light's receiver and blocker collections with its original's state (its own entry:
    "Lit" is INCLUDE in the blockers though its child collection says EXCLUDE); removing the twin leaves the
    file as it was."""
    from rt_lookdev.addon import lookdev_scene

    bpy, scene, twin, before = twin_setup
    copies = _copies(twin)
    receivers = _entries(bpy.data.collections["Key Receivers"])
    blockers = _entries(bpy.data.collections["Key Blockers"])
    assert receivers == dict(before["linking"]["Key Receivers"], **{copies["Excluded"].name: "EXCLUDE"})
    assert blockers == dict(before["linking"]["Key Blockers"], **{copies["Multi"].name: "EXCLUDE",
                                                                   copies["Lit"].name: "INCLUDE"})
    assert [o.name for o in bpy.data.collections["Unlit"].objects] == ["Plain"]
    assert [o.name for o in bpy.data.collections["No Shadows"].objects] == ["Multi", "Lit"]
    made = _data(bpy)
    assert _add_twin(bpy, scene) == {'FINISHED'}                 # a rebuild replaces the twin, names and all
    assert _data(bpy) == made
    lookdev_scene.remove_twin(bpy.data.scenes[scene.name + " Path Traced"])
    assert _data(bpy) == before


def test_twin_lights_its_copies_as_the_light_links_say(twin_setup, tmp_path):
    """16 x 16 Cycles renders, 16 samples: in the twin every object is seen, "Excluded"'s copy and "Plain" get no
    light from Key, as "Plain" gets none in the original (Cycles honours the light linking); "Multi" (both
    halves) and "Lit" are lit."""
    from rt_lookdev.validation.checks.lookdev_twin import render_measurement

    bpy, scene, twin, _ = twin_setup
    rgb, index, _ = render_measurement(twin, (16, 16), 16, 0, tmp_path)
    original, original_index, _ = render_measurement(scene, (16, 16), 16, 0, tmp_path)
    value = rgb.max(axis=-1)
    for name, i in SEEN.items():
        assert (index == i).sum() >= 16, name                    # present in the twin
    lit = float(np.median(value[index == SEEN["Lit"]]))
    assert lit > 0.05
    assert np.median(value[index == SEEN["Multi"]]) > 0.05
    multi = value[index == SEEN["Multi"]]
    assert multi.min() > 0.01                                    # both halves: the Mix one and the twinned one
    assert value[index == SEEN["Excluded"]].max() <= 1e-4 * lit
    assert value[index == SEEN["Plain"]].max() <= 1e-4 * lit
    assert (original_index == SEEN["Plain"]).sum() >= 16
    assert original.max(axis=-1)[original_index == SEEN["Plain"]].max() <= 1e-4 * lit


def test_twin_refuses_a_linking_collection_the_scene_renders(twin_setup):
    """A light-linking collection that a scene renders cannot hold the copies (they would appear there): the
    operator says so and changes nothing; the twin made before stays."""
    bpy, scene, twin, _ = twin_setup
    props = bpy.data.collections.new("Props")
    scene.collection.children.link(props)
    props.objects.link(bpy.data.objects["Excluded"])
    bpy.data.objects["Key"].light_linking.receiver_collection = props
    bpy.context.view_layer.update()
    before = _data(bpy)
    copies = {name: o.name for name, o in _copies(twin).items()}
    with pytest.raises(RuntimeError, match="Props"):
        _add_twin(bpy, scene)
    assert _data(bpy) == before
    assert {name: o.name for name, o in _copies(bpy.data.scenes[twin.name]).items()} == copies


def test_twin_that_fails_leaves_the_file_as_it_was(twin_setup):
    """A material the twin cannot convert (no Material Output) stops the rebuild half-way: what it made is
    removed, the twin made before stays."""
    bpy, scene, twin, _ = twin_setup
    nodes = bpy.data.materials["Blue"].node_tree.nodes
    for node in [n for n in nodes if n.bl_idname == "ShaderNodeOutputMaterial"]:
        nodes.remove(node)
    before = _data(bpy)
    with pytest.raises(RuntimeError, match="Material Output"):
        _add_twin(bpy, scene)
    assert _data(bpy) == before
    assert set(_copies(bpy.data.scenes[twin.name])) == {"Multi", "Excluded", "Lit", "Prop Instancer"}


def test_twin_of_an_object_with_rt_lit_in_a_later_slot(registered, empty_scene, lut_dir):
    """The operator takes a scene whose only RT Lit material is in slot 1 (slot 0, the active one, is a Mix
    Shader material)."""
    bpy = registered
    scene = bpy.context.scene
    red = _rt_lit(bpy, scene, lut_dir, "Red", (0.8, 0.1, 0.1, 1.0))
    multi = _object(bpy, scene, "Multi", _quad(bpy, "Multi", halves=True), (0.0, 0.0, 0.0))
    multi.data.materials.append(_mix_material(bpy, "Mix", (0.6, 0.6, 0.6, 1.0)))
    multi.data.materials.append(red)
    multi.active_material_index = 0
    assert _add_twin(bpy, scene) == {'FINISHED'}
    (copy,) = _copies(bpy.data.scenes[scene.name + " Path Traced"]).values()
    _assert_principled_twin(copy.material_slots[1].material, red)
    assert copy.material_slots[0].material == bpy.data.materials["Mix"]
