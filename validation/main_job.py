"""RT Lookdev main job: bake the LUTs if needed, validate them, write the report.

    python scripts/run_main.py [--full] [--out out/report] [--lut-dir DIR] [--skip-render]
                               [--render-resolution N] [--render-samples S]

By default the validation suite and the world validation run in their quick forms (minutes); --full runs them
whole (about 20-30 minutes on 2 cores).

Steps (each prints what it does):
1. LUTs: bake the groups whose files are missing, stale or corrupt (cached otherwise).
2. Numpy energy checks: E and E_avg against Cycles' own table, the Kulla-Conty white
   furnace with the LUT-driven lobe, the Fdez-Aguera and Turquin furnaces, and the talk's
   E_avg polynomial.
3. LTC area lights (numpy): end-to-end error of the LTC tables on seeded random quads and
   disks against brute-force integrals (a smaller set than scripts/benchmark_ltc.py), and on lights
   crossing the receiver's horizon and lights wholly above it, reported apart, with the sphere table's
   horizon and the exact one (scripts/benchmark_horizon.py --quick's sets).
4. LUT export for engines (scripts/export_luts.py): every format and precision in both layouts into
   <out>/export/rtl and <out>/export/ltc_code, read back against the source tables.
5. Cycles render check: spheres under a white world (scripts/validate_energy.py).
6. Demo lookdev scene (scripts/build_demo_scene.py, scripts/demo_report.py): RT Lit spheres under a
   quad and a disk light, saved to <out>/demo/lookdev_demo.blend; node counts, Cycles render time,
   one EEVEE render compared with Cycles; the scene exported (<out>/demo/realtime_scene) and drawn by
   the GLSL backend's standalone renderer, compared with Cycles.
7. The lookdev scene of "New Lookdev Scene" against its path-traced twin (validation/checks/lookdev_twin.py):
   RT Lit in Cycles vs Cycles path tracing of the Principled twin, with and without the spheres'
   shadows, and EEVEE vs Cycles; <out>/lookdev/ and the pictures of docs/images/lookdev_*.png.
8. Real-time backend, quick benchmark (scripts/benchmark_realtime.py --quick): frame time of the
   emitted material on this machine's OpenGL, into <out>/benchmarks/realtime.md (the full table,
   1080p, is docs/benchmarks/realtime.md).
9. Validation suite (scripts/validate.py): node render vs numpy vs Cycles ground truth or
   brute-force integrals, per technique, with an HTML report in <out>/validation/.
10. World validation (scripts/validate_world.py): the RT Lit World term under Blender's studio HDRIs
   (Lambert vs Cycles Diffuse, SH-LTC CoD vs brute force, specular vs Cycles Glossy over a roughness
   sweep, the white furnace, node render vs numpy, bake times), report in <out>/validation_world/.
11. Robustness sweep, quick (scripts/robustness_sweep.py --points 2000): NaN, Inf, negative and
   over-bound counts per technique family and backend (numpy and GLSL; the node groups in Cycles too with --full).
12. Speed vs error, quick (scripts/benchmark_speed_error.py --quick): RT Lit in Cycles, in EEVEE, as GLSL and in
   numpy against Cycles path tracing of the same BRDFs at 1 ... 256 spp, the equal-error speedup per family, into
   <out>/benchmarks/speed_error/ (the full run is docs/benchmarks/speed_error.md).
13. Report: <out>/report.md and <out>/report.json; exit 1 if an acceptance check fails.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

from .harness import entry


from ..core import multiscatter
from ..core import energy_checks as validation  # noqa: E402
from ..core import lut_bake as bake
from ..core.lut import catalog, lookup  # noqa: E402
from ..core.export import luts as lut_export
from .benchmarks import horizon_benchmark
from .benchmarks import ltc_benchmark as benchmark_ltc
from .benchmarks import ltc_random_lights
from .benchmarks import realtime_benchmark
from .benchmarks import speed_error
from .checks import demo_measure as demo_report
from .checks import energy_render as validate_energy
from .checks import lookdev_twin
from .checks import robustness
from .checks import suite
from .checks import world_suite
from .harness import glsl_runner

REPO = Path(__file__).resolve().parents[1]

#: Acceptance thresholds of the foundation issue (documented in README.md).
E_VS_CYCLES_TOL = 1e-3          # |E - Cycles table| at its nodes, mu >= 0.1
E_AVG_R1 = (0.409, 1e-3)        # E_avg(r = 1)
FURNACE_TOL = 1e-3              # Kulla-Conty E_ss + E_ms = 1, every r, mu >= 0.1
FDEZ_FURNACE_TOL = 5e-3         # Fdez-Aguera environment BRDF with F0 = 1
LTC_MEDIAN_TOL = {"ggx": 0.015, "cod_diffuse": 0.01, "cloth": 0.01}   # quads, lights > 10% of the albedo
LTC_LIGHTS = (120, 60)          # random quads and disks per BRDF in the main job
HORIZON_LIGHTS = (24, 36)       # lights per set at the horizon: Lambert, every other lobe (of benchmark_horizon's 120)
HORIZON_LAMBERT_TOL = 1e-4      # issue 30: Lambert's exact horizon under quads and disks crossing it (float64)


def step_luts(lut_dir, log=entry.flush_log):
    log(f"[1/13] LUTs in {lut_dir}")

    def progress(group, done, total):
        if done == total or done % max(1, total // 4) == 0:
            log(f"      {group}: {done}/{total}")

    records = bake.bake(lut_dir, progress=progress, log=lambda line: log("      " + line))
    status = catalog.lut_status(lut_dir)
    return {"records": [{"group": r.group, "state": r.state, "seconds": round(r.seconds, 2)} for r in records],
            "status": {s.name: s.state for s in status},
            "passed": all(s.state == "ok" for s in status)}


def step_numpy_checks(lut_dir, log=entry.flush_log):
    log("[2/13] numpy energy checks")
    t0 = time.perf_counter()
    tables = lookup.LutSet.from_folder(lut_dir)
    cycles = validation.cycles_table_comparison(tables)
    roughness = np.linspace(0.0, 1.0, 11)
    mu = np.linspace(0.1, 1.0, 10) + 0.013
    mu = mu[mu <= 1.0]
    kc = np.abs(validation.kulla_conty_furnace(tables, roughness, mu))
    scale, bias = (tables.array("ggx_split_sum")[..., c].astype(np.float64) for c in (0, 1))
    fdez = np.abs(multiscatter.fdez_aguera_env_brdf(1.0, scale, bias) - 1.0)
    e = 1.0 - tables.array("ggx_one_minus_E")[..., 0].astype(np.float64)
    turquin = np.abs(e * multiscatter.turquin_compensation(1.0, e) - 1.0)
    talk = validation.talk_polynomial_furnace({n: tables.array(n) for n in ("ggx_one_minus_E", "ggx_one_minus_E_avg")})
    out = {
        "cycles_table": cycles,
        "kulla_conty_furnace_max_abs_err": float(kc.max()),
        "kulla_conty_furnace_grid": {"roughness": roughness.tolist(), "mu": mu.tolist()},
        "fdez_aguera_furnace_max_abs_err": float(fdez.max()),
        "turquin_furnace_max_abs_err": float(turquin.max()),
        "talk_polynomial": talk,
        "seconds": round(time.perf_counter() - t0, 2),
    }
    out["passed"] = bool(cycles["max_abs_diff_E_integrated"] < E_VS_CYCLES_TOL
                         and cycles["max_abs_diff_E_lut"] < E_VS_CYCLES_TOL
                         and abs(cycles["E_avg_r1_lut"] - E_AVG_R1[0]) <= E_AVG_R1[1]
                         and out["kulla_conty_furnace_max_abs_err"] < FURNACE_TOL
                         and out["fdez_aguera_furnace_max_abs_err"] < FDEZ_FURNACE_TOL)
    return out


def step_demo(out_dir, lut_dir, eevee=True, log=entry.flush_log):
    log("[6/13] demo lookdev scene: build, node counts, Cycles, EEVEE and GLSL renders")

    result = demo_report.run(out_dir / "demo", lut_dir=lut_dir, eevee=eevee, log=log)
    result["summary_markdown"] = demo_report.format_markdown(result, image_prefix="demo/")
    return result


def step_lookdev_twin(out_dir, lut_dir, eevee=True, log=entry.flush_log):
    log("[7/13] lookdev scene (New Lookdev Scene) vs its path-traced twin, Cycles and EEVEE")

    result = lookdev_twin.run(out_dir / "lookdev", lut_dir=lut_dir, eevee=eevee, pictures_dir=REPO / "docs" / "images",
                              log=log)
    result.pop("images")
    result["summary_markdown"] = result["summary_markdown"] + "\n" + " ".join(
        f"![{name}](lookdev/{name})" for name in result["pictures"]) + "\n"
    return result


def step_lut_export(out_dir, lut_dir, log=entry.flush_log):
    log("[4/13] LUT export for engines: every format and precision, both layouts, read back (scripts/export_luts.py)")

    t0 = time.perf_counter()
    out = {"layouts": {}}
    lines = ["| layout | folder | files | size | read back |", "|---|---|---|---|---|"]
    for layout in lut_export.LAYOUTS:
        folder = out_dir / "export" / layout
        result = lut_export.export(folder, lut_dir, layout=layout)
        check = lut_export.verify(folder, lut_dir)
        exact = all(r["max_abs"] == 0.0 for f, r in check.items() if "_f32" in f)
        bounded = all(r["within_bound"] for r in check.values())
        out["layouts"][layout] = {"folder": str(folder), "files": result.files, "read_back": check,
                                  "f32_exact": exact, "f16_within_rounding": bounded}
        lines.append(f"| {layout} | `{folder}` | {len(result.files)} | {sum(result.files.values()) / 1e6:.2f} MB | "
                     f"{len(check)} tables read back: f32 {'exact' if exact else '**differs**'}, f16 "
                     f"{'within half rounding' if bounded else '**beyond half rounding**'} |")
        log(f"      {layout}: {len(result.files)} files, {sum(result.files.values()) / 1e6:.2f} MB, read back "
            f"{'ok' if exact and bounded else 'FAILED'}")
    files = out["layouts"]["rtl"]["files"]
    lines += ["", "Files of the rtl layout (bytes):", "", "| file | size |", "|---|---|"]
    lines += [f"| {name} | {size} |" for name, size in sorted(files.items())]
    out["passed"] = all(v["f32_exact"] and v["f16_within_rounding"] for v in out["layouts"].values())
    out["seconds"] = round(time.perf_counter() - t0, 1)
    out["summary_markdown"] = "\n".join(lines) + ("\n\nManifest: `export/<layout>/manifest.json`; half precision per "
                                                   "table and end to end: docs/benchmarks/lut_export.md.")
    return out


#: The backends of the quick job's robustness sweep: the node groups in Cycles (127 of its 205 s at 2,000 points,
#: 2026-12-03) run with --full and in the full sweep (docs/benchmarks/robustness.md).
QUICK_ROBUSTNESS_BACKENDS = "numpy,glsl"


def step_robustness(out_dir, lut_dir, log=entry.flush_log, full=False):
    backends = "numpy,glsl,cycles" if full else QUICK_ROBUSTNESS_BACKENDS
    log("[11/13] robustness sweep, quick: NaN / Inf / negative / over-bound counts per family and backend "
        f"(scripts/robustness_sweep.py --points 2000 --backends {backends})")

    out = out_dir / "benchmarks" / "robustness.md"
    argv = ["--points", "2000", "--backends", backends, "--out", str(out)] + \
        (["--lut-dir", str(lut_dir)] if lut_dir else [])
    result = robustness.run(robustness.parse_args(argv), log=lambda line: None)
    rows = ["| backend | evaluations | NaN | Inf | negative | over bound |", "|---|---|---|---|---|---|"]
    for backend, families in result["summary"].items():
        total = {k: sum(f[k] for f in families.values()) for k in ("points", "nan", "inf", "negative", "over_bound")}
        rows.append(f"| {backend} | {total['points']:,} | {total['nan']} | {total['inf']} | {total['negative']} | "
                    f"{total['over_bound']} |")
        log(f"      {backend}: {total['points']:,} evaluations, {total['nan'] + total['inf'] + total['negative'] + total['over_bound']} failures")
    rows += [f"| {b} | not run: {why} | | | | |" for b, why in result["skipped"].items()]
    text = "\n".join(rows) + (f"\n\nPer family: `{out}`; the full sweep (10^6 points per family and backend): "
                              "docs/benchmarks/robustness.md (`python scripts/robustness_sweep.py`); method, "
                              "findings and the bad-input table: docs/robustness.md.")
    return {"failures": result["failures"], "summary": result["summary"], "skipped": result["skipped"],
            "passed": result["failures"] == 0, "summary_markdown": text}


def step_speed_error(out_dir, lut_dir, eevee=True, log=entry.flush_log):
    log("[12/13] speed vs error, quick: RT Lit's backends against path tracing at equal error "
        "(scripts/benchmark_speed_error.py --quick)")

    folder = out_dir / "benchmarks" / "speed_error"
    cache = out_dir / "validation_world" / "env_cache"           # the world validation's bakes, when there
    result = speed_error.run(folder, lut_dir=lut_dir, quick=True, log=lambda line: log("      " + line), eevee=eevee,
                             cache_dir=cache if cache.is_dir() else None,
                             command="python scripts/benchmark_speed_error.py --quick (main job)")
    text = (result["summary_markdown"] + "\n\nPath tracing's error decay (rel RMS ~ spp^-k), median k per family: "
            + ", ".join(f"{f} {e['median']:.2f}" for f, e in result["exponents"].items())
            + f".  Method, times and per-sphere rows: `{folder / 'speed_error.md'}`; the full run: "
            "docs/benchmarks/speed_error.md (`python scripts/benchmark_speed_error.py`).")
    return {"passed": bool(result["passed"]), "families": result["families"], "exponents": result["exponents"],
            "seconds": result["seconds"], "summary_markdown": text}


def step_realtime_benchmark(out_dir, log=entry.flush_log):
    log("[8/13] real-time backend: frame time of the emitted material, quick (scripts/benchmark_realtime.py --quick)")

    glsl_runner.disable_shader_cache()
    ok, why = glsl_runner.available()
    if not ok:
        log(f"      skipped: {why}")
        return {"available": why, "passed": True, "summary_markdown": f"Not run: {why}."}
    args = realtime_benchmark.parse_args(["--quick", "--out", str(out_dir / "benchmarks" / "realtime.md")])
    result = realtime_benchmark.run(args, progress=lambda line: log("      " + line))
    finite = all(r["finite"] for r in result["rows"] if not r.get("gpu"))
    text = realtime_benchmark.to_markdown(result).split("\n", 2)[2]        # without the title
    return {"rows": result["rows"], "passed": finite, "summary_markdown": text + "\nFull table (1920 x 1080, 1/4/16 "
            "lights): docs/benchmarks/realtime.md (`python scripts/benchmark_realtime.py`)."}


def _run_suite(module, folder, lut_dir, log, full=False):
    """Run a validation module (``suite`` or ``world_suite``) into ``folder``, its quick form unless ``full``:
    (result, checks table)."""
    argv = ["--out", str(folder)] + (["--lut-dir", str(lut_dir)] if lut_dir else []) + ([] if full else ["--quick"])
    result = module.run(module.parse_args(argv), log=lambda line: log("      " + line))
    lines = ["| check | measured | threshold | |", "|---|---|---|---|"]
    lines += [f"| {c['name']} | {c['measured']} | {c['threshold']} | {'ok' if c['ok'] else '**FAIL**'} |"
              for c in result["checks"]]
    return result, lines


def step_validation(out_dir, lut_dir, log=entry.flush_log, full=False):
    log("[9/13] validation suite: node render vs numpy vs Cycles ground truth (scripts/validate.py"
        + ("" if full else " --quick") + ")")

    result, lines = _run_suite(suite, out_dir / "validation", lut_dir, log, full)
    return {"passed": bool(result["passed"]), "checks": result["checks"],
            "summary_markdown": "\n".join(lines) + f"\n\nFull report: `{out_dir / 'validation' / 'report.html'}`."}


def step_world_validation(out_dir, lut_dir, log=entry.flush_log, full=False):
    log("[10/13] world validation: the World term under the studio HDRIs (scripts/validate_world.py"
        + ("" if full else " --quick") + ")")

    result, lines = _run_suite(world_suite, out_dir / "validation_world", lut_dir, log, full)
    report_md = out_dir / "validation_world" / "report.md"
    return {"passed": bool(result["passed"]), "checks": result["checks"],
            "summary_markdown": "\n".join(lines) + f"\n\nFull report (per HDRI and roughness): `{report_md}`."}


def step_render(out_dir, lut_dir, resolution, samples, log=entry.flush_log):
    log("[5/13] Cycles white-furnace render check (4 roughness values, 2 distributions, 2 seeds)")

    options = {k: v for k, v in (("resolution", resolution), ("samples", samples)) if v is not None}
    result = validate_energy.measure(out_dir=out_dir / "energy_render", lut_dir=lut_dir,
                                 log=lambda line: log("      " + line), **options)
    result["summary_markdown"] = validate_energy.to_markdown(result)
    return result


def step_ltc(lut_dir, log=entry.flush_log):
    log("[3/13] LTC area lights: random quads and disks vs brute force")

    t0 = time.perf_counter()
    tables = {name: benchmark_ltc.exr_io_read(lut_dir, name) for name in catalog.TABLES if name.startswith("ltc_")}
    results = ltc_random_lights.end_to_end(tables, None, *LTC_LIGHTS)
    out = {"lights_per_brdf": {"quads": LTC_LIGHTS[0], "disks": LTC_LIGHTS[1]}, "results": results,
           "seconds": round(time.perf_counter() - t0, 1)}
    log("      at the horizon: lights crossing it and lights wholly above it, apart")
    luts = lookup.LutSet.from_folder(lut_dir)
    seed = horizon_benchmark.parse_args([]).seed
    lambert = horizon_benchmark.lambert_study(luts, HORIZON_LIGHTS[0], seed)
    out["horizon"] = {"lights_per_set": {"lambert": HORIZON_LIGHTS[0], "lobes": HORIZON_LIGHTS[1]}, "lambert": lambert,
                      "lobes": horizon_benchmark.lobe_study(luts, HORIZON_LIGHTS[1], seed + 1)}
    out["seconds"] = round(time.perf_counter() - t0, 1)
    out["passed"] = (all(results[f"{lobe}/quad"]["ours"]["rel_median"] <= tol for lobe, tol in LTC_MEDIAN_TOL.items())
                     and all(lambert[f"{kind}/crossing"]["exact horizon"]["rel_max"] <= HORIZON_LAMBERT_TOL
                             for kind in ("quad", "disk")))
    return out


def horizon_markdown(horizon):
    """The main job report's section on lights at the horizon (step 3)."""
    lines = ["### At the horizon", "",
             f"{horizon['lights_per_set']['lambert']} lights per set for Lambert, {horizon['lights_per_set']['lobes']} "
             "per set and lobe for the others, crossing the horizon or wholly above it (acceptance: Lambert's exact "
             f"horizon under crossing quads and disks, max relative error <= {HORIZON_LAMBERT_TOL:g}). Full "
             "benchmark: `python scripts/benchmark_horizon.py` "
             "(docs/benchmarks/horizon.md).", "",
             "| Lambert / light | n | exact horizon: median / max | float32: max | sphere table: median / max |",
             "|---|---|---|---|---|"]
    for key, e in horizon["lambert"].items():
        ex, f32, table = (e[m] for m in ("exact horizon", "exact horizon, float32", "sphere table (default)"))
        lines.append(f"| {key} | {e['lights']} | {ex['rel_median']:.1e} / {ex['rel_max']:.1e} | {f32['rel_max']:.1e} | "
                     f"{table['rel_median']:.1e} / {table['rel_max']:.1e} |")
    lines += ["", "| lobe / light / set | n (>10%) | sphere table: median / p90 | exact horizon: median / p90 |",
              "|---|---|---|---|"]
    def percent(stats):
        if not stats["lights_over_10pct"]:
            return "-"
        return f"{100 * stats['rel_median']:.2f}% / {100 * stats['rel_p90']:.1f}%"

    for key, models in horizon["lobes"].items():
        table, ex = (models[m] for m in ("sphere table (default)", "exact horizon"))
        lines.append(f"| {key} | {ex['lights_over_10pct']}/{ex['lights']} | {percent(table)} | {percent(ex)} |")
    return lines + [""]


def write_report(job, out_dir):
    out_dir.mkdir(parents=True, exist_ok=True)
    (out_dir / "report.json").write_text(json.dumps(job, indent=2, default=float))
    n = job["numpy_checks"]
    c = n["cycles_table"]
    lines = ["# RT Lookdev report", "",
             f"Generated by `bash scripts/main.sh{' --full' if job.get('mode') == 'full' else ''}` on {job['date']} "
             f"in {job['seconds']:.0f} s: the "
             + ("whole validation suite and world validation." if job.get("mode") == "full" else
                "quick forms of the validation suite and the world validation (`--full` runs them whole)."), "",
             "## LUTs", ""]
    lines += [f"- `{name}`: {state}" for name, state in job["luts"]["status"].items()]
    lines += ["- bake: " + ", ".join(f"{r['group']} {r['state']} ({r['seconds']} s)" for r in job["luts"]["records"]),
              "", "## Energy (numpy)", "",
              "| check | value | acceptance |", "|---|---|---|",
              f"| max abs(E - Cycles table), integrator | {c['max_abs_diff_E_integrated']:.2e} | < {E_VS_CYCLES_TOL} |",
              f"| max abs(E - Cycles table), LUT | {c['max_abs_diff_E_lut']:.2e} | < {E_VS_CYCLES_TOL} |",
              f"| max abs(E_avg - Cycles table), LUT | {c['max_abs_diff_E_avg_lut']:.2e} | |",
              f"| E_avg(r = 1), LUT | {c['E_avg_r1_lut']:.5f} | {E_AVG_R1[0]} +- {E_AVG_R1[1]} |",
              f"| Kulla-Conty furnace, max abs(E_ss + E_ms - 1), r in [0, 1], mu >= 0.1 | "
              f"{n['kulla_conty_furnace_max_abs_err']:.2e} | < {FURNACE_TOL} |",
              f"| Fdez-Aguera furnace (F0 = 1), max over table cells | {n['fdez_aguera_furnace_max_abs_err']:.2e} | < {FDEZ_FURNACE_TOL} |",
              f"| Turquin furnace (F0 = 1), max over table cells | {n['turquin_furnace_max_abs_err']:.2e} | |",
              f"| talk's AverageEnergy polynomial: max abs(fit - E_avg) | {n['talk_polynomial']['max_abs_err_vs_table']:.4f} "
              f"(r = {n['talk_polynomial']['at_r']:.3f}) | reported |",
              f"| Kulla-Conty furnace with the talk's polynomial as E_avg, mu >= 0.1 | "
              f"{n['talk_polynomial']['furnace_max_err_mu_ge_0.1']:.3f} | reported (why the table's E_avg ships) |",
              ""]
    ltc = job["ltc"]
    lines += ["## LTC area lights (numpy, seeded random lights vs brute force)", "",
              f"{ltc['lights_per_brdf']['quads']} quads and {ltc['lights_per_brdf']['disks']} disks per BRDF; relative "
              "error on lights carrying > 10% of the lobe's albedo (acceptance: median of quads "
              + ", ".join(f"{k} <= {100 * v:.1f}%" for k, v in LTC_MEDIAN_TOL.items())
              + "). Full benchmark: `python scripts/benchmark_ltc.py` (docs/benchmarks/ltc.md).", "",
              "| BRDF / light | n (>10%) | rel median | rel p90 | abs/albedo median |", "|---|---|---|---|---|"]
    for key, e in ltc["results"].items():
        o = e["ours"]
        lines.append(f"| {key} | {o['lights_over_10pct']}/{o['lights']} | {100 * o['rel_median']:.2f}% | "
                     f"{100 * o['rel_p90']:.1f}% | {100 * o['abs_over_albedo_median']:.2f}% |")
    lines.append("")
    if "horizon" in ltc:
        lines += horizon_markdown(ltc["horizon"])
    export = job.get("lut_export")
    lines += ["## LUT export for engines", ""]
    lines += [export["summary_markdown"], ""] if export else ["Skipped.", ""]
    render = job.get("render")
    lines += ["## Cycles render check (spheres under a white world)", ""]
    if render is None:
        lines += ["Skipped (--skip-render).", ""]
    else:
        settings = render["settings"]
        lines += [f"{settings['resolution_per_sphere']} px per sphere, {settings['samples']} spp, seeds "
                  f"{settings['seeds']}; per-bin acceptance |bias| <= {settings['z_max']} SE + {settings['sys_tol']} "
                  f"(GGX vs our E), Multiscatter GGX 1 +- {settings['ms_tol']}. Full numbers in "
                  f"energy_render/energy_validation.json.", "", render["summary_markdown"], ""]
    demo = job.get("demo")
    lines += ["## Demo lookdev scene (RT Lit materials)", ""]
    lines += [demo["summary_markdown"], ""] if demo else ["Skipped (--skip-render).", ""]
    twin = job.get("lookdev_twin")
    lines += ["## The lookdev scene against its path-traced twin", ""]
    lines += [twin["summary_markdown"], ""] if twin else ["Skipped (--skip-render).", ""]
    bench = job.get("realtime_benchmark")
    lines += ["## Real-time backend: frame time (quick)", ""]
    lines += [bench["summary_markdown"], ""] if bench else ["Skipped.", ""]
    val = job.get("validation")
    lines += ["## Validation suite (node render, numpy, Cycles ground truth)", ""]
    lines += [val["summary_markdown"], ""] if val else ["Skipped (--skip-render).", ""]
    world = job.get("world_validation")
    lines += ["## World validation (the World term under the studio HDRIs)", ""]
    lines += [world["summary_markdown"], ""] if world else ["Skipped (--skip-render).", ""]
    robust = job.get("robustness")
    lines += ["## Robustness (quick sweep)", ""]
    lines += [robust["summary_markdown"], ""] if robust else ["Skipped.", ""]
    speed = job.get("speed_error")
    lines += ["## Speed vs error (quick): equal-error speedup over path tracing", ""]
    lines += [speed["summary_markdown"], ""] if speed else ["Skipped (--skip-render).", ""]
    if job.get("step_seconds"):
        lines += ["## Time per step", "", "| step | seconds |", "|---|---|"]
        lines += [f"| {key} | {seconds:.1f} |" for key, seconds in job["step_seconds"].items()] + [""]
    lines += [f"Overall: **{'PASS' if job['passed'] else 'FAIL'}**", ""]
    (out_dir / "report.md").write_text("\n".join(lines))


def parse_args(argv):
    """The options of scripts/run_main.py (scripts/main.sh) parsed from ``argv``."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", type=Path, default=REPO / "out" / "report")
    p.add_argument("--lut-dir", type=Path, default=catalog.default_lut_dir())
    p.add_argument("--skip-render", action="store_true", help="skip the Cycles render check and the demo scene")
    p.add_argument("--skip-eevee", action="store_true", help="demo scene: skip the EEVEE render")
    p.add_argument("--render-resolution", type=int, default=None, help="pixels per sphere")
    p.add_argument("--render-samples", type=int, default=None, help="Cycles samples per pixel")
    p.add_argument("--full", action="store_true",
                   help="the whole validation suite and world validation (about 20-30 minutes on 2 cores) instead "
                        "of their quick forms (the default: minutes)")
    return p.parse_args(argv)


def _passed(job):
    """Every step passed (a skipped render step, None, counts as passed)."""
    return bool(job["luts"]["passed"] and job["numpy_checks"]["passed"] and job["ltc"]["passed"]
                and all(job.get(k) is None or job[k].get("passed", False)
                        for k in ("lut_export", "render", "demo", "lookdev_twin", "realtime_benchmark", "validation",
                                  "world_validation", "robustness", "speed_error")))


#: The Cycles render check's (pixels per sphere, samples) in the quick main job (--full: the check's own defaults, 256
#: and 256): its four renders took 197 s of a 1166 s quick run at full size (2026-12-03, 2 cores).
QUICK_RENDER = (128, 64)


def _timed(job, key, step, *args, **kwargs):
    """``job[key] = step(*args, **kwargs)``, its wall time in ``job["step_seconds"][key]``."""
    t0 = time.perf_counter()
    job[key] = step(*args, **kwargs)
    job.setdefault("step_seconds", {})[key] = round(time.perf_counter() - t0, 1)
    return job[key]


def run(args, log=entry.flush_log):
    """Every step, then the report (``args.out``/report.md, report.json).  Returns the report dict; when
    the LUTs are not usable, stops after step 1 with ``{"luts": ..., "passed": False}`` (no report)."""
    t0 = time.perf_counter()
    job = {"date": time.strftime("%Y-%m-%d %H:%M:%S"), "mode": "full" if args.full else "quick"}
    _timed(job, "luts", step_luts, args.lut_dir, log)
    if not job["luts"]["passed"]:
        print("LUTs are not usable; see the status above", file=sys.stderr)
        job["passed"] = False
        return job
    _timed(job, "numpy_checks", step_numpy_checks, args.lut_dir, log)
    _timed(job, "ltc", step_ltc, args.lut_dir, log)
    _timed(job, "lut_export", step_lut_export, args.out, args.lut_dir, log)
    job["render"] = job["demo"] = job["lookdev_twin"] = job["validation"] = job["world_validation"] = None
    job["speed_error"] = None
    quick_resolution, quick_samples = (None, None) if args.full else QUICK_RENDER
    if not args.skip_render:
        _timed(job, "render", step_render, args.out, args.lut_dir, args.render_resolution or quick_resolution,
               args.render_samples or quick_samples, log)
        _timed(job, "demo", step_demo, args.out, args.lut_dir, eevee=not args.skip_eevee, log=log)
        _timed(job, "lookdev_twin", step_lookdev_twin, args.out, args.lut_dir, eevee=not args.skip_eevee, log=log)
    _timed(job, "realtime_benchmark", step_realtime_benchmark, args.out, log)
    if not args.skip_render:
        _timed(job, "validation", step_validation, args.out, args.lut_dir, log, args.full)
        _timed(job, "world_validation", step_world_validation, args.out, args.lut_dir, log, args.full)
    _timed(job, "robustness", step_robustness, args.out, args.lut_dir, log, args.full)
    if not args.skip_render:
        _timed(job, "speed_error", step_speed_error, args.out, args.lut_dir, eevee=not args.skip_eevee, log=log)
    job["passed"] = _passed(job)
    job["seconds"] = time.perf_counter() - t0
    log("[13/13] report")
    write_report(job, args.out)
    log((args.out / "report.md").read_text())
    log(f"report written to {args.out / 'report.md'} and report.json")
    return job
