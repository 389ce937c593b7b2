"""LTC fit and accuracy report: bake time, per-cell lobe error, magnitude error, end-to-end
error on random quad and disk lights, with the published GGX table through the same code.

    python scripts/benchmark_ltc.py [--out docs/benchmarks] [--repeats 3] [--quick]
                                    [--lut-dir DIR] [--skip-bake]

Writes ltc.json, ltc.md and PNG heat maps (ltc_tv_<lobe>.png, ltc_tv_ggx_published.png) to --out.

The end-to-end measurements over random lights are ltc_random_lights.py.
"""
from __future__ import annotations

import argparse
import json
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

from ...core import energy, lut_bake as bake
from ...core.ltc import disk, fit, fit_lobes as lobes, polygon
from ...core.lut import catalog, lookup
from ..harness import entry, outputs, png as _png
from .ltc_random_lights import (disk_exactness, disney_sheen_models, end_to_end, error_stats, fmt_stats,
    random_lights, sheen_markdown, sheen_via_diffuse_table, true_integral, zeltner_exactness)
from ...core import rough_diffuse as rd
from ...core.lut import exr_io
from ...core.materials import lobes as rt_lobes
from ..harness import published_ltc as ltc_anchor


REPO = Path(__file__).resolve().parents[2]
LTC_GROUPS = list(catalog.LTC_LOBES)


def bake_time(repeats):
    """Wall time of baking every table of every BRDF from scratch (parallel bake, all cores)."""
    runs = []
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(repeats):
            t0 = time.perf_counter()
            records = bake.bake(tmp, force=True, log=lambda line: None)
            runs.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        cached = bake.bake(tmp, log=lambda line: None)
        cached_s = time.perf_counter() - t0
    return {"median_s": statistics.median(runs), "runs_s": runs,
            "per_group_s_last_run": {r.group: r.seconds for r in records},
            "cached_rerun_s": cached_s, "cached_states": sorted({r.state for r in cached})}


def table_nodes():
    nodes = np.arange(catalog.LTC_SIZE) / (catalog.LTC_SIZE - 1)
    mu = np.maximum(1.0 - nodes ** 2, fit.FIT_MU_MIN)
    return nodes, mu


def tv_map(lobe_name, packed, magnitude, n, band=None, weight=None):
    """TV distance of every table cell (t, a); with a band (``catalog.LTC_BANDS``) and its weight per cell, of
    the mixture the shading uses."""
    lobe = lobes.LOBES[lobe_name]
    nodes, mu = table_nodes()
    fit_band = fit.Band(**band) if band is not None else None
    return np.stack([fit.tv_distance(lobe, mu[t], nodes, magnitude[t], packed[t], n=n, band=fit_band,
                                     weight=None if weight is None else weight[t]) for t in range(nodes.size)])


def magnitude_check(ltc_mag, published_mag, n_ref):
    """GGX magnitude against a converged integral (2^n_ref points per cell, every 2nd node)."""
    nodes, mu = table_nodes()
    rows = np.arange(0, nodes.size, 2)
    theta = np.degrees(np.arccos(mu[rows]))
    ref = energy.directional_albedo(mu[rows], nodes, 1 << n_ref).T          # (rows, a)
    ours = np.abs(ltc_mag[rows] / ref - 1.0)
    pub = np.abs(published_mag[rows] / ref - 1.0) if published_mag is not None else None
    sel = theta <= 89.0
    out = {"reference_samples": 1 << n_ref, "cells": int(ours[sel].size),
           "ours_max_rel_err_theta_le_89": float(ours[sel].max()),
           "ours_max_rel_err_all_rows": float(ours.max())}
    if pub is not None:
        out["published_max_rel_err_theta_le_89"] = float(pub[sel].max())
        out["published_last_row_rel_err_mean"] = float(pub[-1].mean())
    return out


def fit_quality(tables, published, n_tv, out_dir, prefixes=None):
    out = {}
    for prefix, (lobe_name, _) in catalog.LTC_LOBES.items():
        if prefixes is not None and prefix not in prefixes:
            continue
        packed = tables[prefix + "_inv"].astype(np.float64)
        mag = tables[prefix + "_mag"][..., 0].astype(np.float64)
        band = catalog.LTC_BANDS.get(prefix)
        tv = tv_map(lobe_name, packed, mag, n_tv, band, tables[prefix + "_mag"][..., 2] if band else None)
        entry = {"tv_mean": float(tv.mean()), "tv_p90": float(np.quantile(tv, 0.9)), "tv_max": float(tv.max())}
        _png.heatmap(out_dir / f"ltc_tv_{lobe_name}.png", tv, vmax=0.3)
        if prefix == "ltc_ggx" and published is not None:
            tv_pub = tv_map(lobe_name, published[0], mag, n_tv)
            _png.heatmap(out_dir / "ltc_tv_ggx_published.png", tv_pub, vmax=0.3)
            entry.update({
                "published_tv_mean": float(tv_pub.mean()), "published_tv_p90": float(np.quantile(tv_pub, 0.9)),
                "fraction_cells_no_worse": float(np.mean(tv <= tv_pub)),
                "fraction_cells_no_worse_within_1e-3": float(np.mean(tv <= tv_pub + 1e-3)),
                # the published table was fitted with alpha >= 1e-5, ours with alpha >= 1e-4: its r = 0
                # column approximates a narrower lobe, so the comparison is also given without it
                "fraction_cells_no_worse_excluding_r0": float(np.mean(tv[:, 1:] <= tv_pub[:, 1:])),
                "tv_mean_excluding_r0": float(tv[:, 1:].mean()),
                "published_tv_mean_excluding_r0": float(tv_pub[:, 1:].mean()),
                "worse_cells_tv": [[int(t), int(a), float(tv[t, a]), float(tv_pub[t, a])]
                                   for t, a in np.argwhere(tv > tv_pub + 1e-3)][:20],
            })
        out[lobe_name] = entry
    return out


def write_markdown(res, path):
    b = res.get("bake")
    lines = ["# LTC fit and accuracy", "",
             f"Command: `python scripts/benchmark_ltc.py` ({res['machine']}, {res['date']}). "
             "Ground truth: brute-force BRDF x cos over the light (core/ltc/reference.py, Gauss-Legendre "
             "over the light's area, converged to 1e-4 relative by its two-resolution check).", ""]
    if b:
        lines += ["## Bake time (all tables of all BRDFs, parallel bake on all cores)", "",
                  f"Median **{b['median_s']:.1f} s** of {len(b['runs_s'])} runs ({', '.join(f'{t:.1f}' for t in b['runs_s'])} s); "
                  f"per group in the last run: " + ", ".join(f"{k} {v:.1f} s" for k, v in b["per_group_s_last_run"].items())
                  + f". A cached re-run took {b['cached_rerun_s']:.2f} s (states: {', '.join(b['cached_states'])}).", ""]
    notes = []
    lines += ["## Lobe error per table cell (total-variation distance, 0 = identical)", "",
              "| lobe | mean | p90 | max | published GGX table: mean / p90 | cells no worse than published |",
              "|---|---|---|---|---|---|"]
    for name, q in res["fit_quality"].items():
        pub = (f"{q['published_tv_mean']:.4f} / {q['published_tv_p90']:.4f}" if "published_tv_mean" in q else "-")
        frac = (f"{100 * q['fraction_cells_no_worse']:.1f}% ({100 * q['fraction_cells_no_worse_within_1e-3']:.1f}% "
                f"within 1e-3)" if "fraction_cells_no_worse" in q else "-")
        lines.append(f"| {name} | {q['tv_mean']:.4f} | {q['tv_p90']:.4f} | {q['tv_max']:.4f} | {pub} | {frac} |")
        if "fraction_cells_no_worse_excluding_r0" in q:
            excl = (f"Without the r = 0 column (the published table was fitted with alpha >= 1e-5, ours with "
                    f"alpha >= 1e-4, so there it approximates a narrower lobe): mean {q['tv_mean_excluding_r0']:.4f} vs "
                    f"{q['published_tv_mean_excluding_r0']:.4f}, {100 * q['fraction_cells_no_worse_excluding_r0']:.1f}% of "
                    f"cells no worse. Cells worse by more than 1e-3: " + ", ".join(
                        f"(t={w[0]}, a={w[1]}: {w[2]:.3f} vs {w[3]:.3f})" for w in q["worse_cells_tv"]) + ".")
            notes.append(excl)
    lines += [""] + notes
    lines += ["", "Heat maps (u = roughness, v = sqrt(1 - mu), colour 0..0.3): "
              + ", ".join(f"`ltc_tv_{n}.png`" for n in res["fit_quality"]) + ", `ltc_tv_ggx_published.png`.", ""]
    m = res["magnitude"]
    lines += ["## GGX magnitude against a converged integral", "",
              f"{m['cells']} cells ({m['reference_samples']} points each): max relative error with theta <= 89 deg: "
              f"ours **{100 * m['ours_max_rel_err_theta_le_89']:.3f}%**, published "
              f"{100 * m.get('published_max_rel_err_theta_le_89', float('nan')):.2f}%; published grazing row t = 63: "
              f"mean {100 * m.get('published_last_row_rel_err_mean', float('nan')):.1f}% off.", ""]
    lines += ["## End-to-end error on random lights", "",
              "Relative error on lights carrying > 10% of the lobe's albedo; absolute error as a fraction of the albedo on all lights.", "",
              "| lobe / light | table | n (>10%) | rel median | rel p90 | rel max | abs/albedo median | abs/albedo p90 |",
              "|---|---|---|---|---|---|---|---|"]
    for key, e in res["end_to_end"].items():
        lines.append(f"| {key} | ours | {fmt_stats(e['ours'])}")
        if "published" in e:
            lines.append(f"| {key} | published | {fmt_stats(e['published'])}")
    lines += ["", "By view angle (relative error, lights > 10%):", "",
              "| lobe / light | table | 0-30 deg median / p90 | 30-60 | 60-80 |", "|---|---|---|---|---|"]
    for key, e in res["end_to_end"].items():
        for table in ("ours", "published"):
            if table in e:
                bv = e[table]["by_view_angle"]
                cells = [f"{100 * bv[k]['rel_median']:.2f}% / {100 * bv[k]['rel_p90']:.1f}% (n={bv[k]['n']})"
                         if k in bv else "-" for k in ("0-30", "30-60", "60-80")]
                lines.append(f"| {key} | {table} | " + " | ".join(cells) + " |")
    s = res["sheen"]
    lines += ["", "## Disney sheen through the CoD diffuse table at r = 0.5 (the talk's approximation)", "",
              "| light | n (>10%) | rel median | rel p90 | rel max | abs/albedo median | abs/albedo p90 |",
              "|---|---|---|---|---|---|---|", f"| quad | {fmt_stats(s)}", ""]
    if "disney_sheen_models" in res:
        lines += sheen_markdown(res)
    d = res["disk_exactness"]
    lines += ["## Disk closed form", "",
              f"{d['disks_above_horizon']} random disks entirely above the transformed horizon: max relative difference "
              f"between the closed form and numeric integration of the same LTC: {d['max_rel_diff_closed_form_vs_numeric']:.1e}.", ""]
    path.write_text("\n".join(lines))


def parse_args(argv):
    """The options of scripts/benchmark_ltc.py parsed from ``argv``."""
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--out", type=Path, default=REPO / "docs" / "benchmarks")
    p.add_argument("--lut-dir", type=Path, default=catalog.default_lut_dir())
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--quick", action="store_true", help="small sets, no bake timing (smoke run)")
    p.add_argument("--skip-bake", action="store_true", help="do not time the bake")
    p.add_argument("--lobes", nargs="+", default=None, choices=[lobe for lobe, _ in catalog.LTC_LOBES.values()],
                   help="only these lobes' tables (fit error and random lights; the rough diffuse's area forms with "
                        "oren_nayar), written to ltc_<lobes>.md / .json; ltc.md is left alone")
    p.add_argument("--sheen-only", action="store_true",
                   help="only the sheen comparison: sheen_ltc.{json,md} in --out (the same section as in ltc.md)")
    return p.parse_args(argv)


def run(args, log=entry.flush_log):
    """Measure, write ltc.json, ltc.md and the heat maps to ``args.out``; returns the results."""
    args.out.mkdir(parents=True, exist_ok=True)
    import os
    import platform

    res = {"machine": f"{platform.machine()}, {os.cpu_count()} cores", "date": time.strftime("%Y-%m-%d")}
    if getattr(args, "lobes", None):
        return run_lobes(args, res, log)
    status = catalog.lut_status(args.lut_dir)
    if any(s.state != "ok" for s in status):
        log("[bench] baking the LUTs first")
        bake.bake(args.lut_dir)
    tables = {name: exr_io_read(args.lut_dir, name) for name in catalog.TABLES if name.startswith("ltc_")}
    if getattr(args, "sheen_only", False):
        n = (60, 30) if args.quick else (600, 300)
        res["disney_sheen_models"] = disney_sheen_models(tables, *n)
        res["zeltner_exactness"] = zeltner_exactness(args.lut_dir, *n)
        (args.out / "sheen_ltc.json").write_text(json.dumps(res, indent=2))
        (args.out / "sheen_ltc.md").write_text("\n".join(
            ["# Sheen LTCs", "", f"Command: `python scripts/benchmark_ltc.py --sheen-only` ({res['machine']}, "
             f"{res['date']}); the same section is part of ltc.md on a full run.", ""] + sheen_markdown(res)))
        log((args.out / "sheen_ltc.md").read_text())
        return res
    try:
        published = ltc_anchor.load_anchor()
    except FileNotFoundError:
        published = None
        log("[bench] published table not found; comparison rows skipped")
    if not (args.quick or args.skip_bake):
        log("[bench] bake time ...")
        res["bake"] = bake_time(args.repeats)
    log("[bench] lobe error per cell ...")
    res["fit_quality"] = fit_quality(tables, published, 1 << (10 if args.quick else 12), args.out)
    log("[bench] magnitude ...")
    res["magnitude"] = magnitude_check(tables["ltc_ggx_mag"][..., 0].astype(np.float64),
                                       published[1][..., 0] if published is not None else None,
                                       14 if args.quick else 18)
    log("[bench] end-to-end random lights ...")
    res["end_to_end"] = end_to_end(tables, published, 60 if args.quick else 600, 30 if args.quick else 300)
    res["sheen"] = sheen_via_diffuse_table(tables, 60 if args.quick else 600)
    res["disney_sheen_models"] = disney_sheen_models(tables, 60 if args.quick else 600, 30 if args.quick else 300)
    res["zeltner_exactness"] = zeltner_exactness(args.lut_dir, 60 if args.quick else 600, 30 if args.quick else 300)
    res["disk_exactness"] = disk_exactness(tables, 40 if args.quick else 300)
    (args.out / "ltc.json").write_text(json.dumps(res, indent=2))
    write_markdown(res, args.out / "ltc.md")
    log((args.out / "ltc.md").read_text())
    return res


def exr_io_read(lut_dir, name):
    spec = catalog.TABLES[name]
    return exr_io.read_table(Path(lut_dir) / spec.filename, spec.name, spec.shape)[0].astype(np.float64)


# --- one lobe's tables (--lobes) and the rough diffuse's area forms -------------------------------------------

def rough_diffuse_area_forms(tables, n_quads, n_disks, seed=2024):
    """The rough diffuse (core/rough_diffuse.py) under random lights against brute force: its multiple-scattering
    kernel over the light as shipped (Lambert form factor x its ratio towards the light's centre) and through the
    fixed LTC fitted to it (``rough_diffuse.MS_KERNEL_LTC``), and the whole lobe at albedo 1 as RT Lit computes it
    (``lobes.OREN_NAYAR``: the single scattering's LTC x the closed-form albedo, plus the kernel's share)."""
    luts = lookup.LutSet.from_folder(tables["lut_dir"])
    sphere = tables["ltc_ggx_mag"][..., 3]
    results = {}
    for kind, count in (("quad", n_quads), ("disk", n_disks)):
        fn = rt_lobes.OREN_NAYAR.function(kind)
        rows = {k: [] for k in ("centre", "ltc", "ms_truth", "ms_albedo", "total", "total_truth", "albedo", "theta")}
        for r, theta, v, geom in random_lights(kind, count, "oren_nayar", seed):
            mu = float(v[2])
            ms_truth, _ = true_integral(kind, lambda l, vv, r=r: rd.multiscatter_cos(l[..., 2], vv[..., 2], r), v, geom)
            ss_truth, _ = true_integral(kind, lambda l, vv, r=r: rd.fon_single_scatter_cos(
                l[..., 2], vv[..., 2], np.sum(l * vv, axis=-1), r), v, geom)
            light = ({**{f"p{i}": geom[i] for i in range(4)}, "Center": geom.mean(axis=0)} if kind == "quad"
                     else {"Center": geom[0], "Axis U": geom[1], "Axis V": geom[2]})
            out = fn(luts, Position=np.zeros(3), N=np.array([0.0, 0.0, 1.0]), V=v, **light,
                     **{"Diffuse Roughness": np.float64(r)})
            c = rd.MS_KERNEL_LTC
            fixed = (polygon.ltc_polygon_integral_packed(c, list(geom), False, sphere) if kind == "quad"
                     else disk.ltc_disk_integral_packed(c, *geom, False, sphere))
            rows["centre"].append(float(out["Diffuse MS"]))
            rows["ltc"].append(float(fixed) * float(rd.fon_one_minus_albedo(mu, r)))
            rows["ms_truth"].append(ms_truth)
            rows["total"].append(float(out["Diffuse"]) + float(out["Diffuse MS"]))
            rows["total_truth"].append(ss_truth + ms_truth)
            rows["ms_albedo"].append(float(rd.fon_one_minus_albedo(mu, r)))
            rows["albedo"].append(1.0)
            rows["theta"].append(theta)
        ms = (rows["ms_truth"], rows["ms_albedo"], rows["theta"])
        results[kind] = {"ms_centre": error_stats(rows["centre"], *ms), "ms_fixed_ltc": error_stats(rows["ltc"], *ms),
                         "total": error_stats(rows["total"], rows["total_truth"], rows["albedo"], rows["theta"])}
    return results


def run_lobes(args, res, log=entry.flush_log):
    """``--lobes``: the fit error and random-light error of the named lobes' tables (and the rough diffuse's
    area forms), into ltc_<lobes>.md / .json; the other tables' ltc.md is not touched."""
    prefixes = [p for p, (lobe, _) in catalog.LTC_LOBES.items() if lobe in args.lobes]
    status = [s for s in catalog.lut_status(args.lut_dir) if s.name.startswith(tuple(prefixes))]
    if any(s.state != "ok" for s in status):
        log("[bench] baking the LUTs first")
        bake.bake(args.lut_dir, groups=prefixes + ["ltc_ggx"])
    tables = {name: exr_io_read(args.lut_dir, name) for name in catalog.TABLES if name.startswith("ltc_")}
    tables["lut_dir"] = args.lut_dir
    log(f"[bench] lobe error per cell ({', '.join(args.lobes)}) ...")
    res["fit_quality"] = fit_quality(tables, None, 1 << (10 if args.quick else 12), args.out, prefixes)
    log("[bench] end-to-end random lights ...")
    res["end_to_end"] = end_to_end(tables, None, 60 if args.quick else 600, 30 if args.quick else 300,
                                   prefixes=prefixes)
    if "oren_nayar" in args.lobes:
        log("[bench] the rough diffuse's area forms ...")
        res["rough_diffuse"] = rough_diffuse_area_forms(tables, 60 if args.quick else 300, 30 if args.quick else 150)
    stem = "ltc_" + "_".join(args.lobes)
    (args.out / f"{stem}.json").write_text(json.dumps(res, indent=2, default=outputs.json_default))
    write_lobes_markdown(res, args.out / f"{stem}.md", args)
    log((args.out / f"{stem}.md").read_text())
    return res


def write_lobes_markdown(res, path, args):
    lines = [f"# LTC fit and accuracy: {', '.join(args.lobes)}", "",
             f"Command: `python scripts/benchmark_ltc.py --lobes {' '.join(args.lobes)}` ({res['machine']}, "
             f"{res['date']}). The same measurements as ltc.md (which has the other tables), for these lobes; "
             "ground truth: brute-force BRDF x cos over the light (core/ltc/reference.py).", "",
             "## Lobe error per table cell (total-variation distance, 0 = identical)", "",
             "| lobe | mean | p90 | max |", "|---|---|---|---|"]
    for name, q in res["fit_quality"].items():
        lines.append(f"| {name} | {q['tv_mean']:.4f} | {q['tv_p90']:.4f} | {q['tv_max']:.4f} |")
    lines += ["", "Heat maps (u = roughness, v = sqrt(1 - mu), colour 0..0.3): "
              + ", ".join(f"`ltc_tv_{n}.png`" for n in res["fit_quality"]) + ".", "",
              "## End-to-end error on random lights (the table's LTC x its magnitude)", "",
              "Relative error on lights carrying > 10% of the lobe's albedo; absolute error as a fraction of the albedo "
              "on all lights.", "",
              "| lobe / light | n (>10%) | rel median | rel p90 | rel max | abs/albedo median | abs/albedo p90 |",
              "|---|---|---|---|---|---|---|"]
    for key, e in res["end_to_end"].items():
        lines.append(f"| {key} | {fmt_stats(e['ours'])}")
    rd = res.get("rough_diffuse")
    if rd:
        lines += ["", "## The rough diffuse over the light (core/materials/lobes.py, albedo 1)", "",
                  "The multiple-scattering kernel over the light as RT Lit integrates it (the Lambert form factor x "
                  "the kernel's ratio to the cosine towards the light's centre) and through the fixed LTC fitted to "
                  "the kernel (rough_diffuse.MS_KERNEL_LTC; its albedo is 1 - E_F(mu_v)), and the whole lobe "
                  "(single + multiple scattering, albedo 1) against the brute force of both.", "",
                  "| part / light | n (>10%) | rel median | rel p90 | rel max | abs/albedo median | abs/albedo p90 |",
                  "|---|---|---|---|---|---|---|"]
        for kind, e in rd.items():
            lines.append(f"| multiple scattering, centre form (shipped) / {kind} | {fmt_stats(e['ms_centre'])}")
            lines.append(f"| multiple scattering, fixed LTC / {kind} | {fmt_stats(e['ms_fixed_ltc'])}")
            lines.append(f"| whole lobe / {kind} | {fmt_stats(e['total'])}")
    path.write_text("\n".join(lines) + "\n")
