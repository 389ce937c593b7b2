"""Headless validation of the RT Lit World term (issue 6) under Blender's studio HDRIs.

For every studio HDRI shipped in the bpy wheel (core/environment/equirect.py ``studio_hdris``; none is
copied into the repository), plus one rotated and scaled world (Mapping node Euler XYZ rotation,
Background strength), a node block of unit spheres with RT Lit materials and a truth block of Cycles
closures are rendered (validation/checks/world_cases.py describes the scene):

  (a) node render: Cycles, 1 sample at pixel centres, the RT Lit material with its World term;
  (b) numpy: the same IR (core/materials/rt_lit.py with ``world=``) at (a)'s Position / Normal passes;
  (c) ground truth: Cycles path tracing of the equivalent closure lit by the world (max bounces 0, the
      world sampled as a light with MIS; two seeds for the noise), or the brute-force integral of the
      true BRDF over the environment.

Measured per HDRI (the acceptance numbers of issue 6):
  1. Lambert (SH irradiance) vs Cycles Diffuse BSDF: mean / median / p90 relative error; beside it the
     SH truncation alone (SH vs the image summed texel by texel) and the harness check (that texel sum
     vs Cycles, which must be within noise: it pins the mapping, rotation and strength conventions);
  2. CoD WWII diffuse: the talk's SH-LTC lobe and the "magnitude only" baseline (core/indirect.py) vs
     the brute-force integral of the true CoD BRDF, (i) under the SH-projected environment
     (``cod_diffuse_reference``: the lobe approximation alone) and (ii) under the image area-averaged to
     ``--cod-image`` x half texels with their solid angles (SH truncation included);
  3. specular, F = 1 (white metal), r in {0.1, 0.25, 0.5, 0.75, 1}: single-scattering split sum vs Cycles
     Glossy GGX; Turquin, Fdez-Aguera (irradiance form and the talk's radiance form) and Kulla-Conty vs
     Cycles Glossy Multiscatter GGX: median / p90 per roughness, per HDRI and pooled;
  4. furnace: a constant white 64 x 32 equirect as the Environment Texture; every multiscattering model
     with F0 = 1 must give 1 +- ``--furnace-tol`` for r in {0, 0.25, 0.5, 0.75, 1} (node render and numpy);
  5. (a) vs (b) on every world (validate.py's rule: 1e-4 relative where |b| >= 1e-2, 1e-6 absolute below,
     values within 4x their float32 conditioning allowed and counted);
  6. bake time per HDRI (SH and prefiltered levels; ``prefilter.bake_environment`` forced) and a cached
     re-run.

Gates (non-zero exit): (a) vs (b) on every world; the furnace; the SH-LTC CoD lobe's mean error below the
magnitude-only baseline's, per HDRI, against the SH-environment reference (the lobe approximation the
technique is about; against the full image it is reported); the harness check (texel-sum Lambert vs
Cycles median <= ``--harness-lambert-median``).  Relative errors of (a) vs (c) are over values
(pixel x channel) where c > ``--floor`` x the sphere's *median* (``--floor-wide`` also reported): under an
HDRI a sun's highlight is hundreds of times the typical value, and validate.py's max-relative floor would
keep only the highlight's few pixels (e.g. 2-6 values of a r = 0.1 sphere under sunrise / sunset).

Outputs in --out (default out/validation_world): report.json, report.md, report.html, and per world
<name>/{node_a.exr, numpy_b.exr, truth_c.exr, truth_seed*.exr, cycles_passes.exr, a.png, c.png, err_ac.png,
err_ab.png}; the bakes in <out>/env_cache (``--cache``).

Usage:
    python scripts/validate_world.py [--quick] [--hdri NAME ...] [--out DIR] [--samples 768] [--cell 32]
    blender --background --python scripts/validate_world.py -- [same options]   (needs OpenEXR importable)
    python scripts/validate_world.py --rough-diffuse only   (the rough diffuse and CoD vs Cycles' rough Diffuse
                                                             BSDF, docs/rough_diffuse.md; "add": beside the rest)
    python scripts/validate_world.py --node-world plain --node-world sky   (worlds of nodes, issue 33: a plain
        colour baked as a constant, Sky Texture / Mix worlds baked from Cycles' render; alone: only these)
Full run: 7-9 minutes on 2 cores (521 s measured with other jobs on the machine; about 6 min with
--samples 512); --quick (one rotated HDRI, few spheres, 256 spp): about 22 s.

Modules: world_run.py (one world, the furnace), world_studies.py (the CoD, Lambert and GGX studies),
world_report.py (the gated checks, Markdown and HTML); the scenes are world_cases.py.
"""
from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

import numpy as np

from ..harness import outputs
from . import world_cases as vw
from .world_report import gated_checks, html_page, markdown_tables
from .world_run import run_furnace, run_world
from .world_studies import pool_with_front
from ...core.environment import equirect
from ...core.lut import lookup


DEFAULTS = {"ab_tol": 1e-4, "ab_atol": 1e-6, "furnace_tol": 0.005, "floor": 0.1, "floor_wide": 0.01,
            "harness_lambert_median": 0.02}
#: The extra world: rotated (Euler XYZ, radians) and scaled; a small bright sun makes a wrong
#: rotation convention obvious.
ROTATED = ("sunrise", (0.35, -0.25, 2.0), 1.5)
QUICK = ("forest", (0.3, -0.2, 1.2), 1.3)
# --- driver ----------------------------------------------------------------------------------------------

def parse_args(argv):
    """The options of ``run`` (scripts/validate_world.py) parsed from ``argv``."""
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    p.add_argument("--out", default="out/validation_world")
    p.add_argument("--quick", action="store_true",
                   help=f"CI subset: {QUICK[0]} rotated and scaled, few spheres, fewer samples, small furnace")
    p.add_argument("--hdri", action="append", default=None, help="studio HDRI name or EXR path (repeatable)")
    p.add_argument("--node-world", action="append", default=None, choices=sorted(vw.NODE_WORLDS),
                   help="a world of nodes that RT Lit bakes as a constant or from Cycles' render of it (repeatable; "
                        "alone: only these worlds)")
    p.add_argument("--no-rotated", dest="rotated", action="store_false",
                   help=f"skip the rotated world ({ROTATED[0]}, Euler {ROTATED[1]}, strength {ROTATED[2]})")
    p.add_argument("--seed", type=int, default=0, help="seed of the CoD pixel subsets")
    p.add_argument("--cell", type=int, default=None, help="pixels per sphere cell (default 32, quick 24)")
    p.add_argument("--columns", type=int, default=5, help="spheres per row")
    p.add_argument("--samples", type=int, default=None,
                   help="Cycles truth samples per seed (default 768, quick 256; 0 skips the truth)")
    p.add_argument("--seeds", type=int, nargs="+", default=[0, 1])
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--segments", type=int, default=192, help="UV sphere segments (rings = half)")
    p.add_argument("--cod-pixels", type=int, default=None, help="CoD pixels per sphere (default 160, quick 120)")
    p.add_argument("--cod-image", type=int, default=256, help="width of the area-averaged image of the CoD brute force")
    p.add_argument("--lambert-image", type=int, default=512,
                   help="width of the area-averaged image of the Lambert texel sum (1024 = the full image)")
    p.add_argument("--ggx-pixels", type=int, default=None,
                   help="pixels per GGX sphere (r >= 0.25) of the brute-force GGX harness (default 48, quick 0)")
    p.add_argument("--ggx-image", type=int, default=512, help="width of the area-averaged image of the GGX brute force")
    p.add_argument("--furnace-cell", type=int, default=24)
    p.add_argument("--skip-furnace", action="store_true")
    p.add_argument("--no-bake-timing", dest="bake_timing", action="store_false",
                   help="do not force a bake per HDRI to time it")
    p.add_argument("--cache", default=None, help="bake cache folder (default <out>/env_cache)")
    p.add_argument("--lut-dir", default=None)
    p.add_argument("--rough-diffuse", choices=("off", "add", "only"), default="off",
                   help="the rough diffuse (Oren-Nayar) and CoD vs Cycles' rough Diffuse BSDF: added to the node "
                        "block, or the only rows besides Lambert")
    for k, v in DEFAULTS.items():
        p.add_argument("--" + k.replace("_", "-"), type=float, default=v)
    args = p.parse_args(argv)
    args.argv = list(argv)
    return _fill_defaults(args)


def _fill_defaults(args):
    """The defaults that depend on ``--quick`` or ``--out``."""
    if args.cell is None:
        args.cell = 24 if args.quick else 32
    if args.samples is None:
        args.samples = 256 if args.quick else 768
    if args.cod_pixels is None:
        args.cod_pixels = 120 if args.quick else 160
    if args.ggx_pixels is None:
        args.ggx_pixels = 0 if args.quick else 48
    if args.cache is None:
        args.cache = str(Path(args.out) / "env_cache")
    return args


def worlds_of(args):
    nodes = [vw.WorldSpec(kind, "", kind=kind) for kind in (args.node_world or ())]
    if nodes and not args.hdri:
        return nodes
    return _image_worlds(args) + nodes


def _image_worlds(args):
    if args.quick and not args.hdri:
        name, rot, s = QUICK
        return [vw.WorldSpec(f"{name}_rotated", str(equirect.resolve_hdri(name)), rot, s, hdri=name)]
    names = args.hdri or list(equirect.studio_hdris())
    out = []
    for n in names:
        path = equirect.resolve_hdri(n)
        out.append(vw.WorldSpec(Path(path).stem, str(path), hdri=Path(path).stem))
    if args.rotated and not args.hdri:
        name, rot, s = ROTATED
        out.append(vw.WorldSpec(f"{name}_rotated", str(equirect.resolve_hdri(name)), rot, s, hdri=name))
    return out


def run(args, log=print):
    """The whole validation: every world, the furnace, the pooled errors, the gates; writes report.md,
    report.json and report.html into ``--out`` and returns the result."""
    t_start = time.perf_counter()
    out_dir = Path(args.out)
    out_dir.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(args.seed)
    tables = lookup.LutSet.from_folder(args.lut_dir)
    worlds, parts = _run_worlds(args, out_dir, rng, tables, log)
    furnace = None if args.skip_furnace else run_furnace(args, out_dir, tables, log)
    pooled, pooled_worlds = _pool_worlds(worlds, parts)
    checks = gated_checks(args, worlds, furnace)
    result = {"passed": all(c["ok"] for c in checks), "checks": checks, "pooled": pooled,
              "pooled_worlds": ", ".join(pooled_worlds), "cod_pooled": _cod_pooled(worlds, pooled_worlds),
              "worlds": worlds,
              "furnace": furnace,
              "settings": _settings(args, tables)}
    result["timings_s"] = {"total": time.perf_counter() - t_start}
    _write_reports(out_dir, result)
    for c in checks:
        log(f"[world] {'ok  ' if c['ok'] else 'FAIL'} {c['name']}: {c['measured']} (threshold {c['threshold']})")
    log(f"[world] {'PASSED' if result['passed'] else 'FAILED'} in {result['timings_s']['total']:.1f} s; "
        f"report: {out_dir / 'report.md'}")
    return result


def _run_worlds(args, out_dir, rng, tables, log):
    """``run_world`` on every world of ``worlds_of``: the result records and the errors to pool."""
    worlds, parts = [], []
    for spec in worlds_of(args):
        rotated = any(spec.rotation) or spec.strength != 1.0
        variants = vw.node_variants(quick=args.quick or rotated, kulla_conty=not args.quick)
        if getattr(args, "rough_diffuse", "off") != "off":
            keep = [v for v in variants if v.technique == "lambert"] if args.rough_diffuse == "only" else variants
            variants = keep + vw.rough_diffuse_variants()
        r, p = run_world(spec, variants, args, out_dir, rng, tables, log,
                         bake_timing=args.bake_timing and spec.kind == "image" and not (rotated and not args.quick),
                         gate_cod=spec.kind != "plain")      # a constant world: every lobe direction is exact
        worlds.append(r)
        parts += p
    return worlds, parts


def _pool_worlds(worlds, parts):
    """The per-sphere errors pooled per (technique, roughness) over the unrotated worlds (all of them if
    none is unrotated); returns the pooled entries and the names of the pooled worlds."""
    groups = {}
    unrotated = [w["name"] for w in worlds if not any(w["rotation"]) and w["strength"] == 1.0]
    pooled_worlds = unrotated or [w["name"] for w in worlds]
    for p in parts:
        if p["world"] not in pooled_worlds:
            continue
        groups.setdefault((p["technique"], p["roughness"]), []).append(p)
    pooled = [dict(technique=t, roughness=r, **pool_with_front(e)) for (t, r), e in sorted(groups.items())]
    return pooled, pooled_worlds


def _settings(args, tables):
    """The run's settings as recorded in report.json."""
    import bpy

    return {"command": "python scripts/validate_world.py " + " ".join(args.argv),
            "blender": bpy.app.version_string, "threads": args.threads, "cpu_count": os.cpu_count(),
            "cell_px": args.cell, "samples": args.samples, "seeds": list(args.seeds),
            "quick": args.quick, "floor": args.floor, "floor_wide": args.floor_wide,
            "cod_pixels": args.cod_pixels, "cod_image": args.cod_image,
            "lambert_image": args.lambert_image, "ggx_image": args.ggx_image, "ggx_pixels": args.ggx_pixels,
            "ab_tol": args.ab_tol, "ab_atol": args.ab_atol,
            "furnace_tol": args.furnace_tol, "harness_lambert_median": args.harness_lambert_median,
            "segments": args.segments, "lut_dir": str(tables.lut_dir),
            "cache": str(args.cache)}


def _write_reports(out_dir, result):
    """report.md, report.json and report.html."""
    md = markdown_tables(result)
    (out_dir / "report.md").write_text(md)
    (out_dir / "report.json").write_text(json.dumps(result, indent=1, default=outputs.json_default))
    (out_dir / "report.html").write_text(html_page(result, md))


def _cod_pooled(worlds, names):
    """Item 2 over all the named worlds: the mean of the per-world pooled means (and per roughness)."""
    per_r = {}
    for w in worlds:
        if w["name"] not in names or not w.get("cod"):
            continue
        for row in w["cod"]["per_roughness"]:
            for k in ("ltc_vs_ref_sh", "mag_vs_ref_sh", "ltc_vs_ref_img", "mag_vs_ref_img"):
                per_r.setdefault(row["roughness"], {}).setdefault(k, []).append(row[k]["mean"])
    return {f"{r:g}": {k: float(np.mean(v)) for k, v in d.items()} for r, d in sorted(per_r.items())}
