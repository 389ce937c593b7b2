"""LTC matrices: packing, the transformed-cosine density, and sampling.

Heitz et al. 2016, "Real-Time Polygonal-Light Shading with Linearly Transformed Cosines":
a direction w has density D(w) = D_o(w_o) |det Minv| / |Minv w|^3 with w_o = Minv w / |Minv w|
and D_o(w_o) = max(w_o.z, 0) / pi (eq. 1-4).  The density does not depend on the scale of
Minv, which is therefore normalised by its middle element.

Shader code keeps Minv as its four packed entries c = (c0, c1, c2, c3) (the table's channels) and
applies it with ``transform_packed``; full 3x3 matrices appear only in numpy helpers.
"""
from __future__ import annotations

import numpy as np

from .. import shading_ops as op


def unpack_inverse(c):
    """(..., 4) packed entries (c0, c1, c2, c3) -> (..., 3, 3) Minv (row-major layout above)."""
    c = np.asarray(c, dtype=np.float64)
    m = np.zeros(c.shape[:-1] + (3, 3))
    m[..., 0, 0] = c[..., 0]
    m[..., 2, 0] = c[..., 1]
    m[..., 0, 2] = c[..., 2]
    m[..., 2, 2] = c[..., 3]
    m[..., 1, 1] = 1.0
    return m


# Heitz et al. 2016 (ltc_code's table layout, docs/area_lights.md, "Table layout"):
# Minv = [[c0, 0, c2], [0, 1, 0], [c1, 0, c3]].
def transform_packed(c, point):
    """Minv applied to a point (a (..., 3) array or an Expr vector) for packed entries c = (c0, c1, c2, c3):
    (c0 x + c2 z, y, c1 x + c3 z), written as two dot products with the rows (c0, 0, c2) and
    (c1, 0, c3) (shared by every point of a light once traced)."""
    c0, c1, c2, c3 = c
    zero = c0 * 0.0   # a constant 0 once traced; keeps a numpy caller's dtype
    return op.vec3(op.dot(point, op.vec3(c0, zero, c2)), op.component(point, 1), op.dot(point, op.vec3(c1, zero, c3)))


def pack_inverse(minv):
    """(..., 3, 3) Minv with zero y-couplings -> (..., 4) entries normalised by Minv[1][1]."""
    minv = np.asarray(minv, dtype=np.float64)
    scale = minv[..., 1, 1][..., None]
    return np.stack([minv[..., 0, 0], minv[..., 2, 0], minv[..., 0, 2], minv[..., 2, 2]], axis=-1) / scale


def density(minv, w):
    """LTC density D(w) for directions w (..., 3) and matrices Minv (..., 3, 3) (broadcast)."""
    wo = np.einsum("...ij,...j->...i", minv, w)
    length2 = np.sum(wo * wo, axis=-1)
    det = np.abs(np.linalg.det(minv))
    # D_o(wo/|wo|) |det Minv| / |wo|^3 = max(wo.z, 0) / (pi |wo|^4) |det Minv|
    return np.maximum(wo[..., 2], 0.0) / np.pi * det / np.maximum(length2 * length2, 1e-300)


def sample(m, u1, u2):
    """Directions distributed with the LTC of matrix M = inverse(Minv): M w_o / |M w_o|, w_o cosine-distributed."""
    r = np.sqrt(u1)
    phi = 2.0 * np.pi * u2
    wo = np.stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(np.maximum(1.0 - u1, 0.0))], axis=-1)
    w = np.einsum("...ij,...j->...i", m, wo)
    return w / np.linalg.norm(w, axis=-1, keepdims=True)


def density_packed(c, w):
    """D(w) for packed entries c (..., 4) and directions w (..., 3): the density above without
    building matrices (Minv has four free entries and Minv[1][1] = 1)."""
    c0, c1, c2, c3 = (c[..., i] for i in range(4))
    x = c0[..., None] * w[..., 0] + c2[..., None] * w[..., 2]
    y = w[..., 1]
    z = c1[..., None] * w[..., 0] + c3[..., None] * w[..., 2]
    length2 = x * x + y * y + z * z
    det = np.abs(c0 * c3 - c1 * c2)[..., None]
    return np.maximum(z, 0.0) / np.pi * det / np.maximum(length2 * length2, 1e-300)


# The GGX table's band (this project's, issue 15; docs/area_lights.md, "The band"): the fitted LTC with its
# third column scaled by k, Minv diag(1, 1, k): the density at w is the fitted one's at (x, y, k z), its lobe
# pressed towards the horizon (k > 1) with the same azimuths.  Minv_yy stays 1 (the packing holds).
def squash_packed(c, k):
    """Packed entries of Minv diag(1, 1, k) for packed entries c = (c0, c1, c2, c3) (arrays or Exprs)."""
    c0, c1, c2, c3 = c
    return c0, c1, c2 * k, c3 * k
