"""Integral of an LTC over a disk / ellipse light.

Heitz & Hill 2017, "Real-Time Line- and Disk-Light Shading with Linearly Transformed Cosines"
(SIGGRAPH course "Physically Based Shading in Theory and Practice"; ltc_code ``ltc_disk.fs``,
ltc.md §1.6): a linear map takes an ellipse to an ellipse, so the transformed light is the
ellipse (C, V1, V2) seen from the origin.  The cone through it is the quadric p^T Q p <= 0 with
one negative eigenvalue e2 (its axis) and two positive ones e1, e3; the cone is also the cone of a
"front-facing" ellipse centred on the axis at unit distance with extents L1 = sqrt(-e2/e3),
L2 = sqrt(-e2/e1), whose form factor is L1 L2 / sqrt((1 + L1^2)(1 + L2^2)) and whose vector
form factor points along the axis.  The horizon is handled as for polygons, by the sphere
table at (z = axis.z, |F| = form factor).

Departures from ltc_code, for robustness in float32 and for shader nodes (same values):
- the cone matrix is HH2017's Q multiplied by (A1 A2)^2 (A1, A2 the semi-axis lengths), so that
  no entry divides by the distance L of the ellipse plane or by an axis length (the roots scale,
  the form factor and the axis do not); the light is first scaled by 1/(|C| + |V1| + |V2|)
  (the cone is scale invariant) and Q by its largest entry, generalising EEVEE's "rescale the
  cubic by b for small lights" (ltc.md §2.2);
- principal axes of the 2x2 Gram matrix from the better-conditioned row of (G - e I), so the
  eigen threshold (ltc_code 1e-4, EEVEE 7e-4) only has to catch exact circles;
- only the negative root is needed: the form factor is rewritten with
  (e1 - e2)(e3 - e2) = chi'(e2) = 3 e2^2 - 2 tr(Q) e2 + S2(Q) (chi the characteristic
  polynomial), and e2 comes from a stable closed form (below) with the discriminant clamped at 0
  (ltc_code#9, Blender #67060).

Convention (as in ``polygon``): a one-sided disk lights the origin when (V1 x V2) . C >= 0,
i.e. its normal V1 x V2 points away from the lit side (ltc_code ``ltc_disk.fs``).
"""
from __future__ import annotations

import numpy as np

from .. import shading_ops as op
from . import polygon
from . import sphere_table as spheres

#: Relative anisotropy (e_max - e_min)/(e_max + e_min) below which the ellipse is treated as a circle
#: and V1 is taken as its principal axis (the error this makes is of the same relative size).
EIGEN_EPS = 1e-6


def _as_float(*arrays):
    dtype = np.result_type(*[np.asarray(a).dtype for a in arrays], np.float32)
    return [np.asarray(a, dtype=dtype) for a in arrays]


def _mat_vec(m, x):
    return np.einsum("...ij,...j->...i", m, x)


# Eigen-decomposition of the Gram matrix G = [[V1.V1, V1.V2], [V1.V2, V2.V2]] of the conjugate
# semi-diameters (Heitz & Hill 2017): e_max,min = (tr +- sqrt((d11 - d22)^2 + 4 d12^2)) / 2 are the
# squared semi-axis lengths; e_min = det G / e_max with det G = |V1 x V2|^2 (no cancellation);
# the major axis is (e_max - d22) V1 + d12 V2 if d11 >= d22, else d12 V1 + (e_max - d11) V2.
def principal_axes(v1, v2):
    """(unit major axis W1, e_max, e_min, normal V1 x V2) of the ellipse with semi-diameters v1, v2."""
    d11, d22, d12 = op.dot(v1, v1), op.dot(v2, v2), op.dot(v1, v2)
    trace = d11 + d22
    spread = op.sqrt((d11 - d22) * (d11 - d22) + 4.0 * d12 * d12)
    e_max = 0.5 * (trace + spread)
    normal = op.cross(v1, v2)
    e_min = op.safe_div(op.dot(normal, normal), e_max)
    major = op.select((d11 >= d22)[..., None], (e_max - d22)[..., None] * v1 + d12[..., None] * v2,
                      d12[..., None] * v1 + (e_max - d11)[..., None] * v2)
    w1 = op.select((spread > EIGEN_EPS * trace)[..., None], op.normalize(major), op.normalize(v1))
    return w1, e_max, e_min, normal


# The cone through the ellipse (centre (cx, cy, L) in the frame (W1, W2, W3), squared semi-axes
# u, v): p^T Q p = v (L x - cx z)^2 + u (L y - cy z)^2 - u v z^2 <= 0, i.e. HH2017's normalised
# quadric a (x - x0 z)^2 + b (y - y0 z)^2 - z^2 (a = L^2/u, x0 = cx/L, ...) times u v.
# Its invariants: tr Q = p + q + w, S2 = u v L^2 (|C|^2 - u - v) (sum of principal 2x2 minors),
# det Q = -(u v L^2)^2.  All are divided by the largest entry m (Q/m has eigenvalues in [-3, 3]).
def cone_quadric(c, w1, w2, w3, u, v):
    """Entries (p, q, w, r, t) of Q/m (Q = [[p,0,r],[0,q,t],[r,t,w]]) and its invariants (tr, S2, D = -det)."""
    ell, cx, cy = op.dot(w3, c), op.dot(w1, c), op.dot(w2, c)
    entries = [v * ell * ell, u * ell * ell, v * cx * cx + u * cy * cy - u * v, -v * ell * cx, -u * ell * cy]
    m = np.max(np.abs(np.stack(entries, axis=0)), axis=0)
    p, q, w, r, t = (op.safe_div(e, m) for e in entries)
    g = op.safe_div(u * v * ell * ell, m)
    s2 = op.safe_div(g * (op.dot(c, c) - u - v), m)
    det = op.safe_div(g * g, m)
    return (p, q, w, r, t), p + q + w, s2, det


# Negative root of x^3 - T x^2 + S x + D = 0 (three real roots, exactly one negative).
# Viete's trigonometric solution (e.g. Blinn 2007, "How to Solve a Cubic Equation, Part 5: Back to
# Numerics", IEEE CG&A 27(3)) gives each root with an error relative to the largest one; the
# acos argument is clamped to [-1, 1] (the discriminant clamp of ltc_code#9 / Blender #67060).
# If the largest root r is positive, the other two solve x^2 - s x + P = 0 with P = -D / r and
# s = (S - P) / r (Vieta), taken with the cancellation-free quadratic formula (Numerical Recipes
# 3rd ed. §5.6): this keeps the small negative root of small lights accurate (cf. EEVEE's rescale).
def negative_root(trace, s2, det):
    p = s2 - trace * trace / 3.0
    q = -2.0 * trace * trace * trace / 27.0 + trace * s2 / 3.0 + det
    m = op.sqrt(-p / 3.0)
    phi = op.acos(op.clamp(op.safe_div(-q, 2.0 * m * m * m), -1.0, 1.0))
    high = 2.0 * m * np.cos(phi / 3.0) + trace / 3.0
    low = 2.0 * m * np.cos((phi + 2.0 * np.pi) / 3.0) + trace / 3.0
    prod = op.safe_div(-det, high)
    s = op.safe_div(s2 - prod, high)
    one = np.ones_like(s)
    big = 0.5 * (s + op.select(s >= 0.0, one, -one) * op.sqrt(s * s - 4.0 * prod))
    from_quadratic = op.minimum(big, op.safe_div(prod, big))
    return op.minimum(op.select(-low >= high, low, from_quadratic), 0.0)


# Heitz & Hill 2017: |F| = L1 L2 / sqrt((1 + L1^2)(1 + L2^2)) with L1^2 = -e2/e3, L2^2 = -e2/e1,
# i.e. -e2 / sqrt((e1 - e2)(e3 - e2)); the axis is the e2-eigenvector (Q - e2 I) a = 0, a.W3 = 1.
def ellipse_vector_form_factor(c, v1, v2):
    """Vector form factor F of the ellipse (centre c, semi-diameters v1, v2) seen from the origin."""
    extent = op.length(c) + op.length(v1) + op.length(v2)
    scale = op.safe_div(np.ones_like(extent), extent)[..., None]
    c, v1, v2 = c * scale, v1 * scale, v2 * scale
    w1, u, v, normal = principal_axes(v1, v2)
    w3 = op.normalize(normal)
    w3 = op.select((op.dot(w3, c) < 0.0)[..., None], -w3, w3)
    w2 = op.cross(w3, w1)
    (p, q, _, r, t), trace, s2, det = cone_quadric(c, w1, w2, w3, u, v)
    e2 = negative_root(trace, s2, det)
    form_factor = op.saturate(op.safe_div(-e2, op.sqrt(3.0 * e2 * e2 - 2.0 * trace * e2 + s2)))
    ax, ay = op.safe_div(-r, p - e2), op.safe_div(-t, q - e2)
    axis = op.normalize(ax[..., None] * w1 + ay[..., None] * w2 + w3)
    return form_factor[..., None] * axis


def ltc_disk_vector_form_factor(minv, center, axis_u, axis_v):
    """F of the disk transformed by Minv: F.z is the exact LTC integral when it lies above the horizon."""
    minv, center, axis_u, axis_v = _as_float(minv, center, axis_u, axis_v)
    return ellipse_vector_form_factor(_mat_vec(minv, center), _mat_vec(minv, axis_u), _mat_vec(minv, axis_v))


def ltc_disk_integral(minv, center, axis_u, axis_v, two_sided=False, sphere_table=None):
    """Integral of the normalised LTC ``minv`` (..., 3, 3) over the ellipse with centre ``center`` and
    semi-axis vectors ``axis_u``, ``axis_v`` (..., 3) (local frame, relative to the shading point)."""
    minv, center, axis_u, axis_v = _as_float(minv, center, axis_u, axis_v)
    c, v1, v2 = _mat_vec(minv, center), _mat_vec(minv, axis_u), _mat_vec(minv, axis_v)
    f = ellipse_vector_form_factor(c, v1, v2)
    length = op.length(f)
    value = spheres.clipped_sphere_integral(length, op.safe_div(f[..., 2], length), sphere_table)
    if not two_sided:
        value = op.select(op.dot(op.cross(v1, v2), c) < 0.0, 0.0, value)
    return value.astype(center.dtype, copy=False)


# --- equal-area regular N-gon fallback (ltc.md §4.2, §5.1) -------------------------------------

def disk_polygon(center, axis_u, axis_v, n=8):
    """Vertices (..., n, 3) of the affine image of the regular n-gon with the disk's area:
    circumradius sqrt(2 pi / (n sin(2 pi / n))) in units of the semi-axes."""
    center, axis_u, axis_v = _as_float(center, axis_u, axis_v)
    phi = 2.0 * np.pi * np.arange(n) / n
    radius = np.sqrt(2.0 * np.pi / (n * np.sin(2.0 * np.pi / n)))
    cos_phi = (radius * np.cos(phi)).astype(center.dtype)[:, None]
    sin_phi = (radius * np.sin(phi)).astype(center.dtype)[:, None]
    return center[..., None, :] + cos_phi * axis_u[..., None, :] + sin_phi * axis_v[..., None, :]


def ltc_disk_integral_polygon(minv, center, axis_u, axis_v, n=8, two_sided=False, sphere_table=None,
                              method="clipless"):
    """The disk integral through the polygon machinery, with the equal-area n-gon (winding V1 -> V2)."""
    return polygon.ltc_polygon_integral(minv, disk_polygon(center, axis_u, axis_v, n), two_sided,
                                        sphere_table, method)
