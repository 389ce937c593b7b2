"""Cloth and sheen: Ashikhmin velvet with Neubelt-Pettineo visibility, and Disney sheen."""
from __future__ import annotations

import numpy as np

from . import shading_ops as op
from .conventions import ALPHA_MIN, COS_EPS

#: Floor for sin^2(theta_h); sin^4 = 1e-14 stays a normal float32, and at that floor the
#: exponential term exp(-cot^2/alpha^2) is exactly 0, so the floor changes no value.
SIN2_MIN = 1e-7


def ashikhmin_velvet_distribution(n_dot_h, alpha):
    """Inverted-Gaussian velvet distribution with an offset, normalised.

    Ashikhmin & Premoze 2007, "Distribution-based BRDFs" (inverted Gaussian
    D ~ exp(-cot^2 / alpha^2) / sin^4), with the constant offset and normalisation of
    Neubelt & Pettineo 2013, "Crafting a Next-Gen Material Pipeline for The Order: 1886":
        D = (1 + 4 exp(-cot^2(theta_h) / alpha^2) / sin^4(theta_h)) / (pi (1 + 4 alpha^2)).
    int D cos(theta_h) dw = 1 (the exponential term integrates to 4 pi alpha^2 / pi; tested).
    """
    a2 = op.maximum(alpha, ALPHA_MIN) ** 2
    c = op.saturate(n_dot_h)
    c2 = c * c
    s2 = op.maximum((1.0 - c) * (1.0 + c), SIN2_MIN)
    peak = 4.0 * op.exp(-c2 / (a2 * s2)) / (s2 * s2)
    D = (1.0 + peak) / (np.pi * (1.0 + 4.0 * a2))
    return op.select(op.greater(n_dot_h, 0.0), D, 0.0)


def neubelt_visibility(mu_l, mu_v):
    """Cloth visibility V = 1 / (4 (mu_l + mu_v - mu_l mu_v)) (Neubelt & Pettineo 2013)."""
    mu_l, mu_v = op.saturate(mu_l), op.saturate(mu_v)
    return 1.0 / (4.0 * op.maximum(mu_l + mu_v - mu_l * mu_v, COS_EPS))


def ashikhmin_cloth_brdf(mu_l, mu_v, n_dot_h, alpha):
    """Cloth specular as in Filament / UE4 (F = 1; the caller multiplies by the sheen colour):
    f = D_velvet(h) V_neubelt(l, v).  Zero below either horizon.  Reciprocal.
    """
    f = ashikhmin_velvet_distribution(n_dot_h, alpha) * neubelt_visibility(mu_l, mu_v)
    return op.select(op.logical_and(op.greater(mu_l, 0.0), op.greater(mu_v, 0.0)), f, 0.0)


def disney_sheen(l_dot_h):
    """Disney sheen lobe f = (1 - cos theta_d)^5, cos theta_d = l.h (Burley 2012, section 5.3).

    As in the Disney BRDF there is no 1/pi; the caller scales by sheen * tint colour.
    """
    return op.pow5(1.0 - op.saturate(l_dot_h))
