"""Real L2 spherical harmonics of environment images (numpy, float64).

Sources
-------
* Ramamoorthi & Hanrahan 2001, "An Efficient Representation for Irradiance Environment Maps"
  (SIGGRAPH 2001): the real basis of band l <= 2 (eq. 3), the projection L_lm = int L Y_lm (eq. 6
  with the integral over the sphere), irradiance E(n) = sum_lm A_l L_lm Y_lm(n) (eq. 7) with the
  clamped cosine's factors A_0 = pi, A_1 = 2 pi / 3, A_2 = pi / 4 (eq. 8-9).
* Sloan 2008, "Stupid Spherical Harmonics (SH) Tricks" (GDC), section "Zonal harmonics": a
  function k(n.w) symmetric about an axis n has coefficients f_lm = sqrt(4 pi / (2l + 1)) z_l Y_lm(n)
  with z_l its zonal coefficients about +Z (eq. 26, "rotating zonal harmonics"); with the Funk-Hecke
  theorem (Lambda_l = 2 pi int_{-1}^{1} k(t) P_l(t) dt = sqrt(4 pi / (2l + 1)) z_l) this is
  f_lm = Lambda_l Y_lm(n), and for k = max(t, 0), Lambda_l = A_l.  That is the talk's
  ``SH3EvalCosineLobe`` (McAuley 2019, section "LTCs for Spherical Harmonics").

Conventions (the same as ``core/indirect.py``): 9 coefficients ordered
(l, m) = (0,0), (1,-1), (1,0), (1,1), (2,-2), (2,-1), (2,0), (2,1), (2,2), i.e. the functions
1, y, z, x, xy, yz, 3z^2 - 1, xz, x^2 - y^2 times their constants, in world coordinates (Z up);
coefficient arrays are (9, 3) for RGB (or (..., 9) for a scalar lobe).
"""
from __future__ import annotations

import math

import numpy as np

from .. import indirect
from . import equirect

PI = math.pi

#: Band l and order m of each coefficient.
BAND = np.array([0, 1, 1, 1, 2, 2, 2, 2, 2])
ORDER = np.array([0, -1, 0, 1, -2, -1, 0, 1, 2])

#: Ramamoorthi & Hanrahan 2001, eq. 8-9: Funk-Hecke factors of the clamped cosine max(t, 0).
LAMBERT_ZONAL = np.array([PI, 2.0 * PI / 3.0, PI / 4.0])


def sh9_basis(d):
    """(..., 9) real SH basis at unit directions d (..., 3) (R&H 2001, eq. 3; d used as given): the
    traceable basis of core/indirect.py (the one the node groups evaluate), as an array."""
    return indirect.sh9_basis_array(d)


def per_coefficient(zonal):
    """Expand per-band factors (..., 3) to the 9 coefficients (..., 9)."""
    return np.asarray(zonal, dtype=np.float64)[..., BAND]


# --- projection --------------------------------------------------------------------------------

def sh_project(env, rule="fejer", rows_per_chunk=128):
    """(9, 3) SH coefficients L_lm = int L(w) Y_lm(w) dw (R&H 2001, eq. 6) of an environment.

    ``env``: an ``equirect.Environment`` (rotation and strength applied: the coefficients are those
    of the world radiance) or an (H, W, 3) image (no rotation, strength 1).  The integral is the
    point-sample quadrature ``equirect.quadrature_weights(rule)`` at the texel centres: with the
    default Fejer rule it is exact (to rounding) for every environment whose radiance is a polynomial
    of degree < H in z times a trigonometric polynomial of degree < W in phi, since Y_lm L then is
    one too; ``rule="area"`` weights each texel by its exact solid angle."""
    if not isinstance(env, equirect.Environment):
        env = equirect.Environment(np.asarray(env))
    h, w = env.shape
    row_weights = equirect.quadrature_weights(h, 1, rule)[:, 0] / w     # every texel of a row alike
    total = np.zeros((9, 3))
    for s in range(0, h, rows_per_chunk):        # bounded memory for 8K-16K images
        rows = slice(s, s + rows_per_chunk)
        basis = sh9_basis(env.world_texel_directions(rows))                   # (rows, W, 9)
        image = np.asarray(env.image[rows], dtype=np.float64)
        total += np.einsum("hwi,h,hwc->ic", basis, row_weights[rows], image)
    return env.strength * total


def sh_rotate_z(coeffs, angle):
    """Coefficients of the environment L'(d) = L(R_z(angle) d) (a world rotated as by the Mapping
    node) from those of L: for m > 0, c'_{l,m} = cos(m a) c_{l,m} + sin(m a) c_{l,-m},
    c'_{l,-m} = cos(m a) c_{l,-m} - sin(m a) c_{l,m} (the real basis' cos(m phi), sin(m phi) under
    phi -> phi - a).  Exact; used where the image is baked once and the world rotation changes."""
    c = np.array(coeffs, dtype=np.float64, copy=True)
    out = c.copy()
    for plus, minus, m in ((3, 1, 1), (7, 5, 1), (8, 4, 2)):
        ca, sa = math.cos(m * angle), math.sin(m * angle)
        out[..., plus, :] = ca * c[..., plus, :] + sa * c[..., minus, :]
        out[..., minus, :] = ca * c[..., minus, :] - sa * c[..., plus, :]
    return out


# --- evaluation --------------------------------------------------------------------------------

def sh_radiance(coeffs, d):
    """Band-limited radiance sum_lm L_lm Y_lm(d): coeffs (9, 3), d (..., 3) -> (..., 3)."""
    return sh9_basis(d) @ np.asarray(coeffs, dtype=np.float64)


def sh_zonal_convolve(coeffs, d, zonal):
    """int L(w) k(d.w) dw = sum_l Lambda_l sum_m L_lm Y_lm(d) for a zonal kernel with Funk-Hecke
    factors ``zonal`` = (Lambda_0, Lambda_1, Lambda_2) about unit d (..., 3) -> (..., 3)."""
    return (sh9_basis(d) * per_coefficient(zonal)) @ np.asarray(coeffs, dtype=np.float64)


def sh_irradiance(coeffs, n):
    """Irradiance E(n) = int L(w) max(n.w, 0) dw = sum_lm A_l L_lm Y_lm(n) (R&H 2001, eq. 7-9);
    n (..., 3) unit.  Lambert's outgoing radiance is albedo E / pi."""
    return sh_zonal_convolve(coeffs, n, LAMBERT_ZONAL)


def sh_eval_cosine_lobe(direction):
    """SH coefficients (..., 9) of the clamped cosine lobe max(direction . w, 0) about a unit
    direction: the zonal factors A_l (R&H 2001, eq. 8-9) rotated to ``direction``,
    f_lm = A_l Y_lm(direction) (Sloan 2008, eq. 26 with Funk-Hecke), as the talk's
    ``SH3EvalCosineLobe``: 0.886227 = pi Y00, 1.023328 = (2 pi / 3) Y1, 0.858086 = (pi/4) Y2_PRODUCT,
    ...  The lobe integrates to pi; ``lobe @ coeffs`` is the irradiance about ``direction``."""
    return sh9_basis(direction) * per_coefficient(LAMBERT_ZONAL)


def zonal_coefficients_to_factors(z):
    """Funk-Hecke factors Lambda_l = sqrt(4 pi / (2l + 1)) z_l from zonal coefficients z_l (the
    coefficients of Y_l0 of a lobe about +Z) (Sloan 2008, eq. 26)."""
    z = np.asarray(z, dtype=np.float64)
    return z * np.sqrt(4.0 * PI / (2.0 * np.arange(3) + 1.0))


def sh_rotate_zonal(z, direction):
    """(..., 9) coefficients of the zonal lobe with coefficients z_l about +Z, rotated to ``direction``:
    f_lm = sqrt(4 pi / (2l + 1)) z_l Y_lm(direction) (Sloan 2008, eq. 26)."""
    return sh9_basis(direction) * per_coefficient(zonal_coefficients_to_factors(z))


# --- wrapped diffuse ----------------------------------------------------------------------------

def wrapped_lobe_zonal(wrap):
    """Funk-Hecke factors (..., 3) of the normalised wrapped-diffuse kernel
    k(t) = max(t + w, 0) / (pi (1 + w)^2)  (core/diffuse.py ``wrapped_diffuse_cosine``; the talk,
    section "How to combine LTCs with wrapped diffuse"), w = clip(wrap, 0, 1):

        Lambda_l = 2 pi int_{-w}^{1} k(t) P_l(t) dt   (Funk-Hecke)
        Lambda_0 = 1,  Lambda_1 = (2 - w) / 3,  Lambda_2 = (1 - w)^2 / 4

    (l = 1: int_{-w}^{1} (t + w) t dt = (2 + 3w - w^3)/6 = (1 + w)^2 (2 - w)/6;
    l = 2: int_{-w}^{1} (t + w)(3 t^2 - 1)/2 dt = (1 - w^2)^2 / 8.)  Lambda_0 = 1 for every w is the
    normalisation's energy conservation: a uniform white world gives 1, as Lambert's A_0 / pi.
    w = 0 gives A_l / pi = (1, 2/3, 1/4).  Checked against ``zonal_factors_quadrature``."""
    w = np.asarray(wrap, dtype=np.float64)
    return np.stack(np.broadcast_arrays(*indirect.wrapped_lobe_zonal(w)), axis=-1)   # one source


def zonal_factors_quadrature(kernel, breakpoints=(), n=32):
    """Lambda_l = 2 pi int_{-1}^{1} k(t) P_l(t) dt, l = 0, 1, 2, by Gauss-Legendre on each piece
    between ``breakpoints`` (exact for kernels that are polynomials of degree < 2n - 2 on each piece,
    such as the clamped and the wrapped cosine split at their kink)."""
    edges = [-1.0] + sorted(b for b in breakpoints if -1.0 < b < 1.0) + [1.0]
    x, wx = np.polynomial.legendre.leggauss(n)
    total = np.zeros(3)
    for a, b in zip(edges[:-1], edges[1:]):
        t = 0.5 * (b - a) * (x + 1.0) + a
        wt = 0.5 * (b - a) * wx
        legendre = np.stack([np.ones_like(t), t, 0.5 * (3.0 * t * t - 1.0)])
        total += legendre @ (wt * kernel(t))
    return 2.0 * PI * total


def sh_eval_wrapped_lobe(direction, wrap):
    """SH coefficients (..., 9) of the normalised wrapped-diffuse kernel max(direction . w + wrap, 0)
    / (pi (1 + wrap)^2) about ``direction``: Lambda_l(wrap) Y_lm(direction).  ``lobe @ coeffs`` is
    the outgoing radiance of the wrapped diffuse per unit albedo; wrap = 0 gives
    ``sh_eval_cosine_lobe / pi``."""
    return sh9_basis(direction) * per_coefficient(wrapped_lobe_zonal(wrap))


def sh_wrapped_diffuse(coeffs, n, wrap):
    """Outgoing radiance of the normalised wrapped diffuse (albedo 1) under the SH environment:
    sum_l Lambda_l(wrap) sum_m L_lm Y_lm(n)."""
    return sh_zonal_convolve(coeffs, n, wrapped_lobe_zonal(wrap))


# --- references ---------------------------------------------------------------------------------

def irradiance_brute_force(env, normals, rule="fejer", chunk=256):
    """E(n) = int L(w) max(n.w, 0) dw by summing every texel of the environment (quadrature weights
    ``rule``), for normals (K, 3) -> (K, 3).  The reference for the L2 truncation error."""
    if not isinstance(env, equirect.Environment):
        env = equirect.Environment(np.asarray(env))
    h, w = env.shape
    dirs = env.world_texel_directions().reshape(-1, 3)
    weighted = (np.asarray(env.image, dtype=np.float64).reshape(-1, 3)
                * equirect.quadrature_weights(h, w, rule).reshape(-1, 1)) * env.strength
    normals = np.asarray(normals, dtype=np.float64).reshape(-1, 3)
    out = np.empty((len(normals), 3))
    for s in range(0, len(normals), chunk):
        cos = np.maximum(normals[s:s + chunk] @ dirs.T, 0.0)
        out[s:s + chunk] = cos @ weighted
    return out
