import numpy as np
import pytest

from rt_lookdev.core import energy, microfacet
from rt_lookdev.core.energy_checks import CYCLES_E, CYCLES_E_AVG, CYCLES_MU, CYCLES_R
from rt_lookdev.core import shading_ops as op

from quadrature import projected_area, sphere_quadrature



@pytest.mark.parametrize("alpha", [0.05, 0.25, 0.5, 1.0])
def test_ggx_distribution_projected_area_is_one(alpha):
    # int D(h) cos(theta_h) dw = 1 (Walter et al. 2007, eq. 4)
    assert projected_area(microfacet.ggx_distribution, alpha) == pytest.approx(1.0, abs=1e-6)


def test_g2_equals_smith_lambda_form():
    rng = np.random.default_rng(1)
    mu_l, mu_v, alpha = rng.uniform(0.01, 1, 1000), rng.uniform(0.01, 1, 1000), rng.uniform(0.01, 1, 1000)

    def lam(mu):  # Heitz 2014, eq. 86
        tan2 = (1 - mu * mu) / (mu * mu)
        return 0.5 * (np.sqrt(1 + alpha * alpha * tan2) - 1)

    expected = 1 / (1 + lam(mu_l) + lam(mu_v))
    assert np.allclose(microfacet.smith_g2_height_correlated(mu_l, mu_v, alpha), expected, rtol=1e-12)
    assert np.allclose(microfacet.smith_g1(mu_v, alpha), 1 / (1 + lam(mu_v)), rtol=1e-12)
    assert np.allclose(microfacet.smith_visibility_height_correlated(mu_l, mu_v, alpha),
                       expected / (4 * mu_l * mu_v), rtol=1e-12)


def _random_pairs(n, seed=2):
    rng = np.random.default_rng(seed)
    d = rng.normal(size=(2, n, 3))
    d[..., 2] = np.abs(d[..., 2])
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    return d[0], d[1]


def _ggx_eval(l, v, alpha, f0=0.04):
    h = op.normalize(l + v)
    return microfacet.ggx_brdf(l[..., 2], v[..., 2], h[..., 2], op.dot(v, h), alpha, f0)


def test_ggx_brdf_is_reciprocal():
    l, v = _random_pairs(2000)
    assert np.allclose(_ggx_eval(l, v, 0.3), _ggx_eval(v, l, 0.3), rtol=1e-12)


@pytest.mark.parametrize("r", [0.5, 0.75, 1.0])
def test_vndf_albedo_matches_direct_quadrature(r):
    # Independent check of the baking estimator: integrate f_ss * mu_l over the hemisphere
    # with a dense tensor Gauss-Legendre rule instead of importance sampling.
    alpha = r * r
    dirs, w = sphere_quadrature(600, 600, upper_only=True)
    for mu_v in (0.2, 0.6, 1.0):
        v = np.array([np.sqrt(1 - mu_v ** 2), 0.0, mu_v])
        f = _ggx_eval(dirs, np.broadcast_to(v, dirs.shape), alpha, f0=1.0)
        quad = np.sum(f * dirs[..., 2] * w)
        est = energy.directional_albedo([mu_v], [r], 1 << 14)[0, 0]
        assert est == pytest.approx(quad, abs=3e-4)


def test_directional_albedo_matches_cycles_table():
    ours = energy.directional_albedo(CYCLES_MU, CYCLES_R, 1 << 14).T
    assert np.max(np.abs(ours - CYCLES_E)) < 1e-3


def test_average_albedo_matches_cycles_table():
    ours = energy.average_albedo(CYCLES_R, 64, 1 << 14)
    assert np.max(np.abs(ours - CYCLES_E_AVG)) < 1e-3
    assert ours[-1] == pytest.approx(0.409, abs=1e-3)


def test_vndf_samples_are_visible_unit_normals():
    v = np.array([0.8, 0.0, 0.6])
    u1, u2 = np.random.default_rng(0).random((2, 4096))
    m = microfacet.sample_ggx_vndf(np.broadcast_to(v, (4096, 3)), 0.5, u1, u2)
    assert np.allclose(np.linalg.norm(m, axis=-1), 1.0)
    assert np.all(m[:, 2] >= 0) and np.all(m @ v >= -1e-12)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_ggx_terms_finite_at_extremes(dtype):
    c = np.array([0.0, 1e-7, 0.5, 1.0 - 1e-7, 1.0], dtype=dtype)
    a = np.array([0.0, 1e-4, 0.5, 1.0], dtype=dtype)
    C, A = np.meshgrid(c, a)
    for value in (microfacet.ggx_distribution(C, A),
                  microfacet.smith_g1(C, A),
                  microfacet.smith_g2_height_correlated(C, C, A),
                  microfacet.smith_visibility_height_correlated(C, C, A),
                  microfacet.ggx_brdf(C, C, C, C, A)):
        assert np.all(np.isfinite(value))
        assert value.dtype == dtype


def test_ggx_peak_accurate_in_float32():
    alpha = np.float32(0.01)
    d32 = microfacet.ggx_distribution(np.float32(1.0), alpha)
    assert d32 == pytest.approx(1 / (np.pi * 0.01 ** 2), rel=1e-5)
