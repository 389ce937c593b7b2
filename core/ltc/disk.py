"""Integral of an LTC over a disk / ellipse light.

Heitz & Hill 2017, "Real-Time Line- and Disk-Light Shading with Linearly Transformed Cosines"
(SIGGRAPH course "Physically Based Shading in Theory and Practice"; ltc_code ``ltc_disk.fs``;
docs/area_lights.md, "Disk and ellipse lights"): a linear map takes an ellipse to an ellipse, so
the transformed light is the ellipse (C, V1, V2) seen from the origin.  The cone through it is a
quadric with one negative eigenvalue e2 (its axis) and two positive ones e1, e3; the cone is
also the cone of a
"front-facing" ellipse centred on the axis at unit distance with extents L1 = sqrt(-e2/e3),
L2 = sqrt(-e2/e1), whose form factor is L1 L2 / sqrt((1 + L1^2)(1 + L2^2)) and whose vector
form factor points along the axis.  The horizon is handled as for polygons, by the sphere
table at (z = axis.z, |F| = form factor).

The eigenproblem is solved in the (non-orthogonal) basis B = [V1 V2 C] of the light itself, which
needs neither the ellipse's principal axes nor the cone matrix, only dot and cross products (so it
is short in shader nodes, ``LTC_DISK_INTEGRAL``).  With p = B a, the cone is a1^2 + a2^2 <= a3^2,
i.e. Q = B^-T J B^-1 (J = diag(1, 1, -1)); Q x = e x with x = B a is J a = e H a (H = B^T B, the
Gram matrix of V1, V2, C), so the eigenvalues of Q are 1/lambda for the eigenvalues lambda of
J H.  Its characteristic polynomial lambda^3 - T lambda^2 + S lambda + D has
    T = V1.V1 + V2.V2 - C.C,   S = |V1 x V2|^2 - |C x V1|^2 - |C x V2|^2,   D = (C.(V1 x V2))^2
(traces of the principal minors, Lagrange's identity; det(J H) = -det(B)^2), one negative root
lambda (the axis) and two positive ones l1, l3.  In lambda the form factor is
    sqrt(l1 l3) / sqrt((l1 - lambda)(l3 - lambda)) = |C.n| / sqrt((C.n)^2 + lambda^2 (T - 2 lambda))
(n = V1 x V2; l1 l3 = D/|lambda| and (l1 - lambda)(l3 - lambda) = l1 l3 + |lambda| (l1 + l3) + lambda^2,
all terms positive), and the axis is x = B a with a the solution of the first two rows of
(J H - lambda I) a = 0 scaled to a3 = det(G - lambda I) (G the 2x2 Gram block of V1, V2):
    x = det(G - lambda I) C + (n.(V2 x C) + lambda V1.C) V1 + (n.(C x V1) + lambda V2.C) V2,
the point where the axis pierces the light's plane (inside the ellipse), with
det(G - lambda I) = |n|^2 + |lambda| (V1.V1 + V2.V2 + |lambda|) > 0 (no cancellation) and the
Gram-entry products (V1.V2)(V2.C) - (V2.V2)(V1.C) written as n.(V2 x C), and likewise for the
other coefficient (Binet-Cauchy identity), from cross products the coefficients need anyway.

Robustness (float32 and shader nodes):
- the light is first scaled by 1/(|C| + |V1| + |V2|) (the cone is scale invariant), which
  bounds every root by 1, generalising EEVEE's "rescale the cubic for small lights"
  (docs/area_lights.md, "EEVEE's LTC code");
- the negative root comes from Viete's formula with its acos argument clamped (the fix of
  ltc_code#9 / Blender #67060) and, when it is not the root of largest magnitude, from the
  quadratic left after dividing out the largest root (``negative_root``): small lights give a
  dominant negative root (lambda ~ -|C|^2), large near lights a small one;
- every division is Blender's safe divide and the form factor is clamped to 1.

Convention (as in ``polygon``): a one-sided disk lights the origin when (V1 x V2) . C >= 0,
i.e. its normal V1 x V2 points away from the lit side (ltc_code ``ltc_disk.fs``).
"""
from __future__ import annotations

import functools
import operator

import numpy as np

from .. import shading_ops as op
from ..ir.functions import NodeFunction
from ..ir.interface import Socket, vector
from ..lut import lookup
from . import matrix, polygon
from . import sphere_table as spheres


def _as_float(*arrays):
    dtype = np.result_type(*[np.asarray(a).dtype for a in arrays], np.float32)
    return [np.asarray(a, dtype=dtype) for a in arrays]


def _mat_vec(m, x):
    return np.einsum("...ij,...j->...i", m, x)


#: Within this fraction of its smaller semi-axis from a light's centre, the ellipse is seen as a plane
#: (``ellipse_form_factor``).
NEAR_PLANE = 1e-3


# Negative root of x^3 - T x^2 + S x + D = 0 (three real roots, exactly one negative).
# Viete's trigonometric solution (e.g. Blinn 2007, "How to Solve a Cubic Equation, Part 5: Back to
# Numerics", IEEE CG&A 27(3)) gives each root with an error relative to the largest one; the
# acos argument is clamped to [-1, 1] (the discriminant clamp of ltc_code#9 / Blender #67060).
# If the largest root r is positive, the other two solve x^2 - s x + P = 0 with P = -D / r and
# s = (S - P) / r (Vieta), taken with the cancellation-free quadratic formula (Numerical Recipes
# 3rd ed. §5.6): this keeps a small negative root accurate (large lights close to the point).
def negative_root(trace, s2, det):
    """The negative root of x^3 - trace x^2 + s2 x + det (det = D >= 0); 0 for degenerate input."""
    # divisions by 3 and 27 rather than products with 1/3, 2/27: exact constants in float32 nodes
    third = trace / 3.0
    tt = trace * trace
    p = s2 - tt / 3.0
    q = tt * trace * -2.0 / 27.0 + trace * s2 / 3.0 + det
    m = op.sqrt(p / -3.0)
    phi = op.acos(op.safe_div(q, m * m * m * -2.0))        # op.acos clamps to [-1, 1]
    m2 = m * 2.0
    phi3 = phi / 3.0
    high = m2 * op.cos(phi3) + third
    low = m2 * op.cos(phi3 + 2.0 * np.pi / 3.0) + third
    prod = op.safe_div(det * -1.0, high)
    s = op.safe_div(s2 - prod, high)
    sign = polygon.unit_sign(op.less(s, 0.0), s)
    big = 0.5 * (s + sign * op.sqrt(s * s - 4.0 * prod))
    from_quadratic = op.minimum(big, op.safe_div(prod, big))
    return op.minimum(op.select(op.greater(high, -low), from_quadratic, low), 0.0)


# Heitz & Hill 2017 in the light's own basis (module docstring): form factor and axis of the cone.
def ellipse_form_factor(c, v1, v2):
    """(|F|, unit axis of F, C.(V1 x V2) of the scaled light) of the ellipse with centre c and
    semi-diameters v1, v2 (vectors, arrays or Exprs) seen from the origin; the last one's sign
    tells the side the origin is on."""
    extent = op.length(c) + op.length(v1) + op.length(v2)
    scale = op.safe_div(polygon.ones_like(extent), extent)
    c, v1, v2 = op.scale(c, scale), op.scale(v1, scale), op.scale(v2, scale)
    n = op.cross(v1, v2)
    a, b = op.cross(v2, c), op.cross(c, v1)
    cn = op.dot(c, n)
    nn = op.dot(n, n)
    h11, h22, h13, h23 = op.dot(v1, v1), op.dot(v2, v2), op.dot(v1, c), op.dot(v2, c)
    g = h11 + h22
    trace = g - op.dot(c, c)
    s2 = nn - op.dot(a, a) - op.dot(b, b)
    det = cn * cn
    lam = negative_root(trace, s2, det)
    form_factor = op.minimum(op.safe_div(op.absolute(cn), op.sqrt(det + lam * lam * (trace - 2.0 * lam))), 1.0)
    det2 = nn - lam * (g - lam)
    x = op.scale(c, det2) + op.scale(v1, op.dot(n, a) + lam * h13) + op.scale(v2, op.dot(n, b) + lam * h23)
    # Close to a large ellipse (docs/robustness.md): after the scaling |C| ~ distance / size, and for
    # distances below NEAR_PLANE x the smaller semi-axis float32 loses C against V1 and V2 in the sums above
    # (a 10^5 m disk 10 um away gave half its light).  There the cone is the half-space on the light's side:
    # the axis is the light's normal towards it and |F| = |V1 x V2| / (|V1 x V2| + |C|^2), exact for a point on
    # the axis of a circle (R^2 / (R^2 + h^2)) and within O(NEAR_PLANE^2) elsewhere in the region.
    # |C|^2 (|V1|^2 + |V2|^2) < NEAR_PLANE^2 |V1 x V2|^2: |C| below NEAR_PLANE x the smaller semi-axis (or
    # up to sqrt(2) less)
    cc = op.dot(c, c)
    near = op.less(cc * g, NEAR_PLANE * NEAR_PLANE * nn)
    n_len = op.sqrt(nn)
    toward = op.scale(n, op.safe_div(polygon.unit_sign(op.less(cn, 0.0), cn), n_len))
    axis = op.vselect(near, toward, op.normalize(x))
    near_form_factor = op.safe_div(n_len, n_len + cc)
    return op.select(near, near_form_factor, form_factor), axis, cn


def ellipse_vector_form_factor(c, v1, v2):
    """Vector form factor F of the ellipse (centre c, semi-diameters v1, v2) seen from the origin."""
    form_factor, axis, _ = ellipse_form_factor(c, v1, v2)
    return op.scale(axis, form_factor)


def disk_integral_transformed(c, v1, v2, two_sided, sphere_table=None):
    """Horizon-clipped integral of the clamped cosine over the ellipse (c, v1, v2), already transformed
    by Minv; traceable.  ``two_sided`` bool or 0/1; ``sphere_table`` as in ``polygon``."""
    form_factor, axis, cn = ellipse_form_factor(c, v1, v2)
    value = spheres.clipped_sphere_integral(form_factor, op.component(axis, 2), sphere_table)
    # seen edge-on (polygon.EDGE_ON_SIN; the test is scale-free, so the unscaled light serves)
    off = polygon.beyond_plane(op.dot(c, op.cross(v1, v2)),
                               polygon.EDGE_ON_SIN * op.length(c) * op.length(op.cross(v1, v2)))
    return op.select(off, op.select(op.less(cn, 0.0), value * two_sided, value), 0.0)


def ltc_disk_integral_packed(c, center, axis_u, axis_v, two_sided=False, sphere_table=None):
    """Integral of the LTC with packed entries c = (c0, c1, c2, c3) over the ellipse (local frame,
    relative to the shading point); traceable."""
    return disk_integral_transformed(matrix.transform_packed(c, center), matrix.transform_packed(c, axis_u),
                                     matrix.transform_packed(c, axis_v), two_sided, sphere_table)


def ltc_disk_vector_form_factor(minv, center, axis_u, axis_v):
    """F of the disk transformed by Minv: F.z is the exact LTC integral when it lies above the horizon."""
    minv, center, axis_u, axis_v = _as_float(minv, center, axis_u, axis_v)
    return ellipse_vector_form_factor(_mat_vec(minv, center), _mat_vec(minv, axis_u), _mat_vec(minv, axis_v))


def ltc_disk_integral(minv, center, axis_u, axis_v, two_sided=False, sphere_table=None):
    """Integral of the normalised LTC ``minv`` (..., 3, 3) over the ellipse with centre ``center`` and
    semi-axis vectors ``axis_u``, ``axis_v`` (..., 3) (local frame, relative to the shading point); numpy."""
    minv, center, axis_u, axis_v = _as_float(minv, center, axis_u, axis_v)
    value = disk_integral_transformed(_mat_vec(minv, center), _mat_vec(minv, axis_u), _mat_vec(minv, axis_v),
                                      two_sided, sphere_table)
    return np.asarray(value).astype(center.dtype, copy=False)


# --- equal-area regular N-gon fallback (docs/area_lights.md, "Disk and ellipse lights") ---------

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


# --- the node function -------------------------------------------------------------------------

def _disk_integral_node(tables, **inputs):
    c = tuple(inputs[f"c{i}"] for i in range(4))
    return {"Integral": ltc_disk_integral_packed(c, inputs["Center"], inputs["Axis U"], inputs["Axis V"],
                                                 inputs["Two Sided"], tables.sphere_table())}


#: Integral of an LTC over a disk / ellipse light (Heitz & Hill 2017): one node group.
LTC_DISK_INTEGRAL = NodeFunction(
    "RTL LTC Disk Integral", _disk_integral_node,
    inputs=dict(polygon.LTC_MATRIX_SOCKETS, **{
        "Center": vector("Centre of the disk in the local shading frame (T1, T2, N), relative to the "
                         "shading point", "XYZ"),
        "Axis U": vector("First semi-axis vector of the disk (local frame); a circle of radius R has "
                         "|Axis U| = |Axis V| = R", "XYZ"),
        "Axis V": vector("Second semi-axis vector (local frame); Axis U x Axis V points away from the lit "
                         "side", "XYZ"),
        "Two Sided": polygon.TWO_SIDED_SOCKET}),
    outputs={"Integral": Socket("float", 0.0, 0.0, 1.0, "FACTOR",
                                "Integral of the normalised LTC over the disk, horizon-clipped (sphere table): "
                                "multiply by the lobe's magnitude")},
    description="LTC integral over a disk or ellipse light (Heitz & Hill 2017 closed form)",
    tables=lookup.REFERENCES)



# --- exact horizon: the closed form above it, an equal-area polygon clipped at it ----------------

#: Sides of the equal-area polygon (``disk_polygon``) that stands in for a disk crossing the horizon in
#: ``LTC_DISK_INTEGRAL_CLIPPED``.  Measured on the Zeltner sheen's LTC at sheen roughness 0.2 (random disks
#: carrying > 10% of the lobe, crossing the horizon): relative error median / p90 0.39% / 0.86% with 8 sides,
#: 0.03% / 0.17% with 12, against 20% / 36% with the sphere table (docs/sheen.md).
CLIPPED_DISK_SIDES = 12


def _disk_corner(kw, key):
    return kw["Center"] + op.scale(kw["Axis U"], kw[f"Cos {key}"]) + op.scale(kw["Axis V"], kw[f"Sin {key}"])


_DISK_SOCKETS = {"Center": vector("Centre of the transformed disk (local frame)", "XYZ"),
                 "Axis U": vector("First transformed semi-axis", "XYZ"),
                 "Axis V": vector("Second transformed semi-axis", "XYZ")}


def _corner_sockets(keys):
    return {f"{t} {k}": Socket("float", 0.0, description=f"{t} of corner {k}'s angle, times the polygon's "
                                                          "circumradius") for k in keys for t in ("Cos", "Sin")}


# The equal-area polygon's corners are made where they are used (each edge's group builds its own from the
# disk), so only the disk stays live, not the 12 corners (Cycles' SVM stack, Blender 4.5: a shade group with GGX,
# CoD and this integral overflowed it with the corners held at once).
_DISK_EXIT_PART = NodeFunction(
    "RTL Disk Polygon Exit", lambda **kw: {"Exit Part": polygon.exit_part(_disk_corner(kw, "A"), _disk_corner(kw, "B"))},
    dict(_DISK_SOCKETS, **_corner_sockets("AB")),
    {"Exit Part": vector("The edge's crossing where it leaves the upper half-space, else 0", "XYZ")},
    "One edge of the disk's equal-area polygon: its share of the exit point")
_DISK_EDGE = NodeFunction(
    "RTL Disk Polygon Edge",
    lambda **kw: polygon.connected_edge_terms(_disk_corner(kw, "A"), _disk_corner(kw, "B"), _disk_corner(kw, "C"),
                                              kw["Exit"], kw["O"]),
    dict(_DISK_SOCKETS, **_corner_sockets("ABC"), Exit=vector("The polygon's exit point", "XYZ"),
         O=vector("A point of the clipped polygon", "XYZ")),
    {"Area": Socket("float", 0.0, description="z of sum w (a - o) x (b - o) over the edge's two arcs"),
     "Flow": vector("sum w (b - a) over the edge's two arcs", "XYZ")},
    "One edge of the disk's equal-area polygon clipped at the horizon and its connection to the next, in Arvo's "
    "form factor")


def _sum(terms):
    return functools.reduce(operator.add, terms)


def polygon_form_factor_z(c, v1, v2, sides=CLIPPED_DISK_SIDES):
    """z of the vector form factor of the transformed disk's equal-area ``sides``-gon clipped at the horizon
    (``polygon.connected_edge_terms``, corners built per edge: polygon.py says why not the running sums);
    traceable."""
    radius = float(np.sqrt(2.0 * np.pi / (sides * np.sin(2.0 * np.pi / sides))))
    angles = [(float(radius * np.cos(f)), float(radius * np.sin(f))) for f in 2.0 * np.pi * np.arange(sides) / sides]
    disk = {"Center": c, "Axis U": v1, "Axis V": v2}

    def corners(*indices):
        return {f"{t} {k}": angles[i % sides][j] for k, i in zip("ABC", indices) for j, t in enumerate(("Cos", "Sin"))}

    exit_point = _sum([_DISK_EXIT_PART(**disk, **corners(i, i + 1))["Exit Part"] for i in range(sides)])
    origin = polygon.clipped_origin(c + op.scale(v1, angles[0][0]) + op.scale(v2, angles[0][1]),
                                    c + op.scale(v1, angles[1][0]) + op.scale(v2, angles[1][1]), exit_point)
    terms = [_DISK_EDGE(**disk, **corners(i, i + 1, i + 2), Exit=exit_point, O=origin) for i in range(sides)]
    return polygon.connected_sum_z(_sum([t["Area"] for t in terms]), _sum([t["Flow"] for t in terms]), origin)


def disk_integral_horizon_clipped(c, v1, v2, two_sided, sphere_table=None, sides=CLIPPED_DISK_SIDES, closed=None):
    """``disk_integral_transformed`` with an exact horizon: where the transformed ellipse lies above z = 0 the
    closed form is exact; where it crosses, the equal-area ``sides``-gon clipped at the horizon
    (``polygon_form_factor_z``) replaces the sphere table.  ``closed``: the closed form's value when the caller
    has it (the node function's nested "RTL LTC Disk Integral")."""
    if closed is None:
        closed = disk_integral_transformed(c, v1, v2, two_sided, sphere_table)
    reach = op.sqrt(op.component(v1, 2) * op.component(v1, 2) + op.component(v2, 2) * op.component(v2, 2))
    above = op.greater(op.component(c, 2) - reach, 0.0)
    fz = polygon_form_factor_z(c, v1, v2, sides)
    normal = op.cross(v1, v2)
    side = op.dot(c, normal)
    lit = polygon.beyond_plane(side, polygon.EDGE_ON_SIN * op.length(c) * op.length(normal))
    return op.select(above, closed, polygon.clipped_side_value(fz, op.less(side, 0.0), lit, two_sided))


def _disk_integral_clipped_node(tables, **inputs):
    c = tuple(inputs[f"c{i}"] for i in range(4))
    t = [matrix.transform_packed(c, inputs[k]) for k in ("Center", "Axis U", "Axis V")]
    closed = LTC_DISK_INTEGRAL(tables, **inputs)["Integral"]
    return {"Integral": disk_integral_horizon_clipped(*t, inputs["Two Sided"], closed=closed)}


#: ``LTC_DISK_INTEGRAL`` with an exact horizon (``disk_integral_horizon_clipped``).
LTC_DISK_INTEGRAL_CLIPPED = NodeFunction(
    "RTL LTC Disk Integral (Clipped)", _disk_integral_clipped_node, inputs=LTC_DISK_INTEGRAL.input_sockets,
    outputs={"Integral": Socket("float", 0.0, 0.0, 1.0, "FACTOR",
                                "Integral of the normalised LTC over the disk: closed form above the horizon, an "
                                f"equal-area {CLIPPED_DISK_SIDES}-gon clipped exactly where it crosses")},
    description="LTC integral over a disk or ellipse light with an exact horizon (closed form + clipped polygon)",
    tables=lookup.REFERENCES)
