"""Brute-force integrals over polygonal and elliptical lights: the ground truth for the LTC code.

Everything is integrated over the light's *area* with the solid-angle Jacobian
d omega = |n . x| / |x|^3 dA (x the point on the light seen from the shading point at the
origin, n the light's unit normal), by composite Gauss-Legendre rules:
- polygons: fan triangles, each mapped from the unit square (Duffy 1982, "Quadrature over a
  pyramid or cube of integrands with a singularity at a vertex", SIAM J. Numer. Anal. 19(6));
- ellipses: the affine image of the unit disk, parameterised as (s cos t, sin t) with Jacobian
  cos^2 t (smooth over the whole disk and over any circular segment).
Integrands with a kink along a plane through the shading point (the horizon z = 0 for a
BRDF x cos, the transformed horizon (Minv x).z = 0 for an LTC) are integrated over the light
clipped by that plane, exactly, so the rules converge spectrally.

Local frame: N = +Z, shading point at the origin; polygon corners and disk axes are ordered as
in ``polygon`` / ``disk`` (one-sided lights light the origin when p0 . n >= 0, n = Newell normal,
resp. (V1 x V2) . C >= 0).  All functions here handle one light at a time.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from . import matrix

#: Default rule: panels x order Gauss-Legendre points per unit-square axis.
PANELS, ORDER = 8, 16


class Quadrature(NamedTuple):
    value: float
    error: float  # |I(resolution) - I(half the panels)|: the convergence check


def composite_gauss_legendre(a, b, panels, order):
    """Nodes and weights of ``panels`` equal Gauss-Legendre panels of ``order`` points on [a, b]."""
    x, w = np.polynomial.legendre.leggauss(order)
    edges = np.linspace(a, b, panels + 1)
    half = 0.5 * np.diff(edges)[:, None]
    return (edges[:-1, None] + half * (x + 1.0)).ravel(), (half * w).ravel()


# --- clipping ------------------------------------------------------------------------------------

def clip_polygon(points, normal):
    """Sutherland & Hodgman 1974: the part of the convex polygon ``points`` (K, 3) with normal . x >= 0."""
    out = []
    k = len(points)
    for i in range(k):
        a, b = points[i], points[(i + 1) % k]
        da, db = float(normal @ a), float(normal @ b)
        if da >= 0.0:
            out.append(a)
        if (da >= 0.0) != (db >= 0.0):
            out.append(a + (da / (da - db)) * (b - a))
    return np.array(out).reshape(-1, 3)


def newell_normal(points):
    return np.sum(np.cross(points, np.roll(points, -1, axis=0)), axis=0)


# --- area rules --------------------------------------------------------------------------------

def triangle_rule(a, b, c, panels, order):
    """Points (M, 3) and area weights (M,) on triangle abc (Duffy map from the unit square)."""
    s, ws = composite_gauss_legendre(0.0, 1.0, panels, order)
    S, T = np.meshgrid(s, s, indexing="ij")
    W = np.outer(ws, ws) * S * np.linalg.norm(np.cross(b - a, c - b))
    x = a + S[..., None] * (b - a) + (S * T)[..., None] * (c - b)
    return x.reshape(-1, 3), W.ravel()


def polygon_rule(points, clip_normal, panels, order):
    """Area rule over the convex polygon clipped to clip_normal . x >= 0 (None: no clipping)."""
    poly = points if clip_normal is None else clip_polygon(points, clip_normal)
    if len(poly) < 3:
        return np.zeros((0, 3)), np.zeros(0)
    parts = [triangle_rule(poly[0], poly[i], poly[i + 1], panels, order) for i in range(1, len(poly) - 1)]
    return np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])


def disk_rule(center, axis_u, axis_v, clip_normal, panels, order):
    """Area rule over the ellipse C + a V1 + b V2 (a^2 + b^2 <= 1) clipped to clip_normal . x >= 0:
    in (a, b) the clip is the half-plane d . (a, b) >= h, integrated as (s cos t, sin t) along d."""
    area = np.linalg.norm(np.cross(axis_u, axis_v))
    d, h = np.array([1.0, 0.0]), -1.0
    if clip_normal is not None:
        slope = np.array([clip_normal @ axis_u, clip_normal @ axis_v])
        offset, rho = float(clip_normal @ center), float(np.hypot(*slope))
        if rho <= 1e-300:
            h = -1.0 if offset >= 0.0 else 1.0
        else:
            d, h = slope / rho, float(np.clip(-offset / rho, -1.0, 1.0))
    if h >= 1.0:
        return np.zeros((0, 3)), np.zeros(0)
    t, wt = composite_gauss_legendre(np.arcsin(h), 0.5 * np.pi, panels, order)
    s, ws = composite_gauss_legendre(-1.0, 1.0, panels, order)
    S, T = np.meshgrid(s, t, indexing="ij")
    x_par, x_perp = np.sin(T), S * np.cos(T)
    a = x_perp * -d[1] + x_par * d[0]
    b = x_perp * d[0] + x_par * d[1]
    W = np.outer(ws, wt) * np.cos(T) ** 2 * area
    x = center + a[..., None] * axis_u + b[..., None] * axis_v
    return x.reshape(-1, 3), W.ravel()


# Solid angle from area: d omega = |n . x| / |x|^3 dA (n the unit light normal).
def solid_angle_integral(func, x, weights, normal):
    if len(weights) == 0:
        return 0.0
    n = normal / max(np.linalg.norm(normal), 1e-300)
    r = np.linalg.norm(x, axis=-1)
    jac = np.abs(x @ n) / np.maximum(r, 1e-300) ** 3
    return float(np.sum(func(x / r[:, None]) * jac * weights))


def _converged(estimate, panels, order):
    fine = estimate(panels, order)
    coarse = estimate(max(panels // 2, 1), order)
    return Quadrature(fine, abs(fine - coarse))


# --- generic light integrals ------------------------------------------------------------------

def integrate_polygon(func, corners, clip_normal=None, two_sided=True, panels=PANELS, order=ORDER):
    """Integral of func(l) (l unit, (M, 3) -> (M,)) over the solid angle of the polygon's part with
    clip_normal . x >= 0; a one-sided light seen from behind gives 0."""
    corners = np.asarray(corners, dtype=np.float64)
    normal = newell_normal(corners)
    if not two_sided and corners[0] @ normal < 0.0:
        return Quadrature(0.0, 0.0)
    clip = None if clip_normal is None else np.asarray(clip_normal, dtype=np.float64)
    return _converged(lambda p, o: solid_angle_integral(func, *polygon_rule(corners, clip, p, o), normal),
                      panels, order)


def integrate_disk(func, center, axis_u, axis_v, clip_normal=None, two_sided=True, panels=PANELS, order=ORDER):
    """As ``integrate_polygon`` for the ellipse with centre and semi-axis vectors (conjugate diameters)."""
    center, axis_u, axis_v = (np.asarray(a, dtype=np.float64) for a in (center, axis_u, axis_v))
    normal = np.cross(axis_u, axis_v)
    if not two_sided and center @ normal < 0.0:
        return Quadrature(0.0, 0.0)
    clip = None if clip_normal is None else np.asarray(clip_normal, dtype=np.float64)
    return _converged(lambda p, o: solid_angle_integral(
        func, *disk_rule(center, axis_u, axis_v, clip, p, o), normal), panels, order)


# --- LTC densities (Heitz et al. 2016 eq. 1-4, ``matrix.density``) ------------------------------
# The density vanishes where (Minv l).z <= 0, so the light is clipped by the plane with normal
# Minv^T e_z (the third row of Minv), the horizon of the transformed space.

def ltc_integral_polygon(minv, corners, two_sided=True, panels=PANELS, order=ORDER):
    minv = np.asarray(minv, dtype=np.float64)
    return integrate_polygon(lambda l: matrix.density(minv, l), corners, minv[2], two_sided, panels, order)


def ltc_integral_disk(minv, center, axis_u, axis_v, two_sided=True, panels=PANELS, order=ORDER):
    minv = np.asarray(minv, dtype=np.float64)
    return integrate_disk(lambda l: matrix.density(minv, l), center, axis_u, axis_v, minv[2], two_sided,
                          panels, order)


# --- BRDF x cos ground truth ------------------------------------------------------------------
# int_light f(l, v) max(l.z, 0) d omega, the light clipped at the horizon z = 0 (f_cos is 0 below).

_HORIZON = np.array([0.0, 0.0, 1.0])


def _brdf(f_cos, view):
    view = np.asarray(view, dtype=np.float64)
    return lambda l: np.where(l[..., 2] > 0.0, f_cos(l, np.broadcast_to(view, l.shape)), 0.0)


def brdf_integral_polygon(f_cos, view, corners, two_sided=False, panels=32, order=ORDER):
    """Brute-force integral of f_cos(l, v) over a polygonal light (local frame, origin = shading point)."""
    return integrate_polygon(_brdf(f_cos, view), corners, _HORIZON, two_sided, panels, order)


def brdf_integral_disk(f_cos, view, center, axis_u, axis_v, two_sided=False, panels=32, order=ORDER):
    """Brute-force integral of f_cos(l, v) over an elliptical light."""
    return integrate_disk(_brdf(f_cos, view), center, axis_u, axis_v, _HORIZON, two_sided, panels, order)


# --- clipped spherical cap (checks sphere_table) ------------------------------------------------
# The cap of half-angle sigma around an axis at cos(omega) = z: at angle t from the axis,
# l.N = A + B cos(phi) with A = z cos t, B = sqrt(1 - z^2) sin t, and
# int_0^2pi max(A + B cos phi, 0) dphi = 2 (A acos(-A/B) + sqrt(B^2 - A^2)) for B > |A|.

def cap_form_factor_numeric(z, length, panels=64, order=32):
    """Horizon-clipped form factor of the cap (z, |F| = sin^2 sigma) by 1D quadrature in t."""
    sigma = float(np.arcsin(np.sqrt(np.clip(length, 0.0, 1.0))))
    w = float(np.sqrt(max(1.0 - z * z, 0.0)))
    kink = float(np.arctan2(abs(z), w))  # B = |A|
    pieces = [(0.0, min(kink, sigma)), (min(kink, sigma), sigma)]
    total = 0.0
    for lo, hi in pieces:
        if hi <= lo:
            continue
        t, wt = composite_gauss_legendre(lo, hi, panels, order)
        A, B = z * np.cos(t), w * np.sin(t)
        wide = B > np.abs(A)
        ratio = np.clip(-A / np.where(wide, B, 1.0), -1.0, 1.0)
        inner = np.where(wide, 2.0 * (A * np.arccos(ratio) + np.sqrt(np.maximum(B * B - A * A, 0.0))),
                         2.0 * np.pi * np.maximum(A, 0.0))
        total += float(np.sum(inner * np.sin(t) * wt))
    return total / np.pi
