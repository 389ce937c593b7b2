"""The lookdev material presets shipped as assets (``assets/rt_lookdev_presets.blend``, built by
``scripts/build_presets.py``): Principled BSDF values and the RT Lit switches each is converted with.

Metals: Base Color = F0 in linear sRGB, the measured values tabulated by Unity's Shader Graph documentation
("Metal Reflectance Node", after Hoffman 2015, "Physics and Math of Shading", SIGGRAPH course); the project's
Fresnel is Schlick's with F90 = 1 (docs/conventions.md).  Dielectrics use Principled's default IOR 1.5
(F0 = 0.04) unless stated.  Each preset names the technique it shows off (the switches of
``rt_lit_interface.Features``).  No bpy here: the Blender side is ``addon/preset_assets.py``.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from .rt_lit_interface import Features

#: The asset catalogs: (UUID, path, simple name).  The UUIDs are fixed so that a rebuilt library keeps them.
CATALOGS = (
    ("4d9ef5b2-52a3-4f0e-8f36-7a7c1b1f0a01", "RT Lookdev", "RT Lookdev"),
    ("4d9ef5b2-52a3-4f0e-8f36-7a7c1b1f0a02", "RT Lookdev/Metals", "RT Lookdev-Metals"),
    ("4d9ef5b2-52a3-4f0e-8f36-7a7c1b1f0a03", "RT Lookdev/Dielectrics", "RT Lookdev-Dielectrics"),
    ("4d9ef5b2-52a3-4f0e-8f36-7a7c1b1f0a04", "RT Lookdev/Fabrics", "RT Lookdev-Fabrics"),
)
CATALOG_IDS = {path.rsplit("/", 1)[-1]: uuid for uuid, path, _ in CATALOGS}


@dataclass(frozen=True)
class Preset:
    """One lookdev material: its name, catalog, Principled inputs, RT Lit switches and RT Lit-only inputs."""
    name: str
    catalog: str                        # a key of CATALOG_IDS
    principled: dict
    features: Features
    rt_lit: dict = field(default_factory=dict)     # inputs RT Lit has and Principled does not (Cloth, Wrap)
    description: str = ""


def _metal(name, f0, roughness, specular="kulla_conty"):
    return Preset(f"RTL {name}", "Metals",
                  {"Base Color": (*f0, 1.0), "Metallic": 1.0, "Roughness": roughness},
                  Features(specular=specular, diffuse="lambert"),
                  description=f"{name}: measured F0 {f0} (linear sRGB), roughness {roughness}, "
                              f"{specular.replace('_', '-')} multiple scattering")


def _dielectric(name, color, roughness, diffuse="cod", specular="turquin", ior=1.5, description=""):
    return Preset(f"RTL {name}", "Dielectrics",
                  {"Base Color": (*color, 1.0), "Metallic": 0.0, "Roughness": roughness, "IOR": ior},
                  Features(specular=specular, diffuse=diffuse), description=description)


PRESETS = (
    _metal("Gold", (1.000, 0.766, 0.336), 0.25),
    _metal("Silver", (0.972, 0.960, 0.915), 0.2),
    _metal("Copper", (0.955, 0.637, 0.538), 0.35),
    _metal("Aluminium", (0.913, 0.921, 0.925), 0.4),
    _metal("Iron", (0.560, 0.570, 0.580), 0.6, specular="fdez_aguera"),
    _metal("Chromium", (0.550, 0.556, 0.554), 0.08),
    _metal("Titanium", (0.542, 0.497, 0.449), 0.5, specular="turquin"),
    _dielectric("Red Plastic", (0.6, 0.05, 0.04), 0.3,
                description="glossy plastic: CoD diffuse under a Turquin-compensated GGX coat"),
    _dielectric("Black Rubber", (0.03, 0.03, 0.03), 0.75, description="rough, dark: the specular lobe carries it"),
    _dielectric("White Ceramic", (0.85, 0.85, 0.82), 0.05, description="glazed ceramic, near-mirror coat"),
    _dielectric("Rough Clay", (0.50, 0.24, 0.14), 1.0,
                description="terracotta, fully rough: the talk's CoD multiscattering diffuse"),
    Preset("RTL Skin Wrap", "Dielectrics",
           {"Base Color": (0.80, 0.52, 0.42, 1.0), "Metallic": 0.0, "Roughness": 0.5, "IOR": 1.4},
           Features(specular="turquin", diffuse="wrapped"), {"Wrap": 0.4},
           "wrapped diffuse (normalised wrap 0.4), a stand-in for scattering skin"),
    Preset("RTL Cotton", "Fabrics",
           {"Base Color": (0.15, 0.25, 0.55, 1.0), "Metallic": 0.0, "Roughness": 0.7},
           Features(specular="single", diffuse="cod", cloth=True),
           {"Cloth Weight": 1.0, "Cloth Color": (0.55, 0.65, 0.9, 1.0)},
           "the Ashikhmin cloth lobe (LTC under area lights)"),
    Preset("RTL Velvet", "Fabrics",
           {"Base Color": (0.30, 0.03, 0.06, 1.0), "Metallic": 0.0, "Roughness": 0.8, "Sheen Weight": 1.0,
            "Sheen Tint": (1.0, 0.8, 0.85, 1.0)},
           Features(specular="turquin", diffuse="cod", sheen=True),
           description="Disney sheen over CoD diffuse"),
)


def by_name(name):
    for preset in PRESETS:
        if preset.name == name:
            return preset
    raise KeyError(f"no preset {name!r} (presets: {', '.join(p.name for p in PRESETS)})")
