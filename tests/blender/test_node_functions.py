"""Node functions as nested node groups: conformance with numpy, stamps, reuse, interface."""
from __future__ import annotations

import numpy as np
import pytest

from rt_lookdev.core.materials.lobes import LOBES
from rt_lookdev.validation.harness.conformance import check_function
from rt_lookdev.validation.harness.grids import area_lobe_inputs as _area_inputs
from rt_lookdev.validation.harness.grids import punctual_lobe_inputs as _punctual_inputs
from rt_lookdev.validation.harness.grids import shade_inputs, surface_inputs, technique_function_inputs

pytest.importorskip("OpenEXR")

pytestmark = pytest.mark.blender


@pytest.mark.parametrize("lobe", sorted(LOBES))
def test_punctual_lobe_groups_match_numpy(empty_scene, tables, lobe):
    from rt_lookdev.core.materials import lobes

    fn = lobes.LOBES[lobe].function("point")
    vals = _punctual_inputs()
    check_function(fn, {k: vals[k] for k in fn.input_sockets}, tables)


def _nested_trees(ng):
    """``ng`` and every group tree nested in it, once each."""
    trees = {ng.name: ng}
    for tree in list(trees.values()):
        for node in tree.nodes:
            if node.bl_idname == "ShaderNodeGroup" and node.node_tree.name not in trees:
                trees[node.node_tree.name] = node.node_tree
                trees.update({t.name: t for t in _nested_trees(node.node_tree)})
    return list(trees.values())


@pytest.mark.parametrize("kind", ["quad+spread", "disk+spread"])
def test_no_separate_xyz_output_is_left_unread(empty_scene, tables, kind):
    """Cycles gives every output of a Separate XYZ a slot on its SVM stack and frees a slot only once its last reader
    is done, so an unread output holds one for the whole shader; in Blender 4.5 such slots (the spread's rules had
    dozens) took GGX and four other lobes under lights with spread past its 255 floats (node_emit, _emit_component).
    A vector read in part becomes Dot Products with the axes, which the lobe tests render against numpy."""
    from rt_lookdev.addon.node_emit import ensure_function_group
    from rt_lookdev.core.materials import lobes

    trees = _nested_trees(ensure_function_group(lobes.GGX.function(kind), tables))
    separates = [(t.name, n) for t in trees for n in t.nodes if n.bl_idname == "ShaderNodeSeparateXYZ"]
    unread = [(name, s.name) for name, n in separates for s in n.outputs if not s.is_linked]
    assert not unread, unread
    components = [n for t in trees for n in t.nodes if n.bl_idname == "ShaderNodeVectorMath" and n.label == "component"]
    assert components and all(n.operation == "DOT_PRODUCT" for n in components)


def test_groups_are_stamped_reused_and_rebuilt_in_place(empty_scene, tables):
    import bpy

    from rt_lookdev.addon.node_emit import MAX_GROUP_NODES, ensure_function_group, tree_node_counts
    from rt_lookdev.core.materials import lobes

    fn = lobes.GGX.function("point")
    ng = ensure_function_group(fn, tables)
    assert ng.name == "RTL Punctual GGX" and ng["rtl_stamp"].endswith(fn.function.key)
    ng.nodes[0]["marker"] = 1                       # survives only if the group is not rebuilt
    groups_before = len(bpy.data.node_groups)
    assert ensure_function_group(fn, tables) == ng
    assert ng.nodes[0].get("marker") == 1 and len(bpy.data.node_groups) == groups_before
    ng["rtl_stamp"] = "stale"                       # as if the source had changed
    assert ensure_function_group(fn, tables) == ng                     # same datablock...
    assert all(n.get("marker") is None for n in ng.nodes)              # ...rebuilt
    assert ng["rtl_stamp"].endswith(fn.function.key)
    assert max(tree_node_counts(ng).values()) <= MAX_GROUP_NODES
    # the same table image serves every lookup
    assert len([i for i in bpy.data.images if i.name == "RTL_ggx_one_minus_E"]) == 1


def test_interface_has_descriptions_ranges_and_panels(empty_scene, tables):
    from rt_lookdev.addon.node_emit import ensure_function_group
    from rt_lookdev.core.materials.surface import SURFACE

    ng = ensure_function_group(SURFACE, tables)
    items = {i.name: i for i in ng.interface.items_tree}
    rough = items["Roughness"]
    assert rough.subtype == "FACTOR" and rough.min_value == 0.0 and rough.max_value == 1.0
    assert rough.default_value == pytest.approx(0.5) and "roughness" in rough.description.lower()
    assert items["Base Color"].socket_type == "NodeSocketColor"
    assert items["Normal"].hide_value
    panels = {i.name for i in ng.interface.items_tree if i.item_type == "PANEL"}
    assert {"Surface", "Specular", "Sheen", "Cloth"} <= panels
    assert items["Metallic"].parent.name == "Surface"


@pytest.mark.parametrize("kind", ["quad", "disk", "quad+spread", "disk+spread"])
@pytest.mark.parametrize("lobe", sorted(LOBES))
def test_area_lobe_groups_match_numpy(empty_scene, tables, kind, lobe):
    from rt_lookdev.addon.node_emit import MAX_GROUP_NODES, ensure_function_group, tree_node_counts
    from rt_lookdev.core.materials import lobes

    fn = lobes.LOBES[lobe].function(kind)
    vals = _area_inputs(kind)
    check_function(fn, {k: vals[k] for k in fn.input_sockets}, tables)
    counts = tree_node_counts(ensure_function_group(fn, tables))
    print(counts)
    assert max(counts.values()) <= MAX_GROUP_NODES


# Exact horizons (Features.horizon, issue 30) render as numpy where they fit Cycles' SVM stack in Blender 4.5 too (in
# 5.2 every lobe and feature set fits).
@pytest.mark.parametrize("kind, lobe", [("quad", "lambert"), ("quad", "ggx"), ("quad", "cod"), ("disk", "lambert"),
                                        ("disk", "cod"), ("disk", "ggx")])
def test_exact_horizon_groups_match_numpy(empty_scene, tables, kind, lobe):
    from rt_lookdev.core.materials import light_shading
    from rt_lookdev.core.materials.rt_lit_interface import Features

    fn = LOBES[lobe].function(kind, exact_horizon=True)
    vals = _area_inputs(kind)
    check_function(fn, {k: vals[k] for k in fn.input_sockets}, tables)
    if kind == "quad" and lobe == "ggx":
        shade = light_shading.shade_function(kind, Features("turquin", "cod", horizon="exact_quads"))
        vals = shade_inputs(kind)
        check_function(shade, {k: np.asarray(vals[k], np.float32) for k in shade.input_sockets}, tables)


@pytest.mark.parametrize("kind", ["quad", "disk", "point", "spot", "sun"])
def test_shade_groups_match_numpy(empty_scene, tables, kind):
    """A whole light on the material (all lobes of two feature sets), nested groups included."""
    from rt_lookdev.core.materials import light_shading
    from rt_lookdev.core.materials.rt_lit_interface import Features

    vals = shade_inputs(kind)
    for features in (Features("kulla_conty", "wrapped", sheen=True, cloth=True), Features("turquin", "cod"),
                     Features("none", "cod", sheen=True, cloth=True), Features("fdez_aguera", "cod_wrapped"),
                     Features("turquin", "oren_nayar"), Features("turquin", "cod", sheen="zeltner"),
                     Features("single", "lambert", sheen="disney_fitted")):
        fn = light_shading.shade_function(kind, features)
        check_function(fn, {k: np.asarray(vals[k], np.float32) for k in fn.input_sockets}, tables)


def test_surface_group_matches_numpy(empty_scene, tables):
    from rt_lookdev.core.materials.surface import SURFACE

    vals = surface_inputs(SURFACE.input_sockets)
    check_function(SURFACE, {k: np.asarray(v, np.float32) for k, v in vals.items()}, tables)


def test_every_catalog_group_builds_small_and_the_technique_groups_match_numpy(empty_scene, tables):
    import bpy

    from rt_lookdev.addon.node_emit import MAX_GROUP_NODES, ensure_function_group, tree_node_counts
    from rt_lookdev.addon.operators import RTL_OT_add_node_groups
    from rt_lookdev.addon.preferences import classes as pref_classes  # noqa: F401
    from rt_lookdev.core import falloff, multiscatter
    from rt_lookdev.node_groups import library

    counts = {}
    for fn in library.all_functions():
        counts.update(tree_node_counts(ensure_function_group(fn, tables)))
    assert all(fn.name in bpy.data.node_groups for fn in library.all_functions())
    assert max(counts.values()) <= MAX_GROUP_NODES, max(counts.items(), key=lambda kv: kv[1])
    assert all(bpy.data.node_groups[fn.name].description for fn in library.all_functions())
    vals = technique_function_inputs()
    for fn in multiscatter.NODE_FUNCTIONS + falloff.NODE_FUNCTIONS:
        check_function(fn, {k: np.asarray(vals[k], np.float32) for k in fn.input_sockets}, tables)
    # the operator builds the same set, reusing what exists
    bpy.utils.register_class(RTL_OT_add_node_groups)
    try:
        before = len(bpy.data.node_groups)
        assert bpy.ops.rtl.add_node_groups() == {"FINISHED"}
        assert len(bpy.data.node_groups) == before
    finally:
        bpy.utils.unregister_class(RTL_OT_add_node_groups)
