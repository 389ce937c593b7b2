"""RT Lit node groups and the scene's lights: the bpy side of core/materials/rt_lit.py.

- ``sync_scene_lights(scene)`` (re)builds the shared group "RTL Scene Lights": one Value node
  per light parameter, each driven by a simple-expression driver (TRANSFORMS in world space for
  location, quaternion rotation and scale; SINGLE_PROP on the light data for power, colour,
  size and cone), so the drivers evaluate without Python after a reload with auto-run off
  (../shared/reference/blender_addon.md §4.1).  Its outputs are named "Light <i> <parameter>".
- ``ensure_rt_lit_group(features, scene)`` builds "RT Lit (<features>)" from
  ``rt_lit.rt_lit_radiance`` traced with the scene's lights: Geometry > Position / Normal /
  Incoming and the lights group feed it inside the tree; its interface is RT_LIT_INPUTS.
  Groups are stamped with the structure hash of their graph and rebuilt only when it changes.
- The World term (core/materials/world.py) is part of the group when the shared "RTL World" group
  exists with its bake record (``addon/world.py`` ``sync_world``): its outputs feed the "World ..."
  inputs, and the prefiltered image is a table of the graph.  Without it (the world has no image)
  nothing of the world is built or loaded.
"""
from __future__ import annotations

import bpy
import numpy as np

from ..core import lights as core_lights
from ..core.ir import Graph
from ..core.ir.expr import FLOAT, VECTOR
from ..core.ir.interface import Socket
from ..core.materials import rt_lit
from ..core.materials.rt_lit_interface import RT_LIT_INPUTS, RT_LIT_OUTPUTS, Features
from . import node_emit

SCENE_LIGHTS_GROUP = "RTL Scene Lights"
WORLD_GROUP = "RTL World"          # built by addon/world.py sync_world
RT_LIT_PREFIX = "RT Lit"
FEATURES_KEY = "rtl_features"

_AREA_SHAPES = {"SQUARE": "quad", "RECTANGLE": "quad", "DISK": "disk", "ELLIPSE": "disk"}


def light_kind(obj):
    """The RT Lit light kind of a light object, or None if RT Lit does not shade it."""
    if obj.type != "LIGHT":
        return None
    data = obj.data
    if data.type == "AREA":
        return _AREA_SHAPES.get(data.shape)
    return {"POINT": "point", "SPOT": "spot", "SUN": "sun"}.get(data.type)


def scene_lights(scene):
    """(object, kind) of every light RT Lit shades: rendered lights, in name order (the sun
    with angle 0, point and spot lights with radius 0: see core/lights.py)."""
    out = []
    for obj in sorted(scene.objects, key=lambda o: o.name):
        kind = light_kind(obj)
        if kind is not None and not obj.hide_render:
            out.append((obj, kind))
    return out


def _add_driver(socket, obj, source):
    """A simple-expression driver ``var`` on socket.default_value reading ``source``."""
    fc = socket.driver_add("default_value")
    drv = fc.driver
    drv.type = "SCRIPTED"
    drv.expression = "var"
    var = drv.variables.new()
    var.name = "var"
    kind, what = source
    if kind == "transform":
        var.type = "TRANSFORMS"
        t = var.targets[0]
        t.id = obj
        t.transform_type = what
        t.transform_space = "WORLD_SPACE"
        if what.startswith("ROT_"):
            t.rotation_mode = "QUATERNION"
    else:
        var.type = "SINGLE_PROP"
        t = var.targets[0]
        t.id_type = "LIGHT"
        t.id = obj.data
        t.data_path = what
    return fc


def _static_value(obj, source):
    """The value a driver will compute, for the Value node's initial default."""
    kind, what = source
    if kind == "transform":
        loc, rot, scale = obj.matrix_world.decompose()
        axis = "WXYZ".index(what[-1]) if what.startswith("ROT_") else "XYZ".index(what[-1])
        if what.startswith("LOC_"):
            return loc[axis]
        if what.startswith("ROT_"):
            return rot[axis]
        return scale[axis]
    return float(obj.data.path_resolve(what))


def sync_scene_lights(scene):
    """(Re)build the "RTL Scene Lights" group for ``scene``; returns [(object, kind)]."""
    records = scene_lights(scene)
    ng = bpy.data.node_groups.get(SCENE_LIGHTS_GROUP)
    if ng is None:
        ng = bpy.data.node_groups.new(SCENE_LIGHTS_GROUP, "ShaderNodeTree")
    if ng.animation_data is not None:
        for fc in list(ng.animation_data.drivers):
            ng.animation_data.drivers.remove(fc)
    ng.nodes.clear()
    ng.description = "Driver values of the scene's lights (rebuilt by RT Lookdev > Sync Lights)"
    plan = []
    for index, (obj, kind) in enumerate(records):
        shape = obj.data.shape if obj.data.type == "AREA" else None
        for param, source in core_lights.driver_sources(kind, shape).items():
            plan.append((f"Light {index} {param}", obj, source,
                         Socket("float", 0.0, description=f"{obj.name}: {param} ({source[0]} {source[1]})",
                                panel=f"Light {index}: {obj.name}")))
    # an unchanged interface is kept, so RT Lit groups using this one keep their links
    items = node_emit._ensure_interface(ng, [(name, "OUTPUT", FLOAT, spec) for name, _, _, spec in plan])
    out = ng.nodes.new("NodeGroupOutput")
    for row, (name, obj, source, _) in enumerate(plan):
        value = ng.nodes.new("ShaderNodeValue")
        value.name = value.label = name
        value.location = (0.0, -row * 90.0)
        value.outputs[0].default_value = _static_value(obj, source)
        _add_driver(value.outputs[0], obj, source)
        ng.links.new(value.outputs[0], node_emit._socket(out.inputs, items[(name, "OUTPUT")].identifier))
    out.location = (400.0, 0.0)
    ng["rtl_lights"] = [f"{obj.name}:{kind}" for obj, kind in records]
    return records


def world_environment():
    """(WorldEnvironment, record) of the synced world, or None when "RTL World" is absent."""
    from ..core.materials.world import WorldEnvironment

    ng = bpy.data.node_groups.get(WORLD_GROUP)
    record = ng["rtl_world"].to_dict() if ng is not None and "rtl_world" in ng.keys() else None
    if not record:
        return None
    try:
        env = WorldEnvironment.load(record["prefiltered"], record["table"])
        node_emit.register_image(record["table"], record["prefiltered"])
    except Exception as exc:
        # the cache file is gone (another machine, a cleaned cache): the image packed in this file
        # holds the same table
        env = _packed_environment(record)
        if env is None:
            raise RuntimeError(f"the baked world environment {record['prefiltered']} cannot be read ({exc}) and "
                               "is not packed in this file; run RT Lookdev > Sync RT Lit World again") from exc
    return env, record


def _packed_environment(record):
    from ..core.materials.world import WorldEnvironment

    image = bpy.data.images.get(f"RTL_{record['table']}")
    levels = record.get("roughness_levels")
    if image is None or not levels:
        return None
    w, h = image.size
    if w * h == 0 or len(image.pixels) != w * h * 4:
        return None
    table = np.empty(w * h * 4, np.float32)
    image.pixels.foreach_get(table)               # bottom row first: the table's row order
    return WorldEnvironment(record["table"], table.reshape(h, w, 4), tuple(float(r) for r in levels))


def _graph_for(features, records, env=None):
    """Trace the RT Lit material for these lights (and the world's environment ``env``, or None):
    (outputs, material input names, light and world input names)."""
    g = Graph()
    material = {}
    for name, sock in RT_LIT_INPUTS.items():
        material[name] = g.input(name, FLOAT if sock.kind == "float" else VECTOR)
    geometry = {name: g.input(name, VECTOR) for name in ("Position", "Geometry Normal", "Incoming")}
    lights_in = []
    light_inputs = []
    for index, (_, kind) in enumerate(records):
        params = {}
        for param in core_lights.driver_sources(kind):
            params[param] = g.input(f"Light {index} {param}")
            light_inputs.append(f"Light {index} {param}")
        lights_in.append((kind, params))
    world_in = None
    if env is not None:
        from ..core.materials.world import WORLD_PARAMETERS

        params = {}
        for name, sock in WORLD_PARAMETERS.items():
            params[name] = g.input(f"World {name}", FLOAT if sock.kind == "float" else VECTOR)
            light_inputs.append(f"World {name}")
        world_in = (env, params)
    parts = rt_lit.rt_lit_radiance_parts(features, material, geometry, lights_in, world_in)
    outputs = {"Radiance": parts[0]}
    for i, part in enumerate(parts):
        if i == 0:
            name = "Material Emission"
        elif world_in is not None and i == len(parts) - 1:
            name = "World Radiance"
        else:
            name = f"Light {i - 1} Radiance"
        outputs[name] = part
        if i:
            outputs["Radiance"] = outputs["Radiance"] + part
    return outputs, list(RT_LIT_INPUTS), light_inputs


def rt_lit_group_name(features):
    return f"{RT_LIT_PREFIX} ({features.label()})"


def ensure_rt_lit_group(features=None, scene=None, lut_dir=None):
    """The RT Lit group for ``features`` and the lights of ``scene`` (built or reused)."""
    features = features or Features()
    scene = scene or bpy.context.scene
    if bpy.data.node_groups.get(SCENE_LIGHTS_GROUP) is None:
        sync_scene_lights(scene)
    lights_ng = bpy.data.node_groups[SCENE_LIGHTS_GROUP]
    records = []
    for entry in lights_ng.get("rtl_lights", []):
        name, kind = entry.rsplit(":", 1)
        records.append((name, kind))
    world = world_environment()
    env, world_record = world if world is not None else (None, None)
    outputs, material_names, light_names = _graph_for(features, records, env)
    shader_sums = {"Shader": [n for n in outputs if n != "Radiance"]}
    cache = {}

    def geometry_socket(output):
        def make(nodes, links):
            node = cache.get("geometry")
            if node is None:
                node = cache["geometry"] = nodes.new("ShaderNodeNewGeometry")
                node.location = (-400.0, 300.0)
            return node.outputs[output]
        return make

    def light_socket(name):
        def make(nodes, links):
            node = cache.get("lights")
            if node is None:
                node = cache["lights"] = nodes.new("ShaderNodeGroup")
                node.node_tree = lights_ng
                node.location = (-400.0, -200.0)
                node.label = SCENE_LIGHTS_GROUP
            return node.outputs[name]
        return make

    internal = {"Position": geometry_socket("Position"), "Geometry Normal": geometry_socket("Normal"),
                "Incoming": geometry_socket("Incoming")}
    def world_socket(name):
        def make(nodes, links):
            node = cache.get("world")
            if node is None:
                node = cache["world"] = nodes.new("ShaderNodeGroup")
                node.node_tree = bpy.data.node_groups[WORLD_GROUP]
                node.location = (-400.0, -600.0)
                node.label = WORLD_GROUP
            return node.outputs[name]
        return make

    internal.update({n: (world_socket(n) if n.startswith("World ") else light_socket(n)) for n in light_names})
    sockets = (RT_LIT_INPUTS, RT_LIT_OUTPUTS)
    ng, _ = node_emit.ensure_tree(rt_lit_group_name(features), outputs, material_names, sockets,
                                  internal_inputs=internal,
                                  stamp_extra=repr((records, world_record and world_record["table"])), lut_dir=lut_dir,
                                  shader_sums=shader_sums,
                                  description=f"RT Lit lookdev material ({features.label()}): outgoing "
                                              "radiance from every scene light, for an Emission shader")
    ng[FEATURES_KEY] = features.as_dict()
    return ng


def rebuild_rt_lit_groups(scene, lut_dir=None):
    """After a light sync: rebuild every RT Lit group in the file for the scene's lights."""
    rebuilt = []
    for ng in list(bpy.data.node_groups):
        if FEATURES_KEY in ng.keys() and ng.name.startswith(RT_LIT_PREFIX):
            features = Features.from_dict(ng[FEATURES_KEY])
            rebuilt.append(ensure_rt_lit_group(features, scene, lut_dir))
    return rebuilt


def assign_rt_lit(material, features=None, scene=None, lut_dir=None):
    """Make ``material`` an RT Lit material: RT Lit group (Shader) -> Material Output."""
    ng = ensure_rt_lit_group(features, scene, lut_dir)
    nt = material.node_tree
    nodes = nt.nodes
    group = nodes.get("RT Lit")
    if group is None:
        group = nodes.new("ShaderNodeGroup")
        group.name = group.label = "RT Lit"
    group.node_tree = ng
    output = next((n for n in nodes if n.bl_idname == "ShaderNodeOutputMaterial" and n.is_active_output), None)
    if output is None:
        output = nodes.new("ShaderNodeOutputMaterial")
    group.location = (output.location.x - 300.0, output.location.y)
    nt.links.new(group.outputs["Shader"], output.inputs["Surface"])
    material[FEATURES_KEY] = (features or Features()).as_dict()
    return group


def light_parameters(obj, kind):
    """The values the drivers of ``obj`` deliver (parameter name -> float), for numpy evaluation."""
    shape = obj.data.shape if obj.data.type == "AREA" else None
    return {p: float(_static_value(obj, src)) for p, src in core_lights.driver_sources(kind, shape).items()}


def material_parameters(material):
    """RT_LIT_INPUTS name -> unlinked value of the material's RT Lit node (colours as RGB)."""
    node = material.node_tree.nodes["RT Lit"]
    out = {}
    for name, sock in RT_LIT_INPUTS.items():
        value = node.inputs[name].default_value
        out[name] = float(value) if sock.kind == "float" else tuple(float(x) for x in list(value)[:3])
    return out
