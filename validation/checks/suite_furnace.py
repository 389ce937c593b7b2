"""The validation suite's furnace: GGX spheres under a white world, the RT Lit material's energy against Cycles'
(``run_furnace``, a step of ``suite.run``)."""
from __future__ import annotations

import time

import numpy as np

from ..harness import scene_render
from . import energy_render as ve
from ...core import energy_checks as core_validation
from ...core import multiscatter


def run_furnace(args, out_dir, log=print):
    folder = out_dir / "furnace"
    roughness = (0.25, 0.5, 0.75, 1.0)
    t0 = time.perf_counter()
    energy = ve.measure(resolution=args.furnace_cell, samples=args.furnace_samples, roughness=roughness,
                    out_dir=folder, lut_dir=args.lut_dir, seeds=tuple(args.seeds), threads=args.threads,
                    exact=False, log=lambda s: None)
    t_energy = time.perf_counter() - t0
    ms = {k: {"mean": v["mean"], "se": v["se"], "ok": v["ok"]} for k, v in energy["MULTI_GGX"].items()}
    ms_ok = all(abs(v["mean"] - 1.0) <= args.furnace_tol for v in ms.values())

    tables, _ = ve.energy_tables(args.lut_dir)
    mu = np.linspace(0.1, 1.0, 10)
    t0 = time.perf_counter()
    kc = core_validation.kulla_conty_furnace(tables, np.array(roughness), mu)
    kc_max = {f"{r:g}": float(np.max(np.abs(row))) for r, row in zip(roughness, kc)}
    t_kc = time.perf_counter() - t0

    # Kulla-Conty coloured albedo vs Cycles Multiscatter GGX with Color = c (constant Fresnel c):
    # Cycles: c E + c^2 E_avg (1 - E)/(1 - c (1 - E_avg)) = c E + F_ms(c) (1 - E), the KC albedo.
    color = (0.9, 0.6, 0.3)
    t0 = time.perf_counter()
    scene, glossies = ve.build_scene(roughness, args.furnace_cell)
    for g in glossies:
        g.distribution = "MULTI_GGX"
        g.inputs["Color"].default_value = color + (1.0,)
    pair = []
    for seed in args.seeds[:2]:
        ve.configure_render(scene, args.furnace_samples, seed, args.threads)
        path = folder / f"kc_color_seed{seed}.exr"
        scene_render.render_exr(scene, path)
        pair.append(scene_render.read_passes(path))
    (ca, na), (cb, nb) = pair
    h, w = ca.shape[:2]
    sphere, _ = ve.pixel_geometry(w, h, len(roughness))
    nrm = 0.5 * (na + nb)
    length = np.linalg.norm(nrm, axis=-1)
    max_rel = {}
    for i, r in enumerate(roughness):
        sel = (sphere == i) & (length > 0.5)
        m = np.clip((nrm[sel] / length[sel, None]) @ ve.VIEW, 0.0, 1.0)
        cyc = 0.5 * (ca[sel] + cb[sel])
        e = tables.e(m, np.full_like(m, r))
        om_avg = float(tables.one_minus_e_avg(np.array([r]))[0])
        pred = np.stack([ch * e + multiscatter.kulla_conty_fresnel_factor(ch, om_avg) * (1.0 - e) for ch in color], -1)
        worst = 0.0
        for lo, hi in zip(ve.MU_EDGES[1:-1], ve.MU_EDGES[2:]):
            s = (m >= lo) & ((m < hi) if hi < 1 else (m <= hi))
            if s.sum() > 10:
                worst = max(worst, float(np.max(np.abs(cyc[s].mean(0) / pred[s].mean(0) - 1.0))))
        max_rel[f"{r:g}"] = worst
    t_color = time.perf_counter() - t0
    kc_color = {"color": list(color), "max_rel_bin": max_rel,
                "ok": all(v <= args.furnace_tol for v in max_rel.values())}
    out = {"settings": f"{args.furnace_cell} px per sphere, {args.furnace_samples} spp x {len(args.seeds)} seeds",
           "validate_energy_passed": bool(energy["passed"]), "multi_ggx": ms, "multi_ggx_ok": bool(ms_ok),
           "kc_lut_max_abs": kc_max, "kc_lut_ok": all(v <= args.furnace_tol for v in kc_max.values()),
           "kc_color": kc_color,
           "times_s": {"validate_energy": t_energy, "kc_lut": t_kc, "kc_color_render": t_color}}
    ms_text = ", ".join(f"{k}: {v['mean']:.4f}" for k, v in ms.items())
    log(f"[validate] furnace: MS GGX {ms_text}; "
        f"KC LUT max |E-1| {max(kc_max.values()):.1e}; KC colour vs Cycles max {max(max_rel.values()):.3%} "
        f"({t_energy + t_kc + t_color:.1f} s)")
    return out
