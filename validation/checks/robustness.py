"""The robustness sweep: the RT Lit material evaluated at scene-like and adversarial inputs, counted.

A *family* is one technique (or combination) isolated by the material's switches and inputs
(``FAMILIES``): GGX alone on a white metal, each multiple-scattering model, each diffuse model on a
dielectric, cloth, sheen, everything on at once, and the World term in a white furnace.  Every family is
tried under each light kind (quad, disk, point, spot, sun, and the light controls' quad+cone+range,
disk+cone+range, quad_spot+range) at points drawn by ``scene_inputs``: shading
normals unnormalised, zero or denormal; views grazing and back-facing; roughness exactly 0 and 1 and
log-spread near 0; lights at 1e-6 to 1e6 m, 1e-6 to 1e6 m wide, touching the point, in its tangent
plane, behind it, facing away, degenerate (zero size, zero or negative scale), zero power.

For each (family, light kind, backend) ``sweep`` counts points whose radiance is NaN or Inf, negative,
or above the physical bound, and the worst relative error against numpy's float64 evaluation of the
same inputs (and where it is).  The bound: under an area light of emitted radiance L (colour white) a
material whose colours are all at most 1 returns at most L (the white furnace: no lobe or combination
reflects more than it receives), within ``BOUND_TOLERANCE``; the World term under a constant
environment of radiance 1 returns at most 1.  Punctual lights have no such bound (a delta light on a
mirror) and are checked for finiteness, sign and agreement with float64.

Backends: numpy float32 here; Cycles (the node groups) and GLSL (the shader-text backend) evaluate the
same inputs laid out as images (``as_image``), and because Cycles writes a non-finite pixel as 0, their
failures are found by comparison with the float64 reference (``compare_backend``), not by scanning.

The inputs (families, light kinds, the seeded draws, the bounds) are robustness_inputs.py.
"""
from __future__ import annotations

import time
from dataclasses import asdict, dataclass, field

import numpy as np

from ...core import lights as light_math
from ...core.materials import rt_lit
from ...core.materials.rt_lit_interface import Features, RADIANCE_OUTPUT
from .robustness_inputs import (AREA_KINDS, bound, BOUND_TOLERANCE, FAMILIES, Family, geometry_values, HORIZON_BAND,
    LAYERED, LIGHT_KINDS, material_values, NEAR_ZERO, scene_inputs)
from ...core.environment import sh
from ...core.ir import shader_text
from ...core.lut import exr_io
from ...core.lut.lookup import LutSet
from ...core.materials import world_shading
from ..harness import glsl_runner


@dataclass
class Counts:
    """What one (family, light kind, backend) sweep found."""
    family: str
    kind: str
    backend: str
    points: int
    nan: int = 0
    inf: int = 0
    negative: int = 0
    over_bound: int = 0          # -1: no bound for this light kind
    max_of_bound: float = 0.0    # the largest response as a fraction of its bound (area lights, world)
    zeroed: int = 0              # image backends: exactly 0, finite, where numpy float32 is not (flushed)
    at_horizon: int = 0          # points with |mu_v| <= HORIZON_BAND (left out of the error columns)
    off_1pct: int = 0            # points whose per-unit-light response is > 0.01 from float64's
    worst_rel: float = 0.0
    worst_abs_near_zero: float = 0.0
    worst_at: dict = field(default_factory=dict)
    seconds: float = 0.0

    @property
    def failures(self):
        return self.nan + self.inf + self.negative + max(self.over_bound, 0)


def view_cosine(values):
    """mu_v per point: the (guarded) shading normal's cosine with the view direction, float64."""
    n = values["Normal"].astype(np.float64)
    g = values["Geometry Normal"].astype(np.float64)
    n = np.where(((n * n).sum(-1) > 1e-12)[:, None], n, g)
    v = values["Incoming"].astype(np.float64)
    with np.errstate(all="ignore"):
        return (n * v).sum(-1) / np.maximum(np.linalg.norm(n, axis=-1) * np.linalg.norm(v, axis=-1), 1e-300)


def _where(values, material, index):
    light = material.light_inputs[0] if material.light_inputs else {}
    names = ["Roughness", "Metallic"] + [light[p] for p in ("Power", "Size", "Location Z") if p in light]
    out = {k: float(values[k][index]) for k in names if k in values}
    n = values["Geometry Normal"][index].astype(np.float64)
    v = values["Incoming"][index].astype(np.float64)
    out["mu_v"] = float(n @ v / max(np.linalg.norm(n) * np.linalg.norm(v), 1e-300))
    return out


def count(family, kind, backend, got, ref64, unit, values, material, seconds=0.0, nonfinite=None):
    """``Counts`` of ``got`` (radiance, (n, 3)) against the float64 reference ``ref64``.  ``nonfinite``:
    a boolean mask of points known to be non-finite (for renderers that write them as 0), else taken
    from ``got``."""
    got = np.asarray(got, np.float64)
    ref64 = np.asarray(ref64, np.float64)
    unit = np.asarray(unit, np.float64)[:, None]
    c = Counts(family.name, kind, backend, int(got.shape[0]), seconds=round(seconds, 3))
    c.nan = int(np.isnan(got).any(-1).sum())
    c.inf = int(np.isinf(got).any(-1).sum())
    if nonfinite is not None:
        c.nan += int(nonfinite.sum())
    finite = np.isfinite(got).all(-1)
    c.negative = int((got[finite] < 0.0).any(-1).sum())
    with np.errstate(all="ignore"):
        response = np.where(unit > 0, got / np.where(unit > 0, unit, 1.0), 0.0)
        response64 = np.where(unit > 0, ref64 / np.where(unit > 0, unit, 1.0), 0.0)
    if kind == "world" or light_math.base_kind(kind) in AREA_KINDS:
        limit = np.broadcast_to(np.asarray(bound(family, values), np.float64), (got.shape[0],))[:, None]
        ratio = response[finite] / limit[finite]
        c.over_bound = int((ratio > 1.0 + BOUND_TOLERANCE).any(-1).sum())
        c.max_of_bound = float(ratio.max()) if ratio.size else 0.0
    else:
        c.over_bound = -1
    ok = finite & np.isfinite(response64).all(-1)
    switch = np.abs(view_cosine(values)) <= HORIZON_BAND
    c.at_horizon = int(switch.sum())
    ok &= ~switch                       # errors are measured away from the back-facing switch
    err = np.abs(response - response64)
    c.off_1pct = int(((err > 0.01).any(-1) & ok).sum())
    big = np.abs(response64) >= NEAR_ZERO
    rel = np.where(big, err / np.where(big, np.abs(response64), 1.0), 0.0).max(-1)
    absolute = np.where(~big, err, 0.0).max(-1)
    rel[~ok], absolute[~ok] = 0.0, 0.0
    if rel.size:
        i = int(np.argmax(rel))
        c.worst_rel = float(rel[i])
        c.worst_at = _where(values, material, i)
        c.worst_abs_near_zero = float(absolute.max())
    return c


def evaluate_numpy(material, values, luts, dtype, chunk=1 << 16):
    """The material's radiance for every point, evaluated by the numpy backend in ``dtype`` (chunked)."""
    n = len(next(iter(values.values())))
    out = np.empty((n, 3), dtype)
    with np.errstate(all="ignore"):
        for start in range(0, n, chunk):
            part = {k: v[start:start + chunk].astype(dtype) for k, v in values.items()}
            result = material.evaluate(part, luts, dtype=dtype)[RADIANCE_OUTPUT]
            out[start:start + chunk] = np.broadcast_to(result, (len(part["Roughness"]), 3))
    return out


def as_image(values, width):
    """The per-point inputs as (H, width) / (H, width, 3) images (the last row padded with the first
    points) for the image-driven backends; returns (images, n)."""
    n = len(next(iter(values.values())))
    h = -(-n // width)
    images = {}
    index = np.arange(h * width) % n                # the last row padded with the first points again
    for k, v in values.items():
        images[k] = v[index].reshape((h, width) + v.shape[1:])
    return images, n


def from_image(image, n):
    """Per-point values back from an image of ``as_image``."""
    flat = np.asarray(image).reshape((-1,) + np.asarray(image).shape[2:])
    return flat[:n]


def compare_backend(family, kind, backend, got, ref64, unit, values, material, seconds, finite=None, ref32=None):
    """``count`` for an image-driven backend.  ``finite``: the renderer's own finiteness per point (Cycles
    writes NaN and Inf as 0, so it is rendered as a second image, ``conformance.render_group_outputs(...,
    finite_mask=True)``); None: taken from ``got``.  Points that came back exactly 0 while finite and while
    numpy's float32 value is above 1e-6 of the light are counted as ``zeroed`` (Cycles flushes denormal
    intermediates to zero)."""
    got = np.asarray(got, np.float64)
    nonfinite = None if finite is None else ~np.asarray(finite, bool)
    c = count(family, kind, backend, got, ref64, unit, values, material, seconds, nonfinite)
    if ref32 is not None:
        floor = 1e-6 * np.maximum(np.asarray(unit, np.float64), 0.0)
        zero = (got == 0.0).all(-1) & (np.abs(np.asarray(ref32, np.float64)).max(-1) > floor) \
            & (np.abs(view_cosine(values)) > HORIZON_BAND)
        if nonfinite is not None:
            zero &= ~nonfinite
        c.zeroed = int(zero.sum())
    return c


def sweep_numpy(points_per_kind, luts, seed=0, families=FAMILIES, kinds=LIGHT_KINDS, log=print):
    """[Counts] of the numpy float32 backend for every family and light kind, with the float64 references
    and inputs kept for the image backends: returns (counts, cases) where cases[(family, kind)] =
    (values, unit, material, ref64, ref32)."""
    counts, cases = [], {}
    for family in families:
        for kind in kinds:
            values, unit, material = scene_inputs(family, kind, points_per_kind, seed)
            t = time.perf_counter()
            got = evaluate_numpy(material, values, luts, np.float32)
            seconds = time.perf_counter() - t
            ref64 = evaluate_numpy(material, values, luts, np.float64)
            c = count(family, kind, "numpy float32", got, ref64, unit, values, material, seconds)
            counts.append(c)
            cases[(family.name, kind)] = (values, unit, material, ref64, got)
            log(f"[robustness] numpy {family.name} / {kind}: {c.points} points, {c.failures} failures, "
                f"worst rel {c.worst_rel:.2g} ({seconds:.1f} s)")
    return counts, cases


def world_furnace_inputs(n, seed=0):
    """Inputs of the World-term family: the RT Lit material with every technique on, no lights, under a
    constant environment of radiance 1 (exact SH and prefiltered levels), white colours; the radiance
    must stay at most 1 (+ the sheen weight).  Returns (values, material, environment)."""
    import tempfile
    from pathlib import Path

    levels = "[" + ", ".join(str(k / 8.0) for k in range(9)) + "]"
    path = Path(tempfile.mkdtemp(prefix="rtl-furnace-")) / "env_white_furnace_prefiltered.exr"
    exr_io.write_table(path, np.ones((9 * 8, 16, 4), np.float32), {"table": "env_white_furnace",
                                                                   "roughness_levels": levels})
    env = world_shading.WorldEnvironment.load(path, "env_white_furnace")   # a file: Cycles reads it as an image
    coeffs = sh.sh_project(np.ones((32, 64, 3)))
    family = WORLD_FAMILY
    material = rt_lit.build_rt_lit(family.features, (), env)
    rng = np.random.default_rng([seed, 1000])
    vals = material_values(rng, family, n)
    vals.update(geometry_values(rng, n))
    for i, name in enumerate(world_shading.SH_NAMES):
        vals[material.world_inputs[name]] = np.tile(coeffs[i], (n, 1))
    vals[material.world_inputs["Strength"]] = np.ones(n)
    vals[material.world_inputs["Rotation"]] = rng.uniform(-np.pi, np.pi, (n, 3))
    with np.errstate(over="ignore", under="ignore"):
        values = {k: np.asarray(v, np.float32) for k, v in vals.items()}
    return values, material, env


WORLD_FAMILY = Family("World term, everything on (constant environment)",
                      Features("kulla_conty", "cod", sheen=True, cloth=True), FAMILIES[-1].material, LAYERED)


def sweep_world(points, luts, seed=0, log=print):
    values, material, _ = world_furnace_inputs(points, seed)
    t = time.perf_counter()
    got = evaluate_numpy(material, values, luts, np.float32)
    seconds = time.perf_counter() - t
    ref64 = evaluate_numpy(material, values, luts, np.float64)
    unit = np.ones(points)
    c = count(WORLD_FAMILY, "world", "numpy float32", got, ref64, unit, values, material, seconds)
    log(f"[robustness] numpy {WORLD_FAMILY.name}: {c.points} points, {c.failures} failures, "
        f"worst rel {c.worst_rel:.2g} ({seconds:.1f} s)")
    return c, (values, unit, material, ref64, got)


def counts_json(counts):
    return [asdict(c) for c in counts]


# --- the image backends and the report ----------------------------------------------------------------

def sweep_glsl(cases, luts, width=1024, log=print):
    """[Counts] of the GLSL 4.50 backend (llvmpipe or a GPU) on the numpy sweep's inputs (``cases``)."""
    runner = glsl_runner.GlslRunner()
    counts = []
    for (family_name, kind), (values, unit, material, ref64, _) in cases.items():
        family = _family(family_name)
        images, n = as_image(values, width)
        module = shader_text.emit(material.function, "glsl450")
        t = time.perf_counter()
        got = runner.evaluate(module, images, material.tables(luts), outputs=[RADIANCE_OUTPUT])[RADIANCE_OUTPUT]
        seconds = time.perf_counter() - t
        c = compare_backend(family, kind, "GLSL 4.50", from_image(got, n), ref64, unit, values, material, seconds)
        counts.append(c)
        log(f"[robustness] GLSL {family_name} / {kind}: {c.points} points, {c.failures} failures, "
            f"worst rel {c.worst_rel:.2g} ({seconds:.1f} s)")
    return counts


def sweep_cycles(cases, luts, width=1024, log=print):
    """[Counts] of the node groups rendered by Cycles (validation/harness/conformance.py: one pixel per point) on
    the numpy sweep's inputs.  Cycles writes non-finite pixels as 0, so a second render of each case gives
    its finiteness per pixel (``finite_mask``)."""
    from ...addon.node_emit import ensure_function_group
    from ..harness.conformance import LAST_RENDER_SECONDS, render_group_outputs

    counts = []
    for (family_name, kind), (values, unit, material, ref64, ref32) in cases.items():
        family = _family(family_name)
        images, n = as_image(values, width)
        tables = material.tables(luts)
        ng = ensure_function_group(material.function, tables)
        got = render_group_outputs(ng, images, RADIANCE_OUTPUT)
        seconds = LAST_RENDER_SECONDS[0]
        finite = render_group_outputs(ng, images, RADIANCE_OUTPUT, finite_mask=True) > 0.5
        c = compare_backend(family, kind, "Cycles (node groups)", from_image(got, n), ref64, unit, values, material,
                            seconds, finite=from_image(finite, n), ref32=ref32)
        counts.append(c)
        log(f"[robustness] Cycles {family_name} / {kind}: {c.points} points, {c.failures} failures, "
            f"worst rel {c.worst_rel:.2g} ({c.seconds:.1f} s)")
    return counts


def _family(name):
    return next(f for f in FAMILIES + (WORLD_FAMILY,) if f.name == name)


def summary(counts):
    """{backend: {family: {points, nan, inf, negative, over_bound, off_1pct, worst_rel, worst_at}}}."""
    out = {}
    for c in counts:
        row = out.setdefault(c.backend, {}).setdefault(c.family, {
            "points": 0, "nan": 0, "inf": 0, "negative": 0, "over_bound": 0, "zeroed": 0, "at_horizon": 0,
            "off_1pct": 0, "max_of_bound": 0.0,
            "worst_rel": 0.0, "worst_kind": None, "worst_at": {}})
        for key in ("points", "nan", "inf", "negative", "zeroed", "at_horizon", "off_1pct"):
            row[key] += getattr(c, key)
        row["over_bound"] += max(c.over_bound, 0)
        row["max_of_bound"] = max(row["max_of_bound"], c.max_of_bound)
        if c.worst_rel >= row["worst_rel"]:
            row["worst_rel"], row["worst_kind"], row["worst_at"] = c.worst_rel, c.kind, c.worst_at
    return out


def failures(counts):
    """Total NaN + Inf + negative + over-bound points."""
    return sum(c.failures for c in counts)


#: What the campaign found, where it arose and what fixed it (docs/robustness.md); each has a regression
#: example in tests/core/test_properties.py.
FINDINGS = (
    ("CoD WWII diffuse negative for glossy roughness (r ~ 0.05-0.13) with light and view grazing from the same "
     "side", "core/diffuse.py: Chan 2018's retro-reflection quadratic (34.5 g - 59) g + 24.5 is negative for "
     "0.710 < g < 1", "clamped at 0 (retro_reflection_scale); CoD LTC table re-fitted",
     "test_cod_diffuse_never_negative"),
    ("Kulla-Conty lobe under area lights up to ~20x the light's radiance (near-mirror, light centre near the "
     "horizon)", "core/materials/lobes.py: f_ms at the centre's mu times the whole form factor",
     "the integral over the light bounded by its hemisphere value, 1 - E_avg", "test_kulla_conty_area_bounded"),
    ("GGX + Kulla-Conty over 1 of the light (up to 1.39) at grazing views of near-mirrors under area lights",
     "core/materials/light_shading.py: the LTC magnitude (0.99) and the energy table's E (0.61) disagree at "
     "mu_v -> 0", "the multiple-scattering lobe bounded by 1 - E_ltc", "test_grazing_mirror_furnace"),
    ("CoD WWII diffuse reflects up to 1.14 of the light (r -> 1, grazing view) under area lights and the world",
     "Chan 2018's fit: its directional albedo exceeds 1 (quadrature of the formula, no LTC)",
     "the LTC magnitude bounded by 1 (ltc/shading.py albedo_bound)", "test_cod_area_furnace"),
    ("NaN material inputs (a texture, a driver) reached the pixel", "np.minimum / np.maximum propagate NaN; "
     "Cycles' fminf / fmaxf and GPUs' min / max do not", "min / max ignore a NaN operand in every backend "
     "(core/ir/semantics.py); factors and colours clamped in RTL Surface", "test_nan_and_inf_inputs_finite"),
    ("Colours outside [0, 1] gave negative radiance or more than the white furnace", "RTL Surface passed Base "
     "Color, tints and Cloth Color through", "reflectance colours clamped to [0, 1], emission to [0, 1e18]",
     "test_negative_and_huge_colours"),
    ("Denormal normals (|n| ~ 1e-40) shaded with an arbitrary normal in float64 and the geometry's in float32",
     "RTL Surface's zero-normal test dot(n, n) > 0 underflows in float32 only", "threshold |n| > 1e-6 "
     "(surface.NORMAL_MIN)", "test_denormal_normal_falls_back"),
    ("An infinite Normal input gave NaN under point and sun lights in float32 (quads and disks stayed finite)",
     "RTL Surface normalised any normal longer than NORMAL_MIN: inf / inf", "normals as long as 1e18 or longer "
     "(infinite, NaN, or where float32's dot product overflows) fall back to the geometry's normal too "
     "(surface.NORMAL_MAX)", "test_nan_and_inf_inputs_finite"),
    ("Quads much larger than their distance to the point went dark (a 10^4 m panel 1 cm above it: 0 where the "
     "form factor is ~1) or, in Cycles, black on one backend and lit on the other (90 of 12.2 M sweep pixels)",
     "ltc/polygon.py: the side and edge-on tests measured from corner p0 (as ltc_code), whose float32 rounding "
     "(~6e-8 |p0|) exceeds the point's distance to such a light", "the tests measure from the light's centre "
     "(its location, a new Center input of the quad integral)", "test_huge_light_just_above_is_not_edge_on"),
    ("A 1 x 1 world image baked as a varying world (SH Y_2,0 = -3.4 for a constant)", "core/environment: the "
     "bake's quadrature over one row has a single node, at the equator", "images below 16 x 32 texels are "
     "replicated up to it first (equirect.replicate_to_minimum)", "test_a_one_texel_world_bakes_as_a_constant"),
    ("Lights in collections disabled in renders or excluded from the view layer were shaded",
     "addon/materials.py scene_lights checked only the object's hide_render", "is_rendered: the object, its "
     "collections and the view layers' layer collections", "test_lights_outside_the_render_are_not_shaded"),
    ("Sync Lights with 100 lights: the capacity warning was cut off", "the report listed every light's name and "
     "Blender truncates long reports", "beyond 8 lights the report counts them per kind",
     "test_sync_lights_with_no_lights_and_with_a_hundred"),
    ("Convert lost the drivers of driven Principled inputs", "only values and links were transferred",
     "drivers move with the value, both ways", "test_driven_inputs_stay_driven_both_ways"),
    ("A LUT write that failed half way (read-only folder, full disk) left a group with one new and one old "
     "table", "each table was written and renamed on its own", "a group's tables are written to .tmp files "
     "and renamed together (exr_io.write_tables); LutWriteError names the file, the cause and the way out",
     "test_a_failed_write_keeps_the_previous_tables_and_names_the_fix"),
    ("Disks and ellipses much larger than their distance gave about half their light in float32 (a 10^5 m disk "
     "10 um away: 0.5 where float64 gives 1)", "ltc/disk.py: after the scaling by the light's extent, the "
     "centre C (~ distance / size) is lost against V1, V2 in the cone-axis sums", "within 1e-3 of the smaller "
     "semi-axis the cone is the half-space: axis = the light's normal, |F| = |V1 x V2| / (|V1 x V2| + |C|^2) "
     "(disk.NEAR_PLANE)", "test_large_disk_just_above_is_fully_lit"),
    ("A light centred exactly on the shading point was integrated (0.20 of the light in float32, 0.03 in "
     "float64) instead of counting as seen edge-on", "the edge-on test |side| < 1e-5 |p| |n| is false for p = 0",
     "off the plane only where |side| > margin (polygon.beyond_plane), for quads and disks",
     "test_light_centred_on_the_point_is_edge_on"),
    ("NaN texture coordinates raised IndexError for the whole batch", "texel index of NaN", "texel 0 "
     "(semantics.texel_index)", "test_nan_lookup_gives_a_value"),
)

#: Known, measured, not fixed: the sweep reports their share of points (docs/robustness.md).
KNOWN_LIMITS = (
    ("Rectangles and ellipses thinner than 1:1000 (ASPECT_MAX; not drawn)", "an earlier draw of independent sizes "
     "over 12 decades (aspect up to 1e12) found float32 ellipses seen from close returning up to 0.5 of the "
     "light against an exact 200,000-gon integral of 0.01-0.07; not measured since"),
    ("Lights smaller than ~1e-4 m within ~1e-5 m of a point at ~1 m from the world origin", "float32 world "
     "positions resolve ~6e-8 m there, so the light's corners relative to the point carry a few % error before "
     "any shading math (the 'off > 0.01' points of the quad rows); every float32 renderer shares it"),
    ("Spot lights with a hard edge (Spot Blend 0, or nearly), at points on the cone's edge", "the attenuation "
     "jumps from 1 to 0 there by design; float32 and float64 put points within rounding of the edge on "
     "different sides (the spot rows' worst error, 1)"),
    ("GLSL on llvmpipe: near-mirror GGX (r < 0.05) under disks 100-10^5 m wide", "the disk's LTC matrices reach "
     "1e8 there and llvmpipe's sqrt / acos / FMA contraction round differently from numpy's, which that "
     "conditioning multiplies: up to 49x float64 at single points, 589 of 12.2 M points beyond 1% of the light "
     "(numpy float32: 415)"),
    ("Views exactly in the tangent plane (|mu_v| < ~1e-7)", "float32 and float64 fall on different sides of "
     "the back-facing switch (radiance 0 below the horizon), so the response jumps there by design"),
    ("Zeltner sheen under quads and disks more than 1000x larger than their distance", "its exact-horizon "
     "integrals (core/ltc/polygon.py, disk.py: clipped at the horizon) return 0 in the IR's float32 evaluation for "
     "about half of these giant lights seen from micrometres, where float64 gives up to 0.5 of the light (3% of "
     "the sweep's points for those kinds, which draws them on purpose; the same integral in plain numpy float32 "
     "is right, so the loss is in an operation's node semantics, not yet located)"),
    ("The light controls' cone at extreme apexes", "a narrow gap between the inner and the outer angle and a "
     "light far from the point amplify float32 rounding of the cosine at the projector apex (as the spot's "
     "blend edge): a few points in 10^4 beyond 1% of the light"),
)


def parse_args(argv):
    import argparse
    from pathlib import Path

    p = argparse.ArgumentParser(description="The robustness sweep: NaN / Inf / negative / over-bound counts per "
                                            "technique family, light kind and backend")
    p.add_argument("--points", type=int, default=125_000, help="points per family and light kind (default 1.25e5: "
                                                                "1e6 per family over the eight light kinds)")
    p.add_argument("--image-points", type=int, default=None, help="of those, how many the image backends "
                                                                   "(Cycles, GLSL) evaluate (default: all)")
    p.add_argument("--backends", default="numpy,glsl,cycles", help="comma-separated: numpy, glsl, cycles")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--lut-dir", type=Path, default=None)
    p.add_argument("--out", type=Path, default=Path(__file__).resolve().parents[2] / "docs" / "benchmarks"
                   / "robustness.md", help="markdown report (the JSON goes beside it)")
    return p.parse_args(argv)


def run(args, log=print):
    """The sweep of ``parse_args``: writes ``args.out`` (.md) and its .json; returns the result dict."""
    import json
    import platform

    luts = LutSet.from_folder(args.lut_dir) if args.lut_dir else LutSet.from_folder()
    backends = [b.strip() for b in args.backends.split(",") if b.strip()]
    t0 = time.perf_counter()
    counts, cases = sweep_numpy(args.points, luts, args.seed, log=log)
    world, world_case = sweep_world(args.points, luts, args.seed, log=log)
    counts.append(world)
    cases[(WORLD_FAMILY.name, "world")] = world_case
    if args.image_points is not None:
        k = args.image_points
        cases = {key: ({n: a[:k] for n, a in values.items()}, unit[:k], material, ref64[:k], ref32[:k])
                 for key, (values, unit, material, ref64, ref32) in cases.items()}
    skipped = {}
    if "glsl" in backends:
        from ..harness import glsl_runner

        if glsl_runner.available():
            counts += sweep_glsl(cases, luts, log=log)
        else:
            skipped["GLSL 4.50"] = "no OpenGL 4.5 context (EGL / Mesa) on this machine"
    if "cycles" in backends:
        try:
            import bpy  # noqa: F401
        except ImportError:
            skipped["Cycles (node groups)"] = "no bpy module in this Python"
        else:
            counts += sweep_cycles(cases, luts, log=log)
    result = {"points_per_family_and_kind": args.points, "image_points": args.image_points, "seed": args.seed,
              "bound_tolerance": BOUND_TOLERANCE, "seconds": round(time.perf_counter() - t0, 1),
              "machine": f"{platform.machine()}, {platform.python_version()}", "skipped": skipped,
              "failures": failures(counts), "summary": summary(counts), "counts": counts_json(counts),
              "findings": [dict(zip(("defect", "cause", "fix", "test"), f)) for f in FINDINGS],
              "known_limits": [dict(zip(("case", "why"), k)) for k in KNOWN_LIMITS]}
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.with_suffix(".json").write_text(json.dumps(result, indent=1) + "\n")
    args.out.write_text(markdown(result))
    log(f"[robustness] {result['failures']} failures over {sum(c.points for c in counts)} evaluations "
        f"-> {args.out}")
    return result


def markdown(result):
    lines = ["# Robustness sweep", "",
             "Written by `python scripts/robustness_sweep.py` (validation/checks/robustness.py; method in "
             "docs/robustness.md).  Per technique family: the RT Lit material isolated to that technique, at "
             f"{result['points_per_family_and_kind']:,} scene-like and adversarial points per light kind "
             f"({', '.join(LIGHT_KINDS)}; seed {result['seed']}); the image backends evaluate "
             + ("the same points" if result["image_points"] is None else
                f"the first {result['image_points']:,} of them per kind") +
             " as input images.  Cycles writes NaN and Inf pixels as 0, so each Cycles case is rendered twice: "
             "its value, and its own finiteness per pixel (Math Compare of the value with itself).", "",
             f"Failures (NaN + Inf + negative + over the energy bound by more than {result['bound_tolerance']:g}): "
             f"**{result['failures']}**.  Run time {result['seconds']} s ({result['machine']}).", ""]
    for backend, why in result["skipped"].items():
        lines.append(f"- {backend}: not run ({why}).")
    if result["skipped"]:
        lines.append("")
    for backend, families in result["summary"].items():
        lines += [f"## {backend}", "",
                  "| family | points | NaN | Inf | negative | over bound | max / bound | flushed to 0 | off > 0.01 | "
                  "worst rel. error vs float64 (where) |", "|---|---|---|---|---|---|---|---|---|---|"]
        for name, row in families.items():
            where = ", ".join(f"{k} {v:.3g}" for k, v in row["worst_at"].items())
            lines.append(f"| {name} | {row['points']:,} | {row['nan']} | {row['inf']} | {row['negative']} | "
                         f"{row['over_bound']} | {row['max_of_bound']:.4f} | {row['zeroed']} | {row['off_1pct']} | "
                         f"{row['worst_rel']:.2g} ({row['worst_kind']}: {where}) |")
        lines.append("")
    lines += ["The bound is per unit of light: the emitted radiance of an area light, radiance 1 for the "
              "constant environment; 1 for one lobe on a white surface (white furnace), 2 + the sheen weight "
              "where diffuse, specular and sheen are added (as the talk and Filament add them).  Punctual lights "
              "have none (a delta light on a mirror) and count toward NaN / Inf / negative only.  \"off > 0.01\": "
              "points whose response differs from float64's by more than 1% of the light.  \"flushed to 0\": exactly 0 "
              "(and finite) in an image backend where numpy float32 is above 1e-6 of the light: Cycles flushes "
              "denormal intermediates to zero (near-mirror Kulla-Conty lobes, 1 - E_avg ~ 1e-11, under faint "
              "lights), where numpy keeps them.  The error columns leave "
              f"out views within {HORIZON_BAND:g} of the tangent plane, where float32 and float64 (or Cycles and "
              "numpy) may take either side of the back-facing switch.", "",
              "## Found and fixed", "", "| defect | cause | fix | regression test |", "|---|---|---|---|"]
    lines += [f"| {f['defect']} | {f['cause']} | {f['fix']} | `{f['test']}` |" for f in result["findings"]]
    lines += ["", "## Known limits (measured above, not fixed)", "", "| case | why |", "|---|---|"]
    lines += [f"| {k['case']} | {k['why']} |" for k in result["known_limits"]]
    return "\n".join(lines) + "\n"
