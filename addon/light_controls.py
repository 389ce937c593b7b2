"""The talk's light controls on Blender lights (issue 17, item 4): a range with the windowed falloff, a cone
falloff measured at the projector apex behind an area light, and the quad-to-spot fallback as a level of detail.

Storage.  The controls are custom properties of the light data ("rtl_range", ...), shown and edited through
properties registered on ``bpy.types.Light`` (``PROPERTIES``) whose get / set read and write them (Blender 5
keeps Python-defined properties apart from custom properties, so a plain registered property would not be
readable by a driver path).  The drivers of "RTL Scene Lights" read the numbers through the paths
'["rtl_range"]', '["rtl_cone_inner"]', '["rtl_cone_outer"]' (core/lights.py ``driver_sources``): simple-expression
drivers, which evaluate with Python auto-run off and even without the extension (docs/blender.md, "Drivers").
A custom property exists only once written, so the values the drivers read are written when the lights are
synced (``store_driven_values``).

Which controls are on is structural: it is part of the light's kind ("quad+cone+range", "quad_spot+range":
``core.lights.split_kind``), so switching one changes the scene's light signature and the RT Lit groups are
rebuilt (by the automatic light sync, addon/light_sync.py, or Sync Lights).  A light without controls carries
none of their nodes.
"""
from __future__ import annotations

import math

import bpy
from bpy.props import BoolProperty, FloatProperty

from ..core import lights as core_lights

def _tag(self, context):
    """A custom property written by a setter is no depsgraph update by itself: tag the light, so the drivers that
    read it and the automatic light sync (addon/light_sync.py) see the change."""
    self.update_tag()


def _stored(name, default, kind):
    """get / set of a control kept in the light's custom property ``name`` (the property itself stores nothing)."""
    def get(self):
        return kind(self.get(name, default))

    def set_value(self, v):
        self[name] = kind(v)
    return {"get": get, "set": set_value, "update": _tag}


_DEFAULTS = {"rtl_use_range": False, "rtl_range": 10.0, "rtl_use_cone": False, "rtl_cone_inner": math.radians(90.0),
             "rtl_cone_outer": math.radians(100.0), "rtl_spot_fallback": False}

PROPERTIES = {
    "rtl_use_range": BoolProperty(
        name="Range", **_stored("rtl_use_range", False, bool),
        description="Fade the light to 0 at its range with the windowed falloff saturate(1 - (d/r)^4)^2 (Karis 2013; "
                    "the talk's epilogue): RT Lit only, Cycles and EEVEE's own lights are unchanged"),
    "rtl_range": FloatProperty(
        name="Range", min=0.0, soft_max=100.0, subtype='DISTANCE', unit='LENGTH',
        **_stored("rtl_range", _DEFAULTS["rtl_range"], float),
        description="Distance from the light's location at which RT Lit's shading of it reaches 0"),
    "rtl_use_cone": BoolProperty(
        name="Cone", **_stored("rtl_use_cone", False, bool),
        description="Cone falloff between the inner and outer angles, measured at the projector apex behind the "
                    "area light, (d/2)/tan(outer/2) behind it so the cone fits around the light (the talk's epilogue)"),
    "rtl_cone_inner": FloatProperty(
        name="Inner Angle", min=0.0, max=math.pi, subtype='ANGLE',
        **_stored("rtl_cone_inner", _DEFAULTS["rtl_cone_inner"], float),
        description="Full cone angle inside which the light is not attenuated"),
    "rtl_cone_outer": FloatProperty(
        name="Outer Angle", min=0.0, max=math.pi, subtype='ANGLE',
        **_stored("rtl_cone_outer", _DEFAULTS["rtl_cone_outer"], float),
        description="Full cone angle outside which the light is 0; it places the projector apex"),
    "rtl_spot_fallback": BoolProperty(
        name="Shade as Spot", **_stored("rtl_spot_fallback", False, bool),
        description="Level of detail: shade this quad light as a spot light at its projector apex, with the cone "
                    "falloff (the talk's quad-to-spot fallback): cheaper, and exact in the far field"),
}
#: The options of core.lights.LIGHT_OPTIONS these controls switch (the others follow Blender's own settings:
#: addon/light_model.py).
CONTROL_OPTIONS = ("cone", "range")
#: The properties the drivers read (the others choose the light's kind).
DRIVEN = ("rtl_range", "rtl_cone_inner", "rtl_cone_outer")


def value(data, name):
    """A control's value on light data: its custom property, else the default (whether or not the properties are
    registered: they only show and edit the custom properties)."""
    return data.get(name, _DEFAULTS[name])


def light_kind(data, base):
    """The RT Lit kind of a light whose base kind is ``base``, with its controls: "quad+cone+range",
    "quad_spot+range", or ``base`` itself with none on."""
    if base == "quad" and value(data, "rtl_spot_fallback"):
        base = "quad_spot"
    options = [o for o in CONTROL_OPTIONS if value(data, f"rtl_use_{o}") and base in core_lights.OPTION_KINDS[o]]
    return core_lights.kind_name(base, options)


def store_driven_values(data):
    """Write the driven controls as custom properties of ``data`` (the drivers' paths need them stored)."""
    for name in DRIVEN:
        data[name] = float(value(data, name))


def register():
    for name, prop in PROPERTIES.items():
        setattr(bpy.types.Light, name, prop)


def unregister():
    for name in PROPERTIES:
        if hasattr(bpy.types.Light, name):
            delattr(bpy.types.Light, name)

