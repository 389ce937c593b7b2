"""Every node group RT Lookdev offers, as node functions of the numpy core (no bpy here).

Each entry is a ``core.ir.functions.NodeFunction``: the same Python function evaluates in numpy
and is emitted as a Blender node group (addon/node_emit.py).  ``TECHNIQUES`` are the BRDF-level
building blocks (one light direction, or the environment BRDF); ``LIGHTS`` turn Blender light
data into geometry; ``AREA_LOBES`` integrate a lobe over a quad or disk with LTCs;
``MATERIAL`` holds the RT Lit pieces.  ``all_functions()`` lists them in Add > Group order.
"""
from __future__ import annotations

import functools

from ..core import falloff, multiscatter
from ..core import shading_ops as op
from ..core.ir.functions import NodeFunction
from ..core.ir.interface import Socket, color, factor, scalar
from ..core.lut import catalog as lut_catalog
from ..core.lut.lookup import energy_lut_uv
from ..core.materials import lobes, rt_lit
from ..core.materials.rt_lit import per_channel

_F0 = color((0.04, 0.04, 0.04), "Specular reflectance at normal incidence F0 (Schlick, F90 = 1)")
_E = factor(1.0, "Directional albedo E(mu_v) of the single-scattering lobe with F = 1")
_MU = factor(1.0, "mu_v = N.V, cosine of the view angle")
_R = factor(0.5, "Blender roughness r (GGX alpha = r^2)")


# Turquin 2019, eq. 16: f_ss scaled by 1 + F0 (1 - E) / E (per channel).
def _turquin(**kw):
    return {"Scale": per_channel(multiscatter.turquin_compensation, kw["F0"], kw["E"])}


# The talk's approximation to Fdez-Aguera 2019 under area lights: 1 + F_avg (1 - E)/(1 - F_avg (1 - E)).
def _fdez_area(**kw):
    return {"Scale": per_channel(multiscatter.fdez_aguera_area_scale, kw["F0"], kw["E"])}


def _split_sum_lut():
    from ..core.lut import lookup

    tables = lookup.default_energy_tables()
    return op.Lut("ggx_split_sum", tables.tables["ggx_split_sum"])


# Fdez-Aguera 2019, eq. 11-16, with Karis 2013's split-sum table (scale, bias) at (mu_v, r).
def _fdez_env(**kw):
    u, v = energy_lut_uv(op.saturate(kw["N.V"]), op.saturate(kw["Roughness"]), lut_catalog.ENERGY_SIZE)
    lut = _split_sum_lut()
    scale, bias = op.lut_sample(lut, u, v, 0), op.lut_sample(lut, u, v, 1)
    fss = per_channel(lambda f0: multiscatter.fdez_aguera_terms(f0, scale, bias)[0], kw["F0"])
    fms = per_channel(lambda f0: multiscatter.fdez_aguera_terms(f0, scale, bias)[1], kw["F0"])
    return {"FssEss": fss, "FmsEms": fms}


def _window(**kw):
    return {"Falloff": falloff.window_falloff(kw["Distance"], kw["Radius"])}


def _inverse_square(**kw):
    return {"Falloff": falloff.inverse_square_falloff(kw["Distance"])}


def _cone(**kw):
    return {"Falloff": falloff.cone_falloff(kw["Cos To Axis"], kw["Inner Angle"], kw["Outer Angle"])}


def _projector(**kw):
    return {"Distance": falloff.projector_distance(kw["Diameter"], kw["Outer Angle"])}


_SCALE_OUT = {"Scale": color((1.0, 1.0, 1.0), "Multiplies the single-scattering specular")}
_FALLOFF_OUT = {"Falloff": factor(1.0, "Light attenuation factor")}
_DIST = scalar(1.0, "Distance from the light to the shading point (m)", 0.0, None, "DISTANCE")
_ANGLE = {"Inner Angle": scalar(0.6, "Inner full cone angle (rad)", 0.0, 3.14159, "ANGLE"),
          "Outer Angle": scalar(0.8, "Outer full cone angle (rad)", 0.0, 3.14159, "ANGLE")}

TECHNIQUES = (
    NodeFunction("RTL Turquin Compensation", _turquin, {"F0": _F0, "E": _E}, _SCALE_OUT,
                 "Turquin 2019 multiple-scattering compensation of the specular lobe (view-dependent)"),
    NodeFunction("RTL Fdez-Aguera Area Scale", _fdez_area, {"F0": _F0, "E": _E}, _SCALE_OUT,
                 "The talk's approximation to Fdez-Aguera's multiple scattering under area lights"),
    NodeFunction("RTL Fdez-Aguera Environment BRDF", _fdez_env, {"F0": _F0, "N.V": _MU, "Roughness": _R},
                 {"FssEss": color((0.0, 0.0, 0.0), "Single-scattered energy: times prefiltered radiance"),
                  "FmsEms": color((0.0, 0.0, 0.0), "Multiply-scattered energy: times irradiance")},
                 "Fdez-Aguera 2019 multiple-scattering split-sum environment BRDF"),
    NodeFunction("RTL Window Falloff", _window,
                 {"Distance": _DIST, "Radius": scalar(10.0, "Light radius of influence (m)", 0.0, None, "DISTANCE")},
                 _FALLOFF_OUT, "Karis 2013 windowing saturate(1 - (d/r)^4)^2"),
    NodeFunction("RTL Inverse Square Falloff", _inverse_square, {"Distance": _DIST},
                 {"Falloff": scalar(1.0, "1 / max(d^2, 1 cm^2)")}, "Inverse-square law clamped at 1 cm"),
    NodeFunction("RTL Cone Falloff", _cone,
                 {"Cos To Axis": factor(1.0, "Cosine of the angle between the spot axis and the point"), **_ANGLE},
                 _FALLOFF_OUT, "The talk's spot cone falloff between the inner and outer angles"),
    NodeFunction("RTL Projector Distance", _projector,
                 {"Diameter": scalar(1.0, "Light diameter (m)", 0.0, None, "DISTANCE"),
                  "Outer Angle": _ANGLE["Outer Angle"]},
                 {"Distance": scalar(1.0, "Apex distance behind the quad light (m)")},
                 "The talk's quad-to-spot fallback: distance of the spot apex behind the light"),
)


@functools.lru_cache(maxsize=1)
def all_functions():
    """Every offered node function, in Add > Group order (names start with "RTL ")."""
    from ..core import lights
    from ..core.ltc import disk, polygon

    out = [rt_lit.SURFACE]
    out += list(TECHNIQUES)
    out += list(lobes.PUNCTUAL_LOBES.values())
    out += list(lobes.area_lobes("quad").values()) + list(lobes.area_lobes("disk").values())
    out += [polygon.LTC_QUAD_INTEGRAL, disk.LTC_DISK_INTEGRAL]
    out += list(lights.NODE_FUNCTIONS)
    return tuple(out)
