"""Fit LTC tables to BRDF x cos lobes (Heitz et al. 2016, section 4; docs/area_lights.md, "Fitting").

For every cell (view cosine mu, roughness r) of the table:
1. magnitude, Fresnel and average direction of the lobe by importance sampling over a 2D
   Hammersley set (Hill 2016, "LTC Fresnel Approximation": magnitude = int f cos,
   Fresnel = int f cos (1 - v.h)^5);
2. the inverse matrix Minv (four entries, Minv[1][1] = 1) minimising the distance between the
   normalised lobe p = f cos / magnitude and the LTC density q, estimated on a fixed sample
   set (so the objective is a deterministic function of Minv): directions drawn from the lobe's
   own sampling, from the starting LTC, and uniformly over the sphere, weighted by the inverse
   of the mixture density.

Differences from ltc_code (docs/area_lights.md, "Fitting"): the four entries of Minv are fitted
directly (ltc_code fits three in the frame of the average direction, then zeroes couplings),
which can only lower the error; all roughness values of a view row are solved together with a batched
Nelder-Mead; each row starts from the better of the previous row's matrix and that matrix
rotated with the average direction; the first row (normal incidence) is isotropic,
Minv = diag(1, 1, c3), found by a grid search and refined.
"""
from __future__ import annotations

import numpy as np

from .. import sampling
from . import matrix, optimize
from .fit_lobes import LOBES

#: Smallest view cosine fitted (theta <= 89.94 deg); the last table row (mu = 0) uses it.
FIT_MU_MIN = 1e-3


def view_vector(mu):
    mu = float(mu)
    return np.array([np.sqrt(max(1.0 - mu * mu, 0.0)), 0.0, mu])


def lobe_integrals(lobe, mu, roughness, n_samples):
    """Magnitude, Fresnel and unit average direction of the lobe for one mu and many r.

    Returns (magnitude (B,), fresnel (B,), average (B, 3)).
    """
    v = view_vector(mu)
    r = np.asarray(roughness, dtype=np.float64)[:, None]
    u1, u2 = sampling.hammersley_2d(n_samples)
    l, pdf = lobe.sample(v, r, u1[None, :], u2[None, :])
    f = lobe.eval_cos(l, v, r)
    w = np.where((pdf > 0) & (l[..., 2] > 0), f / np.maximum(pdf, 1e-300), 0.0)
    h = l + v
    h /= np.maximum(np.linalg.norm(h, axis=-1, keepdims=True), 1e-300)
    schlick = (1.0 - np.clip(np.sum(v * h, axis=-1), 0.0, 1.0)) ** 5
    magnitude = w.mean(axis=1)
    fresnel = (w * schlick).mean(axis=1)
    avg = (w[..., None] * l).mean(axis=1)
    avg[:, 1] = 0.0
    avg /= np.maximum(np.linalg.norm(avg, axis=-1, keepdims=True), 1e-300)
    return magnitude, fresnel, avg


class RowProblem:
    """Fixed samples and lobe values of one view row; ``objective`` compares LTCs with the lobe."""

    def __init__(self, lobe, mu, roughness, magnitude, start, n_lobe=512, n_ltc=512, n_sphere=128,
                 exponent=2.0):
        v = view_vector(mu)
        r = np.asarray(roughness, dtype=np.float64)[:, None]
        b = r.shape[0]
        u1, u2 = sampling.hammersley_2d(n_lobe)
        l_b, _ = lobe.sample(v, r, u1[None], u2[None])
        l_b = np.broadcast_to(l_b, (b, n_lobe, 3))
        u1, u2 = sampling.hammersley_2d(n_ltc)
        m = np.linalg.inv(matrix.unpack_inverse(start))
        l_q = matrix.sample(m[:, None], u1[None], u2[None])
        u1, u2 = sampling.hammersley_2d(n_sphere)
        z = 2.0 * u1 - 1.0
        s = np.sqrt(np.maximum(1.0 - z * z, 0.0))
        l_u = np.broadcast_to(np.stack([s * np.cos(2 * np.pi * u2), s * np.sin(2 * np.pi * u2), z], -1),
                              (b, n_sphere, 3))
        dirs = np.concatenate([l_b, l_q, l_u], axis=1)
        self.dirs = dirs
        n = dirs.shape[1]
        pdf_lobe = lobe.pdf(dirs, v, r)
        pdf_start = matrix.density_packed(start, dirs)
        mixture = (n_lobe * pdf_lobe + n_ltc * pdf_start + n_sphere / (4 * np.pi)) / n
        self.inv_mixture = 1.0 / mixture / n
        self.p = lobe.eval_cos(dirs, v, r) / np.maximum(magnitude[:, None], 1e-300)
        self.exponent = exponent

    def objective(self, x, idx):
        q = matrix.density_packed(x, self.dirs[idx])
        diff = np.abs(self.p[idx] - q)
        if self.exponent != 1.0:
            diff = diff ** self.exponent
        return np.sum(diff * self.inv_mixture[idx], axis=1)


def tv_distance(lobe, mu, roughness, magnitude, packed, n=1 << 14):
    """Total-variation distance 1/2 int |p - q| between the normalised lobe p and the LTC q.

    Estimated with n lobe samples and n LTC samples, weighting by the mixture density (a
    bounded integrand: |p - q| / (pdf_lobe + q) <= ~1).  0 = identical, 1 = disjoint; it bounds
    the error of the LTC integral over any light, relative to the magnitude.
    """
    v = view_vector(mu)
    r = np.asarray(roughness, dtype=np.float64)[:, None]
    u1, u2 = sampling.hammersley_2d(n)
    l_b, _ = lobe.sample(v, r, u1[None], u2[None])
    m = np.linalg.inv(matrix.unpack_inverse(packed))
    l_q = matrix.sample(m[:, None], u1[None], u2[None])
    dirs = np.concatenate([np.broadcast_to(l_b, l_q.shape), l_q], axis=1)
    p = lobe.eval_cos(dirs, v, r) / np.maximum(magnitude[:, None], 1e-300)
    q = matrix.density_packed(packed, dirs)
    mixture = 0.5 * (lobe.pdf(dirs, v, r) + q)
    return 0.5 * np.mean(np.abs(p - q) / np.maximum(mixture, 1e-300), axis=1)


def _rotate_about_y(packed, angle):
    """Minv of the LTC rotated by ``angle`` about +Y: Minv R^T (R maps the old average direction
    to the new one); rotations about Y keep Minv[1][1] = 1 and the zero couplings."""
    c, s = np.cos(angle), np.sin(angle)
    minv = matrix.unpack_inverse(packed)
    rt = np.zeros(angle.shape + (3, 3))
    rt[..., 0, 0], rt[..., 0, 2], rt[..., 1, 1], rt[..., 2, 0], rt[..., 2, 2] = c, -s, 1.0, s, c
    return matrix.pack_inverse(minv @ rt)


def _step(x):
    scale = 0.05 * np.minimum(np.abs(x[:, 0]), np.abs(x[:, 3]))[:, None]
    return 0.05 * np.maximum(np.abs(x), scale) + 1e-9


def _fit_isotropic_row(lobe, mu, r, magnitude, settings):
    """Normal incidence: Minv = diag(1, 1, c3); grid search in log c3, then Nelder-Mead."""
    b = r.size
    identity = np.tile([1.0, 0.0, 0.0, 1.0], (b, 1))
    problem = RowProblem(lobe, mu, r, magnitude, identity, **settings)
    grid = np.geomspace(1e-5, 4.0, 48)

    def packed(c3):
        out = np.zeros(c3.shape + (4,))
        out[..., 0], out[..., 3] = 1.0, c3
        return out

    errors = np.stack([problem.objective(packed(np.full(b, g)), np.arange(b)) for g in grid], axis=1)
    c3 = grid[np.argmin(errors, axis=1)]
    problem = RowProblem(lobe, mu, r, magnitude, packed(c3), **settings)
    x, _, it = optimize.minimise(lambda x, idx: problem.objective(packed(x[:, 0]), idx),
                                 c3[:, None], 0.1 * c3[:, None], max_iter=300, restarts=0)
    return packed(x[:, 0]), it


def fit_table(lobe_name, size=64, n_moments=1 << 14, n_lobe=384, n_ltc=384, n_sphere=96, exponent=1.0,
              max_iter=300, progress=None):
    """Fit the LTC table of one lobe.  Returns a dict of (size, size[, 4]) arrays indexed [t, a]:
    ``packed`` (c0..c3), ``magnitude``, ``fresnel``, ``tv`` (fit-sample objective), ``iterations``.
    Axes: a -> r = a/(size-1); t -> v = t/(size-1), mu = max(1 - v^2, FIT_MU_MIN).
    """
    lobe = LOBES[lobe_name]
    nodes = np.arange(size, dtype=np.float64) / (size - 1)
    r = nodes
    settings = {"n_lobe": n_lobe, "n_ltc": n_ltc, "n_sphere": n_sphere, "exponent": exponent}
    packed = np.zeros((size, size, 4))
    magnitude = np.zeros((size, size))
    fresnel = np.zeros((size, size))
    objective = np.zeros((size, size))
    iterations = np.zeros((size, size), dtype=np.int64)
    prev_angle = None
    for t in range(size):
        mu = max(1.0 - nodes[t] ** 2, FIT_MU_MIN)
        magnitude[t], fresnel[t], avg = lobe_integrals(lobe, mu, r, n_moments)
        angle = np.arctan2(avg[:, 0], avg[:, 2])
        if t == 0:
            packed[t], iterations[t] = _fit_isotropic_row(lobe, mu, r, magnitude[t], settings)
            problem = RowProblem(lobe, mu, r, magnitude[t], packed[t], **settings)
            objective[t] = problem.objective(packed[t], np.arange(size))
        else:
            rotated = _rotate_about_y(packed[t - 1], angle - prev_angle)
            problem = RowProblem(lobe, mu, r, magnitude[t], rotated, **settings)
            idx = np.arange(size)
            keep = problem.objective(packed[t - 1], idx) < problem.objective(rotated, idx)
            start = np.where(keep[:, None], packed[t - 1], rotated)
            # No restarts: measured on the GGX table, a restart leaves the mean TV at 0.0420 and
            # costs ~25% more time (rows start from the previous row's solution and converge).
            x, f, it = optimize.minimise(problem.objective, start, _step(start), max_iter=max_iter, restarts=0)
            packed[t], objective[t], iterations[t] = x, f, it
        prev_angle = angle
        if progress is not None:
            progress(t + 1, size)
    return {"packed": packed, "magnitude": magnitude, "fresnel": fresnel, "objective": objective,
            "iterations": iterations}
