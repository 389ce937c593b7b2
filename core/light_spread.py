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
   the quad's plane (``QUAD_RULE``: a narrow lobe falls between the plain rule's points), on a disk 3 radial
   x 8 angular points about the foot over the light's own disk cut by the cone's circle (``DISK_RULE``:
   the region shaded there is an ellipse fitted to that lens), or for a narrow lobe the quad's warped rule
   carried onto the disk (``DISK_RULE``); exact where w is constant, and where the region is much larger
   than the cone it finds the cone.

Lambert's lobe under a disk or ellipse needs no LTC and no average: its integral of the clamped cosine times w is
exact along each ray about the foot, and only the rays' direction is a quadrature (``LAMBERT_DISK``, at the end).

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
0.81% / 2.6%, r = 1 0.32% / 2.6% (broad lobes: ``DISK_RULE`` over the true overlap; averaged over the overlap's
fitted ellipse with the polar rule, before: 1.4% / 8.3%, 2.6% / 9.1%, 1.4% / 8.4%), r = 0.1 1.2% / 15% (the warped
rule; the polar rule, before: 13% / 53%).  Cost: the rules add IR operations to each lobe of a light with spread
(``rt_lit.op_counts``, Turquin + CoD, one light, 2026-12-07: quad 3553, disk 6901, against 1254 and 1225 without
spread; the warped rules' first version took a quad from 2524 to 3430 and a disk from 2310 to 6078).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from . import shading_ops as op
from .ir.functions import NodeFunction
from .ir.interface import scalar, vector

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
    ``DISK_RULE`` averages (None: the average is over the region shaded)."""
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
#: A lobe whose footprint (``lobe_footprint``) is below this many of the disk's semi-axes along either axis takes the
#: warped rule, a broader one the polar rule about the cone's foot (``DISK_RULE``): exact along each ray for the
#: cone, where the warped rule for every lobe put a Lambert receiver 3% off, the cone's apex between its points
#: (tests/blender/test_light_model.py, spread 40 deg).
#: Validation suite, spread_disk GGX r = 0.4, median: 0.5 4.5%, 1.0 8.7%.
NARROW_FOOTPRINT = 0.5


def warped_disk_axes(x_peak, y_peak, footprint_x, footprint_y):
    """The warped rule on the unit disk, per axis: ``warped_gauss`` on the square about the square's image of the
    lobe's peak (pulled into the disk), [(x, weight, sqrt(1 - x^2 / 2))] along each axis of the square; the points are
    their products carried onto the disk by the elliptical grid map (``disk_grid_point``)."""
    radius = op.sqrt(x_peak * x_peak + y_peak * y_peak)
    pull = op.safe_div(op.minimum(radius, DISK_PEAK_LIMIT), radius)
    x_square, y_square = _square_from_disk(x_peak * pull, y_peak * pull)
    xs = [(x, w, op.sqrt(1.0 - 0.5 * x * x)) for x, w in warped_gauss_rule(x_square, footprint_x)]
    ys = [(y, w, op.sqrt(1.0 - 0.5 * y * y)) for y, w in warped_gauss_rule(y_square, footprint_y)]
    return xs, ys


def disk_grid_point(x, wx, x_stretch, y, wy, y_stretch):
    """(x', y', weight): the point (x, y) of the square carried onto the disk by the elliptical grid map, its weight
    times the map's Jacobian (1 - (x^2 + y^2) / 2) / (sqrt(1 - x^2 / 2) sqrt(1 - y^2 / 2)) (0 only at the square's
    corners)."""
    return (x * y_stretch, y * x_stretch,
            wx * wy * op.safe_div(1.0 - 0.5 * (x * x + y * y), x_stretch * y_stretch))


def warped_disk_rule(a, b, e):
    """(narrow, xs, ys): whether the lobe whose space holds the disk as a + b x + e y is narrow (``NARROW_FOOTPRINT``)
    and faces the disk's plane, and the warped rule's axes for it (``warped_disk_axes``)."""
    x_peak, y_peak, footprint_x, footprint_y, faces = lobe_footprint(a, b, e)
    narrow = op.logical_and(faces, op.less(op.minimum(footprint_x, footprint_y), NARROW_FOOTPRINT))
    return (narrow, *warped_disk_axes(x_peak, y_peak, footprint_x, footprint_y))


#: The lens rule's Gauss-Legendre points: angles about the foot, and along each ray (``_lens_ray``).
LENS_ANGLES, LENS_ANGLE_WEIGHTS = (tuple(float(x) for x in a) for a in np.polynomial.legendre.leggauss(8))
LENS_RADII, LENS_RADIAL_WEIGHTS = (tuple(float(x) for x in a) for a in np.polynomial.legendre.leggauss(3))


# --- the rules as node functions -------------------------------------------------------------------------------
# The rules are node functions (node groups shared by every lobe and light; functions in shader text) of at most
# addon/node_emit.py's MAX_GROUP_NODES nodes each: written inline, a disk light's rule made each lobe of it one flat
# group of 1,800-3,200 nodes, which Blender took 78-137 s to build for one Lambert material (docs/blender.md, "Node
# groups").  The values are the same to the bit: the same operations in the same order, the running sums passed from
# point to point.

def _sockets(vectors, scalars):
    out = {name: vector(text) for name, text in vectors.items()}
    out.update({name: scalar(0.0, text) for name, text in scalars.items()})
    return out


def _warped_gauss(**kw):
    rule = warped_gauss(kw["Peak"], kw["Footprint"])
    return {**{f"X {i}": x for i, (x, _) in enumerate(rule)}, **{f"Weight {i}": w for i, (_, w) in enumerate(rule)}}


WARPED_GAUSS = NodeFunction(
    "RTL Spread Warped Gauss", _warped_gauss,
    _sockets({}, {"Peak": "Where the lobe's axis meets the axis, in units of the half-extent",
                  "Footprint": "The lobe's footprint along the axis, in units of the half-extent"}),
    {**{f"X {i}": scalar(0.0, f"Point {i}") for i in range(len(QUAD_NODES))},
     **{f"Weight {i}": scalar(0.0, f"Weight of point {i}") for i in range(len(QUAD_NODES))}},
    "Gauss-Legendre points on [-1, 1] moved towards a lobe's peak by a sinh map (Johnston & Elliott 2005; "
    "core/light_spread.py, warped_gauss)")


def warped_gauss_rule(peak, footprint):
    """``warped_gauss`` as one call of ``WARPED_GAUSS``: [(x, weight)]."""
    out = WARPED_GAUSS(Peak=peak, Footprint=footprint)
    return [(out[f"X {i}"], out[f"Weight {i}"]) for i in range(len(QUAD_NODES))]


def kernel_terms(m, w, spread_w):
    """(kernel, kernel x spread weight) of one rule point at m in the lobe's space with the rule's weight w: the
    lobe's kernel max(m.z, 0) w / |m|^4 (module docstring), |m|^2 at least KERNEL_FLOOR."""
    m2 = op.maximum(op.dot(m, m), KERNEL_FLOOR)
    kernel = op.safe_div(op.maximum(op.component(m, 2), 0.0) * w, m2 * m2)
    return kernel, kernel * spread_w


#: The running sums a rule's points pass on (each point adds its kernel terms in order).
_SUMS = {"Total": scalar(0.0, "The rule's sum of the kernel"),
         "Weighted": scalar(0.0, "The rule's sum of the kernel times the spread's weight")}
_SUM_TEXTS = {"Total": "The kernel summed over the points before", "Weighted": "The weighted kernel, likewise"}


def _add_point(kw, kernel, weighted):
    """The running sums with one point's kernel terms added."""
    return {"Total": kernel + kw["Total"], "Weighted": weighted + kw["Weighted"]}


def _region_point(**kw):
    """One point of the region ``centre + axis_u x + axis_v y``: its kernel terms (``kernel_terms``) at m = (a + b x) +
    e y in the lobe's space, the spread's weight at its distance |(g + axis_u x) + axis_v y| from the cone's foot (g
    the centre's offset from the foot), added to the running sums.  The parts along each axis are inputs, so that a
    rule on a grid forms each once (``_quad_rule``)."""
    rho = op.length(kw["Foot X"] + kw["Foot Y"])
    return _add_point(kw, *kernel_terms(kw["Lobe X"] + kw["Lobe Y"], kw["Weight"],
                                        spread_weight(rho, kw["Cone Radius"], kw["Cone Scale"])))


_CONE_SCALARS = {"Cone Radius": "The spread cone's radius R on the light's plane",
                 "Cone Scale": "The spread's normalisation c"}

REGION_POINT = NodeFunction(
    "RTL Spread Region Point", _region_point,
    _sockets({"Lobe X": "A + B x: the point's part along its first axis, in the lobe's space",
              "Lobe Y": "E y: its part along the second", "Foot X": "G + Axis U x: from the cone's foot, world",
              "Foot Y": "Axis V y"}, {"Weight": "The rule's weight of the point", **_CONE_SCALARS, **_SUM_TEXTS}),
    _SUMS, "One point of a spread rule on a quad: the lobe's kernel and the spread's weight there, added to the "
           "running sums (core/light_spread.py)")


def _quad_row(**kw):
    """The five points of the quad's rule at one x, added to the running sums in order (``REGION_POINT``)."""
    sums = {"Total": kw["Total"], "Weighted": kw["Weighted"]}
    for j in range(len(QUAD_NODES)):
        sums = REGION_POINT(**{"Lobe X": kw["Lobe X"], "Foot X": kw["Foot X"], "Lobe Y": kw[f"Lobe Y {j}"],
                               "Foot Y": kw[f"Foot Y {j}"], "Weight": kw["X Weight"] * kw[f"Y Weight {j}"],
                               "Cone Radius": kw["Cone Radius"], "Cone Scale": kw["Cone Scale"], **sums})
    return sums


QUAD_ROW = NodeFunction(
    "RTL Spread Quad Row", _quad_row,
    _sockets({"Lobe X": "A + B x in the lobe's space", "Foot X": "G + Axis U x (world)",
              **{f"{name} {j}": f"{text} of point {j}" for j in range(len(QUAD_NODES))
                 for name, text in (("Lobe Y", "E y"), ("Foot Y", "Axis V y"))}},
             {"X Weight": "The row's weight", **{f"Y Weight {j}": f"The weight of point {j}"
                                                 for j in range(len(QUAD_NODES))},
              **_CONE_SCALARS, **_SUM_TEXTS}),
    _SUMS, "One row of the spread's rule on a quad, added to the running sums (core/light_spread.py)")

#: The region's geometry every rule on it takes (``lobe_average``).
_REGION_VECTORS = {"A": "The region's centre in the lobe's space, scaled (lobe_average)",
                   "B": "The region's first half-axis in the lobe's space, scaled",
                   "E": "The region's second half-axis in the lobe's space, scaled",
                   "G": "The region's centre less the cone's foot (world)",
                   "Axis U": "The region's first half-axis (world)", "Axis V": "The region's second half-axis (world)"}


def _quad_rule(**region):
    """The quad's rule over [-1, 1]^2, for the lobe whose space holds the quad as a + b x + e y: the warped Gauss rule
    of each axis (``warped_gauss``) about the point where the lobe's axis meets the quad's plane, with the lobe's
    footprint there (``lobe_footprint``; the plain 5 x 5 Gauss rule, nearly, where the lobe is broad or faces away
    from the plane); each axis's parts of the points formed once, the rows summed in order (``QUAD_ROW``)."""
    x_peak, y_peak, footprint_x, footprint_y, _ = lobe_footprint(region["A"], region["B"], region["E"])
    xs = warped_gauss_rule(op.clamp(x_peak, -PEAK_LIMIT, PEAK_LIMIT), footprint_x)
    ys = warped_gauss_rule(op.clamp(y_peak, -PEAK_LIMIT, PEAK_LIMIT), footprint_y)
    columns = {}
    for j, (y, wy) in enumerate(ys):
        columns.update({f"Lobe Y {j}": op.scale(region["E"], y), f"Foot Y {j}": op.scale(region["Axis V"], y),
                        f"Y Weight {j}": wy})
    sums = {"Total": 0.0, "Weighted": 0.0}
    for x, wx in xs:
        sums = QUAD_ROW(**{"Lobe X": region["A"] + op.scale(region["B"], x),
                           "Foot X": region["G"] + op.scale(region["Axis U"], x), "X Weight": wx, **columns,
                           "Cone Radius": region["Cone Radius"], "Cone Scale": region["Cone Scale"], **sums})
    return sums


QUAD_RULE = NodeFunction(
    "RTL Spread Quad Rule", _quad_rule, _sockets(_REGION_VECTORS, _CONE_SCALARS), _SUMS,
    "The spread's rule on a quad: the warped 5 x 5 Gauss rule about the lobe's peak (core/light_spread.py, "
    "_quad_rule)")

#: The square's axes of the warped disk rule (``warped_disk_axes``): per axis its points, weights and stretches.
_AXES = {f"{axis} {part} {i}": f"The square's {axis.lower()}-axis {part.lower()} {i}"
         for axis in ("X", "Y") for part in ("Node", "Weight", "Stretch") for i in range(len(QUAD_NODES))}


def _disk_warped_axes(**kw):
    narrow, xs, ys = warped_disk_rule(kw["A"], kw["B"], kw["E"])
    out = {"Narrow": op.select(narrow, 1.0, 0.0)}
    for axis, values in (("X", xs), ("Y", ys)):
        for i, point in enumerate(values):
            out.update({f"{axis} {part} {i}": v for part, v in zip(("Node", "Weight", "Stretch"), point)})
    return out


DISK_WARPED_AXES = NodeFunction(
    "RTL Spread Disk Warped Axes", _disk_warped_axes, _sockets({k: _REGION_VECTORS[k] for k in "ABE"}, {}),
    {"Narrow": scalar(0.0, "1 where the lobe is narrow and faces the disk (NARROW_FOOTPRINT): the warped rule"),
     **{name: scalar(0.0, text) for name, text in _AXES.items()}},
    "The warped disk rule's axes on the square (core/light_spread.py, warped_disk_rule)")

#: A lens-rule point before its kernel: where it lies in the lobe's space, the rule's weight, the spread's weight.
_POINT = {"M": vector("The point in the lobe's space"), "Weight": scalar(0.0, "The rule's weight of the point"),
          "Spread Weight": scalar(0.0, "The spread's weight at the point")}


def _disk_point(**kw):
    """A point of the disk's rule, added to the running sums: for a narrow lobe the warped rule's, the square's
    point (x, y) carried onto the disk (``disk_grid_point``), else the lens rule's (given)."""
    x, y, w = disk_grid_point(kw["X"], kw["X Weight"], kw["X Stretch"], kw["Y"], kw["Y Weight"], kw["Y Stretch"])
    (lobe_x, foot_x), (lobe_y, foot_y) = _point_parts(kw, x, y)
    spread_w = spread_weight(op.length(foot_x + foot_y), kw["Cone Radius"], kw["Cone Scale"])
    narrow = kw["Narrow"]
    return _add_point(kw, *kernel_terms(op.vselect(narrow, lobe_x + lobe_y, kw["M Lens"]),
                                        op.select(narrow, w, kw["Weight Lens"]),
                                        op.select(narrow, spread_w, kw["Spread Weight Lens"])))


def _point_parts(region, x, y):
    """The parts along each axis of the point (x, y) of ``centre + axis_u x + axis_v y``: ((a + b x, g + axis_u x),
    (e y, axis_v y)), in the lobe's space and from the cone's foot."""
    return ((region["A"] + op.scale(region["B"], x), region["G"] + op.scale(region["Axis U"], x)),
            (op.scale(region["E"], y), op.scale(region["Axis V"], y)))


DISK_POINT = NodeFunction(
    "RTL Spread Disk Point", _disk_point,
    _sockets(_REGION_VECTORS, {"Narrow": "1: the warped rule's point, 0: the lens rule's",
                               **{f"{axis}{part}": f"The square's {axis.lower()}-axis {what}"
                                  for axis in ("X", "Y") for part, what in (("", "node"), (" Weight", "weight"),
                                                                           (" Stretch", "stretch"))},
                               **_CONE_SCALARS, **_SUM_TEXTS})
    | {f"{name} Lens": socket for name, socket in _POINT.items()},
    _SUMS, "One point of the spread's rule on a disk, the warped rule's or the lens rule's, added to the running sums "
           "(core/light_spread.py)")

#: The lens rule's inputs (``lens_inputs``): the foot and the disk's axes in the lobe's space, the disk in units of
#: its larger semi-axis.
_LENS_VECTORS = {"Base": "The cone's foot in the lobe's space, scaled (lobe_average)",
                 "Along U": "The disk's first unit axis in the lobe's space, times its larger semi-axis, scaled",
                 "Along V": "The disk's second unit axis in the lobe's space, likewise"}
_LENS_SCALARS = {"Foot U": "The foot along the disk's first axis, in units of its larger semi-axis",
                 "Foot V": "The foot along the second axis, likewise",
                 "Inv U2": "(larger semi-axis / first semi-axis)^2", "Inv V2": "(larger semi-axis / second semi-axis)^2",
                 "Reach": "The cone's radius in units of the disk's larger semi-axis"}
_RAY_SCALARS = {"Outside": "The foot's level in the ellipse's metric less 1 (> 0: outside the disk)",
                "Towards": "The angle towards the disk's centre", "Half Angle": "Half the angle that sees the disk",
                "Node": "The ray's Gauss-Legendre node in [-1, 1]", "Cone Scale": "The spread's normalisation c"}
_RAY_WEIGHTS = {f"Weight {j}": f"The ray's angular weight times its point {j}'s radial weight" for j in range(3)}


def _lens_ray(**kw):
    """The lens rule's three points on the ray at the angle towards + half_angle node about the foot: the stretch
    of the ray inside the ellipse (a quadratic in rho) and within the reach, by Gauss-Legendre."""
    inv_u2, inv_v2, foot_u, foot_v = kw["Inv U2"], kw["Inv V2"], kw["Foot U"], kw["Foot V"]
    phi = kw["Towards"] + kw["Half Angle"] * kw["Node"]
    c, s = op.cos(phi), op.sin(phi)
    # |foot + rho (c, s)| = 1 in the ellipse's metric: q2 rho^2 + q1 rho + outside = 0
    q2 = c * c * inv_u2 + s * s * inv_v2
    q1 = 2.0 * (foot_u * c * inv_u2 + foot_v * s * inv_v2)
    root = op.sqrt(q1 * q1 - 4.0 * q2 * kw["Outside"])
    near = op.minimum(op.maximum(op.safe_div(-q1 - root, 2.0 * q2), 0.0), kw["Reach"])
    far = op.minimum(op.maximum(op.safe_div(-q1 + root, 2.0 * q2), near), kw["Reach"])
    half = (far - near) * 0.5
    direction = op.scale(kw["Along U"], c) + op.scale(kw["Along V"], s)
    out = {}
    for j, radial in enumerate(LENS_RADII):
        rho = near + half + half * radial
        out[f"M {j}"] = kw["Base"] + op.scale(direction, rho)
        out[f"Weight {j}"] = kw["Half Angle"] * kw[f"Weight {j}"] * half * rho
        out[f"Spread Weight {j}"] = spread_weight(rho, kw["Reach"], kw["Cone Scale"])
    return out


LENS_RAY = NodeFunction(
    "RTL Spread Lens Ray", _lens_ray, _sockets(_LENS_VECTORS, {**_LENS_SCALARS, **_RAY_SCALARS, **_RAY_WEIGHTS}),
    {f"{name} {j}": socket for j in range(3) for name, socket in _POINT.items()},
    "Three points of the spread's lens rule on one ray about the cone's foot (core/light_spread.py, _disk_rule)")


def _lens_points(kw):
    """The lens rule's points [(m, weight, spread weight)] (``LENS_RAY``), padded with points of weight 0 to the
    warped rule's count: a polar rule about the cone's foot over the light's own disk cut by the cone's circle, the
    angles that see the disk (all, or the 2 asin(1 / d) of a foot d semi-axes outside its bounding circle), on each
    ray the stretch inside the ellipse and within R.  The weight is linear along each ray, so this rule finds a
    disk's overlap with the cone, a lens, exactly where the region shaded is only its fitted ellipse
    (``spread_disk``)."""
    foot_u, foot_v = kw["Foot U"], kw["Foot V"]
    distance = op.sqrt(foot_u * foot_u + foot_v * foot_v)
    ray = {name: kw[name] for name in (*_LENS_VECTORS, *_LENS_SCALARS, "Cone Scale")}
    ray["Half Angle"] = op.select(op.greater(distance, 1.0), op.asin(op.safe_div(1.0, distance)), math.pi)
    ray["Towards"] = op.atan2(-foot_v, -foot_u)
    ray["Outside"] = foot_u * foot_u * kw["Inv U2"] + foot_v * foot_v * kw["Inv V2"] - 1.0
    points = []
    for angle, angle_weight in zip(LENS_ANGLES, LENS_ANGLE_WEIGHTS):
        out = LENS_RAY(**ray, Node=angle, **{f"Weight {j}": angle_weight * radial_weight
                                             for j, radial_weight in enumerate(LENS_RADIAL_WEIGHTS)})
        points += [(out[f"M {j}"], out[f"Weight {j}"], out[f"Spread Weight {j}"]) for j in range(len(LENS_RADII))]
    return points + [(kw["Base"], 0.0, 0.0)] * (len(QUAD_NODES) ** 2 - len(points))


def _disk_rule(**kw):
    """A narrow lobe's warped rule (``DISK_WARPED_AXES``) or a broad one's lens rule (``_lens_points``), point by point
    (``DISK_POINT``), summed in order."""
    region = {name: kw[name] for name in (*_REGION_VECTORS, *_CONE_SCALARS)}
    axes = DISK_WARPED_AXES(A=kw["A"], B=kw["B"], E=kw["E"])
    grid = [(i, j) for i in range(len(QUAD_NODES)) for j in range(len(QUAD_NODES))]
    sums = {"Total": 0.0, "Weighted": 0.0}
    for (i, j), (m, w, spread_w) in zip(grid, _lens_points(kw)):
        square = {f"X{part}": axes[f"X {name} {i}"] for part, name in (("", "Node"), (" Weight", "Weight"),
                                                                       (" Stretch", "Stretch"))}
        square.update({f"Y{part}": axes[f"Y {name} {j}"] for part, name in (("", "Node"), (" Weight", "Weight"),
                                                                            (" Stretch", "Stretch"))})
        sums = DISK_POINT(**region, **square, Narrow=axes["Narrow"], **{"M Lens": m, "Weight Lens": w,
                                                                       "Spread Weight Lens": spread_w}, **sums)
    return sums


DISK_RULE = NodeFunction(
    "RTL Spread Disk Rule", _disk_rule,
    _sockets({**_REGION_VECTORS, **_LENS_VECTORS}, {**_CONE_SCALARS, **_LENS_SCALARS}), _SUMS,
    "The spread's rule on a disk: for a narrow lobe the quad's warped rule carried onto the disk, for a broad one "
    "8 angles x 3 radii about the cone's foot over the disk's overlap with the cone (core/light_spread.py)")


def lens_inputs(cone, position, to_lobe, inv_size):
    """The lens rule's inputs of ``DISK_RULE`` for the light's own disk (``cone.disk``): m in the lobe's space scaled by
    ``inv_size`` (as ``lobe_average``'s); lengths in units of the disk's larger semi-axis."""
    centre, axis_u, axis_v = cone.disk
    length_u, length_v = op.length(axis_u), op.length(axis_v)
    size = op.maximum(length_u, length_v)
    unit_u, unit_v = op.normalize(axis_u), op.normalize(axis_v)
    offset = cone.foot - centre
    return {"Base": op.scale(to_lobe(cone.foot - position), inv_size),
            "Along U": op.scale(to_lobe(unit_u), size * inv_size),
            "Along V": op.scale(to_lobe(unit_v), size * inv_size),
            "Foot U": op.safe_div(op.dot(offset, unit_u), size), "Foot V": op.safe_div(op.dot(offset, unit_v), size),
            "Inv U2": op.safe_div(size * size, length_u * length_u),
            "Inv V2": op.safe_div(size * size, length_v * length_v),
            "Reach": op.safe_div(cone.radius, size)}


def lobe_average(cone, form, centre, axis_u, axis_v, position, to_lobe):
    """The average of the spread weight over the region ``centre + axis_u x + axis_v y`` (a quad, [-1, 1]^2, or a
    disk), weighted by the rule's weight times a lobe's kernel max(m.z, 0) / |m|^4, m = ``to_lobe``(point -
    position) (module docstring; ``to_lobe`` linear: the shading frame's coordinates, then the LTC's Minv).  The
    quad's rule follows the lobe (``QUAD_RULE``); on a disk, a narrow lobe takes the warped rule
    (``DISK_RULE``), a broad one averages over the light's own overlap with the cone (its lens rule).
    Each point's m and its offset from the foot are formed as vectors (expanding their squared lengths into dot
    products of the three vectors cancels in float32 near the foot); the three vectors in the lobe's space are
    normalised by their size first (the average does not depend on it; a light 1e-6 m or 1e6 m away stays finite in
    float32)."""
    a, b, e = to_lobe(centre - position), to_lobe(axis_u), to_lobe(axis_v)
    inv_size = op.inverse_sqrt(op.dot(a, a) + op.dot(b, b) + op.dot(e, e), 1e-30)
    region = {"A": op.scale(a, inv_size), "B": op.scale(b, inv_size), "E": op.scale(e, inv_size),
              "G": centre - cone.foot, "Axis U": axis_u, "Axis V": axis_v,
              "Cone Radius": cone.radius, "Cone Scale": cone.scale}
    if form == "quad":
        rule = QUAD_RULE(**region)
        return op.safe_div(rule["Weighted"], rule["Total"])
    if cone.disk is None:
        raise ValueError("a disk light's spread cone must carry the light's own disk (light_spread.spread_disk)")
    rule = DISK_RULE(**region, **lens_inputs(cone, position, to_lobe, inv_size))
    return op.safe_div(rule["Weighted"], rule["Total"])


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
    # it misses where the foot is farther than R from the ellipse: at least (inside - 1) min(a, b) away, the map to
    # the unit circle shrinking no distance by more than min(a, b) (the equal-area circle, d > sqrt(a b) + R, culled a
    # thin ellipse's light along its length)
    misses = op.greater((inside - 1.0) * op.minimum(a, b), cone.radius)
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


# --- Lambert under a disk light with spread: exact along each ray -------------------------------------------------
# For the clamped cosine the spread's integral over the disk has a closed form along every ray from the cone's foot
# (this project's construction).  With the foot f at the distance t from the shading point p, a point of the light's
# plane q = f + rho d (d a unit direction in the plane at the angle phi), theta its angle from the light's axis seen
# from p (tan theta = rho / t, so the spread's weight is c (1 - tan theta / tan h)) and N the receiver's normal,
# cos = (a sin theta + b cos theta) with a = d.N and b = N along the unit vector from p to f, and dw = sin theta
# d theta d phi, so
#     int cos w dw / pi = (c / pi) int dphi int (a sin^2 + b sin cos - (a sin^3 / cos + b sin^2) / tan h) d theta
# between the ray's entry and exit (the ellipse's quadratic, the cone's radius R = t tan h, the horizon
# a tan theta + b >= 0): three closed forms (``angular_moments``), written so that narrow spreads (small angles) do
# not cancel in float32.  Only the angle phi is a quadrature, in the angle psi of an importance ellipse (semi-axes
# A, B: the light's own cut to the cone's reach, each x carried to sqrt(ln(1 + x^2 / t^2)), how the radial integral
# grows with a ray's length: as x^2 where rays are short against the height, slowly where long; the rays are
# (A cos psi, B sin psi) / |.|, so they follow the light's shape where it is seen from afar and spread round the foot
# where it is seen from close): Gauss-Legendre over the angles that see the ellipse (psi = centre + half sin(pi s / 2):
# the sine removes the square root with which the chord opens at the tangent rays), or the midpoint rule round the
# foot where it lies inside the light (periodic, and smooth but where the cone's circle crosses the rim or the
# horizon).  Against dense integrals (numpy, 16 rays; tests/core/test_lights.py, docs/benchmarks/spread.md): median /
# p90 0.001% / 0.037% over disks and ellipses at 20-170 deg, where DISK_RULE's lens rule (the weight's average under
# the kernel) was at 0.95% / 3.5% at 40 deg; over ellipses 1:10 to 1:1000 seen from 0.1-10x their width 0.16% / 1.4%
# (rays even in the light's own angle, as first written: all but a few along a thin ellipse's length, 6x too bright
# 0.6 mm under a 0.24 mm one).

#: Rays of the Lambert rule: Gauss-Legendre nodes and weights on [-1, 1] (the foot outside the light's ellipse) and
#: the midpoint rule's (inside it), per ray.
LAMBERT_RAYS = 16
LAMBERT_GAUSS = tuple(zip(*(tuple(float(x) for x in a) for a in np.polynomial.legendre.leggauss(LAMBERT_RAYS))))
LAMBERT_MIDPOINTS = tuple(((2 * i + 1) / LAMBERT_RAYS - 1.0, 2.0 / LAMBERT_RAYS) for i in range(LAMBERT_RAYS))


def _x_minus_sin(x):
    """x - sin x for x >= 0 without cancellation: its Taylor series below 0.5 (to x^9, relative error below 1e-9
    there), the difference above."""
    x2 = x * x
    series = x * x2 * (1.0 / 6.0) * (1.0 - x2 * (1.0 / 20.0) * (1.0 - x2 * (1.0 / 42.0) * (1.0 - x2 * (1.0 / 72.0))))
    return op.select(op.less(x, 0.5), series, x - op.sin(x))


def _log_secant_less_half_sin2(s, q_over_t2):
    """g(s) = -ln(cos theta) - s / 2 for s = sin^2 theta, given 1 / cos^2 theta = q / t^2 (exact where s is near 1):
    its series sum_{k>=2} s^k / (2k) below s = 0.1 (to s^8, relative error below 2e-8 there), the difference above."""
    series = s * s * (0.25 + s * (1.0 / 6.0 + s * (0.125 + s * (0.1 + s * (1.0 / 12.0 + s * (1.0 / 14.0
                                                                                         + s * 0.0625))))))
    direct = op.log2(q_over_t2) * (0.5 * math.log(2.0)) - 0.5 * s
    return op.select(op.less(s, 0.1), series, direct)


def angular_moments(near, far, t):
    """(J1, J2, J3): the integrals of sin^2, sin cos and sin^3 / cos over theta from atan(near / t) to atan(far / t)
    (theta the angle of a point of the light's plane from its axis, seen from the shading point), each in a form that
    does not cancel where the angles are small or close: with D = the angles' difference and S their sum,
    J1 = ((D - sin D) + 2 sin^2(S / 2) sin D) / 2, J2 = sin D sin S / 2, J3 = g(sin^2 far) - g(sin^2 near)
    (``_log_secant_less_half_sin2``)."""
    t2 = t * t
    theta_near, theta_far = op.atan2(near, t), op.atan2(far, t)
    diff = op.atan2((far - near) * t, t2 + far * near)
    total = theta_far + theta_near
    sin_diff, half_sin = op.sin(diff), op.sin(total * 0.5)
    j1 = 0.5 * (_x_minus_sin(diff) + 2.0 * half_sin * half_sin * sin_diff)
    j2 = 0.5 * sin_diff * op.sin(total)
    q_far, q_near = far * far + t2, near * near + t2
    j3 = (_log_secant_less_half_sin2(op.safe_div(far * far, q_far), op.safe_div(q_far, t2))
          - _log_secant_less_half_sin2(op.safe_div(near * near, q_near), op.safe_div(q_near, t2)))
    return j1, j2, j3


def _angular_moments(**kw):
    return dict(zip(("J1", "J2", "J3"), angular_moments(kw["Near"], kw["Far"], kw["Height"])))


ANGULAR_MOMENTS = NodeFunction(
    "RTL Spread Angular Moments", _angular_moments,
    _sockets({}, {"Near": "Where the ray enters, from the foot", "Far": "Where it leaves",
                  "Height": "The shading point's distance from the plane, in the same units"}),
    {"J1": scalar(0.0, "The integral of sin^2 over the angle from the light's axis"),
     "J2": scalar(0.0, "The integral of sin cos"), "J3": scalar(0.0, "The integral of sin^3 / cos")},
    "The angular moments of one ray of the Lambert rule under a disk light with spread (core/light_spread.py)")


def _lambert_ray(**kw):
    """One ray of the Lambert rule: its angle psi in the importance ellipse's coordinates carried to the plane's
    direction (A cos psi, B sin psi) / |.| with the map's Jacobian A B / |.|^2; its entry and exit (the light's
    ellipse met in its own unit-circle coordinates, the cone's reach, the receiver's horizon) and the closed-form
    radial integral, times the ray's angular weight."""
    outside = op.greater(kw["Outside"], 0.0)
    node = op.select(outside, kw["Gauss Node"], kw["Midpoint Node"])
    bend = node * (0.5 * math.pi)
    psi = kw["Towards"] + op.select(outside, kw["Half Angle"] * op.sin(bend), math.pi * node)
    angular = op.select(outside, kw["Half Angle"] * (0.5 * math.pi) * op.cos(bend) * kw["Gauss Weight"],
                        math.pi * kw["Midpoint Weight"])
    dx, dy = kw["Importance U"] * op.cos(psi), kw["Importance V"] * op.sin(psi)
    length2 = dx * dx + dy * dy
    inv_length = op.inverse_sqrt(length2, 1e-30)
    c, s = dx * inv_length, dy * inv_length
    angular = angular * op.safe_div(kw["Importance U"] * kw["Importance V"], length2)
    # the ray in the light's unit-circle coordinates: e = (c / a, s / b) = k e_hat, met at lambda = -(g.e_hat) -+
    # sqrt((1 - p)(1 + p)), p the circle's centre's distance from the ray (g the foot): no difference of squares, so
    # a thin ellipse keeps its chords in float32; rho = lambda / k
    ex, ey = op.safe_div(c, kw["Scale U"]), op.safe_div(s, kw["Scale V"])
    inv_k = op.inverse_sqrt(ex * ex + ey * ey, 1e-30)
    ex, ey = ex * inv_k, ey * inv_k
    along_ray = kw["Unit Foot U"] * ex + kw["Unit Foot V"] * ey
    across = op.clamp(kw["Unit Foot U"] * ey - kw["Unit Foot V"] * ex, -1.0, 1.0)
    root = op.sqrt((1.0 - across) * (1.0 + across))
    reach, t, b = kw["Reach"], kw["Height"], kw["Normal T"]
    a = c * kw["Normal U"] + s * kw["Normal V"]
    near = op.minimum(op.maximum((-along_ray - root) * inv_k, 0.0), reach)
    far = op.minimum(op.maximum((-along_ray + root) * inv_k, near), reach)
    # the horizon: rho a + t b >= 0 bounds rho below where a > 0 and above where a < 0
    cut = op.safe_div(-t * b, a)
    near = op.select(op.greater(a, 0.0), op.maximum(near, cut), near)
    far = op.maximum(op.select(op.less(a, 0.0), op.minimum(far, cut), far), near)
    moments = ANGULAR_MOMENTS(Near=near, Far=far, Height=t)
    j1, j2, j3 = (moments[f"J{k}"] for k in (1, 2, 3))
    inv_tan = op.safe_div(t, reach)                  # 1 / tan(h): R = t tan(h)
    along = a * j1 + b * j2 - (a * j3 + b * j1) * inv_tan
    return {"Integral": op.maximum(along, 0.0) * angular}


_LAMBERT_RAY_SCALARS = {
    "Unit Foot U": "The foot along the ellipse's first axis in its unit-circle coordinates",
    "Unit Foot V": "Likewise, second axis", "Outside": "The foot's distance in those coordinates less 1 (> 0: outside)",
    "Scale U": "The first semi-axis in units of the larger", "Scale V": "The second, likewise",
    "Importance U": "The importance ellipse's first semi-axis (its directions are the rays')",
    "Importance V": "Its second",
    "Towards": "Where the rays' angles start or centre, in the importance ellipse's coordinates",
    "Half Angle": "Half the angle that sees the light, likewise (foot inside: unused)",
    "Reach": "The cone's radius R in the same units", "Height": "The shading point's distance from the plane, likewise",
    "Normal U": "The receiver's normal along the disk's first axis", "Normal V": "Likewise, second axis",
    "Normal T": "The receiver's normal along the unit vector from the point to its foot",
    "Gauss Node": "The ray's Gauss-Legendre node", "Gauss Weight": "Its weight",
    "Midpoint Node": "The ray's midpoint-rule node", "Midpoint Weight": "Its weight"}

LAMBERT_RAY = NodeFunction(
    "RTL Spread Lambert Ray", _lambert_ray, _sockets({}, _LAMBERT_RAY_SCALARS),
    {"Integral": scalar(0.0, "The ray's radial integral times its angular weight")},
    "One ray of the exact-along-rays Lambert rule for a disk light with spread (core/light_spread.py)")


def _ray_importance(extent, height):
    """The importance ellipse's semi-axis for the light's semi-axis ``extent`` (already cut to the cone's reach):
    sqrt(ln(1 + x^2)) of x = extent / height, the radial integral's growth with a ray's length (as x^2 / 2 where the
    ray is short against the height, as ln x where it is long), so that the rays' angular integrand is nearly flat;
    its series below x^2 = 1e-3, where 1 + x^2 rounds in float32."""
    x2 = op.safe_div(extent * extent, height * height)
    series = x2 * (1.0 - 0.5 * x2)
    return op.sqrt(op.select(op.less(x2, 1e-3), series, op.log2(1.0 + x2) * math.log(2.0)))


def _importance_angle(angle, scale_u, scale_v, importance_u, importance_v):
    """The angle in the importance ellipse's coordinates of the plane direction at ``angle`` in the light's own
    unit-circle coordinates (each map a positive scaling of the axes, so orientation is kept)."""
    return op.atan2(importance_u * scale_v * op.sin(angle), importance_v * scale_u * op.cos(angle))


def _lambert_disk(**kw):
    """The rule's setup (the light's own disk in units of its larger semi-axis, the foot in the ellipse's unit-circle
    coordinates, the importance ellipse and the angles the rays span, the receiver's normal in the plane's frame), its
    rays summed in order, and the emitting side."""
    centre, axis_u, axis_v = kw["Disk Center"], kw["Disk Axis U"], kw["Disk Axis V"]
    position, normal = kw["Position"], kw["Normal"]
    length_u, length_v = op.length(axis_u), op.length(axis_v)
    size = op.maximum(length_u, length_v)
    unit_u, unit_v = op.normalize(axis_u), op.normalize(axis_v)
    offset = kw["Foot"] - centre
    foot_u, foot_v = op.safe_div(op.dot(offset, unit_u), size), op.safe_div(op.dot(offset, unit_v), size)
    scale_u, scale_v = op.safe_div(length_u, size), op.safe_div(length_v, size)
    unit_foot_u, unit_foot_v = op.safe_div(foot_u, scale_u), op.safe_div(foot_v, scale_v)
    distance = op.sqrt(unit_foot_u * unit_foot_u + unit_foot_v * unit_foot_v)
    up = kw["Foot"] - position
    height = op.maximum(op.safe_div(op.length(up), size), 1e-6)
    reach = op.safe_div(kw["Cone Radius"], size)
    importance_u = _ray_importance(op.minimum(scale_u, reach), height)
    importance_v = _ray_importance(op.minimum(scale_v, reach), height)
    # the angles that see the light from outside it: symmetric about the centre's in its unit-circle coordinates,
    # carried to the importance ellipse's, where they are not
    towards = op.atan2(-unit_foot_v, -unit_foot_u)
    half = op.asin(op.safe_div(1.0, op.maximum(distance, 1.0)))
    first = _importance_angle(towards - half, scale_u, scale_v, importance_u, importance_v)
    last = _importance_angle(towards + half, scale_u, scale_v, importance_u, importance_v)
    width = op.maximum(op.atan2(op.sin(last - first), op.cos(last - first)), 0.0)
    outside = op.greater(distance, 1.0)
    rays = {"Unit Foot U": unit_foot_u, "Unit Foot V": unit_foot_v, "Outside": distance - 1.0,
            "Scale U": scale_u, "Scale V": scale_v, "Importance U": importance_u, "Importance V": importance_v,
            "Towards": op.select(outside, first + 0.5 * width,
                                 _importance_angle(towards, scale_u, scale_v, importance_u, importance_v)),
            "Half Angle": 0.5 * width, "Reach": reach, "Height": height,
            "Normal U": op.dot(normal, unit_u), "Normal V": op.dot(normal, unit_v),
            "Normal T": op.dot(normal, op.normalize(up))}
    total = 0.0
    for (g_node, g_weight), (m_node, m_weight) in zip(LAMBERT_GAUSS, LAMBERT_MIDPOINTS):
        total = LAMBERT_RAY(**rays, **{"Gauss Node": g_node, "Gauss Weight": g_weight, "Midpoint Node": m_node,
                                       "Midpoint Weight": m_weight})["Integral"] + total
    # the emitting side is away from axis_u x axis_v (the LTC integrals' convention), both sides where two-sided
    lit = op.maximum(op.select(op.less(op.dot(position - centre, op.cross(axis_u, axis_v)), 0.0), 1.0, 0.0),
                     kw["Two Sided"])
    return {"Form Factor": total * kw["Cone Scale"] * (1.0 / math.pi) * lit}


LAMBERT_DISK = NodeFunction(
    "RTL Spread Lambert Disk", _lambert_disk,
    _sockets({"Position": "The shading point", "Normal": "The receiver's unit normal",
              "Foot": "The shading point's foot on the light's plane", "Disk Center": "The disk light's own centre",
              "Disk Axis U": "Its first semi-axis", "Disk Axis V": "Its second semi-axis"},
             {**_CONE_SCALARS, "Two Sided": "1: the light emits on both sides"}),
    {"Form Factor": scalar(0.0, "The disk's form factor weighted by the spread, above the horizon, on its lit side")},
    "Lambert's form factor of a disk light with spread, exact along each of its rays (core/light_spread.py)")


def lambert_disk_form_factor(cone, position, normal, two_sided=0.0):
    """The clamped cosine over pi integrated over the light's own disk (``cone.disk``) times the spread's weight, on
    the side the light emits to (``LAMBERT_DISK``): Lambert's value under a disk light with spread, exact along each
    of its rays, the horizon included.  ``two_sided``: 1 (or True) where the light emits on both sides."""
    centre, axis_u, axis_v = cone.disk
    two_sided = 1.0 if two_sided is True else (0.0 if two_sided is False else two_sided)
    return LAMBERT_DISK(Position=position, Normal=normal, Foot=cone.foot, **{
        "Disk Center": centre, "Disk Axis U": axis_u, "Disk Axis V": axis_v, "Cone Radius": cone.radius,
        "Cone Scale": cone.scale, "Two Sided": two_sided})["Form Factor"]
