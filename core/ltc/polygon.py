"""Integral of an LTC over a polygonal light (quads and N-gons).

Heitz, Dupuy, Hill & Neubelt 2016, "Real-Time Polygonal-Light Shading with Linearly Transformed
Cosines": the integral of an LTC over a polygon equals the integral of the clamped cosine over
the polygon transformed by Minv (eq. 11), which is Lambert's form factor of that polygon
(Lambert 1760; Arvo 1994, "The Irradiance Jacobian for Partially Occluded Polyhedral Sources",
the vector form factor F = 1/(2 pi) sum_i theta_i n_i over the edges).

Two evaluation methods:
- ``"clipless"`` (Hill & Heitz 2017, ltc_code ``ltc_quad.fs``; ltc.md §1.5, §5.1): the vector
  form factor of the unclipped polygon with the rational fit of theta/sin(theta), and the
  horizon handled by the sphere table (``sphere_table.clipped_sphere_integral``).  Branch-free,
  the formulation for shader nodes.
- ``"clipped"``: exact clipping of the transformed polygon to the upper hemisphere and the exact
  edge integral; the reference that tests compare the clipless path with.

Conventions (all in the local shading frame, shading point at the origin, N = +Z):
corners are ordered so that the light's normal n = sum_i p_i x p_(i+1) (Newell; for a quad the
direction of (p1 - p0) x (p3 - p0)) points away from the side it lights: a one-sided light
lights the origin when p0 . n >= 0.  A Blender area light whose local corners are listed
counter-clockwise around its local +Z (it emits along -Z) follows this convention, as do the
ltc_code demos.
"""
from __future__ import annotations

import numpy as np

from .. import shading_ops as op
from . import sphere_table as spheres

_INV_2PI = 0.5 / np.pi

#: EEVEE ``ltc_tangent_basis`` treats N.V > 0.999999 as normal incidence (ltc.md §2.2): sin^2 < 2e-6.
FRAME_SIN2_MIN = 2e-6

#: Floor for sin^2(theta) in the x < 0 branch of the edge fit.  It only prevents 0 * inf: the
#: branch multiplies v1 x v2 (length sin(theta)) by 1/(2 sin(theta)), which stays <= 1/2.
EDGE_SIN2_MIN = 1e-30


# --- local frame -----------------------------------------------------------------------------

# Duff, Burgess, Christensen, Hery, Kensler, Liani & Villemin 2017, "Building an Orthonormal
# Basis, Revisited" (JCGT 6(1)): their branchless first basis vector, a unit tangent of n.
def _any_tangent(n):
    one = np.ones_like(n[..., 2])
    s = op.select(n[..., 2] >= 0.0, one, -one)
    a = -op.safe_div(one, s + n[..., 2])  # |s + n.z| >= 1 for unit n
    return np.stack([1.0 + s * n[..., 0] * n[..., 0] * a, s * n[..., 0] * n[..., 1] * a, -s * n[..., 0]], axis=-1)


# Heitz et al. 2016 / ltc_code ``ltc_quad.fs`` (ltc.md §1.5): T1 = normalize(V - N (V.N)), T2 = N x T1.
def local_frame(n, v):
    """Orthonormal (T1, T2, N) for unit normal n and view v (...,3); T1 falls back to any tangent
    when V is parallel to N (then the LTC is isotropic and the choice does not matter)."""
    n = op.normalize(n)
    t = v - n * op.dot(v, n)[..., None]
    t1 = op.select((op.dot(t, t) > FRAME_SIN2_MIN)[..., None], op.normalize(t), _any_tangent(n))
    return t1, op.cross(n, t1), n


def to_local(points, p, n, v):
    """World-space points (..., K, 3) seen from shading point p (..., 3) with normal n and view v:
    coordinates in the (T1, T2, N) frame relative to p, and the view cosine N.V."""
    t1, t2, n = local_frame(n, v)
    d = np.asarray(points) - np.asarray(p)[..., None, :]
    local = np.stack([op.dot(d, t1[..., None, :]), op.dot(d, t2[..., None, :]), op.dot(d, n[..., None, :])], axis=-1)
    return local, op.dot(n, op.normalize(v))


def transform(minv, points):
    """Minv (..., 3, 3) applied to points (..., K, 3)."""
    return np.einsum("...ij,...kj->...ki", minv, points)


# --- edge integrals ----------------------------------------------------------------------------

# Hill & Heitz 2017 (ltc_code 7c1fa5f ``IntegrateEdgeVec``; ltc.md §1.5): rational fit of
# theta / sin(theta) / (2 pi) in y = |x|, x = cos(theta) (max relative error 1.4e-6); for x < 0
# the symmetry theta -> pi - theta gives 1/(2 sin(theta)) - fit(|x|).
# One departure: ltc_code forms sin^2 = max(1 - x^2, 1e-7) (b23b090), which cancels near
# theta = pi and under-weights nearly antipodal edges (a light seen almost edge-on through the
# shading point, or squashed by a near-singular Minv: up to 8x too dark in tests); here
# sin^2(theta) = |v1 x v2|^2, the squared length of the cross product the edge vector needs anyway.
def edge_factor(x, sin2):
    """theta / (2 pi sin(theta)) for x = cos(theta), sin2 = sin^2(theta), from the rational fit."""
    y = np.abs(x)
    fit = (0.8543985 + (0.4965155 + 0.0145206 * y) * y) / (3.4175940 + (4.1616724 + y) * y)
    return op.select(x < 0.0, 0.5 * op.inverse_sqrt(sin2, EDGE_SIN2_MIN) - fit, fit)


def edge_weight(v1, v2):
    """The fitted edge factor of the arc v1 -> v2 (the edge vector is (v1 x v2) times it)."""
    c = op.cross(v1, v2)
    return edge_factor(op.dot(v1, v2), op.dot(c, c))


def edge_vector(v1, v2):
    """Vector form factor of the great-circle arc from unit v1 to unit v2 (fitted edge factor)."""
    return op.cross(v1, v2) * edge_weight(v1, v2)[..., None]


# Arvo 1994 / Heitz et al. 2016 eq. 11: the exact edge term theta n / (2 pi) with n the unit normal
# of the arc's plane; theta = atan2(|v1 x v2|, v1.v2) (the angle acos(v1.v2), well conditioned for
# short edges).
def edge_weight_exact(v1, v2):
    c = op.length(op.cross(v1, v2))
    return op.safe_div(np.arctan2(c, op.dot(v1, v2)), c) * _INV_2PI


def edge_vector_exact(v1, v2):
    return op.cross(v1, v2) * edge_weight_exact(v1, v2)[..., None]


def _next(points):
    return np.roll(points, -1, axis=-2)


# F = sum_i w_i v_i x v_(i+1) (Arvo 1994), summed as
#   sum_i w_i (v_i - v_0) x (v_(i+1) - v_0)  +  v_0 x sum_i w_i (v_(i+1) - v_i)
# (an identity: v_i x v_(i+1) = (v_i - o) x (v_(i+1) - o) + o x (v_(i+1) - v_i)).  For a light of
# angular size s, the plain sum adds O(s) terms into an O(s^2) result (float32 relative error
# ~ 1e-7 / s^2; measured up to 175% for s ~ 3e-5 .. 1e-3 rad); here every term is O(s^2) or its
# sum cancels exactly, and the error is ~ 1e-7 / s (0.5% there).  Only differences and crosses.
def vector_form_factor(unit_points, exact=False):
    """F = sum over the closed polygon's edges of the edge vectors; unit_points (..., K, 3)."""
    nxt = _next(unit_points)
    w = (edge_weight_exact if exact else edge_weight)(unit_points, nxt)[..., None]
    origin = unit_points[..., :1, :]
    area_part = np.sum(w * op.cross(unit_points - origin, nxt - origin), axis=-2)
    return area_part + op.cross(origin[..., 0, :], np.sum(w * (nxt - unit_points), axis=-2))


def light_normal(points):
    """Newell's normal sum_i p_i x p_(i+1) (twice the vector area of a planar polygon), summed as
    sum_i (p_i - p_0) x (p_(i+1) - p_0) (the same, without cancellation for small lights)."""
    d = points - points[..., :1, :]
    return np.sum(op.cross(d, _next(d)), axis=-2)


def behind(points):
    """True where the origin lies behind the light (p0 . n < 0, ltc_code ``ltc_quad.fs``)."""
    return op.dot(points[..., 0, :], light_normal(points)) < 0.0


# --- horizon clipping (exact reference) ---------------------------------------------------------

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


# Hill & Heitz 2017 (ltc_code ``ltc_quad.fs``, clipless branch; ltc.md §1.5): |F| and z = F.z/|F|;
# behind the light z flips (two-sided) or the light is dark (one-sided); horizon from the sphere table.
def _integral_clipless(transformed, two_sided, table):
    f = vector_form_factor(op.normalize(transformed))
    length = op.length(f)
    z = op.safe_div(f[..., 2], length)
    back = behind(transformed)
    z = op.select(back, -z, z)
    # |F| <= 1 for any spherical region; the clamp removes the edge fit's excess near |F| = 1
    value = spheres.clipped_sphere_integral(op.saturate(length), z, table)
    return value if two_sided else op.select(back, 0.0, value).astype(value.dtype)


# Heitz et al. 2016 (ltc_code ``ltc_quad.fs``, clipped branch): clip, normalise, exact edges;
# two-sided |sum|, one-sided max(sum, 0).
def _integral_clipped(transformed, two_sided):
    clipped = op.normalize(clip_to_horizon(transformed))
    total = vector_form_factor(clipped, exact=True)[..., 2]
    return np.abs(total) if two_sided else op.maximum(total, 0.0).astype(total.dtype)


def ltc_polygon_integral(minv, corners, two_sided=False, sphere_table=None, method="clipless"):
    """Integral of the normalised LTC ``minv`` (..., 3, 3) over the polygon ``corners`` (..., K, 3)
    (local frame, relative to the shading point, ordered as in the module docstring)."""
    minv, corners = _as_float(minv, corners)
    transformed = transform(minv, corners)
    if method == "clipless":
        value = _integral_clipless(transformed, two_sided, sphere_table)
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
    return vector_form_factor(op.normalize(transform(minv, corners)))
