"""The robustness sweep's inputs: the material families and light kinds, seeded random materials, geometry
and lights (``scene_inputs``), and the bound each family's radiance must keep."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...core import light_spread, lights as light_math
from ...core.materials import rt_lit
from ...core.materials.rt_lit_interface import Features


#: The five Blender light kinds, then the talk's light controls (core/lights.py): range and cone on area lights,
#: and the quad-to-spot fallback with a range; then Blender's light model (issue 27): point and spot lights with a
#: radius, suns with an angle, area lights with a spread, light linking.
LIGHT_KINDS = ("quad", "disk", "point", "spot", "sun", "quad+cone+range", "disk+cone+range", "quad_spot+range",
               "sphere", "spot_sphere+range+linking", "sun_disk", "quad+spread", "disk+spread+linking")
#: The kinds whose unit is an emitted radiance (their lobes integrate over a quad or a disk).
AREA_KINDS = ("quad", "disk", "sphere", "spot_sphere", "sun_disk")
#: Allowed excess over the white-furnace bound (relative): float32 rounding and bilinear lookups.
BOUND_TOLERANCE = 1e-3
#: Views this close to the tangent plane may fall on either side of the back-facing switch.
HORIZON_BAND = 1e-6
#: The most elongated rectangle or ellipse the sweep draws (a 10 m x 1 cm strip light).
ASPECT_MAX = 1e3
#: Below this per-unit-light response, errors are measured absolutely (as grids.NEAR_ZERO).
NEAR_ZERO = 1e-2


#: Families whose lobes are added (the talk, Filament, UE4: diffuse + specular + sheen, no layering): the
#: bound is the sum of the lobes' own bounds (1 for the diffuse, 1 for the specular, the sheen weight).
LAYERED = "layered"


@dataclass(frozen=True)
class Family:
    """One technique (or combination): the switches and the material inputs that isolate it.
    ``material``: input name -> "white", "random", a float, or a (low, high) uniform range."""
    name: str
    features: Features
    material: dict
    bound: str = "furnace"        # "furnace": at most 1; LAYERED: 2 + the sheen weight


_WHITE_METAL = {"Metallic": 1.0, "Base Color": "white"}
# A diffuse lobe alone: the specular lobe blended away to a black cloth lobe (Cloth Weight 1).
_DIFFUSE_ALONE = {"Metallic": 0.0, "Base Color": "white", "Cloth Weight": 1.0, "Cloth Color": "black"}
_DIELECTRIC = {"Metallic": 0.0, "Base Color": "white", "Specular Tint": "white"}

FAMILIES = (
    Family("GGX single scattering", Features("single", "lambert"), _WHITE_METAL),
    Family("Turquin multiple scattering", Features("turquin", "lambert"), _WHITE_METAL),
    Family("Fdez-Aguera multiple scattering", Features("fdez_aguera", "lambert"), _WHITE_METAL),
    Family("Kulla-Conty multiple scattering", Features("kulla_conty", "lambert"), _WHITE_METAL),
    Family("Lambert diffuse", Features("single", "lambert", cloth=True), _DIFFUSE_ALONE),
    Family("CoD WWII diffuse", Features("single", "cod", cloth=True), _DIFFUSE_ALONE),
    Family("Wrapped diffuse", Features("single", "wrapped", cloth=True), dict(_DIFFUSE_ALONE, Wrap=(0.0, 1.0))),
    Family("CoD wrapped diffuse", Features("none", "cod_wrapped"), dict(_DIFFUSE_ALONE, Wrap=(0.0, 1.0))),
    Family("Ashikhmin cloth", Features("single", "lambert", cloth=True),
           {"Metallic": 0.0, "Base Color": "black", "Cloth Weight": 1.0, "Cloth Color": "white"}),
    Family("Disney sheen", Features("single", "lambert", sheen=True, cloth=True),
           {"Metallic": 0.0, "Base Color": "black", "Cloth Weight": 1.0, "Cloth Color": "black",
            "Sheen Weight": 1.0, "Sheen Tint": "white"}),
    Family("Rough diffuse (Oren-Nayar as Cycles)", Features("none", "oren_nayar"),
           {"Metallic": 0.0, "Base Color": "white", "Diffuse Roughness": (0.0, 1.0)}),
    Family("Zeltner sheen", Features("none", "lambert", sheen="zeltner"),
           {"Metallic": 0.0, "Base Color": "black", "Sheen Weight": 1.0, "Sheen Tint": "white",
            "Sheen Roughness": (0.0, 1.0)}),
    Family("Disney sheen, fitted LTC", Features("none", "lambert", sheen="disney_fitted"),
           {"Metallic": 0.0, "Base Color": "black", "Sheen Weight": 1.0, "Sheen Tint": "white"}),
    Family("Dielectric: Lambert + GGX", Features("turquin", "lambert"), _DIELECTRIC, LAYERED),
    Family("Dielectric: CoD + GGX", Features("turquin", "cod"), _DIELECTRIC, LAYERED),
    Family("Turquin, mixed metal", Features("turquin", "lambert"),
           {"Metallic": (0.0, 1.0), "Base Color": "random", "Specular Tint": "random"}, LAYERED),
    Family("Everything on, mixed metal", Features("kulla_conty", "cod", sheen=True, cloth=True),
           {"Metallic": (0.0, 1.0), "Base Color": "random", "Specular Tint": "random", "Wrap": (0.0, 1.0),
            "Sheen Weight": (0.0, 1.0), "Sheen Tint": "random", "Cloth Weight": (0.0, 1.0),
            "Cloth Color": "random"}, LAYERED),
)


def _log_uniform(rng, low, high, n):
    return np.exp(rng.uniform(np.log(low), np.log(high), n))


def _unit(rng, n):
    v = rng.normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _mix_special(rng, values, specials, p):
    """``values`` with a fraction ``p`` replaced by a random choice of ``specials`` (each row)."""
    pick = rng.random(len(values)) < p
    choice = np.asarray(specials, np.float64)[rng.integers(0, len(specials), len(values))]
    out = np.array(values, np.float64)
    out[pick] = choice[pick]
    return out


def _quaternions(rng, n):
    """Unit quaternions (w, x, y, z), uniform, with some identity and some turned exactly over."""
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=-1, keepdims=True)
    special = rng.random(n)
    q[special < 0.05] = (1.0, 0.0, 0.0, 0.0)
    q[(special >= 0.05) & (special < 0.1)] = (0.0, 1.0, 0.0, 0.0)
    return q


def _facing(rng, location, position, n):
    """Quaternions turning local -Z (the direction a Blender area or spot light shines) from ``location``
    towards ``position``: lights aimed at the point."""
    d = position - location
    d /= np.maximum(np.linalg.norm(d, axis=-1, keepdims=True), 1e-300)
    minus_z = np.array([0.0, 0.0, -1.0])
    axis = np.cross(minus_z, d)
    w = 1.0 + d @ minus_z
    q = np.concatenate([w[:, None], axis], -1)
    flipped = w < 1e-9
    q[flipped] = (0.0, 1.0, 0.0, 0.0)
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def material_values(rng, family, n):
    vals = {}
    for name, sock in rt_lit.RT_LIT_INPUTS.items():
        spec = family.material.get(name)
        if name == "Normal":
            continue
        if spec is None:
            default = sock.default
            vals[name] = (np.full(n, float(default)) if sock.kind == "float"
                          else np.tile(np.asarray(default[:3]), (n, 1)))
        elif spec in ("white", "black"):
            vals[name] = np.full((n, 3), 1.0 if spec == "white" else 0.0)
        elif spec == "random":
            vals[name] = rng.random((n, 3))
        elif isinstance(spec, tuple):
            vals[name] = _mix_special(rng, rng.uniform(spec[0], spec[1], n), [spec[0], spec[1]], 0.1)
        else:
            vals[name] = np.full(n, float(spec))
    roughness = rng.random(n)
    pick = rng.random(n)
    roughness[pick < 0.2] = _log_uniform(rng, 1e-7, 0.05, n)[pick < 0.2]
    roughness[(pick >= 0.2) & (pick < 0.3)] = 0.0
    roughness[(pick >= 0.3) & (pick < 0.4)] = 1.0
    vals["Roughness"] = roughness
    vals["IOR"] = _mix_special(rng, rng.uniform(1.0, 4.0, n), [1.0, 1.0 + 1e-7, 4.0], 0.1)
    vals["Specular IOR Level"] = _mix_special(rng, rng.random(n), [0.0, 0.5, 1.0], 0.2)
    vals["Emission Strength"] = np.zeros(n)
    return vals


def geometry_values(rng, n):
    position = rng.normal(size=(n, 3))
    geometric = _unit(rng, n)
    normal = geometric.copy()
    pick = rng.random(n)
    tilted = pick < 0.3
    normal[tilted] = geometric[tilted] + 0.5 * rng.normal(size=(tilted.sum(), 3))
    scaled = rng.random(n) < 0.3
    normal[scaled] *= _log_uniform(rng, 1e-3, 1e3, n)[scaled, None]
    normal[(pick >= 0.3) & (pick < 0.35)] = 0.0                       # unlinked: the geometry's normal
    normal[(pick >= 0.35) & (pick < 0.37)] = 1e-40                    # denormal (float32 keeps it)
    incoming = _unit(rng, n)
    mu = np.einsum("ij,ij->i", incoming, geometric)
    back = rng.random(n) < 0.8
    incoming[back & (mu < 0)] *= -1.0                                  # mostly front-facing, some back
    grazing = rng.random(n) < 0.05                                     # exactly in the tangent plane
    g = incoming[grazing] - np.einsum("ij,ij->i", incoming[grazing], geometric[grazing])[:, None] * geometric[grazing]
    incoming[grazing] = g / np.maximum(np.linalg.norm(g, axis=-1, keepdims=True), 1e-300)
    return {"Position": position, "Geometry Normal": geometric, "Normal": normal, "Incoming": incoming}


def _light_values(rng, kind, position, normal, n):
    """Driver values of ``n`` lights of ``kind`` placed around ``position`` (normal ``normal``) as a scene
    could place them, and the per-unit normaliser (area: emitted radiance; punctual: irradiance at
    normal incidence, the light's colour being white)."""
    direction = _unit(rng, n)
    pick = rng.random(n)
    in_plane = pick < 0.05
    d = direction[in_plane] - np.einsum("ij,ij->i", direction[in_plane], normal[in_plane])[:, None] * normal[in_plane]
    direction[in_plane] = d / np.maximum(np.linalg.norm(d, axis=-1, keepdims=True), 1e-300)
    distance = _log_uniform(rng, 1e-6, 1e6, n)
    distance[(pick >= 0.05) & (pick < 0.07)] = 0.0                     # touching: centred on the point
    location = position + direction * distance[:, None]
    rotation = _quaternions(rng, n)
    aimed = rng.random(n) < 0.5
    rotation[aimed] = _facing(rng, location[aimed], position[aimed], int(aimed.sum()))
    scale = np.ones((n, 3))
    odd = rng.random(n)
    scale[odd < 0.05] *= -1.0
    scale[(odd >= 0.05) & (odd < 0.08), 0] = 0.0
    scale[(odd >= 0.08) & (odd < 0.15)] = _log_uniform(rng, 1e-3, 1e3, n)[(odd >= 0.08) & (odd < 0.15), None]
    power = _mix_special(rng, _log_uniform(rng, 1e-3, 1e6, n), [0.0], 0.03)
    vals = {"Location X": location[:, 0], "Location Y": location[:, 1], "Location Z": location[:, 2],
            "Rotation W": rotation[:, 0], "Rotation X": rotation[:, 1], "Rotation Y": rotation[:, 2],
            "Rotation Z": rotation[:, 3], "Scale X": scale[:, 0], "Scale Y": scale[:, 1], "Scale Z": scale[:, 2],
            "Power": power, "Strength": power, "Color R": np.ones(n), "Color G": np.ones(n), "Color B": np.ones(n),
            # a mirrored world matrix (its determinant's sign; the drivers give positive scales: core/lights.py)
            "Determinant": np.where(rng.random(n) < 0.1, -1.0, 1.0) * np.prod(np.abs(scale), axis=-1)}
    size = _mix_special(rng, _log_uniform(rng, 1e-6, 1e6, n), [0.0], 0.03)
    # rectangles and ellipses up to 1:1000 (a strip light); thinner ones are a known limit (KNOWN_LIMITS)
    aspect = _log_uniform(rng, 1.0, ASPECT_MAX, n) ** rng.choice([-1.0, 1.0], n)
    size_y = np.where(rng.random(n) < 0.5, size, _mix_special(rng, size * aspect, [0.0], 0.03))
    # world-space extents (size x scale) stay within 1e-6 .. 1e6 m like the distances
    size = np.minimum(size, 1e6 / np.maximum(np.abs(scale[:, 0]), 1e-30))
    size_y = np.minimum(size_y, 1e6 / np.maximum(np.abs(scale[:, 1]), 1e-30))
    vals.update({"Size": size, "Size Y": size_y, "Spot Size": _mix_special(rng, rng.uniform(0, np.pi, n),
                                                                             [0.0, np.pi], 0.05),
                 "Spot Blend": _mix_special(rng, rng.random(n), [0.0, 1.0], 0.1),
                 # the light controls: ranges from 1 mm to 1000 km and 0 (off), cone angles from 0 to pi
                 "Range": _mix_special(rng, _log_uniform(rng, 1e-3, 1e6, n), [0.0], 0.03),
                 "Cone Inner": _mix_special(rng, rng.uniform(0, np.pi, n), [0.0, np.pi], 0.05),
                 "Cone Outer": _mix_special(rng, rng.uniform(0, np.pi, n), [0.0, np.pi], 0.05),
                 # Blender's light model: exposure over and beyond its range (clamped to +-32), Normalize and Soft
                 # Falloff on or off, radii from 1 um to 1 km and 0, angles and spreads over [0, pi] with both ends
                 "Exposure": _mix_special(rng, rng.uniform(-10, 10, n), [-32.0, 32.0, -1e4, 1e4], 0.05),
                 "Normalize": (rng.random(n) < 0.8).astype(np.float64),
                 "Radius": _mix_special(rng, _log_uniform(rng, 1e-6, 1e3, n), [0.0], 0.03),
                 "Soft Falloff": (rng.random(n) < 0.5).astype(np.float64),
                 "Angle": _mix_special(rng, rng.uniform(0, np.pi, n), [0.0, np.pi], 0.05),
                 "Spread": _mix_special(rng, rng.uniform(0, np.pi, n), [0.0, np.pi], 0.05),
                 "Excluded": _mix_special(rng, (rng.random(n) < 0.5).astype(np.float64), [0.5], 0.05)})
    params = rt_lit.light_parameters(kind)
    return {p: vals[p] for p in params}, _unit_light(kind, vals, position)


def _unit_light(kind, vals, position):
    """What one unit of the light is at the point (float64): the emitted radiance of an area light (its peak
    radiance with a spread: core/light_spread.py), the irradiance at normal incidence of a point, spot or sun
    light (white light), with its exposure and Normalize; a light's options (range, cone, linking) only attenuate
    it.  The quad-to-spot fallback: its on-axis intensity L A over the squared distance."""
    base, options = light_math.split_kind(kind)
    with np.errstate(all="ignore"):
        power = vals["Power"] * np.exp2(np.clip(vals["Exposure"], *light_math.EXPOSURE_RANGE))
        strength = vals["Strength"] * np.exp2(np.clip(vals["Exposure"], *light_math.EXPOSURE_RANGE))
        normalized = vals["Normalize"] > 0.5

        def per_area(area, flux):
            return np.where(area > light_math.AREA_MIN, flux / np.where(normalized, np.maximum(area, 1e-300), 1.0), 0.0)

        loc = np.stack([vals["Location X"], vals["Location Y"], vals["Location Z"]], -1)
        d2 = np.maximum(((loc - position) ** 2).sum(-1), light_math.MIN_DISTANCE ** 2)
        half_u = np.abs(vals["Scale X"] * vals["Size"]) * 0.5
        half_v = np.abs(vals["Scale Y"] * vals["Size Y"]) * 0.5
        if base == "quad_spot":
            area = 4.0 * half_u * half_v
            return per_area(area, power / np.pi) * area / d2
        if base in ("quad", "disk"):
            radiance = per_area(half_u * half_v * (4.0 if base == "quad" else np.pi), power / np.pi)
            if "spread" in options:
                h = np.clip(vals["Spread"] * 0.5, light_spread.MIN_HALF_SPREAD, light_spread.MAX_HALF_SPREAD)
                peak = np.where(vals["Spread"] > np.pi - 1e-6, 1.0, np.tan(h) / (np.tan(h) - h))
                radiance = radiance * peak
            return radiance
        if base in ("sphere", "spot_sphere"):
            return per_area(4.0 * np.pi * vals["Radius"] ** 2, power / np.pi)
        if base == "sun_disk":
            half = np.clip(vals["Angle"] * 0.5, 0.0, 0.5 * np.pi)
            return per_area(np.pi * np.sin(half) ** 2, strength)
        if base == "sun":
            return strength
        return per_area(np.full_like(d2, light_math.POINT_AREA), power / np.pi) / d2


def scene_inputs(family, kind, n, seed=0):
    """(values: input name -> float32 array (n,) or (n, 3), unit light per point (float64), material) for
    ``n`` points of ``family`` under one light of ``kind``."""
    material = rt_lit.build_rt_lit(family.features, (kind,))
    rng = np.random.default_rng([seed, FAMILIES.index(family) if family in FAMILIES else 99,
                                 LIGHT_KINDS.index(kind)])
    vals = material_values(rng, family, n)
    vals.update(geometry_values(rng, n))
    params, unit = _light_values(rng, kind, vals["Position"], vals["Geometry Normal"], n)
    vals.update({material.light_inputs[0][p]: v for p, v in params.items()})
    with np.errstate(over="ignore", under="ignore"):
        values = {k: np.asarray(v, np.float32) for k, v in vals.items()}
    return values, unit, material


def bound(family, values):
    """The energy bound of each point, per unit light: 1 (white furnace), or for added lobes (LAYERED) the
    sum of their bounds, 2 + the sheen weight."""
    if family.bound != LAYERED:
        return np.float64(1.0)
    sheen = np.clip(values["Sheen Weight"].astype(np.float64), 0.0, 1.0) if family.features.sheen != "none" else 0.0
    return 2.0 + sheen
