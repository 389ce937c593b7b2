"""Low-discrepancy point sets for deterministic (reproducible) integration."""
from __future__ import annotations

import numpy as np


def radical_inverse_base2(i):
    """Van der Corput radical inverse in base 2 of non-negative integers (bit reversal)."""
    i = np.asarray(i, dtype=np.uint64)
    bits = i.copy()
    bits = ((bits << np.uint64(16)) | (bits >> np.uint64(16))) & np.uint64(0xFFFFFFFF)
    bits = ((bits & np.uint64(0x55555555)) << np.uint64(1)) | ((bits & np.uint64(0xAAAAAAAA)) >> np.uint64(1))
    bits = ((bits & np.uint64(0x33333333)) << np.uint64(2)) | ((bits & np.uint64(0xCCCCCCCC)) >> np.uint64(2))
    bits = ((bits & np.uint64(0x0F0F0F0F)) << np.uint64(4)) | ((bits & np.uint64(0xF0F0F0F0)) >> np.uint64(4))
    bits = ((bits & np.uint64(0x00FF00FF)) << np.uint64(8)) | ((bits & np.uint64(0xFF00FF00)) >> np.uint64(8))
    return bits.astype(np.float64) * (1.0 / 4294967296.0)


def hammersley_2d(n):
    """The n-point 2D Hammersley set ((i + 1/2)/n, phi_2(i)), i < n <= 2**32.

    For n a power of two this is a (0, m, 2)-net in base 2 (Niederreiter 1992), the
    point set used by Karis 2013 for split-sum baking.  Returns two float64 arrays.
    """
    if n < 1 or n > 2**32:
        raise ValueError(f"hammersley_2d: n must be in [1, 2**32], got {n}")
    i = np.arange(n, dtype=np.uint64)
    return (i.astype(np.float64) + 0.5) / n, radical_inverse_base2(i)


def gauss_legendre(n, a=0.0, b=1.0):
    """n-point Gauss-Legendre nodes and weights on [a, b]."""
    x, w = np.polynomial.legendre.leggauss(n)
    half = 0.5 * (b - a)
    return a + half * (x + 1.0), half * w
