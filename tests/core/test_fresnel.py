import numpy as np
import pytest

from rt_lookdev.core import fresnel


@pytest.mark.parametrize("f0", [0.0, 0.04, 0.5, 0.9, 1.0])
def test_average_fresnel_by_integration(f0):
    # F_avg = 2 int_0^1 F(mu) mu dmu; the degree-6 polynomial is integrated exactly.
    mu, w = np.polynomial.legendre.leggauss(8)
    mu, w = 0.5 * (mu + 1), 0.5 * w
    integral = 2 * np.sum(fresnel.fresnel_schlick(f0, mu) * mu * w)
    assert fresnel.fresnel_average(f0) == pytest.approx(integral, abs=1e-12)
    if f0 < 1:  # the uncorrected pi/21 of Fdez-Aguera's first version is wrong
        assert abs(f0 + np.pi / 21 * (1 - f0) - integral) > 0.05 * (1 - f0)


def test_schlick_limits():
    assert fresnel.fresnel_schlick(0.04, 1.0) == pytest.approx(0.04)
    assert fresnel.fresnel_schlick(0.04, 0.0) == pytest.approx(1.0)
    assert fresnel.fresnel_schlick(0.04, 0.0, f90=0.5) == pytest.approx(0.5)
