"""The cases of scripts/validate.py, as data: techniques, lights, sphere rows (the scenes, images and metrics: below).

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
(harness/scene_render.py's mesh).  The RT Lit material's specular is switched off for pure-diffuse variants
by Cloth Weight 1 with a black Cloth Color (RT Lit has no "no specular" switch; spec x (1 - w) +
cloth x w = 0), and its diffuse by Metallic 1 (albedo 0).

The cases are data here; a case in Blender with (a) and (b) is suite_scene.py, (c) by brute force
suite_brute_force.py, the metrics suite_metrics.py, the run and its gates suite.py.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from ...core.materials.rt_lit_interface import Features


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
    # the cone reaches every sphere of a 3-column case (their centres lie 0-41 deg off its axis), the outer ones
    # through its blend; at 57 deg (before 2026-12-07) three spheres stood outside it and the CoD sphere of
    # spot_brute had 3 lit values
    cases.append(Case("spot", [LightSpec("spot", (-1.0, -4.0, 2.0), 800.0, spot_size=1.6, spot_blend=0.3)],
                      punctual_row, columns=3, description="spot light, radius 0, cone 92 deg, blend 0.3",
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
