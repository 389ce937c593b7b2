"""One world of the world suite (scene and bake, (a) node render and (b) numpy, (c) the Cycles truth, the
per-sphere figures and images), and the white furnace."""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ..harness import metrics, outputs
from . import world_cases as vw
from . import suite_metrics
from . import suite_scene
from .world_studies import cod_study, ERR_VMAX, FRONT_MU, ggx_study, lambert_study, view_cosine


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
        return suite_scene.numpy_radiance(scene, variants, nb.objects, p, index, tables,
                                    (env, vw.world_params_numpy(params)), dtype)

    return suite_scene.conditioning(fn, passes)


def _ab_all(a, b, index, cond, args):
    """(a) vs (b) over every sphere pixel, and whether it passes validate.py's rule."""
    ab_all = suite_metrics.ab_metrics(a, b, index >= 0, conditioning=cond, tol=args.ab_tol, atol=args.ab_atol)
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
    mu_img = view_cosine(ws.scene, nr.passes)
    c_full = np.full(nr.a.shape, np.nan)
    entries, parts = [], []
    lambert_truth = lambert_mask = None
    for i, v in enumerate(variants):
        mask = nr.index == i
        e = {"index": i, "label": v.label, "technique": v.technique, "roughness": v.roughness,
             "closure": list(v.closure) if v.closure else None, "pixels": int(mask.sum()),
             "ab": suite_metrics.ab_metrics(nr.a, nr.b, mask)}
        if truth is not None and v.closure is not None:
            m, c_cell, figures, part = _truth_comparison(spec, i, v, ws, nr, truth, mu_img, samples_total, args)
            e.update(figures)
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
    figures = {"cell_normal_max_diff": ndiff,
               "truth_metrics": suite_metrics.truth_metrics(a_cell, c_cell, m, frac, pair, samples_total,
                                                    error_exponent=suite_metrics.CYCLES_WORLD_ERROR_EXPONENT),
               "truth_metrics_wide": suite_metrics.truth_metrics(a_cell, c_cell, m, frac_w, pair, samples_total,
                                                         error_exponent=suite_metrics.CYCLES_WORLD_ERROR_EXPONENT)}
    rel, noise = metrics.rel_values(a_cell, c_cell, m, frac, pair)
    rel_w, _ = metrics.rel_values(a_cell, c_cell, m, frac_w)
    rel_f = _front_rel_values(a_cell, c_cell, m, ws.nb.cell(mu_img, i), frac)
    if rel_f is not None:
        figures["truth_metrics_front"] = {"values": int(rel_f.size), "median": float(np.median(rel_f)),
                                          "p90": float(np.percentile(rel_f, 90)), "mean": float(rel_f.mean())}
    part = None
    if rel is not None:
        part = {"technique": v.technique, "roughness": v.roughness, "world": spec.name,
                "rel": rel, "noise": noise, "rel_wide": rel_w, "rel_front": rel_f}
    return m, c_cell, figures, part


def _front_rel_values(a_cell, c_cell, m, mu_cell, frac):
    """Relative errors over the front-facing values (N.V >= FRONT_MU) of the mask; None if there are none."""
    front = m & (mu_cell >= FRONT_MU)
    if not front.any():
        return None
    # the same absolute floor as the whole sphere's
    cmax_f = float(np.nanmax(c_cell[front]))
    frac_f = frac * float(np.nanmax(c_cell[m])) / cmax_f if cmax_f > 0 else frac
    rel_f, _ = metrics.rel_values(a_cell, c_cell, front, frac_f)
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
    outputs.write_exr(folder / "node_a.exr", a)
    outputs.write_exr(folder / "numpy_b.exr", b)
    hit = index >= 0
    scale = float(np.percentile(a[hit], 99)) if hit.any() else 1.0
    png = {"a": "a.png", "err_ab": "err_ab.png"}
    outputs.preview_png(folder / "a.png", np.where(hit[..., None], a, 0.0), scale)
    with np.errstate(invalid="ignore", divide="ignore"):
        err_ab = (np.abs(a - b) / np.maximum(np.abs(b), 1e-2)).max(axis=-1) * hit
    outputs.error_png(folder / "err_ab.png", np.minimum(err_ab, args.ab_tol), args.ab_tol)
    if truth is not None:
        outputs.write_exr(folder / "truth_c.exr", truth["mean"])
        outputs.preview_png(folder / "c.png", np.nan_to_num(c_full), scale)
        with np.errstate(invalid="ignore", divide="ignore"):
            err = np.where(np.isfinite(c_full) & (c_full > 0), np.abs(a - c_full) / c_full, np.nan).max(axis=-1)
        outputs.error_png(folder / "err_ac.png", np.minimum(np.nan_to_num(err), ERR_VMAX), ERR_VMAX)
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
            "ggx_harness": ggx, "gate_cod": gate_cod, "lambert": lam, "bake": bake_times, "source": vw.world_source(),
            "timing_s": timing,
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
    outputs.write_exr(folder / "node_a.exr", a)
    outputs.preview_png(folder / "a.png", np.where((index >= 0)[..., None], a, 0.0), 1.0)
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
