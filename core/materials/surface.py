"""The RT Lit surface: the material's inputs turned into the terms every light and the world use.

This is where the material's inputs are guarded, once, as Filament's ``getPixelParams`` does: factors
and reflectance colours are clamped to [0, 1] (a NaN input becomes 0: min and max ignore NaN,
core/shading_ops.py), the emission to [0, EMISSION_MAX], the shading normal and the view direction
normalised (a Normal input shorter than NORMAL_MIN, zero or denormal, or as long as NORMAL_MAX, infinite or
NaN, falls back to the geometry's normal).  The lobes downstream only add the guards their own math needs to stay
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


#: Normal inputs shorter than this fall back to the geometry's normal.  A threshold above float32's
#: denormals, so that float32 and float64 take the same branch (at |n| = 1e-40 the float32 dot
#: product underflows to 0 while float64's does not; docs/robustness.md).
NORMAL_MIN = 1e-6
#: Normal inputs this long or longer fall back to the geometry's normal too: an infinite component makes the
#: length infinite and n / |n| NaN (inf / inf), and from |n| ~ 1.8e19 on the float32 dot product overflows to inf
#: while float64's does not; below 1e18 both precisions compute |n|^2 (at most 1e36) and take the same branch.
NORMAL_MAX = 1e18
#: Emission colour and strength are each clamped to [0, EMISSION_MAX], so their product stays finite in
#: float32 (3.4e38) whatever a texture or driver feeds them.
EMISSION_MAX = 1e18


def _reflectance(c):
    """A colour that scales reflected light, clamped to [0, 1] per channel (an albedo or a tint: above 1
    it would create energy, below 0 it would make radiance negative)."""
    return op.vec3(*(op.saturate(op.component(c, i)) for i in range(3)))


def _emission(c, strength):
    bounded = op.vec3(*(op.clamp(op.component(c, i), 0.0, EMISSION_MAX) for i in range(3)))
    return op.scale(bounded, op.clamp(strength, 0.0, EMISSION_MAX))


def _surface(**kw):
    metallic = op.saturate(kw["Metallic"])
    base, tint = _reflectance(kw["Base Color"]), _reflectance(kw["Specular Tint"])
    n_in = kw["Normal"]
    length2 = op.dot(n_in, n_in)       # NaN fails both comparisons: the geometry's normal
    usable = op.logical_and(op.greater(length2, NORMAL_MIN * NORMAL_MIN), op.less(length2, NORMAL_MAX * NORMAL_MAX))
    n = op.vselect(usable, op.normalize(n_in), op.normalize(kw["Geometry Normal"]))
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
        "Diffuse Roughness": op.saturate(kw["Diffuse Roughness"]),
        "Sheen Color": op.scale(_reflectance(kw["Sheen Tint"]), op.saturate(kw["Sheen Weight"])),
        "Sheen Roughness": op.saturate(kw["Sheen Roughness"]),
        "Cloth Weight": op.saturate(kw["Cloth Weight"]),
        "Cloth Color": _reflectance(kw["Cloth Color"]),
        "Emission": _emission(kw["Emission Color"], kw["Emission Strength"]),
    }


SURFACE = NodeFunction("RTL Surface", _surface, dict(RT_LIT_INPUTS, **{k: v for k, v in GEOMETRY_INPUTS.items()
                                                                        if k != "Position"}),
                       SURFACE_OUTPUTS, "RT Lit material inputs to the terms every light uses")
