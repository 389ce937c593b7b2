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
from .ir.functions import NodeFunction
from .ir.interface import color, factor
from .lut.lookup import REFERENCES

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


# --- node functions (offered to artists as stand-alone groups) --------------------------------------

_F0 = color((0.04, 0.04, 0.04), "Specular reflectance at normal incidence F0 (Schlick, F90 = 1)")
_E = factor(1.0, "Directional albedo E(mu_v) of the single-scattering lobe with F = 1")
_SCALE_OUT = {"Scale": color((1.0, 1.0, 1.0), "Multiplies the single-scattering specular")}


def _turquin_node(F0, E):
    return {"Scale": op.per_channel(turquin_compensation, F0, E)}


def _fdez_area_node(F0, E):
    return {"Scale": op.per_channel(fdez_aguera_area_scale, F0, E)}


# Fdez-Aguera 2019, eq. 11-16, with Karis 2013's split-sum table (scale, bias) at (mu_v, r).
def _fdez_environment_node(tables, **kw):
    scale, bias = tables.split_sum(op.saturate(kw["N.V"]), op.saturate(kw["Roughness"]))
    fss = op.per_channel(lambda f0: fdez_aguera_terms(f0, scale, bias)[0], kw["F0"])
    fms = op.per_channel(lambda f0: fdez_aguera_terms(f0, scale, bias)[1], kw["F0"])
    return {"FssEss": fss, "FmsEms": fms}


TURQUIN_COMPENSATION = NodeFunction(
    "RTL Turquin Compensation", _turquin_node, {"F0": _F0, "E": _E}, _SCALE_OUT,
    "Turquin 2019 multiple-scattering compensation of the specular lobe (view-dependent)")
FDEZ_AGUERA_AREA_SCALE = NodeFunction(
    "RTL Fdez-Aguera Area Scale", _fdez_area_node, {"F0": _F0, "E": _E}, _SCALE_OUT,
    "The talk's approximation to Fdez-Aguera's multiple scattering under area lights")
FDEZ_AGUERA_ENVIRONMENT_BRDF = NodeFunction(
    "RTL Fdez-Aguera Environment BRDF", _fdez_environment_node,
    {"F0": _F0, "N.V": factor(1.0, "mu_v = N.V, cosine of the view angle"),
     "Roughness": factor(0.5, "Blender roughness r (GGX alpha = r^2)")},
    {"FssEss": color((0.0, 0.0, 0.0), "Single-scattered energy: times prefiltered radiance"),
     "FmsEms": color((0.0, 0.0, 0.0), "Multiply-scattered energy: times irradiance")},
    "Fdez-Aguera 2019 multiple-scattering split-sum environment BRDF", tables=REFERENCES)

NODE_FUNCTIONS = (TURQUIN_COMPENSATION, FDEZ_AGUERA_AREA_SCALE, FDEZ_AGUERA_ENVIRONMENT_BRDF)
