"""Zeltner, Burley & Chiang 2022 sheen: the lobe Blender's Principled BSDF and Sheen BSDF (Microfiber) use.

Zeltner et al. 2022, "Practical Multiple-Scattering Sheen Using Linearly Transformed Cosines" (sec. 3-4):
the multiple-scattering reflectance of a volumetric fibre layer, fitted per (mu_v, r) by one LTC whose
inverse matrix keeps two free entries, Minv = [[a, 0, b], [0, a, 0], [0, 0, 1]] in the local frame (N = +Z,
the view in the XZ plane towards +X), and a scale, the directional albedo R(mu_v, r):

    f(l, v) cos(theta_l) = R * D_ltc(l) = R * a^2 max(z, 0) / (pi ((a x + b z)^2 + a^2 y^2 + z^2)^2)

for l = (x, y, z): the LTC density |det Minv| D_o(Minv l / |Minv l|) / |Minv l|^3 with D_o the clamped
cosine / pi (Heitz et al. 2016, eq. 1-4).  (a, b, R) come from the paper's fitted table as Cycles reads it,
measured from Cycles into the table ``zeltner_sheen`` (validation/benchmarks/sheen_table.py, docs/luts.md).

Cycles clamps the sheen roughness to [1e-3, 1] and drops the lobe where the interpolated |a| or albedo is
below 1e-5 (``CUTOFF``); so do we.  Since the density is invariant under a uniform scale of Minv, the
project's packed Minv (normalised so that Minv_yy = 1, core/ltc/matrix.py) is (c0, c1, c2, c3) =
(1, 0, b/a, 1/a), and an area light's integral is the ordinary LTC integral of that matrix times R.
"""
from __future__ import annotations

import numpy as np

from . import shading_ops as op

#: Cycles' sheen roughness floor and its cut-off on |a| and the albedo (bsdf_sheen.h, bsdf_sheen_setup).
ROUGHNESS_MIN = 1e-3
CUTOFF = 1e-5


def zeltner_roughness(r):
    """The sheen roughness as Cycles reads the table with it: clamped to [1e-3, 1]."""
    return op.clamp(r, ROUGHNESS_MIN, 1.0)


def zeltner_active(a, albedo):
    """1 where Cycles keeps the lobe (|a| and the albedo at least ``CUTOFF``), else 0."""
    return op.logical_and(1.0 - op.less(op.absolute(a), CUTOFF), 1.0 - op.less(albedo, CUTOFF))


# Zeltner et al. 2022, sec. 3: the LTC with Minv = [[a, 0, b], [0, a, 0], [0, 0, 1]] (Heitz et al. 2016, eq. 1-4).
def zeltner_density(x, y, z, a, b):
    """D_ltc at the local direction (x, y, z) (unit), without the albedo; 0 below the horizon."""
    u = a * x + b * z
    length2 = u * u + a * a * y * y + z * z
    return op.safe_div(a * a * op.maximum(z, 0.0), np.pi * length2 * length2)


def zeltner_packed_inverse(a, b):
    """The LTC's inverse matrix in the project's packing (c0, c1, c2, c3) = (1, 0, b/a, 1/a)."""
    return (1.0 + 0.0 * a, 0.0 * a, op.safe_div(b, a), op.safe_div(1.0, a))
