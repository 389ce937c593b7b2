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

With a ``Band`` (the GGX table, ``catalog.LTC_BANDS``; docs/area_lights.md, "The band") the fitted density
is the mixture (1 - w) D(Minv) + w D(Minv diag(1, 1, k)) and each cell fits five parameters, Minv's four
and w, with the same objective; the band's own directions join the sample set.  Columns below the band's
``min_roughness`` keep the fit without a band, which is the same, to the bit, as before the band existed.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from .. import sampling
from . import matrix, optimize
from .fit_lobes import LOBES

#: Smallest view cosine fitted (theta <= 89.94 deg); the last table row (mu = 0) uses it.
FIT_MU_MIN = 1e-3


@dataclass(frozen=True)
class Band:
    """A second LTC mixed into the fitted one (docs/area_lights.md, "The band"): density
    (1 - w) D(Minv) + w D(Minv diag(1, 1, squash)) (``matrix.squash_packed``: the fitted lobe pressed towards
    the horizon), w fitted per cell jointly with Minv.  ``max_weight``: the weight's upper bound (the
    optimiser's raw parameter is clipped to [0, max_weight]); ``min_roughness``: columns of lower roughness
    keep the fit without a band (w = 0; where the band does not pay, measured); ``samples``: directions drawn
    from the band per cell for the objective; ``weight_step``: the weight's initial simplex step."""
    squash: float
    max_weight: float = 0.9
    min_roughness: float = 0.0
    samples: int = 128
    weight_step: float = 0.05

    def weight(self, raw):
        return np.clip(raw, 0.0, self.max_weight)

    def of(self, main):
        """The band's packed Minv entries for fitted entries ``main`` (..., 4)."""
        main = np.asarray(main, np.float64)
        return np.stack(matrix.squash_packed(tuple(main[..., i] for i in range(4)), self.squash), axis=-1)


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
                 exponent=2.0, band=None):
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
        parts = [l_b, l_q, l_u]
        self.band = band
        if band is not None:
            # directions of the band LTC too: it puts its mass where the other sets are sparse (the horizon)
            u1, u2 = sampling.hammersley_2d(band.samples)
            l_h = matrix.sample(np.linalg.inv(matrix.unpack_inverse(band.of(start)))[:, None], u1[None], u2[None])
            parts.append(np.broadcast_to(l_h, (b, band.samples, 3)))
        dirs = np.concatenate(parts, axis=1)
        self.dirs = dirs
        n = dirs.shape[1]
        pdf_lobe = lobe.pdf(dirs, v, r)
        pdf_start = matrix.density_packed(start, dirs)
        mixture = n_lobe * pdf_lobe + n_ltc * pdf_start + n_sphere / (4 * np.pi)
        if band is not None:
            mixture = mixture + band.samples * matrix.density_packed(band.of(start), dirs)
        self.inv_mixture = 1.0 / (mixture / n) / n
        self.p = lobe.eval_cos(dirs, v, r) / np.maximum(magnitude[:, None], 1e-300)
        self.exponent = exponent

    def density(self, x, idx):
        """The fitted density at the sample directions of problems ``idx``: the LTC of x[:, :4], mixed with the
        band's LTC by the weight ``band.weight(x[:, 4])`` when the problem has a band."""
        q = matrix.density_packed(x[:, :4], self.dirs[idx])
        if self.band is None:
            return q
        w = self.band.weight(x[:, 4])[:, None]
        return q + w * (matrix.density_packed(self.band.of(x[:, :4]), self.dirs[idx]) - q)

    def objective(self, x, idx):
        q = self.density(x, idx)
        diff = np.abs(self.p[idx] - q)
        if self.exponent != 1.0:
            diff = diff ** self.exponent
        return np.sum(diff * self.inv_mixture[idx], axis=1)


def tv_distance(lobe, mu, roughness, magnitude, packed, n=1 << 14, band=None, weight=None):
    """Total-variation distance 1/2 int |p - q| between the normalised lobe p and the LTC q.

    Estimated with n lobe samples and n LTC samples, weighting by the mixture density (a
    bounded integrand: |p - q| / (pdf_lobe + q) <= ~1).  0 = identical, 1 = disjoint; it bounds
    the error of the LTC integral over any light, relative to the magnitude.  With a ``band`` (a ``Band``)
    and its ``weight`` per cell, q is the mixture of the LTC and its band (sampled in proportion).
    """
    v = view_vector(mu)
    r = np.asarray(roughness, dtype=np.float64)[:, None]
    u1, u2 = sampling.hammersley_2d(n)
    l_b, _ = lobe.sample(v, r, u1[None], u2[None])
    m = np.linalg.inv(matrix.unpack_inverse(packed))
    l_q = matrix.sample(m[:, None], u1[None], u2[None])
    if band is not None:
        # the mixture's samples: a fraction w of the points (picked by a golden-ratio sequence over their index,
        # so that both subsets of the Hammersley set stay spread over the unit square) maps through the band
        w = np.asarray(weight, np.float64)[:, None]
        l_h = matrix.sample(np.linalg.inv(matrix.unpack_inverse(band.of(packed)))[:, None], u1[None], u2[None])
        l_q = np.where((np.arange(n) * 0.6180339887498949 % 1.0 < w)[..., None], l_h, l_q)
    dirs = np.concatenate([np.broadcast_to(l_b, l_q.shape), l_q], axis=1)
    p = lobe.eval_cos(dirs, v, r) / np.maximum(magnitude[:, None], 1e-300)
    q = matrix.density_packed(packed, dirs)
    if band is not None:
        q = q + w * (matrix.density_packed(band.of(packed), dirs) - q)
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


def _fit_isotropic_row(lobe, mu, r, magnitude, settings, band=None):
    """Normal incidence: Minv = diag(1, 1, c3); grid search in log c3, then Nelder-Mead (with a band: in
    (c3, raw weight), from weight 0).  Returns (parameters (B, 4) or (B, 5), iterations)."""
    b = r.size
    identity = np.tile([1.0, 0.0, 0.0, 1.0], (b, 1))
    plain = dict(settings, band=None)
    problem = RowProblem(lobe, mu, r, magnitude, identity, **plain)
    grid = np.geomspace(1e-5, 4.0, 48)

    def packed(c3):
        out = np.zeros(c3.shape + (4,))
        out[..., 0], out[..., 3] = 1.0, c3
        return out

    errors = np.stack([problem.objective(packed(np.full(b, g)), np.arange(b)) for g in grid], axis=1)
    c3 = grid[np.argmin(errors, axis=1)]
    problem = RowProblem(lobe, mu, r, magnitude, packed(c3), **plain)
    x, _, it = optimize.minimise(lambda x, idx: problem.objective(packed(x[:, 0]), idx),
                                 c3[:, None], 0.1 * c3[:, None], max_iter=300, restarts=0)
    if band is None:
        return packed(x[:, 0]), it
    problem = RowProblem(lobe, mu, r, magnitude, packed(x[:, 0]), **settings)

    def with_weight(y):
        return np.concatenate([packed(y[:, 0]), y[:, 1:]], axis=1)

    start = np.stack([x[:, 0], np.zeros(b)], axis=1)
    step = np.stack([0.1 * x[:, 0], np.full(b, band.weight_step)], axis=1)
    y, _, it2 = optimize.minimise(lambda y, idx: problem.objective(with_weight(y), idx), start, step,
                                  max_iter=300, restarts=0)
    return with_weight(y), it + it2


def fit_table(lobe_name, size=64, n_moments=1 << 14, n_lobe=384, n_ltc=384, n_sphere=96, exponent=1.0,
              max_iter=300, progress=None, band=None):
    """Fit the LTC table of one lobe.  Returns a dict of (size, size[, 4]) arrays indexed [t, a]:
    ``packed`` (c0..c3), ``magnitude``, ``fresnel``, ``tv`` (fit-sample objective), ``iterations``, and with a
    ``band`` (a ``Band``) its ``weight`` per cell, fitted jointly with the matrix.
    Axes: a -> r = a/(size-1); t -> v = t/(size-1), mu = max(1 - v^2, FIT_MU_MIN).
    """
    if band is not None and band.min_roughness > 0.0:
        # two fits, columns merged: below min_roughness the fit without a band (the same numbers as a table fitted
        # without one), from it the fit with the band (every column's Nelder-Mead is independent of the others')
        kw = dict(size=size, n_moments=n_moments, n_lobe=n_lobe, n_ltc=n_ltc, n_sphere=n_sphere, exponent=exponent,
                  max_iter=max_iter)
        half = (lambda first: (lambda done, total: progress(done + (0 if first else total), 2 * total))
                if progress is not None else (lambda first: None))
        plain = fit_table(lobe_name, progress=half(True), **kw)
        banded = fit_table(lobe_name, band=dataclasses.replace(band, min_roughness=0.0), progress=half(False), **kw)
        keep = np.arange(size) / (size - 1) < band.min_roughness
        for key in ("packed", "objective", "iterations"):
            banded[key][:, keep] = plain[key][:, keep]
        banded["weight"][:, keep] = 0.0
        return banded
    lobe = LOBES[lobe_name]
    nodes = np.arange(size, dtype=np.float64) / (size - 1)
    r = nodes
    settings = {"n_lobe": n_lobe, "n_ltc": n_ltc, "n_sphere": n_sphere, "exponent": exponent, "band": band}
    params = np.zeros((size, size, 4 if band is None else 5))
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
            params[t], iterations[t] = _fit_isotropic_row(lobe, mu, r, magnitude[t], settings, band)
            problem = RowProblem(lobe, mu, r, magnitude[t], params[t, :, :4], **settings)
            objective[t] = problem.objective(params[t], np.arange(size))
        else:
            rotated = params[t - 1].copy()
            rotated[:, :4] = _rotate_about_y(params[t - 1, :, :4], angle - prev_angle)
            problem = RowProblem(lobe, mu, r, magnitude[t], rotated[:, :4], **settings)
            idx = np.arange(size)
            keep = problem.objective(params[t - 1], idx) < problem.objective(rotated, idx)
            start = np.where(keep[:, None], params[t - 1], rotated)
            step = _step(start[:, :4])
            if band is not None:
                step = np.concatenate([step, np.full((size, 1), band.weight_step)], axis=1)
            # No restarts: measured on the GGX table, a restart leaves the mean TV at 0.0420 and
            # costs ~25% more time (rows start from the previous row's solution and converge).
            x, f, it = optimize.minimise(problem.objective, start, step, max_iter=max_iter, restarts=0)
            params[t], objective[t], iterations[t] = x, f, it
        prev_angle = angle
        if progress is not None:
            progress(t + 1, size)
    out = {"packed": params[..., :4], "magnitude": magnitude, "fresnel": fresnel, "objective": objective,
           "iterations": iterations}
    if band is not None:
        out["weight"] = band.weight(params[..., 4])
    return out
