"""Indirect diffuse from L2 spherical harmonics, with the talk's LTC-rotated cosine lobe.

The talk ("A Journey Through Implementing Multiscattering BRDFs & Area Lights", section "LTCs for
Spherical Harmonics") closes "no multiscattering indirect diffuse" by treating the SH environment
as a light source, mapping the BRDF to a clamped cosine with the LTC inverse matrix of the
multiscattering (CoD WWII) diffuse BRDF, and evaluating the SH with a cosine lobe about the
mapped axis, scaled by the LTC magnitude.  This module gives that method, its comparison baseline
("scaling by the BRDF magnitude only": the cosine lobe about N), Lambert irradiance and a wrapped
cosine lobe, all written with ``core.shading_ops`` so they trace into node graphs, plus a numpy
brute-force reference of the true CoD BRDF under an SH environment.

Conventions
-----------
* Real SH of band <= 2, ordered (l, m) = (0,0), (1,-1), (1,0), (1,1), (2,-2), (2,-1), (2,0), (2,1),
  (2,2), with the basis of Ramamoorthi & Hanrahan 2001 ("An Efficient Representation for
  Irradiance Environment Maps", eq. 3; also Sloan 2008, "Stupid Spherical Harmonics (SH) Tricks",
  appendix) in world coordinates (x, y, z).  Radiance L(w) = sum_i c_i Y_i(w).
* Coefficients are 9 RGB vectors: a sequence of 9 vectors ((..., 3) arrays or IR vectors) or one
  (..., 9, 3) array; a node group takes them as 9 colour inputs.
* Zonal (rotationally symmetric) kernels k(n.w) are applied with the Funk-Hecke theorem:
  int k(n.w) Y_lm(w) dw = Lambda_l Y_lm(n), Lambda_l = 2 pi int_{-1}^{1} k(t) P_l(t) dt, so
  int L(w) k(n.w) dw = sum_l Lambda_l sum_m c_lm Y_lm(n)  (``sh_zonal_eval``).
"""
from __future__ import annotations

import math

import numpy as np

from . import shading_ops as op
from .conventions import ALPHA_MIN
from .diffuse import cod_multiscatter_diffuse, cod_wrapped_diffuse_cosine
from .ltc import polygon

PI = math.pi

# Ramamoorthi & Hanrahan 2001, eq. 3 (normalisation of the real SH basis, l <= 2).
Y00 = 0.5 * math.sqrt(1.0 / PI)                 # 0.282095
Y1 = math.sqrt(3.0 / (4.0 * PI))                # 0.488603
Y2_PRODUCT = 0.5 * math.sqrt(15.0 / PI)         # 1.092548: xy, yz, xz
Y20 = 0.25 * math.sqrt(5.0 / PI)                # 0.315392: (3 z^2 - 1)
Y22 = 0.25 * math.sqrt(15.0 / PI)               # 0.546274: (x^2 - y^2)

#: Band of each of the 9 coefficients.
BAND = (0, 1, 1, 1, 2, 2, 2, 2, 2)

#: Ramamoorthi & Hanrahan 2001, eq. 8-9: the clamped cosine max(t, 0)'s Funk-Hecke factors
#: A_0 = pi, A_1 = 2 pi / 3, A_2 = pi / 4 (irradiance E(n) = sum_l A_l sum_m c_lm Y_lm(n)).
LAMBERT_ZONAL = (PI, 2.0 * PI / 3.0, PI / 4.0)

#: The same lobe normalised to integrate to 1: max(t, 0)/pi -> (1, 2/3, 1/4).
COSINE_LOBE_ZONAL = (1.0, 2.0 / 3.0, 0.25)

#: The CoD WWII multiscattering diffuse LTC tables (albedo 1; channel magnitude = directional albedo).
COD_TABLE = "ltc_cod_diffuse"


def coefficient_list(coeffs):
    """The 9 RGB coefficients as a list of 9 vectors, from a sequence of 9 vectors or a (..., 9, 3) array."""
    if isinstance(coeffs, (list, tuple)):
        if len(coeffs) != 9:
            raise ValueError(f"L2 SH needs 9 coefficients, got {len(coeffs)}")
        return list(coeffs)
    a = np.asarray(coeffs)
    if a.shape[-2:] != (9, 3):
        raise ValueError(f"SH coefficients must be (..., 9, 3), got {a.shape}")
    return [a[..., i, :] for i in range(9)]


# --- the basis ---------------------------------------------------------------------------------

def sh9_basis(d):
    """The 9 real SH basis functions (Ramamoorthi & Hanrahan 2001, eq. 3) at unit direction d:
    a tuple of 9 scalars (arrays (...) or IR floats).  d is used as given (not normalised)."""
    x, y, z = (op.component(d, i) for i in range(3))
    return (Y00 + 0.0 * x,                      # keeps the caller's shape / makes a node when traced
            Y1 * y, Y1 * z, Y1 * x,
            Y2_PRODUCT * (x * y), Y2_PRODUCT * (y * z), Y20 * (3.0 * (z * z) - 1.0),
            Y2_PRODUCT * (x * z), Y22 * ((x - y) * (x + y)))


def sh_zonal_eval(coeffs9, d, zonal):
    """int L(w) k(d.w) dw for a zonal kernel with Funk-Hecke factors ``zonal`` = (Lambda_0, Lambda_1,
    Lambda_2) (scalars, arrays or IR floats) about the unit axis d: sum_l Lambda_l sum_m c_lm Y_lm(d).
    Returns an RGB vector."""
    coeffs = coefficient_list(coeffs9)
    basis = sh9_basis(d)
    total = None
    for band in range(3):
        part = None
        for i in range(9):
            if BAND[i] == band:
                term = op.scale(coeffs[i], basis[i])
                part = term if part is None else part + term
        part = op.scale(part, zonal[band])
        total = part if total is None else total + part
    return total


def sh_irradiance(coeffs9, n):
    """Irradiance E(n) = int L(w) max(n.w, 0) dw = sum_l A_l c_lm Y_lm(n) (Ramamoorthi & Hanrahan
    2001, eq. 7-9).  Lambert's outgoing radiance is albedo E / pi (``sh_lambert``)."""
    return sh_zonal_eval(coeffs9, op.normalize(n), LAMBERT_ZONAL)


def sh_cosine_lobe_eval(coeffs9, d):
    """The talk's "evaluate SH with cosine lobe": int L(w) max(d.w, 0) dw / pi about normalize(d)
    (1 in a uniform white environment)."""
    return sh_zonal_eval(coeffs9, op.normalize(d), COSINE_LOBE_ZONAL)


def sh_lambert(coeffs9, n, albedo):
    """Lambert indirect diffuse: albedo E(n) / pi (albedo: an RGB vector)."""
    return op.vmul(sh_cosine_lobe_eval(coeffs9, n), albedo)


# --- the wrapped lobe ----------------------------------------------------------------------------

def wrapped_lobe_zonal(wrap):
    """Funk-Hecke factors of the normalised wrapped lobe k(t) = max(t + w, 0) / (pi (1 + w)^2)
    (``core.diffuse.wrapped_diffuse_cosine``), w = saturate(wrap):

        Lambda_l = 2/(1 + w)^2 int_{-w}^{1} (t + w) P_l(t) dt
        Lambda_0 = 1,   Lambda_1 = (2 - w)/3,   Lambda_2 = (1 - w)^2 / 4

    (l = 1: int (t + w) t dt = (1 + w)^2 (2 - w)/6; l = 2: int (t + w)(3t^2 - 1)/2 dt = (1 - w^2)^2/8.)
    w = 0 gives the cosine lobe (1, 2/3, 1/4); Lambda_0 = 1 for every w is the normalisation's energy
    conservation (a uniform environment gives 1).  Checked by quadrature in tests/core/test_indirect.py."""
    w = op.saturate(wrap)
    one_minus = 1.0 - w
    return (1.0 + 0.0 * w, (2.0 - w) * (1.0 / 3.0), 0.25 * (one_minus * one_minus))


def sh_wrapped_lobe_eval(coeffs9, d, wrap):
    """int L(w) max(d.w + wrap, 0) dw / (pi (1 + wrap)^2) about normalize(d)."""
    return sh_zonal_eval(coeffs9, op.normalize(d), wrapped_lobe_zonal(wrap))


def sh_wrapped_diffuse(coeffs9, n, albedo, wrap):
    """Normalised wrapped Lambert under the SH environment (albedo: RGB vector)."""
    return op.vmul(sh_wrapped_lobe_eval(coeffs9, n, wrap), albedo)


# --- the talk's LTC-rotated cosine lobe ------------------------------------------------------------

def ltc_lobe_axis(c, frame, axis="talk"):
    """World-space axis of the clamped cosine that the LTC with packed Minv entries c = (c0, c1, c2, c3)
    maps to, in the shading frame ``frame`` = (T1, T2, N) (``polygon.local_frame``); not normalised.

    With R the matrix of rows (T1, T2, N) (world -> local), a world direction w goes to the cosine
    space as Minv R w, and the LTC density is D(w) ~ max((Minv R w).z, 0) / |Minv R w|^4.  The
    z-component is e_z . (Minv R w) = (R^T Minv^T e_z) . w, so the axis is

        a = R^T Minv^T e_z = R^T (row 2 of Minv) = Minv[2][0] T1 + Minv[2][1] T2 + Minv[2][2] N
          = c1 T1 + c3 N            (Minv = [[c0, 0, c2], [0, 1, 0], [c1, 0, c3]], ``core.ltc.matrix``).

    This is the talk's HLSL ``mul(float3(0, 0, 1), mul(Minv, R))``: a row vector times Minv R, i.e. the
    third row of Minv R, with Minv applied to column vectors (``mul(Minv, v)``) as in ltc_code, whose
    GLSL ``mat3(vec3(t.x, 0, t.y), vec3(0, 1, 0), vec3(t.z, 0, t.w))`` is column-major and so has the
    rows of our Minv for t = (c0, c1, c2, c3).  The clamped cosine about a has exactly the LTC's support
    (a.w > 0); the cosine lobe drops the 1/|Minv R w|^4 reshaping.

    ``axis="peak"`` (our alternative, measured more accurate in tests/core/test_indirect.py) takes instead
    the image of the cosine's peak, M e_z with M = Minv^-1: M e_z = (-c2, 0, c0)/det(Minv) in the local
    frame, i.e. the direction -c2 T1 + c0 N (det = c0 c3 - c1 c2 > 0 for every table entry)."""
    t1, _, n = frame
    if axis == "talk":
        return op.scale(t1, c[1]) + op.scale(n, c[3])
    if axis == "peak":
        return op.scale(t1, -c[2]) + op.scale(n, c[0])
    raise ValueError(f"unknown lobe axis {axis!r} (talk, peak)")


def cod_lobe(tables, n, v, roughness, axis="talk"):
    """(unit lobe axis, LTC magnitude) of the CoD multiscattering diffuse at this shading point."""
    mu = op.saturate(op.dot(n, v))
    c, magnitude, _ = tables.ltc(COD_TABLE, mu, roughness)
    return op.normalize(ltc_lobe_axis(c, polygon.local_frame(n, v), axis)), magnitude


def sh_cod_diffuse(tables, coeffs9, n, v, roughness, albedo, axis="talk"):
    """The talk's multiscattering indirect diffuse: the SH evaluated with the cosine lobe about the
    LTC-mapped axis (``ltc_lobe_axis``), scaled by the CoD table's magnitude and the albedo."""
    direction, magnitude = cod_lobe(tables, n, v, roughness, axis)
    return op.vmul(op.scale(sh_cosine_lobe_eval(coeffs9, direction), magnitude), albedo)


def sh_cod_diffuse_magnitude_only(tables, coeffs9, n, v, roughness, albedo):
    """The talk's comparison, "scaling by the BRDF magnitude only": the cosine lobe about N times the
    CoD table's magnitude and the albedo."""
    mu = op.saturate(op.dot(n, v))
    _, magnitude, _ = tables.ltc(COD_TABLE, mu, roughness)
    return op.vmul(op.scale(sh_cosine_lobe_eval(coeffs9, n), magnitude), albedo)


def sh_cod_wrapped_diffuse_magnitude_only(tables, coeffs9, n, v, roughness, albedo, wrap):
    """The "magnitude only" baseline of ``sh_cod_wrapped_diffuse``: the wrapped lobe about N (not the LTC-mapped
    axis) times the CoD table's magnitude and the albedo."""
    mu = op.saturate(op.dot(n, v))
    _, magnitude, _ = tables.ltc(COD_TABLE, mu, roughness)
    return op.vmul(op.scale(sh_wrapped_lobe_eval(coeffs9, n, wrap), magnitude), albedo)


def sh_cod_wrapped_diffuse(tables, coeffs9, n, v, roughness, albedo, wrap, axis="talk"):
    """Multiscattering wrapped diffuse under SH (the talk's "no multiscattering wrapped diffuse"):
    the wrapped lobe (``wrapped_lobe_zonal``) about the LTC-mapped axis, times the CoD magnitude and the
    albedo.  wrap = 0 is ``sh_cod_diffuse``; a uniform environment gives magnitude x albedo for every
    wrap (our combination: the talk shows the wrapped diffuse with LTCs only for area lights)."""
    direction, magnitude = cod_lobe(tables, n, v, roughness, axis)
    return op.vmul(op.scale(sh_wrapped_lobe_eval(coeffs9, direction, wrap), magnitude), albedo)


# --- numpy references ------------------------------------------------------------------------------

def sh9_basis_array(d):
    """(..., 9) array of the basis at directions d (..., 3) (numpy)."""
    return np.stack(np.broadcast_arrays(*sh9_basis(np.asarray(d, dtype=np.float64))), axis=-1)


def sh_radiance(coeffs, d):
    """Radiance sum_i c_i Y_i(d) (numpy): coeffs (..., 9, 3), d (..., K, 3) -> (..., K, 3)."""
    return np.einsum("...ki,...ic->...kc", sh9_basis_array(d), np.asarray(coeffs, dtype=np.float64))


def hemisphere_quadrature(n_theta=48, n_phi=96):
    """Local directions (K, 3) and weights (K,) over the upper hemisphere (z >= 0): Gauss-Legendre in
    z = cos(theta) on [0, 1] times the midpoint rule in phi (exact for trigonometric polynomials of
    degree < n_phi)."""
    x, wx = np.polynomial.legendre.leggauss(n_theta)
    z, wz = 0.5 * (x + 1.0), 0.5 * wx
    phi = (np.arange(n_phi) + 0.5) * (2.0 * PI / n_phi)
    s = np.sqrt(np.maximum(1.0 - z * z, 0.0))
    dirs = np.stack([s[:, None] * np.cos(phi)[None, :], s[:, None] * np.sin(phi)[None, :],
                     np.broadcast_to(z[:, None], (n_theta, n_phi))], axis=-1).reshape(-1, 3)
    weights = np.broadcast_to((wz * (2.0 * PI / n_phi))[:, None], (n_theta, n_phi)).reshape(-1)
    return dirs, weights


def sphere_quadrature(n_theta=48, n_phi=96):
    """Directions (K, 3) and weights over the whole sphere (Gauss-Legendre in z on [-1, 1])."""
    x, wx = np.polynomial.legendre.leggauss(n_theta)
    phi = (np.arange(n_phi) + 0.5) * (2.0 * PI / n_phi)
    s = np.sqrt(np.maximum(1.0 - x * x, 0.0))
    dirs = np.stack([s[:, None] * np.cos(phi)[None, :], s[:, None] * np.sin(phi)[None, :],
                     np.broadcast_to(x[:, None], (n_theta, n_phi))], axis=-1).reshape(-1, 3)
    weights = np.broadcast_to((wx * (2.0 * PI / n_phi))[:, None], (n_theta, n_phi)).reshape(-1)
    return dirs, weights


def cod_diffuse_reference(coeffs, n, v, roughness, n_theta=64, n_phi=128):
    """Brute force: int L(l) f_CoD(l, v) (n.l) dl over the hemisphere of n, the true CoD WWII
    multiscattering diffuse BRDF (``core.diffuse.cod_multiscatter_diffuse``, albedo 1, alpha = r^2
    floored as everywhere) under the SH radiance L = sum c Y.  numpy, float64.

    coeffs (..., 9, 3), n and v (..., 3) unit, roughness (...) -> (..., 3).  The integrand is smooth
    (the BRDF has no peak: its retro-reflection term decays in sqrt(n.h)), so 64 x 128 points give
    ~1e-6 relative (tested against a finer rule)."""
    n = np.asarray(n, dtype=np.float64)
    v = np.asarray(v, dtype=np.float64)
    r = np.asarray(roughness, dtype=np.float64)
    t1, t2, nn = polygon.local_frame(n, v)
    local, weights = hemisphere_quadrature(n_theta, n_phi)
    # world directions (..., K, 3)
    l = (local[:, 0, None] * t1[..., None, :] + local[:, 1, None] * t2[..., None, :]
         + local[:, 2, None] * nn[..., None, :])
    mu_l = local[:, 2]
    mu_v = np.clip(np.sum(nn * v, axis=-1), 0.0, 1.0)[..., None]
    h = l + v[..., None, :]
    h = h / np.maximum(np.linalg.norm(h, axis=-1, keepdims=True), 1e-300)
    n_dot_h = np.sum(h * nn[..., None, :], axis=-1)
    l_dot_h = np.sum(h * l, axis=-1)
    alpha = np.maximum(r * r, ALPHA_MIN)[..., None]
    f = cod_multiscatter_diffuse(1.0, mu_l, mu_v, n_dot_h, l_dot_h, alpha)
    radiance = sh_radiance(coeffs, l)
    return np.einsum("...k,...kc->...c", f * mu_l * weights, radiance)


def cod_wrapped_diffuse_reference(coeffs, n, v, roughness, wrap, n_theta=64, n_phi=128):
    """Brute force of the multiscattering wrapped diffuse (``core.diffuse.cod_wrapped_diffuse_cosine``, albedo 1)
    under the SH radiance: int L(l) f_w(l, v) mu_l dl over the directions with n.l > -w, where it is non-zero
    (Gauss-Legendre in z = n.l on [-w, 1], so the rule does not straddle the kink at z = -w; midpoint rule in
    phi).  ``wrap``: a float; numpy, float64; shapes as ``cod_diffuse_reference``."""
    w = float(np.clip(wrap, 0.0, 1.0))
    n = np.asarray(n, dtype=np.float64)
    v = np.asarray(v, dtype=np.float64)
    r = np.asarray(roughness, dtype=np.float64)
    t1, t2, nn = polygon.local_frame(n, v)
    x, wx = np.polynomial.legendre.leggauss(n_theta)
    z, wz = (x + 1.0) * (0.5 * (1.0 + w)) - w, wx * (0.5 * (1.0 + w))
    phi = (np.arange(n_phi) + 0.5) * (2.0 * PI / n_phi)
    sz = np.sqrt(np.maximum(1.0 - z * z, 0.0))
    local = np.stack([sz[:, None] * np.cos(phi)[None, :], sz[:, None] * np.sin(phi)[None, :],
                      np.broadcast_to(z[:, None], (n_theta, n_phi))], axis=-1).reshape(-1, 3)
    weights = np.broadcast_to((wz * (2.0 * PI / n_phi))[:, None], (n_theta, n_phi)).reshape(-1)
    l = (local[:, 0, None] * t1[..., None, :] + local[:, 1, None] * t2[..., None, :]
         + local[:, 2, None] * nn[..., None, :])
    alpha = np.maximum(r * r, ALPHA_MIN)[..., None]
    f_cos = cod_wrapped_diffuse_cosine(1.0, nn[..., None, :], v[..., None, :], l, alpha, w)
    return np.einsum("...k,...kc->...c", f_cos * weights, sh_radiance(coeffs, l))


def sh_project(fn, n_theta=96, n_phi=192):
    """SH coefficients (9, 3) of a radiance function fn(dirs (K, 3)) -> (K, 3), by quadrature (numpy)."""
    dirs, weights = sphere_quadrature(n_theta, n_phi)
    return np.einsum("ki,k,kc->ic", sh9_basis_array(dirs), weights, np.asarray(fn(dirs), dtype=np.float64))
