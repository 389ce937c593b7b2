"""Quadrature rules shared by the core tests."""
import numpy as np

from rt_lookdev.core import sampling


def sphere_quadrature(n_theta=256, n_phi=256, upper_only=False):
    """Gauss-Legendre in mu over [-1, 1] (or [0, 1]) times uniform phi: directions and weights."""
    mu, w_mu = sampling.gauss_legendre(n_theta, 0.0 if upper_only else -1.0, 1.0)
    phi = (np.arange(n_phi) + 0.5) * (2 * np.pi / n_phi)
    M, P = np.meshgrid(mu, phi, indexing="ij")
    s = np.sqrt(np.maximum(1 - M * M, 0))
    dirs = np.stack([s * np.cos(P), s * np.sin(P), M], axis=-1)
    weights = (w_mu[:, None] * np.full(n_phi, 2 * np.pi / n_phi)[None, :])
    return dirs, weights


def composite_gauss(a, b, panels=400, order=16):
    """Composite Gauss-Legendre rule on [a, b] (cheap to build, accurate for peaked integrands)."""
    x, w = np.polynomial.legendre.leggauss(order)
    edges = np.linspace(a, b, panels + 1)
    half = 0.5 * np.diff(edges)[:, None]
    nodes = edges[:-1, None] + half * (x + 1.0)
    return nodes.ravel(), (half * w).ravel()


def projected_area(distribution, alpha):
    """2 pi int D(theta) cos(theta) sin(theta) dtheta over [0, pi/2]: 1 for a normalised NDF."""
    theta, w = composite_gauss(0.0, 0.5 * np.pi)
    mu = np.cos(theta)
    return 2 * np.pi * np.sum(distribution(mu, alpha) * mu * np.sin(theta) * w)
