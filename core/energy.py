"""Hemispherical integrals of the single-scattering GGX BRDF used to bake the energy LUTs.

E(mu, r) = int f_ss(l, v) mu_l dl with F = 1 (Kulla & Conty 2017, slide "energy"; the talk's
first equation).  Split-sum environment BRDF (Karis 2013, "Real Shading in Unreal Engine 4",
eq. 4 and its listing): with Schlick F = F0 + (1 - F0) Fc, Fc = (1 - v.h)^5,
    int f_ss mu_l dl = F0 * scale + F90 * bias,  scale = int (1 - Fc) f mu_l,  bias = int Fc f mu_l,
so E = scale + bias exactly, from the same samples.

Estimator: visible-normal importance sampling (Heitz 2018) over a 2D Hammersley set, for
which f mu_l / pdf = G2(l, v) / G1(v) (Heitz 2018, eq. 19 with F = 1).  Deterministic.
The view cosine is floored at MU_MIN = 1e-4, as in Cycles' table generator, because the
estimator is 0/0 at mu = 0 exactly (its limit is E -> 1: every reflected ray clears the
horizon when the view is grazing).
"""
from __future__ import annotations

import numpy as np

from . import microfacet, sampling
from .conventions import alpha_from_roughness

MU_MIN = 1e-4


def view_vector(mu):
    """Local-frame view vector (sin theta, 0, cos theta) for cos theta = mu."""
    mu = np.clip(np.asarray(mu, dtype=np.float64), MU_MIN, 1.0)
    return np.stack([np.sqrt(1.0 - mu * mu), np.zeros_like(mu), mu], axis=-1)


def split_sum_terms(mu, roughness, n_samples, progress=None):
    """Split-sum (scale, bias) of GGX for every pair (roughness[i], mu[j]).

    Returns two float64 arrays of shape (len(roughness), len(mu)).  Their sum is E(mu, r).
    ``progress(done, total)`` is called after each mu.
    """
    mu = np.atleast_1d(np.asarray(mu, dtype=np.float64))
    alpha = alpha_from_roughness(np.atleast_1d(np.asarray(roughness, dtype=np.float64)))
    u1, u2 = sampling.hammersley_2d(n_samples)
    scale = np.empty((alpha.size, mu.size))
    bias = np.empty_like(scale)
    a = alpha[:, None]
    for j, v in enumerate(view_vector(mu)):
        m = microfacet.sample_ggx_vndf(np.broadcast_to(v, (alpha.size, n_samples, 3)), a, u1, u2)
        v_dot_m = np.clip(m @ v, 0.0, 1.0)
        mu_l = 2.0 * v_dot_m * m[..., 2] - v[2]          # z of reflect(v, m)
        weight = np.where(
            mu_l > 0.0,
            microfacet.smith_g2_height_correlated(mu_l, v[2], a)
            / microfacet.smith_g1(v[2], a),
            0.0,
        )
        fc = (1.0 - v_dot_m) ** 5
        bias[:, j] = np.mean(weight * fc, axis=1)
        scale[:, j] = np.mean(weight, axis=1) - bias[:, j]
        if progress is not None:
            progress(j + 1, mu.size)
    return scale, bias


def directional_albedo(mu, roughness, n_samples=1 << 16):
    """E(mu, r): directional albedo of single-scattering GGX with F = 1, shape (len(r), len(mu))."""
    scale, bias = split_sum_terms(mu, roughness, n_samples)
    return scale + bias


def average_albedo(roughness, n_mu=64, n_samples=1 << 16):
    """E_avg(r) = 2 int_0^1 E(mu) mu dmu by Gauss-Legendre quadrature in mu (reference values).

    E(mu) is smooth on (0, 1] but has a boundary layer near mu = 0 (the dip and rise
    described in the module docstring); n_mu Gauss nodes clustered near both ends handle it.
    """
    mu, w = sampling.gauss_legendre(n_mu)
    e = directional_albedo(mu, roughness, n_samples)
    return 2.0 * e @ (w * mu)


def average_of_piecewise_linear(e_nodes, mu_nodes):
    """E_avg of the function a LUT reconstructs: E piecewise linear in mu between table nodes.

    E_avg = 2 int_0^1 E(mu) mu dmu.  E is linear on each [mu_k, mu_k+1], so the integrand is
    quadratic there and 2-point Gauss-Legendre is exact.  ``e_nodes`` (..., n) at ``mu_nodes``
    (n,) increasing from 0 to 1.  Using this E_avg with the same table makes the Kulla-Conty
    furnace identity exact.
    """
    e_nodes = np.asarray(e_nodes, dtype=np.float64)
    mu_nodes = np.asarray(mu_nodes, dtype=np.float64)
    if mu_nodes[0] != 0.0 or mu_nodes[-1] != 1.0:
        raise ValueError("mu_nodes must span [0, 1]")
    x, w = np.polynomial.legendre.leggauss(2)
    t = 0.5 * (x + 1.0)                                    # nodes on [0, 1]
    m0, m1 = mu_nodes[:-1], mu_nodes[1:]
    h = m1 - m0
    m = m0[:, None] + h[:, None] * t[None, :]              # (n-1, 2)
    e0, e1 = e_nodes[..., :-1, None], e_nodes[..., 1:, None]
    e = e0 + (e1 - e0) * t                                 # (..., n-1, 2)
    return 2.0 * np.sum(e * m * (0.5 * w) * h[:, None], axis=(-2, -1))
