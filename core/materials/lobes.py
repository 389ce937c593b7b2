"""The lobes of the RT Lit material: each lobe one unit with its punctual and its area form.

Every lobe returns scalars per unit incident light, with the cosine included, so the caller only
multiplies by colours:
- specular: ``Scale``, ``Bias`` (radiance = F0 * Scale + F90 * Bias, F90 = 1, the form of Karis
  2013's split sum and of Hill 2016's LTC Fresnel split) and ``E``, the lobe's directional albedo
  with F = 1 for the multiscattering scales;
- Kulla-Conty: ``Lobe`` (f_ms times the cosine, no Fresnel) and ``One Minus E Avg``;
- diffuse, cloth and sheen: one value each (albedo, colour and weight are applied outside).

A ``Lobe`` keeps together what pbrt keeps together for a BxDF: its outputs, its punctual form (the
BRDF times the cosine at one light direction ``L``: point, spot and sun lights) and its area form
(the BRDF integrated over a quad or a disk with the LTC tables, ``core/ltc/shading.py``).
``Lobe.function(kind)`` is the node function for one light kind: "RTL Punctual GGX",
"RTL Quad GGX", "RTL Disk CoD Diffuse", ...  Bodies read tables through the table set they are
given (``core.lut.lookup.LutSet``; ``REFERENCES`` when traced).
"""
from __future__ import annotations

import functools
from dataclasses import dataclass, field

import numpy as np

from .. import cloth, diffuse, lights, microfacet, multiscatter, rough_diffuse, sheen
from .. import shading_ops as op
from ..conventions import alpha_from_roughness
from ..ir.functions import NodeFunction
from ..ir.interface import Socket, factor, scalar, vector
from ..lut.lookup import REFERENCES
from ..ltc import shading

#: The shading forms over a light (core/lights.py ``SHADING_FORMS``: sphere lights and suns with an angle are disks).
AREA_KINDS = ("quad", "disk")
#: The kinds shaded at one direction (quad_spot: the talk's quad-to-spot fallback, shaded as a spot light).
PUNCTUAL_KINDS = tuple(k for k, form in lights.SHADING_FORMS.items() if form == "punctual")

_N = vector("Shading normal, unit, world space", "NONE", hide_value=True)
_V = vector("Unit direction towards the viewer", "NONE", hide_value=True)
_L = vector("Unit direction towards the light", "NONE", hide_value=True)
_P = vector("Shading point, world space", "NONE", hide_value=True)
_PARAMETERS = {"Roughness": factor(0.5, "Blender roughness r"), "Wrap": factor(0.0, "Wrapped-diffuse amount w")}
_PARAMETERS["Diffuse Roughness"] = factor(0.0, "Diffuse roughness sigma (Principled's Diffuse Roughness)")
_PARAMETERS["Sheen Roughness"] = factor(0.5, "Sheen roughness (Principled's), clamped to [1e-3, 1] as Cycles")
_OUT = Socket("float", 0.0, description="Per unit incident irradiance, cosine included")
_SPEC_OUT = {
    "Scale": Socket("float", 0.0, description="Multiplies F0 (Schlick, F90 = 1)"),
    "Bias": Socket("float", 0.0, description="Multiplies F90 = 1"),
    "E": Socket("float", 1.0, description="Directional albedo of the lobe with F = 1, E(mu_v)"),
}
_KC_OUT = {"Lobe": _OUT, "One Minus E Avg": scalar(0.0, "1 - E_avg(r)")}


@dataclass(frozen=True)
class Lobe:
    """One lobe: ``punctual(tables, N, V, L, **parameters)`` and ``area(tables, light, Position, N, V,
    **parameters)`` (``light`` a ``core.ltc.shading`` QuadLight / DiskLight) return its outputs."""
    key: str
    title: str
    parameters: tuple                   # of "Roughness", "Wrap"
    outputs: dict
    punctual: object
    area: object
    punctual_text: str
    area_text: str
    reads_tables_punctual: bool = field(default=False)

    def function(self, kind, exact_horizon=False):
        """The node function of this lobe for a light kind (cached; one for all punctual kinds; a kind's options
        change the light's data, not its lobes); ``exact_horizon``: area lights clipped at the horizon, else the
        sphere table (``Features.horizon``)."""
        form = lights.shading_form(kind)
        spread = form != "punctual" and "spread" in lights.split_kind(kind)[1]
        return _lobe_function(self.key, lights.kind_name(form, ("spread",) if spread else ()),
                              bool(exact_horizon) or form == "punctual")


def punctual_cosines(n, v, l):
    """(mu_l, mu_v, n.h, v.h) for unit N, V, L; h = normalize(L + V) (zero when L = -V)."""
    h = op.normalize(l + v)
    return op.dot(n, l), op.dot(n, v), op.dot(n, h), op.saturate(op.dot(v, h))


# --- GGX specular -----------------------------------------------------------------------------------
# Punctual: Cook-Torrance GGX (core/microfacet.py) split as F0 * Scale + Bias: Scale = D V (1 - Fc) mu_l,
# Bias = D V Fc mu_l with Fc = (1 - v.h)^5 (Schlick 1994).
# Area: Heitz et al. 2016 with Hill 2016's Fresnel split (core/ltc/shading.py): the GGX LTC integral I,
# magnitude m and Fresnel part f give F0 * I (m - f) + I f; E = m (the talk's "E = LTC magnitude").

def _ggx_punctual(tables, N, V, L, Roughness):
    mu_l, mu_v, n_dot_h, v_dot_h = punctual_cosines(N, V, L)
    alpha = alpha_from_roughness(Roughness)
    full = microfacet.ggx_brdf(mu_l, mu_v, n_dot_h, v_dot_h, alpha, 1.0) * mu_l
    bias = microfacet.ggx_brdf(mu_l, mu_v, n_dot_h, v_dot_h, alpha, 0.0) * mu_l
    return {"Scale": full - bias, "Bias": bias, "E": 1.0 - tables.one_minus_e(op.saturate(mu_v), Roughness)}


def _ggx_area(tables, light, Position, N, V, Roughness):
    value, magnitude, fresnel = shading.lobe_integral(tables, "ltc_ggx", light, Position, N, V, Roughness)
    return {"Scale": value * (magnitude - fresnel), "Bias": value * fresnel, "E": magnitude}


GGX = Lobe("ggx", "GGX", ("Roughness",), _SPEC_OUT, _ggx_punctual, _ggx_area,
           "GGX specular at one light direction, as F0 * Scale + Bias",
           "GGX specular over the light (LTC), as F0 * Scale + Bias", reads_tables_punctual=True)


# --- Kulla-Conty multiple scattering ----------------------------------------------------------------
# Kulla & Conty 2017 (core/multiscatter.py): f_ms mu_l with the tables' 1 - E and 1 - E_avg.
# Under an area light f_ms = (1 - E(mu_o))(1 - E(mu_i)) / (pi (1 - E_avg)) is smooth and diffuse-like,
# so its integral over the light is approximated by the clamped-cosine form factor (the exact Lambert
# LTC) times (1 - E(mu_i)) at the light's centre direction.  The approximation is this project's (not the
# talk's, which uses Turquin / Fdez-Aguera under area lights); the validation measures it.

def _kulla_conty_punctual(tables, N, V, L, Roughness):
    mu_l, mu_v, _, _ = punctual_cosines(N, V, L)
    om_avg = tables.one_minus_e_avg(Roughness)
    lobe = multiscatter.kulla_conty_lobe(tables.one_minus_e(op.saturate(mu_v), Roughness),
                                         tables.one_minus_e(op.saturate(mu_l), Roughness), om_avg)
    above = op.logical_and(op.greater(mu_l, 0.0), op.greater(mu_v, 0.0))
    return {"Lobe": op.select(above, lobe * mu_l, 0.0), "One Minus E Avg": om_avg}


# Over a light, int_light f_ms mu_i dw = (1 - E(mu_v)) / (pi (1 - E_avg)) int_light (1 - E(mu_i)) mu_i dw.  The
# integral is taken as pi x (the Lambert form factor) x (1 - E) towards the light's centre, and bounded by its
# value over the whole hemisphere, pi (1 - E_avg): without the bound a light whose centre sits near the horizon
# of a near-mirror surface (1 - E(mu_c) ~ 1 while 1 - E_avg ~ 1e-5) gave a lobe ~20x the light's radiance, far
# above the lobe's own albedo 1 - E(mu_v) (docs/robustness.md).  With it the lobe never exceeds 1 - E(mu_v).
def _kulla_conty_area(tables, light, Position, N, V, Roughness):
    form_factor = shading.lambert(tables, light, Position, N, V, 1.0)
    to_center = op.normalize(shading.light_center(light) - Position)
    mu_c = op.saturate(op.dot(N, to_center))
    mu_v = op.saturate(op.dot(N, V))
    om_avg = tables.one_minus_e_avg(Roughness)
    over_light = op.minimum(form_factor * tables.one_minus_e(mu_c, Roughness), om_avg)
    lobe = multiscatter.kulla_conty_lobe(tables.one_minus_e(mu_v, Roughness), over_light, om_avg) * np.pi
    return {"Lobe": op.select(op.greater(mu_v, 0.0), lobe, 0.0), "One Minus E Avg": om_avg}


KULLA_CONTY = Lobe("kulla_conty", "Kulla-Conty", ("Roughness",), _KC_OUT, _kulla_conty_punctual, _kulla_conty_area,
                   "Kulla-Conty multiple-scattering lobe (times the cosine), without its Fresnel",
                   "Kulla-Conty lobe over the light: Lambert form factor x (1 - E) towards the light's centre, bounded by "
                   "the hemisphere's (1 - E_avg)",
                   reads_tables_punctual=True)


# --- Lambert ----------------------------------------------------------------------------------------
# max(N.L, 0) / pi; over an area light the identity LTC's form factor (Heitz et al. 2016, sec. 5), exact above the
# horizon and, with an exact horizon (``Features.horizon``), where the light crosses it (``shading.lambert``).

def _lambert_punctual(tables, N, V, L):
    mu_l = op.dot(N, L)
    return {"Diffuse": op.select(op.greater(op.dot(N, V), 0.0), op.maximum(mu_l, 0.0) / np.pi, 0.0)}


def _lambert_area(tables, light, Position, N, V):
    return {"Diffuse": shading.lambert(tables, light, Position, N, V, 1.0)}


LAMBERT = Lobe("lambert", "Lambert", (), {"Diffuse": _OUT}, _lambert_punctual, _lambert_area,
               "Lambert: max(N.L, 0) / pi", "Lambert form factor / albedo 1 (identity LTC)")


# --- CoD WWII multiscattering diffuse (Chan 2018; the talk) ------------------------------------------

def _cod_punctual(tables, N, V, L, Roughness):
    mu_l, mu_v, n_dot_h, v_dot_h = punctual_cosines(N, V, L)
    f = diffuse.cod_multiscatter_diffuse(1.0, mu_l, mu_v, n_dot_h, v_dot_h, alpha_from_roughness(Roughness))
    return {"Diffuse": f * op.maximum(mu_l, 0.0)}


def _cod_area(tables, light, Position, N, V, Roughness):
    return {"Diffuse": shading.cod_diffuse(tables, light, Position, N, V, Roughness, 1.0)}


COD = Lobe("cod", "CoD Diffuse", ("Roughness",), {"Diffuse": _OUT}, _cod_punctual, _cod_area,
           "Call of Duty WWII multiscattering diffuse (albedo 1) times the cosine",
           "CoD WWII multiscattering diffuse (its LTC)")


# --- wrapped diffuse (the talk: normalised wrap; under area lights the tilted normal) -----------------

def _wrapped_punctual(tables, N, V, L, Wrap):
    mu_l = op.dot(N, L)
    return {"Diffuse": op.select(op.greater(op.dot(N, V), 0.0), diffuse.wrapped_diffuse_cosine(mu_l, Wrap), 0.0)}


def _wrapped_area(tables, light, Position, N, V, Wrap):
    return {"Diffuse": shading.wrapped_diffuse(tables, light, Position, N, V, 1.0, Wrap)}


WRAPPED = Lobe("wrapped", "Wrapped Diffuse", ("Wrap",), {"Diffuse": _OUT}, _wrapped_punctual, _wrapped_area,
               "Normalised wrapped diffuse (cos + w)/(pi (1 + w)^2)",
               "Wrapped diffuse: clamped cosine about the tilted normal, / (1 + w) (the talk)")


# --- multiscattering wrapped diffuse (the talk's closing table: CoD diffuse with wrapped lighting) ----------
# Punctual: the CoD lobe at the wrapped light direction (core/diffuse.py: its definition and properties).  Area:
# the talk's tilted normal (WrappedNormal towards the light's centre) with the CoD LTC integrated about it, / (1 + w).

def _cod_wrapped_punctual(tables, N, V, L, Roughness, Wrap):
    return {"Diffuse": diffuse.cod_wrapped_diffuse_cosine(1.0, N, V, L, alpha_from_roughness(Roughness), Wrap)}


def _cod_wrapped_area(tables, light, Position, N, V, Roughness, Wrap):
    return {"Diffuse": shading.cod_wrapped_diffuse(tables, light, Position, N, V, Roughness, 1.0, Wrap)}


COD_WRAPPED = Lobe("cod_wrapped", "CoD Wrapped Diffuse", ("Roughness", "Wrap"), {"Diffuse": _OUT},
                   _cod_wrapped_punctual, _cod_wrapped_area,
                   "CoD WWII multiscattering diffuse (albedo 1) at the wrapped light direction, / (1 + w)",
                   "CoD WWII diffuse LTC about the normal tilted towards the light (the talk), / (1 + w)")


# --- Ashikhmin cloth with Neubelt-Pettineo visibility -------------------------------------------------

def _cloth_punctual(tables, N, V, L, Roughness):
    mu_l, mu_v, n_dot_h, _ = punctual_cosines(N, V, L)
    f = cloth.ashikhmin_cloth_brdf(mu_l, mu_v, n_dot_h, alpha_from_roughness(Roughness))
    return {"Cloth": f * op.maximum(mu_l, 0.0)}


def _cloth_area(tables, light, Position, N, V, Roughness):
    return {"Cloth": shading.ashikhmin_cloth(tables, light, Position, N, V, Roughness, 1.0)}


CLOTH = Lobe("cloth", "Cloth", ("Roughness",), {"Cloth": _OUT}, _cloth_punctual, _cloth_area,
             "Ashikhmin velvet D with Neubelt's visibility, times the cosine", "Ashikhmin cloth (its LTC)")


# --- Disney sheen (Burley 2012; under area lights the talk's CoD table at r = 0.5) --------------------

def _sheen_punctual(tables, N, V, L):
    mu_l, mu_v, _, v_dot_h = punctual_cosines(N, V, L)
    above = op.logical_and(op.greater(mu_l, 0.0), op.greater(mu_v, 0.0))
    return {"Sheen": op.select(above, cloth.disney_sheen(v_dot_h) * mu_l, 0.0)}


def _sheen_area(tables, light, Position, N, V):
    return {"Sheen": shading.disney_sheen(tables, light, Position, N, V, 1.0)}


SHEEN = Lobe("sheen", "Sheen", (), {"Sheen": _OUT}, _sheen_punctual, _sheen_area,
             "Disney sheen (1 - l.h)^5 times the cosine", "Disney sheen via the CoD table at r = 0.5 (the talk)")


# --- Zeltner 2022 sheen (Blender's Principled sheen; core/sheen.py) ----------------------------------
# Punctual: the LTC's density at L times the albedo, exactly Cycles' closure.  Area: the same LTC's integral
# over the light (core/ltc/shading.zeltner_sheen).  Both return the albedo R(mu_v) too, for the layering of
# the lobes below the sheen (Principled: their weight times 1 - max(sheen colour) R).

_ZELTNER_OUT = {"Sheen": _OUT, "Sheen Albedo": scalar(0.0, "Directional albedo R(mu_v) of the sheen lobe")}


def _zeltner_punctual(tables, N, V, L, **kw):
    t1, t2, n = shading.polygon.local_frame(N, V)
    a, b, albedo = tables.zeltner_sheen(op.saturate(op.dot(N, V)), sheen.zeltner_roughness(kw["Sheen Roughness"]))
    keep = op.logical_and(sheen.zeltner_active(a, albedo), op.greater(op.dot(N, V), 0.0))
    value = sheen.zeltner_density(op.dot(L, t1), op.dot(L, t2), op.dot(L, n), a, b) * albedo
    return {"Sheen": op.select(keep, value, 0.0), "Sheen Albedo": op.select(keep, albedo, 0.0)}


def _zeltner_area(tables, light, Position, N, V, **kw):
    value, albedo = shading.zeltner_sheen(tables, light, Position, N, V, kw["Sheen Roughness"])
    return {"Sheen": value, "Sheen Albedo": albedo}


ZELTNER = Lobe("zeltner", "Zeltner Sheen", ("Sheen Roughness",), _ZELTNER_OUT, _zeltner_punctual, _zeltner_area,
               "Zeltner 2022 sheen (Cycles' Principled sheen): its LTC density times the albedo",
               "Zeltner 2022 sheen over the light: its own LTC's integral times the albedo",
               reads_tables_punctual=True)


# --- Disney sheen with its own fitted LTC (core/ltc/fit_lobes.py "disney_sheen") ----------------------
# Punctual: Burley 2012's (1 - l.h)^5 times the cosine, as SHEEN; area: the fitted table's LTC integral times its
# magnitude (the lobe has no roughness: the table's columns are one fit).

def _disney_fitted_area(tables, light, Position, N, V):
    return {"Sheen": shading.disney_sheen_fitted(tables, light, Position, N, V, 1.0)}


DISNEY_FITTED = Lobe("disney_fitted", "Disney Sheen Fitted", (), {"Sheen": _OUT}, _sheen_punctual,
                     _disney_fitted_area, "Disney sheen (1 - l.h)^5 times the cosine",
                     "Disney sheen over the light with its own fitted LTC")


# --- rough diffuse as Cycles: Fujii's improved Oren-Nayar + EON's multiple scattering (core/rough_diffuse.py) ---
# "Diffuse" is the single-scattering part with albedo 1, "Diffuse MS" the multiple-scattering lobe with colour 1,
# (1 - E_F(mu_v)) ms_kernel(mu_l); light_shading.combine_lobes applies the albedo and rough_diffuse.multiscatter_color.
# Punctual: both exact (the BRDF times the cosine).
# Area: the single scattering through its fitted LTC (table ltc_oren_nayar, u = diffuse roughness; Heitz et al.
# 2016) times its directional albedo E_F(mu_v) in closed form (EON); the multiple scattering as (1 - E_F(mu_v))
# times the integral of ms_kernel over the light, taken as the Lambert form factor (the exact identity LTC) x the
# kernel's ratio to the cosine towards the light's centre, bounded by the kernel's hemisphere integral 1 (as the
# Kulla-Conty lobe above).  Measured against Cycles (docs/rough_diffuse.md): median 1.3-1.4% instead of 1.8-2.4%
# at sigma = 1 with a fixed LTC fitted to the kernel (rough_diffuse.MS_KERNEL_LTC), p90 and max no worse.

def _oren_nayar_punctual(tables, N, V, L, **kw):
    r = kw["Diffuse Roughness"]
    mu_l, mu_v = op.dot(N, L), op.dot(N, V)
    return {"Diffuse": rough_diffuse.fon_single_scatter_cos(mu_l, mu_v, op.dot(L, V), r),
            "Diffuse MS": rough_diffuse.multiscatter_cos(mu_l, mu_v, r)}


FON_VIEW_ALBEDO = NodeFunction(
    "RTL FON View Albedo",
    lambda **kw: {"Albedo": rough_diffuse.fon_albedo(kw["Mu"], kw["Roughness"]),
                  "One Minus Albedo": rough_diffuse.fon_one_minus_albedo(kw["Mu"], kw["Roughness"])},
    {"Mu": scalar(0.0, "N.V"), "Roughness": factor(0.0, "Diffuse roughness sigma")},
    {"Albedo": scalar(0.0, "E_F(mu, r): the single scattering's directional albedo"),
     "One Minus Albedo": scalar(0.0, "1 - E_F(mu, r), without cancellation")},
    "The directional albedo of Fujii's improved Oren-Nayar and its complement (EON; core/rough_diffuse.py): a group "
    "of its own, so that the rough diffuse lobe under an area light with spread stays a small group")


def _oren_nayar_area(tables, light, Position, N, V, **kw):
    r = kw["Diffuse Roughness"]
    value, _, _ = shading.lobe_integral(tables, "ltc_oren_nayar", light, Position, N, V, r)
    mu_v = op.dot(N, V)
    form_factor = shading.lambert(tables, light, Position, N, V, 1.0)
    mu_c = op.saturate(op.dot(N, op.normalize(shading.light_center(light) - Position)))
    kernel = op.minimum(form_factor * rough_diffuse.ms_kernel_over_cosine(mu_c), 1.0)
    above = op.greater(mu_v, 0.0)
    albedo = FON_VIEW_ALBEDO(Mu=mu_v, Roughness=r)
    return {"Diffuse": op.select(above, value * albedo["Albedo"], 0.0),
            "Diffuse MS": op.select(above, kernel * albedo["One Minus Albedo"], 0.0)}


_OREN_NAYAR_OUT = {"Diffuse": _OUT,
                   "Diffuse MS": Socket("float", 0.0, description="Multiple-scattering lobe (colour 1), cosine included")}
OREN_NAYAR = Lobe("oren_nayar", "Oren-Nayar", ("Diffuse Roughness",), _OREN_NAYAR_OUT, _oren_nayar_punctual,
                  _oren_nayar_area,
                  "Rough diffuse as Cycles: Fujii's improved Oren-Nayar (albedo 1) and EON's multiple scattering, "
                  "times the cosine",
                  "Rough diffuse as Cycles over the light: its LTC x E_F(mu_v), multiple scattering by the Lambert form "
                  "factor x its kernel towards the light's centre")


#: Every lobe, by key, in Add > Group order.
LOBES = {lobe.key: lobe for lobe in (GGX, KULLA_CONTY, LAMBERT, COD, WRAPPED, COD_WRAPPED, CLOTH, SHEEN)}
LOBES[OREN_NAYAR.key] = OREN_NAYAR
LOBES.update({lobe.key: lobe for lobe in (ZELTNER, DISNEY_FITTED)})


# --- node functions -----------------------------------------------------------------------------------

def _area_light(kind, kw, exact_horizon):
    """The ``core.ltc.shading`` light of an area kind ("quad", "disk", with or without "+spread") from its data."""
    base, options = lights.split_kind(kind)
    spread = lights.spread_cone_of(kw) if "spread" in options else None
    if base == "quad":
        return shading.QuadLight([kw["p0"], kw["p1"], kw["p2"], kw["p3"]], center_point=kw["Center"],
                                 exact_horizon=exact_horizon, spread=spread)
    return shading.DiskLight(kw["Center"], kw["Axis U"], kw["Axis V"], exact_horizon=exact_horizon, spread=spread)


def light_geometry_sockets(kind):
    """The geometry outputs of the light's data function (all but its radiance or irradiance; a light with spread:
    its cone, ``lights.SPREAD_OUTPUTS``)."""
    data = lights.light_data(kind)
    return {n: s for n, s in data.output_sockets.items() if n not in ("Radiance", "Irradiance")}


@functools.lru_cache(maxsize=None)
def _lobe_function(key, kind, exact_horizon):
    lobe = LOBES[key]
    params = {p: _PARAMETERS[p] for p in lobe.parameters}
    if kind == "punctual":
        body = lobe.punctual if lobe.reads_tables_punctual else functools.partial(lobe.punctual, None)
        return NodeFunction(f"RTL Punctual {lobe.title}", body, dict({"N": _N, "V": _V, "L": _L}, **params),
                            lobe.outputs, lobe.punctual_text, tables=REFERENCES if lobe.reads_tables_punctual else None)
    base, options = lights.split_kind(kind)
    if base not in AREA_KINDS or set(options) - {"spread"}:
        raise ValueError(f"unknown light kind {kind!r}")
    geometry = light_geometry_sockets(kind)

    def body(tables, **kw):
        args = {p: kw[p] for p in lobe.parameters}
        return lobe.area(tables, _area_light(kind, kw, exact_horizon), kw["Position"], kw["N"], kw["V"], **args)

    inputs = dict({"Position": _P, "N": _N, "V": _V}, **geometry, **params)
    suffix = "" if exact_horizon else " (Sphere Table Horizon)"
    spread = " Spread" if options else ""
    return NodeFunction(f"RTL {base.capitalize()}{spread} {lobe.title}{suffix}", body, inputs, lobe.outputs,
                        lobe.area_text + ("" if exact_horizon else "; the sphere table's horizon (the talk's)")
                        + ("; each integral weighted by the spread's weight under its lobe" if options else ""),
                        tables=REFERENCES)


def lobe_functions(kind):
    """Lobe key -> NodeFunction for an RT Lit light kind."""
    return {key: lobe.function(kind) for key, lobe in LOBES.items()}
