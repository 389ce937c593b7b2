"""Fresnel terms."""
from __future__ import annotations

from . import shading_ops as op


def schlick_weight(cos_theta):
    """(1 - cos_theta)^5 with cos_theta clamped to [0, 1] (Schlick 1994, eq. 24)."""
    return op.pow5(1.0 - op.saturate(cos_theta))


def fresnel_schlick(f0, cos_theta, f90=1.0):
    """Schlick's Fresnel F = F0 + (F90 - F0)(1 - cos)^5 (Schlick 1994; F90 as in Burley 2012).

    ``cos_theta`` is the cosine between the light (or view) direction and the half vector.
    """
    return op.mix(f0, f90, schlick_weight(cos_theta))


def fresnel_average(f0, f90=1.0):
    """Hemispherical (cosine-weighted) average of Schlick's Fresnel.

    F_avg = 2 int_0^1 F(mu) mu dmu = F0 + (F90 - F0)/21, because
    2 int_0^1 (1 - mu)^5 mu dmu = 2 B(2, 6) = 1/21.  This is the talk's equation 11
    *as corrected*: the first version of Fdez-Aguera 2019 printed pi/21, an error fixed
    in the JCGT update of Feb 2019 that the talk quotes.  Tested by integration.
    """
    return op.mix(f0, f90, 1.0 / 21.0)
