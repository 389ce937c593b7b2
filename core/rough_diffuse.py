"""Rough diffuse as Cycles shades it: Fujii's improved Oren-Nayar plus an energy-preserving multiple-scattering
lobe after EON / OpenPBR (Principled BSDF "Diffuse Roughness" and the Diffuse BSDF's Roughness, Blender 4.3+).

Sources
-------
* Fujii, "A tiny improvement of Oren-Nayar reflectance model" (https://mimosa-pudica.net/improved-oren-nayar.html):
  the "improved" (FON) single-scattering lobe f = rho (A + B s/t), A = 1/(pi + (pi/2 - 2/3) sigma),
  B = sigma A, s = l.v - (n.l)(n.v), t = max(n.l, n.v) where s > 0 and 1 otherwise.
* Portsmouth, Kutz & Hill 2025, "EON: A Practical Energy-Preserving Rough Diffuse BRDF", JCGT 14(1)
  (arXiv 2410.18026; the OpenPBR Surface specification's diffuse): FON's directional albedo in closed form,
  E_F(mu) = A_F (1 + r G(mu)/pi) with A_F = 1/(1 + c1 r), its hemispherical average
  E_avg = A_F (1 + c2 r), and the compensating lobe f_ms = rho_ms/pi (1 - E_F(mu_i))(1 - E_F(mu_o))/(1 - E_avg),
  rho_ms = rho^2 E_avg / (1 - rho (1 - E_avg)).
* Cycles, src/kernel/closure/bsdf_oren_nayar.h (the same code in 4.5 LTS and 5.2; read from the Cycles
  sources, not copied): sigma = saturate(roughness), Lambert below roughness 1e-5, and the multiple-scattering
  term scaled by the closure weight, which is the base colour: Cycles renders rho x rho_ms, not EON's rho_ms
  (measured: docs/rough_diffuse.md, scripts/validate_rough_diffuse.py).

Everything here is per unit colour, cosine included where a name says ``_cos``, written with
``core.shading_ops`` (numpy arrays or traced Exprs).  The colour factors are applied once by the caller:
rho x the single-scattering part, ``multiscatter_color`` x the multiple-scattering part.

The multiple-scattering lobe is zonal and independent of roughness in shape:
1 - E_F(mu) = A_F r (G(0) - G(mu)) / pi and 1 - E_avg = A_F r (c1 - c2), so
(1 - E_F(mu_l)) mu_l / (pi (1 - E_avg)) = (G(0) - G(mu_l)) mu_l / (pi^2 (c1 - c2)) = ``ms_kernel(mu_l)``, a fixed
lobe about N that integrates to 1 over the hemisphere.  The lobe is then (1 - E_F(mu_v)) ms_kernel(mu_l): no
division by 1 - E_avg (0 at r = 0) is ever formed.
"""
from __future__ import annotations

import math

import numpy as np

from . import shading_ops as op

PI = math.pi

# EON, section "FON directional albedo": A_F = 1/(1 + c1 r) (Fujii's A times pi) and the average albedo
# E_avg = A_F (1 + c2 r).  c1 = G(0)/pi.
C1 = 0.5 - 2.0 / (3.0 * PI)
C2 = 2.0 / 3.0 - 28.0 / (15.0 * PI)
#: G(0) = pi/2 - 2/3: the grazing limit of G (Cycles' Taylor expansion at cos = 0 starts there).
G_GRAZING = 0.5 * PI - 2.0 / 3.0


def fon_a(r):
    """A_F = 1 / (1 + c1 r): Fujii's A = A_F / pi (EON; Cycles' ``a`` is A_F / pi)."""
    return 1.0 / (1.0 + C1 * op.saturate(r))


def fon_g_deficit(mu):
    """G(0) - G(mu), where G is the function of FON's directional albedo (EON, "FON directional albedo"; Cycles
    ``bsdf_oren_nayar_G``):

        G = sin(theta) (theta - 2/3 - sin(theta) cos(theta)) + 2/3 tan(theta) (1 - sin^3(theta)),  G(0) = pi/2 - 2/3.

    In that form tan(theta)(1 - sin^3) is 0 x inf at mu = 0 (Cycles switches to a Taylor expansion below
    mu = 1e-6), and G(0) - G(mu), which the multiple scattering needs (``fon_one_minus_albedo``), cancels to
    ~mu near grazing.  Rewritten (our algebra, same function) with s = sin(theta), c = mu, 1 - s = c^2/(1 + s),
    theta = pi/2 - asin(c) and tan(theta)(1 - s^3) = s c (1 + s + s^2)/(1 + s):

        G(0) - G = (pi/2 - 2/3) c^2/(1 + s) + s asin(c) + s^2 c - 2/3 s c (1 + s + s^2)/(1 + s),

    no division by c, and near c = 0 the terms are c + c - c (no catastrophic cancellation).  asin(c) is
    atan2(c, s) (exact for c in [0, 1]; Mesa's arcsine is the least accurate of its inverse trigonometric
    functions, docs/conventions.md).  s from (1 - c)(1 + c)."""
    c = op.saturate(mu)
    s = op.sqrt((1.0 - c) * (1.0 + c))
    inv = 1.0 / (1.0 + s)
    return (G_GRAZING * c * c * inv + s * op.atan2(c, s) + s * s * c
            - (2.0 / 3.0) * s * c * (1.0 + s + s * s) * inv)


def fon_g(mu):
    """G(mu) = G(0) - (G(0) - G(mu)) (``fon_g_deficit``): G(0) = pi/2 - 2/3, G(1) = 0."""
    return G_GRAZING - fon_g_deficit(mu)


def fon_albedo(mu, r):
    """E_F(mu, r) = A_F (1 + r G(mu)/pi): the directional albedo of FON's single scattering, albedo 1 (EON)."""
    r = op.saturate(r)
    return fon_a(r) * (1.0 + r * fon_g(mu) * (1.0 / PI))


def fon_one_minus_albedo(mu, r):
    """1 - E_F(mu, r) = A_F r (G(0) - G(mu)) / pi (from A_F (1 + c1 r) = 1 and c1 = G(0)/pi): no cancellation
    against 1, so it stays >= 0 and exact near r = 0."""
    r = op.saturate(r)
    return fon_a(r) * r * fon_g_deficit(mu) * (1.0 / PI)


def fon_average_albedo(r):
    """E_avg(r) = A_F (1 + c2 r) = 2 int E_F(mu) mu dmu (EON; Cycles ``Eavg``, whose (2 pi - 5.6)/3 B is the same
    c2 = 2/3 - 28/(15 pi) = 0.0725)."""
    r = op.saturate(r)
    return fon_a(r) * (1.0 + C2 * r)


def fon_single_scatter_cos(mu_l, mu_v, l_dot_v, r):
    """Fujii's improved Oren-Nayar times the cosine, albedo 1: A_F/pi (mu_l + r s mu_l / t).

    s = l.v - mu_l mu_v; s/t = s / max(mu_l, mu_v) where s > 0, s elsewhere (Fujii; EON's "FON s/t").
    The BRDF itself is unbounded when both directions graze (s -> 1, t -> 0), the product with the cosine
    is not: mu_l / max(mu_l, mu_v) is in [0, 1], formed as a guarded division (0 where both are 0).
    0 below either horizon (as Cycles: the closure is evaluated for mu_l > 0 and mu_v clamped at 0)."""
    r = op.saturate(r)
    ml = op.maximum(mu_l, 0.0)
    mv = op.maximum(mu_v, 0.0)
    s = l_dot_v - ml * mv
    over_t = op.select(op.greater(s, 0.0), op.safe_div(ml, op.maximum(ml, mv)), ml)
    value = fon_a(r) * (1.0 / PI) * (ml + r * s * over_t)
    above = op.logical_and(op.greater(mu_l, 0.0), op.greater(mu_v, 0.0))
    return op.select(above, op.maximum(value, 0.0), 0.0)


#: (c1 - c2) pi^2: the normalisation of ``ms_kernel``.
_MS_NORM = (C1 - C2) * PI * PI


def ms_kernel(mu):
    """The multiple-scattering lobe's shape about N, cosine included, normalised to 1 over the hemisphere:
    (1 - E_F(mu)) mu / (pi (1 - E_avg)) = (G(0) - G(mu)) mu / (pi^2 (c1 - c2)), the same for every roughness
    (module docstring).  0 below the horizon."""
    c = op.maximum(mu, 0.0)
    return op.select(op.greater(mu, 0.0), fon_g_deficit(c) * c * (1.0 / _MS_NORM), 0.0)


def ms_kernel_over_cosine(mu):
    """pi ms_kernel(mu) / mu = (G(0) - G(mu)) / (pi (c1 - c2)): the kernel relative to the clamped cosine / pi
    (0 at grazing, 1.34 at the normal), without the division by mu."""
    return fon_g_deficit(op.maximum(mu, 0.0)) * (1.0 / (PI * (C1 - C2)))


def multiscatter_cos(mu_l, mu_v, r):
    """EON's f_ms times the cosine with rho_ms = 1: (1 - E_F(mu_v)) (1 - E_F(mu_l)) mu_l / (pi (1 - E_avg))
    = (1 - E_F(mu_v)) ms_kernel(mu_l); 0 below either horizon."""
    above = op.greater(mu_v, 0.0)
    return op.select(above, fon_one_minus_albedo(mu_v, r) * ms_kernel(mu_l), 0.0)


# EON's rho_ms = rho^2 E_avg / (1 - rho (1 - E_avg)); Cycles multiplies its multiple-scattering term by the
# closure weight as well, which is rho (measured in a white-furnace render: docs/rough_diffuse.md).
def multiscatter_albedo(rho, r):
    """EON's rho_ms(rho, r) for one channel (rho in [0, 1]); the denominator is >= E_avg >= 0.78."""
    e_avg = fon_average_albedo(r)
    return rho * rho * e_avg / (1.0 - rho * (1.0 - e_avg))


def multiscatter_color(albedo, base, r):
    """The colour of the multiple-scattering lobe as Cycles renders it: albedo x rho_ms(base) per channel, with
    ``albedo`` the diffuse closure's weight (base colour x (1 - metallic) in Principled) and ``base`` the base
    colour Cycles passes as the lobe's colour (RGB vectors)."""
    return op.vmul(albedo, op.per_channel(lambda c: multiscatter_albedo(c, r), base))


def directional_albedo(rho, mu_v, r):
    """The whole lobe's albedo as Cycles renders it, for one channel: rho E_F + rho rho_ms (1 - E_F)
    (1 for rho = 1: the white furnace)."""
    return rho * fon_albedo(mu_v, r) + rho * multiscatter_albedo(rho, r) * fon_one_minus_albedo(mu_v, r)


def eon_directional_albedo(rho, mu_v, r):
    """EON's albedo (the paper's and OpenPBR's colour): rho E_F + rho_ms (1 - E_F); for tests and the furnace
    measurement that tells it from Cycles'."""
    return rho * fon_albedo(mu_v, r) + multiscatter_albedo(rho, r) * fon_one_minus_albedo(mu_v, r)


# --- the multiple-scattering kernel's Funk-Hecke factors ----------------------------------------------------
# ms_kernel is zonal about N, so under an SH environment it is exact: Lambda_l = 2 pi int_0^1 k(t) P_l(t) dt
# (Funk-Hecke; core/indirect.py).  Lambda_0 = 1 (normalised); the constants are computed once by Gauss-Legendre
# quadrature of the closed form (tests/core/test_rough_diffuse.py checks them against an independent one).

def ms_kernel_zonal(n=256):
    """(Lambda_0, Lambda_1, Lambda_2) of ``ms_kernel`` (numpy, float64)."""
    x, w = np.polynomial.legendre.leggauss(n)
    t = 0.5 * (x + 1.0)
    k = np.asarray(ms_kernel(t), np.float64)
    legendre = (np.ones_like(t), t, 0.5 * (3.0 * t * t - 1.0))
    return tuple(float(2.0 * PI * 0.5 * np.sum(w * k * p)) for p in legendre)


#: Funk-Hecke factors of ``ms_kernel`` (``ms_kernel_zonal()`` rounded to 1e-9; Lambda_0 = 1).
MS_KERNEL_ZONAL = (1.0, 0.740051590, 0.378505935)


# --- the multiple-scattering kernel over an area light: an alternative, measured ------------------------------
# Shading integrates the kernel over a light as the Lambert form factor x ``ms_kernel_over_cosine`` towards the
# light's centre (core/materials/lobes.py).  The kernel being one fixed lobe about N, one fixed LTC also
# approximates it for every roughness (Heitz et al. 2016: an LTC with Minv = diag(1, 1, c3) is isotropic about N);
# c3 minimises the total-variation distance to the kernel (``ms_kernel_ltc_tv``): 0.0585, against 0.130 for the
# plain cosine (c3 = 1).  Against Cycles the centre form measured better (docs/rough_diffuse.md), so this LTC is
# kept for that comparison (validation/benchmarks/ltc_benchmark.py).

def ms_kernel_ltc_tv(c3, n=20000):
    """Total-variation distance 1/2 int |ms_kernel - D_ltc| dw between the kernel and the isotropic LTC
    Minv = diag(1, 1, c3) (numpy; midpoint rule in mu, exact in azimuth: both are zonal)."""
    mu = (np.arange(n) + 0.5) / n
    length2 = (1.0 - mu * mu) + (c3 * mu) ** 2
    ltc = c3 * mu / (PI * length2 * length2) * c3       # D_o(Minv l / |Minv l|) |det Minv| / |Minv l|^3
    k = np.asarray(ms_kernel(mu), np.float64)
    return float(0.5 * 2.0 * PI * np.sum(np.abs(k - ltc)) / n)


#: Packed Minv (c0, c1, c2, c3) of the LTC fitted to ``ms_kernel`` (golden-section search of ``ms_kernel_ltc_tv``).
MS_KERNEL_LTC = (1.0, 0.0, 0.0, 0.82223)
