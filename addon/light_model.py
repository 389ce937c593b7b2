"""Blender's lights as RT Lit shades them: the kind of a light object, where each of its parameters
comes from, what RT Lit does not shade of it, and light linking.

- ``light_kind(obj)``: the core kind (core/lights.py) of a light object: a point or spot light with
  a radius is a sphere light, a sun with an angle a sun disk, an area light with a spread below
  180 deg carries the "spread" option, a light with a receiver collection the "linking" option, and
  the light controls (addon/light_controls.py) add theirs.
- ``add_light_driver`` / ``static_value``: each parameter of ``core.lights.driver_sources`` as the
  driver that feeds it in the "RTL Scene Lights" group, and the value that driver computes (for the
  numpy evaluation and the exports).  Drivers are simple expressions, so they run with Python
  auto-run off.  The transforms are what TRANSFORMS drivers deliver (the rotation and the columns'
  lengths: a mirror is lost there, so "Determinant" is the 3 x 3 determinant of ``matrix_world``
  from its nine entries: core/lights.py, "Mirrors").  A light's colour is the product of its colour,
  its temperature's blackbody colour (``temperature_color``, as Cycles multiplies it in when
  ``use_temperature`` is on) and its node tree's constant emission colour and strength
  (``emission_factors``).
- ``unshaded_settings(obj, kind)``: what RT Lit still does not shade of a light, for Sync Lights'
  report.
- Light linking: ``receives`` is Blender's rule for a light's receiver collection.  The objects the
  collection names carry an attribute (``linking_attribute``: 1 on the excluded ones, or on the
  included ones when it includes any), which the RT Lit tree reads for the light's "Excluded" input
  (an Attribute node, Object type, inverted in include mode), so objects that share a material
  receive the light or not as Cycles decides per object; ``sync_linking`` writes the attributes.

Measured against Cycles: tests/blender/test_light_model.py.
"""
from __future__ import annotations

import math

import bpy

from ..core import lights as core_lights
from . import compat, light_controls
from .common import add_expression_driver

_AREA_SHAPES = {"SQUARE": "quad", "RECTANGLE": "quad", "DISK": "disk", "ELLIPSE": "disk"}
#: Spreads at or above this are Blender's default 180 deg: no spread option (core/light_spread.py).
FULL_SPREAD = math.pi - 1e-6
#: Prefixes of the object attributes that mark the objects a light's receiver collection excludes or includes.
EXCLUDED_PREFIX = "rtl_excluded_"
INCLUDED_PREFIX = "rtl_included_"
#: The state a linking mode marks with its attribute.
_MARKED_STATE = {"exclude": "EXCLUDE", "include": "INCLUDE"}


# --- kinds ----------------------------------------------------------------------------------------------------

def is_portal(data):
    """Whether an area light is a Cycles light portal (it guides the world's sampling; it emits nothing)."""
    settings = getattr(data, "cycles", None)
    return data.type == "AREA" and bool(getattr(settings, "is_portal", False))


def base_kind(data):
    """The core base kind of a light datablock, or None if RT Lit does not shade it (a portal, an unknown type)."""
    if data.type == "AREA":
        return None if is_portal(data) else _AREA_SHAPES.get(data.shape)
    if data.type == "POINT":
        return "sphere" if data.shadow_soft_size > 0.0 else "point"
    if data.type == "SPOT":
        return "spot_sphere" if data.shadow_soft_size > 0.0 else "spot"
    if data.type == "SUN":
        return "sun_disk" if data.angle > 0.0 else "sun"
    return None


def light_kind(obj):
    """The RT Lit light kind of a light object with its options ("quad+cone+range+spread"), or None if RT Lit
    does not shade it."""
    if obj.type != "LIGHT":
        return None
    data = obj.data
    base = base_kind(data)
    if base is None:
        return None
    base, options = core_lights.split_kind(light_controls.light_kind(data, base))
    extra = []
    if base in core_lights.OPTION_KINDS["spread"] and data.spread < FULL_SPREAD:
        extra.append("spread")
    if obj.light_linking.receiver_collection is not None:
        extra.append("linking")
    return core_lights.kind_name(base, options + tuple(extra))


def shape(obj):
    """The area light's shape (None for other lights)."""
    return obj.data.shape if obj.data.type == "AREA" else None


# --- the light's colour: its colour x temperature x node tree ---------------------------------------------------

def emission_node(data):
    """(node, problem) of a light's node tree: the Emission node feeding its Light Output whose Color and Strength
    are constants (node, None); (None, None) without a node tree; (None, "...") for a tree RT Lit cannot read
    ("emits nothing": nothing reaches the output, which Cycles renders as no light)."""
    if not compat.uses_nodes(data):
        return None, None
    outputs = [n for n in data.node_tree.nodes if n.bl_idname == "ShaderNodeOutputLight"]
    output = next((n for n in outputs if n.is_active_output), outputs[0] if outputs else None)
    if output is None or not output.inputs["Surface"].is_linked:
        return None, "node tree emits nothing"
    node = output.inputs["Surface"].links[0].from_node
    if node.bl_idname != "ShaderNodeEmission":
        return None, f"node tree ({node.bl_label} into the output)"
    linked = [s.name for s in node.inputs if s.name in ("Color", "Strength") and s.is_linked]
    if linked:
        return None, f"node tree ({' and '.join(linked)} of the Emission node not constant)"
    return node, None


def color_terms(data, channel):
    """The light-data paths whose product is channel ``channel`` of the light's colour (the factor 0 when its
    node tree emits nothing)."""
    terms = [f"color[{channel}]"]
    if getattr(data, "use_temperature", False):
        terms.append(f"temperature_color[{channel}]")
    node, problem = emission_node(data)
    if node is not None:
        path = f'node_tree.nodes["{bpy.utils.escape_identifier(node.name)}"].inputs'
        terms += [f'{path}[{_socket_index(node, "Color")}].default_value[{channel}]',
                  f'{path}[{_socket_index(node, "Strength")}].default_value']
    elif problem == "node tree emits nothing":
        terms.append(None)                       # the constant 0
    return terms


def _socket_index(node, name):
    return next(i for i, s in enumerate(node.inputs) if s.name == name)


def color_record(data):
    """What the colour drivers are built from (part of the light signature: when it changes, the drivers are
    rebuilt): temperature on or off, the node tree's Emission node or its problem."""
    node, problem = emission_node(data)
    return (f"{'T' if getattr(data, 'use_temperature', False) else ''}"
            f"{'E=' + node.name if node is not None else problem or ''}")


# --- drivers and their values -----------------------------------------------------------------------------------

def _matrix_terms():
    return [(f"m{r}{c}", f"matrix_world[{c}][{r}]") for r in range(3) for c in range(3)]


#: The 3 x 3 determinant of matrix_world's entries m<row><column>, as a simple expression.
DETERMINANT_EXPRESSION = "m00*(m11*m22-m12*m21)-m01*(m10*m22-m12*m20)+m02*(m10*m21-m11*m20)"


def add_light_driver(socket, obj, source):
    """A driver on ``socket.default_value`` delivering ``source`` (``core.lights.driver_sources``) of the light
    object ``obj``."""
    kind, what = source
    if kind == "transform":
        return add_expression_driver(socket, "var", [("var", "transform", obj, what)])
    if kind == "data":
        return add_expression_driver(socket, "var", [("var", "LIGHT", obj.data, what)])
    if kind == "determinant":
        return add_expression_driver(socket, DETERMINANT_EXPRESSION,
                                     [(name, "OBJECT", obj, path) for name, path in _matrix_terms()])
    if kind == "color":
        terms = color_terms(obj.data, what)
        if None in terms:
            return add_expression_driver(socket, "0.0 * c0", [("c0", "LIGHT", obj.data, terms[0])])
        variables = [(f"c{i}", "LIGHT", obj.data, path) for i, path in enumerate(terms)]
        return add_expression_driver(socket, " * ".join(name for name, *_ in variables), variables)
    raise ValueError(f"{obj.name}: no driver for {source!r}")


def static_value(obj, source):
    """The value ``add_light_driver``'s driver computes for ``source`` now (what the numpy evaluation, the tests
    and the exports read)."""
    kind, what = source
    m = obj.matrix_world
    if kind == "transform":
        loc, rot, _ = m.decompose()
        axis = what[-1]
        if what.startswith("LOC_"):
            return loc["XYZ".index(axis)]
        if what.startswith("ROT_"):
            return rot["WXYZ".index(axis)]
        return m.col["XYZ".index(axis)].to_3d().length          # TRANSFORMS: the column's length
    if kind == "data":
        return float(obj.data.path_resolve(what))
    if kind == "determinant":
        return m.to_3x3().determinant()
    if kind == "color":
        value = 1.0
        for path in color_terms(obj.data, what):
            value *= 0.0 if path is None else float(obj.data.path_resolve(path))
        return value
    if kind == "excluded":
        return 0.0
    raise ValueError(f"{obj.name}: no value for {source!r}")


def light_parameters(obj, kind, receiver=None):
    """The values the drivers of ``obj`` deliver (parameter name -> float), for numpy evaluation; "Excluded", the
    linking option's per-object value, for the object ``receiver`` (``excluded_value``; 0 without one)."""
    out = {p: float(static_value(obj, src)) for p, src in core_lights.driver_sources(kind, shape(obj)).items()}
    if "Excluded" in out and receiver is not None:
        out["Excluded"] = excluded_value(obj, receiver)
    return out


# --- what RT Lit does not shade ---------------------------------------------------------------------------------

def unshaded_settings(obj, kind):
    """The settings of a light RT Lit does not shade, as short phrases ("node tree (...)", ...)."""
    data = obj.data
    out = []
    _, problem = emission_node(data)
    if problem is not None and problem != "node tree emits nothing":
        out.append(problem)
    base = core_lights.base_kind(kind)
    if base == "quad_spot" and data.spread < FULL_SPREAD:
        out.append(f"spread {math.degrees(data.spread):.0f} deg (with the spot fallback)")
    hidden = [ray for ray, attr in (("diffuse", "visible_diffuse"), ("glossy", "visible_glossy"))
              if not getattr(obj, attr, True)]
    if hidden:
        out.append(f"{' and '.join(hidden)} ray visibility off")
    return out


# --- light linking --------------------------------------------------------------------------------------------

def link_states(collection):
    """{object pointer: (object, "INCLUDE" or "EXCLUDE")} of a light-linking ``collection`` as Blender reads it
    (source/blender/depsgraph/intern/depsgraph_light_linking.cc): an object of a child collection, at any depth,
    has that child's state, an object of the collection itself its own; a later entry wins, the collection's own
    objects coming after its children."""
    states = {}
    for child, entry in zip(collection.children, collection.collection_children):
        for obj in child.all_objects:
            states[obj.as_pointer()] = (obj, entry.light_linking.link_state)
    for obj, entry in zip(collection.objects, collection.collection_objects):
        states[obj.as_pointer()] = (obj, entry.light_linking.link_state)
    return states


def receives(light_obj, obj, states=None):
    """Whether ``obj`` receives ``light_obj``'s light under light linking (measured with Cycles): every object
    when the light has no receiver collection or an empty one; when the collection includes something, only the
    objects it includes; otherwise all but the ones it excludes.  ``states``: ``link_states`` of the collection,
    when the caller has them."""
    collection = light_obj.light_linking.receiver_collection
    if collection is None:
        return True
    states = link_states(collection) if states is None else states
    entry = states.get(obj.as_pointer())
    if entry is not None:
        return entry[1] == "INCLUDE"
    return not any(state == "INCLUDE" for _, state in states.values())


def linking_mode(light_obj):
    """"include" when the light's receiver collection includes something (only those objects receive it),
    "exclude" otherwise (all but the excluded ones), None without a receiver collection."""
    collection = light_obj.light_linking.receiver_collection
    if collection is None:
        return None
    return "include" if any(state == "INCLUDE" for _, state in link_states(collection).values()) else "exclude"


def linking_attribute(light_obj, mode):
    """The object attribute that marks the objects of ``light_obj``'s receiver collection in ``mode``: 1 on the
    objects it includes ("rtl_included_<light>", include mode) or excludes ("rtl_excluded_<light>").  An object
    without it (a new one) is then what Blender makes of it: excluded in include mode, lit otherwise."""
    return f"{INCLUDED_PREFIX if mode == 'include' else EXCLUDED_PREFIX}{light_obj.name}"


def is_inverted(attribute):
    """Whether the "Excluded" input reads 1 - ``attribute`` (an include-mode attribute)."""
    return attribute.startswith(INCLUDED_PREFIX)


def linking_record(records):
    """For each linked light of ``records`` [(object, kind)]: its name, mode and the objects its collection
    marks (part of the light signature: a change re-syncs the attributes and the trees)."""
    out = []
    for light_obj, kind in records:
        if "linking" in core_lights.split_kind(kind)[1]:
            mode = linking_mode(light_obj)
            marked = sorted(o.name for o, state in link_states(light_obj.light_linking.receiver_collection).values()
                            if state == _MARKED_STATE[mode])
            out.append(f"{light_obj.name}:{mode}:{','.join(marked)}")
    return out


def linking_attributes(records):
    """{light name: (attribute, inverted)} of the linked lights of ``records``: the Attribute node that feeds the
    light's "Excluded" input reads ``attribute``, through 1 - x when ``inverted`` (include mode)."""
    out = {}
    for light_obj, kind in records:
        if "linking" in core_lights.split_kind(kind)[1]:
            mode = linking_mode(light_obj)
            attribute = linking_attribute(light_obj, mode)
            out[light_obj.name] = (attribute, is_inverted(attribute))
    return out


def sync_linking(objects, records):
    """Write the ``linking_attribute`` of every linked light of ``records`` on the objects its receiver collection
    marks, and remove the linking attributes of ``objects`` that no light asks for any more."""
    wanted = {}
    for light_obj, kind in records:
        if "linking" in core_lights.split_kind(kind)[1]:
            mode = linking_mode(light_obj)
            name = linking_attribute(light_obj, mode)
            for obj, state in link_states(light_obj.light_linking.receiver_collection).values():
                if state == _MARKED_STATE[mode]:
                    wanted.setdefault(obj.as_pointer(), (obj, set()))[1].add(name)
    for obj in objects:
        keep = wanted.get(obj.as_pointer(), (obj, set()))[1]
        for key in [k for k in obj.keys() if k.startswith((EXCLUDED_PREFIX, INCLUDED_PREFIX)) and k not in keep]:
            del obj[key]
    for obj, names in wanted.values():
        for name in names:
            if obj.get(name) != 1.0:
                obj[name] = 1.0


def excluded_value(light_obj, obj):
    """The "Excluded" input of ``light_obj`` on ``obj``: 1 when light linking keeps it from ``obj``."""
    return 0.0 if receives(light_obj, obj) else 1.0
