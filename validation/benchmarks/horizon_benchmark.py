"""Area lights at the receiver's horizon (issue 30): every LTC lobe under seeded random quads and disks that cross
the horizon, against the same lights wholly above it, RT Lit's own shading end to end against a brute-force
integral of the true BRDF.

    python scripts/benchmark_horizon.py [--out docs/benchmarks] [--quick]

Lights: centre 0.3-3 m from the shading point (N = +Z, at the origin), quads 0.2-3 m a side, disks of radius
0.1-1.5 m, the lit side towards the point within 60 degrees; views 0-80 degrees, roughness 0.1-0.95.  The
*crossing* set keeps the lights with part of their area below the horizon z = 0 and part above it (centres
drawn within 25 degrees of the horizon); the *above* set the lights wholly above it (centres anywhere from
-20 degrees up), so both come from one generator and differ only in where the light lies.

Lambert: ``core.ltc.shading.lambert`` with the exact horizon (quads clipped, disks by their closed form above the
horizon and the clipped ellipse's boundary integral where they cross it; numpy float64 and float32) and with the talk's
clipless form (the identity LTC with the sphere table's horizon), against the clipped form factor by quadrature
(``core.ltc.reference``), relative error over every light whose form factor is above 1e-6.
Every LTC lobe (``catalog.LTC_LOBES``, with its band where it has one): ``shading.lobe_integral`` x the table's
magnitude, with the sphere table's horizon (the talk's; ``Features.horizon`` "sphere_table", the default) and with
the exact horizon (the transformed light clipped; "exact"),
against the quadrature of the lobe's f cos, relative error over the lights that carry more than 10% of the lobe's
albedo (as docs/benchmarks/ltc.md), crossing and above apart.
Writes ``horizon.md`` and ``horizon.json`` in ``--out``.
"""
from __future__ import annotations

import time

import numpy as np

from ..harness import entry, outputs
from .ltc_random_lights import error_stats, fmt_stats, light_facing_point, true_integral
from ...core.ir.expr import table_filter
from ...core.ir.numpy_backend import flat_node_count
from ...core.ltc import fit, fit_lobes, shading
from ...core.lut import catalog, lookup
from ...core.lut.catalog import default_lut_dir
from ...core.materials import rt_lit
from ...core.materials.rt_lit_interface import HORIZON_MODELS, Features

ORIGIN = np.zeros(3)
NORMAL = np.array([0.0, 0.0, 1.0])
FORM_FACTOR_FLOOR = 1e-6
LAMBERT_MODELS = ("exact horizon", "exact horizon, float32", "sphere table (default)")


# --- lights --------------------------------------------------------------------------------------

def crosses_horizon(kind, geom):
    """True when the light has area on both sides of z = 0."""
    if kind == "quad":
        z = np.asarray(geom)[:, 2]
        return bool(z.min() < 0.0 < z.max())
    centre, u, v = geom
    return bool(abs(centre[2]) < np.hypot(u[2], v[2]))


def wholly_above(kind, geom):
    if kind == "quad":
        return bool(np.asarray(geom)[:, 2].min() > 0.0)
    centre, u, v = geom
    return bool(centre[2] > np.hypot(u[2], v[2]))


def _light(kind, rng, low_elevation):
    el = np.radians(rng.uniform(-25.0, 25.0) if low_elevation else rng.uniform(-20.0, 90.0))
    az = rng.uniform(0.0, 2.0 * np.pi)
    d = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
    return light_facing_point(kind, rng, d, (0.3, 3.0), 60.0, (0.2, 3.0), (0.1, 1.5))


def horizon_lights(kind, count, crossing, seed):
    """``count`` seeded configurations (r, theta_v, v, geometry) whose light crosses the horizon (``crossing``)
    or lies wholly above it."""
    rng = np.random.default_rng(seed)
    keep = crosses_horizon if crossing else wholly_above
    out = []
    while len(out) < count:
        geom = _light(kind, rng, crossing)
        r, theta = rng.uniform(0.1, 0.95), np.radians(rng.uniform(0.0, 80.0))
        if keep(kind, geom):
            out.append((r, theta, np.array([np.sin(theta), 0.0, np.cos(theta)]), geom))
    return out


def shading_light(kind, geom, dtype=np.float64, exact_horizon=False):
    geom = [np.asarray(g, dtype=dtype) for g in geom]
    if kind == "quad":
        return shading.QuadLight(np.stack(geom), exact_horizon=exact_horizon)
    return shading.DiskLight(*geom, exact_horizon=exact_horizon)


# --- Lambert -------------------------------------------------------------------------------------

def _lambert_f_cos(l, v):
    return np.maximum(l[..., 2], 0.0) / np.pi


def lambert_models(tables, kind, geom, v):
    """Lambert's form factor with the exact horizon (float64, float32) and with the sphere table's."""
    out = {}
    for model, dtype, exact in zip(LAMBERT_MODELS, (np.float64, np.float32, np.float64), (True, True, False)):
        cast = lambda a, dtype=dtype: np.asarray(a, dtype=dtype)      # noqa: E731
        out[model] = float(shading.lambert(tables, shading_light(kind, geom, dtype, exact), cast(ORIGIN),
                                           cast(NORMAL), cast(v), dtype(1.0)))
    return out


def lambert_study(tables, count, seed):
    result = {}
    for kind in ("quad", "disk"):
        for crossing in (True, False):
            rows = {m: [] for m in LAMBERT_MODELS}
            truth, truth_err = [], []
            for _, _, v, geom in horizon_lights(kind, count, crossing, seed):
                t, e = true_integral(kind, _lambert_f_cos, v, geom)
                if t <= FORM_FACTOR_FLOOR:
                    continue
                truth.append(t)
                truth_err.append(e / t)
                for model, value in lambert_models(tables, kind, geom, v).items():
                    rows[model].append(value)
            truth = np.array(truth)
            entry_ = {"lights": int(truth.size), "smallest_form_factor": float(truth.min()),
                      "reference_max_rel_error": float(np.max(truth_err))}
            for model, values in rows.items():
                rel = np.abs(np.array(values) - truth) / truth
                entry_[model] = {"rel_median": float(np.median(rel)), "rel_p90": float(np.quantile(rel, 0.9)),
                                 "rel_max": float(rel.max())}
            result[f"{kind}/{'crossing' if crossing else 'above'}"] = entry_
    return result


# --- every LTC lobe ------------------------------------------------------------------------------

LOBE_MODELS = {"sphere table (default)": False, "exact horizon": True}


def lobe_estimate(tables, prefix, kind, geom, v, r, exact_horizon):
    """The LTC estimate of the lobe's f cos integral (F = 1): integral x magnitude."""
    light = shading_light(kind, geom, exact_horizon=exact_horizon)
    integral, magnitude, _ = shading.lobe_integral(tables, prefix, light, ORIGIN, NORMAL, v, np.float64(r))
    return float(integral) * float(magnitude)


def lobe_study(tables, count, seed):
    result = {}
    for prefix, (lobe_name, _) in catalog.LTC_LOBES.items():
        lobe = fit_lobes.LOBES[lobe_name]
        for kind in ("quad", "disk"):
            for crossing in (True, False):
                est = {m: [] for m in LOBE_MODELS}
                truth, albedo, theta = [], [], []
                for r, th, v, geom in horizon_lights(kind, count, crossing, seed):
                    mu = float(v[2])
                    f_cos = (lambda l, vv, r=r: lobe.eval_cos(l, vv, np.array(r)))
                    truth.append(true_integral(kind, f_cos, v, geom)[0])
                    albedo.append(float(fit.lobe_integrals(lobe, max(mu, fit.FIT_MU_MIN), np.array([r]), 1 << 12)[0][0]))
                    theta.append(th)
                    for model, exact in LOBE_MODELS.items():
                        est[model].append(lobe_estimate(tables, prefix, kind, geom, v, r, exact))
                result[f"{lobe_name}/{kind}/{'crossing' if crossing else 'above'}"] = {
                    m: error_stats(est[m], truth, albedo, theta) for m in LOBE_MODELS}
    return result


# --- cost ----------------------------------------------------------------------------------------

COST_FEATURES = {"single + Lambert": Features("single", "lambert"), "Turquin + CoD (default)": Features(),
                 "Kulla-Conty + wrapped + Zeltner sheen + cloth": Features("kulla_conty", "wrapped", sheen="zeltner",
                                                                           cloth=True)}


def _flat(features, kinds):
    return flat_node_count(tuple(rt_lit.build_rt_lit(features, kinds).function.outputs.values()))


def light_costs():
    """Operations of one quad and one disk light in the Cycles tree (Linear table reads), per horizon."""
    out = {}
    with table_filter("linear"):
        for label, features in COST_FEATURES.items():
            row = {}
            for horizon in HORIZON_MODELS:
                f = Features(**dict(features.as_dict(), horizon=horizon))
                base = _flat(f, ())
                row.update({f"{kind}, {horizon}": _flat(f, (kind,)) - base for kind in ("quad", "disk")})
            out[label] = row
    return out


# --- the benchmark -------------------------------------------------------------------------------

def parse_args(argv):
    p = entry.benchmark_parser(__doc__, "docs/benchmarks", "fewer lights (24 per set for Lambert and 12 per lobe instead of 120)")
    p.add_argument("--seed", type=int, default=2030)
    return p.parse_args(argv)


def run(args, progress=entry.flush_log):
    t0 = time.perf_counter()
    tables = lookup.LutSet.from_folder(args.lut_dir or default_lut_dir())
    count = 24 if args.quick else 120
    progress(f"horizon: Lambert, {count} lights per set")
    result = {"lights_per_set": count, "seed": args.seed, "lambert": lambert_study(tables, count, args.seed)}
    progress("horizon: every LTC lobe")
    result["lobe_lights_per_set"] = count // 2 if args.quick else count
    result["lobes"] = lobe_study(tables, result["lobe_lights_per_set"], args.seed + 1)
    result["light_costs"] = light_costs()
    result["seconds"] = time.perf_counter() - t0
    outputs.write_results(args.out, "horizon", result, to_markdown(result))
    return result


def to_markdown(result):
    L = ["# Area lights at the horizon: crossing lights against lights wholly above", "",
         f"`python scripts/benchmark_horizon.py` (validation/benchmarks/horizon_benchmark.py; numpy, "
         f"{result['seconds']:.0f} s). {result['lights_per_set']} seeded lights per set for Lambert, "
         f"{result['lobe_lights_per_set']} per set and lobe for the others; the module's docstring says how they "
         "are drawn.", "",
         "## Lambert: the form factor", "",
         "Relative error against the clipped form factor by quadrature (its own error estimate in the last column), "
         "over the lights whose form factor is above 1e-6: median / p90 / max.", "",
         "| light | n | smallest form factor | " + " | ".join(LAMBERT_MODELS) + " | reference |",
         "|---|---|---|" + "---|" * (len(LAMBERT_MODELS) + 1)]
    for key, e in result["lambert"].items():
        cells = [f"{outputs.scientific(e[m]['rel_median'])} / {outputs.scientific(e[m]['rel_p90'])} / "
                 f"{outputs.scientific(e[m]['rel_max'])}" for m in LAMBERT_MODELS]
        L.append(f"| {key} | {e['lights']} | {outputs.scientific(e['smallest_form_factor'])} | "
                 + " | ".join(cells) + f" | {outputs.scientific(e['reference_max_rel_error'])} |")
    L += ["", "## Every LTC lobe: the sphere table's horizon (the talk's, the default) and the exact horizon", "",
          "The band where the table has one. Relative error over the lights carrying > 10% of the lobe's albedo; "
          "absolute error over the albedo over all lights.", "",
          "| lobe / light / set | horizon | n (>10%) | rel median | rel p90 | rel max | abs/albedo median | "
          "abs/albedo p90 |", "|---|---|---|---|---|---|---|---|"]
    for key, models in result["lobes"].items():
        for model, stats in models.items():
            L.append(f"| {key} | {model} | {fmt_stats(stats)}")
    columns = list(next(iter(result["light_costs"].values())))
    L += ["", "## Cost of one light in the Cycles tree (operations, Linear table reads)", "",
          "The Zeltner sheen clips at the horizon under every setting.", "",
          "| features | " + " | ".join(columns) + " |", "|---|" + "---|" * len(columns)]
    for label, row in result["light_costs"].items():
        L.append(f"| {label} | " + " | ".join(str(row[c]) for c in columns) + " |")
    return "\n".join(L) + "\n"
