"""Blender's lights as the RT Lit material sees them: geometry and light units, one source for
numpy and node groups.

Every function is written with ``core.shading_ops`` and Python operators only, so it computes on
numpy arrays (vectors are (..., 3) arrays) and traces into IR expressions (``core.ir``) that the
node backend emits as node groups.  The inputs are what drivers deliver: a light object's
world-space location, rotation as a unit quaternion (w, x, y, z) and scale (a TRANSFORMS driver
in world space, quaternion mode: mat4_decompose of ``matrix_world``), and the light data
(``energy``, ``color``, ``size``, ``size_y``, ``spot_size``, ``spot_blend``).

Cycles 5.0 conventions (source: blender/blender ``intern/cycles``; measured with the bpy 5.0.1
module in tests/blender/test_light_units.py; see docs/blender.md, "Cycles light units"):

- Strength.  The Blender sync (``blender/light.cpp: sync_light``) sets the light's strength to
  ``color * energy`` (energy = Power P in W for point, spot and area lights, Strength S in W/m^2
  for the sun).  We assume ``exposure = 0``, ``normalize = True`` and ``use_temperature = False``
  (otherwise a driver must deliver ``energy * 2**exposure`` and ``color * temperature_color``).
- Area light (``scene/light.cpp``: ``Light::area``, ``device_update_lights``;
  ``kernel/light/area.h``): a one-sided emitter, centred on the object origin, spanning
  ``size`` along the object's X column and ``size_y`` (SQUARE and DISK: ``size``) along its Y
  column, emitting towards ``-Z`` (``dir = -column 2``).  Its area includes the object scale,
  A = |X| size |Y| size_y (times pi/4 for DISK and ELLIPSE), and the emitted radiance is
  uniform and Lambertian: L = P color / (pi A) (so that the flux pi L A = P).  The kernel's
  factor is ``eval_fac = invarea / 4`` (area.h); where the remaining 4/pi is applied we did not
  trace: the end-to-end value is measured, within 0.015% at 256 spp for all four shapes, a
  rotated and non-uniformly scaled rectangle and ellipse included.
  A light of zero area does not contribute in Cycles (``Light::has_contribution``); here the
  radiance is 0 (never Inf/NaN).  ``spread`` is assumed to be 180 degrees (the default).
- Point light (``scene/light.cpp``: the area of a radius-0 point or spot light is taken as 4, and
  ``eval_fac = invarea / pi``, i.e. 1/(4 pi); for radius 0 the kernel divides by the squared
  distance, "intensity instead of radiance", ``kernel/light/spot.h``): radiant intensity
  I = P color / (4 pi) W/sr, isotropic, independent of the object scale (measured to 1e-5).
- Spot light (``kernel/light/spot.h``): the point light's intensity P color / (4 pi) inside the
  cone (Blender does not renormalise by the cone's solid angle; measured), times the cone
  attenuation ``spot_light_attenuation``: with the direction from the light to the shading point
  expressed in the light object's local frame (the inverse of its rotation and scale applied, so
  a non-uniformly scaled spot has an elliptical cone), normalised, and c its component along the
  local -Z axis, the attenuation is smoothstep((c - cos(spot_size / 2)) /
  ((1 - cos(spot_size / 2)) spot_blend)), with smoothstep(t) = 3t^2 - 2t^3 on [0, 1], 0 below
  and 1 above (``util/math_base.h: smoothstepf``; the factor 1 / ((1 - cos_half) blend) is
  ``spot_smooth`` in ``scene/light.cpp``).  So the edge of the cone is at half-angle
  spot_size / 2 and the blend region spans, in cosine, the fraction ``spot_blend`` of
  [cos(spot_size / 2), 1].  ``use_square`` is not supported.
- Sun (``scene/light.cpp``: ``eval_fac = 1 / area`` with area 1 for angle 0;
  ``kernel/light/distant.h``): irradiance S color W/m^2 at normal incidence, arriving along the
  light's -Z axis, i.e. the direction to the light is its +Z axis; location and scale do not
  matter.

RT Lit treats point and spot lights as radius 0 (``shadow_soft_size = 0``) and the sun as angle 0:
the functions below describe exactly those lights, and the validation renders set them so.

Area-light geometry follows the repository's LTC convention (core/ltc/polygon.py,
docs/conventions.md): quad corners p0..p3 are ordered so that (p1 - p0) x (p3 - p0) points
away from the lit side (counter-clockwise around the light's local +Z), disk semi-axes so that
axis_u x axis_v does.  Negative (mirroring) scales are not supported.
"""
from __future__ import annotations

import functools
import math

import numpy as np

from . import shading_ops as op
from . import falloff
from .falloff import MIN_DISTANCE
from .ir.functions import NodeFunction
from .ir.interface import Socket, scalar, vector

#: Smallest world-space area light area (m^2) that emits; smaller areas (0 size or 0 scale) give
#: radiance 0, so P / (pi A) can neither divide by zero nor overflow float32.
AREA_MIN = 1e-20
#: Smallest denominator (1 - cos(spot_size/2)) * spot_blend of the spot blend ramp: a blend of 0
#: gives a hard edge (Cycles divides by 0 there).
SPOT_SMOOTH_EPS = 1e-20

_EX, _EY, _EZ = np.eye(3)
_INV_PI = 1.0 / np.pi
_INV_4PI = 0.25 / np.pi


# --- transforms ----------------------------------------------------------------------------------

# Rotation of v by the unit quaternion q = (w, u): v' = v + w t + u x t with t = 2 u x v (the
# expansion of q v q*; Rodrigues' formula in quaternion form).
def quat_rotate(w, x, y, z, vec):
    """``vec`` rotated by the unit quaternion (w, x, y, z) (Blender's order, as ROT_W..ROT_Z)."""
    u = op.vec3(x, y, z)
    t = op.cross(u, vec) * 2.0
    # the traced operand first: a numpy constant on the left of + would broadcast over an Expr
    return op.scale(t, w) + op.cross(u, t) + vec


def light_frame(location, w, x, y, z, scale_x, scale_y, scale_z):
    """World-space origin and axes of a light object: (origin, X, Y, Z), the columns of its world
    matrix (rotation times scale); Z is the local +Z axis (area, spot and sun lights emit along -Z)."""
    return (location,
            op.scale(quat_rotate(w, x, y, z, _EX), scale_x),
            op.scale(quat_rotate(w, x, y, z, _EY), scale_y),
            op.scale(quat_rotate(w, x, y, z, _EZ), scale_z))


# --- area lights --------------------------------------------------------------------------------

def area_light_radiance(power, color, area):
    """Emitted radiance L = P color / (pi A) of a Blender area light of world-space area A (m^2);
    0 for A <= AREA_MIN."""
    lum = op.select(op.greater(area, AREA_MIN), op.safe_div(power * _INV_PI, area), 0.0)
    return op.scale(color, lum)


def area_light_quad(location, w, x, y, z, scale_x, scale_y, scale_z, power, color, size, size_y):
    """World corners (p0, p1, p2, p3) and radiance of a SQUARE / RECTANGLE area light.

    ``size_y`` is the light's Y extent: pass ``size`` for SQUARE.  The corners are
    (-u, -v), (+u, -v), (+u, +v), (-u, +v) in the light's local XY plane (u = size/2, v = size_y/2),
    so (p1 - p0) x (p3 - p0) points along local +Z, away from the lit side.  ``scale_z`` does not
    matter (it is taken for a signature common to all lights' transforms)."""
    half_u = scale_x * size * 0.5
    half_v = scale_y * size_y * 0.5
    eu = op.scale(quat_rotate(w, x, y, z, _EX), half_u)
    ev = op.scale(quat_rotate(w, x, y, z, _EY), half_v)
    low, high = location - eu, location + eu
    corners = (low - ev, high - ev, high + ev, low + ev)
    area = op.absolute(half_u * half_v) * 4.0
    return corners + (area_light_radiance(power, color, area),)


def area_light_disk(location, w, x, y, z, scale_x, scale_y, scale_z, power, color, size, size_y):
    """Centre, semi-axis vectors (axis_u, axis_v) and radiance of a DISK / ELLIPSE area light.

    ``size_y`` is the light's Y diameter: pass ``size`` for DISK.  axis_u x axis_v points along
    local +Z, away from the lit side."""
    half_u = scale_x * size * 0.5
    half_v = scale_y * size_y * 0.5
    axis_u = op.scale(quat_rotate(w, x, y, z, _EX), half_u)
    axis_v = op.scale(quat_rotate(w, x, y, z, _EY), half_v)
    area = op.absolute(half_u * half_v) * np.pi
    return location, axis_u, axis_v, area_light_radiance(power, color, area)


def area_light(shape, location, w, x, y, z, scale_x, scale_y, scale_z, power, color, size, size_y):
    """``area_light_quad`` or ``area_light_disk`` by Blender's ``shape`` (a build-time string):
    SQUARE and DISK use ``size`` for both extents, as Cycles does."""
    if shape not in ("SQUARE", "RECTANGLE", "DISK", "ELLIPSE"):
        raise ValueError(f"unknown area light shape {shape!r}")
    fn = area_light_quad if shape in ("SQUARE", "RECTANGLE") else area_light_disk
    return fn(location, w, x, y, z, scale_x, scale_y, scale_z, power, color, size,
              size if shape in ("SQUARE", "DISK") else size_y)


# --- point, spot and sun ------------------------------------------------------------------------

def point_light_intensity(power, color):
    """Radiant intensity I = P color / (4 pi) (W/sr) of a radius-0 point or spot light."""
    return op.scale(color, power * _INV_4PI)


def _towards(position, location):
    """Unit direction l from the shading point to the light and the clamped inverse square law."""
    d = location - position
    dist2 = op.maximum(op.dot(d, d), MIN_DISTANCE * MIN_DISTANCE)
    return op.normalize(d), 1.0 / dist2


def point_light_incidence(position, location, power, color):
    """(l, E): unit direction to a radius-0 point light and the irradiance at normal incidence
    E = I / max(d^2, MIN_DISTANCE^2) (W/m^2, colour; the cosine is not included).  At the light
    itself l = 0 and E is finite."""
    l, inv_d2 = _towards(position, location)
    return l, op.scale(point_light_intensity(power, color), inv_d2)


def smoothstep(t):
    """3t^2 - 2t^3 of t clamped to [0, 1] (Cycles ``smoothstepf``)."""
    s = op.saturate(t)
    return s * s * (3.0 - 2.0 * s)


def spot_attenuation(cos_axis, spot_size, spot_blend):
    """Cycles' spot cone attenuation for the cosine ``cos_axis`` between the spot's axis and the
    direction from the light (in the light's unscaled local frame): smoothstep of
    (c - cos(spot_size/2)) / ((1 - cos(spot_size/2)) spot_blend); a hard edge for spot_blend = 0."""
    cos_half = op.cos(spot_size * 0.5)
    width = op.maximum((1.0 - cos_half) * spot_blend, SPOT_SMOOTH_EPS)
    return smoothstep((cos_axis - cos_half) / width)


def spot_cosine(position, location, w, x, y, z, scale_x, scale_y, scale_z):
    """Cosine between the spot axis (local -Z) and the direction from the light to ``position``,
    measured in the light's local frame (inverse rotation, then inverse scale), as Cycles does."""
    # (-w, x, y, z) = -conjugate(q): the inverse rotation, with one negation instead of three
    local = quat_rotate(-w, x, y, z, position - location)
    inv_scale = op.vec3(op.safe_div(1.0, scale_x), op.safe_div(1.0, scale_y), op.safe_div(1.0, scale_z))
    return -op.component(op.normalize(op.vmul(local, inv_scale)), 2)


def spot_light_incidence(position, location, w, x, y, z, scale_x, scale_y, scale_z, power, color,
                         spot_size, spot_blend):
    """(l, E) of a radius-0 spot light: the point light's incidence times the cone attenuation."""
    l, e = point_light_incidence(position, location, power, color)
    c = spot_cosine(position, location, w, x, y, z, scale_x, scale_y, scale_z)
    return l, op.scale(e, spot_attenuation(c, spot_size, spot_blend))


def sun_light_incidence(w, x, y, z, strength, color):
    """(l, E) of an angle-0 sun: l is the light's local +Z axis (it shines along -Z), E = S color."""
    return quat_rotate(w, x, y, z, _EZ), op.scale(color, strength)


# --- node functions -----------------------------------------------------------------------------

_TRANSFORM_PANEL = "Light Transform"
_DATA_PANEL = "Light Data"


def _location_sockets():
    return {f"Location {a}": scalar(0.0, f"World-space location {a} of the light object (driver: "
                                         f"Transform Channel LOC_{a}, world space)", subtype="DISTANCE",
                                    panel=_TRANSFORM_PANEL) for a in "XYZ"}


def _rotation_sockets():
    return {f"Rotation {a}": scalar(1.0 if a == "W" else 0.0,
                                    f"World-space rotation quaternion {a} of the light object (driver: "
                                    f"Transform Channel ROT_{a}, quaternion mode, world space)",
                                    -1.0, 1.0, panel=_TRANSFORM_PANEL) for a in "WXYZ"}


def _scale_sockets():
    return {f"Scale {a}": scalar(1.0, f"World-space scale {a} of the light object (driver: Transform "
                                      f"Channel SCALE_{a}, world space)", panel=_TRANSFORM_PANEL)
            for a in "XYZ"}


def _color_sockets():
    return {f"Color {c}": scalar(1.0, f"Light colour, {name} channel (light data color[{i}])", 0.0, None,
                                 panel=_DATA_PANEL)
            for i, (c, name) in enumerate((("R", "red"), ("G", "green"), ("B", "blue")))}


def _power_socket(what):
    return {"Power": scalar(1000.0, f"{what} power P in W (light data energy)", 0.0, None,
                            panel=_DATA_PANEL)}


def _size_sockets(shape):
    return {"Size": scalar(1.0, f"{shape} size along the light's X axis in m (light data size)", 0.0, None,
                           subtype="DISTANCE", panel=_DATA_PANEL),
            "Size Y": scalar(1.0, f"{shape} size along the light's Y axis in m (light data size_y; "
                                  f"drive it from size for a {'SQUARE' if shape == 'Quad' else 'DISK'} light)",
                             0.0, None, subtype="DISTANCE", panel=_DATA_PANEL)}


_POSITION = {"Position": vector("Shading point (world space)", "NONE", hide_value=True)}
_RADIANCE = Socket("color", (0.0, 0.0, 0.0, 1.0),
                   description="Emitted radiance L = P color / (pi A), W/(m^2 sr)")
_L = Socket("vector", (0.0, 0.0, 1.0), subtype="DIRECTION",
            description="Unit direction from the shading point to the light (world space)")
_IRRADIANCE = Socket("color", (0.0, 0.0, 0.0, 1.0),
                     description="Irradiance at normal incidence, W/m^2 times colour (no cosine)")


def _loc(kw):
    return op.vec3(kw["Location X"], kw["Location Y"], kw["Location Z"])


def _rot(kw):
    return kw["Rotation W"], kw["Rotation X"], kw["Rotation Y"], kw["Rotation Z"]


def _scl(kw):
    return kw["Scale X"], kw["Scale Y"], kw["Scale Z"]


def _col(kw):
    return op.vec3(kw["Color R"], kw["Color G"], kw["Color B"])


def _quad_node(**kw):
    p0, p1, p2, p3, radiance = area_light_quad(_loc(kw), *_rot(kw), *_scl(kw), kw["Power"], _col(kw),
                                               kw["Size"], kw["Size Y"])
    return {"p0": p0, "p1": p1, "p2": p2, "p3": p3, "Center": _loc(kw), "Radiance": radiance}


def _disk_node(**kw):
    center, axis_u, axis_v, radiance = area_light_disk(_loc(kw), *_rot(kw), *_scl(kw), kw["Power"], _col(kw),
                                                       kw["Size"], kw["Size Y"])
    return {"Center": center, "Axis U": axis_u, "Axis V": axis_v, "Radiance": radiance}


def _point_node(**kw):
    l, e = point_light_incidence(kw["Position"], _loc(kw), kw["Power"], _col(kw))
    return {"L": l, "Irradiance": e}


def _spot_node(**kw):
    l, e = spot_light_incidence(kw["Position"], _loc(kw), *_rot(kw), *_scl(kw), kw["Power"], _col(kw),
                                kw["Spot Size"], kw["Spot Blend"])
    return {"L": l, "Irradiance": e}


def _sun_node(**kw):
    l, e = sun_light_incidence(*_rot(kw), kw["Strength"], _col(kw))
    return {"L": l, "Irradiance": e}


def _corner(i):
    return vector(f"World-space corner {i}; (p1 - p0) x (p3 - p0) points away from the lit side",
                  "XYZ", hide_value=True)


AREA_LIGHT_QUAD = NodeFunction(
    "RTL Area Light Quad", _quad_node,
    {**_location_sockets(), **_rotation_sockets(), **_scale_sockets(), **_power_socket("Area light"),
     **_color_sockets(), **_size_sockets("Quad")},
    {**{f"p{i}": _corner(i) for i in range(4)},
     "Center": vector("World-space centre (the light's location): the side the shading point is on is taken from "
                      "it, which the corners of a light much larger than its distance round away", "XYZ",
                      hide_value=True),
     "Radiance": _RADIANCE},
    "A SQUARE or RECTANGLE Blender area light: world corners and emitted radiance (Cycles units)")

AREA_LIGHT_DISK = NodeFunction(
    "RTL Area Light Disk", _disk_node,
    {**_location_sockets(), **_rotation_sockets(), **_scale_sockets(), **_power_socket("Area light"),
     **_color_sockets(), **_size_sockets("Disk")},
    {"Center": vector("World-space centre of the disk or ellipse", "XYZ", hide_value=True),
     "Axis U": vector("Semi-axis along the light's X axis; Axis U x Axis V points away from the lit side",
                      "XYZ", hide_value=True),
     "Axis V": vector("Semi-axis along the light's Y axis", "XYZ", hide_value=True),
     "Radiance": _RADIANCE},
    "A DISK or ELLIPSE Blender area light: centre, semi-axes and emitted radiance (Cycles units)")

POINT_LIGHT = NodeFunction(
    "RTL Point Light", _point_node,
    {**_location_sockets(), **_power_socket("Point light"), **_color_sockets(), **_POSITION},
    {"L": _L, "Irradiance": _IRRADIANCE},
    "A radius-0 Blender point light: I = P color / (4 pi), irradiance I / d^2 (d >= 1 cm)")

SPOT_LIGHT = NodeFunction(
    "RTL Spot Light", _spot_node,
    {**_location_sockets(), **_rotation_sockets(), **_scale_sockets(), **_power_socket("Spot light"),
     **_color_sockets(),
     "Spot Size": scalar(np.pi / 4, "Full cone angle (light data spot_size)", 0.0, np.pi, subtype="ANGLE",
                         panel=_DATA_PANEL),
     "Spot Blend": scalar(0.15, "Softness of the cone edge (light data spot_blend)", 0.0, 1.0,
                          subtype="FACTOR", panel=_DATA_PANEL),
     **_POSITION},
    {"L": _L, "Irradiance": _IRRADIANCE},
    "A radius-0 Blender spot light: the point light's intensity times Cycles' cone attenuation")

SUN_LIGHT = NodeFunction(
    "RTL Sun Light", _sun_node,
    {**_rotation_sockets(), **{"Strength": scalar(1.0, "Sun strength S: irradiance in W/m^2 (light data "
                                                       "energy)", 0.0, None, panel=_DATA_PANEL)},
     **_color_sockets()},
    {"L": _L, "Irradiance": _IRRADIANCE},
    "An angle-0 Blender sun: direction to the sun (its +Z axis) and irradiance S color")

# --- the talk's epilogue: light controls ---------------------------------------------------------------
# "Control over performance: radius falloff, cone angle falloff; fall back to point lights: omni or spot light."
# Area lights get a cone whose apex sits behind the light at the projector distance p = (d/2)/tan(phi/2) (d the
# light's diameter, phi the outer angle), so that the cone fits around the light; the cone falloff is measured
# at that apex, for the area light and for its spot fallback alike (the talk: "use cone apex for cone angle fall
# off for spot and quad light").  The windowed range multiplies any light but the sun.

def area_light_diameter(scale_x, scale_y, size, size_y, shape):
    """Diameter of the circle around the light seen along its axis: a quad's diagonal, an ellipse's major axis."""
    dx, dy = op.absolute(scale_x * size), op.absolute(scale_y * size_y)
    if shape == "quad":
        return op.sqrt(dx * dx + dy * dy)
    return op.maximum(dx, dy)


def projector_apex(location, w, x, y, z, scale_x, scale_y, size, size_y, outer_angle, shape):
    """(apex, emission axis): the talk's projector point behind an area light, p = (d/2)/tan(phi/2) behind its
    centre (``falloff.projector_distance``), and the unit direction the light emits along (its local -Z)."""
    axis = op.scale(quat_rotate(w, x, y, z, _EZ), -1.0)
    p = falloff.projector_distance(area_light_diameter(scale_x, scale_y, size, size_y, shape), outer_angle)
    return location - op.scale(axis, p), axis


def apex_cone_falloff(position, apex, axis, inner_angle, outer_angle):
    """The talk's cone falloff at the projector apex for a shading point (``falloff.cone_falloff``)."""
    return falloff.cone_falloff(op.dot(op.normalize(position - apex), axis), inner_angle, outer_angle)


def range_falloff(position, location, radius):
    """Karis 2013's window saturate(1 - (d/r)^4)^2 on the distance to the light's location."""
    d = position - location
    return falloff.window_falloff(op.sqrt(op.dot(d, d)), radius)


def quad_spot_incidence(position, location, w, x, y, z, scale_x, scale_y, scale_z, power, color, size, size_y,
                        inner_angle, outer_angle):
    """(l, E) of the quad-to-spot fallback: the quad's far field, a point at its centre of intensity
    I(theta) = L A cos(theta) = P color cos(theta) / pi (a Lambertian emitter, theta from its axis), times the talk's
    cone falloff at the projector apex behind the quad; E = I / max(d^2, d_min^2), d from the centre.

    The talk's images show a spot at the apex, which emits the same intensity in every direction of its cone: it
    misses the quad's cosine, by 29-89% (median) on a floor under the talk's angle pairs, and converges to nothing
    with distance; a spot at the apex with the cosine converges as the apex offset over the distance (10% at one
    light size, 1% at ten); at the centre it is the quad's far field, 2.5% at two light diameters, 0.3% at six
    (docs/benchmarks/light_fallback.md)."""
    apex, axis = projector_apex(location, w, x, y, z, scale_x, scale_y, size, size_y, outer_angle, "quad")
    l, inv_d2 = _towards(position, location)
    emission = op.maximum(-op.dot(l, axis), 0.0)
    cone = apex_cone_falloff(position, apex, axis, inner_angle, outer_angle)
    return l, op.scale(color, power * _INV_PI * inv_d2 * emission * cone)


def _quad_spot_node(**kw):
    l, e = quad_spot_incidence(kw["Position"], _loc(kw), *_rot(kw), *_scl(kw), kw["Power"], _col(kw), kw["Size"],
                               kw["Size Y"], kw["Cone Inner"], kw["Cone Outer"])
    return {"L": l, "Irradiance": e}


def _cone_sockets():
    return {"Cone Inner": scalar(math.radians(90.0), "Inner full cone angle theta at the projector apex (light data "
                                 "rtl_cone_inner)", 0.0, math.pi, subtype="ANGLE", panel=_DATA_PANEL),
            "Cone Outer": scalar(math.radians(100.0), "Outer full cone angle phi at the projector apex; the apex sits "
                                 "(d/2)/tan(phi/2) behind the light (light data rtl_cone_outer)", 0.0, math.pi,
                                 subtype="ANGLE", panel=_DATA_PANEL)}


QUAD_SPOT_LIGHT = NodeFunction(
    "RTL Quad Spot Fallback Light", _quad_spot_node,
    {**_location_sockets(), **_rotation_sockets(), **_scale_sockets(), **_power_socket("Area light"),
     **_color_sockets(), **_size_sockets("Quad"), **_cone_sockets(), **_POSITION},
    {"L": _L, "Irradiance": _IRRADIANCE},
    "The talk's quad-to-spot fallback: the quad's far field, P color cos / pi from its centre, with the cone falloff "
    "at the projector apex")

NODE_FUNCTIONS = (AREA_LIGHT_QUAD, AREA_LIGHT_DISK, POINT_LIGHT, SPOT_LIGHT, SUN_LIGHT, QUAD_SPOT_LIGHT)

#: RT Lit light kind -> the node function that turns driver values into light geometry.
LIGHT_DATA = {"quad": AREA_LIGHT_QUAD, "disk": AREA_LIGHT_DISK, "point": POINT_LIGHT, "spot": SPOT_LIGHT,
              "sun": SUN_LIGHT, "quad_spot": QUAD_SPOT_LIGHT}

#: Build-time options of a light kind ("quad+range", "disk+cone+range"): each adds its falloff, and its driver
#: inputs, to the light's data function (``light_data``); a light without them carries no node of them.
LIGHT_OPTIONS = ("cone", "range")
#: The base kinds each option applies to (quad_spot has its cone built in; the sun has no distance).
OPTION_KINDS = {"cone": ("quad", "disk"), "range": ("quad", "disk", "point", "spot", "quad_spot")}
_OPTION_SEPARATOR = "+"


def split_kind(kind):
    """("quad", ("cone", "range")) from "quad+cone+range"; ValueError for an unknown kind or option."""
    base, *options = kind.split(_OPTION_SEPARATOR)
    if base not in LIGHT_DATA:
        raise ValueError(f"unknown light kind {base!r} (known: {', '.join(LIGHT_DATA)})")
    for option in options:
        if option not in LIGHT_OPTIONS or base not in OPTION_KINDS[option]:
            raise ValueError(f"light kind {base!r} has no option {option!r}")
    if list(options) != sorted(set(options), key=LIGHT_OPTIONS.index):
        raise ValueError(f"{kind!r}: options must be unique and in the order {LIGHT_OPTIONS}")
    return base, tuple(options)


def base_kind(kind):
    """The kind without its options: "quad" for "quad+range"."""
    return split_kind(kind)[0]


def kind_name(base, options=()):
    """The kind string of a base kind with options (in ``LIGHT_OPTIONS`` order, the ones it has)."""
    chosen = [o for o in LIGHT_OPTIONS if o in set(options) and base in OPTION_KINDS[o]]
    return _OPTION_SEPARATOR.join([base] + chosen)


def kind_identifier(kind):
    """``kind`` as an identifier (shader uniform names): "quad_cone_range"."""
    return kind.replace(_OPTION_SEPARATOR, "_")


_RANGE_SOCKET = {"Range": scalar(10.0, "Range r of the windowed falloff saturate(1 - (d/r)^4)^2, d from the light's "
                                       "location (light data rtl_range); r <= 0 turns the light off", 0.0, None,
                                 subtype="DISTANCE", panel=_DATA_PANEL)}


def control_factor(kind, position, params):
    """The falloff the options of ``kind`` apply to the light's colour at ``position`` (1.0 without options);
    ``params``: the light's driver values (``light_data(kind)``'s inputs)."""
    base, options = split_kind(kind)
    factor = 1.0
    if "range" in options:
        factor = range_falloff(position, _loc(params), params["Range"])
    if "cone" in options:
        apex, axis = projector_apex(_loc(params), *_rot(params), params["Scale X"], params["Scale Y"], params["Size"],
                                    params["Size Y"], params["Cone Outer"], base)
        factor = factor * apex_cone_falloff(position, apex, axis, params["Cone Inner"], params["Cone Outer"])
    return factor


def _with_options(base, options):
    data = LIGHT_DATA[base]
    color_name = "Radiance" if "Radiance" in data.output_sockets else "Irradiance"
    kind = kind_name(base, options)

    def body(**kw):
        out = dict(data(**{k: kw[k] for k in data.input_sockets}))
        out[color_name] = op.scale(out[color_name], control_factor(kind, kw["Position"], kw))
        return out

    inputs = dict(data.input_sockets)
    inputs.pop("Position", None)
    if "cone" in options:
        inputs.update(_cone_sockets())
    if "range" in options:
        inputs.update(_RANGE_SOCKET)
    inputs.update(_POSITION)
    words = {"cone": "cone falloff at the projector apex", "range": "windowed range"}
    return NodeFunction(f"{data.name} ({', '.join(options)})", body, inputs, dict(data.output_sockets),
                        f"{data.description}; with the talk's " + " and ".join(words[o] for o in options))


@functools.lru_cache(maxsize=None)
def light_data(kind):
    """The data function of a light kind with its options (``LIGHT_DATA[kind]`` for a kind without)."""
    base, options = split_kind(kind)
    return LIGHT_DATA[base] if not options else _with_options(base, options)


#: The data functions of one light of each kind with every option it takes (what tests check in each backend).
CONTROL_FUNCTIONS = tuple(light_data(kind_name(k, LIGHT_OPTIONS)) for k in ("quad", "disk", "point", "spot", "quad_spot"))

_DATA_PATHS = {"Power": "energy", "Strength": "energy", "Color R": "color[0]", "Color G": "color[1]",
               "Color B": "color[2]", "Size": "size", "Size Y": "size_y", "Spot Size": "spot_size",
               "Spot Blend": "spot_blend",
               # the light controls: custom properties of the light data (addon/light_controls.py registers them)
               "Range": '["rtl_range"]', "Cone Inner": '["rtl_cone_inner"]', "Cone Outer": '["rtl_cone_outer"]'}


def driver_sources(kind, shape=None):
    """Where each input of ``light_data(kind)`` comes from in Blender, as the driver that feeds it:
    ("transform", TRANSFORMS channel in world space) or ("data", light data path).  SQUARE and DISK
    lights have one size: their "Size Y" reads ``size`` too (Cycles ignores size_y for them)."""
    out = {}
    for name in light_data(kind).input_sockets:
        if name == "Position":
            continue
        word, _, axis = name.partition(" ")
        if word in ("Location", "Rotation", "Scale") and len(axis) == 1:
            prefix = {"Location": "LOC_", "Rotation": "ROT_", "Scale": "SCALE_"}[word]
            out[name] = ("transform", prefix + axis)
        elif name == "Size Y" and shape in ("SQUARE", "DISK"):
            out[name] = ("data", "size")
        else:
            out[name] = ("data", _DATA_PATHS[name])
    return out
