"""LTC fit and accuracy report: bake time, per-cell lobe error, magnitude error, end-to-end
error on random quad and disk lights, with the published GGX table through the same code.

    python scripts/benchmark_ltc.py [--out docs/benchmarks] [--repeats 3] [--quick]
                                    [--lut-dir DIR] [--skip-bake]

Writes ltc.json, ltc.md and PNG heat maps (ltc_tv_<lobe>.png, ltc_tv_ggx_published.png) to --out.
"""
from __future__ import annotations

import argparse
import json
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

from . import report

from . import png as _png

from ..core import energy  # noqa: E402
from ..core.ltc import disk, fit, matrix, polygon, reference, shading
from ..core.ltc import fit_lobes as lobes  # noqa: E402
from ..core import lut_bake as bake
from ..core.ir import semantics
from ..core.lut import catalog, lookup  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
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


# --- end-to-end: random lights ---------------------------------------------------------------

def _orthonormal(n):
    t = np.cross(n, [0.0, 0.0, 1.0] if abs(n[2]) < 0.9 else [1.0, 0.0, 0.0])
    t /= np.linalg.norm(t)
    return t, np.cross(n, t)


def random_lights(kind, count, lobe_name, seed):
    """Seeded random configurations: (r, theta_v, light geometry in the local frame).

    Half the lights are aimed within 60 deg of the lobe's peak (the mirror direction for GGX,
    the normal for the other lobes), half anywhere above -15 deg elevation; distance
    1..4, quads 0.3..3 per side, disk radius 0.15..1.5, facing the point within 45 deg.
    """
    rng = np.random.default_rng(seed)
    out = []
    for i in range(count):
        r = rng.uniform(0.15, 0.95)
        theta = np.radians(rng.uniform(0.0, 80.0))
        v = np.array([np.sin(theta), 0.0, np.cos(theta)])
        if i % 2 == 0:
            peak = np.array([-v[0], 0.0, v[2]]) if lobe_name == "ggx" else np.array([0.0, 0.0, 1.0])
            a = rng.normal(size=3)
            a -= peak * (a @ peak)
            a /= np.linalg.norm(a)
            ang = np.radians(rng.uniform(0.0, 60.0))
            d = np.cos(ang) * peak + np.sin(ang) * a
        else:
            el, az = np.radians(rng.uniform(-15.0, 90.0)), rng.uniform(0.0, 2 * np.pi)
            d = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
        centre = d * rng.uniform(1.0, 4.0)
        tilt = rng.normal(size=3)
        tilt -= d * (tilt @ d)
        tilt /= np.linalg.norm(tilt)
        ang = np.radians(rng.uniform(0.0, 45.0))
        normal = -(np.cos(ang) * d + np.sin(ang) * tilt)          # emits towards the point
        t1, t2 = _orthonormal(normal)
        if kind == "quad":
            w, h = rng.uniform(0.3, 3.0, 2) / 2
            corners = np.array([centre - w * t1 - h * t2, centre + w * t1 - h * t2,
                                centre + w * t1 + h * t2, centre - w * t1 + h * t2])
            # ltc_code's winding: (c1 - c0) x (c3 - c0) points away from the lit side
            if np.cross(corners[1] - corners[0], corners[3] - corners[0]) @ normal > 0:
                corners = corners[::-1]
            geom = corners
        else:
            rad = rng.uniform(0.15, 1.5)
            u, w2 = t1 * rad, t2 * rad
            if np.cross(u, w2) @ normal > 0:      # axis_u x axis_v points away from the lit side
                w2 = -w2
            geom = (centre, u, w2)
        out.append((r, theta, v, geom))
    return out


def _truth(kind, f_cos, v, geom):
    for panels in (8, 32):
        q = (reference.brdf_integral_polygon(f_cos, v, geom, panels=panels) if kind == "quad"
             else reference.brdf_integral_disk(f_cos, v, *geom, panels=panels))
        if q.error <= 1e-4 * max(abs(q.value), 1e-6):
            break
    return q.value, q.error


def _ltc_estimate(kind, inv_table, mag_table, sphere, r, mu, geom, use_fresnel=False, scale=1.0, band=None):
    u, w = lookup.ltc_lut_uv(np.array(mu), np.array(r))
    packed = semantics.sample_bilinear(inv_table, u, w)
    mag = semantics.sample_bilinear(mag_table, u, w)
    c = tuple(packed[..., i] for i in range(4))          # the shader path: packed Minv, traceable code

    def integral(c):
        if kind == "quad":
            return polygon.ltc_polygon_integral_packed(c, list(geom), False, sphere)
        return disk.ltc_disk_integral_packed(c, *geom, False, sphere)

    value = integral(c)
    if band is not None:                                 # the table's band (catalog.LTC_BANDS), weight in B
        value = shading.mix_band(value, integral(matrix.squash_packed(c, band["squash"])), mag[2])
    return float(value) * float(mag[1] if use_fresnel else mag[0]) * scale


def _stats(est, truth, albedo, theta):
    est, truth, albedo, theta = map(np.asarray, (est, truth, albedo, theta))
    rel_sel = truth > 0.1 * albedo
    rel = np.abs(est - truth)[rel_sel] / truth[rel_sel]
    absn = np.abs(est - truth) / albedo
    if rel.size == 0:                # no light carries 10% of the albedo (a few lights, a grazing lobe)
        rel = np.array([np.nan])
    out = {"lights": int(truth.size), "lights_over_10pct": int(rel_sel.sum()),
           "rel_median": float(np.median(rel)), "rel_p90": float(np.quantile(rel, 0.9)), "rel_max": float(rel.max()),
           "abs_over_albedo_median": float(np.median(absn)), "abs_over_albedo_p90": float(np.quantile(absn, 0.9)),
           "abs_over_albedo_max": float(absn.max()), "by_view_angle": {}}
    deg = np.degrees(theta)
    for lo, hi in ((0, 30), (30, 60), (60, 81)):
        sel = (deg >= lo) & (deg < hi) & rel_sel
        if sel.any():
            r = np.abs(est - truth)[sel] / truth[sel]
            out["by_view_angle"][f"{lo}-{min(hi, 80)}"] = {"n": int(sel.sum()), "rel_median": float(np.median(r)),
                                                         "rel_p90": float(np.quantile(r, 0.9))}
    return out


def end_to_end(tables, published, n_quads, n_disks, seed=2019, prefixes=None):
    results = {}
    for prefix, (lobe_name, _) in catalog.LTC_LOBES.items():
        if prefixes is not None and prefix not in prefixes:
            continue
        lobe = lobes.LOBES[lobe_name]
        sphere = tables[prefix + "_mag"][..., 3]
        for kind, count in (("quad", n_quads), ("disk", n_disks)):
            rows = {"ours": [], "published": [], "truth": [], "albedo": [], "theta": [], "truth_err": []}
            for r, theta, v, geom in random_lights(kind, count, lobe_name, seed):
                mu = float(v[2])
                f_cos = (lambda l, vv, r=r: lobe.eval_cos(l, vv, np.array(r)))
                truth, err = _truth(kind, f_cos, v, geom)
                albedo = float(fit.lobe_integrals(lobe, max(mu, fit.FIT_MU_MIN), np.array([r]), 1 << 12)[0][0])
                rows["truth"].append(truth)
                rows["truth_err"].append(err)
                rows["albedo"].append(albedo)
                rows["theta"].append(theta)
                rows["ours"].append(_ltc_estimate(kind, tables[prefix + "_inv"], tables[prefix + "_mag"], sphere,
                                                  r, mu, geom, band=catalog.LTC_BANDS.get(prefix)))
                if prefix == "ltc_ggx" and published is not None:
                    rows["published"].append(_ltc_estimate(kind, published[0], published[1], published[1][..., 3],
                                                           r, mu, geom))
            entry = {"ours": _stats(rows["ours"], rows["truth"], rows["albedo"], rows["theta"]),
                     "reference_max_error_estimate": float(np.max(rows["truth_err"]))}
            if rows["published"]:
                entry["published"] = _stats(rows["published"], rows["truth"], rows["albedo"], rows["theta"])
            results[f"{lobe_name}/{kind}"] = entry
    return results


def _disney_sheen_f_cos(l, vv):
    from ..core import cloth

    h = l + vv
    h /= np.linalg.norm(h, axis=-1, keepdims=True)
    return cloth.disney_sheen(np.sum(l * h, axis=-1)) * np.maximum(l[..., 2], 0.0)


def _cosine_albedo(f_cos, v, n=256):
    """int f cos over the hemisphere by cosine-weighted quadrature (n x n stratified points)."""
    u1, u2 = (a.ravel() for a in np.meshgrid((np.arange(n) + 0.5) / n, (np.arange(n) + 0.5) / n))
    z, rr = np.sqrt(1 - u1), np.sqrt(u1)
    l = np.stack([rr * np.cos(2 * np.pi * u2), rr * np.sin(2 * np.pi * u2), z], -1)
    return float(np.mean(f_cos(l, np.broadcast_to(v, l.shape)) / (z / np.pi)))


def sheen_via_diffuse_table(tables, n_quads, seed=2020):
    """Disney sheen (1 - l.h)^5 under quads: brute force vs the talk's CoD-table approximation."""
    est, truth, albedo, theta = [], [], [], []
    for r, th, v, geom in random_lights("quad", n_quads, "cod_diffuse", seed):
        t, _ = _truth("quad", _disney_sheen_f_cos, v, geom)
        truth.append(t)
        albedo.append(_cosine_albedo(_disney_sheen_f_cos, v))
        theta.append(th)
        est.append(_ltc_estimate("quad", tables["ltc_cod_diffuse_inv"], tables["ltc_cod_diffuse_mag"],
                                 tables["ltc_cod_diffuse_mag"][..., 3], shading.SHEEN_TABLE_ROUGHNESS, float(v[2]),
                                 geom, use_fresnel=True, scale=np.pi))
    return _stats(est, truth, albedo, theta)


def disney_sheen_models(tables, n_quads, n_disks, seed=2020):
    """Disney sheen under quads and disks: brute force vs the talk's CoD-table approximation ("talk") and vs
    its own fitted LTC ("fitted", table ltc_disney_sheen read at r = 0), on the same random lights."""
    out = {}
    for kind, count in (("quad", n_quads), ("disk", n_disks)):
        rows = {"talk": [], "fitted": [], "truth": [], "albedo": [], "theta": []}
        for r, th, v, geom in random_lights(kind, count, "cod_diffuse", seed):
            rows["truth"].append(_truth(kind, _disney_sheen_f_cos, v, geom)[0])
            rows["albedo"].append(_cosine_albedo(_disney_sheen_f_cos, v))
            rows["theta"].append(th)
            mu = float(v[2])
            rows["talk"].append(_ltc_estimate(kind, tables["ltc_cod_diffuse_inv"], tables["ltc_cod_diffuse_mag"],
                                              tables["ltc_cod_diffuse_mag"][..., 3], shading.SHEEN_TABLE_ROUGHNESS,
                                              mu, geom, use_fresnel=True, scale=np.pi))
            rows["fitted"].append(_ltc_estimate(kind, tables["ltc_disney_sheen_inv"], tables["ltc_disney_sheen_mag"],
                                                tables["ltc_disney_sheen_mag"][..., 3], 0.0, mu, geom))
        out[kind] = {m: _stats(rows[m], rows["truth"], rows["albedo"], rows["theta"]) for m in ("talk", "fitted")}
    return out


def zeltner_exactness(lut_dir, n_quads, n_disks, seed=2022):
    """The Zeltner sheen's area form vs brute force of the same lobe (the LTC density times the albedo at the
    same table values): the LTC integral with the sphere table's horizon ("sphere table") and with the exact
    horizon RT Lit shades it with ("exact horizon": quads clipped, disks by their closed form above the
    horizon and an equal-area 12-gon clipped where they cross it).  Random sheen roughness in [0.05, 1]."""
    from ..core import sheen

    tables = lookup.LutSet.from_folder(lut_dir)
    sheen_table = tables.array("zeltner_sheen")
    sphere = tables.array("ltc_ggx_mag")[..., 3]
    out = {}
    for kind, count in (("quad", n_quads), ("disk", n_disks)):
        rows = {"sphere table": [], "exact horizon": [], "truth": [], "albedo": [], "theta": []}
        for r, th, v, geom in random_lights(kind, count, "cod_diffuse", seed):
            r = 0.05 + 0.95 * (r - 0.15) / 0.8
            mu = float(v[2])
            size = catalog.ZELTNER_SHEEN_SIZE
            a, b, alb = semantics.sample_bilinear(sheen_table, lookup.lut_coordinate(np.array(r), size),
                                                  lookup.lut_coordinate(np.array(mu), size))[:3]
            if alb < 1e-4:               # no lobe (Cycles' cut-off, or below it): nothing to integrate
                continue

            def f_cos(l, vv, a=float(a), b=float(b), alb=float(alb)):
                return alb * sheen.zeltner_density(l[..., 0], l[..., 1], l[..., 2], a, b)

            rows["truth"].append(_truth(kind, f_cos, v, geom)[0])
            rows["albedo"].append(float(alb))
            rows["theta"].append(th)
            c = sheen.zeltner_packed_inverse(float(a), float(b))
            if kind == "quad":
                clipless = polygon.ltc_polygon_integral_packed(c, list(geom), False, sphere)
                exact = polygon.polygon_integral_horizon_clipped([matrix.transform_packed(c, q) for q in geom], 0.0,
                                                                 list(geom))
            else:
                clipless = disk.ltc_disk_integral_packed(c, *geom, False, sphere)
                exact = disk.disk_integral_horizon_clipped(*(matrix.transform_packed(c, q) for q in geom), 0.0, sphere)
            rows["sphere table"].append(float(clipless) * float(alb))
            rows["exact horizon"].append(float(exact) * float(alb))
        out[kind] = {m: _stats(rows[m], rows["truth"], rows["albedo"], rows["theta"])
                     for m in ("sphere table", "exact horizon")}
    return out


def sheen_markdown(res):
    """The sheen sections of ltc.md (``disney_sheen_models`` and ``zeltner_exactness`` results)."""
    lines = ["## Sheen: Disney sheen's fitted LTC vs the talk's approximation, and Zeltner's own LTC", "",
             "Same random lights for both Disney sheen models (brute force of (1 - l.h)^5 cos over the light); "
             "Zeltner: the LTC integral of the measured lobe vs brute force of the same lobe (what the horizon "
             "handling costs).", "",
             "| lobe / light | model | n (>10%) | rel median | rel p90 | rel max | abs/albedo median | abs/albedo p90 |",
             "|---|---|---|---|---|---|---|---|"]
    for kind, e in res["disney_sheen_models"].items():
        for model in ("talk", "fitted"):
            lines.append(f"| disney_sheen/{kind} | {model} | {_fmt_stats(e[model])}")
    for kind, e in res["zeltner_exactness"].items():
        for model, stats in e.items():
            lines.append(f"| zeltner/{kind} | own LTC, {model} | {_fmt_stats(stats)}")
    return lines + [""]


def disk_exactness(tables, n, seed=7):
    """Disks above the transformed horizon: closed-form F.z vs numeric integration of the same LTC."""
    worst = 0.0
    count = 0
    for r, theta, v, geom in random_lights("disk", n, "ggx", seed):
        u, w = lookup.ltc_lut_uv(np.array(v[2]), np.array(r))
        minv = matrix.unpack_inverse(semantics.sample_bilinear(tables["ltc_ggx_inv"], u, w))
        centre, a, b = geom
        # entirely above the transformed horizon: every boundary point has (Minv x).z > 0
        ts = np.linspace(0, 2 * np.pi, 256)
        boundary = centre + np.cos(ts)[:, None] * a + np.sin(ts)[:, None] * b
        if np.min(boundary @ minv[2]) <= 0 or np.min(boundary[:, 2]) <= 0:
            continue
        closed = float(disk.ltc_disk_vector_form_factor(minv, centre, a, b)[2])
        numeric = reference.ltc_integral_disk(minv, centre, a, b, panels=16).value
        worst = max(worst, abs(closed / numeric - 1))
        count += 1
    return {"disks_above_horizon": count, "max_rel_diff_closed_form_vs_numeric": worst}


def _fmt_stats(s):
    return (f"{s['lights_over_10pct']}/{s['lights']} | {100 * s['rel_median']:.2f}% | {100 * s['rel_p90']:.1f}% | "
            f"{100 * s['rel_max']:.1f}% | {100 * s['abs_over_albedo_median']:.2f}% | {100 * s['abs_over_albedo_p90']:.2f}% |")


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
        lines.append(f"| {key} | ours | {_fmt_stats(e['ours'])}")
        if "published" in e:
            lines.append(f"| {key} | published | {_fmt_stats(e['published'])}")
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
              "|---|---|---|---|---|---|---|", f"| quad | {_fmt_stats(s)}", ""]
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


def run(args, log=report.flush_log):
    """Measure, write ltc.json, ltc.md and the heat maps to ``args.out``; returns the results."""
    args.out.mkdir(parents=True, exist_ok=True)
    import os
    import platform
    from . import published_ltc as ltc_anchor

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
    from ..core.lut import exr_io

    spec = catalog.TABLES[name]
    return exr_io.read_table(Path(lut_dir) / spec.filename, spec.name, spec.shape)[0].astype(np.float64)


# --- one lobe's tables (--lobes) and the rough diffuse's area forms -------------------------------------------

def rough_diffuse_area_forms(tables, n_quads, n_disks, seed=2024):
    """The rough diffuse (core/rough_diffuse.py) under random lights against brute force: its multiple-scattering
    kernel over the light as shipped (Lambert form factor x its ratio towards the light's centre) and through the
    fixed LTC fitted to it (``rough_diffuse.MS_KERNEL_LTC``), and the whole lobe at albedo 1 as RT Lit computes it
    (``lobes.OREN_NAYAR``: the single scattering's LTC x the closed-form albedo, plus the kernel's share)."""
    from ..core import rough_diffuse as rd
    from ..core.materials import lobes as rt_lobes

    luts = lookup.LutSet.from_folder(tables["lut_dir"])
    sphere = tables["ltc_ggx_mag"][..., 3]
    results = {}
    for kind, count in (("quad", n_quads), ("disk", n_disks)):
        fn = rt_lobes.OREN_NAYAR.function(kind)
        rows = {k: [] for k in ("centre", "ltc", "ms_truth", "ms_albedo", "total", "total_truth", "albedo", "theta")}
        for r, theta, v, geom in random_lights(kind, count, "oren_nayar", seed):
            mu = float(v[2])
            ms_truth, _ = _truth(kind, lambda l, vv, r=r: rd.multiscatter_cos(l[..., 2], vv[..., 2], r), v, geom)
            ss_truth, _ = _truth(kind, lambda l, vv, r=r: rd.fon_single_scatter_cos(
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
        results[kind] = {"ms_centre": _stats(rows["centre"], *ms), "ms_fixed_ltc": _stats(rows["ltc"], *ms),
                         "total": _stats(rows["total"], rows["total_truth"], rows["albedo"], rows["theta"])}
    return results


def run_lobes(args, res, log=report.flush_log):
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
    (args.out / f"{stem}.json").write_text(json.dumps(res, indent=2, default=report.json_default))
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
        lines.append(f"| {key} | {_fmt_stats(e['ours'])}")
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
            lines.append(f"| multiple scattering, centre form (shipped) / {kind} | {_fmt_stats(e['ms_centre'])}")
            lines.append(f"| multiple scattering, fixed LTC / {kind} | {_fmt_stats(e['ms_fixed_ltc'])}")
            lines.append(f"| whole lobe / {kind} | {_fmt_stats(e['total'])}")
    path.write_text("\n".join(lines) + "\n")
