"""The lobes of the RT Lit material, one node function per (light category, lobe).

Every lobe returns scalars per unit incident light, with the cosine included, so the caller
only multiplies by colours:
- specular: ``Scale``, ``Bias`` (radiance = F0 * Scale + F90 * Bias, F90 = 1, the form of
  Karis 2013's split sum and of Hill 2016's LTC Fresnel split) and ``E``, the lobe's
  directional albedo with F = 1 for the multiscattering scales;
- Kulla-Conty: ``Lobe`` (f_ms times the cosine, no Fresnel) and ``One Minus E Avg``;
- diffuse, cloth and sheen: one value each (albedo, colour and weight are applied outside).

Punctual lobes (point, spot, sun) evaluate the BRDF at the light direction ``L``; area lobes
integrate it over a quad or a disk with the LTC tables (core/ltc/shading.py).
"""
from __future__ import annotations

import functools

import numpy as np

from .. import cloth, diffuse, microfacet, multiscatter
from .. import shading_ops as op
from ..conventions import alpha_from_roughness
from ..ir.functions import NodeFunction
from ..ir.interface import Socket, factor, scalar, vector
from ..lut import catalog
from ..lut.lookup import energy_lut_uv, lut_coordinate

# --- energy tables as traceable lookups -----------------------------------------------------


def energy_lut(name):
    """The named energy table of the active LUT folder, from ``lookup.default_energy_tables``
    (loaded once; ``lookup.use_lut_dir`` switches the folder)."""
    from ..lut import lookup

    return op.Lut(name, lookup.default_energy_tables().tables[name])


def one_minus_e(mu, roughness):
    """1 - E(mu, r) of single-scattering GGX with F = 1 (table ggx_one_minus_E, channel R)."""
    u, v = energy_lut_uv(mu, roughness)
    return op.lut_sample(energy_lut("ggx_one_minus_E"), u, v, 0)


def one_minus_e_avg(roughness):
    """1 - E_avg(r) (table ggx_one_minus_E_avg)."""
    u = lut_coordinate(roughness, catalog.ENERGY_SIZE)
    return op.lut_sample(energy_lut("ggx_one_minus_E_avg"), u, 0.5 + 0.0 * u, 0)


# --- punctual geometry ------------------------------------------------------------------------

def punctual_cosines(n, v, l):
    """(mu_l, mu_v, n.h, v.h) for unit N, V, L; h = normalize(L + V) (zero when L = -V)."""
    h = op.normalize(l + v)
    return op.dot(n, l), op.dot(n, v), op.dot(n, h), op.saturate(op.dot(v, h))


_N = vector("Shading normal, unit, world space", "NONE", hide_value=True)
_V = vector("Unit direction towards the viewer", "NONE", hide_value=True)
_L = vector("Unit direction towards the light", "NONE", hide_value=True)
_R = factor(0.5, "Blender roughness r")
_WRAP = factor(0.0, "Wrapped-diffuse amount w")
_OUT = Socket("float", 0.0, description="Per unit incident irradiance, cosine included")
_SPEC_OUT = {
    "Scale": Socket("float", 0.0, description="Multiplies F0 (Schlick, F90 = 1)"),
    "Bias": Socket("float", 0.0, description="Multiplies F90 = 1"),
    "E": Socket("float", 1.0, description="Directional albedo of the lobe with F = 1, E(mu_v)"),
}


# Cook-Torrance GGX (core/microfacet.py) split as F0 * Scale + Bias: Scale = D V (1 - Fc) mu_l,
# Bias = D V Fc mu_l with Fc = (1 - v.h)^5 (Schlick 1994).
def _punctual_ggx(N, V, L, Roughness):
    mu_l, mu_v, n_dot_h, v_dot_h = punctual_cosines(N, V, L)
    alpha = alpha_from_roughness(Roughness)
    full = microfacet.ggx_brdf(mu_l, mu_v, n_dot_h, v_dot_h, alpha, 1.0) * mu_l
    bias = microfacet.ggx_brdf(mu_l, mu_v, n_dot_h, v_dot_h, alpha, 0.0) * mu_l
    return {"Scale": full - bias, "Bias": bias, "E": 1.0 - one_minus_e(op.saturate(mu_v), Roughness)}


# Kulla & Conty 2017 (core/multiscatter.py): f_ms mu_l with the tables' 1 - E and 1 - E_avg.
def _punctual_kulla_conty(N, V, L, Roughness):
    mu_l, mu_v, _, _ = punctual_cosines(N, V, L)
    om_avg = one_minus_e_avg(Roughness)
    lobe = multiscatter.kulla_conty_lobe(one_minus_e(op.saturate(mu_v), Roughness),
                                         one_minus_e(op.saturate(mu_l), Roughness), om_avg)
    above = op.logical_and(op.greater(mu_l, 0.0), op.greater(mu_v, 0.0))
    return {"Lobe": op.select(above, lobe * mu_l, 0.0), "One Minus E Avg": om_avg}


def _punctual_lambert(N, V, L):
    mu_l = op.dot(N, L)
    return {"Diffuse": op.select(op.greater(op.dot(N, V), 0.0), op.maximum(mu_l, 0.0) / np.pi, 0.0)}


def _punctual_cod(N, V, L, Roughness):
    mu_l, mu_v, n_dot_h, v_dot_h = punctual_cosines(N, V, L)
    f = diffuse.cod_multiscatter_diffuse(1.0, mu_l, mu_v, n_dot_h, v_dot_h, alpha_from_roughness(Roughness))
    return {"Diffuse": f * op.maximum(mu_l, 0.0)}


def _punctual_wrapped(N, V, L, Wrap):
    mu_l = op.dot(N, L)
    return {"Diffuse": op.select(op.greater(op.dot(N, V), 0.0), diffuse.wrapped_diffuse_cosine(mu_l, Wrap), 0.0)}


def _punctual_cloth(N, V, L, Roughness):
    mu_l, mu_v, n_dot_h, _ = punctual_cosines(N, V, L)
    f = cloth.ashikhmin_cloth_brdf(mu_l, mu_v, n_dot_h, alpha_from_roughness(Roughness))
    return {"Cloth": f * op.maximum(mu_l, 0.0)}


def _punctual_sheen(N, V, L):
    mu_l, mu_v, _, v_dot_h = punctual_cosines(N, V, L)
    above = op.logical_and(op.greater(mu_l, 0.0), op.greater(mu_v, 0.0))
    return {"Sheen": op.select(above, cloth.disney_sheen(v_dot_h) * mu_l, 0.0)}


_NVL = {"N": _N, "V": _V, "L": _L}
PUNCTUAL_LOBES = {
    "ggx": NodeFunction("RTL Punctual GGX", _punctual_ggx, dict(_NVL, Roughness=_R), _SPEC_OUT,
                        "GGX specular at one light direction, as F0 * Scale + Bias"),
    "kulla_conty": NodeFunction("RTL Punctual Kulla-Conty", _punctual_kulla_conty, dict(_NVL, Roughness=_R),
                                {"Lobe": _OUT, "One Minus E Avg": scalar(0.0, "1 - E_avg(r)")},
                                "Kulla-Conty multiple-scattering lobe (times the cosine), without its Fresnel"),
    "lambert": NodeFunction("RTL Punctual Lambert", _punctual_lambert, _NVL, {"Diffuse": _OUT},
                            "Lambert: max(N.L, 0) / pi"),
    "cod": NodeFunction("RTL Punctual CoD Diffuse", _punctual_cod, dict(_NVL, Roughness=_R), {"Diffuse": _OUT},
                        "Call of Duty WWII multiscattering diffuse (albedo 1) times the cosine"),
    "wrapped": NodeFunction("RTL Punctual Wrapped Diffuse", _punctual_wrapped, dict(_NVL, Wrap=_WRAP),
                            {"Diffuse": _OUT}, "Normalised wrapped diffuse (cos + w)/(pi (1 + w)^2)"),
    "cloth": NodeFunction("RTL Punctual Cloth", _punctual_cloth, dict(_NVL, Roughness=_R), {"Cloth": _OUT},
                          "Ashikhmin velvet D with Neubelt's visibility, times the cosine"),
    "sheen": NodeFunction("RTL Punctual Sheen", _punctual_sheen, _NVL, {"Sheen": _OUT},
                          "Disney sheen (1 - l.h)^5 times the cosine"),
}


# --- area lobes (LTC) ------------------------------------------------------------------------------

def _tables():
    from ..lut import lookup

    return lookup.default_ltc_tables()


def _area_light(kind, kw):
    from ..ltc import shading

    if kind == "quad":
        return shading.QuadLight([kw["p0"], kw["p1"], kw["p2"], kw["p3"]])
    return shading.DiskLight(kw["Center"], kw["Axis U"], kw["Axis V"])


def _light_center(kind, kw):
    if kind == "quad":
        return op.scale(kw["p0"] + kw["p1"] + kw["p2"] + kw["p3"], 0.25)
    return kw["Center"]


# Heitz et al. 2016 with Hill 2016's Fresnel split (core/ltc/shading.py): the GGX LTC integral I,
# magnitude m and Fresnel part f give F0 * I (m - f) + I f; E = m (the talk's "E = LTC magnitude").
def _area_ggx(kind):
    def fn(**kw):
        from ..ltc import shading

        value, magnitude, fresnel = shading.lobe_integral(_tables(), "ltc_ggx", _area_light(kind, kw), kw["Position"],
                                                          kw["N"], kw["V"], kw["Roughness"])
        return {"Scale": value * (magnitude - fresnel), "Bias": value * fresnel, "E": magnitude}
    return fn


def _area_cod(kind):
    def fn(**kw):
        from ..ltc import shading

        return {"Diffuse": shading.cod_diffuse(_tables(), _area_light(kind, kw), kw["Position"], kw["N"], kw["V"],
                                               kw["Roughness"], 1.0)}
    return fn


def _area_lambert(kind):
    def fn(**kw):
        from ..ltc import shading

        return {"Diffuse": shading.lambert(_tables(), _area_light(kind, kw), kw["Position"], kw["N"], kw["V"], 1.0)}
    return fn


def _area_wrapped(kind):
    def fn(**kw):
        from ..ltc import shading

        return {"Diffuse": shading.wrapped_diffuse(_tables(), _area_light(kind, kw), kw["Position"], kw["N"],
                                                   kw["V"], 1.0, kw["Wrap"])}
    return fn


def _area_cloth(kind):
    def fn(**kw):
        from ..ltc import shading

        return {"Cloth": shading.ashikhmin_cloth(_tables(), _area_light(kind, kw), kw["Position"], kw["N"], kw["V"],
                                                 kw["Roughness"], 1.0)}
    return fn


def _area_sheen(kind):
    def fn(**kw):
        from ..ltc import shading

        return {"Sheen": shading.disney_sheen(_tables(), _area_light(kind, kw), kw["Position"], kw["N"], kw["V"],
                                              1.0)}
    return fn


# Kulla & Conty 2017 under an area light.  f_ms = (1 - E(mu_o))(1 - E(mu_i)) / (pi (1 - E_avg)) is
# smooth and diffuse-like, so its integral over the light is approximated by the clamped-cosine
# form factor (the exact Lambert LTC) times (1 - E(mu_i)) at the light's centre direction.  The
# approximation is this project's (not the talk's, which uses Turquin / Fdez-Aguera under area
# lights); issue 5's validation measures it.
def _area_kulla_conty(kind):
    def fn(**kw):
        from ..ltc import shading

        form_factor = shading.lambert(_tables(), _area_light(kind, kw), kw["Position"], kw["N"], kw["V"], 1.0)
        to_center = op.normalize(_light_center(kind, kw) - kw["Position"])
        mu_c = op.saturate(op.dot(kw["N"], to_center))
        mu_v = op.saturate(op.dot(kw["N"], kw["V"]))
        om_avg = one_minus_e_avg(kw["Roughness"])
        lobe = multiscatter.kulla_conty_lobe(one_minus_e(mu_v, kw["Roughness"]), one_minus_e(mu_c, kw["Roughness"]),
                                             om_avg) * np.pi
        return {"Lobe": op.select(op.greater(mu_v, 0.0), lobe * form_factor, 0.0), "One Minus E Avg": om_avg}
    return fn


_P = vector("Shading point, world space", "NONE", hide_value=True)


def _geometry_sockets(kind):
    from .. import lights

    data = lights.LIGHT_DATA[kind]
    return {n: s for n, s in data.output_sockets.items() if n not in ("Radiance", "Irradiance")}


@functools.lru_cache(maxsize=None)
def area_lobes(kind):
    """Lobe functions for "quad" or "disk" lights, named "RTL Quad GGX", "RTL Disk CoD Diffuse", ..."""
    title = kind.capitalize()
    base = dict({"Position": _P, "N": _N, "V": _V}, **_geometry_sockets(kind))
    rough = dict(base, Roughness=_R)
    spec = [
        ("ggx", "GGX", _area_ggx, rough, _SPEC_OUT, "GGX specular over the light (LTC), as F0 * Scale + Bias"),
        ("kulla_conty", "Kulla-Conty", _area_kulla_conty, rough,
         {"Lobe": _OUT, "One Minus E Avg": scalar(0.0, "1 - E_avg(r)")},
         "Kulla-Conty lobe over the light: Lambert form factor x (1 - E) towards the light's centre"),
        ("lambert", "Lambert", _area_lambert, base, {"Diffuse": _OUT}, "Lambert form factor / albedo 1 (exact LTC)"),
        ("cod", "CoD Diffuse", _area_cod, rough, {"Diffuse": _OUT}, "CoD WWII multiscattering diffuse (its LTC)"),
        ("wrapped", "Wrapped Diffuse", _area_wrapped, dict(base, Wrap=_WRAP), {"Diffuse": _OUT},
         "Wrapped diffuse: clamped cosine about the tilted normal, / (1 + w) (the talk)"),
        ("cloth", "Cloth", _area_cloth, rough, {"Cloth": _OUT}, "Ashikhmin cloth (its LTC)"),
        ("sheen", "Sheen", _area_sheen, base, {"Sheen": _OUT}, "Disney sheen via the CoD table at r = 0.5 (the talk)"),
    ]
    return {key: NodeFunction(f"RTL {title} {label}", make(kind), inputs, outputs, desc)
            for key, label, make, inputs, outputs, desc in spec}


def lobe_functions(kind):
    """Lobe name -> NodeFunction for an RT Lit light kind."""
    return area_lobes(kind) if kind in ("quad", "disk") else PUNCTUAL_LOBES
