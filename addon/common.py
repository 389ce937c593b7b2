"""Names and small bpy helpers shared by the add-on's modules (one definition each).

- Names of what the add-on stores in a .blend: groups, node names, custom properties, image prefix.
- ``socket_by_identifier``, ``ensure_interface``: node-group interfaces built from
  ``core.ir.interface.Socket`` descriptions, kept when unchanged so users of a group keep their links.
- ``add_driver``, ``add_expression_driver``: simple-expression drivers on a socket's default value, which
  Blender evaluates without Python (so they work after a reload with auto-run off).
- ``socket_value``, ``active_output``, ``source_node``: reading a material's tree (a socket's value as a float
  or tuple, the active Material Output, the node feeding a socket through reroutes).
- ``node_groups_kept_on_error``: a rebuild of the add-on's node groups as one transaction (all or nothing).
"""
from __future__ import annotations

import contextlib

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
#: On "RTL Scene Lights": {light name: object attribute} of the lights with light linking
#: (addon/light_model.py ``linking_attributes``).
LINKING_KEY = "rtl_light_linking"
#: On a culled RT Lit group: the indices of the scene lights it shades (addon/materials.py ``cull_lights``).
LIGHTS_SUBSET_KEY = "rtl_lights_subset"
#: On "RTL Scene Lights": the lights that reach each RT Lit material, as last culled.
REACH_KEY = "rtl_light_reach"
#: Custom property of an emitted group: emitter version and structure hash (rebuilt when it changes).
STAMP_KEY = "rtl_stamp"
#: Name of the RT Lit group node inside a converted material.
RT_LIT_NODE_NAME = "RT Lit"
#: Images of tables are named "RTL_<table>".
IMAGE_PREFIX = "RTL_"
#: RT Lit group output per Material Output target: Cycles' tree and EEVEE's (addon/materials.ENGINE_TREES).
ENGINE_SHADER_OUTPUTS = (("CYCLES", "Shader"), ("EEVEE", "EEVEE Shader"))
#: Custom property of a Material Output whose target RT Lit changed from All to Cycles (restored on revert).
SAVED_TARGET_KEY = "rtl_saved_target"
#: Custom property marking a Material Output that RT Lit added (removed on revert).
ADDED_OUTPUT_KEY = "rtl_added_output"
#: Custom property of a material: its Cycles emission sampling before it became RT Lit.
SAVED_EMISSION_SAMPLING_KEY = "rtl_saved_emission_sampling"
#: Shader AOV of the RT Lit Cycles tree holding scene light i's unshadowed radiance: "RTL Light <i>"
#: (``light_aov_name``; read by the shadow compositor, addon/shadows.py).
LIGHT_AOV_PREFIX = "RTL Light "
#: Shader AOV of the RT Lit EEVEE tree holding the sum of the scene lights' unshadowed radiance, written while the
#: scene has EEVEE shadows on (addon/shadows.py: EEVEE's Shadow pass is one ratio for all lights together).
LIGHTS_AOV = "RTL Lights"
#: The engines RT Lit shadows are built for (``shadows.shadow_settings(scene)["engine"]``): the RT Lit tree of that
#: engine (addon/materials.ENGINE_TREES) writes the AOVs.
SHADOW_ENGINES = ("Cycles", "EEVEE")
#: The view layer property (1.0 in EEVEE shadows' probe layer) by which the RT Lit EEVEE tree, while the scene has
#: EEVEE shadows on, shades white diffuse instead of its emission: EEVEE 4.5 ignores ``ViewLayer.material_override``
#: in renders (measured with 4.5.15; 5.2.3 applies it) and its Shadow pass needs a lit closure.
PROBE_LAYER_ATTRIBUTE = "rtl_shadow_probe"
#: Custom property of a scene with RT Lit shadows on (addon/shadows.py: its settings); its RT Lit Cycles trees then
#: write the lights' AOVs (``materials.ensure_rt_lit_group``).
SHADOWS_KEY = "rtl_shadows"
#: Custom property marking an object or light data that addon/shadows.py made (a shadow probe's light copy):
#: never a light RT Lit shades.
SHADOW_COPY_KEY = "rtl_shadow_copy"

__all__ = ["NODE_GROUP_PREFIX", "RT_LIT_GROUP_PREFIX", "SCENE_LIGHTS_GROUP", "WORLD_GROUP", "FEATURES_KEY",
           "WORLD_RECORD_KEY", "LIGHTS_RECORD_KEY", "LINKING_KEY", "LIGHTS_SIGNATURE_KEY", "LIGHTS_SUBSET_KEY", "REACH_KEY",
           "STAMP_KEY", "RT_LIT_NODE_NAME", "IMAGE_PREFIX", "SOCKET_TYPES",
           "ENGINE_SHADER_OUTPUTS", "SAVED_TARGET_KEY", "ADDED_OUTPUT_KEY", "LIGHT_AOV_PREFIX", "LIGHTS_AOV", "SHADOW_ENGINES", "PROBE_LAYER_ATTRIBUTE",
           "SHADOWS_KEY",
           "SHADOW_COPY_KEY", "light_aov_name", "connect_engine_outputs",
           "restore_engine_outputs", "not_a_light", "restore_emission_sampling",
           "socket_by_identifier", "ensure_interface", "remove_drivers", "add_driver", "add_expression_driver",
           "socket_value", "active_output", "source_node",
           "node_groups_kept_on_error", "before_rebuild"]

SOCKET_TYPES = {"float": "NodeSocketFloat", "vector": "NodeSocketVector", "color": "NodeSocketColor",
                "shader": "NodeSocketShader", FLOAT: "NodeSocketFloat", VECTOR: "NodeSocketVector"}


def light_aov_name(index):
    """The Shader AOV carrying scene light ``index``'s RT Lit radiance (Cycles tree)."""
    return f"{LIGHT_AOV_PREFIX}{index}"


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
    kind, what = source
    return add_expression_driver(socket, "var", [("var", "transform" if kind == "transform" else id_type,
                                                  target_id, what)])


def add_expression_driver(socket, expression, variables):
    """A driver ``expression`` (a simple expression: Blender evaluates it without Python) on
    ``socket.default_value``; ``variables`` [(name, kind, ID, what)]: kind "transform" is a TRANSFORMS
    variable in world space reading channel ``what`` ("LOC_X", "ROT_W" in quaternion mode, "SCALE_Z"),
    any other kind a SINGLE_PROP variable on an ID of that type ("LIGHT", "OBJECT", "WORLD") reading the
    data path ``what``."""
    fc = socket.driver_add("default_value")
    drv = fc.driver
    drv.type = "SCRIPTED"
    drv.expression = expression
    for name, kind, target_id, what in variables:
        var = drv.variables.new()
        var.name = name
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
            target.id_type = kind
            target.id = target_id
            target.data_path = what
    return fc


def connect_engine_outputs(tree, group, output):
    """Link the RT Lit group node ``group`` to a Material Output per engine (``ENGINE_SHADER_OUTPUTS``).

    ``output`` (the material's active output) keeps its role: target All becomes Cycles (the old target
    saved in ``SAVED_TARGET_KEY``), Cycles or EEVEE stay; the other engine's output is found or added
    (marked ``ADDED_OUTPUT_KEY``).  A group without "EEVEE Shader" (one tree for all engines) only
    feeds ``output`` from "Shader".  Returns {target: output node}."""
    if group.outputs.get(ENGINE_SHADER_OUTPUTS[1][1]) is None:
        tree.links.new(group.outputs["Shader"], output.inputs["Surface"])
        return {output.target: output}
    if output.target == "ALL":
        output[SAVED_TARGET_KEY] = "ALL"
        output.target = "CYCLES"
    outputs = {output.target: output}
    for target, socket in ENGINE_SHADER_OUTPUTS:
        node = outputs.get(target) or next((n for n in tree.nodes if n.bl_idname == "ShaderNodeOutputMaterial"
                                            and n.target == target), None)
        if node is None:
            node = tree.nodes.new("ShaderNodeOutputMaterial")
            node.target = target
            node[ADDED_OUTPUT_KEY] = True
            node.name = node.label = f"Material Output ({'EEVEE' if target == 'EEVEE' else 'Cycles'})"
            node.location = (output.location.x, output.location.y - 160.0)
            node.is_active_output = False
        outputs[target] = node
        tree.links.new(group.outputs[socket], node.inputs["Surface"])
    return outputs


def restore_engine_outputs(tree):
    """Undo ``connect_engine_outputs``: remove the outputs it added, give back the targets it changed;
    returns the restored output (or None)."""
    restored = None
    for node in [n for n in tree.nodes if n.bl_idname == "ShaderNodeOutputMaterial"]:
        if node.get(ADDED_OUTPUT_KEY):
            tree.nodes.remove(node)
        elif SAVED_TARGET_KEY in node:
            node.target = node[SAVED_TARGET_KEY]
            del node[SAVED_TARGET_KEY]
            restored = node
    return restored


def not_a_light(material):
    """Cycles samples emissive surfaces as lights: at every render it builds a light tree over their
    triangles (0.17 s of the demo scene's 0.55 s 1-sample render, measured) and sends shadow rays to
    them.  RT Lit's emission is the shaded result, not a light: emission sampling None (the old value
    kept for the way back)."""
    settings = material.cycles
    if SAVED_EMISSION_SAMPLING_KEY not in material:
        material[SAVED_EMISSION_SAMPLING_KEY] = settings.emission_sampling
    settings.emission_sampling = "NONE"


def restore_emission_sampling(material):
    """Undo ``not_a_light``."""
    saved = material.get(SAVED_EMISSION_SAMPLING_KEY)
    if saved is not None:
        material.cycles.emission_sampling = saved
        del material[SAVED_EMISSION_SAMPLING_KEY]


def socket_value(socket):
    """``socket.default_value`` as a float or a tuple (a colour or a vector)."""
    value = socket.default_value
    try:
        return tuple(value)
    except TypeError:
        return value


def active_output(tree):
    """The active Material Output of a material's tree (the one for all render engines first), or None."""
    outputs = [n for n in tree.nodes if n.bl_idname == "ShaderNodeOutputMaterial"]
    if not outputs:
        return None
    try:
        node = tree.get_output_node('ALL')
    except (AttributeError, TypeError):
        node = None
    if node is not None:
        return node
    active = [n for n in outputs if n.is_active_output]
    for target in ('ALL', 'EEVEE', 'CYCLES'):
        for n in active:
            if n.target == target:
                return n
    return active[0] if active else outputs[0]


def source_node(socket):
    """The node feeding the input ``socket`` (following reroutes), or None."""
    seen = set()
    while socket.is_linked:
        link = socket.links[0]
        node = link.from_node
        if node.bl_idname != "NodeReroute" or node.name in seen:
            return node
        seen.add(node.name)
        socket = node.inputs[0]
    return None


@contextlib.contextmanager
def node_groups_kept_on_error():
    """Run the body (a rebuild of the add-on's node groups: a light sync) as one transaction: when it raises, the
    add-on's node groups, the materials' RT Lit nodes and the file's tables are put back exactly as they were, and the
    exception goes on.

    What a sync changes is copied (``ID.copy``: nodes, links, interface with its socket identifiers, drivers) before
    it changes: "RTL Scene Lights", the RT Lit groups (``FEATURES_KEY``) and their engine trees up front, a nested
    group when the emitter is about to rebuild it in place (``before_rebuild``: a stale stamp).  The copies are kept
    out of the body's way: their custom properties are held aside (no scan for RT Lit groups finds them), and their
    Group nodes point at the other copies (Blender updates every Group node of a group whose interface changes, and
    the lights group's changes with the lights).  On failure the copies take the originals' places (their users
    remapped, the originals removed, names and properties given back), the materials' RT Lit nodes get their groups
    back, and the groups and "RTL_" images the body added are removed.  On success the copies are removed, and with
    them what only they kept in use of the groups the body removed.  Measured cost: docs/benchmarks/light_sync.md."""
    snapshot = _GroupSnapshot()
    _SNAPSHOTS.append(snapshot)
    try:
        yield
    except BaseException:
        _SNAPSHOTS.remove(snapshot)
        snapshot.restore()
        raise
    _SNAPSHOTS.remove(snapshot)
    snapshot.discard()


#: The transactions under way (``node_groups_kept_on_error``).
_SNAPSHOTS = []


def replace_group(in_use, rebuilt):
    """Give ``rebuilt`` (a group built where no tree used it) the users and the name of ``in_use``, and remove
    ``in_use``.  For Group nodes to keep their links, ``rebuilt`` must have ``in_use``'s interface socket identifiers
    (build it in ``in_use.copy()``)."""
    import bpy

    name = in_use.name
    in_use.user_remap(rebuilt)
    bpy.data.node_groups.remove(in_use)
    rebuilt.name = name


def before_rebuild(ng):
    """Called by the emitter before it clears a group to rebuild it in place: a transaction under way keeps a copy."""
    for snapshot in _SNAPSHOTS:
        snapshot.keep(ng)


def _plain(value):
    """A custom property's value as plain Python (it outlives the ID it is read from)."""
    return value.to_dict() if hasattr(value, "to_dict") else value.to_list() if hasattr(value, "to_list") else value


def _removed(block):
    try:
        block.name
    except ReferenceError:
        return True
    return False


class _GroupSnapshot:
    """Copies of the add-on's node groups a sync changes, the groups the materials' RT Lit nodes use, and the groups
    and images there are (``node_groups_kept_on_error``)."""

    def __init__(self):
        import bpy

        data = bpy.data
        self.before = {ng.session_uid for ng in data.node_groups}
        self.images = {image.session_uid for image in data.images}
        self.groups = []               # (original, its name, its custom properties, its copy)
        self.copies = {}               # original's session_uid -> copy
        tops = [ng for ng in data.node_groups
                if ng.library is None and (FEATURES_KEY in ng or ng.name == SCENE_LIGHTS_GROUP)]
        trees = {node.node_tree.session_uid: node.node_tree for ng in tops for node in ng.nodes
                 if node.bl_idname == "ShaderNodeGroup" and node.node_tree is not None and node.node_tree.library is None}
        for ng in tops + list(trees.values()):
            self._copy(ng)
        for *_, copy in self.groups:
            self._point_at_copies(copy)
        self.assigned = []
        for material in data.materials:
            node = material.node_tree.nodes.get(RT_LIT_NODE_NAME) if material.node_tree is not None else None
            if node is not None and node.bl_idname == "ShaderNodeGroup" and node.node_tree is not None:
                self.assigned.append((material, self.copies.get(node.node_tree.session_uid, node.node_tree)))

    def _copy(self, ng):
        if ng.session_uid in self.copies:
            return None
        copy = ng.copy()
        properties = {key: _plain(ng[key]) for key in ng.keys()}
        for key in properties:
            del copy[key]
        self.groups.append((ng, ng.name, properties, copy))
        self.copies[ng.session_uid] = copy
        return copy

    def _point_at_copies(self, tree):
        for node in tree.nodes:
            if node.bl_idname == "ShaderNodeGroup" and node.node_tree is not None:
                copy = self.copies.get(node.node_tree.session_uid)
                if copy is not None and copy != tree:
                    node.node_tree = copy

    def keep(self, ng):
        """Copy ``ng``, about to be rebuilt in place, if it existed before the body and is not copied yet."""
        if ng.session_uid in self.before and self._copy(ng) is not None:
            for *_, copy in self.groups:
                self._point_at_copies(copy)

    def restore(self):
        import bpy

        data = bpy.data
        for material, group in self.assigned:
            node = material.node_tree.nodes.get(RT_LIT_NODE_NAME)
            if node is not None and node.node_tree != group:
                node.node_tree = group
        kept = self.before | {copy.session_uid for *_, copy in self.groups}
        removed = [ng for ng in data.node_groups if ng.session_uid not in kept]
        for ng, _, _, copy in self.groups:
            if not _removed(ng):
                ng.user_remap(copy)
                removed.append(ng)
        removed += [image for image in data.images
                    if image.session_uid not in self.images and image.name.startswith(IMAGE_PREFIX)]
        data.batch_remove(removed)
        for _, name, properties, copy in self.groups:
            copy.name = name
            for key, value in properties.items():
                copy[key] = value

    def discard(self):
        import bpy

        data = bpy.data
        # the body removed these (culled groups no material uses); what they used, only their copies use now
        used = {node.node_tree.session_uid for ng, _, _, copy in self.groups if _removed(ng)
                for node in copy.nodes if node.bl_idname == "ShaderNodeGroup" and node.node_tree is not None}
        data.batch_remove([copy for *_, copy in self.groups])
        data.batch_remove([ng for ng in data.node_groups if ng.session_uid in used and ng.users == 0])
