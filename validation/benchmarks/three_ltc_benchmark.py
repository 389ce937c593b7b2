"""The export's ltc_code tables as a drop-in for three.js, measured in a real browser (issue 32).

    python scripts/benchmark_three_ltc.py [--configs 12] [--size 10] [--out docs/benchmarks/three_ltc.md]

three.js r187 (the npm package pinned in ``engines/three/package-lock.json``) in headless Chromium (WebGL2 on
SwiftShader), a white metallic ``MeshStandardMaterial`` plane (F0 = 1, so the specular is ``ltc_2``'s magnitude times
the LTC integral) under one ``RectAreaLight`` of radiance 1, rendered to a float target and read back with a pass of
world positions (``validation/harness/three_browser.py``).  At each pixel the truth is the brute-force integral of
three's own BRDF (GGX, alpha = roughness^2, height-correlated Smith G2, F = 1: ``BRDF_GGX`` in three's
``lights_physical_pars_fragment``; the project's ``fit_lobes.LOBES["ggx"]``) times the cosine over the light
(``ltc_random_lights.true_integral``), zero behind the one-sided light as three has it.  Table pairs, each installed
with ``installRtLookdev`` (same texture settings, so that only the numbers differ):
- ``three``: three's own float tables (``RectAreaLightTexturesLib.LTC_FLOAT_1/2``, the published ltc_code fit);
- ``three_half``: three's own half tables (``LTC_HALF_1/2``);
- ``rtl_f32`` / ``rtl_f16``: the export's ``ltc_code`` layout (``ltc_1``/``ltc_2``, EXR) read by
  ``loadRtLookdevTables`` (three's ``EXRLoader``);
- ``three_stock``: three as shipped (``RectAreaLightUniformsLib.init()``, whose tables minify with nearest filtering).
three's horizon handling (the clipped-sphere form factor) is the same for every pair: what differs is the tables.
- ``rtl_patched``: the material patched by ``patchAreaLights`` (``engines/three/src/patch.js``; single scattering, so
  that it is the same BRDF as the truth): RT Lit's GGX LTC with its band and exact horizon clipping.
Configurations (seeded): a camera 3-5 m from a point of the plane at 20-75 deg elevation (a 20 deg field of view, so
every pixel sees the plane), a light of sides 0.5-3 m 0.8-2.5 m away, aimed at the point, its centre within 25 deg of
the camera's mirror direction for three in four configurations (so that narrow lobes see it) and anywhere above 5 deg
elevation otherwise.  Error: relative, on the pixels whose truth carries > 10% of the lobe's albedo
(``ltc_random_lights.error_stats``), per roughness and pooled.
"""
from __future__ import annotations

import argparse
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...core.export import luts
from ...core.ltc import fit
from ...core.ltc import fit_lobes as lobes
from ..harness import distribute, entry, outputs, three_browser
from . import ltc_random_lights

REPO = Path(__file__).resolve().parents[2]
ROUGHNESS = (0.1, 0.25, 0.4, 0.6, 0.8, 1.0)
TABLES = ("three", "rtl_f32", "rtl_f16", "three_half", "three_stock")
#: The patched material (engines/three/src/patch.js, single scattering so that it is the same BRDF): RT Lit's GGX
#: LTC with its band and exact horizon clipping, with three's own tables installed for everything else.
PATCHED = "rtl_patched"
OURS = {"rtl_f32": "three", "rtl_f16": "three_half"}
SEED = 3232
#: quadrature panels tried in turn for the truth; a pixel whose estimate has not converged to REFERENCE_TOLERANCE
#: (relative) by the last is left out of the statistics and counted (narrow lobes inside large lights crossing the
#: horizon: 128 panels took 5 s a pixel and did not always converge)
PANELS = (8, 32)
REFERENCE_TOLERANCE = 1e-3


def _unit(v):
    return v / np.linalg.norm(v)


def _direction(azimuth, elevation):
    return np.array([np.cos(elevation) * np.cos(azimuth), np.cos(elevation) * np.sin(azimuth), np.sin(elevation)])


def configurations(count, seed=SEED):
    """Seeded camera and light placements (harness.js' config fields), as the module docstring describes."""
    rng = np.random.default_rng(seed)
    out = []
    for k in range(count):
        target = np.append(rng.uniform(-0.5, 0.5, 2), 0.0)
        view = _direction(rng.uniform(0, 2 * np.pi), np.radians(rng.uniform(20, 75)))
        camera = target + view * rng.uniform(3, 5)
        if k % 4 != 3:            # near the mirror direction of the view at the target
            mirror = np.array([-view[0], -view[1], view[2]])
            axis = _unit(np.cross(mirror, rng.normal(size=3)))
            angle = np.radians(rng.uniform(0, 25))
            to_light = mirror * np.cos(angle) + np.cross(axis, mirror) * np.sin(angle)
            to_light[2] = max(to_light[2], np.sin(np.radians(5)))
            to_light = _unit(to_light)
        else:
            to_light = _direction(rng.uniform(0, 2 * np.pi), np.radians(rng.uniform(5, 80)))
        light = target + to_light * rng.uniform(0.8, 2.5)
        aim = target + np.append(rng.uniform(-0.3, 0.3, 2), 0.0)
        out.append({"camera": {"position": camera.tolist(), "target": target.tolist(), "fov": 20},
                    "light": {"position": light.tolist(), "target": aim.tolist(),
                              "width": float(rng.uniform(0.5, 3)), "height": float(rng.uniform(0.5, 3)),
                              "up": _unit(rng.normal(size=3)).tolist()}})
    return out


def truths(config, roughness):
    """Per pixel of one configuration: truth (n_r, n; NaN where the quadrature did not converge to
    REFERENCE_TOLERANCE), albedo (n_r, n) and view angle (n,)."""
    lobe = lobes.LOBES["ggx"]
    v_local, corners, in_front = three_browser.pixel_frames(config.positions, config.camera, config.corners)
    mu = np.clip(v_local[:, 2], 0.0, 1.0)
    truth = np.zeros((len(roughness), len(mu)))
    albedo = np.zeros_like(truth)
    for i, r in enumerate(roughness):
        for j in range(len(mu)):
            albedo[i, j] = fit.lobe_integrals(lobe, max(mu[j], fit.FIT_MU_MIN), np.array([r]), 1 << 12)[0][0]
            if in_front[j]:
                value, error = ltc_random_lights.true_integral(
                    "quad", lambda l, vv, r=r: lobe.eval_cos(l, vv, np.array(r)), v_local[j], corners[j], PANELS)
                truth[i, j] = value if error <= REFERENCE_TOLERANCE * max(abs(value), 1e-6) else np.nan
    return truth, albedo, np.arccos(mu)


@dataclass
class TruthTask:
    """One configuration's pixels (what ``truths`` needs), as a task for ``distribute.map_tasks``."""
    positions: np.ndarray
    camera: np.ndarray
    corners: np.ndarray
    roughness: tuple


def run_task(task, args):
    """The truth of one configuration (``truths``): (truth, albedo, theta)."""
    return truths(task, task.roughness)


def measure(n_configs, size, roughness=ROUGHNESS, tables=TABLES, seed=SEED, progress=entry.quiet, where=None):
    """Render in the browser and compute the truth (one task per configuration, run where ``where`` says: the
    ``--scheduler`` / ``--workers`` options of ``distribute``; None: here); returns (browser run, rows) with
    rows[r] = {"truth", "albedo", "theta", table: estimates} pooled over the configurations."""
    spec = {"size": size, "roughness": list(roughness), "tables": list(tables),
            "configs": configurations(n_configs, seed), "loadTables": ["f32", "f16"],
            "patched": [{"name": f"{PATCHED}_{i}", "params": three_browser.PATCH_VARIANTS["specular"](r, r),
                         "patch": {"specular": "single", "diffuse": "lambert", "sheen": "none"}}
                        for i, r in enumerate(roughness)]}
    with tempfile.TemporaryDirectory(prefix="rtl-three-tables-") as tmp:
        run = three_browser.render(spec, three_browser.export_tables(tmp))
    progress(f"[three ltc] rendered {n_configs} configurations x {len(roughness)} roughness x {len(tables)} table "
             f"pairs at {size} x {size} in {run.info['seconds']:.1f} s ({run.info['renderer']})")
    tasks = [TruthTask(c.positions, c.camera, c.corners, tuple(roughness)) for c in run.configs]
    records = distribute.map_tasks(f"{__name__}:run_task", tasks, where or argparse.Namespace(workers=0),
                                   progress=progress, label=lambda t: f"truth at {len(t.positions)} pixels")
    return run, collect_rows(run.configs, records, roughness, tables)


def collect_rows(configs, truths_per_config, roughness, tables):
    """rows[r] = {"truth", "albedo", "theta", table: estimates (and ``PATCHED``'s where rendered)} pooled over the
    configurations, from their read-backs and their ``truths``."""
    patched = all(f"{PATCHED}_{i}" in c.patched for c in configs for i in range(len(roughness)))
    names = (*tables, PATCHED) if patched else tuple(tables)
    rows = {r: {"truth": [], "albedo": [], "theta": [], **{t: [] for t in names}} for r in roughness}
    for config, (truth, albedo, theta) in zip(configs, truths_per_config):
        for i, r in enumerate(roughness):
            rows[r]["truth"] += list(truth[i])
            rows[r]["albedo"] += list(albedo[i])
            rows[r]["theta"] += list(theta)
            for t in tables:
                rows[r][t] += list(config.values[t][i])
            if patched:
                rows[r][PATCHED] += list(config.patched[f"{PATCHED}_{i}"])
    return rows


def summarise(rows, tables):
    """Error statistics per table: per roughness and pooled over every roughness, on the pixels whose truth
    converged (``"unconverged"``: how many did not, per roughness)."""
    keep = {r: np.isfinite(np.asarray(rw["truth"], np.float64)) for r, rw in rows.items()}
    converged = {r: {k: list(np.asarray(v)[keep[r]]) for k, v in rw.items()} for r, rw in rows.items()}
    return {"unconverged": {str(r): int((~k).sum()) for r, k in keep.items()},
            **ltc_random_lights.stats_by_roughness(converged, tables)}


def acceptance(stats):
    """Issue 32: each exported pair's median error at or below three's own pair's (float vs float, half vs half)
    at every roughness, and its pooled p90 below."""
    out = {}
    for ours, theirs in OURS.items():
        if ours not in stats or theirs not in stats:
            continue
        per_r = stats[ours]["per_roughness"]
        out[ours] = {
            "against": theirs,
            "median_at_or_below_at_every_roughness": all(
                per_r[r]["rel_median"] <= stats[theirs]["per_roughness"][r]["rel_median"] for r in per_r),
            "pooled_p90_below": stats[ours]["pooled"]["rel_p90"] < stats[theirs]["pooled"]["rel_p90"]}
    return out


def table_orientation(run):
    """The largest difference between the pair the page loaded (EXRLoader) and the export's tables as numpy
    holds them, per precision: 0 when the files arrive right way up and unchanged."""
    from ...core.lut import lookup, catalog
    source = lookup.LutSet.from_folder(catalog.default_lut_dir())
    exported = {t.name: t for t in luts.layout_tables(source, "ltc_code")}
    out = {}
    for precision, pair in run.tables.items():
        out[precision] = max(float(np.max(np.abs(pair[key] - luts.decode(*exported[stem].encode(precision)))))
                             for key, stem in (("ltc1", "ltc_1"), ("ltc2", "ltc_2")))
    return out


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--configs", type=int, default=12, help="light and camera configurations (default 12)")
    p.add_argument("--size", type=int, default=10, help="pixels per side of each render (default 10)")
    p.add_argument("--seed", type=int, default=SEED)
    p.add_argument("--out", default=str(REPO / "docs" / "benchmarks" / "three_ltc.md"))
    distribute.add_arguments(p)
    return p.parse_args(argv)


def run(args, progress=entry.flush_log):
    """Measure; writes ``args.out`` (Markdown) and the JSON beside it; returns the result."""
    t0 = time.perf_counter()
    browser, rows = measure(args.configs, args.size, seed=args.seed, progress=progress, where=args)
    stats = summarise(rows, (*TABLES, PATCHED))
    result = {"date": time.strftime("%Y-%m-%d"), "configs": args.configs, "size": args.size, "seed": args.seed,
              "roughness": list(ROUGHNESS), "browser": browser.info, "stats": stats,
              "acceptance": acceptance(stats), "loaded_table_max_difference": table_orientation(browser),
              "truth_ran": distribute.where(args),
              "seconds": time.perf_counter() - t0}
    out = Path(args.out)
    outputs.write_results(out.parent, out.stem, result, to_markdown(result))
    progress(f"wrote {out} and {out.with_suffix('.json')}")
    return result


def _median_p90(stats):
    return f"{100 * stats['rel_median']:.2f}% / {100 * stats['rel_p90']:.2f}%"


def to_markdown(result):
    """The result as Markdown (three_ltc.md)."""
    s = result["stats"]
    names = [n for n in (*TABLES, PATCHED) if n in s]
    b = result["browser"]
    lines = ["# The exported ltc_code tables in three.js, in a real browser", "",
             f"Measured {result['date']} with `python scripts/benchmark_three_ltc.py --configs {result['configs']} "
             f"--size {result['size']}` ({result['seconds']:.0f} s; `validation/benchmarks/three_ltc_benchmark.py`, "
             "whose docstring says what is rendered and how the truth is computed). three.js "
             f"r{b['three']} in headless Chromium, WebGL renderer `{b['renderer']}` (float linear filtering: "
             f"{b['floatLinear']}). {result['configs']} configurations x {result['size']}^2 pixels per roughness. "
             "Relative error on the pixels that carry > 10% of the lobe's albedo, median / p90:", "",
             "| roughness | pixels counted | truth not converged (left out) | " + " | ".join(f"`{n}`" for n in names)
             + " |", "|---|---|---|" + "---|" * len(names)]
    for r in result["roughness"]:
        key = str(r)
        count = s[names[0]]["per_roughness"][key]["lights_over_10pct"]
        lines.append(f"| {r} | {count} | {s['unconverged'][key]} | " + " | ".join(
            _median_p90(s[n]["per_roughness"][key]) for n in names) + " |")
    lines.append("| pooled | " + str(s[names[0]]["pooled"]["lights_over_10pct"]) + " | "
                 + str(sum(s["unconverged"].values())) + " | " + " | ".join(
        _median_p90(s[n]["pooled"]) for n in names) + " |")
    if PATCHED in s:
        lines += ["", f"`{PATCHED}`: the white metal patched by `patchAreaLights` (single scattering): RT Lit's GGX "
                  "LTC with its band and exact horizon clipping in place of three's LTC and clipped-sphere form "
                  "factor; the other columns differ only in their tables."]
    lines += ["", "Acceptance (issue 32: the exported pair's median at or below three's own at every roughness, and a "
              "lower pooled p90):", ""]
    for ours, a in result["acceptance"].items():
        lines.append(f"- `{ours}` against `{a['against']}`: median at or below at every roughness: "
                     f"**{a['median_at_or_below_at_every_roughness']}**; pooled p90 below: **{a['pooled_p90_below']}**")
    lines += ["", "The pair as the page loaded it (`loadRtLookdevTables`, three's `EXRLoader`) against the export's "
              "tables in numpy, largest difference: " + ", ".join(
                  f"{p} {d:.1e}" for p, d in result["loaded_table_max_difference"].items())
              + " (0: right way up, values unchanged).", ""]
    return "\n".join(lines)
