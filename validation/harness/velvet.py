"""Cycles' Sheen BSDF "Ashikhmin" (velvet) beside RT Lit's cloth lobe (issue 17, item 1c).

Cycles' velvet closure (src/kernel/closure/bsdf_ashikhmin_velvet.h, from OSL) is Ashikhmin, Premoze & Shirley
2000's velvet: an inverted-Gaussian distribution without offset, with sigma = the node's Roughness (floored at
0.01), the V-cavity masking of Cook & Torrance, and no Fresnel:

    D = exp(-cot^2(theta_h) / sigma^2) / (pi sigma^2 sin^4(theta_h)),
    G = min(1, 2 (n.h)(n.v)/(v.h), 2 (n.h)(n.l)/(v.h)),      f cos = D G / (4 n.v)

(zero unless n.v > 0, n.l > 0, |n.h| < 1 - 1e-5 and v.h > 1e-5; (n.h)/(v.h) floored at 1e-5).  RT Lit's cloth
(core/cloth.py) is Neubelt & Pettineo 2013's: the same inverted Gaussian plus a constant offset, normalised,
D = (1 + 4 exp(-cot^2/alpha^2)/sin^4) / (pi (1 + 4 alpha^2)) with alpha = r^2, and the visibility
1 / (4 (n.l + n.v - n.l n.v)).  So they are not the same lobe: this module measures how far apart they are
(``compare``, docs/sheen.md) and checks the formula above against Cycles renders (tests/blender/test_sheen_table.py).
"""
from __future__ import annotations

import numpy as np

from ...core import cloth
from ...core.conventions import alpha_from_roughness

#: Cycles' floor on sigma (bsdf_ashikhmin_velvet_setup).
SIGMA_MIN = 0.01


def cycles_velvet_f_cos(l, v, sigma):
    """Cycles' velvet BRDF times n.l for local directions l, v (..., 3) (N = +Z) and the node's Roughness sigma."""
    l, v = np.asarray(l, np.float64), np.asarray(v, np.float64)
    inv_s2 = 1.0 / np.maximum(sigma, SIGMA_MIN) ** 2
    h = l + v
    h = h / np.maximum(np.linalg.norm(h, axis=-1, keepdims=True), 1e-300)
    n_l, n_v, n_h = l[..., 2], v[..., 2], h[..., 2]
    v_h = np.abs(np.sum(v * h, axis=-1))
    valid = (n_l > 0) & (n_v > 0) & (np.abs(n_h) < 1.0 - 1e-5) & (v_h > 1e-5)
    ratio = np.maximum(n_h / np.maximum(v_h, 1e-30), 1e-5)
    g = np.minimum(1.0, np.minimum(2.0 * np.abs(ratio * n_v), 2.0 * np.abs(ratio * n_l)))
    sin2 = np.maximum(1.0 - n_h * n_h, 1e-30)
    d = np.exp(-(n_h * n_h / sin2) * inv_s2) * inv_s2 / np.pi / (sin2 * sin2)
    return np.where(valid, 0.25 * d * g / np.maximum(n_v, 1e-30), 0.0)


def rt_lit_cloth_f_cos(l, v, r):
    """RT Lit's cloth lobe (core/cloth.py, alpha = r^2) times n.l."""
    h = l + v
    h = h / np.maximum(np.linalg.norm(h, axis=-1, keepdims=True), 1e-300)
    f = cloth.ashikhmin_cloth_brdf(l[..., 2], v[..., 2], h[..., 2], alpha_from_roughness(np.float64(r)))
    return f * np.maximum(l[..., 2], 0.0)


def _hemisphere(n_theta=96, n_phi=192):
    """Local directions and solid-angle weights over the upper hemisphere (midpoint rule in cos theta, phi)."""
    z = (np.arange(n_theta) + 0.5) / n_theta
    phi = (np.arange(n_phi) + 0.5) * 2.0 * np.pi / n_phi
    s = np.sqrt(1.0 - z * z)
    d = np.stack([s[:, None] * np.cos(phi), s[:, None] * np.sin(phi), np.broadcast_to(z[:, None], (n_theta, n_phi))],
                 axis=-1).reshape(-1, 3)
    return d, np.full(len(d), 2.0 * np.pi / (n_theta * n_phi))


def compare(roughness=(0.3, 0.5, 0.8), mus=(0.2, 0.5, 0.9)):
    """Per (r, mu_v): directional albedo of Cycles' velvet (sigma = r) and of RT Lit's cloth (alpha = r^2), and
    the relative L1 distance of the two f cos over the hemisphere (int |a - b| / int b, 0 = the same lobe)."""
    l, w = _hemisphere()
    rows = []
    for r in roughness:
        for mu in mus:
            v = np.array([np.sqrt(1.0 - mu * mu), 0.0, mu])
            a = cycles_velvet_f_cos(l, v, r)
            b = rt_lit_cloth_f_cos(l, v, r)
            rows.append({"roughness": r, "mu_v": mu, "albedo_cycles_velvet": float(np.sum(a * w)),
                         "albedo_rt_lit_cloth": float(np.sum(b * w)),
                         "l1_distance": float(np.sum(np.abs(a - b) * w) / max(np.sum(b * w), 1e-30))})
    return rows


def markdown(rows):
    lines = ["| r | mu_v | albedo, Cycles velvet (sigma = r) | albedo, RT Lit cloth (alpha = r^2) | "
             "int abs(velvet - cloth) / int cloth |", "|---|---|---|---|---|"]
    for e in rows:
        lines.append(f"| {e['roughness']:g} | {e['mu_v']:g} | {e['albedo_cycles_velvet']:.4f} | "
                     f"{e['albedo_rt_lit_cloth']:.4f} | {100 * e['l1_distance']:.0f}% |")
    return "\n".join(lines)
