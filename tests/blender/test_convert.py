"""Principled BSDF <-> RT Lit material conversion (addon/convert.py), with a stand-in RT Lit group
that has the real interface (RT_LIT_INPUTS / RT_LIT_OUTPUTS) and Radiance = Base Color."""
from __future__ import annotations

import pytest

from rt_lookdev.core.materials.rt_lit_interface import RT_LIT_INPUTS, RT_LIT_OUTPUTS, Features

pytestmark = pytest.mark.blender

SOCKET_TYPES = {"float": "NodeSocketFloat", "color": "NodeSocketColor", "vector": "NodeSocketVector",
                "shader": "NodeSocketShader"}

#: Non-default values for every mapped input but Base Color (linked) and Normal (linked).
EDITED = {
    "Metallic": 0.7,
    "Roughness": 0.23,
    "IOR": 1.33,
    "Specular IOR Level": 0.8,
    "Specular Tint": (0.9, 0.5, 0.2, 1.0),
    "Sheen Weight": 0.4,
    "Sheen Tint": (0.2, 0.6, 0.3, 1.0),
    "Emission Color": (0.1, 0.2, 0.9, 1.0),
    "Emission Strength": 2.5,
}
BASE_COLOR_UNDER_LINK = (0.3, 0.1, 0.05, 1.0)
SUBSURFACE_WEIGHT = 0.35


@pytest.fixture
def convert(bpy_module):
    from rt_lookdev.addon import convert

    return convert


class StandInFactory:
    """``group_factory(features)``: one cached stand-in group per feature set; records calls."""

    def __init__(self, bpy):
        self.bpy = bpy
        self.calls = []

    def __call__(self, features):
        self.calls.append(features)
        name = f"RT Lit stand-in ({features.label()})"
        group = self.bpy.data.node_groups.get(name)
        if group is None:
            group = self._build(name)
        return group

    def _build(self, name):
        group = self.bpy.data.node_groups.new(name, "ShaderNodeTree")
        for out_name, sock in RT_LIT_OUTPUTS.items():
            group.interface.new_socket(out_name, in_out="OUTPUT", socket_type=SOCKET_TYPES[sock.kind])
        for in_name, sock in RT_LIT_INPUTS.items():
            item = group.interface.new_socket(in_name, in_out="INPUT", socket_type=SOCKET_TYPES[sock.kind])
            item.default_value = sock.default
            if sock.min is not None:
                item.min_value = sock.min
            if sock.max is not None:
                item.max_value = sock.max
            item.hide_value = sock.hide_value
        gin = group.nodes.new("NodeGroupInput")
        gout = group.nodes.new("NodeGroupOutput")
        gout.location = (300, 0)
        group.links.new(gin.outputs["Base Color"], gout.inputs["Radiance"])
        emission = group.nodes.new("ShaderNodeEmission")
        group.links.new(gin.outputs["Base Color"], emission.inputs["Color"])
        group.links.new(emission.outputs[0], gout.inputs["Shader"])
        return group


@pytest.fixture
def factory(bpy_module, empty_scene):
    return StandInFactory(bpy_module)


def _new_material(bpy, name):
    """A new material with the default Principled BSDF -> Material Output tree."""
    from rt_lookdev.addon import compat
    mat = compat.new_material(name)
    return mat


def _principled_material(bpy, name="Lookdev", *, subsurface=SUBSURFACE_WEIGHT):
    """A Principled material: every mapped input non-default, Base Color from an image texture,
    Normal from a Normal Map node, Subsurface Weight non-default."""
    mat = _new_material(bpy, name)
    tree = mat.node_tree
    p = tree.nodes["Principled BSDF"]
    for key, value in EDITED.items():
        p.inputs[key].default_value = value
    p.inputs["Base Color"].default_value = BASE_COLOR_UNDER_LINK
    p.inputs["Subsurface Weight"].default_value = subsurface

    tex = tree.nodes.new("ShaderNodeTexImage")
    tex.name = "Albedo"
    tex.image = bpy.data.images.new("albedo", 4, 4)
    tree.links.new(tex.outputs["Color"], p.inputs["Base Color"])
    nmap = tree.nodes.new("ShaderNodeNormalMap")
    nmap.name = "Normal Map"
    nmap.inputs["Strength"].default_value = 0.6
    tree.links.new(nmap.outputs["Normal"], p.inputs["Normal"])
    return mat


from rt_lookdev.addon.common import socket_value as _value  # noqa: E402  (the same reading as the module under test)


def _close(a, b, tol=1e-6):
    if isinstance(a, tuple):
        return len(a) == len(b) and all(abs(x - y) <= tol for x, y in zip(a, b))
    return abs(a - b) <= tol


def _snapshot_inputs(node):
    """identifier -> (value or None, [(from node name, from socket identifier, muted)])"""
    return {
        s.identifier: (_value(s) if hasattr(s, "default_value") else None,
                       [(l.from_node.name, l.from_socket.identifier, l.is_muted) for l in s.links])
        for s in node.inputs
    }


def _assert_same_inputs(got, want):
    assert set(got) == set(want)
    for key in want:
        (gv, gl), (wv, wl) = got[key], want[key]
        assert gl == wl, f"{key}: links {gl} != {wl}"
        if wv is not None:
            assert _close(gv, wv), f"{key}: {gv} != {wv}"


def _snapshot_tree(tree):
    nodes = sorted((n.name, n.bl_idname, n.parent.name if n.parent else None, n.hide) for n in tree.nodes)
    links = sorted((l.from_node.name, l.from_socket.identifier, l.to_node.name, l.to_socket.identifier)
                   for l in tree.links)
    values = {n.name: _snapshot_inputs(n) for n in tree.nodes}
    return nodes, links, values


def _surface_source(tree):
    out = tree.get_output_node('ALL')
    link = out.inputs["Surface"].links[0]
    return link.from_node


def test_convert_to_rt_lit_maps_every_input(bpy_module, convert, factory):
    mat = _principled_material(bpy_module)
    tree = mat.node_tree
    p = tree.nodes["Principled BSDF"]
    features = Features(specular="kulla_conty", diffuse="wrapped", sheen=True)

    result = convert.principled_to_rt_lit(mat, factory, features)

    assert result.status == "converted"
    assert factory.calls == [features]
    rt = tree.nodes["RT Lit"]
    assert rt.bl_idname == "ShaderNodeGroup" and rt.node_tree == factory(features)
    surface = tree.nodes["Material Output"].inputs["Surface"].links[0] if "Material Output" in tree.nodes else None
    assert _surface_source(tree) == rt                      # the group's Shader feeds the output
    assert surface is None or surface.from_socket.name == "Shader"

    # Every mapped value and link lands on the RT Lit node.
    for key, value in EDITED.items():
        assert _close(_value(rt.inputs[key]), value if isinstance(value, float) else tuple(value)), key
        assert not rt.inputs[key].is_linked, key
    assert rt.inputs["Base Color"].links[0].from_socket == tree.nodes["Albedo"].outputs["Color"]
    assert rt.inputs["Normal"].links[0].from_socket == tree.nodes["Normal Map"].outputs["Normal"]
    assert set(convert.MAPPED_INPUTS) <= set(RT_LIT_INPUTS)

    # The Principled node is kept, out of the render, collapsed in the labelled frame.
    assert not p.outputs["BSDF"].is_linked
    assert p.hide and p.parent is not None and p.parent.label == convert.FRAME_LABEL
    # Subsurface (no RT Lit counterpart, non-default) is reported.
    assert result.ignored_inputs == ("Subsurface Weight",)
    assert any("Subsurface Weight" in w for w in result.warnings)
    assert convert.stored_features(mat) == features
    assert mat["rtl_features"].to_dict() == features.as_dict()


def test_round_trip_is_lossless(bpy_module, convert, factory):
    mat = _principled_material(bpy_module)
    tree = mat.node_tree
    p = tree.nodes["Principled BSDF"]
    # Some unmapped inputs non-default or linked too, and a non-default setting.
    p.inputs["Coat Weight"].default_value = 0.5
    p.inputs["Alpha"].default_value = 0.75
    tree.links.new(tree.nodes["Albedo"].outputs["Alpha"], p.inputs["Transmission Weight"])
    p.distribution = 'GGX'
    before_inputs = _snapshot_inputs(p)
    before_tree = _snapshot_tree(tree)
    location = tuple(p.location)
    groups = set(bpy_module.data.node_groups.keys())

    result = convert.principled_to_rt_lit(mat, factory)
    assert set(result.ignored_inputs) == {"Alpha", "Subsurface Weight", "Transmission Weight", "Coat Weight"}
    converted = Features(sheen="zeltner")         # the material has Sheen Weight 0.4: Blender's own sheen
    assert convert.stored_features(mat) == converted

    back = convert.rt_lit_to_principled(mat)
    assert back.status == "converted" and not back.warnings
    p = tree.nodes["Principled BSDF"]
    _assert_same_inputs(_snapshot_inputs(p), before_inputs)
    assert _snapshot_tree(tree) == before_tree
    assert p.distribution == 'GGX' and tuple(p.location) == pytest.approx(location)
    assert _surface_source(tree) == p
    assert "RT Lit" not in tree.nodes and not any(n.bl_idname == "NodeFrame" for n in tree.nodes)
    assert all(k not in p for k in ("rtl_role", "rtl_location", "rtl_parent", "rtl_hide"))
    # The RT Lit group datablock is left alone; the material still remembers its switches.
    assert set(bpy_module.data.node_groups.keys()) >= groups | {factory(converted).name}
    assert convert.stored_features(mat) == converted


def test_edits_made_in_rt_lit_survive(bpy_module, convert, factory):
    mat = _principled_material(bpy_module)
    tree = mat.node_tree
    convert.principled_to_rt_lit(mat, factory)
    rt = tree.nodes["RT Lit"]
    rt.inputs["Roughness"].default_value = 0.81
    rt.inputs["Specular Tint"].default_value = (0.1, 0.2, 0.3, 1.0)
    # Relink: the normal map goes, a value node drives Metallic.
    tree.links.remove(rt.inputs["Normal"].links[0])
    value = tree.nodes.new("ShaderNodeValue")
    value.name = "Metal Mask"
    tree.links.new(value.outputs[0], rt.inputs["Metallic"])
    rt.inputs["Wrap"].default_value = 0.3  # RT Lit only: remembered for the next conversion

    back = convert.rt_lit_to_principled(mat)
    assert not back.warnings
    p = tree.nodes["Principled BSDF"]
    assert p.inputs["Roughness"].default_value == pytest.approx(0.81)
    assert tuple(p.inputs["Specular Tint"].default_value) == pytest.approx((0.1, 0.2, 0.3, 1.0))
    assert not p.inputs["Normal"].is_linked
    assert p.inputs["Metallic"].links[0].from_node.name == "Metal Mask"
    assert p.inputs["Base Color"].links[0].from_node.name == "Albedo"
    assert p.inputs["Subsurface Weight"].default_value == pytest.approx(SUBSURFACE_WEIGHT)

    convert.principled_to_rt_lit(mat, factory)
    assert tree.nodes["RT Lit"].inputs["Wrap"].default_value == pytest.approx(0.3)
    assert tree.nodes["RT Lit"].inputs["Roughness"].default_value == pytest.approx(0.81)


def test_material_without_principled_is_an_error_and_unchanged(bpy_module, convert, factory):
    mat = _new_material(bpy_module, "Diffuse")
    tree = mat.node_tree
    tree.nodes.remove(tree.nodes["Principled BSDF"])
    diffuse = tree.nodes.new("ShaderNodeBsdfDiffuse")
    tree.links.new(diffuse.outputs["BSDF"], tree.nodes["Material Output"].inputs["Surface"])
    before = _snapshot_tree(tree)
    groups = set(bpy_module.data.node_groups.keys())

    with pytest.raises(convert.ConversionError, match="must be fed by a Principled BSDF.*Diffuse BSDF"):
        convert.principled_to_rt_lit(mat, factory)
    with pytest.raises(convert.ConversionError, match="not an RT Lit material"):
        convert.rt_lit_to_principled(mat)
    assert _snapshot_tree(tree) == before
    assert set(bpy_module.data.node_groups.keys()) == groups
    assert "rtl_features" not in mat and not factory.calls

    # An empty Surface is an error too.
    tree.links.remove(tree.nodes["Material Output"].inputs["Surface"].links[0])
    with pytest.raises(convert.ConversionError, match="fed by nothing"):
        convert.principled_to_rt_lit(mat, factory)


def test_converting_twice_is_idempotent(bpy_module, convert, factory):
    mat = _principled_material(bpy_module)
    tree = mat.node_tree
    convert.principled_to_rt_lit(mat, factory)
    once = _snapshot_tree(tree)

    again = convert.principled_to_rt_lit(mat, factory)
    assert again.status == "unchanged" and not again.warnings
    assert _snapshot_tree(tree) == once

    # New switches swap the group and keep every value and link.
    sheen = Features(sheen=True)
    tree.nodes["RT Lit"].inputs["Roughness"].default_value = 0.66
    rt_inputs = _snapshot_inputs(tree.nodes["RT Lit"])
    updated = convert.principled_to_rt_lit(mat, factory, sheen)
    assert updated.status == "updated"
    assert tree.nodes["RT Lit"].node_tree == factory(sheen)
    _assert_same_inputs(_snapshot_inputs(tree.nodes["RT Lit"]), rt_inputs)
    assert len(tree.nodes) == len(once[0])
    assert convert.stored_features(mat) == sheen

    # Back twice: the second is an error that changes nothing.
    convert.rt_lit_to_principled(mat)
    principled = _snapshot_tree(tree)
    with pytest.raises(convert.ConversionError):
        convert.rt_lit_to_principled(mat)
    assert _snapshot_tree(tree) == principled
    # ... and the material remembers its switches for the next conversion.
    convert.principled_to_rt_lit(mat, factory)
    assert tree.nodes["RT Lit"].node_tree == factory(sheen)
    assert [n.name for n in tree.nodes].count("RT Lit") == 1


def test_plain_principled_converts_without_warning(bpy_module, convert, factory):
    mat = _new_material(bpy_module, "Plain")
    before = _snapshot_inputs(mat.node_tree.nodes["Principled BSDF"])
    result = convert.principled_to_rt_lit(mat, factory)
    assert result.ignored_inputs == () and not result.warnings
    convert.rt_lit_to_principled(mat)
    _assert_same_inputs(_snapshot_inputs(mat.node_tree.nodes["Principled BSDF"]), before)


def test_back_conversion_without_kept_principled_creates_one(bpy_module, convert, factory):
    mat = _principled_material(bpy_module)
    tree = mat.node_tree
    convert.principled_to_rt_lit(mat, factory)
    tree.nodes.remove(tree.nodes["Principled BSDF"])
    result = convert.rt_lit_to_principled(mat)
    assert any("not found" in w for w in result.warnings)
    p = _surface_source(tree)
    assert p.bl_idname == "ShaderNodeBsdfPrincipled"
    for key, value in EDITED.items():
        assert _close(_value(p.inputs[key]), value if isinstance(value, float) else tuple(value)), key
    assert p.inputs["Normal"].links[0].from_node.name == "Normal Map"


@pytest.fixture
def operators(bpy_module, convert, factory, monkeypatch):
    from rt_lookdev.addon import convert_ui

    monkeypatch.setattr(convert, "default_group_factory", lambda lut_dir=None: factory)
    for cls in convert_ui.classes:
        bpy_module.utils.register_class(cls)
    yield bpy_module.ops.rtl
    for cls in reversed(convert_ui.classes):
        bpy_module.utils.unregister_class(cls)


def _object_with(bpy, scene, *materials):
    mesh = bpy.data.meshes.new("mesh")
    obj = bpy.data.objects.new("obj", mesh)
    scene.collection.objects.link(obj)
    for mat in materials:
        obj.data.materials.append(mat)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    return obj


def test_operators(bpy_module, empty_scene, convert, factory, operators):
    from rt_lookdev.addon.convert_ui import RTL_OT_convert_to_principled, RTL_OT_convert_to_rt_lit

    assert RTL_OT_convert_to_rt_lit.bl_idname == "rtl.convert_to_rt_lit"
    assert RTL_OT_convert_to_principled.bl_idname == "rtl.convert_to_principled"
    assert not operators.convert_to_rt_lit.poll()  # nothing selected, no active material
    assert not operators.convert_to_principled.poll()

    first, second = _principled_material(bpy_module, "A"), _principled_material(bpy_module, "B", subsurface=0.0)
    obj = _object_with(bpy_module, empty_scene, first, second)
    obj.active_material_index = 1
    assert operators.convert_to_rt_lit.poll() and not operators.convert_to_principled.poll()

    # Active material only, with switches.
    assert operators.convert_to_rt_lit(target='ACTIVE', specular='single', cloth=True) == {'FINISHED'}
    assert convert.is_rt_lit_material(second) and not convert.is_rt_lit_material(first)
    assert convert.stored_features(second) == Features(specular="single", cloth=True)
    assert operators.convert_to_principled.poll()

    # Every material of the selected objects (B again: unchanged, no duplicate nodes).
    nodes_b = len(second.node_tree.nodes)
    assert operators.convert_to_rt_lit(target='SELECTED') == {'FINISHED'}
    assert convert.is_rt_lit_material(first)
    assert len(second.node_tree.nodes) == nodes_b
    assert convert.stored_features(first) == Features()

    assert operators.convert_to_principled(target='SELECTED') == {'FINISHED'}
    assert not convert.is_rt_lit_material(first) and not convert.is_rt_lit_material(second)
    assert not operators.convert_to_principled.poll()


def test_operator_reports_error_and_changes_nothing(bpy_module, empty_scene, convert, operators):
    mat = _new_material(bpy_module, "Emissive")
    tree = mat.node_tree
    tree.nodes.remove(tree.nodes["Principled BSDF"])
    emission = tree.nodes.new("ShaderNodeEmission")
    tree.links.new(emission.outputs[0], tree.nodes["Material Output"].inputs["Surface"])
    _object_with(bpy_module, empty_scene, mat)
    before = _snapshot_tree(tree)

    assert operators.convert_to_rt_lit.poll()
    with pytest.raises(RuntimeError, match="Principled BSDF"):
        operators.convert_to_rt_lit()
    assert _snapshot_tree(tree) == before
    assert "rtl_features" not in mat


def test_principled_in_a_frame_behind_a_reroute(bpy_module, convert, factory):
    mat = _principled_material(bpy_module, "Framed")
    tree = mat.node_tree
    p, out = tree.nodes["Principled BSDF"], tree.nodes["Material Output"]
    frame = tree.nodes.new("NodeFrame")
    frame.name = "Shading"
    p.parent = frame
    reroute = tree.nodes.new("NodeReroute")
    tree.links.new(p.outputs["BSDF"], reroute.inputs[0])
    tree.links.new(reroute.outputs[0], out.inputs["Surface"])
    location = tuple(getattr(p, "location_absolute", p.location))

    convert.principled_to_rt_lit(mat, factory)
    assert _surface_source(tree).name == "RT Lit"
    assert p.parent.name == "RT Lit Kept Principled"
    convert.rt_lit_to_principled(mat)
    assert p.parent == frame and not p.hide
    assert tuple(getattr(p, "location_absolute", p.location)) == pytest.approx(location)
    assert _surface_source(tree) == p


def test_driven_inputs_stay_driven_both_ways(bpy_module, convert, factory):
    """A Principled input driven by an object's property is driven on the RT Lit node after Convert, and on
    the Principled again after converting back (the drivers move, so one evaluates at a time)."""
    bpy = bpy_module
    mat = _principled_material(bpy, "Driven")
    tree = mat.node_tree
    target = bpy.data.objects.new("Driver Target", None)
    bpy.context.scene.collection.objects.link(target)
    target.location = (0.25, 0.0, 0.0)
    fc = tree.nodes["Principled BSDF"].inputs["Roughness"].driver_add("default_value")
    var = fc.driver.variables.new()
    var.name, var.type = "x", "TRANSFORMS"
    var.targets[0].id = target
    var.targets[0].transform_type = "LOC_X"
    fc.driver.expression = "x * 2"
    tint = tree.nodes["Principled BSDF"].inputs["Sheen Tint"].driver_add("default_value", 1)
    tint.driver.expression = "0.125"
    convert.principled_to_rt_lit(mat, factory)
    rt = convert.find_rt_lit_node(mat)
    paths = {(d.data_path, d.array_index): d for d in tree.animation_data.drivers}
    rough = paths[(rt.inputs["Roughness"].path_from_id("default_value"), 0)]
    assert rough.driver.expression == "x * 2" and rough.driver.variables[0].targets[0].id == target
    assert rough.driver.variables[0].targets[0].transform_type == "LOC_X"
    assert (rt.inputs["Sheen Tint"].path_from_id("default_value"), 1) in paths
    assert len(tree.animation_data.drivers) == 2                       # moved, not copied
    bpy.context.view_layer.update()
    bpy.context.evaluated_depsgraph_get().update()
    convert.rt_lit_to_principled(mat)
    p = _surface_source(tree)
    paths = {(d.data_path, d.array_index) for d in tree.animation_data.drivers}
    assert paths == {(p.inputs["Roughness"].path_from_id("default_value"), 0),
                     (p.inputs["Sheen Tint"].path_from_id("default_value"), 1)}


def test_linked_material_is_refused_with_the_fix(bpy_module, convert, factory, relink_from_library):
    """A material linked from a library: an error naming the library and how to make it local; unchanged."""
    bpy = bpy_module
    _principled_material(bpy, "Library Material")
    mat = relink_from_library("materials", "Library Material")
    before = _snapshot_tree(mat.node_tree)
    with pytest.raises(convert.ConversionError, match="library.blend.*Make Local"):
        convert.principled_to_rt_lit(mat, factory)
    assert _snapshot_tree(mat.node_tree) == before


def test_sheen_off_with_a_sheen_material_says_so(bpy_module, convert, factory):
    """A Principled material with sheen: the dialog proposes Sheen on; converting with it off warns that the
    sheen is not shaded (it used to vanish silently)."""
    mat = _principled_material(bpy_module, "Velvet")          # EDITED: Sheen Weight 0.4
    assert convert.principled_uses_sheen(mat)
    result = convert.principled_to_rt_lit(mat, factory, Features(sheen=False))
    assert any("Sheen Weight 0.4 is not shaded" in w and "Sheen on" in w for w in result.warnings)
    # without explicit switches a Principled material with sheen gets Blender's own sheen, Sheen Roughness mapped
    velvet = _principled_material(bpy_module, "Velvet 2")
    principled = next(n for n in velvet.node_tree.nodes if n.bl_idname == "ShaderNodeBsdfPrincipled")
    principled.inputs["Sheen Roughness"].default_value = 0.25
    assert convert.principled_to_rt_lit(velvet, factory).features.sheen == "zeltner"
    assert convert.find_rt_lit_node(velvet).inputs["Sheen Roughness"].default_value == pytest.approx(0.25)
    plain = _new_material(bpy_module, "Plain")
    assert not convert.principled_uses_sheen(plain)
    assert not any("Sheen" in w for w in convert.principled_to_rt_lit(plain, factory, Features()).warnings)


def test_switches_in_the_panel_rebuild_the_group(bpy_module, empty_scene, lut_dir):
    """Material.rtl_switches shows the stored switches and, when one is set, rebuilds the material's RT Lit
    group with it (values and links kept), as the Convert dialog does."""
    from rt_lookdev import addon
    from rt_lookdev.addon import convert

    addon.register()
    try:
        mat = _principled_material(bpy_module, "Switchable")
        convert.principled_to_rt_lit(mat, convert.default_group_factory(lut_dir), Features("turquin", "cod"))
        switches = mat.rtl_switches
        assert (switches.specular, switches.diffuse, switches.sheen) == ("turquin", "cod", "none")
        rt = convert.find_rt_lit_node(mat)
        roughness = rt.inputs["Roughness"].default_value
        switches.sheen = "zeltner"
        switches.specular = "kulla_conty"
        assert convert.stored_features(mat) == Features("kulla_conty", "cod", sheen="zeltner")
        rt = convert.find_rt_lit_node(mat)
        assert "kulla-conty, cod, zeltner sheen" in rt.node_tree.name
        assert rt.inputs["Roughness"].default_value == roughness and rt.inputs["Base Color"].is_linked
        assert (switches.specular, switches.sheen) == ("kulla_conty", "zeltner")
        assert switches.horizon == "sphere_table"
        switches.horizon = "exact_quads"                   # quads clipped at the horizon: its own group, values kept
        assert convert.stored_features(mat) == Features("kulla_conty", "cod", sheen="zeltner", horizon="exact_quads")
        rt = convert.find_rt_lit_node(mat)
        assert "exact-quads horizon" in rt.node_tree.name and rt.inputs["Base Color"].is_linked
        mat["rtl_features"]["sheen"] = 1           # a file saved with the old switch: the talk's Disney sheen
        assert switches.sheen == "disney_talk"
    finally:
        addon.unregister()


def test_exact_horizon_warns_in_blender_4(bpy_module, convert, factory):
    """An exact area-light horizon converts everywhere, with a warning in Blender 4.x where its Cycles runs out of
    shader stack with it: for every switch on, not for Turquin + CoD (measured: core/materials/cycles_capacity.py,
    EXACT_HORIZON_IN_4; docs/area_lights.md)."""
    from rt_lookdev.addon import compat

    mat = compat.new_material("Horizon")
    result = convert.principled_to_rt_lit(mat, factory, Features("turquin", "cod", horizon="exact_quads"))
    assert result.status == "converted" and convert.stored_features(mat).horizon == "exact_quads"
    assert not any("shader stack" in w for w in result.warnings)
    every = Features("kulla_conty", "wrapped", sheen=True, cloth=True, horizon="exact")
    result = convert.principled_to_rt_lit(compat.new_material("Every"), factory, every)
    assert result.status == "converted"
    warned = any("shader stack" in w for w in result.warnings)
    assert warned == (bpy_module.app.version < (5, 0, 0))
    plain = convert.principled_to_rt_lit(compat.new_material("Plain"), factory,
                                         Features("kulla_conty", "wrapped", sheen=True, cloth=True))
    assert not any("shader stack" in w for w in plain.warnings)


def test_diffuse_roughness_maps_both_ways_and_is_proposed(bpy_module, convert, factory):
    """Principled's Diffuse Roughness: the dialog proposes the Oren-Nayar diffuse for it, the value maps to RT Lit's
    input and back, and another diffuse model says it is not shaded."""
    from rt_lookdev.addon import compat

    mat = compat.new_material("Clay")
    principled = mat.node_tree.nodes["Principled BSDF"]
    assert not convert.principled_uses_diffuse_roughness(mat)          # Blender's default: 0
    principled.inputs["Diffuse Roughness"].default_value = 0.65
    assert convert.principled_uses_diffuse_roughness(mat)
    assert "Diffuse Roughness" in convert.MAPPED_INPUTS

    result = convert.principled_to_rt_lit(mat, factory, Features("turquin", "oren_nayar"))
    rt = mat.node_tree.nodes["RT Lit"]
    assert rt.inputs["Diffuse Roughness"].default_value == pytest.approx(0.65)
    assert not result.ignored_inputs and not any("Diffuse Roughness" in w for w in result.warnings)
    rt.inputs["Diffuse Roughness"].default_value = 0.3                    # edited in RT Lit
    back = convert.rt_lit_to_principled(mat)
    assert back.status == "converted"
    assert mat.node_tree.nodes["Principled BSDF"].inputs["Diffuse Roughness"].default_value == pytest.approx(0.3)

    # another diffuse model: converted, with the roughness kept on the node and a warning that it is not shaded
    result = convert.principled_to_rt_lit(mat, factory, Features("turquin", "cod"))
    assert mat.node_tree.nodes["RT Lit"].inputs["Diffuse Roughness"].default_value == pytest.approx(0.3)
    assert any("Diffuse Roughness 0.3 is not shaded" in w and "Oren-Nayar" in w for w in result.warnings)
