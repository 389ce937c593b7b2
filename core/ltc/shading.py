"""Area-light shading with LTCs: the talk's combinations, evaluated in numpy.

Every function returns outgoing radiance per unit emitted radiance of the light (multiply by
the light's radiance), vectorised over shading points.  Geometry is world-space: shading
point ``p``, unit normal ``n``, unit view ``v`` (towards the eye), and a light built with
``QuadLight`` or ``DiskLight``.  ``tables`` is a ``core.lut.lookup.LtcTables``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import diffuse, multiscatter
from .. import shading_ops as op
from . import disk, matrix, polygon

#: The talk's Disney sheen uses the CoD diffuse tables at this roughness (smoothness 0.5).
SHEEN_TABLE_ROUGHNESS = 0.5


@dataclass(frozen=True)
class QuadLight:
    """A planar quad: corners (..., 4, 3) in order.  One-sided lights emit on the side away from
    which (c1 - c0) x (c3 - c0) points (corners clockwise seen from the lit side; ltc_code's
    convention, ``polygon.behind``)."""
    corners: np.ndarray
    two_sided: bool = False

    def integral(self, minv, p, n, v, sphere_table):
        local, _ = polygon.to_local(self.corners, p, n, v)
        return polygon.ltc_quad_integral(minv, local, self.two_sided, sphere_table)


@dataclass(frozen=True)
class DiskLight:
    """An ellipse (disk when |axis_u| = |axis_v|): centre and semi-axis vectors (..., 3).  One-sided
    lights emit on the side away from which axis_u x axis_v points (as ``QuadLight``)."""
    center: np.ndarray
    axis_u: np.ndarray
    axis_v: np.ndarray
    two_sided: bool = False

    def integral(self, minv, p, n, v, sphere_table):
        t1, t2, nn = polygon.local_frame(n, v)

        def local(x, is_point):
            d = np.asarray(x) - (np.asarray(p) if is_point else 0.0)
            return np.stack([op.dot(d, t1), op.dot(d, t2), op.dot(d, nn)], axis=-1)

        return disk.ltc_disk_integral(minv, local(self.center, True), local(self.axis_u, False),
                                      local(self.axis_v, False), self.two_sided, sphere_table)


def lobe_integral(tables, prefix, light, p, n, v, roughness):
    """(LTC integral, magnitude, fresnel) of one table's lobe at this shading point."""
    mu = op.saturate(op.dot(n, v))
    packed, magnitude, fresnel = tables.lookup(prefix, mu, roughness)
    value = light.integral(matrix.unpack_inverse(packed), p, n, v, tables.sphere_table(prefix))
    return value, magnitude, fresnel


# Heitz et al. 2016 with Hill 2016's Fresnel split: int f cos F = F0 (mag - fres) + F90 fres.
def ggx_specular(tables, light, p, n, v, roughness, f0, f90=1.0):
    value, magnitude, fresnel = lobe_integral(tables, "ltc_ggx", light, p, n, v, roughness)
    return value * (f0 * (magnitude - fresnel) + f90 * fresnel)


# The talk, "No implementation for multiscattering specular": scale f_ss by Turquin's
# 1 + F0 (1 - E)/E or by the approximation to Fdez-Aguera, E = the GGX table's magnitude.
def ggx_specular_multiscatter(tables, light, p, n, v, roughness, f0, method="turquin"):
    value, magnitude, fresnel = lobe_integral(tables, "ltc_ggx", light, p, n, v, roughness)
    single = value * (f0 * (magnitude - fresnel) + fresnel)
    if method == "turquin":
        return single * multiscatter.turquin_compensation(f0, magnitude)
    if method == "fdez_aguera":
        return single * multiscatter.fdez_aguera_area_scale(f0, magnitude)
    raise ValueError(f"unknown multiscattering method {method!r}")


# The talk, "LTCs for multiscattering diffuse": the CoD WWII lobe's own LTC (albedo 1 in the table).
def cod_diffuse(tables, light, p, n, v, roughness, albedo):
    value, magnitude, _ = lobe_integral(tables, "ltc_cod_diffuse", light, p, n, v, roughness)
    return np.asarray(albedo) * magnitude * value


# The talk, "LTCs for Ashikhmin cloth": the cloth lobe's LTC (sheen colour 1 in the table).
def ashikhmin_cloth(tables, light, p, n, v, roughness, sheen_color):
    value, magnitude, _ = lobe_integral(tables, "ltc_cloth", light, p, n, v, roughness)
    return np.asarray(sheen_color) * magnitude * value


def disney_sheen(tables, light, p, n, v, sheen_color):
    """The talk: f_sheen(theta) ~ LTC_MagFresnel,MSDiffuse(theta, 0.5): the Fresnel channel of the
    CoD diffuse table at r = 0.5 with that table's LTC.  The CoD lobe carries 1/pi and Disney
    sheen (1 - l.h)^5 does not (Burley 2012), hence the factor pi; the error of the whole
    approximation is measured in docs/benchmarks/ltc.md."""
    r = np.full(np.shape(op.dot(n, v)), SHEEN_TABLE_ROUGHNESS)
    value, _, fresnel = lobe_integral(tables, "ltc_cod_diffuse", light, p, n, v, r)
    return np.asarray(sheen_color) * np.pi * fresnel * value


def lambert(tables, light, p, n, v, albedo):
    """Lambert: the identity LTC gives the exact form factor (Heitz et al. 2016, section 5)."""
    identity = np.broadcast_to(np.eye(3), np.shape(op.dot(n, v)) + (3, 3))
    value = light.integral(identity, p, n, v, tables.sphere_table())
    return np.asarray(albedo) * value


def light_center(light):
    return light.center if isinstance(light, DiskLight) else np.mean(light.corners, axis=-2)


# The talk, "How to combine LTCs with wrapped diffuse": tilt N towards the light's centre
# (WrappedNormal), integrate the clamped cosine about the tilted normal, normalise by 1/(1 + w).
def wrapped_diffuse(tables, light, p, n, v, albedo, wrap):
    to_light = op.normalize(light_center(light) - np.asarray(p))
    n_wrapped = diffuse.wrapped_normal(n, to_light, wrap)
    return lambert(tables, light, p, n_wrapped, v, albedo) / (1.0 + op.saturate(wrap))
