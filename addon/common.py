"""Names and small bpy helpers shared by the add-on's modules (one definition each).

- Names of what the add-on stores in a .blend: groups, node names, custom properties, image prefix.
- ``socket_by_identifier``, ``ensure_interface``: node-group interfaces built from
  ``core.ir.interface.Socket`` descriptions, kept when unchanged so users of a group keep their links.
- ``add_driver``: a simple-expression driver (``var``) on a socket's default value, which Blender
  evaluates without Python (so it works after a reload with auto-run off).
"""
from __future__ import annotations

from ..core.ir.expr import FLOAT, VECTOR
from ..core.materials.rt_lit_interface import NODE_GROUP_PREFIX, RT_LIT_GROUP_PREFIX

#: The shared group of the scene's lights' driver values (``materials.sync_scene_lights``).
SCENE_LIGHTS_GROUP = NODE_GROUP_PREFIX + "Scene Lights"
#: The shared group of the world's SH and driven strength / rotation (``world_sync.sync_world``).
WORLD_GROUP = NODE_GROUP_PREFIX + "World"
#: Custom property holding a material's or an RT Lit group's ``Features`` (a dict).
FEATURES_KEY = "rtl_features"
#: Custom property of ``WORLD_GROUP`` holding the bake's record.
WORLD_RECORD_KEY = "rtl_world"
#: Custom property of ``SCENE_LIGHTS_GROUP`` listing "<object>:<kind>" per synced light.
LIGHTS_RECORD_KEY = "rtl_lights"
#: Custom property of ``SCENE_LIGHTS_GROUP``: the synced lights' "<object>:<kind>:<shape>", what the
#: automatic light sync compares (addon/light_sync.py).
LIGHTS_SIGNATURE_KEY = "rtl_light_signature"
#: Custom property of an emitted group: emitter version and structure hash (rebuilt when it changes).
STAMP_KEY = "rtl_stamp"
#: Name of the RT Lit group node inside a converted material.
RT_LIT_NODE_NAME = "RT Lit"
#: Images of tables are named "RTL_<table>".
IMAGE_PREFIX = "RTL_"

__all__ = ["NODE_GROUP_PREFIX", "RT_LIT_GROUP_PREFIX", "SCENE_LIGHTS_GROUP", "WORLD_GROUP", "FEATURES_KEY",
           "WORLD_RECORD_KEY", "LIGHTS_RECORD_KEY", "LIGHTS_SIGNATURE_KEY", "STAMP_KEY", "RT_LIT_NODE_NAME", "IMAGE_PREFIX", "SOCKET_TYPES",
           "socket_by_identifier", "ensure_interface", "remove_drivers", "add_driver"]

SOCKET_TYPES = {"float": "NodeSocketFloat", "vector": "NodeSocketVector", "color": "NodeSocketColor",
                "shader": "NodeSocketShader", FLOAT: "NodeSocketFloat", VECTOR: "NodeSocketVector"}


def socket_by_identifier(sockets, identifier):
    for s in sockets:
        if s.identifier == identifier:
            return s
    raise KeyError(identifier)


def _apply_socket_spec(item, in_out, spec):
    item.description = spec.description
    if spec.kind == "shader":
        return item
    if spec.subtype and spec.subtype != "NONE":
        item.subtype = spec.subtype
    if in_out == "INPUT":
        default = spec.default
        if spec.kind == "color" and len(default) == 3:
            default = (*default, 1.0)
        item.default_value = default
        if spec.min is not None and hasattr(item, "min_value"):
            item.min_value = spec.min
        if spec.max is not None and hasattr(item, "max_value"):
            item.max_value = spec.max
        item.hide_value = spec.hide_value
    return item


def _new_interface_socket(iface, name, in_out, kind, spec, panels):
    """An interface socket from a core.ir.interface.Socket (or just a kind)."""
    socket_kind = spec.kind if spec is not None else kind
    parent = None
    if spec is not None and spec.panel:
        parent = panels.get(spec.panel)
        if parent is None:
            parent = panels[spec.panel] = iface.new_panel(spec.panel, default_closed=False)
    item = iface.new_socket(name, in_out=in_out, socket_type=SOCKET_TYPES[socket_kind], parent=parent)
    if spec is not None:
        _apply_socket_spec(item, in_out, spec)
    return item


def _interface_signature(spec_list):
    return sorted((name, in_out, SOCKET_TYPES[spec.kind if spec is not None else kind],
                   spec.panel if spec is not None else None) for name, in_out, kind, spec in spec_list)


def ensure_interface(ng, wanted):
    """Interface items (name, in_out) -> item for ``wanted`` [(name, in_out, kind, Socket or None)].

    An interface that already has exactly these sockets (names, types, panels) is kept as it is:
    Group nodes using the tree keep their links and values when it is rebuilt.  Otherwise the
    interface is created anew (descriptions, ranges and defaults are refreshed either way)."""
    iface = ng.interface
    existing = [it for it in iface.items_tree if it.item_type == "SOCKET"]
    current = sorted((it.name, it.in_out, it.socket_type, it.parent.name if it.parent and it.parent.name else None)
                     for it in existing)
    keep = current == _interface_signature(wanted) and len({(it.name, it.in_out) for it in existing}) == len(existing)
    if not keep:
        iface.clear()
        panels = {}
        return {(name, in_out): _new_interface_socket(iface, name, in_out, kind, spec, panels)
                for name, in_out, kind, spec in wanted}
    items = {(it.name, it.in_out): it for it in existing}
    for name, in_out, kind, spec in wanted:
        if spec is not None:
            _apply_socket_spec(items[(name, in_out)], in_out, spec)
    return items


def remove_drivers(id_block):
    """Remove every driver of an ID (a node group about to be rebuilt)."""
    if id_block.animation_data is not None:
        for fc in list(id_block.animation_data.drivers):
            id_block.animation_data.drivers.remove(fc)


def add_driver(socket, target_id, source, id_type=None):
    """A simple-expression driver ``var`` on ``socket.default_value`` (or on ``socket`` itself when it
    is a property owner with ``driver_add``) reading ``source`` of ``target_id``:
    ("transform", "LOC_X" / "ROT_W" / "SCALE_Z", ...) is a TRANSFORMS variable in world space
    (quaternion rotation), ("data", path) a SINGLE_PROP variable on ``target_id`` (an ID of
    ``id_type``, e.g. "LIGHT" or "WORLD")."""
    fc = socket.driver_add("default_value")
    drv = fc.driver
    drv.type = "SCRIPTED"
    drv.expression = "var"
    var = drv.variables.new()
    var.name = "var"
    kind, what = source
    target = var.targets[0]
    if kind == "transform":
        var.type = "TRANSFORMS"
        target.id = target_id
        target.transform_type = what
        target.transform_space = "WORLD_SPACE"
        if what.startswith("ROT_"):
            target.rotation_mode = "QUATERNION"
    else:
        var.type = "SINGLE_PROP"
        target.id_type = id_type
        target.id = target_id
        target.data_path = what
    return fc
