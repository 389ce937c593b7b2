"""Cycles' area-light spread on the RT Lit material.

Blender's area light "Spread" models a soft box's grid of slats (Cycles ``kernel/light/area.h``:
``area_light_spread_attenuation``; ``scene/light.cpp``: ``normalize_spread``).  The radiance of a
direction that meets the light at the angle a from its axis is the Lambertian radiance L times

    w(a) = max(1 - tan(a) / tan(h), 0) tan(h) / (tan(h) - h),       h = spread / 2,

normalised so that the light's flux stays P (the integral of cos(a) w(a) over the hemisphere is pi;
Cycles divides by (tan h - h) and multiplies by tan h inside the attenuation).  The weight depends on
the direction only: seen from a shading point at the distance t from the light's plane, it is a
cone over the plane, w = c max(1 - rho / R, 0), c = tan h / (tan h - h), rho the distance from the
point's foot on the plane and R = t tan h.  Measured against Cycles (the formula, per pixel, in
tests/blender/test_light_units.py).

An LTC integrates a lobe over a light of constant radiance, not over this cone.  RT Lit shades a
light with spread as (this project's construction; docs/blender.md, "Spread"):

1. the emitting region: a quad clamped to the square of half-size R about the foot (Cycles' own
   ``area_light_spread_clamp_light``: outside it w = 0); a disk clipped to the circle of radius R
   about the foot (the circle, the disk, or an ellipse fitted to their lens: ``spread_disk``);
2. the LTC integral of every lobe over that region at the light's radiance L, times
3. the average of w over the region weighted by the Lambert kernel cos(receiver) cos(light) / d^2,
   by a Gauss-Legendre rule on the region (4 x 4 points on a quad, 3 radial x 6 angular on a disk):
   exact where w is constant, and where the region is much larger than the cone it finds the cone.

Against the exact integral of a Lambert receiver (numpy, seeded random lights, receivers and spreads
20-170 deg): quads 0.3-2.5 m at 0.5-3 m (280), median 0.06%, p90 1.7%, those in the cone's narrow part
(R < half their size) 1.3% / 4.3%; disks of radius 0.3-1 m at 0.6-2 m (91), median 1.2%, p90 8.4%, max
14%, the error in the partial overlaps, whose lens the fitted ellipse only approximates
(tests/core/test_lights.py checks the quad's).  Glossy lobes see w through the Lambert kernel's
average: the validation suite's spread cases measure them against Cycles.
"""
from __future__ import annotations

import math

import numpy as np

from . import shading_ops as op

#: Smallest half-spread taken (0.25 deg): below it tan(h) - h underflows float32; Cycles' own floor is 0.05 deg.
MIN_HALF_SPREAD = math.radians(0.25)
#: Largest half-spread that is a spread: at pi / 2 (Blender's 180 deg, the default) the weight is 1.
MAX_HALF_SPREAD = 0.5 * math.pi

#: Gauss-Legendre rule on [-1, 1] (numpy.polynomial.legendre.leggauss(4)): the quad's points per axis.
QUAD_NODES, QUAD_WEIGHTS = (tuple(float(x) for x in a) for a in np.polynomial.legendre.leggauss(4))
#: The disk's rule: Gauss-Legendre in the radius (3 points, weighted by r) x 6 equally spaced angles.
_RADIAL_X, _RADIAL_W = np.polynomial.legendre.leggauss(3)
DISK_RADII = tuple(float(0.5 * (x + 1.0)) for x in _RADIAL_X)
DISK_RADIAL_WEIGHTS = tuple(float(0.25 * w * (x + 1.0)) for x, w in zip(_RADIAL_X, _RADIAL_W))
DISK_ANGLES = tuple(2.0 * math.pi * (k + 0.5) / 6.0 for k in range(6))


def half_spread(spread):
    """h = spread / 2 within [MIN_HALF_SPREAD, pi / 2]."""
    return op.clamp(spread * 0.5, MIN_HALF_SPREAD, MAX_HALF_SPREAD)


def spread_normalization(tan_h, h):
    """c = tan h / (tan h - h): Cycles' ``normalize_spread`` times tan h (module docstring)."""
    return op.safe_div(tan_h, tan_h - h)


def spread_weight(rho, cone_radius, normalization):
    """w = c max(1 - rho / R, 0) at the distance rho from the foot on the light's plane."""
    return op.maximum(1.0 - op.safe_div(rho, cone_radius), 0.0) * normalization


class _Cone:
    """The spread's cone over the light's plane as one shading point sees it: the foot's offset from the light's
    centre (its coordinates along the light's unit axes), the plane distance t and R = t tan h."""

    def __init__(self, position, location, unit_u, unit_v, spread):
        offset = position - location
        self.foot_u, self.foot_v = op.dot(offset, unit_u), op.dot(offset, unit_v)
        self.height = op.absolute(op.dot(offset, op.cross(unit_u, unit_v)))
        h = half_spread(spread)
        tan_h = op.tan(h)
        self.radius = self.height * tan_h
        self.normalization = spread_normalization(tan_h, h)
        # where the spread is 180 deg the weight is 1 everywhere (Cycles: tan(h) = FLT_MAX)
        self.full = op.greater(spread, 2.0 * MAX_HALF_SPREAD - 1e-6)


def _kernel_average(cone, position, normal, centre, axis_u, axis_v, points):
    """The average of the spread weight over the points ``centre + axis_u x + axis_v y`` ((x, y, weight) each) of
    the region, weighted by the rule's weight times the Lambert kernel max(cos, 0) / d^4 (the plane's cosine t / d
    and the inverse square, t a common factor).  Scalar algebra on dot products: axis_u and axis_v are orthogonal."""
    c = centre - position
    cc, cu, cv = op.dot(c, c), op.dot(c, axis_u), op.dot(c, axis_v)
    uu, vv = op.dot(axis_u, axis_u), op.dot(axis_v, axis_v)
    cn, un, vn = op.dot(c, normal), op.dot(axis_u, normal), op.dot(axis_v, normal)
    t2 = cone.height * cone.height
    total, weighted = 0.0, 0.0
    for x, y, w in points:
        d2 = op.maximum(cc + (2.0 * x) * cu + (2.0 * y) * cv + (x * x) * uu + (y * y) * vv, 1e-12)
        kernel = op.safe_div(op.maximum(cn + x * un + y * vn, 0.0) * w, d2 * d2)
        rho = op.sqrt(d2 - t2)
        total = kernel + total
        weighted = kernel * spread_weight(rho, cone.radius, cone.normalization) + weighted
    return op.select(cone.full, 1.0, op.safe_div(weighted, total))


def _quad_points():
    return [(x, y, wx * wy) for x, wx in zip(QUAD_NODES, QUAD_WEIGHTS) for y, wy in zip(QUAD_NODES, QUAD_WEIGHTS)]


def _disk_points():
    return [(r * math.cos(a), r * math.sin(a), wr / len(DISK_ANGLES))
            for r, wr in zip(DISK_RADII, DISK_RADIAL_WEIGHTS) for a in DISK_ANGLES]


def spread_quad(position, normal, location, half_u, half_v, spread):
    """(centre, half_u, half_v, factor): a quad light with spread as RT Lit shades it (module docstring): the quad
    clamped to the cone's square (centre and half-extent vectors, zero when the square misses the light) and the
    factor its radiance is multiplied by (the kernel-weighted average of the spread weight; 0 when it misses).
    ``half_u``, ``half_v``: the light's orthogonal half-extent vectors (``lights._area_axes``)."""
    a, b = op.length(half_u), op.length(half_v)
    unit_u, unit_v = op.normalize(half_u), op.normalize(half_v)
    cone = _Cone(position, location, unit_u, unit_v, spread)
    reach = op.select(cone.full, 1e30, cone.radius)
    u0, u1 = op.maximum(cone.foot_u - reach, -a), op.minimum(cone.foot_u + reach, a)
    v0, v1 = op.maximum(cone.foot_v - reach, -b), op.minimum(cone.foot_v + reach, b)
    hits = op.logical_and(op.greater(u1, u0), op.greater(v1, v0))
    centre = location + op.scale(unit_u, (u0 + u1) * 0.5) + op.scale(unit_v, (v0 + v1) * 0.5)
    eu = op.scale(unit_u, op.maximum(u1 - u0, 0.0) * 0.5)
    ev = op.scale(unit_v, op.maximum(v1 - v0, 0.0) * 0.5)
    average = _kernel_average(cone, position, normal, centre, eu, ev, _quad_points())
    return centre, eu, ev, op.select(hits, average, 0.0)


def _segment_area(radius, chord):
    """Area of the circular segment of a circle of ``radius`` beyond the chord at the signed distance ``chord``
    from its centre: r^2 acos(x / r) - x sqrt(r^2 - x^2)."""
    x = op.clamp(chord, -radius, radius)
    return radius * radius * op.acos(op.safe_div(x, radius)) - x * op.sqrt(radius * radius - x * x)


def _lens(r1, r2, d):
    """(area, apex 1, apex 2, half width) of the intersection of two circles of radii r1, r2 whose centres are d
    apart, overlapping in part (|r1 - r2| < d < r1 + r2): two circular segments cut by the common chord at
    x1 = (d^2 + r1^2 - r2^2) / (2 d) from centre 1; its apexes along the line of centres at r1 from centre 1 and
    d - r2 (distances from centre 1); its half width across, the half chord (or the smaller radius where the
    chord lies beyond a centre)."""
    x1 = op.safe_div(d * d + r1 * r1 - r2 * r2, 2.0 * d)
    area = _segment_area(r1, x1) + _segment_area(r2, d - x1)
    chord_between = op.logical_and(op.greater(x1, 0.0), op.less(x1, d))
    width = op.select(chord_between, op.sqrt(r1 * r1 - x1 * x1), op.minimum(r1, r2))
    return area, r1, d - r2, width


def spread_disk(position, normal, centre, axis_u, axis_v, spread):
    """(centre, axis_u, axis_v, factor) of a disk or ellipse light with spread (module docstring): the region it
    emits from is the light clipped to the cone's circle of radius R about the foot: the circle where it lies inside
    the light, the light where it lies inside the circle, and where they overlap in part the ellipse spanning the
    lens between its apexes and across its width, scaled to the lens's area (an ellipse light taken as the circle
    of its area there); the factor as ``spread_quad``'s."""
    a, b = op.length(axis_u), op.length(axis_v)
    unit_u, unit_v = op.normalize(axis_u), op.normalize(axis_v)
    cone = _Cone(position, centre, unit_u, unit_v, spread)
    partial = op.less(cone.full, 0.5)
    # the circle lies inside the ellipse if the foot is at least R inside it along the ellipse's smaller axis
    inside = op.length(op.vec3(op.safe_div(cone.foot_u, a), op.safe_div(cone.foot_v, b), 0.0))
    circle_in_light = op.logical_and(op.less(inside + op.safe_div(cone.radius, op.minimum(a, b)), 1.0), partial)
    d = op.length(op.vec3(cone.foot_u, cone.foot_v, 0.0))
    light_in_circle = op.select(op.less(d + op.maximum(a, b), cone.radius), 1.0, op.select(cone.full, 1.0, 0.0))
    radius = op.sqrt(a * b)
    misses = op.logical_and(op.greater(d, radius + cone.radius), partial)
    # partial overlap: the lens of the light's equal-area circle and the cone's circle
    area, apex_far, apex_near, width = _lens(radius, cone.radius, op.maximum(d, 1e-12))
    towards = op.normalize(op.scale(unit_u, cone.foot_u) + op.scale(unit_v, cone.foot_v))
    across = op.cross(op.cross(unit_u, unit_v), towards)
    length = op.maximum((apex_far - apex_near) * 0.5, 0.0)
    fit = op.sqrt(op.safe_div(area, np.pi * length * width))
    lens_centre = centre + op.scale(towards, (apex_far + apex_near) * 0.5)
    foot = centre + op.scale(unit_u, cone.foot_u) + op.scale(unit_v, cone.foot_v)
    new_centre = op.vselect(circle_in_light, foot, op.vselect(light_in_circle, centre, lens_centre))
    new_u = op.vselect(circle_in_light, op.scale(unit_u, cone.radius),
                       op.vselect(light_in_circle, axis_u, op.scale(towards, length * fit)))
    new_v = op.vselect(circle_in_light, op.scale(unit_v, cone.radius),
                       op.vselect(light_in_circle, axis_v, op.scale(across, width * fit)))
    average = _kernel_average(cone, position, normal, new_centre, new_u, new_v, _disk_points())
    return new_centre, new_u, new_v, op.select(misses, 0.0, average)
