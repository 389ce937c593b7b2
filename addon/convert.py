"""Convert a Principled BSDF material into an RT Lit lookdev material and back: the node-tree edits (the
RT Lit node built, the kept Principled restored, values, links and drivers transferred).  Which inputs
correspond and how a value crosses is ``core/materials/principled_mapping.py``; the operators and the
switches' UI are ``convert_ui.py``.

An RT Lit material's surface is ``RT Lit group node (Shader output) -> Material Output``: the
group computes the outgoing radiance itself and emits it (one Emission closure per light inside
the group; older materials with an Emission node in between are still recognised).  The group's inputs
(``RT_LIT_INPUTS``) take the Principled BSDF's names where one exists, so the conversion maps
them one to one (``MAPPED_INPUTS``): a linked input is re-linked from the same source socket, an
unlinked one gets the value copied (the value is copied under a link too, so it is there when
the link goes).

The round trip is lossless: the original Principled BSDF node is kept in the tree, unlinked
from the output, collapsed in a frame labelled ``FRAME_LABEL``; its inputs without an RT Lit
counterpart (Subsurface, Coat, Alpha, ...) and its settings (distribution, subsurface method)
stay on it untouched.  Converting back writes the RT Lit node's current values and links into
it (so edits made in RT Lit survive), reconnects it to the output and removes the RT Lit nodes;
the RT Lit group datablock is left alone.  The RT Lit-only inputs (Wrap, Cloth ...) have no
Principled counterpart: their unlinked values are remembered on the material and restored on the
next conversion.

The material remembers its switches in ``material[common.FEATURES_KEY]`` (a dict of ``Features``);
a conversion without explicit features reuses them.  Converting an RT Lit material again is
idempotent: no nodes are added, the group is swapped only when the features ask for another one.

The functions here raise ``ConversionError`` (before changing anything) when a material cannot
be converted; the operators (``convert_ui``) turn that into reports.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import bpy

from ..core.materials import cycles_capacity
from ..core.materials.principled_mapping import (LINK_ONLY_INPUTS, MAPPED_INPUTS, RT_LIT_ONLY_INPUTS, converted_value,
                                                values_equal)
from ..core.materials.rt_lit_interface import PRINCIPLED_SHEEN, Features
from .common import (FEATURES_KEY, RT_LIT_NODE_NAME, active_output, connect_engine_outputs, not_a_light,
                     restore_emission_sampling, restore_engine_outputs, socket_value, source_node)
from .materials import ensure_rt_lit_group

EMISSION_NODE_NAME = "RT Lit Emission"
FRAME_NODE_NAME = "RT Lit Kept Principled"
FRAME_LABEL = "Original Principled (kept for conversion back)"
RT_LIT_OUTPUT = "Shader"

#: Custom properties.  On the material: ``common.FEATURES_KEY`` (dict of Features: the switches) and
RT_ONLY_VALUES_PROP = "rtl_rt_only"     # dict: RT Lit-only input values, kept while Principled
#: On nodes this module creates or keeps:
ROLE_PROP = "rtl_role"                  # "rt_lit" | "emission" | "frame" | "kept_principled"
SAVED_LOCATION_PROP = "rtl_location"    # kept Principled: where it stood (absolute)
SAVED_PARENT_PROP = "rtl_parent"        # kept Principled: its frame before ("" = none)
SAVED_HIDE_PROP = "rtl_hide"            # kept Principled: was it collapsed


class ConversionError(ValueError):
    """A material cannot be converted; raised before anything is changed."""


@dataclass
class ConversionResult:
    """What a conversion did.  ``status``: "converted", "updated" (an RT Lit material got new
    switches) or "unchanged" (an RT Lit material converted again with the same switches)."""
    material: str
    status: str
    warnings: list[str] = field(default_factory=list)
    #: Principled inputs RT Lit ignores that were non-default or linked (kept on the stored node).
    ignored_inputs: tuple[str, ...] = ()
    features: Features | None = None


# --------------------------------------------------------------------------------------------
# Tree helpers


def _role(node):
    try:
        return node.get(ROLE_PROP)
    except TypeError:  # nodes without ID properties
        return None


def _nodes_with_role(tree, role):
    return [n for n in tree.nodes if _role(n) == role]


def _is_rt_lit_node(node):
    return node is not None and node.bl_idname == "ShaderNodeGroup" and (
        _role(node) == "rt_lit" or node.name == RT_LIT_NODE_NAME)


def _rt_lit_feeding(output):
    """The RT Lit node feeding the output's Surface (directly or through an Emission), or None."""
    node = source_node(output.inputs["Surface"])
    if node is not None and node.bl_idname == "ShaderNodeEmission":
        node = source_node(node.inputs["Color"])
    return node if _is_rt_lit_node(node) else None


def find_rt_lit_node(material):
    """The material's RT Lit group node: the one feeding the active output, else any (tagged or
    named ``RT_LIT_NODE_NAME``), else None."""
    tree = material.node_tree
    if tree is None:
        return None
    output = active_output(tree)
    node = _rt_lit_feeding(output) if output is not None else None
    if node is not None:
        return node
    tagged = [n for n in tree.nodes if n.bl_idname == "ShaderNodeGroup" and _role(n) == "rt_lit"]
    if tagged:
        return tagged[0]
    node = tree.nodes.get(RT_LIT_NODE_NAME)
    return node if _is_rt_lit_node(node) else None


def is_rt_lit_material(material):
    return material is not None and find_rt_lit_node(material) is not None


def _copy_value(src, dst):
    """Copy ``src``'s default value to ``dst`` (float, colour or vector; sizes adapted)."""
    if not hasattr(src, "default_value") or not hasattr(dst, "default_value"):
        return
    dst.default_value = converted_value(socket_value(src), socket_value(dst))


def _relink(tree, src_input, dst_input):
    """Make ``dst_input``'s links those of ``src_input`` (same source sockets), or none."""
    for link in list(dst_input.links):
        tree.links.remove(link)
    for link in src_input.links:
        new = tree.links.new(link.from_socket, dst_input)
        new.is_muted = link.is_muted


def _socket_drivers(tree, socket):
    """The drivers of ``socket``'s value (one per component), from the tree's animation data."""
    if tree.animation_data is None or not hasattr(socket, "default_value"):
        return []
    path = socket.path_from_id("default_value")
    return [fc for fc in tree.animation_data.drivers if fc.data_path == path]


def _copy_driver(src, dst):
    """Make the driver ``dst`` (a new driver F-curve's ``.driver``) compute what ``src`` computes."""
    dst.type = src.type
    dst.expression = src.expression
    dst.use_self = src.use_self
    for var in src.variables:
        new = dst.variables.new()
        new.name, new.type = var.name, var.type
        for t_src, t_dst in zip(var.targets, new.targets):
            if var.type == "SINGLE_PROP":
                t_dst.id_type = t_src.id_type
            t_dst.id = t_src.id
            for attr in ("data_path", "bone_target", "transform_type", "transform_space", "rotation_mode"):
                setattr(t_dst, attr, getattr(t_src, attr))


def _move_drivers(tree, src, dst):
    """Move the drivers of ``src``'s value onto ``dst``'s (a driven Principled input stays driven in RT Lit
    and back); a driver on a component ``dst`` lacks is dropped."""
    for fc in _socket_drivers(tree, src):
        size = len(socket_value(dst)) if isinstance(socket_value(dst), tuple) else 0
        if size and fc.array_index >= size:
            continue
        new = dst.driver_add("default_value", fc.array_index) if size else dst.driver_add("default_value")
        _copy_driver(fc.driver, new.driver)
        tree.animation_data.drivers.remove(fc)


def _transfer(tree, src_node, dst_node, names):
    """Copy values, links and drivers of the inputs ``names`` from ``src_node`` to ``dst_node``."""
    for name in names:
        src, dst = src_node.inputs.get(name), dst_node.inputs.get(name)
        if src is None or dst is None:
            continue
        if name not in LINK_ONLY_INPUTS:
            _copy_value(src, dst)
        _relink(tree, src, dst)
        _move_drivers(tree, src, dst)


_principled_defaults: dict[str, object] = {}


def principled_defaults():
    """Default input values of a fresh Principled BSDF (identifier -> value), read once."""
    if not _principled_defaults:
        group = bpy.data.node_groups.new(".rtl_principled_defaults", "ShaderNodeTree")
        try:
            node = group.nodes.new("ShaderNodeBsdfPrincipled")
            for socket in node.inputs:
                if hasattr(socket, "default_value"):
                    _principled_defaults[socket.identifier] = socket_value(socket)
        finally:
            bpy.data.node_groups.remove(group)
    return _principled_defaults


def ignored_principled_inputs(node):
    """Principled inputs RT Lit has no counterpart for that are linked or non-default, in node
    order (names; disabled sockets, such as Subsurface IOR under Random Walk, are skipped)."""
    defaults = principled_defaults()
    ignored = []
    for socket in node.inputs:
        if socket.name in MAPPED_INPUTS or not socket.enabled:
            continue
        if socket.is_linked:
            ignored.append(socket.name)
        elif hasattr(socket, "default_value") and socket.identifier in defaults \
                and not socket.hide_value and not values_equal(socket_value(socket), defaults[socket.identifier]):
            ignored.append(socket.name)
    return tuple(ignored)


def principled_uses_sheen(material):
    """Whether ``material``'s Principled BSDF (feeding its active output) has sheen: Sheen Weight > 0 or
    linked.  The Convert dialog turns the sheen switch on for it."""
    return _principled_input_used(material, "Sheen Weight")


def principled_uses_diffuse_roughness(material):
    """Whether ``material``'s Principled BSDF has a rough diffuse: Diffuse Roughness > 0 or linked.  The Convert
    dialog proposes the "oren_nayar" diffuse for it (what Cycles renders)."""
    return _principled_input_used(material, "Diffuse Roughness")


def _principled_input_used(material, name):
    """Whether the Principled BSDF feeding ``material``'s active output has input ``name`` linked or above 0
    (False without such a node or input)."""
    if material is None or material.node_tree is None:
        return False
    output = active_output(material.node_tree)
    node = source_node(output.inputs["Surface"]) if output is not None else None
    if node is None or node.bl_idname != "ShaderNodeBsdfPrincipled" or node.inputs.get(name) is None:
        return False
    socket = node.inputs[name]
    return bool(socket.is_linked or socket.default_value > 0.0)


def exact_horizon_renders(features):
    """Whether Cycles renders a material with ``features`` and an exact horizon in this Blender: every set in 5.x, the
    measured ones (and those a costlier measured set bounds) in 4.x."""
    return bpy.app.version >= (5, 0, 0) or cycles_capacity.renders_with_exact_horizon_in_4(features)


#: What an exact area-light horizon costs in Blender 4.x (measured on 4.5: the largest feature set overflows Cycles'
#: SVM stack under clipped quads and renders black, the others measured fit: core/materials/cycles_capacity.py,
#: EXACT_HORIZON_IN_4; every set fits in 5.2; docs/area_lights.md, "RT Lit's exact horizon").
EXACT_HORIZON_WARNING = ("Material '{material}': with these switches an exact area-light horizon overflows Cycles' "
                         "shader stack in Blender 4.x (the material renders black there); Blender 5 fits it, or choose "
                         "fewer switches or the Sphere Table horizon")


def stored_features(material):
    """The features remembered on the material, or None."""
    data = material.get(FEATURES_KEY) if material is not None else None
    if data is None:
        return None
    try:
        data = data.to_dict() if hasattr(data, "to_dict") else dict(data)
        features = Features.from_dict(data)
        return Features(specular=str(features.specular), diffuse=str(features.diffuse),
                        sheen=str(features.sheen), cloth=bool(features.cloth),
                        environment_ms=str(features.environment_ms), occlusion=str(features.occlusion),
                        horizon=str(features.horizon))
    except (TypeError, ValueError):
        return None


def _store_features(material, features):
    material[FEATURES_KEY] = features.as_dict()


def _absolute_location(node):
    loc = getattr(node, "location_absolute", None)
    return tuple(loc if loc is not None else node.location)


def _check_editable(material):
    if material is None:
        raise ConversionError("No material to convert")
    if material.library is not None:
        raise ConversionError(f"Material '{material.name}' is linked from the library "
                              f"'{material.library.filepath}' and cannot be edited here: make it local "
                              "(Object > Relations > Make Local) or convert it in its own file")
    if material.node_tree is None:
        raise ConversionError(f"Material '{material.name}' has no node tree (it does not use nodes)")
    output = active_output(material.node_tree)
    if output is None:
        raise ConversionError(f"Material '{material.name}' has no Material Output node")
    return material.node_tree, output


# --------------------------------------------------------------------------------------------
# Principled -> RT Lit


def _swap_group(tree, rt, group):
    """Point ``rt`` at ``group``, keeping its input values and links (by name)."""
    if rt.node_tree == group:
        return False
    values = {s.name: socket_value(s) for s in rt.inputs if hasattr(s, "default_value")}
    links = {s.name: [(l.from_socket, l.is_muted) for l in s.links] for s in rt.inputs}
    rt.node_tree = group
    for socket in rt.inputs:
        if socket.name in values and hasattr(socket, "default_value"):
            try:
                socket.default_value = values[socket.name]
            except (TypeError, ValueError):
                pass
        for from_socket, muted in links.get(socket.name, ()):
            if not socket.is_linked:
                tree.links.new(from_socket, socket).is_muted = muted
    return True


def _restore_kept_principled(node):
    """Take a kept Principled out of the frame, back where it stood; drop the bookkeeping."""
    location = node.get(SAVED_LOCATION_PROP)
    parent_name = node.get(SAVED_PARENT_PROP, "")
    hide = node.get(SAVED_HIDE_PROP)
    tree = node.id_data
    node.parent = None
    if location is not None:
        node.location = tuple(location)
    parent = tree.nodes.get(parent_name) if parent_name else None
    if parent is not None and parent.bl_idname == "NodeFrame":
        node.parent = parent
    if hide is not None:
        node.hide = bool(hide)
    for key in (ROLE_PROP, SAVED_LOCATION_PROP, SAVED_PARENT_PROP, SAVED_HIDE_PROP):
        if key in node:
            del node[key]


def _remove_rt_lit_nodes(tree, rt=None):
    """Remove the RT Lit node(s), the Emission and the kept-frame this module made."""
    doomed = _nodes_with_role(tree, "rt_lit") + _nodes_with_role(tree, "emission")
    if rt is not None and rt not in doomed:
        doomed.append(rt)
    for frame in _nodes_with_role(tree, "frame"):
        for child in [n for n in tree.nodes if n.parent == frame]:
            child.parent = None
        doomed.append(frame)
    for node in doomed:
        tree.nodes.remove(node)


def principled_to_rt_lit(material, group_factory, features=None):
    """Convert ``material`` from a Principled BSDF to an RT Lit material (see the module doc).

    ``group_factory(features) -> ShaderNodeTree`` gives the RT Lit group; ``features`` (a
    ``Features``) defaults to the ones stored on the material, else ``Features()`` (with the Zeltner sheen,
    Principled's, when the Principled BSDF has sheen).  Returns a
    ``ConversionResult``; raises ``ConversionError`` (changing nothing) when the active Material
    Output's Surface is not fed by a Principled BSDF (or an RT Lit material).
    """
    tree, output = _check_editable(material)
    if features is None:
        features = stored_features(material) or (Features(sheen=PRINCIPLED_SHEEN) if principled_uses_sheen(material)
                                                 else Features())
    elif not isinstance(features, Features):
        features = Features.from_dict(features)

    rt = _rt_lit_feeding(output)
    if rt is not None:  # already RT Lit: only the switches may change
        group = group_factory(features)
        swapped = _swap_group(tree, rt, group)
        connect_engine_outputs(tree, rt, output)
        not_a_light(material)
        changed = swapped or stored_features(material) != features
        _store_features(material, features)
        rt.label = f"RT Lit ({features.label()})"
        return ConversionResult(material.name, "updated" if changed else "unchanged", features=features)

    principled = source_node(output.inputs["Surface"])
    if principled is None or principled.bl_idname != "ShaderNodeBsdfPrincipled":
        found = "nothing" if principled is None else f"'{principled.name}' ({principled.bl_label})"
        raise ConversionError(
            f"Material '{material.name}': the Surface of the active Material Output '{output.name}' "
            f"must be fed by a Principled BSDF, but is fed by {found}")

    group = group_factory(features)
    if group is None:
        raise ConversionError("The RT Lit group factory returned no node group")
    sockets = [i for i in group.interface.items_tree if getattr(i, "item_type", "SOCKET") == 'SOCKET']
    missing = [name for name in MAPPED_INPUTS
               if name not in {i.name for i in sockets if i.in_out == 'INPUT'}]
    if missing or RT_LIT_OUTPUT not in {i.name for i in sockets if i.in_out == 'OUTPUT'}:
        raise ConversionError(f"Node group '{group.name}' is not an RT Lit group "
                              f"(missing inputs {missing} or output '{RT_LIT_OUTPUT}')")

    # Leftovers of an earlier conversion whose Principled was plugged back by hand.
    for node in _nodes_with_role(tree, "kept_principled"):
        _restore_kept_principled(node)
    _remove_rt_lit_nodes(tree)

    ignored = ignored_principled_inputs(principled)
    px, py = _absolute_location(principled)

    rt = tree.nodes.new("ShaderNodeGroup")
    rt.node_tree = group
    rt.name = RT_LIT_NODE_NAME
    rt.label = f"RT Lit ({features.label()})"
    rt[ROLE_PROP] = "rt_lit"
    rt.width = max(rt.width, 240.0)
    rt.location = (px - 180.0, py)

    _transfer(tree, principled, rt, MAPPED_INPUTS)
    remembered = material.get(RT_ONLY_VALUES_PROP)
    if remembered is not None:
        for name in RT_LIT_ONLY_INPUTS:
            socket = rt.inputs.get(name)
            if socket is not None and name in remembered and hasattr(socket, "default_value"):
                value = remembered[name]
                try:
                    socket.default_value = tuple(value) if hasattr(value, "__len__") else value
                except (TypeError, ValueError):
                    pass
        del material[RT_ONLY_VALUES_PROP]

    # the group's Shader output is the emission of every light (one closure per light), Cycles' tree;
    # "EEVEE Shader" feeds an EEVEE Material Output (replaces the BSDF link)
    connect_engine_outputs(tree, rt, output)
    not_a_light(material)

    # Keep the Principled node, collapsed in a labelled frame below the RT Lit node.
    frame = tree.nodes.new("NodeFrame")
    frame.name = FRAME_NODE_NAME
    frame.label = FRAME_LABEL
    frame[ROLE_PROP] = "frame"
    frame.location = (px - 180.0, py - 700.0)
    old_parent = principled.parent
    principled[SAVED_LOCATION_PROP] = (px, py)
    principled[SAVED_PARENT_PROP] = old_parent.name if old_parent is not None else ""
    principled[SAVED_HIDE_PROP] = bool(principled.hide)
    principled[ROLE_PROP] = "kept_principled"
    principled.parent = None
    principled.location = (px - 160.0, py - 740.0)
    principled.hide = True
    principled.parent = frame

    _store_features(material, features)
    result = ConversionResult(material.name, "converted", ignored_inputs=ignored, features=features)
    sheen = principled.inputs["Sheen Weight"]
    if features.sheen == "none" and (sheen.is_linked or sheen.default_value > 0.0):
        amount = "a linked Sheen Weight" if sheen.is_linked else f"Sheen Weight {sheen.default_value:.3g}"
        result.warnings.append(f"Material '{material.name}': {amount} is not shaded because the sheen switch is "
                               "off; convert again with Sheen on to keep it")
    rough = principled.inputs.get("Diffuse Roughness")
    if features.diffuse != "oren_nayar" and rough is not None and (rough.is_linked or rough.default_value > 0.0):
        amount = "a linked Diffuse Roughness" if rough.is_linked else f"Diffuse Roughness {rough.default_value:.3g}"
        result.warnings.append(f"Material '{material.name}': {amount} is not shaded by the '{features.diffuse}' "
                               "diffuse; convert again with the Oren-Nayar diffuse to keep it")
    if features.horizon != "sphere_table" and not exact_horizon_renders(features):
        result.warnings.append(EXACT_HORIZON_WARNING.format(material=material.name))
    if ignored:
        result.warnings.append(
            f"Material '{material.name}': RT Lit ignores the Principled inputs "
            f"{', '.join(ignored)}; they stay on the kept Principled BSDF and come back on "
            "conversion to Principled")
    return result


# --------------------------------------------------------------------------------------------
# RT Lit -> Principled


def kept_principled(tree):
    """The Principled BSDF a conversion kept in ``tree`` (tagged, or in the kept-frame), or None."""
    kept = [n for n in _nodes_with_role(tree, "kept_principled") if n.bl_idname == "ShaderNodeBsdfPrincipled"]
    if kept:
        return kept[0]
    frame = tree.nodes.get(FRAME_NODE_NAME)
    if frame is not None:
        for node in tree.nodes:
            if node.parent == frame and node.bl_idname == "ShaderNodeBsdfPrincipled":
                return node
    return None


def rt_lit_to_principled(material):
    """Convert an RT Lit material back to a Principled BSDF (see the module doc).

    Restores the kept Principled BSDF (or creates one), writes the RT Lit node's current values
    and links of ``MAPPED_INPUTS`` into it, connects it to the active Material Output's Surface
    and removes the RT Lit node, its Emission and the kept-frame; the RT Lit group datablock
    stays.  Returns a ``ConversionResult``; raises ``ConversionError`` (changing nothing) when
    the material has no RT Lit node.
    """
    tree, output = _check_editable(material)
    rt = find_rt_lit_node(material)
    if rt is None:
        raise ConversionError(f"Material '{material.name}' is not an RT Lit material (no '{RT_LIT_NODE_NAME}' "
                              "group node)")
    if rt.node_tree is None:
        raise ConversionError(f"Material '{material.name}': the RT Lit node '{rt.name}' has no node group")

    result = ConversionResult(material.name, "converted", features=stored_features(material))
    principled = kept_principled(tree)
    if principled is None:
        principled = tree.nodes.new("ShaderNodeBsdfPrincipled")
        principled.location = _absolute_location(rt)
        result.warnings.append(f"Material '{material.name}': the original Principled BSDF was not found; "
                               "created a new one from the RT Lit values")
    else:
        _restore_kept_principled(principled)

    _transfer(tree, rt, principled, MAPPED_INPUTS)

    remembered, dropped = {}, []
    for name in RT_LIT_ONLY_INPUTS:
        socket = rt.inputs.get(name)
        if socket is None:
            continue
        if hasattr(socket, "default_value"):
            remembered[name] = socket_value(socket)
        if socket.is_linked:
            dropped.append(name)
    if remembered:
        material[RT_ONLY_VALUES_PROP] = remembered
    if dropped:
        result.warnings.append(f"Material '{material.name}': Principled has no counterpart for the linked "
                               f"RT Lit inputs {', '.join(dropped)}; their links are dropped")

    _remove_rt_lit_nodes(tree, rt)
    output = restore_engine_outputs(tree) or output
    restore_emission_sampling(material)
    tree.links.new(principled.outputs["BSDF"], output.inputs["Surface"])
    return result


# --------------------------------------------------------------------------------------------
# The add-on's RT Lit groups


def default_group_factory(lut_dir=None):
    """The add-on's RT Lit group factory (``materials.ensure_rt_lit_group``), reading the LUTs of ``lut_dir``."""
    return lambda features: ensure_rt_lit_group(features, lut_dir=lut_dir)
