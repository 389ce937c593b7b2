"""The RT Lit material: Principled-like inputs, every scene light, real-time techniques.

Structure (each box a node function, so a node group in Blender; see core/ir/functions.py):

    RTL Surface                     material inputs + geometry -> N, V, F0, albedo, ...
    per light:
      RTL <Kind> Light data         driver values -> world-space light geometry and colour
      RTL Shade <Kind> (features)   lobes of the enabled techniques, combined with colours
        RTL <Kind> <Lobe>           one lobe (core/materials/lobes.py)
          RTL LTC ... Integral      (area lights) the LTC integral over the light

``rt_lit_radiance`` composes them; called with numpy arrays it evaluates the material
directly, called with IR expressions it builds the graph the RT Lit node group is emitted
from.  Colours are 3-vectors; the specular colour is F0 * Scale + Bias per channel.

Light units (core/lights.py): area lights give emitted radiance, punctual lights irradiance
at normal incidence; lobes are per unit of either, cosine included.
"""
from __future__ import annotations

import functools

from .. import multiscatter
from .. import shading_ops as op
from ..fresnel import fresnel_average
from ..ir.functions import NodeFunction
from ..ir.interface import color, factor, vector
from . import lobes
from .rt_lit_interface import RT_LIT_INPUTS

LIGHT_KINDS = ("quad", "disk", "point", "spot", "sun")

# --- surface ------------------------------------------------------------------------------------

GEOMETRY_INPUTS = {
    "Position": vector("Shading point, world space", "NONE", hide_value=True),
    "Geometry Normal": vector("Interpolated surface normal, world space", "NONE", hide_value=True),
    "Incoming": vector("Unit direction towards the viewer (Geometry > Incoming)", "NONE", hide_value=True),
}

SURFACE_OUTPUTS = {
    "N": vector("Unit shading normal", "NONE"),
    "V": vector("Unit direction towards the viewer", "NONE"),
    "Roughness": factor(0.5, "Blender roughness r"),
    "F0": color((0.04, 0.04, 0.04), "Specular reflectance at normal incidence"),
    "Dielectric F0": color((0.04, 0.04, 0.04), "F0 of the dielectric part (IOR, level, tint)"),
    "Metal F0": color((0.8, 0.8, 0.8), "F0 of the metallic part (base colour)"),
    "Metallic": factor(0.0, "Blend from dielectric to metal"),
    "Albedo": color((0.8, 0.8, 0.8), "Diffuse albedo"),
    "Wrap": factor(0.0, "Wrapped-diffuse amount"),
    "Sheen Color": color((0.0, 0.0, 0.0), "Sheen weight times tint"),
    "Cloth Weight": factor(0.0, "Blend from specular to cloth"),
    "Cloth Color": color((1.0, 1.0, 1.0), "Cloth colour"),
    "Emission": color((0.0, 0.0, 0.0), "Emitted radiance"),
}


# Principled BSDF v2 (Blender 4.0+ manual, "Principled BSDF"): dielectric F0 from the IOR,
# ((IOR - 1)/(IOR + 1))^2 (Fresnel at normal incidence), scaled by 2 x Specular IOR Level and
# tinted; metals take F0 = base colour; the diffuse albedo is base colour x (1 - metallic).
def dielectric_f0(ior, level):
    r = op.safe_div(ior - 1.0, ior + 1.0)
    return op.saturate(r * r * 2.0 * level)


def _surface(**kw):
    metallic = op.saturate(kw["Metallic"])
    base, tint = kw["Base Color"], kw["Specular Tint"]
    n_in = kw["Normal"]
    n = op.vselect(op.greater(op.dot(n_in, n_in), 0.0), op.normalize(n_in), op.normalize(kw["Geometry Normal"]))
    f0_dielectric = op.scale(tint, dielectric_f0(kw["IOR"], kw["Specular IOR Level"]))
    f0 = op.scale(f0_dielectric, 1.0 - metallic) + op.scale(base, metallic)
    return {
        "Dielectric F0": f0_dielectric,
        "Metal F0": base,
        "Metallic": metallic,
        "N": n,
        "V": op.normalize(kw["Incoming"]),
        "Roughness": op.saturate(kw["Roughness"]),
        "F0": f0,
        "Albedo": op.scale(base, 1.0 - metallic),
        "Wrap": op.saturate(kw["Wrap"]),
        "Sheen Color": op.scale(kw["Sheen Tint"], op.saturate(kw["Sheen Weight"])),
        "Cloth Weight": op.saturate(kw["Cloth Weight"]),
        "Cloth Color": kw["Cloth Color"],
        "Emission": op.scale(kw["Emission Color"], kw["Emission Strength"]),
    }


SURFACE = NodeFunction("RTL Surface", _surface, dict(RT_LIT_INPUTS, **{k: v for k, v in GEOMETRY_INPUTS.items()
                                                                        if k != "Position"}),
                       SURFACE_OUTPUTS, "RT Lit material inputs to the terms every light uses")


# --- combining lobes with colours -----------------------------------------------------------------

def per_channel(fn, rgb, *args):
    """fn applied to each channel of a colour (a Separate/Combine XYZ pair in nodes)."""
    return op.vec3(*(fn(op.component(rgb, i), *args) for i in range(3)))


def splat(x):
    return op.vec3(x, x, x)


def combine_lobes(features, surface, lobe_values, light_color):
    """Radiance towards the viewer from one light: the enabled lobes weighted by the material's
    colours, times the light's colour (radiance or irradiance, per light kind)."""
    f0 = surface["F0"]
    spec = op.scale(f0, lobe_values["Scale"]) + splat(lobe_values["Bias"])
    if features.specular == "turquin":
        # Turquin 2019, eq. 16 (the talk): f_ss (1 + F0 (1 - E)/E)
        spec = op.vmul(spec, per_channel(multiscatter.turquin_compensation, f0, lobe_values["E"]))
    elif features.specular == "fdez_aguera":
        # The talk's approximation to Fdez-Aguera 2019: f_ss (1 + F_avg (1 - E)/(1 - F_avg (1 - E)))
        spec = op.vmul(spec, per_channel(multiscatter.fdez_aguera_area_scale, f0, lobe_values["E"]))
    elif features.specular == "kulla_conty":
        # Kulla & Conty 2017: + F_ms(F_avg) f_ms
        om_avg = lobe_values["One Minus E Avg"]
        f_ms = per_channel(lambda c: multiscatter.kulla_conty_fresnel_factor(fresnel_average(c), om_avg), f0)
        spec = spec + op.scale(f_ms, lobe_values["Lobe"])
    if features.cloth:
        cloth = op.scale(surface["Cloth Color"], lobe_values["Cloth"])
        w = surface["Cloth Weight"]
        spec = op.scale(spec, 1.0 - w) + op.scale(cloth, w)
    total = spec + op.scale(surface["Albedo"], lobe_values["Diffuse"])
    if features.sheen:
        total = total + op.scale(surface["Sheen Color"], lobe_values["Sheen"])
    return op.vmul(light_color, total)


def _lobe_names(features):
    names = ["ggx", features.diffuse]
    if features.specular == "kulla_conty":
        names.append("kulla_conty")
    if features.cloth:
        names.append("cloth")
    if features.sheen:
        names.append("sheen")
    return names


_SURFACE_FOR_SHADE = ("N", "V", "Roughness", "F0", "Albedo", "Wrap", "Sheen Color", "Cloth Weight", "Cloth Color")


def _lobe_args(fn, available):
    return {name: available[name] for name in fn.input_sockets}


@functools.lru_cache(maxsize=None)
def shade_function(kind, features):
    """``RTL Shade <Kind> (<features>)``: one light's radiance towards the viewer."""
    from .. import lights

    data = lights.LIGHT_DATA[kind]
    geometry_names = [n for n in data.output_sockets if n not in ("Radiance", "Irradiance")]
    color_name = "Radiance" if "Radiance" in data.output_sockets else "Irradiance"
    lobe_table = lobes.lobe_functions(kind)

    def shade(**kw):
        surface = {k: kw[k] for k in _SURFACE_FOR_SHADE}
        values = {}
        for lobe in _lobe_names(features):
            values.update(lobe_table[lobe](**_lobe_args(lobe_table[lobe], kw)))
        return {"Radiance": combine_lobes(features, surface, values, kw[color_name])}

    inputs = {k: SURFACE_OUTPUTS[k] for k in _SURFACE_FOR_SHADE}
    if kind in ("quad", "disk", "point", "spot"):
        inputs["Position"] = GEOMETRY_INPUTS["Position"]
    for n in geometry_names + [color_name]:
        inputs[n] = data.output_sockets[n]
    # only the inputs some lobe or the combination reads
    used = set(_SURFACE_FOR_SHADE) | {color_name}
    for lobe in _lobe_names(features):
        used |= set(lobe_table[lobe].input_sockets)
    inputs = {k: v for k, v in inputs.items() if k in used}
    title = kind.capitalize() if kind not in ("quad", "disk") else f"{kind.capitalize()} Area"
    return NodeFunction(f"RTL Shade {title} ({features.label()})", shade, inputs,
                        {"Radiance": color((0.0, 0.0, 0.0), "Radiance towards the viewer from this light")},
                        f"One {kind} light on the RT Lit material ({features.label()})")


# --- the whole material ---------------------------------------------------------------------------

def rt_lit_radiance(features, material, geometry, lights_in_scene, world=None):
    """Outgoing radiance of the RT Lit material (3-vector) plus its emission.

    ``material``: RT_LIT_INPUTS name -> value; ``geometry``: Position, Geometry Normal, Incoming;
    ``lights_in_scene``: list of (kind, {driver parameter name -> value}); ``world``: None (no world
    contribution) or (``world.WorldEnvironment``, {``world.WORLD_PARAMETERS`` name -> value}).
    """
    parts = rt_lit_radiance_parts(features, material, geometry, lights_in_scene, world)
    total = parts[0]
    for part in parts[1:]:
        total = total + part
    return total


def rt_lit_radiance_parts(features, material, geometry, lights_in_scene, world=None):
    """[the material's emission, radiance from light 0, from light 1, ..., (the world)]: the terms of
    ``rt_lit_radiance`` (in nodes, one Emission closure each); the world's term comes last."""
    from .. import lights

    surface = SURFACE(**{k: material[k] for k in RT_LIT_INPUTS},
                      **{k: geometry[k] for k in ("Geometry Normal", "Incoming")})
    parts = [surface["Emission"]]
    for kind, params in lights_in_scene:
        data_fn = lights.LIGHT_DATA[kind]
        args = dict(params)
        if "Position" in data_fn.input_sockets:
            args["Position"] = geometry["Position"]
        light = data_fn(**args)
        fn = shade_function(kind, features)
        available = dict(surface, Position=geometry["Position"], **light)
        parts.append(fn(**_lobe_args(fn, available))["Radiance"])
    if world is not None:
        from . import world as world_term

        env, params = world
        fn = world_term.shade_world_function(features, env)
        args = {k: surface[k] for k in world_term.WORLD_SURFACE}
        args.update({f"World {k}": params[k] for k in world_term.WORLD_PARAMETERS})
        parts.append(fn(**args)["Radiance"])
    return parts

