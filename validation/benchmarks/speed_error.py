"""Speed against error: what RT Lit's backends buy over Cycles path tracing of the same BRDFs.

    python scripts/benchmark_speed_error.py [--quick] [--out docs/benchmarks] [--cases NAME ...]

For a fixed, seeded set of scenes (``plan``): cases of the validation suite (``suite_cases.build_cases(
seed=0)``; quad, disk and point lights, the variants with a Cycles closure: Lambert, single-scattering GGX,
Turquin vs Multiscatter GGX), worlds of the world validation (a studio HDRI as the only light), and, in
the full mode, the demo scene (``addon/demo_scene.py``) against its Principled twin:

- ground truth: Cycles path tracing of the equivalent closures (``harness.closures.closure_material``,
  ``world_cases.closure_material``; for the demo the Principled BSDF each RT Lit material was converted
  from, ``lookdev_scene.add_path_traced_twin``), direct light only, two seeds, with its own noise
  (|c1 - c2| / 2 relative, the suite's metric, and the FLIP between the two seeds);
- the path-tracing ladder: the same scene at 1, 2, 4, ... spp with another seed, each rendered and timed;
- the backends of the RT Lit material: (1) its node group in Cycles (1 sample at pixel centres, as the
  suite's (a)), (2) in EEVEE (headless llvmpipe), (3) its emitted GLSL evaluated on this machine's OpenGL
  at the Cycles Position / Normal passes (a deferred shading pass over a G-buffer), (4) the numpy backend
  at the same passes;
- per sphere: the relative RMS error over values above the suite's floor, and the mean FLIP (LDR, fixed exposure);
  the equal-error speedup: the time path tracing needs to reach the backend's error (interpolated
  log-log between the ladder's rungs) over the backend's time.

The full mode adds how the cost grows (``speed_scaling``: lights, resolution, feature sets, EEVEE's
shader compile) and the Cycles node path on the demo scene against its last commit before per-engine
trees (``node_path_benchmark``).

Times (wall clock, this machine, ``threads`` Cycles threads): a render is ``bpy.ops.render.render``,
scene sync, shader compile, the samples and the EXR write included.  A Cycles or EEVEE render's time
splits into a fixed part (the intercept of time against samples: sync, shader compile, kernel and film)
and the per-sample part (its slope), so "render only" is the time of the samples alone, both for the
path tracer and the backends.  Details: ``format_markdown``.

Modules: speed_error_scenes.py (the plan, the scenes), speed_error_backends.py (the renders, the four
backends), speed_error_metrics.py (FLIP, RMS, the ladder, equal error), speed_error_report.py (summary,
Markdown, plots); this one runs a case and the whole benchmark.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import tempfile
import time
from pathlib import Path

import numpy as np

from ..harness import entry, metrics, outputs
from .speed_error_backends import backend_cycles, backend_eevee, backend_glsl, backend_numpy, render
from .speed_error_metrics import decay_exponent, errors, make_reference, pt_cost_model, run_ladder, speedups
from .speed_error_report import (exponent_summary, family_summary, fmt_speedup, format_markdown, plot_families,
    summary_table)
from .speed_error_scenes import FLOOR, LADDER_SEED, METRICS, plan, prepare, REF_SEEDS, REPO
from ...core.lut import lookup
from ..harness import glsl_runner


# --- one case ------------------------------------------------------------------------------------------

def run_case(spec, plan_, luts, folder, threads=2, cache_dir=None, eevee=True, glsl=True, log=print):
    """Build the case, run the backends, the references and the ladder; returns the case's record."""
    t_case = time.perf_counter()
    phases = {}
    clock = [time.perf_counter()]

    def phase(name):
        now = time.perf_counter()
        phases[name] = now - clock[0]
        clock[0] = now

    prep = prepare(spec, plan_, getattr(luts, "lut_dir", None), cache_dir)
    phase("build")
    cyc, passes = backend_cycles(prep, folder, threads)
    phase("cycles")
    n = len(prep.objects)
    index = passes["index"]
    log(f"[speed] {spec.name}: {n} spheres, {prep.resolution[0]} x {prep.resolution[1]} px, built in "
        f"{prep.build_seconds:.1f} s; RT Lit in Cycles {cyc['total_s']:.3f} s")
    backends = {"cycles": cyc}
    if eevee:
        backends["eevee"] = backend_eevee(prep, folder, plan_.eevee_repeats)
        phase("eevee")
    if glsl:
        backends["glsl"] = backend_glsl(prep, passes, [index == i + 1 for i in range(n)], luts)
        phase("glsl")
    backends["numpy"] = backend_numpy(prep, passes, index - 1, luts)
    phase("numpy")
    prep.use_pt()
    top = spec.ladder_max or plan_.ladder_max
    t0 = time.perf_counter()
    ref_renders = [render(prep.pt_scene, spec.ref_spp, s, folder, threads, passes=(k == 0))
                   for k, s in enumerate(REF_SEEDS)]
    ref_seconds = time.perf_counter() - t0
    same = ref_renders[0]["index"] == index               # both renders must see the same sphere
    interior = metrics.interior_pixels(np.where(same, index, 0))
    masks = [interior & (index == i + 1) for i in range(n)]
    ref = make_reference(prep, ref_renders, masks, index > 0)
    phase("reference")
    log(f"      reference {spec.ref_spp} spp x {len(REF_SEEDS)} seeds: {ref_seconds:.1f} s; noise (rel RMS) "
        + ", ".join(f"{v['label']} {x:.2%}" for v, x in zip(prep.variants, ref.noise)))
    rungs = run_ladder(prep, top, ref, folder, threads, log)
    phase("ladder")
    fixed, per_sample = pt_cost_model(rungs)
    for name, b in backends.items():
        if "image" in b:
            b["errors"] = errors(b.pop("image"), ref)
    prep.use_rt()
    phase("metrics")
    record = _case_record(spec, prep, backends, rungs, ref, fixed, per_sample, ref_renders,
                          time.perf_counter() - t_case, top)
    record["phases_s"] = phases
    _log_case(record, log)
    return record


def _case_record(spec, prep, backends, rungs, ref, fixed, per_sample, ref_renders, seconds, top):
    variants = []
    for i, v in enumerate(prep.variants):
        entry = {"case": spec.name, "family": v["family"], "label": v["label"], "technique": v["technique"],
                 "roughness": v["roughness"], "features": v["features"].label(), "pixels": int(ref.masks[i].sum()),
                 "floor_fraction": float(ref.floors[i]),
                 "reference": {"spp": spec.ref_spp, "seeds": list(REF_SEEDS), "noise_rel_rms": ref.noise[i],
                               "flip_between_seeds": ref.flip_noise[i]},
                 "ladder": [{"spp": r["spp"], **r["errors"][i]} for r in rungs],
                 "exponent": decay_exponent(rungs, i), "backends": {}}
        for name, b in backends.items():
            if "errors" not in b:
                continue
            e = b["errors"][i]
            entry["backends"][name] = dict(e, speedup={m: speedups(rungs, i, m, e[m], b, per_sample) for m in METRICS})
        variants.append(entry)
    timing = {name: {k: v for k, v in b.items() if k != "errors"} for name, b in backends.items()}
    return {"name": spec.name, "kind": spec.kind, "source": spec.source or (spec.world[0] if spec.world else "demo"),
            "resolution": list(prep.resolution), "spheres": len(prep.objects), "build_s": prep.build_seconds,
            "ladder_top": top, "ladder": [{k: r[k] for k in ("spp", "seconds", "seconds_all")} for r in rungs],
            "pt_fixed_s": fixed, "pt_per_sample_s": per_sample,
            "reference": {"spp": spec.ref_spp, "seeds": list(REF_SEEDS), "seconds": [r["seconds"] for r in ref_renders]},
            "flip_exposure": ref.exposure,
            "backends": timing, "variants": variants, "seconds": seconds}


def _log_case(record, log):
    for v in record["variants"]:
        parts = []
        for name, b in v["backends"].items():
            parts.append(f"{name} {b['rel_rms']:.2%}/{b['flip']:.3f} x{fmt_speedup(b['speedup']['rel_rms'])}")
        log(f"      {v['label']}: ref noise {v['reference']['noise_rel_rms']:.2%}; " + "; ".join(parts))
    log(f"      case done in {record['seconds']:.1f} s (" + ", ".join(f"{k} {v:.1f}" for k, v in record["phases_s"].items())
        + ")")


# --- driver --------------------------------------------------------------------------------------------

def _cpu_model():
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


def _settings(p, threads, command, eevee, glsl):
    import bpy

    s = {"date": time.strftime("%Y-%m-%d %H:%M"), "cpu_model": _cpu_model(), "cpu_count": os.cpu_count(),
         "platform": platform.platform(), "blender": bpy.app.version_string, "threads": threads,
         "quick": p.quick, "cell_px": p.cell, "eevee_repeats": p.eevee_repeats,
         "demo_resolution": p.demo_resolution, "ladder_max": p.ladder_max,
         "floor": FLOOR, "ladder_seed": LADDER_SEED, "reference_seeds": list(REF_SEEDS), "command": command,
         "shader_cache_disabled": glsl_runner.shader_cache_disabled(), "eevee": eevee, "glsl": glsl}
    ok, why = glsl_runner.available() if glsl else (False, "not run")
    s["gl_renderer"] = why if ok else "-"
    return s


def run(out_dir, lut_dir=None, quick=True, log=print, cases=None, cell=None, threads=2, eevee=True, glsl=True,
        cache_dir=None, command=None, image_prefix="", ladder_max=None, ref_spp=None, scaling=None, node_path=None):
    """Measure the plan (``plan(quick)``; ``cases``: only those whose name contains one of these), write
    speed_error.{md,json} and the PNG plots into ``out_dir``; returns the result with "summary_markdown" (the
    family-median table) and "passed" (every error finite).  ``ladder_max`` / ``ref_spp``: caps on the ladder's
    top and the references' samples (small development runs)."""
    glsl_runner.disable_shader_cache()          # before any OpenGL context, Blender's (EEVEE) included
    t_start = time.perf_counter()
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    p = plan(quick, cell)
    if ladder_max:
        p.ladder_max = ladder_max
        for c in p.cases:
            c.ladder_max = min(c.ladder_max or ladder_max, ladder_max)
    if ref_spp:
        for c in p.cases:
            c.ref_spp = min(c.ref_spp, ref_spp)
    if cases:
        p.cases = [c for c in p.cases if any(s in c.name for s in cases)]
    luts = lookup.LutSet.from_folder(lut_dir)
    command = command or ("python scripts/benchmark_speed_error.py" + (" --quick" if quick else ""))
    settings = _settings(p, threads, command, eevee, glsl)
    records = []
    with tempfile.TemporaryDirectory(prefix="rtl-speed-error-") as tmp:
        for spec in p.cases:
            records.append(run_case(spec, p, luts, tmp, threads, cache_dir, eevee, glsl, log))
    rows = family_summary(records)
    result = {"settings": settings, "cases": records, "families": rows, "exponents": exponent_summary(records),
              "summary_markdown": summary_table(rows)}
    # the full run adds how the cost grows and the node path against its baseline (not in the quick mode)
    if not quick if scaling is None else scaling:
        from . import speed_scaling

        log("[speed] scaling: lights, resolution, features, EEVEE compile")
        result["scaling"] = speed_scaling.run(quick=False, eevee=eevee, log=log)
    if not quick if node_path is None else node_path:
        from . import node_path_benchmark

        log(f"[speed] the Cycles node path against {node_path_benchmark.BASELINE}")
        result["node_path"] = node_path_benchmark.run(log=log)
    result["seconds"] = time.perf_counter() - t_start
    result["passed"] = all(np.isfinite(b[m]) for c in records for v in c["variants"] for b in v["backends"].values()
                           for m in METRICS) and bool(records)
    result["plots"] = plot_families(result, out_dir)
    (out_dir / "speed_error.json").write_text(json.dumps(result, indent=1, default=outputs.json_default))
    (out_dir / "speed_error.md").write_text(format_markdown(result, image_prefix))
    log(f"[speed] {len(records)} cases in {result['seconds']:.0f} s; {out_dir / 'speed_error.md'}")
    return result


def parse_args(argv):
    """The options of scripts/benchmark_speed_error.py parsed from ``argv``."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", type=Path, default=REPO / "docs" / "benchmarks",
                   help="folder of speed_error.{md,json} and the plots (default docs/benchmarks)")
    p.add_argument("--quick", action="store_true",
                   help="three small cases (a quad, a disk, a world), ladder to 256 spp, lower references")
    p.add_argument("--cases", nargs="*", default=None, help="only the cases whose name contains one of these")
    p.add_argument("--cell", type=int, default=None, help="pixels per sphere cell (default 24)")
    p.add_argument("--threads", type=int, default=2, help="Cycles threads")
    p.add_argument("--lut-dir", type=Path, default=None)
    p.add_argument("--env-cache", type=Path, default=None, help="world bake cache (default: the add-on's)")
    p.add_argument("--skip-eevee", action="store_true")
    p.add_argument("--skip-glsl", action="store_true")
    p.add_argument("--ladder-max", type=int, default=None, help="cap the ladder's top (spp; development runs)")
    p.add_argument("--ref-spp", type=int, default=None, help="cap the references' samples per seed (development runs)")
    p.add_argument("--skip-scaling", action="store_true", help="no scaling section (the full run has one)")
    p.add_argument("--skip-node-path", action="store_true",
                   help="no node-path comparison with the baseline commit (the full run has one; needs git history)")
    args = p.parse_args(argv)
    args.argv = list(argv)
    return args


def run_args(args, log=entry.flush_log):
    """``run`` with the options of ``parse_args``; logs the family table; returns the result."""
    result = run(args.out, args.lut_dir, args.quick, log, args.cases, args.cell, args.threads, not args.skip_eevee,
                 not args.skip_glsl, args.env_cache,
                 command="python scripts/benchmark_speed_error.py " + " ".join(args.argv),
                 ladder_max=args.ladder_max, ref_spp=args.ref_spp,
                 scaling=False if args.skip_scaling else None, node_path=False if args.skip_node_path else None)
    log(result["summary_markdown"])
    return result
