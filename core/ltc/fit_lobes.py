"""The BRDF x cos lobes that get LTC tables, each with its importance sampling.

A lobe is evaluated with F = 1 (GGX), albedo 1 (CoD WWII diffuse) or sheen colour 1 (cloth):
the table's magnitude and Fresnel channels carry the scale (Hill 2016, "LTC Fresnel
Approximation").  ``eval_cos(l, v, r)`` returns f(l, v) * max(l.z, 0); ``sample(v, r, u1, u2)``
returns directions and their pdf (solid angle).  Directions are local (N = +Z).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import cloth, diffuse, microfacet, rough_diffuse
from ..conventions import alpha_from_roughness


def _half_vector_terms(l, v):
    h = l + v
    h = h / np.maximum(np.linalg.norm(h, axis=-1, keepdims=True), 1e-300)
    return h[..., 2], np.clip(np.sum(l * h, axis=-1), 0.0, 1.0)


def _cosine_sample(u1, u2):
    """Cosine-weighted hemisphere (Malley's method): pdf = z / pi."""
    r = np.sqrt(u1)
    phi = 2.0 * np.pi * u2
    z = np.sqrt(np.maximum(1.0 - u1, 0.0))
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=-1), z / np.pi


def _uniform_hemisphere_sample(u1, u2):
    z = u1
    r = np.sqrt(np.maximum(1.0 - z * z, 0.0))
    phi = 2.0 * np.pi * u2
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=-1), np.full(np.shape(z), 0.5 / np.pi)


@dataclass(frozen=True)
class Lobe:
    name: str
    description: str

    def eval_cos(self, l, v, r):
        raise NotImplementedError

    def sample(self, v, r, u1, u2):
        raise NotImplementedError

    def pdf(self, l, v, r):
        """Density (solid angle) with which ``sample`` produces direction l."""
        raise NotImplementedError


class GGXLobe(Lobe):
    """Single-scattering GGX, F = 1 (core.microfacet); sampled with visible normals (Heitz 2018)."""

    def eval_cos(self, l, v, r):
        alpha = alpha_from_roughness(r)
        n_dot_h, _ = _half_vector_terms(l, v)
        f = microfacet.ggx_distribution(n_dot_h, alpha) * microfacet.smith_visibility_height_correlated(
            l[..., 2], v[..., 2], alpha)
        return np.where((l[..., 2] > 0) & (v[..., 2] > 0), f * l[..., 2], 0.0)

    def sample(self, v, r, u1, u2):
        alpha = alpha_from_roughness(r)
        m = microfacet.sample_ggx_vndf(np.broadcast_to(v, np.broadcast_shapes(np.shape(u1) + (3,), v.shape)),
                                       alpha, u1, u2)
        l = microfacet.reflect(v, m)
        # pdf(l) = G1(v) D(m) / (4 v.z)  (Heitz 2018, eq. 17 and the reflection Jacobian)
        pdf = (microfacet.smith_g1(v[..., 2], alpha) * microfacet.ggx_distribution(m[..., 2], alpha)
               / (4.0 * np.maximum(v[..., 2], 1e-12)))
        return l, pdf

    def pdf(self, l, v, r):
        alpha = alpha_from_roughness(r)
        h = l + v
        h = h / np.maximum(np.linalg.norm(h, axis=-1, keepdims=True), 1e-300)
        pdf = (microfacet.smith_g1(v[..., 2], alpha) * microfacet.ggx_distribution(h[..., 2], alpha)
               / (4.0 * np.maximum(v[..., 2], 1e-12)))
        return np.where(np.sum(v * h, axis=-1) > 0, pdf, 0.0)


class CodDiffuseLobe(Lobe):
    """Call of Duty WWII multiscattering diffuse, albedo 1 (core.diffuse); cosine sampling."""

    def eval_cos(self, l, v, r):
        n_dot_h, l_dot_h = _half_vector_terms(l, v)
        f = diffuse.cod_multiscatter_diffuse(1.0, l[..., 2], v[..., 2], n_dot_h, l_dot_h, alpha_from_roughness(r))
        return f * np.maximum(l[..., 2], 0.0)

    def sample(self, v, r, u1, u2):
        return _cosine_sample(u1, u2)

    def pdf(self, l, v, r):
        return np.maximum(l[..., 2], 0.0) / np.pi


class ClothLobe(Lobe):
    """Ashikhmin velvet with Neubelt-Pettineo visibility, sheen colour 1 (core.cloth); uniform sampling
    (the lobe peaks towards grazing directions, where cosine sampling starves)."""

    def eval_cos(self, l, v, r):
        n_dot_h, _ = _half_vector_terms(l, v)
        f = cloth.ashikhmin_cloth_brdf(l[..., 2], v[..., 2], n_dot_h, alpha_from_roughness(r))
        return f * np.maximum(l[..., 2], 0.0)

    def sample(self, v, r, u1, u2):
        return _uniform_hemisphere_sample(u1, u2)

    def pdf(self, l, v, r):
        return np.where(l[..., 2] > 0, 0.5 / np.pi, 0.0)


class OrenNayarLobe(CodDiffuseLobe):
    """Fujii's improved Oren-Nayar single scattering, albedo 1 (core.rough_diffuse); r is the diffuse roughness
    sigma.  Cosine sampling, as the CoD lobe (both are close to a cosine)."""

    def eval_cos(self, l, v, r):
        return rough_diffuse.fon_single_scatter_cos(l[..., 2], v[..., 2], np.sum(l * v, axis=-1), r)


class DisneySheenLobe(Lobe):
    """Disney sheen (1 - l.h)^5 (Burley 2012, sec. 5.3; core.cloth.disney_sheen), colour 1, no 1/pi and no
    roughness; cosine sampling (the lobe is broad, brightest towards grazing light)."""

    def eval_cos(self, l, v, r):
        _, l_dot_h = _half_vector_terms(l, v)
        f = cloth.disney_sheen(l_dot_h)
        return np.where((l[..., 2] > 0) & (v[..., 2] > 0), f * l[..., 2], 0.0)

    def sample(self, v, r, u1, u2):
        return _cosine_sample(u1, u2)

    def pdf(self, l, v, r):
        return np.maximum(l[..., 2], 0.0) / np.pi


LOBES = {
    "ggx": GGXLobe("ggx", "single-scattering GGX, height-correlated Smith G2, F = 1"),
    "cod_diffuse": CodDiffuseLobe("cod_diffuse", "Call of Duty WWII multiscattering diffuse (Chan 2018), albedo 1"),
    "cloth": ClothLobe("cloth", "Ashikhmin velvet + Neubelt-Pettineo visibility (cloth), colour 1"),
    "oren_nayar": OrenNayarLobe("oren_nayar", "Fujii's improved Oren-Nayar single scattering, albedo 1"),
    "disney_sheen": DisneySheenLobe("disney_sheen", "Disney sheen (1 - l.h)^5, colour 1, no roughness"),
}
