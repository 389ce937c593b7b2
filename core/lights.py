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
  ``color * energy * 2^exposure`` (energy = Power P in W for point, spot and area lights, Strength S
  in W/m^2 for the sun), times the blackbody colour of its temperature (RNA ``temperature_color``)
  when ``use_temperature`` is on, and a light node tree multiplies it by its emission; with
  ``normalize`` off the power is not divided by the light's area (``Light::area``).  Here "Color"
  is the product of the colours (the colour, the temperature's, the node tree's constant emission
  colour times its strength: addon/materials.py drives it so), "Exposure" and "Normalize" are
  inputs of every light (``exposure_scale``, ``emitting_area``).  All measured against Cycles in
  tests/blender/test_light_units.py.
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

- Sphere lights (``kernel/light/point.h``, ``spot.h``; ``scene/light.cpp``): a point or spot light of
  radius r > 0 emits the radiance L = P color / (pi 4 pi r^2) (normalize on; ``Light::area`` = 4 pi
  r^2).  With Soft Falloff on (Blender's default; ``is_sphere`` off in Cycles) it is a disk of
  radius r at the light's location that always faces the shading point; with it off, a sphere of
  radius r, whose visible cap subtends the cone of half-angle asin(r/d).  Both are a uniform disk
  facing the point (``facing_disk``): tan(half-angle) = r/d, resp. r / sqrt(d^2 - r^2), so every
  lobe's disk form shades them.  A spot light's cone attenuation multiplies the radiance of each
  direction (Cycles); here it is taken at the direction of the light's centre (and not applied
  inside the sphere, as Cycles does not).
- A sun of angle a > 0 (``kernel/light/distant.h``; ``Light::area`` = pi sin^2(a/2)): a uniform cone
  of half-angle a/2 about its direction, radiance S color / (pi sin^2(a/2)) (normalize on): a disk
  at unit distance facing the point, radius tan(a/2).
- Area-light spread (``kernel/light/area.h``: ``area_light_spread_attenuation``,
  ``area_light_spread_clamp_light``): core/light_spread.py.

Mirrors.  For a world matrix M with a negative determinant (a negative scale, Ctrl+M, a mirrored
parent) the TRANSFORMS drivers deliver the rotation of -M (a proper rotation) and the columns'
lengths as the scale (measured with bpy 5.2: a light scaled (-1, 1, 1) reads scale (1, 1, 1) and a
quaternion of -M), so rotation x scale is -M: the handedness is lost.  Every light whose orientation
matters therefore takes the determinant of its world matrix as the input "Determinant" (a driver
on ``matrix_world``'s nine entries), and its frame is sign(det) x rotation x scale (``light_frame``).
Cycles emits area, spot and sun light along minus M's third column whatever its handedness
(measured: a light mirrored in X or Y still lights the same side, one mirrored in Z the other):
directions here are that column (``light_axis``), and an area light's corners are ordered so that
they wind about it (``_area_axes``), so mirrored lights shade as Cycles'.

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
from . import falloff, light_spread
from .falloff import MIN_DISTANCE
from .ir.functions import NodeFunction
from .ir.interface import Socket, factor, scalar, vector

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


def sign_of(value):
    """-1 where ``value`` < 0, else +1."""
    return op.select(op.less(value, 0.0), -1.0, 1.0)


def light_axis(w, x, y, z, scale_z, determinant=1.0):
    """The unit direction of the light object's local +Z axis in world space (its world matrix's third
    column, normalised): the rotation's Z axis times the signs of the Z scale and of the determinant
    (module docstring, "Mirrors").  Area, spot and sun lights emit along minus this axis (Cycles)."""
    return op.scale(quat_rotate(w, x, y, z, _EZ), sign_of(scale_z * determinant))


def light_frame(location, w, x, y, z, scale_x, scale_y, scale_z, determinant=1.0):
    """World-space origin and axes of a light object: (origin, X, Y, Z), the columns of its world
    matrix, sign(det) x rotation x scale (module docstring, "Mirrors"); Z is the local +Z axis (area,
    spot and sun lights emit along -Z)."""
    h = sign_of(determinant)
    return (location,
            op.scale(quat_rotate(w, x, y, z, _EX), scale_x * h),
            op.scale(quat_rotate(w, x, y, z, _EY), scale_y * h),
            op.scale(quat_rotate(w, x, y, z, _EZ), scale_z * h))


# --- Blender's light units --------------------------------------------------------------------------
# Cycles (blender/light.cpp ``sync_light``; scene/light.cpp ``Light::area``, ``device_update_lights``) scales a
# light's strength by 2^exposure and, with Normalize on, divides it by the light's area: the quad or ellipse
# (world-space), 4 pi r^2 for a sphere light, 4 for a radius-0 point or spot light (so that I = P / (4 pi)),
# pi sin^2(a/2) for a sun of angle a and 1 for an angle-0 sun.  With Normalize off it divides by 1.

#: Blender's range of a light's Exposure (RNA hard limits), applied here too so 2^exposure stays finite.
EXPOSURE_RANGE = (-32.0, 32.0)


def exposure_scale(exposure):
    """2^exposure: Blender's light Exposure (stops, clamped to its range) as a factor of its power."""
    return op.exp2(op.clamp(exposure, *EXPOSURE_RANGE))


def emitting_area(area, normalize):
    """The area Cycles divides a light's power by: ``area`` with Normalize on (``normalize`` 1), 1 with it
    off (0)."""
    return op.select(op.greater(normalize, 0.5), area, 1.0)


def emitted_radiance(power, color, area, exposure, normalize, factor=_INV_PI):
    """L = P 2^exposure color factor / A for an emitter of area A (``emitting_area``), factor 1/pi for a
    Lambertian one; 0 for A <= AREA_MIN (Cycles: no contribution; and P / A can neither divide by zero nor
    overflow float32)."""
    lum = op.safe_div(power * exposure_scale(exposure) * factor, emitting_area(area, normalize))
    return op.scale(color, op.select(op.greater(area, AREA_MIN), lum, 0.0))


# --- area lights --------------------------------------------------------------------------------

def area_light_radiance(power, color, area, exposure=0.0, normalize=1.0):
    """Emitted radiance L = P 2^exposure color / (pi A) of a Blender area light of world-space area A (m^2;
    A = 1 with Normalize off); 0 for A <= AREA_MIN (Cycles: no contribution)."""
    return emitted_radiance(power, color, area, exposure, normalize)


def _area_axes(w, x, y, z, scale_x, scale_y, scale_z, size, size_y, determinant=1.0):
    """Half-extent vectors (eu, ev) of an area light and its area A: the world matrix's X and Y columns times
    the half sizes, Y flipped where the matrix mirrors, so that eu x ev points along its Z column (away from
    the lit side) as Cycles emits (``light_axis``).  With h = sign(det): eu = h R X half_u and ev = h R Y half_v
    sign(h sx sy sz) = R Y half_v sign(sx sy sz)."""
    half_u = scale_x * size * 0.5
    half_v = scale_y * size_y * 0.5
    eu = op.scale(quat_rotate(w, x, y, z, _EX), half_u * sign_of(determinant))
    ev = op.scale(quat_rotate(w, x, y, z, _EY), half_v * sign_of(scale_x * scale_y * scale_z))
    return eu, ev, op.absolute(half_u * half_v) * 4.0


def area_light_quad(location, w, x, y, z, scale_x, scale_y, scale_z, power, color, size, size_y, exposure=0.0,
                    normalize=1.0, determinant=1.0):
    """World corners (p0, p1, p2, p3) and radiance of a SQUARE / RECTANGLE area light.

    ``size_y`` is the light's Y extent: pass ``size`` for SQUARE.  The corners are
    (-u, -v), (+u, -v), (+u, +v), (-u, +v) in the light's local XY plane (u = size/2, v = size_y/2;
    v mirrored with the matrix), so (p1 - p0) x (p3 - p0) points along the light's +Z axis, away from
    the lit side."""
    eu, ev, area = _area_axes(w, x, y, z, scale_x, scale_y, scale_z, size, size_y, determinant)
    low, high = location - eu, location + eu
    corners = (low - ev, high - ev, high + ev, low + ev)
    return corners + (area_light_radiance(power, color, area, exposure, normalize),)


def area_light_disk(location, w, x, y, z, scale_x, scale_y, scale_z, power, color, size, size_y, exposure=0.0,
                    normalize=1.0, determinant=1.0):
    """Centre, semi-axis vectors (axis_u, axis_v) and radiance of a DISK / ELLIPSE area light.

    ``size_y`` is the light's Y diameter: pass ``size`` for DISK.  axis_u x axis_v points along the
    light's +Z axis, away from the lit side."""
    axis_u, axis_v, quad_area = _area_axes(w, x, y, z, scale_x, scale_y, scale_z, size, size_y, determinant)
    area = quad_area * (np.pi / 4.0)
    return location, axis_u, axis_v, area_light_radiance(power, color, area, exposure, normalize)


def area_light(shape, location, w, x, y, z, scale_x, scale_y, scale_z, power, color, size, size_y, exposure=0.0,
               normalize=1.0):
    """``area_light_quad`` or ``area_light_disk`` by Blender's ``shape`` (a build-time string):
    SQUARE and DISK use ``size`` for both extents, as Cycles does."""
    if shape not in ("SQUARE", "RECTANGLE", "DISK", "ELLIPSE"):
        raise ValueError(f"unknown area light shape {shape!r}")
    fn = area_light_quad if shape in ("SQUARE", "RECTANGLE") else area_light_disk
    return fn(location, w, x, y, z, scale_x, scale_y, scale_z, power, color, size,
              size if shape in ("SQUARE", "DISK") else size_y, exposure, normalize)


# --- point, spot and sun ------------------------------------------------------------------------

#: Cycles' area of a radius-0 point or spot light (``Light::area``): the power is divided by pi x 4.
POINT_AREA = 4.0


def point_light_intensity(power, color, exposure=0.0, normalize=1.0):
    """Radiant intensity I = P 2^exposure color / (4 pi) (W/sr) of a radius-0 point or spot light; P color / pi
    with Normalize off."""
    return emitted_radiance(power, color, POINT_AREA, exposure, normalize)


def _towards(position, location):
    """Unit direction l from the shading point to the light and the clamped inverse square law."""
    d = location - position
    dist2 = op.maximum(op.dot(d, d), MIN_DISTANCE * MIN_DISTANCE)
    return op.normalize(d), 1.0 / dist2


def point_light_incidence(position, location, power, color, exposure=0.0, normalize=1.0):
    """(l, E): unit direction to a radius-0 point light and the irradiance at normal incidence
    E = I / max(d^2, MIN_DISTANCE^2) (W/m^2, colour; the cosine is not included).  At the light
    itself l = 0 and E is finite."""
    l, inv_d2 = _towards(position, location)
    return l, op.scale(point_light_intensity(power, color, exposure, normalize), inv_d2)


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


def to_local(vec, w, x, y, z, scale_x, scale_y, scale_z, determinant=1.0):
    """A world-space vector in the light's local frame: the inverse of sign(det) x rotation x scale applied."""
    # (-w, x, y, z) = -conjugate(q): the inverse rotation, with one negation instead of three
    local = quat_rotate(-w, x, y, z, vec)
    h = sign_of(determinant)
    return op.vmul(local, op.vec3(op.safe_div(h, scale_x), op.safe_div(h, scale_y), op.safe_div(h, scale_z)))


def spot_cosine(position, location, w, x, y, z, scale_x, scale_y, scale_z, determinant=1.0):
    """Cosine between the spot axis (local -Z) and the direction from the light to ``position``,
    measured in the light's local frame (the inverse of sign(det) x rotation x scale), as Cycles does."""
    return local_cosine(to_local(position - location, w, x, y, z, scale_x, scale_y, scale_z, determinant))


def local_cosine(local):
    """The cosine between a local-frame direction and the light's -Z axis."""
    return -op.component(op.normalize(local), 2)


def spot_light_incidence(position, location, w, x, y, z, scale_x, scale_y, scale_z, power, color,
                         spot_size, spot_blend, exposure=0.0, normalize=1.0, determinant=1.0):
    """(l, E) of a radius-0 spot light: the point light's incidence times the cone attenuation."""
    l, e = point_light_incidence(position, location, power, color, exposure, normalize)
    c = spot_cosine(position, location, w, x, y, z, scale_x, scale_y, scale_z, determinant)
    return l, op.scale(e, spot_attenuation(c, spot_size, spot_blend))


def sun_light_incidence(w, x, y, z, scale_z, strength, color, exposure=0.0, determinant=1.0):
    """(l, E) of an angle-0 sun: l is the light's local +Z axis (it shines along -Z; ``light_axis``),
    E = S 2^exposure color (Normalize divides by an area of 1)."""
    return light_axis(w, x, y, z, scale_z, determinant), op.scale(color, strength * exposure_scale(exposure))


# --- sphere lights and suns with an angle: a uniform disk facing the shading point -------------------

#: Largest tangent of the half-angle of a facing disk (89.4 deg): a point inside a sphere light (or at the centre of
#: a soft-falloff disk) sees the disk towards the light's centre, not Cycles' whole sphere of directions; the bound
#: keeps the disk integrals finite in float32.
FACING_DISK_TAN_MAX = 100.0
FACING_DISK_COS_MIN = 1.0 / math.sqrt(1.0 + FACING_DISK_TAN_MAX * FACING_DISK_TAN_MAX)


def tangent_basis(n):
    """(t1, t2): unit tangents of the unit vector n with t1 x t2 = n: t1 = normalize(helper x n) with the helper
    axis +Z, or +X where n is within 25 deg of +-Z (so the cross product never degenerates), t2 = n x t1."""
    helper = op.vselect(op.less(op.absolute(op.component(n, 2)), 0.9), _EZ, _EX)
    t1 = op.normalize(op.cross(helper, n))
    return t1, op.cross(n, t1)


def facing_disk(position, direction, distance, tan_half_angle):
    """(centre, axis_u, axis_v) of the disk that subtends the cone of half-angle a about the unit ``direction``
    from ``position``: at ``distance`` along it, radius distance tan(a) (tan(a) at most FACING_DISK_TAN_MAX),
    axis_u x axis_v = direction (pointing away from the lit side: the LTC convention)."""
    t1, t2 = tangent_basis(direction)
    radius = distance * op.minimum(tan_half_angle, FACING_DISK_TAN_MAX)
    return position + op.scale(direction, distance), op.scale(t1, radius), op.scale(t2, radius)


def sphere_tan_half_angle(distance, radius, soft_falloff):
    """tan of the half-angle a sphere light of ``radius`` subtends at ``distance``: r/d with Soft Falloff (Cycles'
    disk of radius r facing the point), r / sqrt(d^2 - r^2) without (the visible cap of the sphere, sin a = r/d);
    FACING_DISK_TAN_MAX at and inside the sphere."""
    soft = op.safe_div(radius, distance)
    gap = distance * distance - radius * radius
    sphere = op.select(op.greater(gap, 0.0), op.safe_div(radius, op.sqrt(gap)), FACING_DISK_TAN_MAX)
    return op.select(op.greater(soft_falloff, 0.5), soft, sphere)


def sphere_light_area(radius):
    """Cycles' area of a point or spot light of radius r > 0: the sphere's, 4 pi r^2."""
    return (4.0 * np.pi) * radius * radius


def sphere_light(position, location, power, color, radius, soft_falloff, exposure=0.0, normalize=1.0):
    """(centre, axis_u, axis_v, radiance) of a point light of radius r > 0 seen from ``position``: the disk facing
    the point that subtends what the light does (``sphere_tan_half_angle``), at the light's location, with the
    sphere's radiance P 2^exposure color / (pi 4 pi r^2)."""
    d = location - position
    distance = op.maximum(op.length(d), MIN_DISTANCE)
    direction = op.normalize(d)
    centre, axis_u, axis_v = facing_disk(position, direction, distance,
                                         sphere_tan_half_angle(distance, radius, soft_falloff))
    return centre, axis_u, axis_v, emitted_radiance(power, color, sphere_light_area(radius), exposure, normalize)


#: Chebyshev-Gauss rule of the second kind on [-1, 1] with three points (weight sqrt(1 - x^2): a uniform disk's
#: density along a diameter): the points across the spot sphere's disk at which its cone attenuation is averaged.
DISK_DIAMETER_RULE = ((-math.sqrt(0.5), 0.25), (0.0, 0.5), (math.sqrt(0.5), 0.25))


def spot_sphere_light(position, location, w, x, y, z, scale_x, scale_y, scale_z, power, color, radius,
                      soft_falloff, spot_size, spot_blend, exposure=0.0, normalize=1.0, determinant=1.0):
    """``sphere_light`` times the spot's cone attenuation towards ``position`` (outside the sphere only, as Cycles).
    Cycles attenuates each direction to the light by the cone at the point it comes from; here the attenuation is
    averaged over three points of the facing disk on the diameter along which the cone's axis tilts
    (``DISK_DIAMETER_RULE``: the disk's density along it), which keeps the penumbra a sphere light casts at the
    cone's edge."""
    centre, axis_u, axis_v, radiance = sphere_light(position, location, power, color, radius, soft_falloff,
                                                    exposure, normalize)
    towards = op.normalize(location - position)
    emits = op.scale(light_axis(w, x, y, z, scale_z, determinant), -1.0)
    tilt = op.normalize(emits - op.scale(towards, op.dot(emits, towards)))
    frame = (w, x, y, z, scale_x, scale_y, scale_z, determinant)
    # the direction from a point of the disk to the shading point, in the local frame: one transform of each part
    to_point = to_local(position - location, *frame)
    across = to_local(op.scale(tilt, op.length(axis_u)), *frame)
    cone = 0.0
    for offset, weight in DISK_DIAMETER_RULE:
        c = local_cosine(to_point - op.scale(across, offset))
        cone = spot_attenuation(c, spot_size, spot_blend) * weight + cone
    d = location - position
    outside = op.greater(op.dot(d, d), radius * radius)
    return centre, axis_u, axis_v, op.scale(radiance, op.select(outside, cone, 1.0))


def sun_disk_light(position, w, x, y, z, scale_z, strength, color, angle, exposure=0.0, normalize=1.0,
                   determinant=1.0):
    """(centre, axis_u, axis_v, radiance) of a sun of angle a > 0: the disk at unit distance towards the sun
    subtending a/2, radiance S 2^exposure color / (pi sin^2(a/2)) (Normalize on; Cycles ``Light::area``)."""
    half = op.clamp(angle * 0.5, 0.0, 0.5 * np.pi)
    sin_half = op.sin(half)
    # tan(a/2) as sin / cos, the cosine bounded (not the angle: near pi/2 the tangent would amplify the bound's
    # float32 rounding a hundredfold)
    tan_half = op.safe_div(sin_half, op.maximum(op.cos(half), FACING_DISK_COS_MIN))
    centre, axis_u, axis_v = facing_disk(position, light_axis(w, x, y, z, scale_z, determinant), 1.0, tan_half)
    area = np.pi * sin_half * sin_half
    return centre, axis_u, axis_v, emitted_radiance(strength, color, area, exposure, normalize, factor=1.0)


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
    out = {f"Scale {a}": scalar(1.0, f"World-space scale {a} of the light object (driver: Transform "
                                     f"Channel SCALE_{a}, world space)", panel=_TRANSFORM_PANEL)
           for a in "XYZ"}
    out["Determinant"] = scalar(1.0, "Determinant of the light object's world matrix: negative for a mirrored "
                                     "light (driver: the 3 x 3 determinant of matrix_world)", panel=_TRANSFORM_PANEL)
    return out


def _color_sockets():
    return {f"Color {c}": scalar(1.0, f"Light colour, {name} channel: light data color[{i}] times the blackbody "
                                      f"colour of its temperature (when used) and its node tree's constant emission "
                                      f"colour and strength", 0.0, None, panel=_DATA_PANEL)
            for i, (c, name) in enumerate((("R", "red"), ("G", "green"), ("B", "blue")))}


def _power_socket(what):
    return {"Power": scalar(1000.0, f"{what} power P in W (light data energy)", 0.0, None,
                            panel=_DATA_PANEL)}


def _units_sockets():
    return {"Exposure": scalar(0.0, "Exposure in stops: the power times 2^exposure (light data exposure)",
                               *EXPOSURE_RANGE, panel=_DATA_PANEL),
            "Normalize": factor(1.0, "1: the power is divided by the light's area (light data normalize); 0: by 1",
                                panel=_DATA_PANEL)}


def _size_sockets(shape):
    return {"Size": scalar(1.0, f"{shape} size along the light's X axis in m (light data size)", 0.0, None,
                           subtype="DISTANCE", panel=_DATA_PANEL),
            "Size Y": scalar(1.0, f"{shape} size along the light's Y axis in m (light data size_y; "
                                  f"drive it from size for a {'SQUARE' if shape == 'Quad' else 'DISK'} light)",
                             0.0, None, subtype="DISTANCE", panel=_DATA_PANEL)}


def _spot_sockets():
    return {"Spot Size": scalar(np.pi / 4, "Full cone angle (light data spot_size)", 0.0, np.pi, subtype="ANGLE",
                                panel=_DATA_PANEL),
            "Spot Blend": scalar(0.15, "Softness of the cone edge (light data spot_blend)", 0.0, 1.0,
                                 subtype="FACTOR", panel=_DATA_PANEL)}


def _sphere_sockets():
    return {"Radius": scalar(0.1, "Radius r of the light in m (light data shadow_soft_size)", 0.0, None,
                             subtype="DISTANCE", panel=_DATA_PANEL),
            "Soft Falloff": factor(1.0, "1: a disk of radius r facing the shading point (Cycles' Soft Falloff, "
                                        "Blender's default); 0: a sphere (light data use_soft_falloff)",
                                   panel=_DATA_PANEL)}


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


def _units(kw):
    return kw["Exposure"], kw["Normalize"]


def _oriented_units(kw):
    """Exposure, Normalize and Determinant: the trailing arguments of the oriented lights' functions."""
    return kw["Exposure"], kw["Normalize"], kw["Determinant"]


def _quad_node(**kw):
    p0, p1, p2, p3, radiance = area_light_quad(_loc(kw), *_rot(kw), *_scl(kw), kw["Power"], _col(kw),
                                               kw["Size"], kw["Size Y"], *_oriented_units(kw))
    return {"p0": p0, "p1": p1, "p2": p2, "p3": p3, "Center": _loc(kw), "Radiance": radiance}


def _disk_node(**kw):
    center, axis_u, axis_v, radiance = area_light_disk(_loc(kw), *_rot(kw), *_scl(kw), kw["Power"], _col(kw),
                                                       kw["Size"], kw["Size Y"], *_oriented_units(kw))
    return {"Center": center, "Axis U": axis_u, "Axis V": axis_v, "Radiance": radiance}


def _point_node(**kw):
    l, e = point_light_incidence(kw["Position"], _loc(kw), kw["Power"], _col(kw), *_units(kw))
    return {"L": l, "Irradiance": e}


def _spot_node(**kw):
    l, e = spot_light_incidence(kw["Position"], _loc(kw), *_rot(kw), *_scl(kw), kw["Power"], _col(kw),
                                kw["Spot Size"], kw["Spot Blend"], *_oriented_units(kw))
    return {"L": l, "Irradiance": e}


def _sun_node(**kw):
    l, e = sun_light_incidence(*_rot(kw), kw["Scale Z"], kw["Strength"], _col(kw), kw["Exposure"],
                               kw["Determinant"])
    return {"L": l, "Irradiance": e}


def _disk_outputs(center, axis_u, axis_v, radiance):
    return {"Center": center, "Axis U": axis_u, "Axis V": axis_v, "Radiance": radiance}


def _sphere_node(**kw):
    return _disk_outputs(*sphere_light(kw["Position"], _loc(kw), kw["Power"], _col(kw), kw["Radius"],
                                       kw["Soft Falloff"], *_units(kw)))


def _spot_sphere_node(**kw):
    return _disk_outputs(*spot_sphere_light(kw["Position"], _loc(kw), *_rot(kw), *_scl(kw), kw["Power"], _col(kw),
                                            kw["Radius"], kw["Soft Falloff"], kw["Spot Size"], kw["Spot Blend"],
                                            *_oriented_units(kw)))


def _sun_disk_node(**kw):
    return _disk_outputs(*sun_disk_light(kw["Position"], *_rot(kw), kw["Scale Z"], kw["Strength"], _col(kw),
                                         kw["Angle"], *_oriented_units(kw)))


def _corner(i):
    return vector(f"World-space corner {i}; (p1 - p0) x (p3 - p0) points away from the lit side",
                  "XYZ", hide_value=True)


_DISK_OUTPUTS = {
    "Center": vector("World-space centre of the disk or ellipse", "XYZ", hide_value=True),
    "Axis U": vector("Semi-axis along the light's X axis; Axis U x Axis V points away from the lit side",
                     "XYZ", hide_value=True),
    "Axis V": vector("Semi-axis along the light's Y axis", "XYZ", hide_value=True),
    "Radiance": _RADIANCE}
_FACING_DISK_OUTPUTS = {
    "Center": vector("World-space centre of the disk facing the shading point", "XYZ", hide_value=True),
    "Axis U": vector("Semi-axis of the disk; Axis U x Axis V points from the shading point to the light", "XYZ",
                     hide_value=True),
    "Axis V": vector("Second semi-axis of the disk", "XYZ", hide_value=True),
    "Radiance": _RADIANCE}
_STRENGTH = {"Strength": scalar(1.0, "Sun strength S: irradiance in W/m^2 (light data energy)", 0.0, None,
                                panel=_DATA_PANEL)}

AREA_LIGHT_QUAD = NodeFunction(
    "RTL Area Light Quad", _quad_node,
    {**_location_sockets(), **_rotation_sockets(), **_scale_sockets(), **_power_socket("Area light"),
     **_color_sockets(), **_size_sockets("Quad"), **_units_sockets()},
    {**{f"p{i}": _corner(i) for i in range(4)},
     "Center": vector("World-space centre (the light's location): the side the shading point is on is taken from "
                      "it, which the corners of a light much larger than its distance round away", "XYZ",
                      hide_value=True),
     "Radiance": _RADIANCE},
    "A SQUARE or RECTANGLE Blender area light: world corners and emitted radiance (Cycles units)")

AREA_LIGHT_DISK = NodeFunction(
    "RTL Area Light Disk", _disk_node,
    {**_location_sockets(), **_rotation_sockets(), **_scale_sockets(), **_power_socket("Area light"),
     **_color_sockets(), **_size_sockets("Disk"), **_units_sockets()},
    _DISK_OUTPUTS,
    "A DISK or ELLIPSE Blender area light: centre, semi-axes and emitted radiance (Cycles units)")

POINT_LIGHT = NodeFunction(
    "RTL Point Light", _point_node,
    {**_location_sockets(), **_power_socket("Point light"), **_color_sockets(), **_units_sockets(), **_POSITION},
    {"L": _L, "Irradiance": _IRRADIANCE},
    "A radius-0 Blender point light: I = P color / (4 pi), irradiance I / d^2 (d >= 1 cm)")

SPOT_LIGHT = NodeFunction(
    "RTL Spot Light", _spot_node,
    {**_location_sockets(), **_rotation_sockets(), **_scale_sockets(), **_power_socket("Spot light"),
     **_color_sockets(), **_spot_sockets(), **_units_sockets(), **_POSITION},
    {"L": _L, "Irradiance": _IRRADIANCE},
    "A radius-0 Blender spot light: the point light's intensity times Cycles' cone attenuation")

SUN_LIGHT = NodeFunction(
    "RTL Sun Light", _sun_node,
    {**_rotation_sockets(), **_scale_sockets(), **_STRENGTH, **_color_sockets(), **_units_sockets()},
    {"L": _L, "Irradiance": _IRRADIANCE},
    "An angle-0 Blender sun: direction to the sun (its +Z axis) and irradiance S color")

SPHERE_LIGHT = NodeFunction(
    "RTL Sphere Light", _sphere_node,
    {**_location_sockets(), **_power_socket("Point light"), **_color_sockets(), **_sphere_sockets(),
     **_units_sockets(), **_POSITION},
    _FACING_DISK_OUTPUTS,
    "A Blender point light of radius r > 0: the disk facing the shading point that it subtends (a disk of radius r "
    "with Soft Falloff, the sphere's cap without), radiance P color / (4 pi^2 r^2)")

SPOT_SPHERE_LIGHT = NodeFunction(
    "RTL Spot Sphere Light", _spot_sphere_node,
    {**_location_sockets(), **_rotation_sockets(), **_scale_sockets(), **_power_socket("Spot light"),
     **_color_sockets(), **_sphere_sockets(), **_spot_sockets(), **_units_sockets(), **_POSITION},
    _FACING_DISK_OUTPUTS,
    "A Blender spot light of radius r > 0: the sphere light's facing disk times the cone attenuation towards the "
    "shading point")

SUN_DISK_LIGHT = NodeFunction(
    "RTL Sun Disk Light", _sun_disk_node,
    {**_rotation_sockets(), **_scale_sockets(), **_STRENGTH, **_color_sockets(),
     "Angle": scalar(math.radians(0.526), "Angular diameter of the sun (light data angle)", 0.0, np.pi,
                     subtype="ANGLE", panel=_DATA_PANEL),
     **_units_sockets(), **_POSITION},
    _FACING_DISK_OUTPUTS,
    "A Blender sun of angle a > 0: the disk at unit distance subtending a/2 about its direction, radiance "
    "S color / (pi sin^2(a/2))")


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


def projector_apex(location, w, x, y, z, scale_x, scale_y, scale_z, size, size_y, outer_angle, shape,
                   determinant=1.0):
    """(apex, emission axis): the talk's projector point behind an area light, p = (d/2)/tan(phi/2) behind its
    centre (``falloff.projector_distance``), and the unit direction the light emits along (its local -Z axis,
    mirrored or not: ``light_axis``)."""
    axis = op.scale(light_axis(w, x, y, z, scale_z, determinant), -1.0)
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
                        inner_angle, outer_angle, exposure=0.0, normalize=1.0, determinant=1.0):
    """(l, E) of the quad-to-spot fallback: the quad's far field, a point at its centre of intensity
    I(theta) = L A cos(theta) = P color cos(theta) / pi (a Lambertian emitter, theta from its axis; L A = P / pi
    with Normalize on, P A / pi with it off, 0 for a light of no area), times the talk's
    cone falloff at the projector apex behind the quad; E = I / max(d^2, d_min^2), d from the centre.

    The talk's images show a spot at the apex, which emits the same intensity in every direction of its cone: it
    misses the quad's cosine, by 29-89% (median) on a floor under the talk's angle pairs, and converges to nothing
    with distance; a spot at the apex with the cosine converges as the apex offset over the distance (10% at one
    light size, 1% at ten); at the centre it is the quad's far field, 2.5% at two light diameters, 0.3% at six
    (docs/benchmarks/light_fallback.md)."""
    apex, axis = projector_apex(location, w, x, y, z, scale_x, scale_y, scale_z, size, size_y, outer_angle, "quad",
                                determinant)
    l, inv_d2 = _towards(position, location)
    emission = op.maximum(-op.dot(l, axis), 0.0)
    cone = apex_cone_falloff(position, apex, axis, inner_angle, outer_angle)
    _, _, area = _area_axes(w, x, y, z, scale_x, scale_y, scale_z, size, size_y)
    intensity = op.scale(area_light_radiance(power, color, area, exposure, normalize), area)
    return l, op.scale(intensity, inv_d2 * emission * cone)


def _quad_spot_node(**kw):
    l, e = quad_spot_incidence(kw["Position"], _loc(kw), *_rot(kw), *_scl(kw), kw["Power"], _col(kw), kw["Size"],
                               kw["Size Y"], kw["Cone Inner"], kw["Cone Outer"], *_oriented_units(kw))
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
     **_color_sockets(), **_size_sockets("Quad"), **_cone_sockets(), **_units_sockets(), **_POSITION},
    {"L": _L, "Irradiance": _IRRADIANCE},
    "The talk's quad-to-spot fallback: the quad's far field, P color cos / pi from its centre, with the cone falloff "
    "at the projector apex")

NODE_FUNCTIONS = (AREA_LIGHT_QUAD, AREA_LIGHT_DISK, POINT_LIGHT, SPOT_LIGHT, SUN_LIGHT, QUAD_SPOT_LIGHT,
                  SPHERE_LIGHT, SPOT_SPHERE_LIGHT, SUN_DISK_LIGHT)

#: RT Lit light kind -> the node function that turns driver values into light geometry.
LIGHT_DATA = {"quad": AREA_LIGHT_QUAD, "disk": AREA_LIGHT_DISK, "point": POINT_LIGHT, "spot": SPOT_LIGHT,
              "sun": SUN_LIGHT, "quad_spot": QUAD_SPOT_LIGHT, "sphere": SPHERE_LIGHT, "spot_sphere": SPOT_SPHERE_LIGHT,
              "sun_disk": SUN_DISK_LIGHT}

#: How the lobes shade each kind: over a polygon ("quad"), over an ellipse ("disk"; sphere lights and suns with an
#: angle are the disk facing the point), or at one direction ("punctual").
SHADING_FORMS = {"quad": "quad", "disk": "disk", "sphere": "disk", "spot_sphere": "disk", "sun_disk": "disk",
                 "point": "punctual", "spot": "punctual", "sun": "punctual", "quad_spot": "punctual"}
#: Inputs of a light's data function that the material feeds from the shading point, not from the light.
SHADING_POINT_INPUTS = ("Position",)


def shading_form(kind):
    """"quad", "disk" or "punctual": how the lobes shade a light of ``kind`` (``SHADING_FORMS``; the spread
    option keeps the form: core/light_spread.py)."""
    return SHADING_FORMS[split_kind(kind)[0]]

#: Build-time options of a light kind ("quad+range", "disk+cone+range"): each adds its falloff, and its driver
#: inputs, to the light's data function (``light_data``); a light without them carries no node of them.
LIGHT_OPTIONS = ("cone", "range", "spread", "linking")
#: The base kinds each option applies to (quad_spot has its cone built in; the sun has no distance).  "spread":
#: Blender's area-light spread below 180 deg (core/light_spread.py); the quad-to-spot fallback has none.
OPTION_KINDS = {"cone": ("quad", "disk"), "range": ("quad", "disk", "point", "spot", "quad_spot", "sphere",
                                                    "spot_sphere"),
                "spread": ("quad", "disk"),
                # Blender's light linking, where a material's objects differ in receiving the light: an input
                # "Excluded" per object (addon/materials.py feeds it from an object attribute)
                "linking": ("quad", "disk", "point", "spot", "sun", "quad_spot", "sphere", "spot_sphere", "sun_disk")}
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


_SPREAD_SOCKET = {"Spread": scalar(np.pi, "Spread angle of the area light (light data spread; core/light_spread.py)",
                                   0.0, np.pi, subtype="ANGLE", panel=_DATA_PANEL)}
_EXCLUDED_SOCKET = {"Excluded": factor(0.0, "1 on an object that light linking excludes from this light (the "
                                            "object's attribute rtl_excluded_<light>), 0 where it receives it",
                                       panel=_DATA_PANEL)}


def control_factor(kind, position, params):
    """The falloff the options of ``kind`` apply to the light's colour at ``position`` (1.0 without options);
    ``params``: the light's driver values (``light_data(kind)``'s inputs).  The spread is not a factor of the
    colour alone: ``spread_geometry``."""
    base, options = split_kind(kind)
    out = 1.0
    if "range" in options:
        out = range_falloff(position, _loc(params), params["Range"])
    if "cone" in options:
        apex, axis = projector_apex(_loc(params), *_rot(params), *_scl(params), params["Size"], params["Size Y"],
                                    params["Cone Outer"], base, params["Determinant"])
        out = out * apex_cone_falloff(position, apex, axis, params["Cone Inner"], params["Cone Outer"])
    if "linking" in options:
        out = out * (1.0 - op.saturate(params["Excluded"]))
    return out


#: What a light with spread hands its lobes besides its clamped region: its cone (``light_spread.SpreadCone``), by
#: which each lobe weights its own integral (``light_spread.lobe_average``).
SPREAD_OUTPUTS = {
    "Spread Foot": vector("The shading point's foot on the light's plane (core/light_spread.py)", "XYZ"),
    "Spread Radius": scalar(light_spread.FULL_RADIUS, "Radius R of the spread's cone on the light's plane"),
    "Spread Scale": scalar(1.0, "The spread's normalisation c: the weight is c max(1 - rho / R, 0)"),
}


#: A disk light with spread also hands its lobes its own ellipse, over whose overlap with the cone broad lobes average
#: the weight (``light_spread.DISK_RULE``; the region it shades is an ellipse fitted to that overlap).
SPREAD_DISK_OUTPUTS = {
    "Spread Disk Center": vector("The disk light's own centre (core/light_spread.py, DISK_RULE)", "XYZ"),
    "Spread Disk Axis U": vector("The disk light's own first semi-axis", "XYZ"),
    "Spread Disk Axis V": vector("The disk light's own second semi-axis", "XYZ"),
}


def spread_geometry(base, light, position, spread):
    """The outputs of a quad or disk light's data function (``light``) with Blender's spread applied
    (core/light_spread.py): the clamped region's geometry, the cone (``SPREAD_OUTPUTS``) and the radiance, 0 where
    the cone misses the light."""
    if base == "quad":
        half_u, half_v = op.scale(light["p1"] - light["p0"], 0.5), op.scale(light["p3"] - light["p0"], 0.5)
        centre, eu, ev, cone, hits = light_spread.spread_quad(position, light["Center"], half_u, half_v, spread)
        low, high = centre - eu, centre + eu
        out = {"p0": low - ev, "p1": high - ev, "p2": high + ev, "p3": low + ev, "Center": centre}
    else:
        centre, axis_u, axis_v, cone, hits = light_spread.spread_disk(position, light["Center"], light["Axis U"],
                                                                      light["Axis V"], spread)
        out = {"Center": centre, "Axis U": axis_u, "Axis V": axis_v}
        out.update(zip(SPREAD_DISK_OUTPUTS, cone.disk))
    out["Radiance"] = op.scale(light["Radiance"], hits)
    out.update({"Spread Foot": cone.foot, "Spread Radius": cone.radius, "Spread Scale": cone.scale})
    return out


def spread_cone_of(light):
    """The ``light_spread.SpreadCone`` in the outputs of a light with spread (``spread_geometry``)."""
    disk = tuple(light[n] for n in SPREAD_DISK_OUTPUTS) if "Spread Disk Center" in light else None
    return light_spread.SpreadCone(light["Spread Foot"], light["Spread Radius"], light["Spread Scale"], disk)


def _with_options(base, options):
    data = LIGHT_DATA[base]
    color_name = "Radiance" if "Radiance" in data.output_sockets else "Irradiance"
    kind = kind_name(base, options)

    def body(**kw):
        out = dict(data(**{k: kw[k] for k in data.input_sockets}))
        if "spread" in options:
            out.update(spread_geometry(base, out, kw["Position"], kw["Spread"]))
        out[color_name] = op.scale(out[color_name], control_factor(kind, kw["Position"], kw))
        return out

    inputs = dict(data.input_sockets)
    inputs.pop("Position", None)
    if "cone" in options:
        inputs.update(_cone_sockets())
    if "range" in options:
        inputs.update(_RANGE_SOCKET)
    if "spread" in options:
        inputs.update(_SPREAD_SOCKET)
    if "linking" in options:
        inputs.update(_EXCLUDED_SOCKET)
    inputs.update(_POSITION)
    outputs = dict(data.output_sockets)
    if "spread" in options:
        outputs.update(SPREAD_OUTPUTS)
        if base == "disk":
            outputs.update(SPREAD_DISK_OUTPUTS)
    words = {"cone": "the talk's cone falloff at the projector apex", "range": "the talk's windowed range",
             "spread": "Blender's spread", "linking": "Blender's light linking"}
    return NodeFunction(f"{data.name} ({', '.join(options)})", body, inputs, outputs,
                        f"{data.description}; with " + " and ".join(words[o] for o in options))


@functools.lru_cache(maxsize=None)
def light_data(kind):
    """The data function of a light kind with its options (``LIGHT_DATA[kind]`` for a kind without)."""
    base, options = split_kind(kind)
    return LIGHT_DATA[base] if not options else _with_options(base, options)


#: The data functions of one light of each kind with every option it takes (what tests check in each backend).
CONTROL_FUNCTIONS = tuple(light_data(kind_name(k, LIGHT_OPTIONS)) for k in LIGHT_DATA)

_DATA_PATHS = {"Power": "energy", "Strength": "energy", "Size": "size", "Size Y": "size_y", "Spot Size": "spot_size",
               "Spot Blend": "spot_blend", "Exposure": "exposure", "Normalize": "normalize",
               "Radius": "shadow_soft_size", "Soft Falloff": "use_soft_falloff", "Angle": "angle", "Spread": "spread",
               # the light controls: custom properties of the light data (addon/light_controls.py registers them)
               "Range": '["rtl_range"]', "Cone Inner": '["rtl_cone_inner"]', "Cone Outer": '["rtl_cone_outer"]'}


def driver_sources(kind, shape=None):
    """Where each input of ``light_data(kind)`` comes from in Blender, as the driver that feeds it:
    ("transform", TRANSFORMS channel in world space), ("data", light data path), ("color", channel) for the
    light's colour (the product of its colours: addon/materials.py), ("determinant", None) for its world
    matrix's determinant or ("excluded", None) for the linking option's object attribute.  SQUARE and DISK lights have one size: their "Size Y" reads ``size`` too (Cycles
    ignores size_y for them)."""
    out = {}
    for name in light_data(kind).input_sockets:
        if name in SHADING_POINT_INPUTS:
            continue
        word, _, axis = name.partition(" ")
        if word in ("Location", "Rotation", "Scale") and len(axis) == 1:
            prefix = {"Location": "LOC_", "Rotation": "ROT_", "Scale": "SCALE_"}[word]
            out[name] = ("transform", prefix + axis)
        elif word == "Color" and len(axis) == 1:
            out[name] = ("color", "RGB".index(axis))
        elif name == "Excluded":
            out[name] = ("excluded", None)
        elif name == "Determinant":
            out[name] = ("determinant", None)
        elif name == "Size Y" and shape in ("SQUARE", "DISK"):
            out[name] = ("data", "size")
        else:
            out[name] = ("data", _DATA_PATHS[name])
    return out
