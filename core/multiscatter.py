"""Multiple-scattering compensation for GGX specular.

Inputs come from the energy LUTs (core/lut): one_minus_e = 1 - E(mu, r),
one_minus_e_avg = 1 - E_avg(r), and the split-sum (scale, bias).  The tables store 1 - E and
1 - E_avg rather than E and E_avg because both tend to 1 at low roughness, where forming
1 - E_avg in float32 would lose most digits (the lobe divides by it).  All take F90 = 1 unless given.
"""
from __future__ import annotations

import numpy as np

from . import shading_ops as op
from .conventions import COS_EPS
from .fresnel import fresnel_average

#: Floor for 1 - E_avg, which tends to 0 with roughness (r = 0: 1 - E_avg < 1e-7).
#: The lobe's numerator (1 - E(mu_o))(1 - E(mu_i)) vanishes faster, so f_ms -> 0.
ONE_MINUS_E_AVG_MIN = 1e-7


def kulla_conty_lobe(one_minus_e_o, one_minus_e_i, one_minus_e_avg):
    """Kulla-Conty multiple-scattering lobe for F = 1 (Kulla & Conty 2017, slide 18; the talk).

    f_ms(mu_o, mu_i) = (1 - E(mu_o)) (1 - E(mu_i)) / (pi (1 - E_avg)).
    With E_avg = 2 int E mu dmu, int (f_ss + f_ms) mu_i dw_i = 1 for every mu_o.
    """
    return one_minus_e_o * one_minus_e_i / (np.pi * op.maximum(one_minus_e_avg, ONE_MINUS_E_AVG_MIN))


def kulla_conty_fresnel_factor(f_avg, one_minus_e_avg):
    """Energy kept by the multiply-scattered paths with Fresnel F_avg per bounce.

    F_ms = F_avg^2 E_avg / (1 - F_avg (1 - E_avg)) (Kulla & Conty 2017, slide 20; the talk).
    The denominator is >= E_avg > 0 for F_avg <= 1.
    """
    return f_avg * f_avg * (1.0 - one_minus_e_avg) / op.maximum(1.0 - f_avg * one_minus_e_avg, COS_EPS)


def kulla_conty_brdf(one_minus_e_o, one_minus_e_i, one_minus_e_avg, f0, f90=1.0):
    """Kulla-Conty lobe with Schlick's average Fresnel: F_ms(F_avg(F0), E_avg) * f_ms."""
    return (kulla_conty_fresnel_factor(fresnel_average(f0, f90), one_minus_e_avg)
            * kulla_conty_lobe(one_minus_e_o, one_minus_e_i, one_minus_e_avg))


def turquin_compensation(f0, e_v):
    """Scale for f_ss: 1 + F0 (1 - E(mu_v)) / E(mu_v) (Turquin 2019, eq. 16; the talk).

    Uses the view cosine only, so the compensated BRDF is not reciprocal (as in Cycles,
    Filament and HDRP).  E >= ~0.3 for GGX with F = 1; the floor only guards bad inputs.
    """
    return 1.0 + f0 * (1.0 - e_v) / op.maximum(e_v, COS_EPS)


def split_sum_specular(f0, scale, bias, f90=1.0):
    """Split-sum environment BRDF F0 * scale + F90 * bias (Karis 2013, eq. 4)."""
    return f0 * scale + f90 * bias


def fdez_aguera_terms(f0, scale, bias, f90=1.0):
    """Fdez-Aguera 2019, "A Multiple-Scattering Microfacet Model for Real-Time IBL", eq. 11-16.

    Returns (FssEss, FmsEms): single-scattered and multiply-scattered energy factors, so that
    L = FssEss * prefiltered_radiance + FmsEms * irradiance (the paper) or
    L = (FssEss + FmsEms) * prefiltered_radiance (the talk's approximation).
    FssEss = F0 scale + F90 bias; Ess = scale + bias; Ems = 1 - Ess;
    Fms = FssEss F_avg / (1 - Ems F_avg), F_avg = F0 + (F90 - F0)/21.
    The talk's snippet indexes its LUT the other way round (x = bias, y = scale); here
    ``scale`` multiplies F0 as in Karis 2013.
    """
    fss_ess = split_sum_specular(f0, scale, bias, f90)
    e_ms = 1.0 - (scale + bias)
    f_avg = fresnel_average(f0, f90)
    f_ms = fss_ess * f_avg / op.maximum(1.0 - e_ms * f_avg, COS_EPS)
    return fss_ess, f_ms * e_ms


def fdez_aguera_env_brdf(f0, scale, bias, f90=1.0):
    """Directional albedo of the Fdez-Aguera model: FssEss + FmsEms (1 for F0 = F90 = 1)."""
    fss_ess, fms_ems = fdez_aguera_terms(f0, scale, bias, f90)
    return fss_ess + fms_ems


def average_energy_polynomial_talk(smoothness):
    """The talk's ``AverageEnergy(smoothness)`` fit of E_avg, s = 1 - r, clamped to 0.999.

    Kept only to measure it against the baked E_avg (scripts/benchmark_luts.py): its 0.999
    clamp breaks the furnace identity at low roughness.  The shipped code uses E_avg from
    the same table as E.
    """
    s = np.asarray(smoothness, dtype=np.float64)
    r = -0.0761947 - 0.383026 * s
    r = 1.04997 + s * r
    r = 0.409255 + s * r
    return np.minimum(0.999, r)


def fdez_aguera_area_scale(f0, e, f90=1.0):
    """Scale for single-scattered specular under area lights: 1 + F_avg (1 - E) / (1 - F_avg (1 - E)).

    The talk's "approximation to Fdez-Aguera": f_ms = F_avg (1 - E(mu)) / (1 - F_avg (1 - E(mu))) f_ss,
    with E(mu) the magnitude of the GGX LTC table.  Equals 1/E for F0 = F90 = 1 (white furnace).
    """
    f_avg = fresnel_average(f0, f90)
    lost = f_avg * (1.0 - e)
    return 1.0 + lost / op.maximum(1.0 - lost, COS_EPS)
