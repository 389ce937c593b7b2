"""Headless validation of the RT Lit World term (issue 6) under Blender's studio HDRIs.

For every studio HDRI shipped in the bpy wheel (core/environment/equirect.py ``studio_hdris``; none is
copied into the repository), plus one rotated and scaled world (Mapping node Euler XYZ rotation,
Background strength), a node block of unit spheres with RT Lit materials and a truth block of Cycles
closures are rendered (validation/world_cases.py describes the scene):

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
Full run: 7-9 minutes on 2 cores (521 s measured with other jobs on the machine; about 6 min with
--samples 512); --quick (one rotated HDRI, few spheres, 256 spp): about 22 s.
"""
from __future__ import annotations

import argparse
import html
import json
import os
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import report
from . import suite_cases as suite
from . import world_cases as vw

DEFAULTS = {"ab_tol": 1e-4, "ab_atol": 1e-6, "furnace_tol": 0.005, "floor": 0.1, "floor_wide": 0.01,
            "harness_lambert_median": 0.02}
#: The extra world: rotated (Euler XYZ, radians) and scaled; a small bright sun makes a wrong
#: rotation convention obvious.
ROTATED = ("sunrise", (0.35, -0.25, 2.0), 1.5)
QUICK = ("forest", (0.3, -0.2, 1.2), 1.3)
ERR_VMAX = 0.2
#: Front-facing pixels (N.V >= this) get their own specular statistics: the split sum's error
#: concentrates at grazing view angles.
FRONT_MU = 0.5


def _rel_values(a, c, mask, floor_frac, c_pair=None):
    from . import suite as validate

    return validate._rel_values(a, c, mask, floor_frac, c_pair)


def _pool(entries):
    """validate._pool plus the median / p90 over the front-facing values (N.V >= FRONT_MU)."""
    from . import suite as validate

    out = validate._pool(entries)
    front = [e["rel_front"] for e in entries if e.get("rel_front") is not None]
    if front:
        f = np.concatenate(front)
        if f.size:
            out.update({"front_values": int(f.size), "front_median": float(np.median(f)),
                        "front_p90": float(np.percentile(f, 90))})
    return out


# --- one world: pixel helpers ------------------------------------------------------------------------

def _pick_pixels(ys, xs, count, rng):
    """At most ``count`` of the pixels (ys, xs): a seeded subset, kept in raster order."""
    if len(ys) > count:
        pick = np.sort(rng.choice(len(ys), count, replace=False))
        ys, xs = ys[pick], xs[pick]
    return ys, xs


def _image_frame(scene, normal, position, R):
    """Unit normals and view directions of pixels (their Normal / Position pass values) in the
    environment image's frame: rotated by the Mapping's R."""
    from .engines import camera_incoming

    n = normal.astype(np.float64)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    view = camera_incoming(scene, position.astype(np.float64))
    return n @ R.T, np.ascontiguousarray(view @ R.T)


def _view_cosine(scene, passes):
    """N.V per pixel of the node render (N the Normal pass, V towards the camera)."""
    from .engines import camera_incoming

    nrm = passes["Normal"].astype(np.float64)
    return np.sum(nrm * camera_incoming(scene, passes["Position"].astype(np.float64)), axis=-1) / \
        np.maximum(np.linalg.norm(nrm, axis=-1), 1e-12)


# --- one world: studies ------------------------------------------------------------------------------

def cod_study(spec, bake, image, variants, block, scene, passes, index, a, args, rng, tables, technique="cod"):
    """Item 2 on up to ``--cod-pixels`` seeded pixels of every CoD sphere (``technique`` "cod", or "cod_wrapped":
    the multiscattering wrapped diffuse at the variant's wrap): the SH-LTC lobe (numpy float64, and (a)) and the
    magnitude-only baseline vs the brute-force integrals of the true BRDF under the SH environment and under the
    area-averaged image.  Image frame: n, v rotated by the Mapping's R."""
    R = vw.euler_xyz_matrix(spec.rotation)
    coeffs = np.asarray(bake.sh_image, np.float64)
    quad = vw.image_quadrature(image, (args.cod_image, args.cod_image // 2))
    rows, parts = [], {k: [] for k in ("ltc", "mag", "node", "ref_sh", "ref_img")}
    t0 = time.perf_counter()
    for i, v in enumerate(variants):
        if v.technique != technique:
            continue
        ys, xs = _pick_pixels(*np.nonzero(index == i), args.cod_pixels, rng)
        ni, vi = _image_frame(scene, passes["Normal"][ys, xs], passes["Position"][ys, xs], R)
        wrap = v.wrap if technique == "cod_wrapped" else None
        vals = _cod_values(spec, tables, coeffs, quad, ni, vi, v.roughness, a[ys, xs], wrap)
        for k in parts:
            parts[k].append(vals[k])
        rows.append(_cod_row(vals, v.roughness, len(ys), args))
    if not rows:
        return None
    return {"per_roughness": rows, "pooled": _cod_pooled_stats(parts, args),
            "image_quadrature": [args.cod_image, args.cod_image // 2], "seconds": time.perf_counter() - t0}


def _cod_values(spec, tables, coeffs, quad, ni, vi, roughness, node, wrap=None):
    """One CoD sphere's pixels: the SH-LTC lobe and the magnitude-only baseline (numpy float64), the node
    render's values, and the brute-force references under the SH environment and under the image; ``wrap``: the
    multiscattering wrapped diffuse's (None: the CoD diffuse)."""
    from ..core import indirect

    r = np.full(len(ni), roughness)
    white = np.ones(3)
    s = spec.strength
    if wrap is not None:
        cl = indirect.coefficient_list(coeffs)
        return {"ltc": s * indirect.sh_cod_wrapped_diffuse(tables, cl, ni, vi, roughness, white, wrap),
                "mag": s * indirect.sh_cod_wrapped_diffuse_magnitude_only(tables, cl, ni, vi, roughness, white, wrap),
                "node": node.astype(np.float64),
                "ref_sh": s * indirect.cod_wrapped_diffuse_reference(coeffs, ni, vi, r, wrap),
                "ref_img": s * vw.cod_reference_image(quad, ni, vi, r, wrap=wrap)}
    return {"ltc": s * indirect.sh_cod_diffuse(tables, indirect.coefficient_list(coeffs), ni, vi, roughness, white),
            "mag": s * indirect.sh_cod_diffuse_magnitude_only(tables, indirect.coefficient_list(coeffs), ni, vi,
                                                              roughness, white),
            "node": node.astype(np.float64),
            "ref_sh": s * indirect.cod_diffuse_reference(coeffs, ni, vi, r),
            "ref_img": s * vw.cod_reference_image(quad, ni, vi, r)}


def _cod_row(vals, roughness, pixels, args):
    """One CoD sphere's errors: each model vs each reference, (a) vs numpy, and the two references."""
    return {"roughness": roughness, "pixels": int(pixels),
            **{f"{m}_vs_{ref}": vw.rel_stats(vals[m], vals[ref], args.floor)
               for m in ("ltc", "mag") for ref in ("ref_sh", "ref_img")},
            "node_vs_ltc_numpy": vw.rel_stats(vals["node"], vals["ltc"], args.floor_wide),
            "sh_ref_vs_img_ref": vw.rel_stats(vals["ref_sh"], vals["ref_img"], args.floor)}


def _cod_pooled_stats(parts, args):
    """The CoD errors over all the world's CoD spheres, at both floors."""
    cat = {k: np.concatenate(v) for k, v in parts.items()}
    pooled = {f"{m}_vs_{ref}": vw.rel_stats(cat[m], cat[ref], args.floor) for m in ("ltc", "mag")
              for ref in ("ref_sh", "ref_img")}
    pooled.update({f"{m}_vs_{ref}_wide": vw.rel_stats(cat[m], cat[ref], args.floor_wide) for m in ("ltc", "mag")
                   for ref in ("ref_sh", "ref_img")})
    pooled["node_vs_ltc_numpy"] = vw.rel_stats(cat["node"], cat["ltc"], args.floor_wide)
    return pooled


def lambert_study(spec, image, variants, block, scene, passes, index, a, truth_cell, mask_cell, args):
    """SH truncation (a vs the texel-sum Lambert) and the harness check (texel sum vs Cycles) on the
    Lambert sphere's pixels."""

    i = next((k for k, v in enumerate(variants) if v.technique == "lambert"), None)
    if i is None:
        return None
    R = vw.euler_xyz_matrix(spec.rotation)
    quad = vw.image_quadrature(image, (args.lambert_image, args.lambert_image // 2))
    na = block.cell(passes["Normal"], i).astype(np.float64)
    sel = mask_cell
    n = na[sel] / np.linalg.norm(na[sel], axis=-1, keepdims=True)
    ref = spec.strength * vw.lambert_reference_image(quad, n @ R.T)
    a_cell = block.cell(a, i)[sel]
    out = {"sh_vs_image": vw.rel_stats(a_cell, ref, args.floor),
           "image_quadrature": [args.lambert_image, args.lambert_image // 2]}
    if truth_cell is not None:
        out["image_vs_cycles"] = vw.rel_stats(ref, truth_cell[sel], args.floor)
    return out


def ggx_study(spec, image, variants, block, scene, passes, a, truth, closures, args, rng, tables):
    """Harness of the specular comparison on ``--ggx-pixels`` seeded pixels of every single-scattering
    sphere with r >= 0.25: the brute-force integral of the true GGX BRDF (F = 1) over the image
    (area-averaged to ``--ggx-image`` texels) vs Cycles Glossy GGX (must agree to the noise), and the
    split sum (a) vs that integral (its error without Monte Carlo noise), split into the split sum's
    own approximation (the exact split sum E(N.V) P(dominant direction), P the brute-force prefilter
    integral over the same texels, vs the integral) and the stored levels' lookup (a vs that exact
    split sum: 128 x 64 levels, bilinear, linear between roughness levels)."""
    from ..core.environment import equirect

    if args.ggx_pixels <= 0:
        return None
    R = vw.euler_xyz_matrix(spec.rotation)
    quad = vw.image_quadrature(image, (args.ggx_image, args.ggx_image // 2))
    small = equirect.downsample(np.asarray(image, np.float32), image.shape[1] // args.ggx_image)
    rows = []
    t0 = time.perf_counter()
    for i, v in enumerate(variants):
        if v.technique != "ggx" or v.roughness < 0.25:
            continue
        j = closures.index(v.closure) if truth is not None else None
        normal, position = block.cell(passes["Normal"], i), block.cell(passes["Position"], i)
        ys, xs = _pick_pixels(*np.nonzero(np.linalg.norm(normal, axis=-1) > 0.5), args.ggx_pixels, rng)
        ni, vi = _image_frame(scene, normal[ys, xs], position[ys, xs], R)
        cycles = truth["block"].cell(truth["mean"], j)[ys, xs] if truth is not None else None
        rows.append(_ggx_row(spec, tables, quad, small, ni, vi, v.roughness, block.cell(a, i)[ys, xs], cycles, args))
    return {"rows": rows, "image_quadrature": [args.ggx_image, args.ggx_image // 2],
            "seconds": time.perf_counter() - t0} if rows else None


def _ggx_row(spec, tables, quad, small, ni, vi, roughness, node, cycles, args):
    """One ggx sphere's pixels: the split sum (a), the exact split sum and Cycles (``cycles``, None
    without a truth) vs the brute-force GGX integral, and (a) vs the exact split sum."""
    from ..core.environment import prefilter
    from ..core.materials import world_shading as world_term

    ref = spec.strength * vw.ggx_reference_image(quad, ni, vi, roughness)
    mu = np.clip(np.sum(ni * vi, axis=-1), 0.0, 1.0)
    scale_a, bias_b = tables.split_sum(mu, np.full(len(mu), roughness))
    dom = np.asarray(world_term.dominant_direction(ni, vi, np.full(len(mu), roughness)), np.float64)
    exact = spec.strength * (np.asarray(scale_a + bias_b, np.float64)[:, None]
                             * prefilter.prefilter_reference(small, dom, roughness, rule="area"))
    row = {"roughness": roughness, "pixels": int(len(ni)),
           "split_sum_vs_brute": vw.rel_stats(node, ref, args.floor),
           "exact_split_sum_vs_brute": vw.rel_stats(exact, ref, args.floor),
           "split_sum_vs_exact_split_sum": vw.rel_stats(node, exact, args.floor),
           "bias_exact_split_sum_vs_brute": float(np.sum(exact - ref) / np.sum(ref))}
    if cycles is not None:
        row["brute_vs_cycles"] = vw.rel_stats(ref, cycles, args.floor)
    return row


# --- one world: the run ------------------------------------------------------------------------------

@dataclass
class _WorldScene:
    """One world's scene: the synced world (environment, parameters, bake, image) and its sphere blocks."""
    scene: object
    env: object
    params: dict
    bake: object
    image: object
    nb: object             # node block: the RT Lit materials
    tb: object             # truth block: the Cycles closures (None without a truth render)
    closures: list
    blocks: list


@dataclass
class _NodeRender:
    """(a) the node render's passes and Combined, the sphere index per pixel, (b) numpy, and (a) vs (b)."""
    passes: dict
    a: np.ndarray
    index: np.ndarray
    b: np.ndarray
    ab: dict
    ab_ok: object


def run_world(spec, variants, args, out_dir, rng, tables, log=print, bake_timing=True, gate_cod=True):
    """One world: scene and bake, (a) node render and (b) numpy, (c) Cycles truth, per-sphere metrics,
    the CoD / Lambert / GGX studies, the images; returns the world's result record and the per-sphere
    relative errors that ``run`` pools across worlds."""
    folder = out_dir / spec.name
    folder.mkdir(parents=True, exist_ok=True)
    t_start = time.perf_counter()
    timing = {}
    scene = vw.new_scene()
    vw.setup_world(scene, spec)
    bake_times = _measure_bake(scene, spec, args, log) if bake_timing else None
    ws = _build_world_scene(scene, variants, args, timing)
    nr = _render_node_and_numpy(ws, variants, folder, args, tables, timing)
    truth = _render_truth(ws, args, folder, timing)
    entries, parts, c_full, lambert_truth, lambert_mask = _variant_entries(spec, variants, ws, nr, truth, args)
    studies = _studies(spec, variants, ws, nr, truth, lambert_truth, lambert_mask, args, rng, tables)
    png = _write_world_images(folder, nr, truth, c_full, args)
    timing["total"] = time.perf_counter() - t_start
    result = _world_record(spec, ws, nr, entries, studies, bake_times, timing, gate_cod, png)
    _log_world(spec, entries, studies[0], nr.ab, timing, log)
    return result, parts


def _measure_bake(scene, spec, args, log):
    """Item 6: a forced bake of the world, then a cached re-run, timed."""
    bake_times = vw.measure_bake(scene, args.cache)
    f, c = bake_times["forced"], bake_times["cached"]
    log(f"[world] bake {spec.hdri}: SH {f['seconds']['sh']:.2f} s, prefiltered {f['seconds']['prefiltered']:.2f} s, "
        f"call {f['wall']:.2f} s; cached re-run {c['wall']:.3f} s ({c['states']})")
    return bake_times


def _build_world_scene(scene, variants, args, timing):
    """Sync the world (bake or cache) and add the node block and, with ``--samples`` > 0, the truth block."""
    t0 = time.perf_counter()
    env, params, bake, image = vw.sync_world(scene, args.cache, args.lut_dir)
    timing["sync"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    mesh = vw.sphere_mesh(args.segments, args.segments // 2)
    nb = vw.add_node_block(scene, variants, args.cell, args.columns, 0.0, args.lut_dir, mesh)
    closures = vw.truth_closures(variants) if args.samples > 0 else []
    tb = vw.add_truth_block(scene, closures, args.cell, args.columns, -vw.BLOCK_GAP, mesh) if closures else None
    blocks = [b for b in (nb, tb) if b is not None]
    timing["build"] = time.perf_counter() - t0
    return _WorldScene(scene, env, params, bake, image, nb, tb, closures, blocks)


def _numpy_b(scene, variants, nb, passes, index, tables, env, params):
    """(b): the same IR evaluated in numpy at the node render's passes, with its float32 conditioning."""
    def fn(p, dtype):
        return suite.numpy_radiance(scene, variants, nb.objects, p, index, tables,
                                    (env, vw.world_params_numpy(params)), dtype)

    return suite.conditioning(fn, passes)


def _ab_all(a, b, index, cond, args):
    """(a) vs (b) over every sphere pixel, and whether it passes validate.py's rule."""
    ab_all = suite.ab_metrics(a, b, index >= 0, conditioning=cond, tol=args.ab_tol, atol=args.ab_atol)
    ab_ok = (ab_all["finite"] and ab_all["max_rel_beyond_float32"] <= args.ab_tol
             and ab_all["max_abs_near_zero_beyond_float32"] <= args.ab_atol)
    return ab_all, ab_ok


def _render_node_and_numpy(ws, variants, folder, args, tables, timing):
    """(a) the node render (Cycles, 1 sample at pixel centres), (b) numpy at its passes, (a) vs (b)."""
    passes = vw.render_node(ws.scene, ws.nb, ws.blocks, folder)
    timing["a"] = passes["seconds"]
    a = passes["Combined"].astype(np.float64)
    index = vw.block_index(ws.nb, passes["Normal"])
    t0 = time.perf_counter()
    b, cond = _numpy_b(ws.scene, variants, ws.nb, passes, index, tables, ws.env, ws.params)
    timing["b"] = time.perf_counter() - t0
    ab_all, ab_ok = _ab_all(a, b, index, cond, args)
    return _NodeRender(passes, a, index, b, ab_all, ab_ok)


def _render_truth(ws, args, folder, timing):
    """(c) Cycles path tracing of the truth block, one render per seed; None without a truth block."""
    if ws.tb is None:
        return None
    images, secs, tnormal = vw.render_truth(ws.scene, ws.tb, ws.blocks, args.samples, tuple(args.seeds), folder,
                                            args.threads)
    timing["c_cycles"] = list(secs)
    return {"pair": images, "mean": 0.5 * (images[0] + images[1]) if len(images) > 1 else images[0],
            "normal": tnormal, "seconds": secs, "block": ws.tb}


def _variant_entries(spec, variants, ws, nr, truth, args):
    """Per sphere: (a) vs (b) and, where it has a Cycles closure, (a) vs (c).  Returns the entries, the
    relative errors to pool, the truth laid out on the node cells (NaN elsewhere), and the Lambert
    sphere's truth cell and mask (None without them)."""
    samples_total = args.samples * len(args.seeds)
    mu_img = _view_cosine(ws.scene, nr.passes)
    c_full = np.full(nr.a.shape, np.nan)
    entries, parts = [], []
    lambert_truth = lambert_mask = None
    for i, v in enumerate(variants):
        mask = nr.index == i
        e = {"index": i, "label": v.label, "technique": v.technique, "roughness": v.roughness,
             "closure": list(v.closure) if v.closure else None, "pixels": int(mask.sum()),
             "ab": suite.ab_metrics(nr.a, nr.b, mask)}
        if truth is not None and v.closure is not None:
            m, c_cell, metrics, part = _truth_comparison(spec, i, v, ws, nr, truth, mu_img, samples_total, args)
            e.update(metrics)
            if part is not None:
                parts.append(part)
            ws.nb.cell(c_full, i)[m] = c_cell[m]
            if v.technique == "lambert":
                lambert_truth, lambert_mask = c_cell, m
        entries.append(e)
    return entries, parts, c_full, lambert_truth, lambert_mask


def _truth_comparison(spec, i, v, ws, nr, truth, mu_img, samples_total, args):
    """Node sphere i vs its Cycles closure: the aligned pixel mask, the truth cell, the metrics (at
    ``--floor``, ``--floor-wide`` and front-facing) and the relative errors to pool (None if none)."""
    j = ws.closures.index(v.closure)
    m, ndiff = vw.cell_alignment(ws.nb, nr.passes["Normal"], i, ws.tb, truth["normal"], j)
    a_cell = ws.nb.cell(nr.a, i)
    c_cell = ws.tb.cell(truth["mean"], j)
    pair = [ws.tb.cell(x, j) for x in truth["pair"]]
    pair = pair if len(pair) > 1 else None
    frac = vw.max_fraction(c_cell, m, args.floor)
    frac_w = vw.max_fraction(c_cell, m, args.floor_wide)
    metrics = {"cell_normal_max_diff": ndiff,
               "truth_metrics": suite.truth_metrics(a_cell, c_cell, m, frac, pair, samples_total,
                                                    error_exponent=suite.CYCLES_WORLD_ERROR_EXPONENT),
               "truth_metrics_wide": suite.truth_metrics(a_cell, c_cell, m, frac_w, pair, samples_total,
                                                         error_exponent=suite.CYCLES_WORLD_ERROR_EXPONENT)}
    rel, noise = _rel_values(a_cell, c_cell, m, frac, pair)
    rel_w, _ = _rel_values(a_cell, c_cell, m, frac_w)
    rel_f = _front_rel_values(a_cell, c_cell, m, ws.nb.cell(mu_img, i), frac)
    if rel_f is not None:
        metrics["truth_metrics_front"] = {"values": int(rel_f.size), "median": float(np.median(rel_f)),
                                          "p90": float(np.percentile(rel_f, 90)), "mean": float(rel_f.mean())}
    part = None
    if rel is not None:
        part = {"technique": v.technique, "roughness": v.roughness, "world": spec.name,
                "rel": rel, "noise": noise, "rel_wide": rel_w, "rel_front": rel_f}
    return m, c_cell, metrics, part


def _front_rel_values(a_cell, c_cell, m, mu_cell, frac):
    """Relative errors over the front-facing values (N.V >= FRONT_MU) of the mask; None if there are none."""
    front = m & (mu_cell >= FRONT_MU)
    if not front.any():
        return None
    # the same absolute floor as the whole sphere's
    cmax_f = float(np.nanmax(c_cell[front]))
    frac_f = frac * float(np.nanmax(c_cell[m])) / cmax_f if cmax_f > 0 else frac
    rel_f, _ = _rel_values(a_cell, c_cell, front, frac_f)
    return rel_f


def _studies(spec, variants, ws, nr, truth, lambert_truth, lambert_mask, args, rng, tables):
    """The CoD, Lambert and GGX studies of the world (``cod_study``, ``lambert_study``, ``ggx_study``)."""
    cod = cod_study(spec, ws.bake, ws.image, variants, ws.nb, ws.scene, nr.passes, nr.index, nr.a, args, rng, tables)
    li = next((k for k, v in enumerate(variants) if v.technique == "lambert"), None)
    if lambert_mask is None and li is not None:
        na = ws.nb.cell(nr.passes["Normal"], li)
        lambert_mask = np.linalg.norm(na, axis=-1) > 0.5
    lam = lambert_study(spec, ws.image, variants, ws.nb, ws.scene, nr.passes, nr.index, nr.a, lambert_truth,
                        lambert_mask, args)
    ggx = ggx_study(spec, ws.image, variants, ws.nb, ws.scene, nr.passes, nr.a, truth, ws.closures, args, rng, tables)
    cod_wrapped = cod_study(spec, ws.bake, ws.image, variants, ws.nb, ws.scene, nr.passes, nr.index, nr.a, args, rng,
                            tables, technique="cod_wrapped")
    return cod, lam, ggx, cod_wrapped


def _write_world_images(folder, nr, truth, c_full, args):
    """node_a.exr, numpy_b.exr, a.png, err_ab.png and, with a truth, truth_c.exr, c.png, err_ac.png;
    returns the PNGs by key."""
    a, b, index = nr.a, nr.b, nr.index
    report.write_exr(folder / "node_a.exr", a)
    report.write_exr(folder / "numpy_b.exr", b)
    hit = index >= 0
    scale = float(np.percentile(a[hit], 99)) if hit.any() else 1.0
    png = {"a": "a.png", "err_ab": "err_ab.png"}
    report.preview_png(folder / "a.png", np.where(hit[..., None], a, 0.0), scale)
    with np.errstate(invalid="ignore", divide="ignore"):
        err_ab = (np.abs(a - b) / np.maximum(np.abs(b), 1e-2)).max(axis=-1) * hit
    report.error_png(folder / "err_ab.png", np.minimum(err_ab, args.ab_tol), args.ab_tol)
    if truth is not None:
        report.write_exr(folder / "truth_c.exr", truth["mean"])
        report.preview_png(folder / "c.png", np.nan_to_num(c_full), scale)
        with np.errstate(invalid="ignore", divide="ignore"):
            err = np.where(np.isfinite(c_full) & (c_full > 0), np.abs(a - c_full) / c_full, np.nan).max(axis=-1)
        report.error_png(folder / "err_ac.png", np.minimum(np.nan_to_num(err), ERR_VMAX), ERR_VMAX)
        png.update({"c": "c.png", "err_ac": "err_ac.png"})
    return png


def _world_record(spec, ws, nr, entries, studies, bake_times, timing, gate_cod, png):
    """The world's entry of report.json."""
    cod, lam, ggx, cod_wrapped = studies
    cod_ok = None
    if cod is not None:
        p = cod["pooled"]
        cod_ok = p["ltc_vs_ref_sh"]["mean"] < p["mag_vs_ref_sh"]["mean"]
    return {"name": spec.name, "description": spec.describe(), "hdri": spec.hdri, "path": str(spec.path),
            "rotation": list(spec.rotation), "strength": spec.strength,
            "image": list(ws.nb.resolution), "truth_image": list(ws.tb.resolution) if ws.tb else None,
            "ab": nr.ab, "ab_ok": bool(nr.ab_ok), "variants": entries, "cod": cod, "cod_ok": cod_ok,
            "cod_wrapped": cod_wrapped,
            "ggx_harness": ggx, "gate_cod": gate_cod, "lambert": lam, "bake": bake_times, "timing_s": timing,
            "world_parameters": {k: (list(v) if isinstance(v, (tuple, list, np.ndarray)) else v)
                                 for k, v in ws.params.items()},
            "png": {k: f"{spec.name}/{v}" for k, v in png.items()}}


def _log_world(spec, entries, cod, ab_all, timing, log):
    """The world's summary line: (a)-(b), Lambert vs Cycles, CoD, timings."""
    lam_txt = ""
    e0 = next((e for e in entries if e["technique"] == "lambert" and e.get("truth_metrics")), None)
    if e0:
        lam_txt = f" | Lambert vs Cycles mean {e0['truth_metrics']['mean']:.2%}"
    cod_txt = ""
    if cod:
        p = cod["pooled"]
        cod_txt = (f" | CoD SH-LTC {p['ltc_vs_ref_sh']['mean']:.2%} vs mag-only {p['mag_vs_ref_sh']['mean']:.2%}"
                   f" (SH env), {p['ltc_vs_ref_img']['mean']:.2%} vs {p['mag_vs_ref_img']['mean']:.2%} (image)")
    log(f"[world] {spec.name}: (a)-(b) max rel {ab_all['max_rel']:.2e} ({ab_all['conditioned']} conditioned)"
        f"{lam_txt}{cod_txt} | a {timing['a']:.1f}s b {timing['b']:.1f}s c {sum(timing.get('c_cycles', [0])):.1f}s "
        f"total {timing['total']:.1f}s")


# --- furnace ---------------------------------------------------------------------------------------------

def run_furnace(args, out_dir, tables, log=print):
    """Uniform white world as a constant 64 x 32 Environment Texture: per variant the mean / min / max of
    (a) and (b) over the sphere's values."""
    folder = out_dir / "furnace"
    folder.mkdir(parents=True, exist_ok=True)
    path = vw.write_constant_equirect(folder / "white_64x32.exr", 1.0, 64, 32)
    spec = vw.WorldSpec("furnace", str(path))
    variants = vw.furnace_variants(args.quick)
    t0 = time.perf_counter()
    scene = vw.new_scene()
    vw.setup_world(scene, spec)
    env, params, bake, _ = vw.sync_world(scene, args.cache, args.lut_dir)
    mesh = vw.sphere_mesh(args.segments, args.segments // 2)
    columns = len(vw.FURNACE_ROUGHNESS)
    nb = vw.add_node_block(scene, variants, args.furnace_cell, columns, 0.0, args.lut_dir, mesh, name="furnace")
    passes = vw.render_node(scene, nb, [nb], folder)
    a = passes["Combined"].astype(np.float64)
    index = vw.block_index(nb, passes["Normal"])
    b, cond = _numpy_b(scene, variants, nb, passes, index, tables, env, params)
    ab_all, ab_ok = _ab_all(a, b, index, cond, args)
    rows = [_furnace_row(v, index == i, a, b, args) for i, v in enumerate(variants)]
    report.write_exr(folder / "node_a.exr", a)
    report.preview_png(folder / "a.png", np.where((index >= 0)[..., None], a, 0.0), 1.0)
    out = {"variants": rows, "ab": ab_all, "ab_ok": bool(ab_ok), "image": list(nb.resolution),
           "ok": all(r["ok"] for r in rows if r["gated"]), "seconds": time.perf_counter() - t0,
           "png": {"a": "furnace/a.png"}}
    worst = max((r for r in rows if r["gated"]), key=lambda r: r["max_abs_dev"])
    log(f"[world] furnace: max |value - 1| {worst['max_abs_dev']:.2e} ({worst['label']}); (a)-(b) "
        f"{ab_all['max_rel']:.2e}; {out['seconds']:.1f} s")
    return out


def _furnace_row(v, m, a, b, args):
    """One furnace sphere (pixels ``m``): (a) and (b) mean / min / max, the largest |value - 1| and, for
    the multiscattering models and Lambert, whether it is within ``--furnace-tol``."""
    ra, rb = a[m], b[m]
    gated = v.technique in vw.MULTISCATTER or v.technique == "lambert"
    row = {"label": v.label, "technique": v.technique, "roughness": v.roughness, "pixels": int(m.sum()),
           "node_mean": float(ra.mean()), "node_min": float(ra.min()), "node_max": float(ra.max()),
           "numpy_mean": float(rb.mean()), "numpy_min": float(rb.min()), "numpy_max": float(rb.max()),
           "max_abs_dev": float(max(np.abs(ra - 1).max(), np.abs(rb - 1).max())), "gated": gated}
    row["ok"] = (row["max_abs_dev"] <= args.furnace_tol) if gated else None
    return row


# --- checks, tables ------------------------------------------------------------------------------------

def _checks(args, worlds, furnace):
    checks = []
    cases = list(worlds) + ([dict(furnace, name="furnace")] if furnace else [])
    if cases:
        worst = max(cases, key=lambda c: c["ab"].get("max_rel_beyond_float32", 0.0))
        checks.append({"name": "(a) node render vs (b) numpy, every world (rel where |b| >= 1e-2 / abs below; "
                               "beyond 4x float32 conditioning)",
                       "measured": f"{max(c['ab']['max_rel'] for c in cases):.2e} (beyond conditioning "
                                   f"{worst['ab'].get('max_rel_beyond_float32', 0.0):.2e}, {worst['name']}; "
                                   f"{sum(c['ab'].get('conditioned', 0) for c in cases)} values conditioned) / "
                                   f"{max(c['ab'].get('max_abs_near_zero_beyond_float32', 0.0) for c in cases):.2e}",
                       "threshold": f"{args.ab_tol:g} / {args.ab_atol:g}", "ok": all(c["ab_ok"] for c in cases)})
    if furnace:
        gated = [r for r in furnace["variants"] if r["gated"]]
        worst = max(gated, key=lambda r: r["max_abs_dev"])
        checks.append({"name": "furnace (white world): multiscattering split sums with F0 = 1 and Lambert, "
                               "max |value - 1| over every pixel, node render and numpy",
                       "measured": f"{worst['max_abs_dev']:.2e} ({worst['label']})",
                       "threshold": f"{args.furnace_tol:g}", "ok": furnace["ok"]})
    for w in worlds:
        if w["cod"] is not None and w["gate_cod"]:
            p = w["cod"]["pooled"]
            checks.append({"name": f"{w['name']}: CoD SH-LTC mean error < magnitude-only (vs brute force under the "
                                   "SH environment)",
                           "measured": f"{p['ltc_vs_ref_sh']['mean']:.3%} < {p['mag_vs_ref_sh']['mean']:.3%}",
                           "threshold": "below", "ok": bool(w["cod_ok"])})
    for w in worlds:
        lam = w.get("lambert") or {}
        h = lam.get("image_vs_cycles")
        if h:
            checks.append({"name": f"{w['name']}: harness, Lambert texel sum vs Cycles Diffuse (median)",
                           "measured": f"{h['median']:.3%}", "threshold": f"{args.harness_lambert_median:.1%}",
                           "ok": h["median"] <= args.harness_lambert_median})
    return checks


def _pct(x, d=2):
    return "-" if x is None else f"{100 * x:.{d}f}%"


def _median_p90(x):
    """'median / p90' of a rel_stats dict, '-' without one."""
    return "-" if not x else f"{_pct(x['median'])} / {_pct(x['p90'])}"


def _mean_median_p90(x):
    """'mean (median, p90)' of a rel_stats dict."""
    return f"{_pct(x['mean'])} ({_pct(x['median'])}, {_pct(x['p90'])})"


def _with_furnace(result):
    """The worlds and, when it ran, the furnace as one more case."""
    fur = result.get("furnace")
    return result["worlds"] + ([dict(fur, name="furnace", description="furnace")] if fur else [])


def _tables(result):
    """Markdown tables of the acceptance numbers."""
    sections = (_md_intro, _md_gates, _md_lambert, _md_cod, _md_specular, _md_furnace, _md_ab, _md_bake,
                _md_timings)
    return "\n".join(line for section in sections for line in section(result)) + "\n"


def _md_intro(result):
    """Title and the run's settings."""
    s = result["settings"]
    return ["# RT Lit World term: validation under Blender's studio HDRIs", "",
            f"Generated by `{s['command']}` in {result['timings_s']['total']:.0f} s "
            f"(Blender {s['blender']}, {s['threads']} threads, {s['cpu_count']} CPUs).  Spheres {s['cell_px']} px per "
            f"cell; Cycles truth {s['samples']} spp x seeds {s['seeds']}, max bounces 0 (world sampled as a light, "
            f"MIS); relative errors over values (pixel x channel) where the reference exceeds {s['floor']:g} x the "
            f"sphere's median (a max-relative floor would keep only a sun's highlight).  Noise: |c1 - c2| / 2 per value, the Monte Carlo error of the truth c.", ""]


def _md_gates(result):
    """The checks that set the exit status."""
    L = ["## Gates", "", "| check | measured | threshold | |", "|---|---|---|---|"]
    for c in result["checks"]:
        L.append(f"| {c['name']} | {c['measured']} | {c['threshold']} | {'ok' if c['ok'] else 'FAIL'} |")
    return L


def _md_lambert(result):
    """Item 1: Lambert vs Cycles per world, with the SH truncation and the harness check."""
    s = result["settings"]
    L = ["", "## 1. Lambert (L2 SH irradiance) vs Cycles Diffuse BSDF", "",
         "SH truncation = RT Lit (a) vs the Lambert integral summed over the image's texels "
         f"(area-averaged to {s['lambert_image']} x {s['lambert_image'] // 2}); harness = that texel sum vs Cycles "
         "(must be at the noise level: it checks mapping, rotation and strength).", "",
         "| world | mean | median | p90 | max | bias | noise median | SH truncation mean / median | harness median |",
         "|---|---|---|---|---|---|---|---|---|"]
    for w in result["worlds"]:
        e = next((x for x in w["variants"] if x["technique"] == "lambert"), None)
        t = (e or {}).get("truth_metrics")
        lam = w.get("lambert") or {}
        tr, hc = lam.get("sh_vs_image"), lam.get("image_vs_cycles")
        if t:
            L.append(f"| {w['description']} | {_pct(t['mean'])} | {_pct(t['median'])} | {_pct(t['p90'])} | "
                     f"{_pct(t['max'])} | {_pct(t['bias_rel'])} | {_pct(t.get('noise_median'), 3)} | "
                     f"{_pct(tr and tr['mean'])} / {_pct(tr and tr['median'])} | {_pct(hc and hc['median'])} |")
    return L


def _md_cod(result):
    """Item 2: the CoD study per world, pooled per roughness, and per world and roughness; the multiscattering
    wrapped diffuse's beside it."""
    wrapped = ["", "### Multiscattering wrapped diffuse (CoD + wrap, w = 0.5): the wrapped lobe about the SH-LTC axis vs "
                   "about N", ""] + _md_cod_worlds(result, "cod_wrapped")[5:] + _md_cod_per_roughness(result, "cod_wrapped")
    has_wrapped = any(w.get("cod_wrapped") for w in result["worlds"])
    return (_md_cod_worlds(result) + _md_cod_pooled(result) + _md_cod_per_roughness(result)
            + (wrapped if has_wrapped else []))


def _md_cod_worlds(result, key="cod"):
    L = ["", "## 2. CoD WWII diffuse: SH-LTC lobe vs magnitude only, against brute force of the true BRDF", "",
         "Per world, pooled over the CoD spheres (r in the sweep), seeded pixels: mean (median, p90) relative error. "
         "'SH env' = the BRDF integrated against the SH-projected environment (the lobe approximation alone); "
         "'image' = against the image area-averaged to the stated texels (includes the SH truncation).", "",
         "| world | SH-LTC vs SH env | magnitude only vs SH env | SH-LTC vs image | magnitude only vs image | "
         "(a) vs numpy SH-LTC (max) |", "|---|---|---|---|---|---|"]
    for w in result["worlds"]:
        c = w.get(key)
        if not c:
            continue
        p = c["pooled"]
        L.append(f"| {w['description']} | {_mean_median_p90(p['ltc_vs_ref_sh'])} | "
                 f"{_mean_median_p90(p['mag_vs_ref_sh'])} | {_mean_median_p90(p['ltc_vs_ref_img'])} | "
                 f"{_mean_median_p90(p['mag_vs_ref_img'])} | {p['node_vs_ltc_numpy']['max']:.1e} |")
    return L


def _md_cod_pooled(result):
    cp = result.get("cod_pooled") or {}
    if not cp:
        return []
    L = ["", f"Mean over {result['pooled_worlds']} of the per-world mean error, per roughness:", "",
         "| r | SH-LTC vs SH env | magnitude only vs SH env | SH-LTC vs image | magnitude only vs image |",
         "|---|---|---|---|---|"]
    for r, d in cp.items():
        L.append(f"| {r} | {_pct(d['ltc_vs_ref_sh'])} | {_pct(d['mag_vs_ref_sh'])} | {_pct(d['ltc_vs_ref_img'])} | "
                 f"{_pct(d['mag_vs_ref_img'])} |")
    return L


def _md_cod_per_roughness(result, key="cod"):
    L = ["", "Per world and roughness (mean errors):", "",
         "| world | r | SH-LTC / mag-only vs SH env | SH-LTC / mag-only vs image |", "|---|---|---|---|"]
    for w in result["worlds"]:
        c = w.get(key)
        if not c:
            continue
        for row in c["per_roughness"]:
            L.append(f"| {w['name']} | {row['roughness']:g} | {_pct(row['ltc_vs_ref_sh']['mean'])} / "
                     f"{_pct(row['mag_vs_ref_sh']['mean'])} | {_pct(row['ltc_vs_ref_img']['mean'])} / "
                     f"{_pct(row['mag_vs_ref_img']['mean'])} |")
    return L


def _md_specular(result):
    """Item 3: specular vs Cycles pooled (all and front-facing values), the GGX harness, and per world."""
    pooled = result["pooled"]
    techs = [t for t in ("ggx", "turquin", "fdez_aguera", "fdez_aguera_radiance", "kulla_conty")
             if any(g["technique"] == t for g in pooled)]
    rough = sorted({g["roughness"] for g in pooled if g["technique"] in techs})
    by = {(g["technique"], g["roughness"]): g for g in pooled}
    return (_md_specular_pooled(result, techs, rough, by) + _md_specular_front(techs, rough, by)
            + _md_ggx_harness(result) + _md_specular_per_world(result, techs, rough))


def _technique_table(techs, rough, by, cell):
    """Technique x roughness table of the pooled entries ``by``, one ``cell(entry or None)`` each."""
    L = ["| technique | " + " | ".join(f"r = {r:g}" for r in rough) + " |", "|---|" + "---|" * len(rough)]
    for t in techs:
        L.append(f"| {t} | " + " | ".join(cell(by.get((t, r))) for r in rough) + " |")
    return L


def _md_specular_pooled(result, techs, rough, by):
    def cell(g):
        return ("-" if not g or not g["values"] else
                f"{_pct(g['median'])} / {_pct(g['p90'])} ({_pct(g.get('noise_median'), 2)})")

    return (["", "## 3. Specular (F = 1) vs Cycles", "",
             f"Pooled over {result['pooled_worlds']}: median / p90 relative error (noise median of the truth in brackets).  "
             "ggx = single-scattering split sum vs Glossy GGX; the others vs Glossy Multiscatter GGX.", ""]
            + _technique_table(techs, rough, by, cell))


def _md_specular_front(techs, rough, by):
    def cell(g):
        return "-" if not g or "front_median" not in g else f"{_pct(g['front_median'])} / {_pct(g['front_p90'])}"

    return (["", f"The same, front-facing values only (N.V >= {FRONT_MU:g}): median / p90.", ""]
            + _technique_table(techs, rough, by, cell))


def _md_ggx_harness(result):
    s = result["settings"]
    L = ["", "Harness and the split sum's error without noise (single scattering, F = 1), on seeded pixels of the "
         "ggx spheres: (1) the brute-force integral of the true GGX BRDF over the image (area-averaged to "
         f"{s['ggx_image']} x {s['ggx_image'] // 2} texels) vs Cycles Glossy GGX: the harness, should be at the noise "
         "level; (2) RT Lit (a) vs that integral; (3) the exact split sum E(N.V) P(dominant direction), P the "
         "prefilter integral over the same texels, vs the integral: the split-sum approximation itself "
         "(signed bias of the sum in brackets); (4) (a) vs the exact split sum: the stored levels' lookup "
         "(128 x 64, bilinear, linear between roughness levels).  Median / p90.", "",
         "| world | r | (1) brute vs Cycles | (2) RT Lit vs brute | (3) exact split sum vs brute (bias) | "
         "(4) RT Lit vs exact split sum |", "|---|---|---|---|---|---|"]
    for w in result["worlds"]:
        g = w.get("ggx_harness")
        if not g:
            continue
        for row in g["rows"]:
            L.append(f"| {w['name']} | {row['roughness']:g} | {_median_p90(row.get('brute_vs_cycles'))} | "
                     f"{_median_p90(row['split_sum_vs_brute'])} | {_median_p90(row['exact_split_sum_vs_brute'])} "
                     f"({_pct(row['bias_exact_split_sum_vs_brute'])}) | "
                     f"{_median_p90(row['split_sum_vs_exact_split_sum'])} |")
    return L


def _md_specular_per_world(result, techs, rough):
    L = ["", "Per world (median / p90):", ""]
    for t in techs:
        L += [f"### {t}", "", "| world | " + " | ".join(f"r = {r:g}" for r in rough) + " |",
              "|---|" + "---|" * len(rough)]
        for w in result["worlds"]:
            cells = []
            for r in rough:
                e = next((x for x in w["variants"] if x["technique"] == t and x["roughness"] == r), None)
                cells.append(_median_p90((e or {}).get("truth_metrics")))
            if any(c != "-" for c in cells):
                L.append(f"| {w['description']} | " + " | ".join(cells) + " |")
        L.append("")
    return L


def _md_furnace(result):
    """Item 4: the furnace per variant (the section before ends with a blank line)."""
    fur = result.get("furnace")
    if not fur:
        return []
    L = ["## 4. Furnace (constant white 64 x 32 Environment Texture, F0 = 1)", "",
         "Node render (a) and numpy (b): mean [min, max] over every sphere value.  ggx (single scattering) is "
         "the split-sum albedo E, reported, not gated.", "",
         "| technique | r | (a) mean [min, max] | (b) mean [min, max] | max abs dev | |", "|---|---|---|---|---|---|"]
    for r in fur["variants"]:
        L.append(f"| {r['technique']} | {r['roughness']:g} | {r['node_mean']:.6f} [{r['node_min']:.6f}, "
                 f"{r['node_max']:.6f}] | {r['numpy_mean']:.6f} [{r['numpy_min']:.6f}, {r['numpy_max']:.6f}] | "
                 f"{r['max_abs_dev']:.1e} | {'' if r['ok'] is None else ('ok' if r['ok'] else 'FAIL')} |")
    return L


def _md_ab(result):
    """Item 5: (a) vs (b) per world and the furnace."""
    L = ["", "## 5. Node render (a) vs numpy (b)", "",
         "| world | max rel (|b| >= 1e-2) | beyond float32 conditioning | conditioned values | max abs near 0 | values |",
         "|---|---|---|---|---|---|"]
    for w in _with_furnace(result):
        ab = w["ab"]
        L.append(f"| {w['description']} | {ab['max_rel']:.2e} | {ab.get('max_rel_beyond_float32', 0):.2e} | "
                 f"{ab.get('conditioned', 0)} | {ab['max_abs_near_zero']:.1e} | {ab['values']} |")
    return L


def _md_bake(result):
    """Item 6: bake time per HDRI, forced and cached."""
    s = result["settings"]
    L = ["", "## 6. Bake time per HDRI", "",
         "As RT Lookdev > Sync World bakes (`addon.world.bake_world`: the Environment Texture image's pixels, "
         "1024 x 512, through `prefilter.bake_environment_image`: L2 SH projection and 9 GGX-prefiltered levels of "
         f"128 x 64 by FFT quadrature), forced, then a cached re-run; {s['threads']}-core machine "
         f"({s['cpu_count']} CPUs).  'call' = the whole bake_world call (reading the image's pixels included).", "",
         "| HDRI | SH (s) | prefiltered (s) | bake total (s) | call (s) | cached re-run call (s) | cached states |",
         "|---|---|---|---|---|---|---|"]
    for w in result["worlds"]:
        bt = w.get("bake")
        if not bt:
            continue
        f, c = bt["forced"], bt["cached"]
        L.append(f"| {w['hdri']} | {f['seconds']['sh']:.2f} | {f['seconds']['prefiltered']:.2f} | "
                 f"{f['seconds']['total']:.2f} | {f['wall']:.2f} | {c['wall']:.3f} | "
                 f"{', '.join(f'{k}: {v}' for k, v in c['states'].items())} |")
    return L


def _md_timings(result):
    """Seconds per step and world."""
    L = ["", "## Timings (s)", "", "| world | sync | build | (a) | (b) | Cycles truth (per seed) | total |",
         "|---|---|---|---|---|---|---|"]
    for w in result["worlds"]:
        t = w["timing_s"]
        L.append(f"| {w['name']} | {t.get('sync', 0):.1f} | {t.get('build', 0):.1f} | {t['a']:.1f} | {t['b']:.1f} | "
                 + ", ".join(f"{x:.1f}" for x in t.get("c_cycles", [])) + f" | {t['total']:.1f} |")
    return L


def _html(result, md_text):
    """report.html: the markdown tables as preformatted text, the checks, and the images per world."""
    out = [f"<!doctype html><html><head><meta charset='utf-8'><title>RT Lit World validation</title>"
           f"<style>{report._CSS}</style></head><body><h1>RT Lit World term: validation</h1>",
           f"<p>Overall: {report._ok(result['passed'])}; {result['timings_s']['total']:.0f} s.</p>",
           "<table><tr><th>check</th><th>measured</th><th>threshold</th><th></th></tr>"]
    for c in result["checks"]:
        out.append(f"<tr><td class='l'>{html.escape(c['name'])}</td><td>{html.escape(c['measured'])}</td>"
                   f"<td>{html.escape(c['threshold'])}</td><td>{report._ok(c['ok'])}</td></tr>")
    out.append("</table>")
    for w in _with_furnace(result):
        out.append(f"<h3>{html.escape(w['description'])}</h3>")
        for key, cap in (("a", "(a) node render"), ("c", "(c) Cycles truth, per node cell"),
                         ("err_ac", f"|a - c| / c (bar 0 - {ERR_VMAX:g})"), ("err_ab", "|a - b| / max(|b|, 0.01)")):
            if key in w.get("png", {}):
                out.append(f"<figure><img src='{w['png'][key]}'><figcaption>{cap}</figcaption></figure>")
    out.append("<h2>Tables</h2><pre>" + html.escape(md_text) + "</pre></body></html>")
    return "\n".join(out)


# --- driver ----------------------------------------------------------------------------------------------

def parse_args(argv):
    """The options of ``run`` (scripts/validate_world.py) parsed from ``argv``."""
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    p.add_argument("--out", default="out/validation_world")
    p.add_argument("--quick", action="store_true",
                   help=f"CI subset: {QUICK[0]} rotated and scaled, few spheres, fewer samples, small furnace")
    p.add_argument("--hdri", action="append", default=None, help="studio HDRI name or EXR path (repeatable)")
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
    from ..core.environment import equirect

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
    from ..core.lut import lookup

    t_start = time.perf_counter()
    out_dir = Path(args.out)
    out_dir.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(args.seed)
    tables = lookup.LutSet.from_folder(args.lut_dir)
    worlds, parts = _run_worlds(args, out_dir, rng, tables, log)
    furnace = None if args.skip_furnace else run_furnace(args, out_dir, tables, log)
    pooled, pooled_worlds = _pool_worlds(worlds, parts)
    checks = _checks(args, worlds, furnace)
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
                         bake_timing=args.bake_timing and not (rotated and not args.quick))
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
    pooled = [dict(technique=t, roughness=r, **_pool(e)) for (t, r), e in sorted(groups.items())]
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
    md = _tables(result)
    (out_dir / "report.md").write_text(md)
    (out_dir / "report.json").write_text(json.dumps(result, indent=1, default=report.json_default))
    (out_dir / "report.html").write_text(_html(result, md))


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
