import numpy as np
import pytest

from rt_lookdev.core import cloth, falloff
from rt_lookdev.core import shading_ops as op

from quadrature import projected_area, sphere_quadrature


@pytest.mark.parametrize("alpha", [0.1, 0.25, 0.5, 1.0])
def test_velvet_distribution_is_normalised(alpha):
    assert projected_area(cloth.ashikhmin_velvet_distribution, alpha) == pytest.approx(1.0, abs=1e-6)


def test_cloth_albedo_reference_values():
    # docs/multiscattering.md, "Cloth and sheen" (computed): Ashikhmin/Neubelt, alpha = 0.5, F = 1:
    # 0.57 / 0.25 / 0.13
    dirs, w = sphere_quadrature(400, 400, upper_only=True)
    for mu_v, expected in ((0.1, 0.57), (0.5, 0.25), (1.0, 0.13)):
        v = np.array([np.sqrt(1 - mu_v ** 2), 0.0, mu_v])
        h = op.normalize(dirs + v)
        f = cloth.ashikhmin_cloth_brdf(dirs[..., 2], mu_v, h[..., 2], 0.5)
        assert np.sum(f * dirs[..., 2] * w) == pytest.approx(expected, abs=0.01)


def test_cloth_reciprocal_and_finite():
    c = np.array([0.0, 1e-6, 0.3, 1 - 1e-7, 1.0], dtype=np.float32)
    C, A = np.meshgrid(c, np.array([0.0, 1e-4, 0.5, 1.0], dtype=np.float32))
    for value in (cloth.ashikhmin_velvet_distribution(C, A), cloth.neubelt_visibility(C, C),
                  cloth.ashikhmin_cloth_brdf(C, C, C, A)):
        assert np.all(np.isfinite(value)) and value.dtype == np.float32
    assert np.allclose(cloth.ashikhmin_cloth_brdf(0.2, 0.7, 0.9, 0.4), cloth.ashikhmin_cloth_brdf(0.7, 0.2, 0.9, 0.4))


def test_disney_sheen():
    assert cloth.disney_sheen(1.0) == 0.0
    assert cloth.disney_sheen(0.0) == 1.0
    assert cloth.disney_sheen(0.5) == pytest.approx(0.5 ** 5)


def test_window_falloff():
    d = np.array([0.0, 0.5, 1.0, 2.0])
    assert np.allclose(falloff.window_falloff(d, 1.0), [1.0, (1 - 0.0625) ** 2, 0.0, 0.0])
    assert falloff.window_falloff(1.0, 0.0) == 0.0


def test_inverse_square_clamped():
    assert falloff.inverse_square_falloff(2.0) == pytest.approx(0.25)
    assert falloff.inverse_square_falloff(0.0) == pytest.approx(1e4)


def test_cone_falloff():
    inner, outer = np.radians(30), np.radians(60)
    assert falloff.cone_falloff(np.cos(inner / 2), inner, outer) == pytest.approx(1)
    assert falloff.cone_falloff(np.cos(outer / 2), inner, outer) == pytest.approx(0, abs=1e-12)
    assert falloff.cone_falloff(np.cos(np.radians(90)), inner, outer) == 0
    hard = falloff.cone_falloff(np.cos(np.radians([10, 29.9, 30.1])), outer, outer)
    assert np.all(np.isfinite(hard)) and hard[0] == 1 and hard[2] == 0


def test_projector_distance():
    assert falloff.projector_distance(2.0, np.radians(90)) == pytest.approx(1.0)
    assert falloff.projector_distance(1.0, np.radians(120)) == pytest.approx(0.5 / np.tan(np.radians(60)))
    assert np.isfinite(falloff.projector_distance(1.0, 0.0))
