"""Integral of an LTC over a polygonal light (quads and N-gons).

Heitz, Dupuy, Hill & Neubelt 2016, "Real-Time Polygonal-Light Shading with Linearly Transformed
Cosines": the integral of an LTC over a polygon equals the integral of the clamped cosine over
the polygon transformed by Minv (eq. 11), which is Lambert's form factor of that polygon
(Lambert 1760; Arvo 1994, "The Irradiance Jacobian for Partially Occluded Polyhedral Sources",
the vector form factor F = 1/(2 pi) sum_i theta_i n_i over the edges).

Two evaluation methods:
- ``"clipless"`` (Hill & Heitz 2017, ltc_code ``ltc_quad.fs``; docs/area_lights.md, "Clipless
  evaluation"): the vector form factor of the unclipped polygon with the rational fit of
  theta/sin(theta), and the horizon handled by the sphere table
  (``sphere_table.clipped_sphere_integral``).  Branch-free, the formulation for shader nodes.
- ``"clipped"``: exact clipping of the transformed polygon to the upper hemisphere and the exact
  edge integral; the reference that tests compare the clipless path with.

Shader path.  Everything up to the clipless integral is written with ``core.shading_ops`` only,
so it evaluates numpy arrays and traces into the expression IR (core/ir) alike: a polygon is a
Python sequence of K vectors (each a (..., 3) array or an Expr vector), the LTC is given by its
packed entries c = (c0, c1, c2, c3) (``matrix.transform_packed``), and ``LTC_QUAD_INTEGRAL`` is
the node function (one node group) of the quad integral.  The exact clipped reference
(``clip_to_horizon``, exact edges) is numpy-only; ``ltc_polygon_integral`` and
``ltc_quad_integral`` keep the array API ((..., 3, 3) Minv, (..., K, 3) corners).

Conventions (all in the local shading frame, shading point at the origin, N = +Z):
corners are ordered so that the light's normal n = sum_i p_i x p_(i+1) (Newell; for a quad the
direction of (p1 - p0) x (p3 - p0)) points away from the side it lights: a one-sided light
lights the origin when p0 . n >= 0.  A Blender area light whose local corners are listed
counter-clockwise around its local +Z (it emits along -Z) follows this convention, as do the
ltc_code demos.
"""
from __future__ import annotations

import functools
import operator

import numpy as np

from .. import shading_ops as op
from ..ir.expr import is_expr
from ..ir.functions import NodeFunction
from ..ir.interface import Socket, factor, vector
from ..lut import lookup
from . import matrix
from . import sphere_table as spheres

_INV_2PI = 0.5 / np.pi

#: EEVEE ``ltc_tangent_basis`` treats N.V > 0.999999 as normal incidence: sin^2 < 2e-6
#: (docs/area_lights.md, "EEVEE's LTC code").
FRAME_SIN2_MIN = 2e-6

#: Floor for sin^2(theta) in the x < 0 branch of the edge fit.  It only prevents 0 * inf: the
#: branch multiplies v1 x v2 (length sin(theta)) by 1/(2 sin(theta)), which stays <= 1/2.
EDGE_SIN2_MIN = 1e-30

#: A light whose plane passes within this angle (radians, as |c . n| / (|c| |n|), c its centre) of the shading
#: point is seen edge-on and gives 0.  Exactly in the plane the answer is a discontinuity (0 seen
#: from the plane, the full hemisphere just in front of a light the point lies on), and which side
#: float32 rounding picks differs between numpy and the Cycles/EEVEE kernels; this margin (100x
#: float32 rounding of the dot product) makes all three agree.  A point nearer to the light's
#: plane than 1e-5 of its distance to the light's centre is treated as lying in it (``off_plane``).
EDGE_ON_SIN = 1e-5


def corner_vectors(points):
    """A polygon as a list of K vectors: sequences pass through, arrays (..., K, 3) are split."""
    if isinstance(points, (list, tuple)):
        return list(points)
    arr = np.asarray(points)
    return [arr[..., k, :] for k in range(arr.shape[-2])]


def _sum(terms):
    """Sum of vectors (no 0 start value: a float 0 plus an Expr vector is a type error)."""
    return functools.reduce(operator.add, terms)


def ones_like(x):
    """1: a constant once traced, an array of x's shape and dtype in numpy."""
    return 1.0 if is_expr(x) else np.ones_like(x)


def unit_sign(negative, like):
    """-1 where ``negative`` else +1: a Select node once traced, an array of ``like``'s dtype in numpy."""
    s = op.select(negative, -1.0, 1.0)
    return s if is_expr(s) else s.astype(np.result_type(np.asarray(like).dtype, np.float32))


# --- local frame -----------------------------------------------------------------------------

# Duff, Burgess, Christensen, Hery, Kensler, Liani & Villemin 2017, "Building an Orthonormal
# Basis, Revisited" (JCGT 6(1)): their branchless first basis vector, a unit tangent of n.
def _any_tangent(n):
    nx, ny, nz = (op.component(n, i) for i in range(3))
    s = unit_sign(op.less(nz, 0.0), nz)
    a = -op.safe_div(ones_like(nz), s + nz)  # |s + n.z| >= 1 for unit n
    return op.vec3(1.0 + s * nx * nx * a, s * nx * ny * a, -s * nx)


# Heitz et al. 2016 / ltc_code ``ltc_quad.fs`` (docs/area_lights.md, "Clipless evaluation"):
# T1 = normalize(V - N (V.N)), T2 = N x T1.
def local_frame(n, v):
    """Orthonormal (T1, T2, N) for unit normal n and view v (vectors); T1 falls back to any tangent
    when V is parallel to N (then the LTC is isotropic and the choice does not matter)."""
    n = op.normalize(n)
    t = v - op.scale(n, op.dot(v, n))
    t1 = op.vselect(op.greater(op.dot(t, t), FRAME_SIN2_MIN), op.normalize(t), _any_tangent(n))
    return t1, op.cross(n, t1), n


def frame_coordinates(frame, d):
    """Coordinates of vector d in the frame (T1, T2, N) of ``local_frame``: three dot products."""
    t1, t2, n = frame
    return op.vec3(op.dot(d, t1), op.dot(d, t2), op.dot(d, n))


def to_local(points, p, n, v):
    """World-space points seen from shading point p with normal n and view v: coordinates in the
    (T1, T2, N) frame relative to p, and the view cosine N.V.  ``points`` is a sequence of vectors
    (returned as a list) or an array (..., K, 3) (returned as an array)."""
    frame = local_frame(n, v)
    local = [frame_coordinates(frame, q - p) for q in corner_vectors(points)]
    if not isinstance(points, (list, tuple)):
        local = np.stack(local, axis=-2)
    return local, op.dot(frame[2], op.normalize(v))


def transform(minv, points):
    """Minv (..., 3, 3) applied to points (..., K, 3) (numpy; shader code uses ``matrix.transform_packed``)."""
    return np.einsum("...ij,...kj->...ki", minv, points)


# --- edge integrals ----------------------------------------------------------------------------

# Hill & Heitz 2017 (ltc_code 7c1fa5f ``IntegrateEdgeVec``; docs/area_lights.md, "Clipless
# evaluation"): rational fit of
# theta / sin(theta) / (2 pi) in y = |x|, x = cos(theta) (max relative error 1.4e-6); for x < 0
# the symmetry theta -> pi - theta gives 1/(2 sin(theta)) - fit(|x|).
# One departure: ltc_code forms sin^2 = max(1 - x^2, 1e-7) (b23b090), which cancels near
# theta = pi and under-weights nearly antipodal edges (a light seen almost edge-on through the
# shading point, or squashed by a near-singular Minv: up to 8x too dark in tests); here
# sin^2(theta) = |v1 x v2|^2, the squared length of the cross product the edge vector needs anyway.
# The fit's seven-digit coefficients are rounded to float32 here, as the GLSL source and Blender's
# sockets (core/ir constants) hold them, so numpy and node evaluation use the same numbers.
_FIT_A, _FIT_B, _FIT_C, _FIT_D, _FIT_E = (float(np.float32(x)) for x in
                                          (0.8543985, 0.4965155, 0.0145206, 3.4175940, 4.1616724))


def edge_factor(x, sin2):
    """theta / (2 pi sin(theta)) for x = cos(theta), sin2 = sin^2(theta), from the rational fit."""
    y = op.absolute(x)
    fit = (_FIT_A + (_FIT_B + _FIT_C * y) * y) / (_FIT_D + (_FIT_E + y) * y)
    return op.select(op.less(x, 0.0), 0.5 * op.inverse_sqrt(sin2, EDGE_SIN2_MIN) - fit, fit)


def edge_weight(v1, v2):
    """The fitted edge factor of the arc v1 -> v2 (the edge vector is (v1 x v2) times it)."""
    c = op.cross(v1, v2)
    return edge_factor(op.dot(v1, v2), op.dot(c, c))


def edge_vector(v1, v2):
    """Vector form factor of the great-circle arc from unit v1 to unit v2 (fitted edge factor)."""
    return op.scale(op.cross(v1, v2), edge_weight(v1, v2))


# Arvo 1994 / Heitz et al. 2016 eq. 11: the exact edge term theta n / (2 pi) with n the unit normal
# of the arc's plane; theta = atan2(|v1 x v2|, v1.v2) (the angle acos(v1.v2), well conditioned for
# short edges).
def edge_weight_exact(v1, v2):
    c = op.length(op.cross(v1, v2))
    return op.safe_div(op.atan2(c, op.dot(v1, v2)), c) * _INV_2PI


def edge_vector_exact(v1, v2):
    return op.scale(op.cross(v1, v2), edge_weight_exact(v1, v2))


def _next(points):
    return np.roll(points, -1, axis=-2)


# F = sum_i w_i v_i x v_(i+1) (Arvo 1994), summed as
#   sum_i w_i (v_i - v_0) x (v_(i+1) - v_0)  +  v_0 x sum_i w_i (v_(i+1) - v_i)
# (an identity: v_i x v_(i+1) = (v_i - o) x (v_(i+1) - o) + o x (v_(i+1) - v_i)).  For a light of
# angular size s, the plain sum adds O(s) terms into an O(s^2) result (float32 relative error
# ~ 1e-7 / s^2; measured up to 175% for s ~ 3e-5 .. 1e-3 rad); here every term is O(s^2) or its
# sum cancels exactly, and the error is ~ 1e-7 / s (0.5% there).  Only differences and crosses;
# the first and last terms of the first sum are zero and left out.
def vector_form_factor(unit_points, exact=False):
    """F = sum over the closed polygon's edges of the edge vectors; unit_points: K unit vectors
    (a sequence, or an array (..., K, 3))."""
    pts = corner_vectors(unit_points)
    nxt = pts[1:] + pts[:1]
    weight = edge_weight_exact if exact else edge_weight
    w = [weight(a, b) for a, b in zip(pts, nxt)]
    origin = pts[0]
    d = [q - origin for q in pts]
    area_part = _sum([op.scale(op.cross(d[i], d[i + 1]), w[i]) for i in range(1, len(pts) - 1)])
    flow = _sum([op.scale(b - a, wi) for a, b, wi in zip(pts, nxt, w)])
    return area_part + op.cross(origin, flow)


def light_normal(points):
    """Newell's normal sum_i p_i x p_(i+1) (twice the vector area of a planar polygon), summed as
    sum_i (p_i - p_0) x (p_(i+1) - p_0) (the same, without cancellation for small lights); for a
    quad it is the cross product of the diagonals, (p2 - p0) x (p3 - p1) (the same sum expanded)."""
    pts = corner_vectors(points)
    if len(pts) == 4:
        return op.cross(pts[2] - pts[0], pts[3] - pts[1])
    d = [q - pts[0] for q in pts]
    return _sum([op.cross(d[i], d[i + 1]) for i in range(1, len(pts) - 1)])


# The side of the light's plane the origin is on, from a point of the plane: ltc_code takes corner p0.  A
# light much larger than its distance to the origin has corners |p0| >> that distance, and their float32
# rounding (~6e-8 |p0|) decides the side, so the caller gives the light's centre (``center``, transformed
# like the corners): for such a light it is known to its own distance's precision (docs/robustness.md).
# Without one, the corners' mean (never farther than the farthest corner).
def _plane_point(pts, center):
    if center is not None:
        return center
    return op.scale(_sum(list(pts)), 1.0 / len(pts))


def behind(points, center=None):
    """True (1) where the origin lies behind the light (p . n < 0, ltc_code ``ltc_quad.fs``; p = ``center`` or
    the corners' mean where ltc_code takes p0)."""
    pts = corner_vectors(points)
    return op.less(op.dot(_plane_point(pts, center), light_normal(pts)), 0.0)


def off_plane(points, center=None):
    """1 where the origin lies off the light's plane by more than ``EDGE_ON_SIN`` (measured from ``center`` or
    the corners' mean); 0 where the light is seen edge-on and gives 0."""
    pts = corner_vectors(points)
    normal = light_normal(pts)
    ref = _plane_point(pts, center)
    return beyond_plane(op.dot(ref, normal), EDGE_ON_SIN * op.length(ref) * op.length(normal))


def beyond_plane(side, margin):
    """1 where |side| > margin: strictly, so that a light centred on the point (side = margin = 0) counts as
    seen edge-on, as any other point of its plane does."""
    return op.greater(op.absolute(side), margin)


# --- horizon clipping (exact reference, numpy only) ----------------------------------------------

# Sutherland & Hodgman 1974 against the plane z = 0: every edge keeps its part with z >= 0 as a
# (start, end) pair; edges entirely below are replaced by a repeat of the previous kept point, so
# the sequence stays closed and repeated points add zero-length edges (fixed size 2K, vectorised).
def clip_to_horizon(points):
    """(..., K, 3) polygon -> (..., 2K, 3) closed sequence of its part above z = 0 (all zero if none)."""
    a, b = points, _next(points)
    za, zb = a[..., 2], b[..., 2]
    crossing = (za >= 0.0) != (zb >= 0.0)
    t = op.safe_div(za, op.select(crossing, za - zb, 1.0))
    x = a + t[..., None] * (b - a)
    x[..., 2] = 0.0
    start = op.select((za >= 0.0)[..., None], a, x)
    end = op.select((zb >= 0.0)[..., None], b, x)
    seq = np.stack([start, end], axis=-2).reshape(points.shape[:-2] + (-1, 3))
    keep = np.repeat((za >= 0.0) | (zb >= 0.0), 2, axis=-1)
    idx = np.where(keep, np.arange(keep.shape[-1]), -1)
    last = np.maximum.accumulate(idx, axis=-1)
    last = np.where(last < 0, last[..., -1:], last)
    out = np.take_along_axis(seq, np.maximum(last, 0)[..., None], axis=-2)
    return np.where((last >= 0)[..., None], out, 0.0)


# --- LTC integrals ---------------------------------------------------------------------------

def _as_float(minv, corners):
    dtype = np.result_type(np.asarray(minv).dtype, np.asarray(corners).dtype, np.float32)
    return np.asarray(minv, dtype=dtype), np.asarray(corners, dtype=dtype)


# Hill & Heitz 2017 (ltc_code ``ltc_quad.fs``, clipless branch; docs/area_lights.md, "Clipless
# evaluation"): |F| and z = F.z/|F|;
# behind the light z flips (two-sided) or the light is dark (one-sided); horizon from the sphere table.
# The side tests take the polygon before the transform, as ltc_code does (Minv has a positive
# determinant, so the side is the same), from ``center`` (``_plane_point``).
def polygon_integral_clipless(transformed, two_sided, sphere_table=None, untransformed=None, center=None):
    """Clipless integral of the clamped cosine over a polygon already transformed by Minv (K vectors,
    a sequence or an (..., K, 3) array).  ``two_sided``: bool or 0/1 (an Expr when traced);
    ``sphere_table``: see ``sphere_table.clipped_sphere_integral`` (a Table when traced);
    ``untransformed``: the polygon before the transform, for the side tests (default: ``transformed``),
    ``center``: a point of its plane there (default: its corners' mean)."""
    pts = corner_vectors(transformed)
    plane = pts if untransformed is None else corner_vectors(untransformed)
    f = vector_form_factor([op.normalize(q) for q in pts])
    length = op.length(f)
    z = op.safe_div(op.component(f, 2), length)
    back = behind(plane, center)
    z = op.select(back, -z, z)
    # |F| <= 1 for any spherical region; the clamp removes the edge fit's excess near |F| = 1
    value = spheres.clipped_sphere_integral(op.saturate(length), z, sphere_table)
    return op.select(off_plane(plane, center), op.select(back, value * two_sided, value), 0.0)


def ltc_polygon_integral_packed(c, corners, two_sided=False, sphere_table=None, center=None):
    """Clipless integral of the LTC with packed entries c = (c0, c1, c2, c3) over the polygon
    ``corners`` (K vectors in the local frame, relative to the shading point; ``center``: the light's
    centre there, for the side tests); traceable."""
    corners = corner_vectors(corners)
    return polygon_integral_clipless([matrix.transform_packed(c, q) for q in corners], two_sided, sphere_table,
                                     corners, center)


# Heitz et al. 2016 (ltc_code ``ltc_quad.fs``, clipped branch): clip, normalise, exact edges;
# two-sided |sum|, one-sided max(sum, 0).
def _integral_clipped(transformed, two_sided):
    clipped = op.normalize(clip_to_horizon(transformed))
    total = vector_form_factor(clipped, exact=True)[..., 2]
    return np.abs(total) if two_sided else op.maximum(total, 0.0).astype(total.dtype)


def ltc_polygon_integral(minv, corners, two_sided=False, sphere_table=None, method="clipless"):
    """Integral of the normalised LTC ``minv`` (..., 3, 3) over the polygon ``corners`` (..., K, 3)
    (local frame, relative to the shading point, ordered as in the module docstring); numpy.
    ``sphere_table``: None (the analytic table), an (H, W) table or a Table."""
    minv, corners = _as_float(minv, corners)
    transformed = transform(minv, corners)
    if method == "clipless":
        value = np.asarray(polygon_integral_clipless(transformed, two_sided, sphere_table, corners))
    elif method == "clipped":
        value = _integral_clipped(transformed, two_sided)
    else:
        raise ValueError(f"unknown method {method!r}")
    return value.astype(corners.dtype, copy=False)


def ltc_quad_integral(minv, corners, two_sided=False, sphere_table=None, method="clipless"):
    """``ltc_polygon_integral`` for quads: corners (..., 4, 3)."""
    if np.shape(corners)[-2:] != (4, 3):
        raise ValueError("a quad needs corners of shape (..., 4, 3)")
    return ltc_polygon_integral(minv, corners, two_sided, sphere_table, method)


def ltc_polygon_vector_form_factor(minv, corners):
    """Vector form factor F of the transformed, unclipped polygon (fitted edges): F.z is the exact
    LTC integral when the transformed polygon lies above the horizon (used by tests)."""
    minv, corners = _as_float(minv, corners)
    return vector_form_factor([op.normalize(q) for q in corner_vectors(transform(minv, corners))])


# --- horizon clipping, traceable (exact for lobes that live near the horizon) --------------------

# Heitz et al. 2016 (ltc_code ``ltc_quad.fs``, its clipped branch ``ClipQuadToHorizon``), written without
# branches (Sutherland & Hodgman 1974 against z = 0).  The clipped polygon's boundary is every edge's part above
# the horizon plus one arc along the horizon, from where the polygon leaves the upper half-space (the exit point)
# to where it comes back (the entry point): a convex polygon crosses z = 0 at most twice.  So its form factor is
# one arc per edge (zero for an edge wholly below) and one closing arc (zero when nothing crosses: both points
# are then 0), streamed edge by edge in one pass so that only the K corners and four running sums stay live
# (Cycles' SVM stack: a 12-gon's 24 clipped points held at once overflowed it in Blender 4.5).
def _horizon_crossing(a, b):
    """(point of the segment a-b on z = 0 (z set to exactly 0), a above, b above: 0/1 floats)."""
    za, zb = op.component(a, 2), op.component(b, 2)
    above_a, above_b = 1.0 - op.less(za, 0.0), 1.0 - op.less(zb, 0.0)
    crossing = above_a + above_b - 2.0 * above_a * above_b
    t = op.safe_div(za, op.select(crossing, za - zb, 1.0))
    x = a + op.scale(b - a, t)
    return op.vec3(op.component(x, 0), op.component(x, 1), 0.0 * za), above_a, above_b


def _cross_z(a, b):
    return op.component(a, 0) * op.component(b, 1) - op.component(a, 1) * op.component(b, 0)


def _arc_terms(a, b, o, exact=False):
    """(z of w (a - o) x (b - o), w (b - a)) of the arc a -> b (unit vectors), w its fitted edge factor (``exact``:
    the exact one, ``edge_weight_exact``): one edge of ``vector_form_factor``'s cancellation-free sum about the
    unit point o."""
    w = edge_weight_exact(a, b) if exact else edge_weight(a, b)
    return _cross_z(a - o, b - o) * w, op.scale(b - a, w)


def clipped_edge_terms(a, b, origin, sums=None, exact=False):
    """{"Area", "Flow"}: the terms of the part of the edge a -> b above the horizon (zero for an edge wholly
    below) in ``clipped_form_factor_z``'s sum about ``origin`` (a point near the polygon, not normalised);
    {"Exit", "Entry"}: the edge's crossing where it leaves (enters) the upper half-space, else 0.  ``sums``: the
    same four summed over the edges before this one, added to this edge's (the running sums)."""
    x, above_a, above_b = _horizon_crossing(a, b)
    # an end below the horizon moves to the crossing; an edge wholly below becomes the arc x -> x, exactly zero
    start = op.normalize(op.vselect(above_a, a, x))
    end = op.normalize(op.vselect(above_b, b, x))
    area, flow = _arc_terms(start, end, op.normalize(origin), exact)
    terms = {"Area": area, "Flow": flow, "Exit": op.scale(x, above_a * (1.0 - above_b)),
             "Entry": op.scale(x, above_b * (1.0 - above_a))}
    return terms if sums is None else {name: sums[name] + value for name, value in terms.items()}


def clipped_sum_z(sums, origin, exact=False):
    """z of the clipped polygon's vector form factor from its edges' running sums: the closing arc from the exit
    point to the entry point along the horizon added, then the origin's part o x flow."""
    o = op.normalize(origin)
    closing_area, closing_flow = _arc_terms(op.normalize(sums["Exit"]), op.normalize(sums["Entry"]), o, exact)
    return sums["Area"] + closing_area + _cross_z(o, sums["Flow"] + closing_flow)


#: The running sums of the clipped edges (``clipped_edge_terms``), each edge's group's outputs.
CLIPPED_EDGE_SOCKETS = {
    "Area": Socket("float", 0.0, description="z of w (a - o) x (b - o) over the edges' parts above the horizon"),
    "Flow": vector("w (b - a) over the edges' parts above the horizon", "XYZ"),
    "Exit": vector("The crossing where an edge leaves the upper half-space (0 while none has)", "XYZ"),
    "Entry": vector("The crossing where an edge enters the upper half-space (0 while none has)", "XYZ")}

_EDGE_SOCKETS = {"A": vector("Edge start (transformed, local frame)", "XYZ"), "B": vector("Edge end", "XYZ"),
                 "O": vector("A point near the polygon (normalised inside): the sum's origin", "XYZ")}


def _running_sums(kw):
    return {name: kw[f"{name} In"] for name in CLIPPED_EDGE_SOCKETS}


# The edges run as a chain: each edge's group takes the running sums and gives them back with its own terms added,
# so only one set of sums (10 floats) is live between edges.  Summing the edges' outputs apart (four sums over K
# groups) kept every edge's Flow, Exit and Entry live while the Area sum was compiled, and a 12-gon's overflowed
# Cycles' SVM stack (255 floats) in Blender 4.5, which compiles nodes in the order they were made.
def _clipped_edge_functions(exact):
    suffix = " (Exact Edges)" if exact else ""
    first = NodeFunction(
        "RTL Clipped First Edge" + suffix, lambda **kw: clipped_edge_terms(kw["A"], kw["B"], kw["O"], exact=exact),
        _EDGE_SOCKETS, CLIPPED_EDGE_SOCKETS, "The first edge of a polygon clipped at the horizon (Sutherland-Hodgman) "
        "in Arvo's form factor: the running sums' start")
    edge = NodeFunction(
        "RTL Clipped Edge" + suffix,
        lambda **kw: clipped_edge_terms(kw["A"], kw["B"], kw["O"], _running_sums(kw), exact=exact),
        dict(_EDGE_SOCKETS, **{f"{name} In": s for name, s in CLIPPED_EDGE_SOCKETS.items()}), CLIPPED_EDGE_SOCKETS,
        "One edge of a polygon clipped at the horizon (Sutherland-Hodgman) in Arvo's form factor, added to the "
        "running sums")
    return first, edge


#: (first edge, further edge) groups: the fitted edge factor (the LTC lobes) and the exact one (Lambert).
_CLIPPED_EDGES = {exact: _clipped_edge_functions(exact) for exact in (False, True)}


def clipped_form_factor_z(points, exact=False):
    """z of the vector form factor (fitted edges; ``exact``: the exact ones) of the convex polygon ``points`` (K
    vectors, transformed, local frame, not normalised) clipped at z = 0: every edge's part above the horizon and the
    closing arc along it, summed as ``vector_form_factor`` does about the polygon's centroid, one nested group per
    edge (a running sum); traceable.  Negative seen from the polygon's back."""
    pts = corner_vectors(points)
    k = len(pts)
    origin = op.scale(_sum(pts), 1.0 / k)
    first_edge, next_edge = _CLIPPED_EDGES[exact]
    sums = first_edge(A=pts[0], B=pts[1 % k], O=origin)
    for i in range(1, k):
        sums = next_edge(A=pts[i], B=pts[(i + 1) % k], O=origin, **{f"{n} In": sums[n] for n in sums})
    return clipped_sum_z(sums, origin, exact)


@functools.lru_cache(maxsize=None)
def clipped_form_factor_function(k, exact=False):
    """"RTL Clipped Form Factor (<k> corners)": ``clipped_form_factor_z`` of a convex k-gon (``exact``: with the
    exact edge factor)."""
    def body(**kw):
        return {"Fz": clipped_form_factor_z([kw[f"p{i}"] for i in range(k)], exact)}

    return NodeFunction(
        f"RTL Clipped Form Factor ({k} corners{', exact edges' if exact else ''})", body,
        {f"p{i}": vector(f"Corner {i} (transformed, local frame)", "XYZ") for i in range(k)},
        {"Fz": Socket("float", 0.0, description="z of the vector form factor of the polygon's part above z = 0 "
                                                "(signed: negative seen from its back)")},
        "Lambert's form factor of a convex polygon clipped exactly at the horizon (Heitz et al. 2016, eq. 11)")


def clipped_side_value(fz, back, lit, two_sided):
    """The clipped integral from its signed form factor: |fz| on the lit side (the back only when two-sided),
    0 for a light seen edge-on (``lit`` 0)."""
    value = op.saturate(op.select(back, -fz, fz))
    return op.select(lit, op.select(back, value * two_sided, value), 0.0)


def polygon_integral_horizon_clipped(transformed, two_sided, untransformed=None, center=None, exact_edges=False):
    """``polygon_integral_clipless`` with the exact horizon: the transformed quad clipped to z >= 0
    (``clipped_form_factor_z``), then the z of its vector form factor (Heitz et al. 2016, eq. 11); the same
    side and edge-on tests.  Any convex polygon (K corners, 2K clipped points).  ``exact_edges``: the exact edge
    factor instead of the fit (Lambert's form factor, ``QUAD_FORM_FACTOR_CLIPPED``)."""
    pts = corner_vectors(transformed)
    plane = pts if untransformed is None else corner_vectors(untransformed)
    fz = clipped_form_factor_function(len(pts), exact_edges)(**{f"p{i}": q for i, q in enumerate(pts)})["Fz"]
    return clipped_side_value(fz, behind(plane, center), off_plane(plane, center), two_sided)


# --- the node function -------------------------------------------------------------------------

def _quad_integral_node(tables, **inputs):
    c = tuple(inputs[f"c{i}"] for i in range(4))
    corners = [inputs[f"p{i}"] for i in range(4)]
    return {"Integral": ltc_polygon_integral_packed(c, corners, inputs["Two Sided"], tables.sphere_table(),
                                                    inputs["Center"])}


_C_TIPS = {"c0": "Minv[0][0] (R of the LTC matrix table)", "c1": "Minv[2][0] (G of the LTC matrix table)",
           "c2": "Minv[0][2] (B of the LTC matrix table)", "c3": "Minv[2][2] (A of the LTC matrix table)"}

#: Inputs shared by the LTC integral node functions: the packed inverse matrix and the sidedness.
LTC_MATRIX_SOCKETS = {name: Socket("float", 1.0 if name in ("c0", "c3") else 0.0, description=tip + "; "
                                   "Minv = [[c0, 0, c2], [0, 1, 0], [c1, 0, c3]]")
                      for name, tip in _C_TIPS.items()}
TWO_SIDED_SOCKET = factor(0.0, "1: the light emits on both sides; 0: only on the side away from which "
                               "its normal points")

#: Integral of an LTC over a quad light (Heitz et al. 2016; clipless, Hill & Heitz 2017): one node group.
LTC_QUAD_INTEGRAL = NodeFunction(
    "RTL LTC Quad Integral", _quad_integral_node,
    inputs=dict(LTC_MATRIX_SOCKETS, **{
        f"p{i}": vector(f"Corner {i} of the quad in the local shading frame (T1, T2, N), relative to the "
                        "shading point; (p1 - p0) x (p3 - p0) points away from the lit side", "XYZ")
        for i in range(4)}, **{
        "Center": vector("Centre of the quad in the local shading frame, relative to the shading point: the side "
                         "tests use it (more precise than the corners for lights much larger than their distance)",
                         "XYZ"),
        "Two Sided": TWO_SIDED_SOCKET}),
    outputs={"Integral": Socket("float", 0.0, 0.0, 1.0, "FACTOR",
                                "Integral of the normalised LTC over the light, horizon-clipped (sphere table): "
                                "multiply by the lobe's magnitude")},
    description="LTC integral over a quad light (Heitz et al. 2016, clipless form of Hill & Heitz 2017)",
    tables=lookup.REFERENCES)



def _quad_integral_clipped_node(tables, **inputs):
    c = tuple(inputs[f"c{i}"] for i in range(4))
    corners = [inputs[f"p{i}"] for i in range(4)]
    transformed = [matrix.transform_packed(c, q) for q in corners]
    return {"Integral": polygon_integral_horizon_clipped(transformed, inputs["Two Sided"], corners, inputs["Center"])}


#: ``LTC_QUAD_INTEGRAL`` with the exact horizon (``polygon_integral_horizon_clipped``): for lobes that live near the
#: horizon (the Zeltner sheen at low roughness), where the sphere table's cap is far from the clipped polygon.
LTC_QUAD_INTEGRAL_CLIPPED = NodeFunction(
    "RTL LTC Quad Integral (Clipped)", _quad_integral_clipped_node, inputs=LTC_QUAD_INTEGRAL.input_sockets,
    outputs={"Integral": Socket("float", 0.0, 0.0, 1.0, "FACTOR",
                                "Integral of the normalised LTC over the light, clipped exactly at the horizon: "
                                "multiply by the lobe's magnitude")},
    description="LTC integral over a quad light with exact horizon clipping (Heitz et al. 2016)",
    tables=lookup.REFERENCES)


# Lambert's form factor is the identity LTC's integral: no transform, and the exact edge factor, because the fit's
# 1.4e-6 of an edge's term was the largest error of the clipped form factor (1.1e-4 of small lights; exact edges:
# 1.5e-12 in float64, docs/benchmarks/horizon.md).  The LTC lobes keep the fit: their tables' error is larger by
# orders, and the fit's float32 behaviour is what Cycles and the numpy backend agree on.
def _quad_form_factor_clipped_node(**inputs):
    corners = [inputs[f"p{i}"] for i in range(4)]
    return {"Integral": polygon_integral_horizon_clipped(corners, inputs["Two Sided"], corners, inputs["Center"],
                                                         exact_edges=True)}


#: Lambert's form factor of a quad light clipped exactly at the horizon (exact edges).
QUAD_FORM_FACTOR_CLIPPED = NodeFunction(
    "RTL Quad Form Factor (Clipped)", _quad_form_factor_clipped_node,
    inputs={k: s for k, s in LTC_QUAD_INTEGRAL.input_sockets.items() if not k.startswith("c")},
    outputs={"Integral": Socket("float", 0.0, 0.0, 1.0, "FACTOR",
                                "Lambert's form factor of the light, clipped exactly at the horizon")},
    description="Form factor of a quad light with exact horizon clipping and exact edges (Heitz et al. 2016, eq. 11)")
