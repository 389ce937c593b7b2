"""The RT Lit surface: the material's inputs turned into the terms every light and the world use.

This is where the material's inputs are guarded, once, as Filament's ``getPixelParams`` does: factors
are clamped to [0, 1], the shading normal and the view direction normalised (a zero Normal input falls
back to the geometry's normal).  The lobes downstream only add the guards their own math needs to stay
finite (``conventions.ALPHA_MIN``, cosine floors).
"""
from __future__ import annotations

from .. import shading_ops as op
from ..ir.functions import NodeFunction
from .rt_lit_interface import GEOMETRY_INPUTS, RT_LIT_INPUTS, SURFACE_OUTPUTS


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
