"""The RT Lit material's interface: its inputs and outputs, their names, and its build-time switches.

Inputs are node-group sockets an artist sets or links (``RT_LIT_INPUTS``, Principled-like), the
shading point's geometry (``GEOMETRY_INPUTS``), and the scene's lights and world: light ``i``'s
parameter ``p`` is the input ``light_input(i, p)`` ("Light 0 Power"), the world's parameter ``p`` the
input ``world_input(p)`` ("World SH 0").  Outputs: the total ``Radiance`` and its parts, the material's
emission, each light's radiance and the world's (``light_output(i)``, ...), which the node backend
turns into one Emission closure each.

Switches (``Features``) choose which techniques the material is built with, so a disabled technique
carries no nodes at all (the switch is folded away at build time, not multiplied by zero at render
time).  Names shared by every layer (group-name prefixes) are defined here once.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass, fields

from ..ir.interface import Socket, color, factor, scalar, vector

#: "none" switches the specular lobe off (no GGX lobe, tables or world specular term in the tree): a
#: diffuse-only material, e.g. for checking the diffuse models alone.
SPECULAR_MODELS = ("single", "turquin", "fdez_aguera", "kulla_conty", "none")
#: "cod_wrapped": the CoD multiscattering diffuse with the Wrap input (the talk's multiscattering wrapped diffuse).
DIFFUSE_MODELS = ("lambert", "cod", "wrapped", "cod_wrapped")
#: "oren_nayar": rough diffuse as Cycles shades Principled's Diffuse Roughness (Fujii's improved Oren-Nayar with
#: EON's energy-preserving multiple scattering; core/rough_diffuse.py), read from the "Diffuse Roughness" input.
DIFFUSE_MODELS += ("oren_nayar",)
#: The sheen lobe: none; Zeltner, Burley & Chiang 2022 (Blender's Principled sheen, core/sheen.py); Disney
#: sheen (Burley 2012) with its own fitted LTC under area lights; Disney sheen as the talk shades it (the CoD
#: table at r = 0.5 under area lights).  A stored ``sheen: true`` (the old switch) is "disney_talk".
SHEEN_MODELS = ("none", "zeltner", "disney_fitted", "disney_talk")
#: The sheen model of Blender's Principled BSDF: what a conversion picks for a Principled material with sheen.
PRINCIPLED_SHEEN = "zeltner"
#: Fdez-Aguera's multiple scattering under the environment: lit by the irradiance (the paper) or by
#: the prefiltered radiance (the talk's approximation); core/materials/world.py.
ENVIRONMENT_MS_FORMS = ("irradiance", "radiance")
#: Occlusion of the World term by the scene (issue 29; core/occlusion.py): none (the world lights every point
#: as if nothing stood around it), or the renderer's ambient occlusion on the world's diffuse, sheen and cloth
#: and a specular occlusion derived from it on the world's specular: Lagarde & de Rousiers 2014 ("lagarde"),
#: Jimenez et al. 2016's cones ("cones") or the cones clipped by the horizon ("cones_clipped", the most
#: accurate of the three in docs/benchmarks/specular_occlusion.md).  The lights are not occluded by it.
OCCLUSION_MODELS = ("none", "lagarde", "cones", "cones_clipped")
#: How the lobes' LTC integrals meet the receiver's horizon under area lights (issue 30; docs/area_lights.md,
#: "RT Lit's exact horizon"): "sphere_table" is the talk's clipless form for every light (Hill & Heitz 2017),
#: "exact_quads" clips quad lights exactly at the horizon and leaves disks (and sphere lights) to the sphere table,
#: "exact" clips disks too (the clipped ellipse's boundary integral where they cross it).  Measured
#: (docs/benchmarks/horizon.md): clipping takes GGX under quads crossing the horizon from 17% to 3.5% p90 and Lambert
#: to float precision, for ~1.8x a quad light's nodes; disks (Lambert to 5e-7) for ~2.7x theirs.  The default stays
#: the talk's form: cheapest, and in Blender 4.5 the largest feature set's clipped quads overflow Cycles' SVM stack
#: (black renders; the other measured sets fit, all fit in 5.2: docs/area_lights.md).  The Zeltner sheen clips under
#: all three.
HORIZON_MODELS = ("sphere_table", "exact_quads", "exact")
#: The model an artist gets when switching world occlusion on (the Convert dialog, New Lookdev Scene).
DEFAULT_OCCLUSION = "cones_clipped"

#: Input name -> socket, in interface order.  Names follow the Principled BSDF where one exists,
#: so a conversion maps them one to one.
RT_LIT_INPUTS = {
    "Base Color": color((0.8, 0.8, 0.8, 1.0), "Diffuse albedo (dielectric) or F0 (metal)", "Surface"),
    "Metallic": factor(0.0, "Blend from dielectric to metal", "Surface"),
    "Roughness": factor(0.5, "Blender roughness r; GGX alpha = r^2", "Surface"),
    "IOR": scalar(1.5, "Index of refraction of the dielectric: F0 = ((IOR - 1)/(IOR + 1))^2", 1.0, 4.0,
                  panel="Specular"),
    "Specular IOR Level": factor(0.5, "Scales the dielectric F0 by 2 x level (0.5 keeps it), as Principled",
                                 "Specular"),
    "Specular Tint": color((1.0, 1.0, 1.0, 1.0), "Tint of the dielectric F0", "Specular"),
    "Wrap": factor(0.0, "Wrapped-diffuse amount w (used by the 'wrapped' and 'cod_wrapped' diffuse models)",
                   "Diffuse"),
    "Diffuse Roughness": factor(0.0, "Oren-Nayar roughness sigma, as Principled's Diffuse Roughness (used when the "
                                     "diffuse model is 'oren_nayar')", "Diffuse"),
    "Sheen Weight": factor(0.0, "Disney sheen amount (used when sheen is switched on)", "Sheen"),
    "Sheen Roughness": factor(0.5, "Sheen roughness (Zeltner sheen, as Principled's; the Disney sheens ignore it)",
                              "Sheen"),
    "Sheen Tint": color((1.0, 1.0, 1.0, 1.0), "Colour of the Disney sheen", "Sheen"),
    "Cloth Weight": factor(0.0, "Blend from the specular lobe to the Ashikhmin cloth lobe (cloth switched on)",
                           "Cloth"),
    "Cloth Color": color((1.0, 1.0, 1.0, 1.0), "Colour of the cloth lobe", "Cloth"),
    "Emission Color": color((1.0, 1.0, 1.0, 1.0), "Emitted radiance colour, added to the shaded result",
                            "Emission"),
    "Emission Strength": scalar(0.0, "Emitted radiance strength", 0.0, None, panel="Emission"),
    "Normal": vector("Shading normal (world space); unlinked = the geometry's normal", "NONE",
                     hide_value=True),
}

#: The renderer's ambient occlusion at the shading point (an input of materials with world occlusion on: Blender's
#: Ambient Occlusion node feeds it in Cycles and EEVEE, an engine its own AO in the shader backend).
OCCLUSION_INPUT = "Ambient Occlusion"
OCCLUSION_SOCKET = factor(1.0, "Cosine-weighted visible share of the hemisphere about the normal (1: unoccluded)")

#: The shading point, as the node backend's Geometry node delivers it.
GEOMETRY_INPUTS = {
    "Position": vector("Shading point, world space", "NONE", hide_value=True),
    "Geometry Normal": vector("Interpolated surface normal, world space", "NONE", hide_value=True),
    "Incoming": vector("Unit direction towards the viewer (Geometry > Incoming)", "NONE", hide_value=True),
}

#: The RT Lit surface terms every light and the world use (outputs of "RTL Surface").
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
    "Diffuse Roughness": factor(0.0, "Diffuse (Oren-Nayar) roughness sigma"),
    "Sheen Color": color((0.0, 0.0, 0.0), "Sheen weight times tint"),
    "Sheen Roughness": factor(0.5, "Sheen roughness"),
    "Cloth Weight": factor(0.0, "Blend from specular to cloth"),
    "Cloth Color": color((1.0, 1.0, 1.0), "Cloth colour"),
    "Emission": color((0.0, 0.0, 0.0), "Emitted radiance"),
}

#: Every node group built from a core function is named "RTL ..." (Add > Group lists them together).
NODE_GROUP_PREFIX = "RTL "
#: RT Lit material groups are named "RT Lit (<features>)" (``rt_lit_group_name``).
RT_LIT_GROUP_PREFIX = "RT Lit"
#: The total radiance and the parts it sums.
RADIANCE_OUTPUT = "Radiance"
EMISSION_OUTPUT = "Material Emission"
WORLD_OUTPUT = "World Radiance"
#: The light kinds RT Lit shades (area quad and disk, point, spot, sun, the talk's quad-to-spot fallback, and
#: Blender's point and spot lights with a radius and suns with an angle: core/lights.py).  A kind may carry
#: build-time options, "quad+cone+range" (``core.lights.split_kind``).
LIGHT_KINDS = ("quad", "disk", "point", "spot", "sun", "quad_spot", "sphere", "spot_sphere", "sun_disk")


def light_input(index, parameter):
    """Name of light ``index``'s parameter input: "Light 0 Power"."""
    return f"Light {index} {parameter}"


def light_output(index):
    """Name of light ``index``'s radiance output: "Light 0 Radiance"."""
    return f"Light {index} Radiance"


def world_input(parameter):
    """Name of the world's parameter input: "World SH 0", "World Strength", "World Rotation"."""
    return f"World {parameter}"


def rt_lit_group_name(features):
    """"RT Lit (<features label>)"."""
    return f"{RT_LIT_GROUP_PREFIX} ({features.label()})"


#: Output name -> socket.  "Shader" is the material's surface: one Emission closure per light (and
#: one for the material's own emission), summed by Add Shader nodes.  Cycles compiles each closure's
#: nodes in turn, so per-light values do not pile up on its SVM stack (255 floats per material: a
#: single summed colour overflowed it from 2 to 8 lights, measured).  "Radiance" is the same total
#: as a colour, for use in other node setups.
RT_LIT_OUTPUTS = {
    "Shader": Socket("shader", None, description="Outgoing radiance as emission: connect to Surface"),
    "Radiance": Socket("color", (0.0, 0.0, 0.0, 1.0), description="Outgoing radiance towards the camera"),
}


@dataclass(frozen=True)
class Features:
    """Build-time switches of an RT Lit group."""
    specular: str = "turquin"        # one of SPECULAR_MODELS
    diffuse: str = "cod"             # one of DIFFUSE_MODELS
    sheen: str = "none"              # one of SHEEN_MODELS (True / False: "disney_talk" / "none")
    cloth: bool = False
    environment_ms: str = "irradiance"   # one of ENVIRONMENT_MS_FORMS (Fdez-Aguera under the world)
    occlusion: str = "none"              # one of OCCLUSION_MODELS (the World term's occlusion)
    horizon: str = "sphere_table"        # one of HORIZON_MODELS (the lobes under area lights)

    def __post_init__(self):
        if isinstance(self.sheen, (bool, int)):       # the old switch (stored materials, Features(sheen=True))
            object.__setattr__(self, "sheen", "disney_talk" if self.sheen else "none")
        if self.sheen not in SHEEN_MODELS:
            raise ValueError(f"sheen model must be one of {SHEEN_MODELS}, got {self.sheen!r}")
        if self.specular not in SPECULAR_MODELS:
            raise ValueError(f"specular model must be one of {SPECULAR_MODELS}, got {self.specular!r}")
        if self.diffuse not in DIFFUSE_MODELS:
            raise ValueError(f"diffuse model must be one of {DIFFUSE_MODELS}, got {self.diffuse!r}")
        if self.environment_ms not in ENVIRONMENT_MS_FORMS:
            raise ValueError(f"environment_ms must be one of {ENVIRONMENT_MS_FORMS}, got {self.environment_ms!r}")
        if self.occlusion not in OCCLUSION_MODELS:
            raise ValueError(f"occlusion must be one of {OCCLUSION_MODELS}, got {self.occlusion!r}")
        if self.horizon not in HORIZON_MODELS:
            raise ValueError(f"horizon must be one of {HORIZON_MODELS}, got {self.horizon!r}")

    def as_dict(self):
        return asdict(self)

    @classmethod
    def from_dict(cls, data):
        names = {f.name for f in fields(cls)}
        return cls(**{k: v for k, v in dict(data).items() if k in names})

    def label(self):
        parts = ["no specular" if self.specular == "none" else self.specular.replace("_", "-"), self.diffuse]
        if self.specular == "fdez_aguera" and self.environment_ms != "irradiance":
            parts[0] += f" ({self.environment_ms})"
        parts += [p for p, on in ((_SHEEN_LABELS[self.sheen], self.sheen != "none"), ("cloth", self.cloth)) if on]
        if self.occlusion != "none":
            parts.append(f"{self.occlusion.replace('_', '-')} AO")
        if self.horizon != "sphere_table":
            parts.append(f"{self.horizon.replace('_', '-')} horizon")
        return ", ".join(parts)


#: Sheen model -> its word in group names ("disney_talk" keeps the old switch's "sheen", so the groups of
#: materials saved before the sheen models keep their names).
_SHEEN_LABELS = {"none": "", "zeltner": "zeltner sheen", "disney_fitted": "disney-fitted sheen",
                 "disney_talk": "sheen"}
