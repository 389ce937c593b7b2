import numpy as np
import pytest

from rt_lookdev.core import diffuse
from rt_lookdev.core import shading_ops as op

from quadrature import sphere_quadrature


def test_cod_gloss_mapping_values():
    alpha = np.array([0.5, 0.75, 1.0]) ** 2
    g = diffuse.cod_gloss_from_alpha(alpha)
    assert g[0] == pytest.approx(0.2752, abs=5e-4)
    assert g[1] == pytest.approx(0.134, abs=1e-3)
    assert g[2] == 0.0
    assert diffuse.cod_gloss_from_alpha(0.04 ** 2) == 1.0
    # inverse: CoD's alpha^2 = 2 / (1 + 2^(18 g))
    assert 2 / (1 + 2 ** (18 * g[0])) == pytest.approx(alpha[0] ** 2, rel=1e-9)


def test_talk_gloss_constant_means_log10():
    s = np.linspace(0.05, 0.9, 18)
    paper = diffuse.cod_gloss_from_alpha((1 - s) ** 2)
    assert np.allclose(diffuse.cod_gloss_talk(s), paper, atol=3e-5)          # 0.18455 = 1/(18 log10 2)
    assert diffuse.cod_gloss_talk(0.5, natural_log=True) == pytest.approx(0.634, abs=1e-3)


def _cod_albedo(mu_v, r, n=400):
    dirs, w = sphere_quadrature(n, n, upper_only=True)
    v = np.array([np.sqrt(1 - mu_v ** 2), 0.0, mu_v])
    h = op.normalize(dirs + v)
    f = diffuse.cod_multiscatter_diffuse(1.0, dirs[..., 2], mu_v, h[..., 2], op.dot(dirs, h), r * r)
    return np.sum(f * dirs[..., 2] * w)


def test_cod_directional_albedo_reference_values():
    # independent numbers from docs/multiscattering.md, "Call of Duty WWII diffuse" (computed),
    # given to 2 decimals
    assert _cod_albedo(0.5, 0.5) == pytest.approx(0.88, abs=0.01)
    assert _cod_albedo(1.0, 0.5) == pytest.approx(0.94, abs=0.01)
    assert _cod_albedo(0.1, 1.0) == pytest.approx(1.05, abs=0.01)


def test_cod_is_reciprocal():
    rng = np.random.default_rng(5)
    d = rng.normal(size=(2, 1000, 3)); d[..., 2] = np.abs(d[..., 2])
    l, v = d / np.linalg.norm(d, axis=-1, keepdims=True)
    h = op.normalize(l + v)
    a = diffuse.cod_multiscatter_diffuse(0.8, l[:, 2], v[:, 2], h[:, 2], op.dot(l, h), 0.3)
    b = diffuse.cod_multiscatter_diffuse(0.8, v[:, 2], l[:, 2], h[:, 2], op.dot(v, h), 0.3)
    assert np.allclose(a, b, rtol=1e-12)


@pytest.mark.parametrize("w", [0.0, 0.25, 0.5, 1.0])
def test_wrapped_diffuse_conserves_energy(w):
    # a uniform environment of radiance 1 over the whole sphere reflects exactly 1
    dirs, weights = sphere_quadrature(2000, 4)
    assert np.sum(diffuse.wrapped_diffuse_cosine(dirs[..., 2], w) * weights) == pytest.approx(1.0, abs=1e-6)
    # the un-normalised talk form (cos + w)/(1 + w)/pi gains energy 1 + w
    gain = np.sum(np.maximum(dirs[..., 2] + w, 0) / (1 + w) / np.pi * weights)
    assert gain == pytest.approx(1 + w, abs=1e-6)


def test_wrapped_diffuse_zero_is_lambert():
    mu = np.linspace(-1, 1, 101)
    assert np.allclose(diffuse.wrapped_diffuse_cosine(mu, 0.0), np.maximum(mu, 0) / np.pi)


def test_wrapped_normal():
    n = np.array([0.0, 0.0, 1.0])
    l_side = np.array([1.0, 0.0, 0.0])
    assert np.allclose(diffuse.wrapped_normal(n, l_side, 0.0), n)       # w = 0: unchanged
    assert np.allclose(diffuse.wrapped_normal(n, n, 0.7), n)            # light at the normal
    tilted = diffuse.wrapped_normal(n, l_side, 1.0)                     # sin(phi) = lerp(1, 0, 0.5)
    assert np.allclose(tilted, [0.5, 0.0, np.sqrt(0.75)])
    back = diffuse.wrapped_normal(n, -n, 1.0)                           # degenerate: N returned
    assert np.allclose(back, n)
    rng = np.random.default_rng(7)
    ls = rng.normal(size=(500, 3)); ls /= np.linalg.norm(ls, axis=-1, keepdims=True)
    out = diffuse.wrapped_normal(np.broadcast_to(n, ls.shape), ls, rng.random((500,)))
    assert np.all(np.isfinite(out)) and np.allclose(np.linalg.norm(out, axis=-1), 1.0)
