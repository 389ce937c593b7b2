"""One scene light on the RT Lit material: its lobes combined with the material's colours.

``shade_function(kind, features)`` is the node function "RTL Shade <Kind> (<features>)": the lobes
of the enabled techniques (``lobes``) for that light kind, weighted by the surface's colours
(``surface``), times the light's radiance (area lights) or irradiance (punctual lights;
core/lights.py).  Colours are 3-vectors; the specular colour is F0 * Scale + Bias per channel.
"""
from __future__ import annotations

import functools

from .. import lights, multiscatter, rough_diffuse
from .. import shading_ops as op
from ..fresnel import fresnel_average
from ..ir.functions import NodeFunction
from ..ir.interface import color
from ..lut.lookup import REFERENCES
from . import lobes
from .rt_lit_interface import GEOMETRY_INPUTS, SURFACE_OUTPUTS


#: Specular models whose compensation is non-linear in F0: a partly metallic surface is shaded once with
#: the dielectric F0 and once with the metal's, then mixed by Metallic (as the World term does).  The single-
#: scattering lobe, F0 * Scale + Bias, is linear in F0, so its mixed F0 gives the same value at less cost.
SPLIT_F0_MODELS = ("turquin", "fdez_aguera", "kulla_conty")


def specular_color(features, f0, lobe_values, area=False):
    """The specular lobe's colour for one F0 (3-vector): F0 * Scale + Bias, times the specular model's
    multiple-scattering compensation (``area``: the lobes are integrals over an area light)."""
    spec = op.scale(f0, lobe_values["Scale"]) + op.splat(lobe_values["Bias"])
    if features.specular == "turquin":
        # Turquin 2019, eq. 16 (the talk): f_ss (1 + F0 (1 - E)/E)
        return op.vmul(spec, op.per_channel(multiscatter.turquin_compensation, f0, lobe_values["E"]))
    if features.specular == "fdez_aguera":
        # The talk's approximation to Fdez-Aguera 2019: f_ss (1 + F_avg (1 - E)/(1 - F_avg (1 - E)))
        return op.vmul(spec, op.per_channel(multiscatter.fdez_aguera_area_scale, f0, lobe_values["E"]))
    if features.specular == "kulla_conty":
        # Kulla & Conty 2017: + F_ms(F_avg) f_ms
        om_avg = lobe_values["One Minus E Avg"]
        f_ms = op.per_channel(lambda c: multiscatter.kulla_conty_fresnel_factor(fresnel_average(c), om_avg), f0)
        lobe = lobe_values["Lobe"]
        if area:
            # Over an area light the single-scattering lobe's albedo is the LTC magnitude E, the multiple-
            # scattering lobe's the energy table's 1 - E(mu_v): two fits that disagree at grazing views of
            # near-mirrors (E_ltc ~ 0.99, E_table ~ 0.61 at mu_v -> 0, r -> 0), where their sum reached 1.39
            # of the light (docs/robustness.md).  The lobe is bounded by what the first leaves, 1 - E_ltc.
            lobe = op.minimum(lobe, op.maximum(1.0 - lobe_values["E"], 0.0))
        return spec + op.scale(f_ms, lobe)
    return spec


def mixed_specular_color(features, surface, lobe_values, area=False):
    """The specular colour of a surface that is Metallic parts metal: the dielectric's and the metal's, each
    compensated with its own F0, mixed by Metallic (``SPLIT_F0_MODELS``), or the mixed F0's when that is
    exact (single scattering)."""
    if features.specular not in SPLIT_F0_MODELS:
        return specular_color(features, surface["F0"], lobe_values, area)
    m = surface["Metallic"]
    return (op.scale(specular_color(features, surface["Dielectric F0"], lobe_values, area), 1.0 - m)
            + op.scale(specular_color(features, surface["Metal F0"], lobe_values, area), m))


def combine_lobes(features, surface, lobe_values, light_color, area=False):
    """Radiance towards the viewer from one light: the enabled lobes weighted by the material's
    colours, times the light's colour (radiance or irradiance, per light kind; ``area``: an area
    light's, whose lobes are integrals over the light)."""
    if features.specular == "none":
        return _without_specular(features, surface, lobe_values, light_color)
    spec = mixed_specular_color(features, surface, lobe_values, area)
    if features.cloth:
        cloth = op.scale(surface["Cloth Color"], lobe_values["Cloth"])
        w = surface["Cloth Weight"]
        spec = op.scale(spec, 1.0 - w) + op.scale(cloth, w)
    total = spec + op.scale(surface["Albedo"], lobe_values["Diffuse"])
    if features.diffuse == "oren_nayar":
        total = total + _rough_diffuse_multiscatter(surface, lobe_values)
    return op.vmul(light_color, add_sheen(features, surface, lobe_values, total))


def add_sheen(features, surface, lobe_values, below):
    """``below`` (the lobes under the sheen) plus the sheen lobe.  The Disney sheens add (Burley 2012, the
    talk); Zeltner's is layered as the Principled BSDF does (Cycles' ``principled_bsdf_emission``): the
    lobes below are weighted by 1 - max(sheen colour) x R(mu_v), R the sheen's directional albedo."""
    if features.sheen == "none":
        return below
    return layer_sheen(features, surface, below, op.scale(surface["Sheen Color"], lobe_values["Sheen"]),
                       lobe_values.get("Sheen Albedo"))


def layer_sheen(features, surface, below, sheen, albedo):
    """``below`` under the sheen radiance ``sheen`` (colour applied); ``albedo`` R(mu_v) (Zeltner's only)."""
    if features.sheen == "zeltner":
        below = op.scale(below, sheen_layer_weight(surface["Sheen Color"], albedo))
    return below + sheen


def sheen_layer_weight(sheen_color, albedo):
    """Cycles' ``closure_layering_weight`` for the Principled sheen: saturate(1 - max_c(colour_c) R)."""
    c = op.maximum(op.maximum(op.component(sheen_color, 0), op.component(sheen_color, 1)),
                   op.component(sheen_color, 2))
    return op.saturate(1.0 - c * albedo)


def _without_specular(features, surface, lobe_values, light_color):
    """``combine_lobes`` with the specular switched off: the cloth lobe still blends in by Cloth Weight
    (over no specular), the diffuse and sheen add."""
    total = op.scale(surface["Albedo"], lobe_values["Diffuse"])
    if features.diffuse == "oren_nayar":
        total = total + _rough_diffuse_multiscatter(surface, lobe_values)
    if features.cloth:
        total = total + op.scale(op.scale(surface["Cloth Color"], lobe_values["Cloth"]), surface["Cloth Weight"])
    return op.vmul(light_color, add_sheen(features, surface, lobe_values, total))


def _rough_diffuse_multiscatter(surface, lobe_values):
    """The rough diffuse's multiple-scattering lobe in colour: Cycles' albedo x rho_ms(base colour) per channel
    (core/rough_diffuse.py; Principled's diffuse weight is base x (1 - metallic), its lobe colour the base)."""
    color = rough_diffuse.multiscatter_color(surface["Albedo"], surface["Metal F0"], surface["Diffuse Roughness"])
    return op.scale(color, lobe_values["Diffuse MS"])


def lobe_keys(features):
    """The lobes ``features`` enables, in evaluation order."""
    keys = ([] if features.specular == "none" else ["ggx"]) + [features.diffuse]
    if features.specular == "kulla_conty":
        keys.append("kulla_conty")
    if features.cloth:
        keys.append("cloth")
    if features.sheen != "none":
        keys.append(SHEEN_LOBES[features.sheen])
    return keys


#: Sheen model -> its lobe (``lobes.LOBES``).
SHEEN_LOBES = {"disney_talk": "sheen", "zeltner": "zeltner", "disney_fitted": "disney_fitted"}

#: The surface terms a light's shading reads (``shade_surface``: those of one feature set).
SHADE_SURFACE = ("N", "V", "Roughness", "F0", "Albedo", "Wrap", "Sheen Color", "Cloth Weight", "Cloth Color")
#: What the split specular models read instead of the mixed F0.
SPLIT_F0_SURFACE = ("Dielectric F0", "Metal F0", "Metallic")
#: ... and those the rough diffuse adds (only groups built with it read them).
ROUGH_DIFFUSE_SURFACE = ("Diffuse Roughness", "Metal F0")


def shade_surface(features):
    """The surface terms one light's shading reads with ``features``: the mixed F0, or the dielectric and
    metal F0 and Metallic for the models that shade them apart (``SPLIT_F0_MODELS``), no F0 without specular;
    the rough diffuse's inputs with it."""
    if features.specular == "none":
        terms = tuple(k for k in SHADE_SURFACE if k != "F0")
    elif features.specular not in SPLIT_F0_MODELS:
        terms = SHADE_SURFACE
    else:
        terms = tuple(k for k in SHADE_SURFACE if k != "F0") + SPLIT_F0_SURFACE
    if features.diffuse == "oren_nayar":
        terms += tuple(k for k in ROUGH_DIFFUSE_SURFACE if k not in terms)
    return terms


#: Surface terms only some lobes read (a shade function has them only when one of its lobes does).
OPTIONAL_SURFACE = ("Sheen Roughness",)


def light_color_name(kind):
    """"Radiance" for area lights, "Irradiance" for punctual lights (the light data's colour output)."""
    return "Radiance" if "Radiance" in lights.LIGHT_DATA[lights.base_kind(kind)].output_sockets else "Irradiance"


def _arguments(fn, available):
    return {name: available[name] for name in fn.input_sockets}


def exact_horizon(features, kind):
    """Whether the lobes clip a light of ``kind`` at the horizon (``Features.horizon``): every area light under
    "exact", quads only under "exact_quads", none under "sphere_table"."""
    return features.horizon == "exact" or (features.horizon == "exact_quads" and lights.shading_form(kind) == "quad")


@functools.lru_cache(maxsize=None)
def shade_function(kind, features):
    """``RTL Shade <Kind> (<features>)``: one light's radiance towards the viewer (``kind`` a base kind: its
    options change the light's data, not its shading)."""
    color_name = light_color_name(kind)
    functions = [lobes.LOBES[key].function(kind, exact_horizon(features, kind)) for key in lobe_keys(features)]
    area = lights.shading_form(kind) != "punctual"

    def shade(tables, **kw):
        values = {}
        for fn in functions:
            values.update(fn(tables, **_arguments(fn, kw)))
        return {"Radiance": combine_lobes(features, kw, values, kw[color_name], area)}

    surface_terms = shade_surface(features)
    inputs = {k: SURFACE_OUTPUTS[k] for k in surface_terms + tuple(k for k in OPTIONAL_SURFACE if k not in surface_terms)}
    if kind != "sun":
        inputs["Position"] = GEOMETRY_INPUTS["Position"]
    inputs.update(lobes.light_geometry_sockets(kind))
    inputs[color_name] = lights.LIGHT_DATA[lights.base_kind(kind)].output_sockets[color_name]
    # only the inputs some lobe or the combination reads
    used = set(surface_terms) | {color_name}.union(*(fn.input_sockets for fn in functions))
    inputs = {k: v for k, v in inputs.items() if k in used}
    base, options = lights.split_kind(kind)
    title = {"quad_spot": "Quad Spot Fallback"}.get(base, base.capitalize())
    title = title if base not in lobes.AREA_KINDS else f"{title} Area" + (" Spread" if options else "")
    return NodeFunction(f"RTL Shade {title} ({features.label()})", shade, inputs,
                        {"Radiance": color((0.0, 0.0, 0.0), "Radiance towards the viewer from this light")},
                        f"One {kind} light on the RT Lit material ({features.label()})", tables=REFERENCES)


def shading_kind(kind):
    """The kind whose shade function shades ``kind``: its base kind, "disk" for the lights shaded as the disk facing
    the point (sphere lights, suns with an angle: their data functions give a disk's outputs), with "+spread" for an
    area light with spread (its lobes weight their integrals by the spread: core/light_spread.py)."""
    base, options = lights.split_kind(kind)
    if base not in lobes.AREA_KINDS:
        return "disk" if lights.shading_form(base) == "disk" else base
    return lights.kind_name(base, ("spread",) if "spread" in options else ())


def shade_light(tables, kind, features, surface, position, light):
    """Radiance from one light: ``surface`` the "RTL Surface" outputs, ``light`` the outputs of the
    light's data function (``core.lights.LIGHT_DATA``); arrays (``tables`` with data) or Exprs."""
    fn = shade_function(shading_kind(kind), features)
    available = dict(surface, Position=position, **light)
    return fn(tables, **_arguments(fn, available))["Radiance"]
