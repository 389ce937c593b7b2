"""Area-light spread (issue 27): where a lobe's error under a light with spread comes from, in numpy against dense
integrals of the true BRDF times Cycles' spread weight.

    python scripts/benchmark_spread.py [--out docs/benchmarks] [--quick]

RT Lit shades a light with spread as each lobe's LTC integral over the region the cone leaves, times the spread's
weight averaged under that LTC by a fixed rule (core/light_spread.py).  Three things can be off: the rule (its
average against the exact integral of the same LTC times the weight), the LTC's own shape where the weight makes the
light non-uniform (the exact integral of the LTC times the weight against the true BRDF's), and the LTC's error
under the same light without spread (the uniform emitter LTCs are fitted for).  This benchmark measures the three
apart, so that what a rule could still gain is known.

Cases (seeded): a quad (0.4-2 m a side) or a disk (radius 0.3-1 m) facing -Z at 0.6-2.5 m, the receiver within
1.2 m of the light's axis with its normal tilted up to about 50 degrees, viewing near the mirror direction of a point
of the light (the highlight; as tests/core/test_lights.py draws them), spreads 40 and 90 degrees.  Lobes: Lambert
(``shading.lambert``: the identity LTC, exact without spread; on a disk with spread the rule exact along each ray,
``light_spread.LAMBERT_DISK``) and GGX (F = 1, height-correlated Smith) at r = 0.1-0.55, below the band
(``ltc_ggx`` is one LTC there).  Truth: a midpoint rule over the light (quads 300 x 300, disks 160 radii x 320
angles) of f cos times w per solid angle.  Relative errors over the cases whose truth is above 1e-3 of the light's
unit radiance: median / p90.  Writes ``spread.md`` and ``spread.json`` in ``--out``.
"""
from __future__ import annotations

import time

import numpy as np

from ..harness import entry, outputs
from ...core import light_spread
from ...core.ltc import fit_lobes, matrix, polygon, shading
from ...core.lut import lookup
from ...core.lut.catalog import default_lut_dir

SPREADS_DEG = (40.0, 90.0)
FORMS = ("quad", "disk")
LOBES = (("lambert", None), ("ggx", 0.1), ("ggx", 0.25), ("ggx", 0.4), ("ggx", 0.55))
#: The Lambert lobe's LTC: Minv = I (packed), the clamped cosine over pi.
IDENTITY = (1.0, 0.0, 0.0, 1.0)
TRUTH_FLOOR = 1e-3
#: What each column compares (estimate, truth).
COLUMNS = {"RT Lit vs truth": ("rt_lit", "truth"),
           "rule: RT Lit vs LTC x w": ("rt_lit", "ltc_weighted"),
           "LTC x w vs truth": ("ltc_weighted", "truth"),
           "no spread: LTC vs truth": ("plain", "plain_truth")}


# --- cases ---------------------------------------------------------------------------------------

def draw_case(rng, form):
    """(position, normal, view, light geometry) of one seeded case; None where the view grazes the surface."""
    height = rng.uniform(0.6, 2.5)
    centre = np.array([0.0, 0.0, height])
    if form == "quad":
        su, sv = rng.uniform(0.4, 2.0, 2)
        geom = (np.array([su / 2, 0.0, 0.0]), np.array([0.0, sv / 2, 0.0]))
    else:
        radius = rng.uniform(0.3, 1.0)
        geom = (np.array([radius, 0.0, 0.0]), np.array([0.0, radius, 0.0]))
    position = np.array([rng.uniform(-1.2, 1.2), rng.uniform(-1.2, 1.2), 0.0])
    normal = rng.normal(size=3)
    normal[2] = abs(normal[2]) + 0.8
    normal /= np.linalg.norm(normal)
    target = centre + rng.uniform(-0.7, 0.7) * geom[0] + rng.uniform(-0.7, 0.7) * geom[1] - position
    target /= np.linalg.norm(target)
    view = 2 * (normal @ target) * normal - target + rng.normal(scale=0.15, size=3)
    view /= np.linalg.norm(view)
    if view @ normal < 0.05:
        return None
    return position, normal, view, centre, geom


def shaded_light(form, position, centre, geom, spread):
    """The light RT Lit shades (core/light_spread.py ``spread_quad`` / ``spread_disk``) and whether the cone meets
    it."""
    half_u, half_v = geom
    if form == "quad":
        c, eu, ev, cone, hits = light_spread.spread_quad(position, centre, half_u, half_v, spread)
        corners = [c - eu - ev, c + eu - ev, c + eu + ev, c - eu + ev]
        return shading.QuadLight(corners, center_point=c, exact_horizon=True, spread=cone), float(hits)
    c, u, v, cone, hits = light_spread.spread_disk(position, centre, half_u, half_v, spread)
    return shading.DiskLight(c, u, v, exact_horizon=True, spread=cone), float(hits)


def plain_light(form, centre, geom):
    """The same light without spread."""
    half_u, half_v = geom
    if form == "quad":
        corners = [centre - half_u - half_v, centre + half_u - half_v, centre + half_u + half_v,
                   centre - half_u + half_v]
        return shading.QuadLight(corners, center_point=centre, exact_horizon=True)
    return shading.DiskLight(centre, half_u, half_v, exact_horizon=True)


# --- the dense integrals ---------------------------------------------------------------------------

def spread_weight(points, position, spread):
    """Cycles' spread weight (``area_light_spread_attenuation``, normalised) of the directions from ``position`` to
    ``points`` on a light facing -Z, written out from the kernel's formula (not core/light_spread.py's)."""
    d = points - position
    w = d / np.linalg.norm(d, axis=-1, keepdims=True)
    h = spread / 2
    tan_a = np.sqrt(np.maximum(1 - w[:, 2] ** 2, 0)) / w[:, 2]
    return np.maximum(1 - tan_a / np.tan(h), 0) * np.tan(h) / (np.tan(h) - h)


def light_points(form, centre, geom, quick):
    """Midpoints of a rule over the light and their areas."""
    half_u, half_v = geom
    if form == "quad":
        n = 150 if quick else 300
        s = (np.arange(n) + 0.5) / n * 2 - 1
        uu, vv = np.meshgrid(s, s)
        q = centre + uu.ravel()[:, None] * half_u + vv.ravel()[:, None] * half_v
        return q, np.full(n * n, 4 * np.linalg.norm(half_u) * np.linalg.norm(half_v) / (n * n))
    radial, angular = (80, 160) if quick else (160, 320)
    radius = np.linalg.norm(half_u)
    r = (np.arange(radial) + 0.5) / radial * radius
    rr, aa = np.meshgrid(r, (np.arange(angular) + 0.5) / angular * 2 * np.pi)
    q = centre + np.stack([(rr * np.cos(aa)).ravel(), (rr * np.sin(aa)).ravel(), np.zeros(rr.size)], -1)
    return q, rr.ravel() * (radius / radial) * (2 * np.pi / angular)


def dense_integrals(points, area, position, spread, integrand):
    """(integral of integrand x w, integral of integrand) per solid angle over the light; ``integrand`` of unit
    directions (world space)."""
    d = points - position
    r2 = np.sum(d * d, -1)
    w = d / np.sqrt(r2)[:, None]
    base = integrand(w) * w[:, 2] / r2 * area
    return float(np.sum(spread_weight(points, position, spread) * base)), float(np.sum(base))


# --- one case ----------------------------------------------------------------------------------------

def case_values(tables, form, case, spread, lobe, roughness, quick):
    """{rt_lit, ltc_weighted, truth, plain, plain_truth} of one case and lobe (values per unit radiance)."""
    position, normal, view, centre, geom = case
    frame = polygon.local_frame(normal, view)
    basis = np.stack(frame)
    v_local = basis @ view
    if lobe == "lambert":
        packed, magnitude = IDENTITY, 1.0 / np.pi

        def f_cos(w):
            return np.maximum(w @ normal, 0.0) / np.pi
    else:
        table, magnitude, _ = tables.ltc("ltc_ggx", np.array(view @ normal), np.array(roughness))
        packed, magnitude = tuple(float(x) for x in table), float(magnitude)

        def f_cos(w):
            return fit_lobes.LOBES["ggx"].eval_cos(w @ basis.T, np.broadcast_to(v_local, (len(w), 3)), roughness)
    # the identity LTC's integral is the form factor (cos / pi integrated), its magnitude 1
    scale = 1.0 if lobe == "lambert" else magnitude
    light, hits = shaded_light(form, position, centre, geom, spread)
    points, area = light_points(form, centre, geom, quick)
    truth, _ = dense_integrals(points, area, position, spread, f_cos)
    ltc_weighted, _ = dense_integrals(points, area, position, spread,
                                      lambda w: matrix.density_packed(np.array(packed)[None], w @ basis.T)[0])
    _, plain_truth = dense_integrals(points, area, position, np.pi, f_cos)
    plain = plain_light(form, centre, geom)
    if lobe == "lambert":       # RT Lit's Lambert lobe (shading.lambert: on a disk with spread, exact along its rays)
        rt_lit = float(shading.lambert(tables, light, position, normal, view, 1.0)) * hits
        plain_value = float(shading.lambert(tables, plain, position, normal, view, 1.0))
    else:
        rt_lit = float(light.integral(tables, packed, frame, position)) * hits * scale
        plain_value = float(plain.integral(tables, packed, frame, position)) * scale
    return {"rt_lit": rt_lit, "ltc_weighted": ltc_weighted * scale, "truth": truth, "plain": plain_value,
            "plain_truth": plain_truth}


def relative_stats(rows, estimate, truth):
    """Median / p90 of |estimate / truth - 1| over the rows whose truth is above TRUTH_FLOOR."""
    rel = np.array([abs(r[estimate] / r[truth] - 1.0) for r in rows if r[truth] > TRUTH_FLOOR])
    if rel.size == 0:
        return {"n": 0, "median": None, "p90": None}
    return {"n": int(rel.size), "median": float(np.median(rel)), "p90": float(np.quantile(rel, 0.9))}


def study(tables, cases_per_set, seed, quick, progress):
    """{form / spread / lobe: {column: stats}} (``COLUMNS``)."""
    out = {}
    for form in FORMS:
        for spread_deg in SPREADS_DEG:
            rng = np.random.default_rng(seed)
            cases = []
            while len(cases) < cases_per_set:
                case = draw_case(rng, form)
                if case is not None:
                    cases.append(case)
            progress(f"spread: {form}, {spread_deg:.0f} deg, {len(cases)} cases")
            for lobe, roughness in LOBES:
                rows = [case_values(tables, form, case, np.radians(spread_deg), lobe, roughness, quick)
                        for case in cases]
                key = f"{form} / {spread_deg:.0f} deg / {lobe}" + (f" r {roughness}" if roughness else "")
                out[key] = {name: relative_stats(rows, *pair) for name, pair in COLUMNS.items()}
    return out


# --- entry ---------------------------------------------------------------------------------------------

def parse_args(argv):
    p = entry.benchmark_parser(__doc__, "docs/benchmarks", "8 cases per set and coarser truth rules (40 cases)")
    p.add_argument("--seed", type=int, default=27)
    return p.parse_args(argv)


def run(args, progress=entry.flush_log):
    t0 = time.perf_counter()
    tables = lookup.LutSet.from_folder(args.lut_dir or default_lut_dir())
    count = 8 if args.quick else 40
    result = {"cases_per_set": count, "seed": args.seed, "quick": bool(args.quick),
              "sets": study(tables, count, args.seed, args.quick, progress)}
    result["seconds"] = time.perf_counter() - t0
    outputs.write_results(args.out, "spread", result, to_markdown(result))
    return result


def _cell(stats):
    if not stats["n"]:
        return "-"
    return f"{100 * stats['median']:.2f}% / {100 * stats['p90']:.1f}%"


def to_markdown(result):
    L = ["# Area-light spread: the rule, the LTC's shape and the LTC without spread", "",
         f"`python scripts/benchmark_spread.py` (validation/benchmarks/spread_benchmark.py; numpy, "
         f"{result['seconds']:.0f} s{', --quick' if result['quick'] else ''}). {result['cases_per_set']} seeded cases "
         "per light form and spread (the module's docstring says how they are drawn); relative error median / p90 "
         f"over the cases whose truth is above {TRUTH_FLOOR:g}. Truth: the true BRDF's f cos times Cycles' spread "
         "weight, integrated densely over the light. \"LTC x w\": the same dense integral of the lobe's LTC times "
         "the weight (what a perfect rule on top of the LTC would give); \"rule\": RT Lit against it; \"no "
         "spread\": the same light without spread, RT Lit's LTC integral against the true BRDF's.", "",
         "| light / spread / lobe | n | " + " | ".join(COLUMNS) + " |", "|---|---|" + "---|" * len(COLUMNS)]
    for key, columns in result["sets"].items():
        n = columns["RT Lit vs truth"]["n"]
        L.append(f"| {key} | {n} | " + " | ".join(_cell(columns[c]) for c in COLUMNS) + " |")
    return "\n".join(L) + "\n"
