"""A batched Nelder-Mead minimiser: many independent small problems advanced in lock-step.

Nelder & Mead 1965 with the standard coefficients (reflection 1, expansion 2, contraction
1/2, shrink 1/2; as in Numerical Recipes and ltc_code's fitter).  Each problem b has its own
simplex; ``objective(x, idx)`` evaluates points x (k, n) for the problems idx (k,), so a
batch only pays for the problems that need a new point.  Converged problems are frozen.
"""
from __future__ import annotations

import numpy as np


def minimise(objective, x0, step, max_iter=400, ftol=1e-7, xtol=1e-9, restarts=1):
    """Minimise B problems of dimension n from starting points x0 (B, n) and steps (B, n).

    After convergence each problem restarts ``restarts`` times from its best point with a fresh
    simplex of the initial size: Nelder-Mead can stall on a collapsed simplex, especially on
    non-smooth objectives (the remedy recommended by Numerical Recipes, section 10.5).
    Returns (x_best (B, n), f_best (B,), iterations (B,), summed over the rounds).
    """
    x, f, total = _minimise_once(objective, np.asarray(x0, dtype=np.float64), step, max_iter, ftol, xtol)
    for _ in range(restarts):
        x2, f2, it = _minimise_once(objective, x, step, max_iter, ftol, xtol)
        better = f2 < f
        x[better], f[better] = x2[better], f2[better]
        total += it
    return x, f, total


def _minimise_once(objective, x0, step, max_iter, ftol, xtol):
    x0 = np.asarray(x0, dtype=np.float64)
    b, n = x0.shape
    all_idx = np.arange(b)
    simplex = np.repeat(x0[:, None, :], n + 1, axis=1)
    for i in range(n):
        simplex[:, i + 1, i] += step[:, i]
    values = objective(simplex.reshape(-1, n), np.repeat(all_idx, n + 1)).reshape(b, n + 1)
    iterations = np.zeros(b, dtype=np.int64)
    active = np.ones(b, dtype=bool)
    for _ in range(max_iter):
        order = np.argsort(values, axis=1)
        simplex = np.take_along_axis(simplex, order[..., None], axis=1)
        values = np.take_along_axis(values, order, axis=1)
        spread = np.abs(values[:, -1] - values[:, 0])
        size = np.max(np.abs(simplex[:, 1:] - simplex[:, :1]), axis=(1, 2))
        active &= ~((spread <= ftol * (np.abs(values[:, 0]) + 1e-30)) | (size <= xtol))
        idx = all_idx[active]
        if idx.size == 0:
            break
        iterations[idx] += 1
        s, v = simplex[idx], values[idx]
        centroid = s[:, :-1].mean(axis=1)
        worst = s[:, -1]
        xr = centroid + (centroid - worst)
        fr = objective(xr, idx)
        expand = fr < v[:, 0]
        contract = fr >= v[:, -2]
        outside = contract & (fr < v[:, -1])
        # second point: expansion, or outside / inside contraction
        x2 = np.where(expand[:, None], centroid + 2.0 * (xr - centroid),
                      np.where(outside[:, None], centroid + 0.5 * (xr - centroid),
                               centroid + 0.5 * (worst - centroid)))
        need2 = expand | contract
        f2 = np.full(idx.size, np.inf)
        if np.any(need2):
            f2[need2] = objective(x2[need2], idx[need2])
        new_x, new_f = xr.copy(), fr.copy()
        take_e = expand & (f2 < fr)
        new_x[take_e], new_f[take_e] = x2[take_e], f2[take_e]
        ok_c = contract & np.where(outside, f2 <= fr, f2 < v[:, -1])
        new_x[ok_c], new_f[ok_c] = x2[ok_c], f2[ok_c]
        replace = ~contract | ok_c
        s[replace, -1] = new_x[replace]
        v[replace, -1] = new_f[replace]
        shrink = contract & ~ok_c
        if np.any(shrink):
            best = s[shrink, :1]
            s[shrink, 1:] = best + 0.5 * (s[shrink, 1:] - best)
            k = int(shrink.sum())
            pts = s[shrink, 1:].reshape(-1, n)
            v[shrink, 1:] = objective(pts, np.repeat(idx[shrink], n)).reshape(k, n)
        simplex[idx], values[idx] = s, v
    best = np.argmin(values, axis=1)
    return simplex[all_idx, best], values[all_idx, best], iterations
