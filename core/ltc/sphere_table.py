"""Horizon-clipped form factor of a spherical cap, and its table (the LTC "sphere table").

The clipless LTC evaluation (Hill & Heitz 2016/2017; docs/area_lights.md, "Clipless evaluation")
replaces a polygon or a disk by the spherical cap with the same vector form factor F:
|F| = sin^2(sigma) (sigma = cap half-angle) and the cap axis along F.  The light's
horizon-clipped form factor is then approximated by the cap's, which is known in closed form
(Snyder 1996).

Table layout (stored in the spare channel A of every ``*_mag`` LTC table): ``table[j, i]``
with the z axis along i (texture u) and the |F| axis along j (texture v):
    z = 2 i/(N - 1) - 1 (cosine of the cap axis elevation), len = j/(N - 1) (= |F|),
    value = clipped_form_factor(z, len) / len in [0, 1], and max(z, 0) at len = 0.
A shader reads it at u = lut_coordinate(z/2 + 1/2), v = lut_coordinate(|F|) and multiplies
by |F| (``clipped_sphere_integral``).  Traced shader code reads channel A of the ``ltc_ggx_mag``
table (``core.lut.lookup.LutSet.sphere_table()``, a ``core.ir.tables.Table``); numpy callers may
also pass a bare (H, W) table, or nothing for the analytic table of ``default_table``.
"""
from __future__ import annotations

import functools

import numpy as np

from .. import shading_ops as op
from ..ir.expr import is_expr
from ..ir.tables import Table

#: Channel of a ``*_mag`` LTC table that holds the sphere table (docs/luts.md).
SPHERE_CHANNEL = 3

#: Default table size (64 x 64, the LTC tables' size, docs/area_lights.md, "Table layout").
SIZE = 64


# Snyder 1996, "Area light sources for real-time graphics" (Microsoft Research TR-96-11),
# projected solid angle I_hemi(omega, sigma) of a cap of half-angle sigma whose axis makes the
# angle omega with the normal, clipped by the horizon, written with its functions G and H.
# Rewritten here in z = cos(omega), len = sin^2(sigma), c = cos(sigma), q = sqrt(len - z^2);
# with sin(gamma) = c / sin(omega) and cos(gamma) = q / sin(omega), Snyder's
#   omega <  pi/2:  pi z len + G - H,    omega >= pi/2:  G + H
# collapse to one expression (H is odd in z, G even):
#   I = pi max(z, 0) len + pi/2 - atan2(c, q) - c q - |z| len atan2(q, |z| c)
# for z^2 < len (the cap straddles the horizon); I = pi max(z, 0) len otherwise.
def cap_projected_solid_angle(z, length):
    """Projected solid angle of the horizon-clipped cap (Snyder 1996 I_hemi), in [0, pi]."""
    z = op.clamp(z, -1.0, 1.0)
    length = op.saturate(length)
    c = op.sqrt(1.0 - length)
    q = op.sqrt(length - z * z)
    az = op.absolute(z)
    straddling = (0.5 * np.pi - op.atan2(c, q) - c * q - az * length * op.atan2(q, az * c))
    unclipped = np.pi * op.maximum(z, 0.0) * length
    return unclipped + op.select(z * z < length, straddling, 0.0)


def cap_form_factor(z, length):
    """Horizon-clipped form factor of the cap: I_hemi / pi (Snyder 1996), in [0, 1]."""
    return cap_projected_solid_angle(z, length) / np.pi


def cap_form_factor_ratio(z, length):
    """Clipped over unclipped form factor, clipped / |F| in [0, 1]; max(z, 0) at |F| = 0."""
    return op.select(op.saturate(length) > 0.0, op.saturate(op.safe_div(cap_form_factor(z, length), length)),
                     op.maximum(op.clamp(z, -1.0, 1.0), 0.0))


def sphere_horizon_table(size=SIZE):
    """(size, size) table[j, i] = ratio at z = 2 i/(N-1) - 1 (u axis), |F| = j/(N-1) (v axis)."""
    t = np.arange(size, dtype=np.float64) / (size - 1)
    z = 2.0 * t - 1.0
    return cap_form_factor_ratio(z[None, :], t[:, None])


@functools.lru_cache(maxsize=4)
def default_table(size=SIZE):
    """The table, built once per size (read-only)."""
    table = sphere_horizon_table(size)
    table.setflags(write=False)
    return table


def _sphere_lut(table, traced):
    """(Table, channel) for a sphere table given as a Table (channel A of a ``*_mag`` table), an (H, W)
    array, or None (the analytic table; numpy only)."""
    if isinstance(table, Table):
        return table, SPHERE_CHANNEL
    if traced:
        raise TypeError("traced code reads the sphere table from an image: pass its Table "
                        "(core.lut.lookup.LutSet.sphere_table())")
    table = default_table() if table is None else np.asarray(table)
    if table.ndim == 3:
        return Table.from_array("sphere_table", table), SPHERE_CHANNEL
    return Table.from_array("sphere_table", table[..., None]), 0


# Hill & Heitz 2016/2017 (ltc_code ``ltc_quad.fs``; docs/area_lights.md, "Clipless evaluation"):
# clipped integral of a light with
# vector form factor F ~ |F| * table(z/2 + 1/2, |F|), z = F.z / |F|, bilinear at texel centres.
# The coordinates are lut_coordinate's (x (N - 1) + 0.5) / N folded into one multiply-add each,
# without its clamp to [0, 1]: EXTEND clamps to the edge texels, which is the same lookup.
def clipped_sphere_integral(length, z, table=None):
    """|F| times the table's ratio at (z, |F|): the horizon-clipped form factor of the equivalent cap.
    ``length``, ``z`` arrays or Exprs; ``table`` as in ``_sphere_lut`` (a Table when traced)."""
    traced = is_expr(length, z)
    lut, channel = _sphere_lut(table, traced)
    size_v, size_u = lut.shape
    u = z * (0.5 * (size_u - 1) / size_u) + 0.5
    v = length * ((size_v - 1) / size_v) + 0.5 / size_v
    value = length * op.lut_sample(lut, u, v, channel)
    if traced:
        return value
    return np.asarray(value).astype(np.result_type(np.asarray(length).dtype, np.asarray(z).dtype, np.float32),
                                    copy=False)
