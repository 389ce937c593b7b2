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
2. each lobe's LTC integral over that region at the light's radiance L, times
3. the average of w over the region weighted by that lobe's own kernel (``lobe_average``), by a
   Gauss rule on the region: on a quad 5 x 5 Gauss-Legendre points moved towards where the lobe's axis meets
   the quad's plane (``quad_points``: a narrow lobe falls between the plain rule's points), on a disk 3 radial
   x 8 angular points about the foot over the light's own disk cut by the cone's circle (``lens_samples``:
   the region shaded there is an ellipse fitted to that lens), or for a narrow lobe the quad's warped rule
   carried onto the disk (``warped_disk_rule``); exact where w is constant, and where the region is much larger
   than the cone it finds the cone.

The kernel of an LTC with inverse matrix Minv, over the light's area, is max((Minv x).z, 0) / |Minv x|^4
for x the point relative to the shading point in the shading frame (Heitz et al. 2016, eq. 1-4: the
density D(w) |det Minv| max(w_o.z, 0) / (pi |Minv w|^3) times the solid angle dA cos / |x|^2; the
constant factors cancel in the average); Lambert's is the case Minv = I, cos(receiver) cos(light) / d^2.
Weighting by each lobe's kernel rather than Lambert's matters for glossy lobes, which see the weight
near their reflection direction only (issue 27).

Against the exact integral of a Lambert receiver (numpy, seeded random lights, receivers and spreads
20-170 deg; 4 x 4 points then): quads 0.3-2.5 m at 0.5-3 m (280), median 0.06%, p90 1.7%, those in the cone's narrow part
(R < half their size) 1.3% / 4.3%; disks of radius 0.3-1 m at 0.6-2 m (91), median 1.2%, p90 8.4%, max
14%, the error in the partial overlaps, then averaged over the lens's fitted ellipse (now over the lens itself:
below) (tests/core/test_lights.py checks the quad's).  The GGX LTC over seeded quads against the dense integral of
the same LTC times w (tests/core/test_lights.py checks r = 0.4 at random spreads and r = 0.1 at 60 deg),
median / p90 / max over 40 quads, spread 60 deg: with each lobe's kernel and the warped 5 x 5 rule, r = 0.1 0.33% /
11% / 17%, r = 0.4 0.13% / 0.97% / 14%, r = 1 0.25% / 0.85% / 3.5%; the plain 5 x 5 rule (before): 5.7% / 53% / 132%,
0.21% / 1.6% / 44%, 0.13% / 0.77% / 4.0%; with Lambert's kernel, as before issue 27 (80 quads, random spreads):
15% / 119% / 4040%, 8.4% / 45% / 119% and 0.66% / 3.0% / 7%.  Disks of radius 0.3-1 m at 0.6-2 m, spread 90 deg
(30 receivers; tests/core/test_lights.py checks Lambert and r = 0.1), median / p90: Lambert 0.36% / 2.7%, r = 0.4
0.81% / 2.6%, r = 1 0.32% / 2.6% (broad lobes: ``lens_samples`` over the true overlap; averaged over the overlap's
fitted ellipse with the polar rule, before: 1.4% / 8.3%, 2.6% / 9.1%, 1.4% / 8.4%), r = 0.1 1.2% / 15% (the warped
rule; the polar rule, before: 13% / 53%).  Cost: the warped rules add IR operations to each lobe of a light with
spread (Turquin + CoD, one light: quad 2524 -> 3430, disk 2310 -> 6078; a light without spread is unchanged).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from . import shading_ops as op

#: Smallest half-spread taken (0.25 deg): below it tan(h) - h underflows float32; Cycles' own floor is 0.05 deg.
MIN_HALF_SPREAD = math.radians(0.25)
#: Largest half-spread that is a spread: at pi / 2 (Blender's 180 deg, the default) the weight is 1.
MAX_HALF_SPREAD = 0.5 * math.pi

#: Gauss-Legendre rule on [-1, 1] (numpy.polynomial.legendre.leggauss(5)): the quad's points per axis (GGX r = 0.4,
#: the test set of tests/core/test_lights.py, median / p90 / max: 4 x 4 points 0.27% / 6.7% / 15%, 5 x 5 0.06% /
#: 1.7% / 7.0%, 6 x 6 0.02% / 0.95% / 4.4%).
QUAD_NODES, QUAD_WEIGHTS = (tuple(float(x) for x in a) for a in np.polynomial.legendre.leggauss(5))
def half_spread(spread):
    """h = spread / 2 within [MIN_HALF_SPREAD, pi / 2]."""
    return op.clamp(spread * 0.5, MIN_HALF_SPREAD, MAX_HALF_SPREAD)


def spread_normalization(tan_h, h):
    """c = tan h / (tan h - h): Cycles' ``normalize_spread`` times tan h (module docstring)."""
    return op.safe_div(tan_h, tan_h - h)


def spread_weight(rho, cone_radius, normalization):
    """w = c max(1 - rho / R, 0) at the distance rho from the foot on the light's plane."""
    return op.maximum(1.0 - op.safe_div(rho, cone_radius), 0.0) * normalization


@dataclass(frozen=True)
class SpreadCone:
    """The spread's cone over the light's plane as one shading point sees it: its ``foot`` (the shading point's
    projection on the plane, world space), ``radius`` R = t tan h (t the point's distance from the plane; 1e30 at
    180 deg: ``FULL_RADIUS``, where the weight is 1 everywhere: Cycles takes tan(h) = FLT_MAX) and ``scale`` c (1 at 180 deg);
    for a disk light, ``disk``: the light's own (centre, axis_u, axis_v), over whose overlap with the cone's circle
    ``lens_samples`` averages (None: the average is over the region shaded)."""
    foot: object
    radius: object
    scale: object
    disk: tuple = None

    def weight(self, rho):
        """w at the distance rho from the foot."""
        return spread_weight(rho, self.radius, self.scale)


def spread_cone(position, location, unit_u, unit_v, spread):
    """(cone, foot_u, foot_v): the ``SpreadCone`` of a light in the plane through ``location`` spanned by the unit
    axes, and the foot's coordinates along them."""
    offset = position - location
    foot_u, foot_v = op.dot(offset, unit_u), op.dot(offset, unit_v)
    height = op.absolute(op.dot(offset, op.cross(unit_u, unit_v)))
    h = half_spread(spread)
    tan_h = op.tan(h)
    full = op.greater(spread, 2.0 * MAX_HALF_SPREAD - 1e-6)
    foot = location + op.scale(unit_u, foot_u) + op.scale(unit_v, foot_v)
    cone = SpreadCone(foot, op.select(full, FULL_RADIUS, height * tan_h),
                      op.select(full, 1.0, spread_normalization(tan_h, h)))
    return cone, foot_u, foot_v


#: R of a cone that covers the plane (spread 180 deg): 1 - rho / R rounds to 1 in float32 for every rho below 1e7 m,
#: and R^2 (the disk's lens) stays finite (no Inf for a node's Mix to turn into NaN).
FULL_RADIUS = 1e15
#: Least squared length of a rule point in the lobe's space, relative to the region's scale (a point on the
#: shading point itself): bounds the kernel below Inf.
KERNEL_FLOOR = 1e-12


#: The lobe's footprint on the quad's plane, as a fraction of the distance t along the lobe's axis to the plane,
#: times 1 / |b| (b the quad's half-extent in the lobe's space): the kernel t / (t^2 + rho^2)^2 of a plane facing
#: the axis falls to half at rho = 0.64 t.  Measured (GGX r = 0.1 / 0.4 / 1, spread 60 deg, median): 0.4: 0.59% /
#: 0.13% / 0.17%; 0.65: 0.33% / 0.13% / 0.25%; 1.0: 0.78% / 0.15% / 0.29%.
FOOTPRINT = 0.65
#: The footprint's bounds, in units of the quad's half-extent: above 3 the warp is nearly linear (the plain Gauss
#: rule, for broad lobes); 1e-3 keeps the map's asinh arguments finite for a lobe much narrower than the rule.
FOOTPRINT_BOUNDS = (1e-3, 3.0)
#: How far outside the quad (in half-extents) the lobe's axis may meet its plane and still move the points.
PEAK_LIMIT = 3.0


def _asinh(u):
    """asinh(u) = sign(u) ln(|u| + sqrt(u^2 + 1)), odd by construction (the log of the negative branch would
    cancel in float32)."""
    au = op.absolute(u)
    v = op.log2(au + op.sqrt(au * au + 1.0)) * math.log(2.0)
    return op.select(op.less(u, 0.0), -v, v)


def lobe_peak(a, b, e):
    """(x*, y*, t): where the lobe's axis (+z of its space) meets the plane of the points a + b x + e y, at the
    distance t along it (t <= 0: the plane is behind the lobe).  Cramer's rule on a + b x + e y = t z:
    x* = (e x a).z / (b x e).z, y* = (a x b).z / (b x e).z, t = a . (b x e) / (b x e).z."""
    ax, ay = op.component(a, 0), op.component(a, 1)
    bx, by = op.component(b, 0), op.component(b, 1)
    ex, ey = op.component(e, 0), op.component(e, 1)
    nz = bx * ey - by * ex
    t = op.safe_div(op.dot(a, op.cross(b, e)), nz)
    return op.safe_div(ex * ay - ey * ax, nz), op.safe_div(ax * by - ay * bx, nz), t


def warped_gauss(peak, footprint):
    """The Gauss-Legendre rule on [-1, 1] moved towards a lobe's peak: the points x(s) = peak + f sinh(A s + B) of
    the Gauss nodes s, with weights times the map's Jacobian A f cosh(A s + B); A, B make x(-1) = -1, x(1) = 1
    (A = (a1 - a0) / 2, B = (a1 + a0) / 2, a0,1 = asinh((-+1 - peak) / f)).  The points crowd within about f of the
    peak, like the lobe's kernel (1 / (1 + x^2 / f^2) after the map); for f much larger than 1 the map is linear and
    the rule is Gauss-Legendre's.  This is the sinh transformation of Johnston & Elliott 2005 ("A sinh
    transformation for evaluating nearly singular boundary element integrals", IJNME 62), applied per axis with the
    lobe's peak and footprint as its centre and width (this project's use).  Returns [(x, weight)]."""
    a0 = _asinh(op.safe_div(-1.0 - peak, footprint))
    a1 = _asinh(op.safe_div(1.0 - peak, footprint))
    slope, shift = (a1 - a0) * 0.5, (a1 + a0) * 0.5
    rule = []
    for node, weight in zip(QUAD_NODES, QUAD_WEIGHTS):
        grow, decay = op.exp(slope * node + shift), op.exp(-(slope * node + shift))
        rule.append((peak + footprint * ((grow - decay) * 0.5), slope * footprint * ((grow + decay) * 0.5) * weight))
    return rule


def lobe_footprint(a, b, e):
    """(x*, y*, f_x, f_y, faces) of the lobe whose space holds the region as a + b x + e y: where its axis meets the
    region's plane (``lobe_peak``; 0, 0 where the plane is behind the lobe: ``faces`` false) and its footprint
    there along each axis, FOOTPRINT t / |b| and t / |e| within ``FOOTPRINT_BOUNDS`` (the upper bound where it does
    not face the plane)."""
    x_peak, y_peak, t = lobe_peak(a, b, e)
    faces = op.greater(t, 0.0)
    lo, hi = FOOTPRINT_BOUNDS

    def along(extent):
        return op.select(faces, op.clamp(op.safe_div(FOOTPRINT * t, op.length(extent)), lo, hi), hi)

    return op.select(faces, x_peak, 0.0), op.select(faces, y_peak, 0.0), along(b), along(e), faces


def quad_points(a, b, e):
    """The quad's rule, points (x, y, weight) of ``centre + axis_u x + axis_v y`` over [-1, 1]^2, for the lobe whose
    space holds the quad as a + b x + e y: the warped Gauss rule of each axis (``warped_gauss``) about the point
    where the lobe's axis meets the quad's plane, with the lobe's footprint there (``lobe_footprint``; the plain
    5 x 5 Gauss rule, nearly, where the lobe is broad or faces away from the plane)."""
    x_peak, y_peak, footprint_x, footprint_y, _ = lobe_footprint(a, b, e)
    xs = warped_gauss(op.clamp(x_peak, -PEAK_LIMIT, PEAK_LIMIT), footprint_x)
    ys = warped_gauss(op.clamp(y_peak, -PEAK_LIMIT, PEAK_LIMIT), footprint_y)
    return [(x, y, wx * wy) for x, wx in xs for y, wy in ys]


def _square_from_disk(x, y):
    """The inverse of the elliptical grid map (x, y) -> (x sqrt(1 - y^2 / 2), y sqrt(1 - x^2 / 2)) of the square
    [-1, 1]^2 onto the unit disk (Fong 2015, "Analytical methods for squaring the disc"), for a point of the disk:
    x = (sqrt(2 + t + 2 sqrt(2) x) - sqrt(2 + t - 2 sqrt(2) x)) / 2, y likewise with -t and y, t = x^2 - y^2."""
    t = x * x - y * y
    k = 2.0 * math.sqrt(2.0)
    return (0.5 * op.sqrt(2.0 + t + k * x) - 0.5 * op.sqrt(2.0 + t - k * x),
            0.5 * op.sqrt(2.0 - t + k * y) - 0.5 * op.sqrt(2.0 - t - k * y))


#: How far inside the disk's rim (radius 1) the lobe's peak is pulled for the warped disk rule.
DISK_PEAK_LIMIT = 0.999
#: A lobe whose footprint (``quad_points``) is below this many of the disk's semi-axes along either axis takes the
#: warped rule, a broader one the polar rule about the cone's foot (``lens_samples``): exact along each ray for the
#: cone, where the warped rule for every lobe put a Lambert receiver 3% off, the cone's apex between its points
#: (tests/blender/test_light_model.py, spread 40 deg).
#: Validation suite, spread_disk GGX r = 0.4, median: 0.5 4.5%, 1.0 8.7%.
NARROW_FOOTPRINT = 0.5


def warped_disk_points(x_peak, y_peak, footprint_x, footprint_y):
    """The warped rule on the unit disk: ``warped_gauss`` on the square about the square's image of the lobe's peak
    (pulled into the disk), carried onto the disk by the elliptical grid map, whose Jacobian is
    (1 - (x^2 + y^2) / 2) / (sqrt(1 - x^2 / 2) sqrt(1 - y^2 / 2)) (0 only at the square's corners)."""
    radius = op.sqrt(x_peak * x_peak + y_peak * y_peak)
    pull = op.safe_div(op.minimum(radius, DISK_PEAK_LIMIT), radius)
    x_square, y_square = _square_from_disk(x_peak * pull, y_peak * pull)
    xs = [(x, w, op.sqrt(1.0 - 0.5 * x * x)) for x, w in warped_gauss(x_square, footprint_x)]
    ys = [(y, w, op.sqrt(1.0 - 0.5 * y * y)) for y, w in warped_gauss(y_square, footprint_y)]
    return [(x * y_stretch, y * x_stretch,
             wx * wy * op.safe_div(1.0 - 0.5 * (x * x + y * y), x_stretch * y_stretch))
            for x, wx, x_stretch in xs for y, wy, y_stretch in ys]


def warped_disk_rule(a, b, e):
    """(narrow, points): whether the lobe whose space holds the disk as a + b x + e y is narrow (``NARROW_FOOTPRINT``)
    and faces the disk's plane, and the warped rule's points for it (``warped_disk_points``)."""
    x_peak, y_peak, footprint_x, footprint_y, faces = lobe_footprint(a, b, e)
    narrow = op.logical_and(faces, op.less(op.minimum(footprint_x, footprint_y), NARROW_FOOTPRINT))
    return narrow, warped_disk_points(x_peak, y_peak, footprint_x, footprint_y)


#: The lens rule's Gauss-Legendre points: angles about the foot, and along each ray (``lens_samples``).
LENS_ANGLES, LENS_ANGLE_WEIGHTS = (tuple(float(x) for x in a) for a in np.polynomial.legendre.leggauss(8))
LENS_RADII, LENS_RADIAL_WEIGHTS = (tuple(float(x) for x in a) for a in np.polynomial.legendre.leggauss(3))


def lens_samples(cone, position, to_lobe, inv_size):
    """(m, weight, spread weight) of a polar rule about the cone's foot over the light's own disk (``cone.disk``) cut
    by the cone's circle: the angles that see the disk (all, or the 2 asin(1 / d) of a foot d semi-axes outside
    its bounding circle), on each ray the stretch inside the ellipse (a quadratic in rho) and within R.  The weight
    is linear along each ray, so this rule finds a disk's overlap with the cone, a lens, exactly where the region
    shaded is only its fitted ellipse (``spread_disk``).  m in the lobe's space scaled by ``inv_size`` (as
    ``lobe_average``'s); lengths in units of the disk's larger semi-axis; padded with points of weight 0 to the
    warped rule's count (``lobe_average`` picks one rule's point or the other's per point)."""
    centre, axis_u, axis_v = cone.disk
    length_u, length_v = op.length(axis_u), op.length(axis_v)
    size = op.maximum(length_u, length_v)
    unit_u, unit_v = op.normalize(axis_u), op.normalize(axis_v)
    inv_u2 = op.safe_div(size * size, length_u * length_u)
    inv_v2 = op.safe_div(size * size, length_v * length_v)
    offset = cone.foot - centre
    foot_u, foot_v = op.safe_div(op.dot(offset, unit_u), size), op.safe_div(op.dot(offset, unit_v), size)
    reach = op.safe_div(cone.radius, size)
    distance = op.sqrt(foot_u * foot_u + foot_v * foot_v)
    half_angle = op.select(op.greater(distance, 1.0), op.asin(op.safe_div(1.0, distance)), math.pi)
    towards = op.atan2(-foot_v, -foot_u)
    base = op.scale(to_lobe(cone.foot - position), inv_size)
    along_u, along_v = op.scale(to_lobe(unit_u), size * inv_size), op.scale(to_lobe(unit_v), size * inv_size)
    outside = foot_u * foot_u * inv_u2 + foot_v * foot_v * inv_v2 - 1.0
    samples = []
    for angle, angle_weight in zip(LENS_ANGLES, LENS_ANGLE_WEIGHTS):
        phi = towards + half_angle * angle
        c, s = op.cos(phi), op.sin(phi)
        # |foot + rho (c, s)| = 1 in the ellipse's metric: q2 rho^2 + q1 rho + outside = 0
        q2 = c * c * inv_u2 + s * s * inv_v2
        q1 = 2.0 * (foot_u * c * inv_u2 + foot_v * s * inv_v2)
        root = op.sqrt(q1 * q1 - 4.0 * q2 * outside)
        near = op.minimum(op.maximum(op.safe_div(-q1 - root, 2.0 * q2), 0.0), reach)
        far = op.minimum(op.maximum(op.safe_div(-q1 + root, 2.0 * q2), near), reach)
        half = (far - near) * 0.5
        direction = op.scale(along_u, c) + op.scale(along_v, s)
        for radial, radial_weight in zip(LENS_RADII, LENS_RADIAL_WEIGHTS):
            rho = near + half + half * radial
            samples.append((base + op.scale(direction, rho), half_angle * (angle_weight * radial_weight) * half * rho,
                            spread_weight(rho, reach, cone.scale)))
    return samples + [(base, 0.0, 0.0)] * (len(QUAD_NODES) ** 2 - len(samples))


def lobe_average(cone, form, centre, axis_u, axis_v, position, to_lobe):
    """The average of the spread weight over the region ``centre + axis_u x + axis_v y`` (a quad, [-1, 1]^2, or a
    disk), weighted by the rule's weight times a lobe's kernel max(m.z, 0) / |m|^4, m = ``to_lobe``(point -
    position) (module docstring; ``to_lobe`` linear: the shading frame's coordinates, then the LTC's Minv).  The
    quad's rule follows the lobe (``quad_points``); on a disk, a narrow lobe takes the warped rule
    (``warped_disk_rule``), a broad one averages over the light's own overlap with the cone (``lens_samples``).  Each point's m and its
    offset from the foot are formed as vectors (expanding their squared lengths into dot products of the three
    vectors cancels in float32 near the foot); the three vectors in the lobe's space are normalised by their size
    first (the average does not depend on it; a light 1e-6 m or 1e6 m away stays finite in float32)."""
    a, b, e = to_lobe(centre - position), to_lobe(axis_u), to_lobe(axis_v)
    inv_size = op.inverse_sqrt(op.dot(a, a) + op.dot(b, b) + op.dot(e, e), 1e-30)
    a, b, e = op.scale(a, inv_size), op.scale(b, inv_size), op.scale(e, inv_size)
    g = centre - cone.foot

    def on_region(x, y, w):
        return a + op.scale(b, x) + op.scale(e, y), w, cone.weight(op.length(g + op.scale(axis_u, x) + op.scale(axis_v, y)))

    if form == "quad":
        samples = [on_region(*point) for point in quad_points(a, b, e)]
    elif cone.disk is None:
        raise ValueError("a disk light's spread cone must carry the light's own disk (light_spread.spread_disk)")
    else:
        narrow, warped = warped_disk_rule(a, b, e)
        samples = [(op.vselect(narrow, m_warped, m_lens), op.select(narrow, w_warped, w_lens),
                    op.select(narrow, c_warped, c_lens))
                   for (m_warped, w_warped, c_warped), (m_lens, w_lens, c_lens)
                   in zip([on_region(*point) for point in warped], lens_samples(cone, position, to_lobe, inv_size))]
    total, weighted = 0.0, 0.0
    for m, w, spread_w in samples:
        m2 = op.maximum(op.dot(m, m), KERNEL_FLOOR)
        kernel = op.safe_div(op.maximum(op.component(m, 2), 0.0) * w, m2 * m2)
        total = kernel + total
        weighted = kernel * spread_w + weighted
    return op.safe_div(weighted, total)


def spread_quad(position, location, half_u, half_v, spread):
    """(centre, half_u, half_v, cone, hits): a quad light with spread as RT Lit shades it (module docstring): the
    quad clamped to the cone's square (centre and half-extent vectors, zero when the square misses the light), its
    ``SpreadCone`` and 1.0 where the square meets the light (0.0 else).  ``half_u``, ``half_v``: the light's
    orthogonal half-extent vectors (``lights._area_axes``)."""
    a, b = op.length(half_u), op.length(half_v)
    unit_u, unit_v = op.normalize(half_u), op.normalize(half_v)
    cone, foot_u, foot_v = spread_cone(position, location, unit_u, unit_v, spread)
    u0, u1 = op.maximum(foot_u - cone.radius, -a), op.minimum(foot_u + cone.radius, a)
    v0, v1 = op.maximum(foot_v - cone.radius, -b), op.minimum(foot_v + cone.radius, b)
    hits = op.logical_and(op.greater(u1, u0), op.greater(v1, v0))
    centre = location + op.scale(unit_u, (u0 + u1) * 0.5) + op.scale(unit_v, (v0 + v1) * 0.5)
    eu = op.scale(unit_u, op.maximum(u1 - u0, 0.0) * 0.5)
    ev = op.scale(unit_v, op.maximum(v1 - v0, 0.0) * 0.5)
    return centre, eu, ev, cone, op.select(hits, 1.0, 0.0)


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


def spread_disk(position, centre, axis_u, axis_v, spread):
    """(centre, axis_u, axis_v, cone, hits) of a disk or ellipse light with spread (module docstring): the region it
    emits from is the light clipped to the cone's circle of radius R about the foot: the circle where it lies inside
    the light, the light where it lies inside the circle, and where they overlap in part the ellipse spanning the
    lens between its apexes and across its width, scaled to the lens's area (an ellipse light taken as the circle
    of its area there); the cone and hits as ``spread_quad``'s."""
    a, b = op.length(axis_u), op.length(axis_v)
    unit_u, unit_v = op.normalize(axis_u), op.normalize(axis_v)
    cone, foot_u, foot_v = spread_cone(position, centre, unit_u, unit_v, spread)
    # the circle lies inside the ellipse if the foot is at least R inside it along the ellipse's smaller axis
    inside = op.length(op.vec3(op.safe_div(foot_u, a), op.safe_div(foot_v, b), 0.0))
    circle_in_light = op.less(inside + op.safe_div(cone.radius, op.minimum(a, b)), 1.0)
    d = op.length(op.vec3(foot_u, foot_v, 0.0))
    light_in_circle = op.less(d + op.maximum(a, b), cone.radius)
    radius = op.sqrt(a * b)
    misses = op.greater(d, radius + cone.radius)
    # partial overlap: the lens of the light's equal-area circle and the cone's circle
    area, apex_far, apex_near, width = _lens(radius, cone.radius, op.maximum(d, 1e-12))
    towards = op.normalize(op.scale(unit_u, foot_u) + op.scale(unit_v, foot_v))
    across = op.cross(op.cross(unit_u, unit_v), towards)
    length = op.maximum((apex_far - apex_near) * 0.5, 0.0)
    fit = op.sqrt(op.safe_div(area, np.pi * length * width))
    lens_centre = centre + op.scale(towards, (apex_far + apex_near) * 0.5)
    new_centre = op.vselect(circle_in_light, cone.foot, op.vselect(light_in_circle, centre, lens_centre))
    new_u = op.vselect(circle_in_light, op.scale(unit_u, cone.radius),
                       op.vselect(light_in_circle, axis_u, op.scale(towards, length * fit)))
    new_v = op.vselect(circle_in_light, op.scale(unit_v, cone.radius),
                       op.vselect(light_in_circle, axis_v, op.scale(across, width * fit)))
    return new_centre, new_u, new_v, replace(cone, disk=(centre, axis_u, axis_v)), op.select(misses, 0.0, 1.0)
