"""GGX (Trowbridge-Reitz) microfacet model: distribution, masking-shadowing, BRDF, sampling.

Conventions (core/conventions.py): alpha = r^2 floored at ALPHA_MIN, cosines measured from
the shading normal, height-correlated Smith G2.  Every function takes cosines (not vectors)
so that reciprocity is visible in the signature: swapping (mu_l, mu_v) leaves f unchanged.
"""
from __future__ import annotations

import numpy as np

from . import shading_ops as op
from .conventions import ALPHA_MIN, COS_EPS


def _alpha(alpha):
    return op.maximum(alpha, ALPHA_MIN)


def ggx_distribution(n_dot_h, alpha):
    """GGX normal distribution D(h) (Walter et al. 2007, eq. 33; Trowbridge & Reitz 1975).

    D = alpha^2 / (pi ((1 - c^2) + alpha^2 c^2)^2), c = n.h.  (1 - c^2) is formed as
    (1 - c)(1 + c) so that the peak stays accurate in float32; with alpha >= ALPHA_MIN the
    denominator is >= pi alpha^4 > 0.  Zero for c <= 0.
    """
    a2 = _alpha(alpha) ** 2
    c = op.saturate(n_dot_h)
    d = (1.0 - c) * (1.0 + c) + a2 * c * c
    D = a2 / (np.pi * d * d)
    return op.select(op.greater(n_dot_h, 0.0), D, 0.0)


def _smith_root(mu, a2):
    """sqrt(alpha^2 + (1 - alpha^2) mu^2) = mu sqrt(1 + alpha^2 tan^2 theta)."""
    return op.sqrt(a2 + (1.0 - a2) * mu * mu)


def smith_g1(mu, alpha):
    """Smith masking G1 = 1/(1 + Lambda(mu)) for GGX (Heitz 2014, eq. 72 and 86).

    Written as 2 mu / (mu + sqrt(alpha^2 + (1 - alpha^2) mu^2)), finite at mu = 0.
    """
    a2 = _alpha(alpha) ** 2
    mu = op.saturate(mu)
    return 2.0 * mu / (mu + _smith_root(mu, a2))


def smith_g2_height_correlated(mu_l, mu_v, alpha):
    """Height-correlated masking-shadowing G2 = 1/(1 + Lambda(mu_l) + Lambda(mu_v)).

    Heitz 2014, "Understanding the Masking-Shadowing Function", eq. 99; the choice of
    Cycles (bsdf_microfacet.h) and selfshadow/ltc_code (brdf_ggx.h).  Multiplying through:
    G2 = 2 mu_l mu_v / (mu_v S(mu_l) + mu_l S(mu_v)), S(mu) = sqrt(alpha^2 + (1 - alpha^2) mu^2).
    """
    a2 = _alpha(alpha) ** 2
    mu_l, mu_v = op.saturate(mu_l), op.saturate(mu_v)
    den = mu_v * _smith_root(mu_l, a2) + mu_l * _smith_root(mu_v, a2)
    return 2.0 * mu_l * mu_v / op.maximum(den, COS_EPS)


def smith_visibility_height_correlated(mu_l, mu_v, alpha):
    """V = G2 / (4 mu_l mu_v) = 0.5 / (mu_v S(mu_l) + mu_l S(mu_v)) (Lagarde & de Rousiers 2014, eq. 3-4)."""
    a2 = _alpha(alpha) ** 2
    mu_l, mu_v = op.saturate(mu_l), op.saturate(mu_v)
    den = mu_v * _smith_root(mu_l, a2) + mu_l * _smith_root(mu_v, a2)
    return 0.5 / op.maximum(den, COS_EPS)


def ggx_brdf(mu_l, mu_v, n_dot_h, v_dot_h, alpha, f0=1.0, f90=1.0):
    """Single-scattering GGX BRDF f_ss = F(v.h) D(h) G2(l, v) / (4 mu_l mu_v).

    Cook & Torrance 1982 with Walter et al. 2007; Schlick Fresnel with F90.  Zero unless
    both directions are above the surface.  Multiply by mu_l for reflected radiance.
    """
    from .fresnel import fresnel_schlick

    f = (fresnel_schlick(f0, v_dot_h, f90) * ggx_distribution(n_dot_h, alpha)
         * smith_visibility_height_correlated(mu_l, mu_v, alpha))
    return op.select(op.logical_and(op.greater(mu_l, 0.0), op.greater(mu_v, 0.0)), f, 0.0)


def sample_ggx_vndf(view, alpha, u1, u2):
    """Sample a microfacet normal from the GGX distribution of visible normals.

    Heitz 2018, "Sampling the GGX Distribution of Visible Normals", JCGT 7(4), listing 1,
    isotropic case.  ``view`` (..., 3) in the local frame (normal = +Z, view.z > 0),
    ``alpha`` and ``u1``, ``u2`` broadcast against view[..., 0].  Returns unit normals (..., 3).
    The pdf of the sampled normal is G1(v) max(0, v.m) D(m) / v.z.
    """
    alpha = _alpha(alpha)
    vx, vy, vz = view[..., 0], view[..., 1], view[..., 2]
    # Stretch the view vector into the hemisphere configuration (section 3.2).
    vh = op.normalize(np.stack(np.broadcast_arrays(alpha * vx, alpha * vy, vz), axis=-1))
    hx, hy, hz = vh[..., 0], vh[..., 1], vh[..., 2]
    lensq = hx * hx + hy * hy
    inv_len = 1.0 / np.sqrt(np.maximum(lensq, 1e-300))
    has_tangent = lensq > 0.0
    t1x = np.where(has_tangent, -hy * inv_len, 1.0)
    t1y = np.where(has_tangent, hx * inv_len, 0.0)
    t1z = np.zeros_like(t1x)
    t1 = np.stack(np.broadcast_arrays(t1x, t1y, t1z), axis=-1)
    t2 = np.cross(vh, t1)
    # Uniform disk sample warped onto the projected visible hemisphere (section 4.2).
    rad = np.sqrt(u1)
    phi = 2.0 * np.pi * u2
    p1 = rad * np.cos(phi)
    p2 = rad * np.sin(phi)
    s = 0.5 * (1.0 + hz)
    p2 = (1.0 - s) * np.sqrt(np.maximum(1.0 - p1 * p1, 0.0)) + s * p2
    p3 = np.sqrt(np.maximum(1.0 - p1 * p1 - p2 * p2, 0.0))
    nh = p1[..., None] * t1 + p2[..., None] * t2 + p3[..., None] * vh
    # Unstretch (section 3.4).
    ne = np.stack(np.broadcast_arrays(alpha * nh[..., 0], alpha * nh[..., 1],
                                      np.maximum(nh[..., 2], 0.0)), axis=-1)
    return op.normalize(ne)


def reflect(view, normal):
    """Mirror direction of ``view`` about ``normal``: 2 (v.n) n - v."""
    return 2.0 * op.dot(view, normal)[..., None] * normal - view
