"""Render check of the GGX energy tables against Cycles (white furnace on spheres).

A row of smooth UV spheres, one per roughness, sits under a uniform white world (Background,
strength 1) and is seen by an orthographic camera looking down -Z, so the view vector is
V = +Z for every pixel.  With a white Glossy BSDF and nothing else in the scene, each sphere
pixel is the directional albedo of the BSDF at mu = N.V
(docs/multiscattering.md, "Ground truth in Cycles"):

* distribution 'GGX': single-scattering GGX with F = 1, i.e. E(mu, r), compared per pixel with
  ``LutSet.e`` (our LUT, sampled as Blender samples it) and with a dense evaluation of
  ``core.energy.directional_albedo``;
* distribution 'MULTI_GGX': Cycles' albedo-scaled GGX (f_ss / E_cycles(mu)), which must be
  1 +- 0.005 (docs/multiscattering.md, "Multiscatter GGX in Cycles"); its residual is Cycles'
  own 32x32 table interpolation error.

mu comes from the Normal pass (world-space shading normal, the one the closure uses).  Every
configuration is rendered with two seeds; the per-pixel Monte Carlo variance of the mean
of the two renders is estimated as (a - b)^2 / 4, so a bin of n pixels has the standard error
sqrt(sum (a - b)^2 / 4) / n.  Results are binned in mu (10 bins over [0.1, 1] plus a grazing
bin [0, 0.1) that is reported but not judged).

Usage (plain Python with the bpy module, or inside Blender):
    python scripts/validate_energy.py [--resolution N] [--samples S] [--roughness 0.25 0.5 ...]
                                      [--out DIR] [--lut-dir DIR]
    blender --background --python scripts/validate_energy.py -- [same options]
``measure(...)`` is the entry point for other code (``run(args, progress)`` the entry signature's); it resets the open file with
``read_homefile(use_empty=True)`` (never ``read_factory_settings``, which disables extensions).
"""
from __future__ import annotations

import argparse
import json
import math
import tempfile
import time
from pathlib import Path

import numpy as np

from ...core import energy
from ...core import lut_bake as bake
from ...core.lut import catalog
from ...core.lut.lookup import LutSet
from ..harness import outputs, scene_render
from ..harness.render_setup import configure_cycles_measurement

#: Bin edges in mu for the report; bins below MU_JUDGED are reported, not judged.
MU_EDGES = tuple(float(x) for x in np.round(np.linspace(0.0, 1.0, 11), 10))
MU_JUDGED = 0.1
#: A GGX bin matches when |mean(pixel - E)| <= Z_MAX standard errors.  4 rather than 3: with
#: 10 bins x 4 roughness values a 3-sigma rule fails a correct renderer ~10 % of the time,
#: 4 sigma ~0.25 %.
Z_MAX = 4.0
#: Multiscatter GGX acceptance: every judged bin mean within 1 +- MS_TOL.
MS_TOL = 0.005
#: Systematic floor added to the noise bound of a GGX bin: |bias| <= Z_MAX * se + SYS_TOL.
#: Without it the test gets stricter as samples grow, until it resolves effects that are not
#: errors of our E: our 64x64 bilinear LUT is within 1.3e-4 of the exact integral for
#: mu >= 0.1, and Cycles' rendered GGX albedo itself deviates from the exact integral by up to
#: ~3e-4 (common to both seeds, so not noise; measured at 256 spp, 42k pixels per sphere).
#: Half the LUT-level target |dE| <= 1e-3 (docs/multiscattering.md, "Accuracy targets").
#: ``ok_noise_only`` in the
#: results is the pure |z| <= Z_MAX verdict.
SYS_TOL = 5e-4
#: |mean(pixel - E)| over all judged pixels of one roughness must stay below this.
ABS_BIAS_TARGET = 1e-3

SPHERE_RADIUS = 1.0
CELL = 2.2                       # world units per sphere along the row (diameter + margin)
CAMERA_HEIGHT = 10.0
VIEW = np.array([0.0, 0.0, 1.0])  # direction towards the orthographic camera


# ---------------------------------------------------------------------------------------------
# scene
# ---------------------------------------------------------------------------------------------

def build_scene(roughness, resolution, segments=256, rings=128):
    """Reset the file and build the spheres, world and camera.  Returns (scene, glossy nodes)."""
    from ...addon import compat
    import bpy

    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    n = len(roughness)

    world = compat.new_world("RTL_white_world")
    wt = world.node_tree
    wt.nodes.clear()
    bg = wt.nodes.new("ShaderNodeBackground")
    bg.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    bg.inputs["Strength"].default_value = 1.0
    wout = wt.nodes.new("ShaderNodeOutputWorld")
    wt.links.new(bg.outputs["Background"], wout.inputs["Surface"])
    scene.world = world

    mesh = scene_render.uv_sphere_mesh("RTL_sphere", segments, rings, SPHERE_RADIUS)
    glossies = []
    for i, r in enumerate(roughness):
        mat = compat.new_material(f"RTL_glossy_{r:g}")
        nt = mat.node_tree
        nt.nodes.clear()
        g = nt.nodes.new("ShaderNodeBsdfGlossy")
        g.distribution = "GGX"
        g.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
        g.inputs["Roughness"].default_value = float(r)
        g.inputs["Anisotropy"].default_value = 0.0
        out = nt.nodes.new("ShaderNodeOutputMaterial")
        out.target = "ALL"
        nt.links.new(g.outputs["BSDF"], out.inputs["Surface"])
        me = mesh.copy()
        me.materials.append(mat)
        ob = bpy.data.objects.new(f"RTL_sphere_{i}", me)
        ob.location = ((i - (n - 1) / 2.0) * CELL, 0.0, 0.0)
        # Poles on the silhouette (top and bottom of the image), not facing the camera.
        ob.rotation_euler = (math.pi / 2.0, 0.0, 0.0)
        # Only camera rays see the spheres: reflected rays go straight to the world, so no
        # sphere lights its neighbours (a row of spheres does see itself sideways; with GGX
        # that darkens mid-mu pixels by up to ~9 %).  A convex sphere cannot see itself, so
        # this changes nothing else (bar rays that leave below the tessellated surface at the
        # silhouette).
        ob.visible_glossy = False
        ob.visible_diffuse = False
        ob.visible_transmission = False
        ob.visible_volume_scatter = False
        ob.visible_shadow = False
        scene.collection.objects.link(ob)
        glossies.append(g)

    cam_data = bpy.data.cameras.new("RTL_ortho")
    cam_data.type = "ORTHO"
    cam_data.ortho_scale = n * CELL
    cam_data.sensor_fit = "HORIZONTAL"
    cam_data.clip_start = 0.1
    cam_data.clip_end = 100.0
    cam = bpy.data.objects.new("RTL_camera", cam_data)
    cam.location = (0.0, 0.0, CAMERA_HEIGHT)   # rotation 0: looks down -Z
    scene.collection.objects.link(cam)
    scene.camera = cam

    rd = scene.render
    rd.resolution_x = n * resolution
    rd.resolution_y = resolution
    rd.resolution_percentage = 100
    rd.pixel_aspect_x = rd.pixel_aspect_y = 1.0
    return scene, glossies


def configure_render(scene, samples, seed, threads=2):
    """Cycles settings for an unbiased, unclamped, point-sampled linear render
    (validation/harness/render_setup.py), plus what the furnace needs: glossy bounces, no glossy filter."""
    from ...addon import compat

    configure_cycles_measurement(scene, samples, seed, threads)
    c = scene.cycles
    c.blur_glossy = 0.0                # "Filter Glossy"
    c.caustics_reflective = True
    c.caustics_refractive = True
    c.max_bounces = 4
    c.glossy_bounces = 4
    c.diffuse_bounces = 0
    c.transmission_bounces = 0
    c.volume_bounces = 0
    c.transparent_max_bounces = 0
    scene.view_layers[0].use_pass_combined = True
    scene.view_layers[0].use_pass_normal = True
    s = scene.render.image_settings
    compat.set_exr_output(s, multilayer=True)
    s.exr_codec = "ZIP"


# ---------------------------------------------------------------------------------------------
# analysis
# ---------------------------------------------------------------------------------------------

def pixel_geometry(width, height, n_spheres):
    """Per pixel: sphere index (-1 outside every disc) and the analytic true-sphere normal."""
    px = CELL * n_spheres / width                       # world units per pixel (square pixels)
    x = (np.arange(width) + 0.5 - width / 2.0) * px
    y = (height / 2.0 - (np.arange(height) + 0.5)) * px  # EXR row 0 = top
    X, Y = np.meshgrid(x, y)
    idx = np.floor(X / CELL + n_spheres / 2.0).astype(np.int64)
    cx = (idx - (n_spheres - 1) / 2.0) * CELL
    lx, ly = (X - cx) / SPHERE_RADIUS, Y / SPHERE_RADIUS
    rho2 = lx * lx + ly * ly
    inside = rho2 < 1.0
    nz = np.sqrt(np.clip(1.0 - rho2, 0.0, 1.0))
    normal = np.stack([lx, ly, nz], axis=-1)
    return np.where(inside, idx, -1), normal


def _bin_stats(mu, diff_mean, diff_ab, edges):
    """Per mu bin: n, mean of diff_mean, its standard error from (a - b), z."""
    rows = []
    for lo, hi in zip(edges[:-1], edges[1:]):
        lo, hi = float(lo), float(hi)
        sel = (mu >= lo) & ((mu < hi) if hi < 1.0 else (mu <= hi))
        n = int(sel.sum())
        if n == 0:
            rows.append({"mu_lo": lo, "mu_hi": hi, "n": 0})
            continue
        mean = float(diff_mean[sel].mean())
        se = float(math.sqrt(np.sum(diff_ab[sel] ** 2) / 4.0) / n)
        rows.append({"mu_lo": lo, "mu_hi": hi, "n": n, "mean_mu": float(mu[sel].mean()),
                     "bias": mean, "se": se, "z": mean / se if se > 0 else float("inf")})
    return rows


class ExactE:
    """E(mu, r) from core.energy.directional_albedo on a dense mu grid (linear in between).

    With 257 nodes the interpolation error is ~E'' h^2 / 8 < 1e-5 for mu >= 0.1; the Hammersley
    estimator with 2^15 points is accurate to ~1e-5.
    """

    def __init__(self, roughness, n_mu=257, n_samples=1 << 15):
        self.mu = np.linspace(0.0, 1.0, n_mu)
        self.table = {float(r): row for r, row in
                      zip(roughness, energy.directional_albedo(self.mu, roughness, n_samples))}

    def __call__(self, mu, r):
        return np.interp(mu, self.mu, self.table[float(r)])


def analyse(renders, roughness, tables, exact=None, mu_edges=MU_EDGES, z_max=Z_MAX,
            ms_tol=MS_TOL, abs_bias_target=ABS_BIAS_TARGET, sys_tol=SYS_TOL):
    """Statistics of the GGX and MULTI_GGX render pairs.  ``renders[dist] = [(rgb, nrm), (rgb, nrm)]``."""
    edges = np.asarray(mu_edges)
    results = {"GGX": {}, "MULTI_GGX": {}, "normal_check": {}}
    passed = True
    for dist in ("GGX", "MULTI_GGX"):
        if dist not in renders:
            continue
        (ca, na), (cb, nb) = renders[dist]
        h, w = ca.shape[:2]
        sphere, n_true = pixel_geometry(w, h, len(roughness))
        for i, r in enumerate(roughness):
            nrm = 0.5 * (na + nb)
            length = np.linalg.norm(nrm, axis=-1)
            # Background has Normal = 0; the analytic disc drops pixels whose centre is off the
            # true sphere, which also drops the last pixels of the polygonal silhouette.
            sel = (sphere == i) & (length > 0.5)
            nn = nrm[sel] / length[sel, None]
            mu = np.clip(nn @ VIEW, 0.0, 1.0)
            a = ca[sel].mean(axis=-1)           # white BSDF: R = G = B up to float rounding
            b = cb[sel].mean(axis=-1)
            m = 0.5 * (a + b)
            key = f"{r:g}"
            entry = {"roughness": float(r), "pixels": int(sel.sum()),
                     "rgb_spread_max": float(np.max(np.ptp(ca[sel], axis=-1)))}
            judged = mu >= MU_JUDGED
            if dist == "GGX":
                e_lut = tables.e(mu, r)
                bins = _bin_stats(mu, m - e_lut, a - b, edges)
                ok_bins = True
                for row in bins:
                    row["judged"] = row["n"] > 0 and row["mu_lo"] >= MU_JUDGED - 1e-12
                    if row["n"] and exact is not None:
                        s = (mu >= row["mu_lo"]) & ((mu < row["mu_hi"]) if row["mu_hi"] < 1 else (mu <= 1))
                        e_ex = exact(mu[s], r)
                        row["bias_vs_exact"] = float(np.mean(m[s] - e_ex))
                        row["z_vs_exact"] = row["bias_vs_exact"] / row["se"] if row["se"] > 0 else None
                        row["lut_minus_exact"] = float(np.mean(e_lut[s] - e_ex))
                    if row["judged"]:
                        row["ok_noise_only"] = bool(abs(row["z"]) <= z_max)
                        row["ok"] = bool(abs(row["bias"]) <= z_max * row["se"] + sys_tol)
                        ok_bins &= row["ok"]
                bias_all = float(np.mean((m - e_lut)[judged]))
                se_all = float(math.sqrt(np.sum((a - b)[judged] ** 2) / 4.0) / judged.sum())
                entry.update({
                    "bins": bins,
                    "mean_bias": bias_all, "mean_abs_bias_over_bins": float(np.mean(
                        [abs(x["bias"]) for x in bins if x.get("judged")])),
                    "se": se_all, "z": bias_all / se_all,
                    "pixel_sigma_rms": float(np.sqrt(np.mean((a - b)[judged] ** 2 / 2.0))),
                    "ok_noise_only": bool(all(x["ok_noise_only"] for x in bins if x.get("judged"))),
                    "max_abs_bin_bias": float(max(abs(x["bias"]) for x in bins if x.get("judged"))),
                    "ok": bool(ok_bins and abs(bias_all) <= abs_bias_target),
                })
                if exact is not None:
                    e_ex = exact(mu[judged], r)
                    entry["mean_bias_vs_exact"] = float(np.mean(m[judged] - e_ex))
                    entry["lut_minus_exact_max_abs"] = float(np.max(np.abs(e_lut[judged] - e_ex)))
            else:
                bins = _bin_stats(mu, m - 1.0, a - b, edges)
                ok_bins = True
                for row in bins:
                    row["judged"] = row["n"] > 0 and row["mu_lo"] >= MU_JUDGED - 1e-12
                    if row["n"]:
                        row["mean"] = 1.0 + row["bias"]
                    if row["judged"]:
                        row["ok"] = bool(abs(row["bias"]) <= ms_tol)
                        ok_bins &= row["ok"]
                mean_all = float(np.mean(m[judged]))
                entry.update({"bins": bins, "mean": mean_all,
                              "se": float(math.sqrt(np.sum((a - b)[judged] ** 2) / 4.0) / judged.sum()),
                              "ok": bool(ok_bins and abs(mean_all - 1.0) <= ms_tol)})
            passed &= entry["ok"]
            results[dist][key] = entry

            if dist == "GGX":
                # Normal pass vs the analytic sphere normal at the pixel centre (exact for a
                # true sphere; the mesh is a 256x128 polygon, so they differ by the tessellation).
                nt = n_true[sel]
                ang = np.degrees(np.arccos(np.clip(np.sum(nt * nn, axis=-1), -1.0, 1.0)))
                mu_true = nt @ VIEW
                results["normal_check"][key] = {
                    "angle_deg_mean": float(ang.mean()), "angle_deg_max": float(ang.max()),
                    "mu_pass_minus_analytic_mean": float(np.mean((mu - mu_true)[judged])),
                    "mu_pass_minus_analytic_max_abs": float(np.max(np.abs(mu - mu_true)[judged])),
                    "seed_normals_identical": bool(np.array_equal(na[sel], nb[sel])),
                }
    results["passed"] = bool(passed)
    return results


# ---------------------------------------------------------------------------------------------
# driver
# ---------------------------------------------------------------------------------------------

def energy_tables(lut_dir):
    """The LUT set of lut_dir, or of the shipped folder if current, or of a fresh temp bake."""
    if lut_dir is None:
        if all(s.state == "ok" for s in catalog.lut_status()):
            lut_dir = catalog.default_lut_dir()
        else:
            lut_dir = Path(tempfile.mkdtemp(prefix="rtl-luts-"))
    # only the energy tables are read here; a no-op when they are current (the main job has
    # checked them already), so only actual baking is reported
    bake.bake(lut_dir, groups=["ggx_energy"], log=lambda line: "nothing to do" in line or print(line))
    return LutSet.from_folder(lut_dir), str(lut_dir)


def measure(resolution=256, samples=256, roughness=(0.25, 0.5, 0.75, 1.0), out_dir=None, lut_dir=None,
            seeds=(0, 1), threads=2, segments=256, rings=128, exact=True, keep_exr=True, log=print):
    """Render and analyse; returns a JSON-serialisable dict (also written to out_dir)."""
    t_start = time.perf_counter()
    roughness = [float(r) for r in roughness]
    out_dir = Path(out_dir) if out_dir is not None else Path(tempfile.mkdtemp(prefix="rtl-energy-"))
    out_dir.mkdir(parents=True, exist_ok=True)
    exr_dir = out_dir if keep_exr else Path(tempfile.mkdtemp(prefix="rtl-energy-exr-"))

    t0 = time.perf_counter()
    tables, lut_used = energy_tables(lut_dir)
    t_luts = time.perf_counter() - t0
    t0 = time.perf_counter()
    exact_e = ExactE(roughness) if exact else None
    t_exact = time.perf_counter() - t0

    t0 = time.perf_counter()
    scene, glossies = build_scene(roughness, resolution, segments, rings)
    t_build = time.perf_counter() - t0

    renders, timings = {}, {}
    for dist in ("GGX", "MULTI_GGX"):
        for g in glossies:
            g.distribution = dist
        pair = []
        for seed in seeds[:2]:
            configure_render(scene, samples, seed, threads)
            path = exr_dir / f"energy_{dist.lower()}_seed{seed}.exr"
            timings[f"{dist}_seed{seed}"] = scene_render.render_exr(scene, path)
            log(f"[validate_energy] rendered {path.name} in {timings[f'{dist}_seed{seed}']:.1f} s")
            pair.append(scene_render.read_passes(path))
            if not keep_exr:
                path.unlink()
        renders[dist] = pair
    if not keep_exr:
        exr_dir.rmdir()

    t0 = time.perf_counter()
    results = analyse(renders, roughness, tables, exact_e)
    t_analyse = time.perf_counter() - t0
    import bpy

    results["settings"] = {
        "blender": bpy.app.version_string, "resolution_per_sphere": resolution,
        "image": [scene.render.resolution_x, scene.render.resolution_y], "samples": samples,
        "seeds": list(seeds[:2]), "threads": threads, "roughness": roughness,
        "sphere_segments": [segments, rings], "normals": "smooth, custom radial vertex normals",
        "camera": "orthographic, looking down -Z (V = +Z)", "world": "Background white, strength 1",
        "world_sampling": scene.world.cycles.sampling_method,
        "filter": [scene.cycles.pixel_filter_type, scene.cycles.filter_width],
        "blur_glossy": scene.cycles.blur_glossy,
        "clamp": [scene.cycles.sample_clamp_direct, scene.cycles.sample_clamp_indirect],
        "bounces": {"max": scene.cycles.max_bounces, "glossy": scene.cycles.glossy_bounces},
        "view_transform": scene.view_settings.view_transform, "lut_dir": lut_used,
        "z_max": Z_MAX, "sys_tol": SYS_TOL, "abs_bias_target": ABS_BIAS_TARGET,
        "ms_tol": MS_TOL, "mu_edges": list(MU_EDGES), "mu_judged_min": MU_JUDGED,
    }
    results["timings_s"] = {"luts": t_luts, "exact_reference": t_exact, "build_scene": t_build,
                            "renders": timings, "analyse": t_analyse,
                            "total": time.perf_counter() - t_start}
    (out_dir / "energy_validation.json").write_text(json.dumps(results, indent=2, default=outputs.json_default))
    log(format_table(results))
    return results


def format_table(res):
    lines = []
    for r, e in res["GGX"].items():
        lines.append(f"GGX r={r}: pixels {e['pixels']}, mean(pixel - E_lut) = {e['mean_bias']:+.2e} "
                     f"(se {e['se']:.1e}, z {e['z']:+.1f})"
                     + (f", vs exact {e['mean_bias_vs_exact']:+.2e}" if "mean_bias_vs_exact" in e else "")
                     + f"  {'ok' if e['ok'] else 'FAIL'}")
        lines.append("   mu bin        n    bias        se       z     vs_exact  lut-exact")
        for b in e["bins"]:
            if not b["n"]:
                continue
            lines.append(f"   [{b['mu_lo']:.1f},{b['mu_hi']:.1f}) {b['n']:7d} {b['bias']:+.2e} {b['se']:.2e} "
                         f"{b['z']:+6.2f}  {b.get('bias_vs_exact', float('nan')):+.2e} "
                         f"{b.get('lut_minus_exact', float('nan')):+.2e}"
                         + ("" if b["judged"] else "  (not judged)")
                         + ("" if b.get("ok_noise_only", True) else "  >z_max")
                         + ("" if b.get("ok", True) else "  FAIL"))
    for r, e in res["MULTI_GGX"].items():
        lines.append(f"MULTI_GGX r={r}: mean {e['mean']:.5f} (se {e['se']:.1e})  {'ok' if e['ok'] else 'FAIL'}")
        lines.append("   " + " ".join(f"{b['mean']:.4f}" if b["n"] else "  -   " for b in e["bins"]))
    for r, c in res.get("normal_check", {}).items():
        lines.append(f"normal pass vs analytic sphere r={r}: angle mean {c['angle_deg_mean']:.4f} deg, "
                     f"max {c['angle_deg_max']:.3f} deg; mu diff mean {c['mu_pass_minus_analytic_mean']:+.1e}")
    lines.append(f"PASSED: {res['passed']}")
    return "\n".join(lines)


def parse_args(argv):
    """The options of scripts/validate_energy.py parsed from ``argv`` (the arguments after Blender's
    ``--`` when run inside Blender: the script strips them)."""
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--resolution", type=int, default=256, help="pixels per sphere cell (default 256)")
    p.add_argument("--samples", type=int, default=256)
    p.add_argument("--roughness", type=float, nargs="+", default=[0.25, 0.5, 0.75, 1.0])
    p.add_argument("--out", default="energy_validation_out")
    p.add_argument("--lut-dir", default=None)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--segments", type=int, default=256)
    p.add_argument("--rings", type=int, default=128)
    p.add_argument("--no-exact", action="store_true", help="skip the dense directional_albedo reference")
    return p.parse_args(argv)


def run(args, progress=print):
    """The entry signature (validation/harness/entry.py): ``measure`` with the options of ``parse_args``; its
    results (``"passed"``)."""
    return measure(args.resolution, args.samples, args.roughness, args.out, args.lut_dir, threads=args.threads,
                   segments=args.segments, rings=args.rings, exact=not args.no_exact, log=progress)


def to_markdown(result):
    """``format_table`` as a Markdown code block (the main job's report)."""
    return "```\n" + format_table(result) + "\n```"
