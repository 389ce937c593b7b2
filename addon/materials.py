"""RT Lit node groups and the scene's lights: the bpy side of ``core.materials.rt_lit``.

- ``sync_scene_lights(scene)`` (re)builds the shared group "RTL Scene Lights": one Value node per
  light parameter, each driven by a simple-expression driver (TRANSFORMS in world space for location,
  quaternion rotation and scale; SINGLE_PROP on the light data for power, colour, size and cone), so
  the drivers evaluate without Python after a reload with auto-run off (docs/blender.md, "Drivers").
  Its outputs are the RT Lit material's light inputs, "Light <i> <parameter>".
- ``ensure_rt_lit_group(features, scene)`` emits "RT Lit (<features>)": the core function
  ``rt_lit.build_rt_lit(features, light kinds, environment)``; this module only wires its inputs: the
  material inputs become the group's interface, Geometry > Position / Normal / Incoming, the lights
  group and the world group feed the rest inside the tree.  Groups are stamped with the structure hash
  of the function and rebuilt only when it changes.
- The World term is part of the group when the shared "RTL World" group exists with its bake record
  (``world_sync.sync_world``); without it nothing of the world is built or loaded.
"""
from __future__ import annotations

from dataclasses import replace

import bpy
import numpy as np

from ..core import lights as core_lights
from ..core.ir.expr import FLOAT, table_filter
from ..core.ir.interface import Socket
from ..core.lut.lookup import LutSet
from ..core.materials import rt_lit
from ..core.materials.rt_lit_interface import (GEOMETRY_INPUTS, RT_LIT_INPUTS, RT_LIT_OUTPUTS,
                                               Features, light_input, rt_lit_group_name)
from . import compat, light_controls, light_model, node_emit, world_sync
from .common import (FEATURES_KEY, LIGHTS_RECORD_KEY, LINKING_KEY, LIGHTS_SIGNATURE_KEY, LIGHTS_SUBSET_KEY, REACH_KEY,
                     RT_LIT_GROUP_PREFIX, RT_LIT_NODE_NAME, SCENE_LIGHTS_GROUP, SHADOWS_KEY, SHADOW_COPY_KEY, STAMP_KEY,
                     WORLD_GROUP, connect_engine_outputs, ensure_interface, light_aov_name, not_a_light, remove_drivers,
                     replace_group, socket_by_identifier)
from .light_model import light_kind

#: Geometry node output feeding each geometry input of the material function.
_GEOMETRY_SOCKETS = {"Position": "Position", "Geometry Normal": "Normal", "Incoming": "Incoming"}
#: The Ambient Occlusion node's Distance (m) in RT Lit trees with world occlusion on: far enough that the objects of
#: a lookdev set-up occlude one another's sky as path tracing sees it, near enough that an open scene's far
#: geometry does not.  Cycles traces its rays (the node's samples: 16); EEVEE estimates AO from its own horizon scan.
AO_DISTANCE = 10.0
#: Driver sources that are not in "RTL Scene Lights": the linking option's per-object attribute.
_PER_OBJECT_SOURCES = ("excluded",)


def is_rendered(scene, obj):
    """Whether a render of ``scene`` includes ``obj``: not disabled in renders (the object or a collection
    holding it), and in a view layer that renders (a collection excluded from every rendering view layer
    takes its objects out of them)."""
    if obj.hide_render or any(c.hide_render for c in obj.users_collection):
        return False
    held = {c.name for c in obj.users_collection}
    return any(layer.use and held & _layer_collections(scene, layer) for layer in scene.view_layers)


def _layer_collections(scene, layer):
    """The collections ``layer`` renders; a view layer not synced yet (a scene just made by
    ``bpy.data.scenes.new`` has no layer collection until its first update) excludes nothing."""
    if layer.layer_collection is None:
        return {scene.collection.name, *(c.name for c in scene.collection.children_recursive)}
    return _included_collections(layer.layer_collection)


def _included_collections(layer_collection, out=None):
    """Names of the collections a view layer includes (an excluded layer collection drops its children);
    read from the layer collections themselves, which do not wait for the view layer to resync."""
    out = set() if out is None else out
    if not layer_collection.exclude:
        out.add(layer_collection.collection.name)
        for child in layer_collection.children:
            _included_collections(child, out)
    return out


def scene_lights(scene):
    """(object, kind) of every light RT Lit shades: rendered lights (``is_rendered``), in name order
    (``light_model.light_kind``); the shadow probes' light copies (``SHADOW_COPY_KEY``) are not among them."""
    out = []
    for obj in sorted(scene.objects, key=lambda o: o.name):
        if SHADOW_COPY_KEY in obj:
            continue                    # a shadow probe's copy of a light (addon/shadows.py)
        kind = light_kind(obj)
        if kind is not None and is_rendered(scene, obj):
            out.append((obj, kind))
    return out


def sync_scene_lights(scene):
    """(Re)build the "RTL Scene Lights" group for ``scene`` (kept as it is when it already delivers the scene's
    lights, ``_delivers``); returns [(object, kind)]."""
    records = scene_lights(scene)
    plan = []
    for index, (obj, kind) in enumerate(records):
        if core_lights.split_kind(kind)[1] or core_lights.base_kind(kind) == "quad_spot":
            light_controls.store_driven_values(obj.data)
        for param, source in core_lights.driver_sources(kind, light_model.shape(obj)).items():
            if source[0] in _PER_OBJECT_SOURCES:
                continue
            plan.append((light_input(index, param), obj, source,
                         Socket("float", 0.0, description=f"{obj.name}: {param} ({source[0]} {source[1]})",
                                panel=f"Light {index}: {obj.name}")))
    signature = light_signature(records)
    in_use = bpy.data.node_groups.get(SCENE_LIGHTS_GROUP)
    if _delivers(in_use, signature, plan):
        ng = in_use
    else:
        ng = _build_lights_group(in_use, plan)
        ng[LIGHTS_RECORD_KEY] = [f"{obj.name}:{kind}" for obj, kind in records]
        ng[LIGHTS_SIGNATURE_KEY] = signature
    ng[LINKING_KEY] = {name: attr for name, (attr, _) in light_model.linking_attributes(records).items()}
    light_model.sync_linking(scene.objects, records)
    return records


def _build_lights_group(in_use, plan):
    """The lights group for ``plan`` [(output name, object, driver source, Socket)]: one Value node per output, driven.

    Built in a copy of the group in use (which no tree uses), then swapped in (``replace_group``): every edit of a
    group in use is propagated to the trees that use it (the RT Lit trees, thousands of nodes), which made a sync of
    100 lights take minutes (docs/benchmarks/light_sync.md).  The copy keeps the interface's socket identifiers, and
    an unchanged interface is kept (``ensure_interface``), so the links of the trees using it hold."""
    ng = in_use.copy() if in_use is not None else bpy.data.node_groups.new(SCENE_LIGHTS_GROUP, "ShaderNodeTree")
    try:
        remove_drivers(ng)
        ng.nodes.clear()
        ng.description = "Driver values of the scene's lights (rebuilt by RT Lookdev > Sync Lights)"
        items = ensure_interface(ng, [(name, "OUTPUT", FLOAT, spec) for name, _, _, spec in plan])
        out = ng.nodes.new("NodeGroupOutput")
        for row, (name, obj, source, _) in enumerate(plan):
            value = ng.nodes.new("ShaderNodeValue")
            value.name = value.label = name
            value.location = (0.0, -row * 90.0)
            value.outputs[0].default_value = light_model.static_value(obj, source)
            light_model.add_light_driver(value.outputs[0], obj, source)
            ng.links.new(value.outputs[0], socket_by_identifier(out.inputs, items[(name, "OUTPUT")].identifier))
        out.location = (400.0, 0.0)
    except BaseException:
        if in_use is not None:          # the group in use stays as it was
            bpy.data.node_groups.remove(ng)
        raise
    if in_use is not None:
        replace_group(in_use, ng)
    return ng


def _delivers(ng, signature, plan):
    """Whether the lights group ``ng`` delivers ``plan`` as it is: synced for the same light ``signature``, one driven
    Value node linked per output, and every driver reading the light object (or its light data) it was made for.  A
    light deleted and another made under its name gives the same signature, but drivers that read nothing."""
    if ng is None or list(ng.get(LIGHTS_SIGNATURE_KEY, [])) != signature:
        return False
    drivers = ng.animation_data.drivers if ng.animation_data is not None else ()
    if not len(ng.nodes) == len(ng.links) + 1 == len(plan) + 1 == len(drivers) + 1:
        return False
    wanted = {f'nodes["{name}"].outputs[0].default_value': obj for name, obj, _, _ in plan}
    for fc in drivers:
        obj = wanted.get(fc.data_path)
        if obj is None:
            return False
        for variable in fc.driver.variables:
            target = variable.targets[0].id
            if target is None or (target != obj and target != obj.data):
                return False
    return True


def light_signature(records):
    """What the RT Lit groups and the lights' drivers depend on in a light list: each light's name, kind, area
    shape and what its colour is the product of (``light_model.color_record``); then what the linked lights
    exclude (``light_model.linking_record``)."""
    return ([f"{obj.name}:{kind}:{light_model.shape(obj) or ''}:{light_model.color_record(obj.data)}"
             for obj, kind in records] + light_model.linking_record(records))


def lights_out_of_sync(scene):
    """Whether ``scene``'s shaded lights differ from the ones the RT Lit groups were last synced for (False
    when the file has no RT Lit group: nothing to keep in sync)."""
    if not has_rt_lit_groups():
        return False
    records = scene_lights(scene)
    return differs_from_sync(light_signature(records), lambda: material_reach(scene, records))


def has_rt_lit_groups():
    """Whether the file has an RT Lit group (then its lights are kept in sync)."""
    return any(ng.name.startswith(RT_LIT_GROUP_PREFIX) and FEATURES_KEY in ng for ng in bpy.data.node_groups)


def differs_from_sync(signature, reach):
    """Whether the RT Lit groups were last synced for another light signature (``light_signature``) or, with
    ``reach()`` called only when the signatures agree, for another reach (``material_reach``)."""
    ng = bpy.data.node_groups.get(SCENE_LIGHTS_GROUP)
    synced = list(ng.get(LIGHTS_SIGNATURE_KEY, [])) if ng is not None else []
    if signature != synced:
        return True
    # a light with a range or an object that moved can change which lights reach a material (``cull_lights``)
    return ng is not None and _reach_record(reach()) != ng.get(REACH_KEY, _reach_record({}))


def synced_light_kinds():
    """The light kinds of "RTL Scene Lights" in order (what RT Lit groups are built for)."""
    ng = bpy.data.node_groups.get(SCENE_LIGHTS_GROUP)
    entries = ng.get(LIGHTS_RECORD_KEY, []) if ng is not None else []
    return [tuple(entry.rsplit(":", 1)) for entry in entries]


def synced_linking():
    """{light name: (attribute, inverted)} of the linked lights at the last sync (``light_model.linking_attributes``):
    what the RT Lit trees read for their "Excluded" inputs."""
    ng = bpy.data.node_groups.get(SCENE_LIGHTS_GROUP)
    stored = ng.get(LINKING_KEY, {}) if ng is not None else {}
    return {name: (str(attr), light_model.is_inverted(str(attr))) for name, attr in dict(stored).items()}


class _TreeInputs:
    """Sockets inside an RT Lit tree for the material function's internal inputs: the Geometry node,
    the lights group and the world group, each added once."""

    def __init__(self):
        self.nodes = {}

    def _node(self, key, nodes, make):
        node = self.nodes.get(key)
        if node is None:
            node = self.nodes[key] = make(nodes)
        return node

    def geometry(self, output):
        def make(nodes, links):
            def new(nodes):
                node = nodes.new("ShaderNodeNewGeometry")
                node.location = (-400.0, 300.0)
                return node
            return self._node("geometry", nodes, new).outputs[output]
        return make

    def ambient_occlusion(self):
        """The AO output of an Ambient Occlusion node (``AO_DISTANCE``, the shading normal: its Normal unlinked)."""
        def make(nodes, links):
            def new(nodes):
                node = nodes.new("ShaderNodeAmbientOcclusion")
                node.inputs["Distance"].default_value = AO_DISTANCE
                node.location = (-400.0, 600.0)
                return node
            return self._node("ambient occlusion", nodes, new).outputs["AO"]
        return make

    def attribute(self, name, inverted, y):
        """The Fac output of an Attribute node (Object type) reading ``name`` (an object's custom property, 0
        where the object has none), or 1 - Fac when ``inverted``."""
        def make(nodes, links):
            def new(nodes):
                node = nodes.new("ShaderNodeAttribute")
                node.attribute_type = "OBJECT"
                node.attribute_name = name
                node.label = name
                node.location = (-600.0, y)
                if not inverted:
                    return node
                invert = nodes.new("ShaderNodeMath")
                invert.operation = "SUBTRACT"
                invert.inputs[0].default_value = 1.0
                invert.location = (-400.0, y)
                links.new(node.outputs["Fac"], invert.inputs[1])
                return invert
            node = self._node(("attribute", name), nodes, new)
            return node.outputs["Fac" if not inverted else "Value"]
        return make

    def group(self, key, group_name, y, output):
        def make(nodes, links):
            def new(nodes):
                node = nodes.new("ShaderNodeGroup")
                node.node_tree = bpy.data.node_groups[group_name]
                node.location = (-400.0, y)
                node.label = group_name
                return node
            return self._node(key, nodes, new).outputs[output]
        return make


#: RT Lit's tree per render engine: (engine, Material Output target, table filter, output prefix).  Cycles'
#: Image Texture with Linear interpolation is the exact bilinear filter of the tables (one node per
#: lookup); EEVEE's picks mipmaps from screen-space derivatives, so its tree writes the filter out as
#: four Closest fetches (core.ir.tables.bilinear_function).  docs/blender.md, "Per-engine trees".
ENGINE_TREES = (("Cycles", "CYCLES", "linear", ""), ("EEVEE", "EEVEE", "fetch4", "EEVEE "))
#: The engine trees that write each light's radiance to a Shader AOV (``common.light_aov_name``) for the shadow
#: compositor (addon/shadows.py), only while the scene has shadows on (``SHADOWS_KEY``).  Not always: Cycles drops an
#: AOV node whose AOV no view layer declares, but EEVEE compiles every AOV node's inputs, whatever the Material
#: Output's target, so the Cycles tree's AOVs put the whole Cycles tree into EEVEE's shader (measured with 5.2.3:
#: "Uniform block _node_tree too big (66000/65536)" and a wrong image in tests/blender/test_engine_trees.py).
AOV_ENGINES = ("Cycles",)
ENGINE_STAMP_KEY = "rtl_engine_trees"
#: With the World term's shadows on as well (addon/shadows.py, ``world=True``): the Cycles tree writes the World
#: Radiance part and the world's white-Lambert radiance (SH) to these Shader AOVs (function output -> AOV), and leaves
#: out ``Features.occlusion`` (the ratio occludes the world there).
WORLD_AOVS = {"World Radiance": "RTL World", "World Irradiance": "RTL World Irradiance"}


def world_shadows_on(scene):
    """Whether ``scene``'s RT Lit shadows shadow the World term too (``shadows.enable_shadows(world=True)``)."""
    stored = scene.get(SHADOWS_KEY)
    return stored is not None and bool(stored.get("world", False))


def engine_tree_name(features, engine):
    """Name of the RT Lit tree of ``features`` for ``engine`` ("Cycles" / "EEVEE")."""
    return f"{rt_lit_group_name(features)} [{engine}]"


def engine_output(engine, output="Shader"):
    """The RT Lit group's output that carries ``output`` ("Shader", "Radiance") of ``engine``'s tree."""
    return next(prefix for name, _, _, prefix in ENGINE_TREES if name == engine) + output


def culled_group_name(features, lights):
    """"RT Lit (<features>) [lights 0, 2]": the RT Lit group of a material that only some lights reach."""
    return f"{rt_lit_group_name(features)} [lights {', '.join(str(i) for i in lights)}]"


def ensure_rt_lit_group(features=None, scene=None, lut_dir=None, lights=None):
    """The RT Lit group for ``features`` and the lights of ``scene`` (built or reused): the material
    inputs as its interface, one nested tree per engine (``ENGINE_TREES``) fed by them, and each tree's
    outputs ("Shader", "Radiance" for Cycles; "EEVEE Shader", "EEVEE Radiance").  ``lights``: the indices
    of the scene's lights it shades (``cull_lights``), default all of them.  While ``scene`` has shadows on
    (addon/shadows.py) the Cycles tree also writes each light's radiance to its AOV (``AOV_ENGINES``)."""
    features = features or Features()
    scene = scene or bpy.context.scene
    if bpy.data.node_groups.get(SCENE_LIGHTS_GROUP) is None:
        sync_scene_lights(scene)
    records = synced_light_kinds()
    linked = synced_linking()
    shaded = tuple(range(len(records))) if lights is None else tuple(lights)
    name = rt_lit_group_name(features) if lights is None else culled_group_name(features, shaded)
    world = world_sync.world_environment()
    env, world_record = world if world is not None else (None, None)
    tables = _tables(lut_dir, env)
    trees, material_inputs = {}, None
    for engine, _, table_filter_mode, _ in ENGINE_TREES:
        aovs = engine in AOV_ENGINES and SHADOWS_KEY in scene
        world_aovs = aovs and env is not None and world_shadows_on(scene)
        with table_filter(table_filter_mode):
            material = rt_lit.build_rt_lit(replace(features, occlusion="none") if world_aovs else features,
                                           tuple(records[i][1] for i in shaded), env, world_irradiance=world_aovs)
        inputs = _TreeInputs()
        internal = {n: inputs.geometry(_GEOMETRY_SOCKETS[n]) for n in GEOMETRY_INPUTS}
        # the material function's light k is the scene's light shaded[k]: "Light k p" <- "Light shaded[k] p"; the
        # linking option's "Excluded" is the object's attribute (light_model.excluded_attribute)
        for k, per_light in enumerate(material.light_inputs):
            internal.update({n: (inputs.attribute(*linked[records[shaded[k]][0]], -900.0 - 120.0 * k)
                                 if param == "Excluded" else
                                 inputs.group("lights", SCENE_LIGHTS_GROUP, -200.0, light_input(shaded[k], param)))
                             for param, n in per_light.items()})
        internal.update({n: inputs.group("world", WORLD_GROUP, -600.0, n) for n in material.world_inputs.values()})
        internal.update({n: inputs.ambient_occlusion() for n in material.occlusion_inputs})
        trees[engine], _ = node_emit.ensure_tree(f"{name} [{engine}]", material.function,
                                                 material.material_inputs, sockets=(RT_LIT_INPUTS, RT_LIT_OUTPUTS),
                                                 internal_inputs=internal,
                                                 stamp_extra=repr((records, shaded, world_record and world_record["table"],
                                                                   sorted(linked.items()))),
                                                 tables=tables, shader_sums={"Shader": list(material.part_outputs)},
                                                 aov_outputs=({**{part: light_aov_name(shaded[k]) for k, part
                                                                  in enumerate(material.part_outputs[1:1 + len(shaded)])},
                                                               **(WORLD_AOVS if world_aovs else {})}
                                                              if aovs else None))
        material_inputs = material.material_inputs
    ng = _ensure_engine_group(name, trees, material_inputs)
    ng[FEATURES_KEY] = features.as_dict()
    if lights is not None:
        ng[LIGHTS_SUBSET_KEY] = list(shaded)
    return ng


def engine_node_counts(ng):
    """{engine: flattened Blender nodes of its tree} of an RT Lit group (``{"All": n}`` for a group
    without engine trees)."""
    trees = {n.name: n.node_tree for n in ng.nodes if n.bl_idname == "ShaderNodeGroup" and n.node_tree is not None
             and n.name in {engine for engine, *_ in ENGINE_TREES}}
    if not trees:
        return {"All": node_emit.flat_tree_node_count(ng)}
    return {engine: node_emit.flat_tree_node_count(tree) for engine, tree in trees.items()}


def _ensure_engine_group(name, trees, material_inputs):
    """The group artists see: interface = the material inputs, one Group node per engine tree, each
    tree's outputs under its engine's prefix.  Kept when it already holds these trees (they are rebuilt
    in place), so materials keep their links and values."""
    ng = bpy.data.node_groups.get(name)
    if ng is None:
        ng = bpy.data.node_groups.new(name, "ShaderNodeTree")
    # a tree's outputs in the stamp: a tree rebuilt with another output list (the World shadows' "World Irradiance")
    # loses the links of this group's node to it
    stamp = repr([(engine, tree.name, [i.name for i in tree.interface.items_tree if getattr(i, "in_out", "") == "OUTPUT"])
                  for engine, tree in trees.items()] + list(material_inputs))
    wanted = [(engine_output(engine, out), "OUTPUT", RT_LIT_OUTPUTS[out].kind, RT_LIT_OUTPUTS[out])
              for engine in trees for out in RT_LIT_OUTPUTS]
    wanted += [(n, "INPUT", RT_LIT_INPUTS[n].kind, RT_LIT_INPUTS[n]) for n in material_inputs]
    items = ensure_interface(ng, wanted)
    # the group's stamp follows its trees' (they are rebuilt in place when their function changes)
    ng[STAMP_KEY] = repr([(engine, tree.get(STAMP_KEY)) for engine, tree in trees.items()])
    if ng.get(ENGINE_STAMP_KEY) == stamp and len(ng.nodes) == 2 + len(trees):
        return ng
    ng.nodes.clear()
    ng.description = "RT Lit: the material inputs feed one tree per render engine (Cycles: Linear table " \
                     "lookups; EEVEE: four exact texel fetches); connect Shader to a Cycles Material Output " \
                     "and EEVEE Shader to an EEVEE one (assign_rt_lit does)"
    group_in = ng.nodes.new("NodeGroupInput")
    group_in.location = (-400.0, 0.0)
    group_out = ng.nodes.new("NodeGroupOutput")
    group_out.location = (400.0, 0.0)
    for row, (engine, tree) in enumerate(trees.items()):
        node = ng.nodes.new("ShaderNodeGroup")
        node.node_tree = tree
        node.name = node.label = engine
        node.width = 240
        node.location = (0.0, -row * 500.0)
        for n in material_inputs:
            ng.links.new(socket_by_identifier(group_in.outputs, items[(n, "INPUT")].identifier), node.inputs[n])
        for out in RT_LIT_OUTPUTS:
            target = socket_by_identifier(group_out.inputs, items[(engine_output(engine, out), "OUTPUT")].identifier)
            ng.links.new(node.outputs[out], target)
    ng[ENGINE_STAMP_KEY] = stamp
    return ng


def _tables(lut_dir, env):
    """The LUT set of ``lut_dir`` and the synced environment's table (its file as found now)."""
    luts = LutSet.from_folder(lut_dir)
    return luts if env is None else luts.with_tables(env.as_table())


def rebuild_rt_lit_groups(scene, lut_dir=None):
    """After a light sync: rebuild every RT Lit group in the file for the scene's lights, then give each material
    the group of the lights that reach it (``cull_lights``)."""
    # read first: a rebuild replaces the groups it rebuilds (``node_emit.ensure_tree``)
    wanted = [Features.from_dict(ng[FEATURES_KEY]) for ng in bpy.data.node_groups
              if FEATURES_KEY in ng.keys() and ng.name.startswith(RT_LIT_GROUP_PREFIX) and LIGHTS_SUBSET_KEY not in ng]
    rebuilt = [ensure_rt_lit_group(features, scene, lut_dir) for features in wanted]
    rebuilt += cull_lights(scene, lut_dir)
    return rebuilt


# --- lights out of range (issue 15: skip what a scene does not need) ----------------------------------------
# A light with a range (core/lights.py, option "range") gives exactly 0 beyond it (Karis 2013's window is 0 for
# d >= r).  A material whose objects all lie beyond a light's range gets an RT Lit group without that light:
# the same values, fewer nodes.  "Beyond" is tested against a sphere around each object (conservative: a light
# may be kept that a box would cull).  Which lights reach which material is re-checked when lights or objects
# change (``lights_out_of_sync``); the automatic light sync keeps each object's sphere between depsgraph updates and
# re-computes only what an update names (addon/light_sync.py; docs/benchmarks/light_sync.md).

def rendered_objects(scene):
    """The objects a render of ``scene`` includes (as ``is_rendered``, in one pass over the collections)."""
    names = set()
    for layer in scene.view_layers:
        if layer.use:
            names |= _layer_collections(scene, layer)
    hidden = {c.name for c in bpy.data.collections if c.hide_render}
    out = {o for o in scene.collection.objects if not o.hide_render} if scene.collection.name in names else set()
    for name in names - hidden:
        collection = bpy.data.collections.get(name)
        if collection is not None:
            out.update(o for o in collection.objects if not o.hide_render)
    # an object in a hidden collection is hidden, whatever other collection also holds it (``is_rendered``)
    for name in hidden:
        out.difference_update(bpy.data.collections[name].objects)
    return out


def render_layout(scene):
    """What decides which collections a render of ``scene`` includes: each view layer's use and included collections,
    and the collections disabled in renders.  While it is unchanged, only a change of an object itself (its
    ``hide_render``, its collections) changes the objects a render includes."""
    layers = tuple((layer.name, layer.use, frozenset(_layer_collections(scene, layer)) if layer.use else None)
                   for layer in scene.view_layers)
    return layers, frozenset(c.name for c in bpy.data.collections if c.hide_render)


_GEOMETRY = {"MESH", "CURVE", "SURFACE", "META", "FONT"}


def _material_pointers(obj):
    """The pointers of the materials an object of a geometry type uses (sorted), () for none or another type."""
    if obj.type not in _GEOMETRY:
        return ()
    return tuple(sorted({slot.material.as_pointer() for slot in obj.material_slots if slot.material is not None}))


def _spheres(matrices, boxes):
    """Centres (n, 3) and radii (n,) of the spheres around objects from their world matrices (n, 4, 4; rows first) and
    object-space bounding boxes (n, 8, 3): the box's centre and half-diagonal, the radius times the largest scale (of
    the matrix's columns).  Element by element, so one object gives the same sphere alone as among many."""
    m, b = matrices.astype(np.float64), boxes.astype(np.float64)
    mid, half = (b[:, 0] + b[:, 6]) * 0.5, (b[:, 6] - b[:, 0]) * 0.5
    centres = m[:, :3, 0] * mid[:, :1] + m[:, :3, 1] * mid[:, 1:2] + m[:, :3, 2] * mid[:, 2:] + m[:, :3, 3]
    length = np.sqrt(half[:, 0] ** 2 + half[:, 1] ** 2 + half[:, 2] ** 2)
    scale = np.sqrt(m[:, 0, :3] ** 2 + m[:, 1, :3] ** 2 + m[:, 2, :3] ** 2).max(axis=1)
    return centres, length * scale


def reach_row(obj):
    """(material pointers, sphere centre, sphere radius) of an object for the reach check: a sphere around it (its
    bounding box's centre and half-diagonal, times its largest scale: conservative, and cheap for every update);
    None for an object without geometry or materials."""
    used = _material_pointers(obj)
    if not used:
        return None
    centres, radii = _spheres(np.array(obj.matrix_world, np.float32)[None], np.array(obj.bound_box, np.float32)[None])
    return used, tuple(centres[0]), float(radii[0])


def reach_rows(scene, objects):
    """{object pointer: ``reach_row``} of the ``objects`` of ``scene`` (a set) that have one, all at once: the world
    matrices and bounding boxes of the scene's objects read in one call each (``foreach_get``)."""
    found, picked = [], []
    for i, obj in enumerate(scene.objects):
        used = _material_pointers(obj) if obj in objects else ()
        if used:
            found.append((obj.as_pointer(), used))
            picked.append(i)
    if not picked:
        return {}
    n = len(scene.objects)
    matrices, boxes = np.empty(n * 16, np.float32), np.empty(n * 24, np.float32)
    scene.objects.foreach_get("matrix_world", matrices)           # columns first
    scene.objects.foreach_get("bound_box", boxes)
    centres, radii = _spheres(matrices.reshape(n, 4, 4).transpose(0, 2, 1)[picked], boxes.reshape(n, 8, 3)[picked])
    return {pointer: (used, tuple(c), float(r)) for (pointer, used), c, r in zip(found, centres, radii)}


def material_spheres(rows, places=None):
    """The spheres of ``rows`` ({object: ``reach_row``}) by material: (material pointers, starts, centres (n, 3), radii
    (n,)), material k's rows from starts[k] to starts[k + 1]; ``places``, when given, is filled with {object: [its row
    indices]}."""
    found = {}
    for obj, (used, centre, radius) in rows.items():
        for pointer in used:
            found.setdefault(pointer, []).append((obj, centre, radius))
    starts, centres, radii = [0], [], []
    for spheres in found.values():
        for obj, centre, radius in spheres:
            if places is not None:
                places.setdefault(obj, []).append(len(radii))
            centres.append(centre)
            radii.append(radius)
        starts.append(len(radii))
    return list(found), np.array(starts), np.array(centres, np.float64).reshape(-1, 3), np.array(radii, np.float64)


def ranged_lights(records):
    """[(index, location, range)] of the lights with a range among ``records`` ([(object, kind)])."""
    return [(i, tuple(obj.matrix_world.translation), float(light_controls.value(obj.data, "rtl_range")))
            for i, (obj, kind) in enumerate(records) if "range" in core_lights.split_kind(kind)[1]]


def out_of_range(ranged, spheres):
    """{material pointer: the indices of the lights of ``ranged`` ([(index, location, range)]) that reach none of its
    spheres} (``spheres``: ``material_spheres``): every sphere of the material lies at or beyond the light's range."""
    materials, starts, centres, radii = spheres
    if not ranged or not materials:
        return {m: frozenset() for m in materials}
    locations = np.array([loc for _, loc, _ in ranged], np.float64)
    ranges = np.array([r for _, _, r in ranged], np.float64)
    squared = np.zeros((len(ranged), len(radii)))          # (lights, spheres): the spheres along numpy's fast axis
    for axis in range(3):
        offset = locations[:, axis:axis + 1] - centres[:, axis]
        offset *= offset
        squared += offset
    gaps = np.sqrt(squared) - radii
    reached = np.logical_or.reduceat(~(gaps >= ranges[:, None]), starts[:-1], axis=1)    # (lights, materials)
    return {m: frozenset(i for (i, _, _), hit in zip(ranged, column) if not hit)
            for m, column in zip(materials, reached.T)}


def reach_of_materials(beyond, count):
    """What ``material_reach`` returns, from ``beyond`` ({material pointer: indices of the lights that reach none of
    its objects}) and the number of scene lights: {material name: indices of the lights that can reach it} for the
    RT Lit materials some light cannot reach."""
    if not any(beyond.values()):
        return {}
    materials = {m.as_pointer(): m for m in bpy.data.materials}
    out = {}
    for pointer, far in beyond.items():
        material = materials.get(pointer)
        if far and material is not None and FEATURES_KEY in material.keys():
            out[material.name] = [i for i in range(count) if i not in far]
    return out


def material_reach(scene, records):
    """{material name: indices of the lights that can reach its objects} for the RT Lit materials some light with
    a range cannot reach; {} when every light reaches every material."""
    ranged = ranged_lights(records)
    if not ranged:
        return {}
    return reach_of_materials(out_of_range(ranged, material_spheres(reach_rows(scene, rendered_objects(scene)))),
                              len(records))


def _reach_record(reach):
    return repr(sorted((k, list(v)) for k, v in reach.items()))


def cull_lights(scene, lut_dir=None):
    """Give each RT Lit material the group of the scene lights that can reach it: the shared group when all do, a
    culled one ("RT Lit (<features>) [lights 0, 2]") when a light's range stops short of its objects.  Culled groups
    no material uses are removed.  Returns the culled groups in use."""
    records = scene_lights(scene)
    reach = material_reach(scene, records)
    used = []
    for material in bpy.data.materials:
        if FEATURES_KEY not in material.keys() or material.node_tree is None or material.library is not None:
            continue
        node = material.node_tree.nodes.get(RT_LIT_NODE_NAME)
        if node is None or node.node_tree is None:
            continue
        features = Features.from_dict(material[FEATURES_KEY])
        lights = reach.get(material.name)
        group = (ensure_rt_lit_group(features, scene, lut_dir, lights) if lights is not None
                 else bpy.data.node_groups.get(rt_lit_group_name(features)) or ensure_rt_lit_group(features, scene, lut_dir))
        if node.node_tree != group:
            node.node_tree = group
        if lights is not None:
            used.append(group)
    _remove_groups([ng for ng in bpy.data.node_groups if LIGHTS_SUBSET_KEY in ng and ng not in used and ng.users == 0])
    lights_group = bpy.data.node_groups.get(SCENE_LIGHTS_GROUP)
    if lights_group is not None:
        lights_group[REACH_KEY] = _reach_record(reach)
    return used


def _remove_groups(groups):
    """Remove RT Lit groups and then their engine trees that nothing else uses."""
    names = {n.node_tree.name for ng in groups for n in ng.nodes
             if n.bl_idname == "ShaderNodeGroup" and n.node_tree is not None}
    for ng in groups:
        bpy.data.node_groups.remove(ng)
    for name in names:
        tree = bpy.data.node_groups.get(name)
        if tree is not None and tree.users == 0:
            bpy.data.node_groups.remove(tree)


def assign_rt_lit(material, features=None, scene=None, lut_dir=None):
    """Make ``material`` an RT Lit material: the RT Lit group's "Shader" to a Material Output for Cycles
    and its "EEVEE Shader" to one for EEVEE (``common.connect_engine_outputs``)."""
    ng = ensure_rt_lit_group(features, scene, lut_dir)
    nt = compat.ensure_node_tree(material)
    nodes = nt.nodes
    group = nodes.get(RT_LIT_NODE_NAME)
    if group is None:
        group = nodes.new("ShaderNodeGroup")
        group.name = group.label = RT_LIT_NODE_NAME
    group.node_tree = ng
    group.width = max(group.width, 240.0)
    output = next((n for n in nodes if n.bl_idname == "ShaderNodeOutputMaterial" and n.is_active_output), None)
    if output is None:
        output = nodes.new("ShaderNodeOutputMaterial")
    group.location = (output.location.x - 300.0, output.location.y)
    connect_engine_outputs(nt, group, output)
    not_a_light(material)
    material[FEATURES_KEY] = (features or Features()).as_dict()
    return group


def material_parameters(material):
    """RT_LIT_INPUTS name -> unlinked value of the material's RT Lit node (colours as RGB)."""
    node = material.node_tree.nodes[RT_LIT_NODE_NAME]
    out = {}
    for name, sock in RT_LIT_INPUTS.items():
        value = node.inputs[name].default_value
        out[name] = float(value) if sock.kind == "float" else tuple(float(x) for x in list(value)[:3])
    return out

