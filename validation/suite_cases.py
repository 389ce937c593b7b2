"""The cases of scripts/validate.py: scenes, the three images per case, and their metrics.

A case is a grid of unit spheres (one per *variant*: a technique with its material values) under a
set of Blender lights, seen by an orthographic camera looking along +Y.  Per case:

(a) node render: every sphere gets the RT Lit material (emission only) and Cycles renders 1 sample
    at pixel centres with Position and Normal passes (``engine_parity.render_cycles_passes``);
(b) numpy: ``core.materials.rt_lit.rt_lit_radiance`` at (a)'s Position / Normal passes with the
    material values and the lights' driver values (``numpy_radiance``);
(c) ground truth, per variant:
    - ``cycles``: the spheres' materials are swapped to the Cycles closure with the same BRDF
      (Diffuse BSDF for Lambert, Glossy BSDF GGX for single-scattering GGX with F = 1, Glossy
      Multiscatter GGX for the multiscattering specular with F = 1, Metallic BSDF GGX with F82 and a
      white edge tint (= Schlick with F0 = Base Color) for coloured specular, plus a Diffuse BSDF for
      dielectrics), the same light objects (radius 0 / angle 0 for punctual lights), direct light only
      (max bounces 0), fixed seed, no adaptive sampling, no denoising, rendered with two seeds;
    - ``brute``: the integral over the light of the *true* BRDF of the RT Lit material, per pixel, on
      a seeded subset of the sphere's pixels (``brute_force_radiance``).  The true BRDF is the
      material's punctual shading (``rt_lit.shade_function("sun", features)``: the lobes evaluated at
      one light direction, exactly the technique's BRDF times the cosine) summed over a Gauss-Legendre
      rule on the light (core/ltc/reference.py ``polygon_rule`` / ``disk_rule``), the light clipped at
      the shading point's horizon where the BRDF vanishes below it (so the rule converges
      spectrally); the wrapped diffuse extends below the horizon and is integrated unclipped.

Spheres are seen by camera rays only (no sphere shadows or lights another), so a sphere is convex
and unoccluded; their meshes are 192 x 96 UV spheres with exactly radial normals
(validate_energy's mesh).  The RT Lit material's specular is switched off for pure-diffuse variants
by Cloth Weight 1 with a black Cloth Color (RT Lit has no "no specular" switch; spec x (1 - w) +
cloth x w = 0), and its diffuse by Metallic 1 (albedo 0).
"""
from __future__ import annotations

import functools
import math
import time
from dataclasses import dataclass, field
from typing import ClassVar
from pathlib import Path

import numpy as np


from ..core.materials.rt_lit_interface import Features

# --- case description -----------------------------------------------------------------------

WHITE = (1.0, 1.0, 1.0)
BLACK = (0.0, 0.0, 0.0)

MIX_TRUTH = ("{} at Metallic 0.5 (copper base colour, IOR 1.5) vs Cycles' Mix Shader of the dielectric (Metallic "
             "BSDF Multiscatter GGX, F82 white, F0 0.04, + Diffuse BSDF) and the metal (Metallic BSDF Multiscatter GGX, "
             "F82 white, F0 = base colour)")

#: Technique -> (RT Lit features, truth kind, short description).
TECHNIQUES = {
    "lambert": (Features("none", "lambert"), "cycles", "Lambert diffuse vs Cycles Diffuse BSDF"),
    "ggx": (Features("single", "lambert"), "cycles", "single-scattering GGX, F0 = 1, vs Cycles Glossy GGX"),
    "turquin": (Features("turquin", "lambert"), "cycles",
                "Turquin multiscattering GGX, F0 = 1, vs Cycles Glossy Multiscatter GGX"),
    "fdez_aguera": (Features("fdez_aguera", "lambert"), "cycles",
                    "Fdez-Aguera (talk's area form) GGX, F0 = 1, vs Cycles Glossy Multiscatter GGX"),
    "dielectric": (Features("single", "lambert"), "cycles",
                   "GGX (Schlick F0 0.04) + Lambert vs Cycles Metallic BSDF (GGX, F82 white) + Diffuse BSDF"),
    "metal": (Features("single", "lambert"), "cycles",
              "GGX with coloured Schlick F0 vs Cycles Metallic BSDF (GGX, F82 white tint)"),
    "cod": (Features("none", "cod"), "brute", "CoD WWII multiscattering diffuse vs its integral"),
    "wrapped": (Features("none", "wrapped"), "brute", "wrapped diffuse vs its integral"),
    "cod_wrapped": (Features("none", "cod_wrapped"), "brute",
                    "CoD multiscattering wrapped diffuse (tilted normal + CoD LTC) vs the integral of its BRDF"),
    "cloth": (Features("none", "lambert", cloth=True), "brute", "Ashikhmin cloth vs its integral"),
    "sheen": (Features("none", "lambert", sheen=True), "brute", "Disney sheen vs its integral"),
    "kulla_conty": (Features("kulla_conty", "lambert"), "brute",
                    "Kulla-Conty GGX with coloured F0 vs the integral of f_ss + F_ms f_ms"),
    "turquin_color": (Features("turquin", "lambert"), "brute",
                      "Turquin GGX with coloured F0 vs the integral of its BRDF f_ss (1 + F0 (1 - E)/E)"),
    "kulla_conty_white": (Features("kulla_conty", "lambert"), "cycles",
                          "Kulla-Conty GGX, F0 = 1, vs Cycles Glossy Multiscatter GGX"),
    # Metallic 0.5 (issue 17, item 5): the dielectric and the metal shaded apart and mixed, against the same mix
    # of Cycles closures, each with Cycles' own multiple scattering (Metallic BSDF Multiscatter GGX)
    "mix_turquin": (Features("turquin", "lambert"), "cycles", MIX_TRUTH.format("Turquin")),
    "mix_fdez_aguera": (Features("fdez_aguera", "lambert"), "cycles", MIX_TRUTH.format("Fdez-Aguera (talk's area form)")),
    "mix_kulla_conty": (Features("kulla_conty", "lambert"), "cycles", MIX_TRUTH.format("Kulla-Conty")),
}
#: The metallic-mix techniques' Metallic.
MIX_METALLIC = 0.5


#: The rough diffuse (core/rough_diffuse.py) against Cycles' own: the Diffuse BSDF with Roughness sigma is the
#: closure Principled's Diffuse Roughness makes (the same Oren-Nayar, measured: scripts/validate_rough_diffuse.py).
#: Beside it the talk's CoD diffuse against the same reference, its Roughness set to sigma: what to pick.
TECHNIQUES["oren_nayar"] = (Features("none", "oren_nayar"), "cycles",
                            "rough diffuse (Fujii + EON, as Cycles) vs Cycles Diffuse BSDF with Roughness sigma")
TECHNIQUES["cod_cycles"] = (Features("none", "cod"), "cycles",
                            "CoD WWII diffuse with Roughness = sigma vs Cycles Diffuse BSDF with Roughness sigma")
#: Base colour of the rough-diffuse variants (the multiple scattering's colour is non-linear in it).
ROUGH_DIFFUSE_COLOR = (0.8, 0.55, 0.3)
#: Sheen (issue 17): Zeltner's against Cycles' own closures (the variant's roughness is the sheen roughness);
#: both Disney sheens against their integral.
TECHNIQUES.update({
    "zeltner": (Features("none", "lambert", sheen="zeltner"), "cycles",
                "Zeltner sheen vs Cycles Sheen BSDF (Microfiber)"),
    "zeltner_principled": (Features("none", "lambert", sheen="zeltner"), "cycles",
                           "Lambert under Zeltner sheen (Principled's layering) vs Cycles Principled BSDF with "
                           "Specular IOR Level 0"),
    "disney_fitted": (Features("none", "lambert", sheen="disney_fitted"), "brute",
                      "Disney sheen with its fitted LTC vs its integral"),
})
#: The Principled material of "zeltner_principled": base colour and sheen weight.
ZELTNER_PRINCIPLED = {"Base Color": (0.5, 0.3, 0.2), "Sheen Weight": 0.8}


def technique_material(technique, roughness=0.5, color=None, wrap=0.5):
    """RT Lit input values of a variant (the inputs not given keep RT_LIT_INPUTS' defaults).  The diffuse,
    cloth and sheen techniques are built without specular (``TECHNIQUES``: specular "none"); Metallic 1
    removes the diffuse where only cloth or sheen is measured."""
    m = {"Roughness": float(roughness), "Base Color": WHITE, "Metallic": 0.0, "Cloth Weight": 0.0,
         "Cloth Color": BLACK, "Sheen Weight": 0.0, "Wrap": 0.0}
    if technique in ("lambert", "cod", "wrapped", "cod_wrapped"):
        m.update({"Base Color": color or WHITE})
        if technique in ("wrapped", "cod_wrapped"):
            m["Wrap"] = float(wrap)
    elif technique in ("ggx", "turquin", "fdez_aguera", "kulla_conty_white"):
        m.update({"Metallic": 1.0, "Base Color": WHITE})
    elif technique.startswith("mix_"):
        m.update({"Metallic": MIX_METALLIC, "Base Color": color or (0.95, 0.64, 0.54), "IOR": 1.5,
                  "Specular IOR Level": 0.5})
    elif technique in ("metal", "kulla_conty", "turquin_color"):
        m.update({"Metallic": 1.0, "Base Color": color or (0.95, 0.64, 0.54)})
    elif technique == "dielectric":
        m.update({"Base Color": color or (0.5, 0.25, 0.1), "IOR": 1.5, "Specular IOR Level": 0.5})
    elif technique == "cloth":
        m.update({"Metallic": 1.0, "Cloth Weight": 1.0, "Cloth Color": color or WHITE})
    elif technique in ("sheen", "disney_fitted"):
        m.update({"Metallic": 1.0, "Sheen Weight": 1.0, "Sheen Tint": color or WHITE})
    elif technique in ("oren_nayar", "cod_cycles"):
        m.update({"Base Color": color or ROUGH_DIFFUSE_COLOR, "Diffuse Roughness": float(roughness)})
    elif technique == "zeltner":
        m.update({"Metallic": 1.0, "Sheen Weight": 1.0, "Sheen Tint": color or WHITE, "Sheen Roughness": float(roughness)})
    elif technique == "zeltner_principled":
        m.update({"Base Color": color or ZELTNER_PRINCIPLED["Base Color"], "Sheen Weight": ZELTNER_PRINCIPLED["Sheen Weight"],
                  "Sheen Tint": WHITE, "Sheen Roughness": float(roughness)})
    else:
        raise ValueError(f"unknown technique {technique!r}")
    return m


@dataclass(frozen=True)
class Variant:
    """One sphere of a case: a technique (a key of ``techniques``: (features, truth, text)) and its
    material values.  The world validation's variants (world_cases.WorldVariant) share it."""
    technique: str
    roughness: float = 0.5
    color: tuple | None = None
    wrap: float = 0.5
    techniques: ClassVar[dict] = TECHNIQUES

    @property
    def features(self):
        return self.techniques[self.technique][0]

    @property
    def truth(self):
        return self.techniques[self.technique][1]

    @property
    def label(self):
        s = f"{self.technique} r={self.roughness:g}"
        if self.technique in ("wrapped", "cod_wrapped"):
            s += f" w={self.wrap:g}"
        return s

    def material(self):
        return technique_material(self.technique, self.roughness, self.color, self.wrap)


@dataclass
class LightSpec:
    kind: str                       # quad, disk, point, spot, sun; sphere, spot_sphere (radius > 0), sun_disk (angle > 0)
    location: tuple
    energy: float
    size: float = 1.0
    size_y: float | None = None     # RECTANGLE / ELLIPSE when given
    target: tuple = (0.0, 0.0, 0.0)
    color: tuple = WHITE
    spot_size: float = 0.9
    spot_blend: float = 0.3
    #: RT Lookdev's light controls (addon/light_controls.py): custom property -> value, e.g. {"rtl_use_range": True}
    controls: dict = field(default_factory=dict)
    #: Blender's light model (issue 27): the radius of sphere lights, Soft Falloff, the sun's angle, the area light's
    #: spread, other light data settings (exposure, normalize, use_temperature, temperature), the node tree's Emission
    #: (strength, colour) or None, the object's scale (a mirror), and the variants light linking excludes
    radius: float = 0.0
    soft_falloff: bool = True
    angle: float = 0.0
    spread: float = math.pi
    settings: dict = field(default_factory=dict)
    emission: tuple | None = None
    scale: tuple = (1.0, 1.0, 1.0)
    excludes: tuple = ()

    @property
    def pool(self):
        """The light's name in the pooled statistics and gates: its kind, and what of Blender's light model it shows
        beyond it ("quad_spread", "point_units", "quad_mirrored", "point_linked")."""
        out = self.kind
        if self.spread < math.pi - 1e-6:
            out += "_spread"
        if self.settings or self.emission is not None:
            out += "_units"
        if any(s < 0 for s in self.scale):
            out += "_mirrored"
        if self.excludes:
            out += "_linked"
        return out

    def describe(self):
        x, y, z = self.location
        s = f"{self.kind} at ({x:.2f}, {y:.2f}, {z:.2f})"
        if self.kind in ("quad", "disk"):
            s += f" size {self.size:.2f}" + (f" x {self.size_y:.2f}" if self.size_y else "")
        if self.kind in ("sphere", "spot_sphere"):
            s += f" radius {self.radius:g} m" + ("" if self.soft_falloff else " (sphere)")
        if self.kind == "sun_disk":
            s += f" angle {math.degrees(self.angle):g} deg"
        if self.spread < math.pi - 1e-6:
            s += f" spread {math.degrees(self.spread):.0f} deg"
        extra = [f"{k} {v:g}" if isinstance(v, float) else f"{k} {v}" for k, v in self.settings.items()]
        if self.emission is not None:
            extra.append(f"node tree emission {self.emission[0]:g}")
        if any(s < 0 for s in self.scale):
            extra.append(f"scale {tuple(self.scale)}")
        if self.excludes:
            extra.append(f"linking excludes spheres {list(self.excludes)}")
        on = [k[len("rtl_"):] for k, v in self.controls.items() if v is True]
        return s + f", energy {self.energy:g}" + (f", {'/'.join(on)}" if on else "") + \
            (f", {', '.join(extra)}" if extra else "")


@dataclass
class Case:
    name: str
    lights: list
    variants: list
    columns: int = 4
    description: str = ""
    tags: dict = field(default_factory=dict)

    @property
    def light_kinds(self):
        return sorted({l.pool for l in self.lights})


CELL = 2.2                          # world units per sphere cell
#: Least distance of a sphere centre in front of an area light's plane (sphere radius 1).
MIN_CLEARANCE = 1.6


def sphere_centres(case):
    n = len(case.variants)
    cols = min(case.columns, n)
    rows = math.ceil(n / cols)
    out = []
    for i in range(n):
        r, c = divmod(i, cols)
        out.append(((c - 0.5 * (cols - 1)) * CELL, 0.0, (0.5 * (rows - 1) - r) * CELL))
    return out, cols, rows


def _spherical(rng, dist, elev_lo, elev_hi, az_lo=-70.0, az_hi=70.0):
    """A point at ``dist`` from the origin on the camera's side (-Y), elevation/azimuth in degrees."""
    el = math.radians(rng.uniform(elev_lo, elev_hi))
    az = math.radians(rng.uniform(az_lo, az_hi))
    return (dist * math.cos(el) * math.sin(az), -dist * math.cos(el) * math.cos(az), dist * math.sin(el))


def _area_power(kind, size, size_y, dist, target_radiance):
    """Power giving the light the radiance that makes ~target irradiance at distance ``dist``."""
    area = size * (size_y or size) * (math.pi / 4 if kind == "disk" else 1.0)
    return float(target_radiance * math.pi * area)


def _keep_in_front(light, centres, clearance=MIN_CLEARANCE):
    """Move the light back along its axis until every sphere centre lies at least ``clearance``
    in front of its plane: no sphere crosses the light's plane (a unit sphere at clearance 1.6 keeps
    0.6 from it), so every shading point is on the lit side or sees the light from behind as a
    whole; spheres still see the light partly below their horizon near the terminator."""
    loc = np.array(light.location, np.float64)
    axis = np.array(light.target, np.float64) - loc
    axis /= np.linalg.norm(axis)
    depth = min(float((np.asarray(c) - loc) @ axis) for c in centres)
    if depth < clearance:
        shift = axis * (depth - clearance)
        light.location = tuple(float(x) for x in loc + shift)
        light.target = tuple(float(x) for x in np.array(light.target) + shift)


def build_cases(seed=0, quick=False):
    """The built-in suite.  ``quick``: a small subset (the CI test's)."""
    rng = np.random.default_rng(seed)
    closure_row = [Variant("lambert"), Variant("ggx", 0.25), Variant("ggx", 0.5), Variant("ggx", 0.8),
                   Variant("turquin", 0.6), Variant("fdez_aguera", 0.6), Variant("dielectric", 0.4),
                   Variant("metal", 0.5)]
    brute_row = [Variant("cod", 0.5), Variant("wrapped", 0.5, wrap=0.5), Variant("cloth", 0.5),
                 Variant("sheen", 0.5), Variant("kulla_conty", 0.7), Variant("turquin_color", 0.7),
                 Variant("lambert"), Variant("ggx", 0.5), Variant("cod_wrapped", 0.5, wrap=0.5),
                 Variant("cod_wrapped", 0.8, wrap=1.0)]
    cases = []
    # area lights: (kind, size, size_y, distance, tilt deg, elevation range)
    configs = [("quad", 1.0, None, 3.0, 0.0), ("quad", 2.5, 1.2, 2.5, 25.0), ("quad", 0.5, None, 4.0, 10.0),
               ("quad", 4.0, 2.0, 2.2, 40.0), ("disk", 1.2, None, 3.0, 0.0), ("disk", 3.0, 1.5, 2.4, 30.0),
               ("disk", 0.6, None, 4.0, 15.0)]
    if quick:
        configs = [("quad", 1.5, None, 3.0, 15.0), ("disk", 1.5, None, 3.0, 15.0)]
    for i, (kind, size, size_y, dist, tilt) in enumerate(configs):
        loc = _spherical(rng, dist, -20.0, 60.0)
        # tilt: aim at a point off the sphere centre, perpendicular to the light's direction
        off = np.cross(np.array(loc), [0.0, 0.0, 1.0])
        off = off / max(np.linalg.norm(off), 1e-9) * dist * math.tan(math.radians(tilt))
        target = tuple(float(x) for x in off)
        # radiance so the brightest pixel is O(1): L A / d^2 ~ 1
        radiance = dist * dist / (size * (size_y or size))
        light = LightSpec(kind, tuple(float(x) for x in loc), _area_power(kind, size, size_y, dist, radiance),
                          size, size_y, target)
        _keep_in_front(light, sphere_centres(Case("", [], closure_row, columns=4))[0])
        # every sphere of a row sees the light from a different direction; the row's width
        # (4 cells, 8.8 units) puts the outer spheres' lights at up to ~70 deg off their centre
        cases.append(Case(f"{kind}{i}_closures", [light], closure_row if not quick else
                          [Variant("lambert"), Variant("ggx", 0.5), Variant("turquin", 0.6)],
                          columns=4, description=f"{light.describe()}, tilt {tilt:g} deg: Cycles-closure techniques",
                          tags={"light": kind, "tilt": tilt, "distance": dist}))
        if not quick and i in (0, 1, 4, 5):
            cases.append(Case(f"{kind}{i}_brute", [light], brute_row, columns=4,
                              description=f"{light.describe()}, tilt {tilt:g} deg: techniques without a "
                                          "Cycles closure, against brute-force integrals",
                              tags={"light": kind, "tilt": tilt, "distance": dist}))
    if quick:
        cases.append(Case("quad_brute", [cases[0].lights[0]],
                          [Variant("cod", 0.5), Variant("cloth", 0.5), Variant("kulla_conty", 0.7)], columns=3,
                          description="brute-force subset", tags={"light": "quad"}))
        cases.append(Case("point", [LightSpec("point", (1.5, -3.0, 1.5), 400.0)],
                          [Variant("lambert"), Variant("ggx", 0.5)], columns=2,
                          description="point light, radius 0", tags={"light": "point"}))
        return cases
    # roughness sweep, dielectric and metal, under a rectangle
    sweep = [Variant("dielectric", r) for r in (0.1, 0.3, 0.5, 0.7, 0.9)] + \
            [Variant("metal", r, (0.95, 0.64, 0.54)) for r in (0.1, 0.3, 0.5, 0.7, 0.9)]
    light = LightSpec("quad", (1.5, -3.0, 2.0), _area_power("quad", 2.0, 1.0, 3.0, 4.5), 2.0, 1.0)
    cases.append(Case("quad_sweep", [light], sweep, columns=5,
                      description=f"{light.describe()}: dielectric (top) and metal (bottom), r = 0.1 ... 0.9",
                      tags={"light": "quad"}))
    light = LightSpec("disk", (-2.0, -2.5, 1.5), _area_power("disk", 1.5, None, 3.0, 4.0), 1.5)
    cases.append(Case("disk_sweep", [light], sweep, columns=5,
                      description=f"{light.describe()}: dielectric (top) and metal (bottom), r = 0.1 ... 0.9",
                      tags={"light": "disk"}))
    # punctual lights (deterministic in Cycles: radius 0 / angle 0)
    punctual_row = [Variant("lambert"), Variant("ggx", 0.3), Variant("ggx", 0.7), Variant("turquin", 0.6),
                    Variant("dielectric", 0.4), Variant("metal", 0.5), Variant("fdez_aguera", 0.6),
                    Variant("kulla_conty_white", 0.6)]
    cases.append(Case("point", [LightSpec("point", (1.5, -3.0, 1.5), 400.0)], punctual_row, columns=3,
                      description="point light, radius 0", tags={"light": "point"}))
    cases.append(Case("spot", [LightSpec("spot", (-1.0, -4.0, 2.0), 800.0, spot_size=1.0, spot_blend=0.3)],
                      punctual_row, columns=3, description="spot light, radius 0, cone 57 deg, blend 0.3",
                      tags={"light": "spot"}))
    cases.append(Case("sun", [LightSpec("sun", (0.0, -3.0, 3.0), 2.0, target=(0.3, 0.0, -0.2))], punctual_row,
                      columns=3, description="sun, angle 0", tags={"light": "sun"}))
    # the techniques without a Cycles closure under the punctual lights: their exact BRDF, evaluated in float64
    # numpy from the light's own data (issue 17, item 6)
    punctual_brute = [Variant("cod", 0.5), Variant("wrapped", 0.5, wrap=0.5), Variant("cloth", 0.5),
                      Variant("sheen", 0.5), Variant("kulla_conty", 0.7), Variant("turquin_color", 0.7),
                      Variant("cod_wrapped", 0.5, wrap=0.5)]
    for case in [c for c in cases if c.name in ("point", "spot", "sun")]:
        cases.append(Case(f"{case.name}_brute", case.lights, punctual_brute, columns=3,
                          description=f"{case.description}: techniques without a Cycles closure, against their "
                                      "BRDF at the light's direction", tags=dict(case.tags)))
    # Metallic 0.5 under each kind of light: the multiple-scattering models with dielectric and metal apart
    mix_row = [Variant(t, r) for t in ("mix_turquin", "mix_fdez_aguera", "mix_kulla_conty") for r in (0.3, 0.6, 0.9)]
    for spec in (LightSpec("quad", (1.5, -3.0, 2.0), _area_power("quad", 2.0, 1.0, 3.0, 4.5), 2.0, 1.0),
                 LightSpec("disk", (-2.0, -2.5, 1.5), _area_power("disk", 1.5, None, 3.0, 4.0), 1.5),
                 LightSpec("point", (1.5, -3.0, 1.5), 400.0)):
        cases.append(Case(f"metallic_mix_{spec.kind}", [spec], mix_row, columns=3,
                          description=f"{spec.describe()}: Turquin, Fdez-Aguera, Kulla-Conty (rows) at Metallic 0.5, "
                                      "r = 0.3, 0.6, 0.9", tags={"light": spec.kind}))
    cases += rough_diffuse_cases(cases)
    cases += sheen_cases(cases)
    cases += light_model_cases()
    return cases


#: The rows of the light-model cases: Cycles closures (Lambert, GGX r = 0.1 ... 1, Turquin, the dielectric and the
#: metal) and the demo scene's techniques without one (against the integral of their BRDF over the true emitter).
LIGHT_MODEL_ROW = [Variant("lambert"), Variant("ggx", 0.1), Variant("ggx", 0.3), Variant("ggx", 0.5),
                   Variant("ggx", 0.8), Variant("ggx", 1.0), Variant("turquin", 0.6), Variant("dielectric", 0.4),
                   Variant("metal", 0.5), Variant("cod", 0.5), Variant("cod_wrapped", 0.5, wrap=0.5),
                   Variant("cloth", 0.5), Variant("kulla_conty", 0.7), Variant("zeltner", 0.5)]
#: A shorter row for the settings that only scale or orient a light.
LIGHT_SETTINGS_ROW = [Variant("lambert"), Variant("ggx", 0.1), Variant("ggx", 0.4), Variant("turquin", 0.7),
                      Variant("metal", 0.5), Variant("cod", 0.5)]


def light_model_cases():
    """Blender's light model (issue 27): sphere lights (radius 0.05, 0.1, 0.25 m, their surfaces 1-3 m from the
    spheres', Soft Falloff on and off), a spot with a radius, suns of angle 0.5, 2 and 10 deg, area lights with a
    spread, exposure, temperature, Normalize off and a node tree's emission, mirrored lights and light linking."""
    def case(name, spec, row, text):
        return Case(name, [spec], row, columns=5 if len(row) > 6 else 3, description=f"{spec.describe()}: {text}",
                    tags={"light": spec.pool})

    full, short = LIGHT_MODEL_ROW, LIGHT_SETTINGS_ROW
    out = [
        case("sphere_r005", LightSpec("sphere", (1.0, -2.4, 1.3), 300.0, radius=0.05), full,
             "sphere light (Soft Falloff), the row's techniques"),
        case("sphere_r01_hard", LightSpec("sphere", (-1.5, -3.0, 1.6), 500.0, radius=0.1, soft_falloff=False), full,
             "sphere light without Soft Falloff, the row's techniques"),
        case("sphere_r025", LightSpec("sphere", (0.6, -2.3, -0.9), 250.0, radius=0.25), full,
             "large sphere light, the row's techniques"),
        case("spot_sphere", LightSpec("spot_sphere", (-1.0, -3.6, 1.8), 900.0, radius=0.15, spot_size=1.0,
                                      spot_blend=0.3), short, "spot light with a radius"),
        case("spread_quad", LightSpec("quad", (1.2, -2.8, 1.8), _area_power("quad", 2.0, None, 3.0, 4.0), 2.0,
                                      spread=math.radians(60.0)), short, "area light with spread 60 deg"),
        case("spread_disk", LightSpec("disk", (-1.5, -2.6, 1.2), _area_power("disk", 2.0, None, 3.0, 4.0), 2.0,
                                      spread=math.radians(90.0)), short, "disk light with spread 90 deg"),
        case("units_point", LightSpec("point", (1.5, -3.0, 1.5), 150.0,
                                      settings={"exposure": 1.5, "use_temperature": True, "temperature": 4000.0,
                                                "normalize": False}), short,
             "exposure, temperature and Normalize off"),
        case("units_quad", LightSpec("quad", (-1.2, -3.0, 1.5), _area_power("quad", 1.5, None, 3.0, 4.0), 1.5,
                                     settings={"normalize": False, "exposure": -1.0}, emission=(0.5, (1.0, 0.7, 0.4))),
             short, "Normalize off, exposure and a node tree's emission"),
        case("mirrored_quad", LightSpec("quad", (1.0, -3.0, 1.0), _area_power("quad", 1.5, 0.8, 3.0, 4.0), 1.5, 0.8,
                                        scale=(-1.0, 1.0, 1.0)), short, "area light mirrored in X"),
        case("linked_point", LightSpec("point", (0.5, -3.0, 1.5), 400.0, excludes=(0, 2)), short,
             "light linking excludes two spheres"),
    ]
    for c in out:
        if c.lights[0].kind in ("quad", "disk"):
            _keep_in_front(c.lights[0], sphere_centres(c)[0])
    for angle in (0.5, 2.0, 10.0):
        out.append(case(f"sun_disk_{angle:g}", LightSpec("sun_disk", (0.0, -3.0, 3.0), 2.0, target=(0.3, 0.0, -0.2),
                                                          angle=math.radians(angle)),
                        short, f"sun of angle {angle:g} deg"))
    return out


def rough_diffuse_cases(cases):
    """The rough diffuse and CoD against Cycles' Diffuse BSDF with Roughness sigma, under the lights of two quad,
    two disk and the point, spot and sun cases of ``cases`` (the same light objects)."""
    row = ([Variant("oren_nayar", r) for r in (0.3, 0.6, 1.0)] + [Variant("cod_cycles", r) for r in (0.3, 0.6, 1.0)])
    out = []
    for case in cases:
        if case.name in ("quad0_closures", "quad1_closures", "disk4_closures", "disk5_closures", "point", "spot",
                         "sun"):
            name = case.name.replace("_closures", "")
            out.append(Case(f"{name}_rough_diffuse", case.lights, row, columns=3,
                            description=f"{case.lights[0].describe()}: Oren-Nayar (top) and CoD (bottom), "
                                        "sigma = 0.3, 0.6, 1, vs Cycles' rough Diffuse BSDF",
                            tags=dict(case.tags, rough_diffuse=True)))
    return out


#: The sheen row (issue 17): Zeltner at three sheen roughnesses and under Principled's layering (Cycles truth),
#: the fitted and the talk's Disney sheen (brute force).
SHEEN_ROW = [Variant("zeltner", 0.2), Variant("zeltner", 0.5), Variant("zeltner", 0.9),
             Variant("zeltner_principled", 0.5), Variant("disney_fitted"), Variant("sheen")]


def sheen_cases(cases):
    """The sheen row under the lights of the quad0, quad1, disk4, disk5, point, spot and sun cases."""
    out = []
    for case in cases:
        stem = case.name.replace("_closures", "")
        if stem in ("quad0", "quad1", "disk4", "disk5", "point", "spot", "sun"):
            out.append(Case(f"{stem}_sheen", case.lights, SHEEN_ROW, columns=3,
                            description=f"{case.lights[0].describe()}: sheen models", tags=dict(case.tags)))
    return out


# --- scene ------------------------------------------------------------------------------------

def _aim(obj, target):
    import mathutils

    direction = mathutils.Vector(target) - obj.location
    obj.rotation_mode = "QUATERNION"
    obj.rotation_quaternion = direction.to_track_quat("-Z", "Y")


#: Blender light type of each LightSpec kind.
_LIGHT_TYPES = {"quad": "AREA", "disk": "AREA", "point": "POINT", "spot": "SPOT", "sun": "SUN", "sphere": "POINT",
                "spot_sphere": "SPOT", "sun_disk": "SUN"}


def _light_object(bpy, scene, name, spec):
    """A light object as ``spec`` describes it, linked to ``scene`` and aimed at its target."""
    data = bpy.data.lights.new(name, _LIGHT_TYPES[spec.kind])
    data.energy = spec.energy
    data.color = spec.color
    if spec.kind in ("quad", "disk"):
        shape = {"quad": ("SQUARE", "RECTANGLE"), "disk": ("DISK", "ELLIPSE")}[spec.kind]
        data.shape = shape[1] if spec.size_y else shape[0]
        data.size = spec.size
        data.size_y = spec.size_y or spec.size
        data.spread = spec.spread
    elif spec.kind in ("point", "spot", "sphere", "spot_sphere"):
        data.shadow_soft_size = spec.radius if spec.kind in ("sphere", "spot_sphere") else 0.0
        data.use_soft_falloff = spec.soft_falloff
        if spec.kind in ("spot", "spot_sphere"):
            data.spot_size, data.spot_blend = spec.spot_size, spec.spot_blend
    else:
        data.angle = spec.angle if spec.kind == "sun_disk" else 0.0
    for key, value in spec.settings.items():
        setattr(data, key, value)
    if spec.emission is not None:
        data.use_nodes = True
        node = next(n for n in data.node_tree.nodes if n.bl_idname == "ShaderNodeEmission")
        node.inputs["Strength"].default_value = spec.emission[0]
        node.inputs["Color"].default_value = tuple(spec.emission[1]) + (1.0,)
    for key, value in spec.controls.items():
        data[key] = value
    obj = bpy.data.objects.new(name, data)
    obj.location = spec.location
    obj.visible_camera = False
    scene.collection.objects.link(obj)
    _aim(obj, spec.target)
    obj.scale = spec.scale
    return obj


def build_scene(case, cell_px, segments=192, rings=96, lut_dir=None):
    """Reset the file; lights, spheres with RT Lit materials, camera.  Returns (scene, spheres)."""
    from ..addon import compat
    import bpy

    from . import energy_render as validate_energy
    from ..addon import materials

    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    receivers = {}
    for i, spec in enumerate(case.lights):
        obj = _light_object(bpy, scene, f"L{i}_{spec.kind}", spec)
        if spec.excludes:
            receivers[i] = obj.light_linking.receiver_collection = bpy.data.collections.new(f"L{i} receivers")
    materials.sync_scene_lights(scene)

    centres, cols, rows = sphere_centres(case)
    mesh = validate_energy._uv_sphere_mesh(bpy, "RTL_val_sphere", segments, rings)
    spheres = []
    for i, (variant, centre) in enumerate(zip(case.variants, centres)):
        me = mesh.copy()
        mat = compat.new_material(f"RTL_val_{i}")
        materials.assign_rt_lit(mat, variant.features, scene, lut_dir)
        node = mat.node_tree.nodes["RT Lit"]
        for k, v in variant.material().items():
            node.inputs[k].default_value = tuple(v) + (1.0,) if isinstance(v, tuple) else v
        me.materials.append(mat)
        ob = bpy.data.objects.new(f"RTL_val_sphere_{i}", me)
        ob.location = centre
        for attr in ("visible_glossy", "visible_diffuse", "visible_transmission", "visible_volume_scatter",
                     "visible_shadow"):
            setattr(ob, attr, False)
        scene.collection.objects.link(ob)
        spheres.append(ob)
    for i, collection in receivers.items():
        for k in case.lights[i].excludes:
            collection.objects.link(spheres[k])
            collection.collection_objects[len(collection.objects) - 1].light_linking.link_state = "EXCLUDE"
    if receivers:
        materials.sync_scene_lights(scene)          # the excluded spheres' attributes (addon/light_model.py)
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.data.type = "ORTHO"
    cam.data.sensor_fit = "HORIZONTAL"
    cam.data.ortho_scale = CELL * cols
    cam.data.clip_start, cam.data.clip_end = 0.1, 100.0
    cam.location = (0.0, -20.0, 0.0)
    cam.rotation_euler = (math.pi / 2, 0.0, 0.0)
    scene.collection.objects.link(cam)
    scene.camera = cam
    scene.world = None
    scene.render.resolution_x = cell_px * cols
    scene.render.resolution_y = cell_px * rows
    return scene, spheres


def sphere_index(case, position, normal):
    """Per pixel: index of the sphere hit (-1 for background)."""
    centres, _, _ = sphere_centres(case)
    hit = np.linalg.norm(normal, axis=-1) > 0.5
    idx = np.full(hit.shape, -1, np.int64)
    for i, c in enumerate(centres):
        idx[hit & (np.linalg.norm(position - np.asarray(c), axis=-1) < 1.05)] = i
    return idx


# --- (b) numpy -------------------------------------------------------------------------------

def scene_light_params(scene, receiver=None):
    """[(kind, driver values)] of the scene's lights; the linking option's "Excluded" for the object ``receiver``."""
    from ..addon import light_model, materials

    return [(kind, light_model.light_parameters(obj, kind, receiver)) for obj, kind in materials.scene_lights(scene)]


def numpy_material(variant):
    """RT_LIT_INPUTS name -> the variant's value (the socket default where the variant sets none)."""
    from ..core.materials.rt_lit_interface import RT_LIT_INPUTS

    out = {}
    for name, sock in RT_LIT_INPUTS.items():
        v = variant.material().get(name, sock.default)
        if sock.kind == "float":
            out[name] = float(v)
        elif name == "Normal":
            out[name] = np.zeros(3)
        else:
            out[name] = np.array(list(v)[:3], dtype=np.float64)
    return out


def material_values(material):
    """Inputs of the RT Lit function from a material's RT Lit node (``materials.material_parameters``)."""
    from ..addon import materials

    return {k: (np.array(v) if isinstance(v, tuple) else v) for k, v in materials.material_parameters(material).items()}


def numpy_radiance(scene, variants, objects, passes, index, tables, world=None, dtype=np.float32):
    """(b): each sphere's RT Lit material, the core function the node groups are emitted from
    (``core.materials.rt_lit.build_rt_lit`` for its features, the scene's lights and the world), evaluated
    by the numpy backend at the render's Position / Normal passes with the material node's values, the
    lights' driver values and the world's parameters; float32 with Cycles' node semantics (float64 on
    request).  ``objects[i]`` carries variant i's material; ``world``: None or (WorldEnvironment, params)."""
    from ..core.materials import rt_lit
    from .engines import camera_incoming

    pos = passes["Position"].astype(np.float64)
    nrm = passes["Normal"].astype(np.float64)
    out = np.zeros(pos.shape)
    lights = scene_light_params(scene)
    env, world_params = world if world is not None else (None, {})
    for i, variant in enumerate(variants):
        mine = index == i
        if not mine.any():
            continue
        material = rt_lit.build_rt_lit(variant.features, tuple(kind for kind, _ in lights), env)
        lights = scene_light_params(scene, objects[i])
        values = material_values(objects[i].data.materials[0])
        values.update({"Position": pos[mine], "Geometry Normal": nrm[mine],
                       "Incoming": camera_incoming(scene, pos[mine])})
        for names, (_, params) in zip(material.light_inputs, lights):
            values.update({names[p]: params[p] for p in names})
        values.update({material.world_inputs[p]: v for p, v in world_params.items()})
        out[mine] = material.evaluate(values, tables, dtype)["Radiance"]
    return out


def conditioning(fn, passes, b=None):
    """(b) = fn(passes, float32) (computed unless given) and, per value, how far float32 rounding moves
    it: the float64 evaluation moved by one float32 ulp of position and normal (random signs), and
    float32 vs float64 at both positions (its internal rounding)."""
    b = fn(passes, np.float32) if b is None else b
    b64 = fn(passes, np.float64)
    moved = dict(passes)
    signs = np.random.default_rng(17)
    for key in ("Position", "Normal"):
        x = passes[key].astype(np.float32)
        moved[key] = np.nextafter(x, np.where(signs.random(x.shape) < 0.5, -np.inf, np.inf).astype(np.float32))
    b64_moved = fn(moved, np.float64)
    b32_moved = fn(moved, np.float32)
    return b, np.maximum.reduce([np.abs(b - b64), np.abs(b64_moved - b64), np.abs(b32_moved - b64_moved)])


# --- (c) Cycles ground truth -----------------------------------------------------------------

def _closure_material(variant, name):
    from ..addon import compat

    mat = compat.new_material(name)
    nt = mat.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    m = variant.material()
    t = variant.technique

    def glossy(dist):
        g = nt.nodes.new("ShaderNodeBsdfGlossy")
        g.distribution = dist
        g.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
        g.inputs["Roughness"].default_value = m["Roughness"]
        g.inputs["Anisotropy"].default_value = 0.0
        return g

    def metallic(f0, dist="GGX"):
        g = nt.nodes.new("ShaderNodeBsdfMetallic")
        g.distribution = dist
        g.fresnel_type = "F82"
        g.inputs["Base Color"].default_value = tuple(f0) + (1.0,)
        g.inputs["Edge Tint"].default_value = (1.0, 1.0, 1.0, 1.0)
        g.inputs["Roughness"].default_value = m["Roughness"]
        g.inputs["Anisotropy"].default_value = 0.0
        return g

    def diffuse(color):
        d = nt.nodes.new("ShaderNodeBsdfDiffuse")
        d.inputs["Color"].default_value = tuple(color) + (1.0,)
        d.inputs["Roughness"].default_value = 0.0
        return d

    if t == "lambert":
        shader = diffuse(m["Base Color"])
    elif t in ("oren_nayar", "cod_cycles"):
        shader = diffuse(m["Base Color"])
        shader.inputs["Roughness"].default_value = m["Diffuse Roughness"]
    elif t == "ggx":
        shader = glossy("GGX")
    elif t in ("turquin", "fdez_aguera", "kulla_conty_white"):
        shader = glossy("MULTI_GGX")
    elif t == "metal":
        shader = metallic(m["Base Color"])
    elif t == "zeltner":
        shader = nt.nodes.new("ShaderNodeBsdfSheen")
        shader.distribution = "MICROFIBER"
        shader.inputs["Color"].default_value = tuple(np.multiply(m["Sheen Tint"], m["Sheen Weight"])) + (1.0,)
        shader.inputs["Roughness"].default_value = m["Sheen Roughness"]
    elif t == "zeltner_principled":
        shader = nt.nodes.new("ShaderNodeBsdfPrincipled")
        values = {"Base Color": tuple(m["Base Color"]) + (1.0,), "Metallic": 0.0, "Specular IOR Level": 0.0,
                  "Sheen Weight": m["Sheen Weight"], "Sheen Roughness": m["Sheen Roughness"],
                  "Sheen Tint": tuple(m["Sheen Tint"]) + (1.0,), "Coat Weight": 0.0, "Transmission Weight": 0.0,
                  "Subsurface Weight": 0.0, "Diffuse Roughness": 0.0}
        for name, value in values.items():
            if name in shader.inputs:              # Diffuse Roughness: Blender 4.3+
                shader.inputs[name].default_value = value
    elif t == "dielectric" or t.startswith("mix_"):
        from ..core.materials.surface import dielectric_f0

        dist = "MULTI_GGX" if t.startswith("mix_") else "GGX"
        f0 = float(dielectric_f0(np.float64(m["IOR"]), np.float64(m["Specular IOR Level"])))
        add = nt.nodes.new("ShaderNodeAddShader")
        nt.links.new(metallic((f0, f0, f0), dist).outputs[0], add.inputs[0])
        nt.links.new(diffuse(m["Base Color"]).outputs[0], add.inputs[1])
        shader = add
        if t.startswith("mix_"):
            mix = nt.nodes.new("ShaderNodeMixShader")
            mix.inputs["Fac"].default_value = m["Metallic"]
            nt.links.new(add.outputs[0], mix.inputs[1])
            nt.links.new(metallic(m["Base Color"], dist).outputs[0], mix.inputs[2])
            shader = mix
    else:
        raise ValueError(f"{t} has no Cycles closure")
    nt.links.new(shader.outputs[0], out.inputs["Surface"])
    return mat


def configure_truth_render(scene, samples, seed, threads=2):
    from ..addon import compat
    from .render_setup import configure_cycles_measurement

    configure_cycles_measurement(scene, samples, seed, threads)
    c = scene.cycles
    c.max_bounces = 0                 # direct light only: spheres are convex and see nothing else
    c.blur_glossy = 0.0
    c.caustics_reflective = True
    c.caustics_refractive = True
    vl = scene.view_layers[0]
    vl.use_pass_combined = True
    vl.use_pass_normal = True
    vl.use_pass_position = False
    s = scene.render.image_settings
    compat.set_exr_output(s, multilayer=True)
    s.exr_codec = "ZIP"


def render_truth(case, scene, spheres, samples, seeds, folder, threads=2):
    """(c) for the Cycles-closure variants: one render per seed.  Returns ([rgb per seed], seconds
    per seed, normal) or None when no variant uses Cycles."""
    from . import energy_render as validate_energy

    todo = [i for i, v in enumerate(case.variants) if v.truth == "cycles"]
    if not todo:
        return None
    saved = []
    for i, ob in enumerate(spheres):
        saved.append((ob.data.materials[0], ob.hide_render))
        if i in todo:
            ob.data.materials[0] = _closure_material(case.variants[i], f"RTL_truth_{i}")
        else:
            ob.hide_render = True
    images, seconds, normal = [], [], None
    try:
        for seed in seeds:
            configure_truth_render(scene, samples, seed, threads)
            path = Path(folder) / f"truth_seed{seed}.exr"
            seconds.append(validate_energy.render_exr(scene, path))
            rgb, nrm = validate_energy.read_passes(path)
            images.append(rgb)
            normal = nrm
    finally:
        for ob, (mat, hidden) in zip(spheres, saved):
            ob.data.materials[0] = mat
            ob.hide_render = hidden
    return images, seconds, normal


# --- (c) brute-force ground truth -------------------------------------------------------------

def _area_geometry(kind, params, position=None):
    """The light's true emitter, as Cycles samples it, for the brute-force integral: geometry and radiance without
    its options' falloff (``core.lights.control_factor``) and without the spread (its weight is taken per direction:
    ``_direction_weight``); a sphere light's or a sun's disk facing ``position``, a spot sphere's without its cone
    (taken per direction too)."""
    from ..core import lights as core_lights

    base = core_lights.base_kind(kind)
    data = core_lights.LIGHT_DATA["sphere" if base == "spot_sphere" else base]
    args = {k: np.float64(v) for k, v in params.items() if k in data.input_sockets}
    if "Position" in data.input_sockets:
        args["Position"] = np.asarray(position, np.float64)
    out = {k: np.asarray(v, np.float64) for k, v in data(**args).items()}
    if "p0" in out:
        return {"corners": np.stack([out[f"p{i}"] for i in range(4)]), "radiance": out["Radiance"]}
    return {"center": out["Center"], "u": out["Axis U"], "v": out["Axis V"], "radiance": out["Radiance"]}


def _direction_weight(kind, params, position, dirs, light_normal):
    """What Cycles multiplies the radiance of each direction ``dirs`` (from ``position`` towards the light) by: the
    spread's weight (kernel/light/area.h ``area_light_spread_attenuation``, core/light_spread.py) and a spot
    sphere's cone attenuation of the direction (kernel/light/spot.h); 1 for the other lights."""
    from ..core import light_spread, lights as core_lights

    base, options = core_lights.split_kind(kind)
    weight = np.ones(len(dirs))
    if "spread" in options:
        h = float(np.clip(params["Spread"] * 0.5, light_spread.MIN_HALF_SPREAD, light_spread.MAX_HALF_SPREAD))
        if params["Spread"] < np.pi - 1e-6:
            cos_a = np.clip(dirs @ light_normal, 1e-12, 1.0)
            tan_a = np.sqrt(np.maximum(1.0 - cos_a * cos_a, 0.0)) / cos_a
            weight *= np.maximum(1.0 - tan_a / np.tan(h), 0.0) * np.tan(h) / (np.tan(h) - h)
    if base == "spot_sphere":
        loc = np.array([params["Location X"], params["Location Y"], params["Location Z"]])
        if np.sum((loc - position) ** 2) > params["Radius"] ** 2:
            c = core_lights.spot_cosine(position, position + dirs, *(params[f"Rotation {a}"] for a in "WXYZ"),
                                        *(params[f"Scale {a}"] for a in "XYZ"), params["Determinant"])
            weight *= core_lights.spot_attenuation(c, params["Spot Size"], params["Spot Blend"])
    return weight


def _rule(kind, geo, p, clip_normal, panels, order):
    """Points relative to p (M, 3), area weights (M,), unit light normal, or None if unlit."""
    from ..core.ltc import reference

    if kind == "quad":
        rel = geo["corners"] - p
        normal = reference.newell_normal(rel)
        if rel[0] @ normal < 0.0:
            return None
        x, w = reference.polygon_rule(rel, clip_normal, panels, order)
    else:
        c = geo["center"] - p
        normal = np.cross(geo["u"], geo["v"])
        if c @ normal < 0.0:
            return None
        x, w = reference.disk_rule(c, geo["u"], geo["v"], clip_normal, panels, order)
    return x, w, normal / np.linalg.norm(normal)


def _surface(features, material, n, v):
    from ..core.materials.rt_lit_interface import RT_LIT_INPUTS
    from ..core.materials.surface import SURFACE

    return SURFACE(**{k: material[k] for k in RT_LIT_INPUTS}, **{"Geometry Normal": n, "Incoming": v})


def brute_force_radiance(case, scene, passes, index, pixel_cap, rng, tables, panels=8, order=8, only=None,
                         chunk=24):
    """(c) for the brute-force variants on at most ``pixel_cap`` seeded pixels per sphere.

    Returns (image with NaN where not computed, quadrature error estimate image, seconds per
    variant).  The error estimate is |I(panels) - I(panels / 2)| (reference._converged's check).
    Pixels are evaluated in chunks: the rule's points of ``chunk`` pixels go through one call of
    the shading function (numpy, float64; ``tables`` the LUT set the punctual GGX reads E from)."""
    from ..core import lights as core_lights
    from ..core.materials import light_shading
    from .engines import camera_incoming

    import bpy

    pos = passes["Position"].astype(np.float64)
    nrm = passes["Normal"].astype(np.float64)
    img = np.full(pos.shape, np.nan)
    qerr = np.full(pos.shape, np.nan)
    seconds = {}
    levels = (panels, max(panels // 2, 1))
    for i, variant in enumerate(case.variants):
        if (only is None and variant.truth != "brute") or (only is not None and i not in only):
            continue
        t0 = time.perf_counter()
        ys, xs = np.nonzero(index == i)
        if len(ys) > pixel_cap:
            pick = np.sort(rng.choice(len(ys), pixel_cap, replace=False))
            ys, xs = ys[pick], xs[pick]
        features = variant.features
        material = numpy_material(variant)
        lights = scene_light_params(scene, bpy.data.objects.get(f"RTL_val_sphere_{i}"))
        shade = functools.partial(light_shading.shade_function("sun", features), tables)
        unclipped = features.diffuse in ("wrapped", "cod_wrapped")
        P = pos[ys, xs]
        N = nrm[ys, xs] / np.linalg.norm(nrm[ys, xs], axis=-1, keepdims=True)
        V = camera_incoming(scene, P)
        surface = _surface(features, material, N, V)
        sums = np.zeros((len(levels), len(ys), 3))
        for kind, params in lights:
            form = core_lights.shading_form(kind)
            if form in ("quad", "disk"):
                facing = "Position" in core_lights.LIGHT_DATA[core_lights.base_kind(kind)].input_sockets
                geo = None if facing else _area_geometry(kind, params)
                # the options' falloff is constant over the light for one shading point
                control = np.broadcast_to(np.asarray(core_lights.control_factor(
                    kind, P, {k: np.float64(v) for k, v in params.items()}), np.float64), (len(ys),))
                for lev, level in enumerate(levels):
                    for start in range(0, len(ys), chunk):
                        owner, dirs, irr = [], [], []
                        for k in range(start, min(start + chunk, len(ys))):
                            light = _area_geometry(kind, params, P[k]) if facing else geo
                            rule = _rule(form, light, P[k], None if unclipped else N[k], level, order)
                            if rule is None or len(rule[1]) == 0:
                                continue
                            xr, w, ln = rule
                            r = np.linalg.norm(xr, axis=-1)
                            unit = xr / r[:, None]
                            weight = _direction_weight(kind, params, P[k], unit, ln)
                            owner.append(np.full(len(w), k))
                            dirs.append(unit)
                            irr.append((w * weight * np.abs(xr @ ln) / r ** 3)[:, None] * light["radiance"] * control[k])
                        if owner:
                            owner = np.concatenate(owner)
                            rad = _shade(shade, surface, owner, np.concatenate(dirs), np.concatenate(irr))
                            for ch in range(3):
                                sums[lev, :, ch] += np.bincount(owner, rad[:, ch], minlength=len(ys))
            else:
                # punctual: the true BRDF at the one light direction (no integral)
                args = {k: np.full(len(ys), v, np.float64) for k, v in params.items()}
                if "Position" in core_lights.light_data(kind).input_sockets:
                    args["Position"] = P
                light = core_lights.light_data(kind)(**args)
                L = np.broadcast_to(np.asarray(light["L"], np.float64), P.shape)
                E = np.broadcast_to(np.asarray(light["Irradiance"], np.float64), P.shape)
                sums += _shade(shade, surface, np.arange(len(ys)), L, E)[None]
        img[ys, xs] = sums[0]
        qerr[ys, xs] = np.abs(sums[0] - sums[1])
        seconds[i] = time.perf_counter() - t0
    return img, qerr, seconds


def _shade(shade, surface, owner, l, irradiance):
    """The material's punctual shading (radiance, (M, 3)) for directions l (M, 3) with irradiance
    (M, 3); surface values per pixel, ``owner`` the pixel of each direction."""
    kw = {}
    for name in shade.func.input_sockets:
        if name == "L":
            kw[name] = l
        elif name == "Irradiance":
            kw[name] = irradiance
        elif name == "Position":
            kw[name] = np.zeros(l.shape)
        else:
            val = np.asarray(surface[name], np.float64)
            if val.ndim == 0:
                kw[name] = np.full(len(owner), float(val))
            elif val.ndim == 1 and val.shape[0] == 3 and name not in ("N", "V"):
                kw[name] = np.broadcast_to(val, l.shape)
            else:
                kw[name] = val[owner]
    return np.asarray(shade(**kw)["Radiance"], np.float64).reshape(-1, 3)


# --- metrics ------------------------------------------------------------------------------------

#: A value may differ from (b) by this many times its float32 conditioning.
CONDITIONING_FACTOR = 4.0


def ab_metrics(a, b, mask, near_zero=1e-2, conditioning=None, tol=1e-4, atol=1e-6):
    """(a) vs (b): max relative difference where |b| >= near_zero, max abs difference below.

    With ``conditioning`` (per value: how much float32 rounding of the inputs and of the
    evaluation moves it, see validate.py), values whose difference exceeds ``tol`` x |b| but stays
    within CONDITIONING_FACTOR x conditioning are allowed (e.g. the edge of a spot light's cone,
    where the blend ramp amplifies the rounding of the cosine): ``max_rel_beyond_float32`` is the
    max relative difference over the other values; ``conditioned`` counts the allowed ones."""
    av, bv = a[mask].astype(np.float64), b[mask].astype(np.float64)
    err = np.abs(av - bv)
    big = np.abs(bv) >= near_zero
    out = {"max_rel": float((err[big] / np.abs(bv[big])).max()) if big.any() else 0.0,
           "max_abs_near_zero": float(err[~big].max()) if (~big).any() else 0.0,
           "values": int(av.size), "values_rel": int(big.sum()),
           "finite": bool(np.all(np.isfinite(a[mask])) and np.all(np.isfinite(b[mask])))}
    if conditioning is not None:
        cond = CONDITIONING_FACTOR * conditioning[mask].astype(np.float64)
        rel_fail = big & (err > tol * np.abs(bv))
        allowed = rel_fail & (err <= cond)
        beyond = big & ~allowed
        out["max_rel_beyond_float32"] = float((err[beyond] / np.abs(bv[beyond])).max()) if beyond.any() else 0.0
        abs_fail = ~big & (err > atol)
        abs_allowed = abs_fail & (err <= cond)
        small_beyond = ~big & ~abs_allowed
        out["max_abs_near_zero_beyond_float32"] = float(err[small_beyond].max()) if small_beyond.any() else 0.0
        out["conditioned"] = int(allowed.sum() + abs_allowed.sum())
    return out


#: Cycles' path-tracing error falls as spp^-k in these scenes (spheres seen by camera rays only, direct light),
#: not as 1/sqrt(spp) (k = 0.5): its stratified, scrambled sample sequences integrate the smooth direct-lighting
#: integrand faster.  Measured by validation/speed_error.py (docs/benchmarks/speed_error.md, "Path tracing's
#: error decay": relative RMS error of 1 ... 4096 spp ladders against 4096 spp x 2 references, median per family
#: under quad and disk lights; full run 2026-12-02): diffuse (Lambert) 1.09 (0.91-1.13, 5 spheres), glossy (GGX
#: r <= 0.3) 0.77 (0.74-0.86, 5), rough (GGX and Multiscatter GGX r > 0.3) 0.99 (0.81-1.07, 10).
CYCLES_ERROR_EXPONENTS = {"diffuse": 1.09, "glossy": 0.77, "rough": 0.99}
#: A variant without a family of its own (the suite's other closures) takes the pooled median.
CYCLES_ERROR_EXPONENT = 0.99
#: The same under a studio HDRI (the world validation): 0.66 median (0.62-0.70, forest and sunrise, 8 spheres).
CYCLES_WORLD_ERROR_EXPONENT = 0.66
#: Largest roughness of the "glossy" family (as validation/speed_error.py).
GLOSSY_MAX_ROUGHNESS = 0.3


def cycles_error_exponent(variant):
    """k of Cycles' error ~ spp^-k for a suite variant (``CYCLES_ERROR_EXPONENTS`` by its family)."""
    if variant.technique == "lambert":
        return CYCLES_ERROR_EXPONENTS["diffuse"]
    if variant.technique in ("ggx", "turquin", "fdez_aguera", "dielectric", "metal", "kulla_conty_white") \
            or variant.technique.startswith("mix_"):
        return CYCLES_ERROR_EXPONENTS["glossy" if variant.roughness <= GLOSSY_MAX_ROUGHNESS else "rough"]
    return CYCLES_ERROR_EXPONENT


def truth_metrics(a, c, mask, floor_frac, c_pair=None, samples_total=None, qerr=None,
                  error_exponent=CYCLES_ERROR_EXPONENT):
    """(a) vs (c) over the values (pixels x channels) of ``mask`` where c > floor_frac * max(c).

    ``c_pair``: the two seed images (c is their mean) for the Monte Carlo noise: per value
    sigma_c = |c1 - c2| / 2, an unbiased one-sample estimate of the noise of c (so the
    "noise_*" figures are what the error statistics would be if the node render were exact).
    ``error_exponent``: k of Cycles' error ~ spp^-k, for ``cycles_spp_to_match``.
    """
    av, cv = a[mask].astype(np.float64).ravel(), c[mask].astype(np.float64).ravel()
    ok = np.isfinite(cv)
    if not ok.any():
        return None
    cmax = float(np.max(cv[ok]))
    floor = floor_frac * cmax
    sel = ok & (cv > floor)
    if not sel.any():
        return None
    rel = np.abs(av[sel] - cv[sel]) / cv[sel]
    out = {"values": int(sel.sum()), "floor": floor, "c_max": cmax,
           "mean": float(rel.mean()), "median": float(np.median(rel)), "p90": float(np.percentile(rel, 90)),
           "max": float(rel.max()), "rmse": float(np.sqrt(np.mean((av[sel] - cv[sel]) ** 2))),
           "rms_rel": float(np.sqrt(np.mean(rel ** 2))),
           "bias_rel": float(np.mean((av[sel] - cv[sel]) / cv[sel]))}
    if c_pair is not None:
        c1, c2 = (x[mask].astype(np.float64).ravel()[sel] for x in c_pair)
        sig = np.abs(c1 - c2) / 2.0
        nrel = sig / cv[sel]
        out.update({"noise_mean": float(nrel.mean()), "noise_median": float(np.median(nrel)),
                    "noise_p90": float(np.percentile(nrel, 90)), "noise_rms_rel": float(np.sqrt(np.mean(nrel ** 2))),
                    "noise_rmse": float(np.sqrt(np.mean(sig ** 2)))})
        # Node render's own (systematic) error: the RMS relative error with the noise's share removed.
        own = math.sqrt(max(out["rms_rel"] ** 2 - out["noise_rms_rel"] ** 2, 0.0))
        out["node_rms_rel_excess"] = own
        if samples_total:
            # Cycles noise ~ spp^-k (``error_exponent``, measured: CYCLES_ERROR_EXPONENT): samples for Cycles' own
            # RMS relative noise to equal the node render's error (the two seeds' samples counted as one render's).
            # Below the noise floor of this comparison the figure is a lower bound.
            resolved = own > 0.5 * out["noise_rms_rel"]
            eff = own if resolved else 0.5 * out["noise_rms_rel"]
            out["cycles_spp_to_match"] = (float(samples_total * (out["noise_rms_rel"] / eff) ** (1.0 / error_exponent))
                                          if eff > 0 else None)
            out["cycles_spp_to_match_is_lower_bound"] = not resolved
    if qerr is not None:
        qv = qerr[mask].astype(np.float64).reshape(-1)[sel] / cv[sel]
        out.update({"quadrature_rel_median": float(np.median(qv)), "quadrature_rel_max": float(qv.max())})
    return out
