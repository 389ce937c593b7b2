"""Which rough diffuse does Cycles render?  A white-furnace render of Diffuse BSDF / Principled spheres.

The scene of ``energy_render`` (a row of spheres under a uniform white world, orthographic camera looking
down -Z, spheres invisible to secondary rays), each sphere with its own material: the Diffuse BSDF with
Roughness sigma and Color rho, or the Principled BSDF with Diffuse Roughness sigma, Base Color rho and its
specular switched off (Specular IOR Level 0: F0 = 0 at every angle).  Each pixel is then the lobe's directional
albedo at mu = N.V (mu from the Normal pass), and the bin means are compared with the candidate models
(core/rough_diffuse.py):

* ``lambert``       rho
* ``fon``           rho E_F(mu)                                    Fujii's improved Oren-Nayar alone (loses energy)
* ``eon``           rho E_F + rho_ms (1 - E_F)                     EON / OpenPBR (energy-preserving)
* ``cycles``        rho E_F + rho rho_ms (1 - E_F)                 EON's lobe, scaled by the closure weight rho

With rho = 1 the energy-preserving models give exactly 1 (the white furnace) and FON gives E_F < 1; with
rho < 1 the last two differ by the factor rho on the multiple scattering.  Two seeds give each bin's standard
error ((a - b)^2 / 4 per pixel, as ``energy_render``).

    python scripts/validate_rough_diffuse.py [--resolution N] [--samples S] [--out DIR]
"""
from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

import numpy as np

from ...core import rough_diffuse
from ..harness import outputs, scene_render
from . import energy_render

#: (label, node, rho, sigma): the spheres, left to right.
DEFAULT_CASES = (
    ("diffuse rho=1 sigma=1", "diffuse", 1.0, 1.0),
    ("diffuse rho=0.5 sigma=1", "diffuse", 0.5, 1.0),
    ("principled rho=0.5 sigma=1", "principled", 0.5, 1.0),
    ("diffuse rho=0.5 sigma=0.5", "diffuse", 0.5, 0.5),
    ("principled rho=0.8 sigma=0.7", "principled", 0.8, 0.7),
)
MU_EDGES = (0.1, 0.3, 0.5, 0.7, 0.9, 1.0)
MODELS = ("lambert", "fon", "eon", "cycles")


def model_albedo(model, rho, mu, sigma):
    """The directional albedo of a candidate model (one channel)."""
    if model == "lambert":
        return np.full(np.shape(mu), rho)
    if model == "fon":
        return rho * rough_diffuse.fon_albedo(mu, sigma)
    if model == "eon":
        return rough_diffuse.eon_directional_albedo(rho, mu, sigma)
    if model == "cycles":
        return rough_diffuse.directional_albedo(rho, mu, sigma)
    raise ValueError(f"unknown model {model!r}")


def _set_material(bpy, material, node, rho, sigma):
    nt = material.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    out.target = "ALL"
    if node == "diffuse":
        bsdf = nt.nodes.new("ShaderNodeBsdfDiffuse")
        bsdf.inputs["Color"].default_value = (rho, rho, rho, 1.0)
        bsdf.inputs["Roughness"].default_value = sigma
    else:
        bsdf = nt.nodes.new("ShaderNodeBsdfPrincipled")
        bsdf.inputs["Base Color"].default_value = (rho, rho, rho, 1.0)
        bsdf.inputs["Diffuse Roughness"].default_value = sigma
        bsdf.inputs["Specular IOR Level"].default_value = 0.0
        bsdf.inputs["Metallic"].default_value = 0.0
    nt.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])


def build_scene(cases, resolution):
    """``energy_render``'s spheres and world, each sphere's material replaced by its case's BSDF."""
    import bpy

    scene, _ = energy_render.build_scene([1.0] * len(cases), resolution, segments=128, rings=64)
    for i, (_, node, rho, sigma) in enumerate(cases):
        _set_material(bpy, bpy.data.objects[f"RTL_sphere_{i}"].material_slots[0].material, node, rho, sigma)
    return scene


def analyse(renders, cases, mu_edges=MU_EDGES):
    """Per case and mu bin: the rendered mean, its standard error, and each model's mean over the same pixels;
    per case the models with the smallest chi^2 over the bins (several where they coincide: rho = 1)."""
    (ca, na), (cb, nb) = renders
    h, w = ca.shape[:2]
    sphere, _ = energy_render.pixel_geometry(w, h, len(cases))
    nrm = 0.5 * (na + nb)
    length = np.linalg.norm(nrm, axis=-1)
    out = []
    for i, (label, node, rho, sigma) in enumerate(cases):
        sel = (sphere == i) & (length > 0.5)
        mu = np.clip((nrm[sel] / length[sel, None]) @ energy_render.VIEW, 0.0, 1.0)
        a, b = ca[sel].mean(axis=-1), cb[sel].mean(axis=-1)
        m = 0.5 * (a + b)
        bins, chi2 = [], {k: 0.0 for k in MODELS}
        for lo, hi in zip(mu_edges[:-1], mu_edges[1:]):
            s = (mu >= lo) & ((mu < hi) if hi < 1.0 else (mu <= hi))
            n = int(s.sum())
            if n == 0:
                continue
            se = float(np.sqrt(np.sum((a - b)[s] ** 2) / 4.0) / n)
            row = {"mu_lo": lo, "mu_hi": hi, "n": n, "rendered": float(m[s].mean()), "se": se}
            for k in MODELS:
                row[k] = float(np.mean(model_albedo(k, rho, mu[s], sigma)))
                chi2[k] += ((row["rendered"] - row[k]) / max(se, 1e-12)) ** 2
            bins.append(row)
        out.append({"case": label, "node": node, "rho": rho, "sigma": sigma, "pixels": int(sel.sum()),
                    "bins": bins, "chi2": chi2,
                    "best": [k for k in MODELS if chi2[k] <= min(chi2.values()) * (1 + 1e-9)]})
    return out


def measure(cases=DEFAULT_CASES, resolution=96, samples=64, seeds=(0, 1), threads=2, out_dir=None, log=print):
    """Render the furnace pair and analyse it; returns a JSON-serialisable dict (also written to out_dir)."""
    import bpy

    t0 = time.perf_counter()
    out_dir = Path(out_dir) if out_dir is not None else Path(tempfile.mkdtemp(prefix="rtl-rough-diffuse-"))
    out_dir.mkdir(parents=True, exist_ok=True)
    scene = build_scene(cases, resolution)
    renders = []
    for seed in seeds[:2]:
        energy_render.configure_render(scene, samples, seed, threads)
        scene.cycles.diffuse_bounces = 1          # the world is reached by one diffuse bounce (MIS with its light)
        path = out_dir / f"rough_diffuse_furnace_seed{seed}.exr"
        scene_render.render_exr(scene, path)
        renders.append(scene_render.read_passes(path))
    res = {"blender": bpy.app.version_string, "resolution_per_sphere": resolution, "samples": samples,
           "seeds": list(seeds[:2]), "cases": analyse(renders, cases), "seconds": time.perf_counter() - t0}
    (out_dir / "rough_diffuse_furnace.json").write_text(json.dumps(res, indent=2, default=outputs.json_default))
    log(format_table(res))
    return res


def format_table(res):
    lines = [f"Blender {res['blender']}: white furnace, {res['samples']} spp x 2 seeds, "
             f"{res['resolution_per_sphere']} px per sphere", "",
             "| case | mu bin | rendered +- se | lambert | fon | eon | cycles (rho x rho_ms) |", "|---|---|---|---|---|---|---|"]
    for c in res["cases"]:
        for row in c["bins"]:
            lines.append(f"| {c['case']} | {row['mu_lo']:.1f}-{row['mu_hi']:.1f} | {row['rendered']:.4f} +- "
                         f"{row['se']:.4f} | " + " | ".join(f"{row[k]:.4f}" for k in MODELS) + " |")
    lines += ["", "| case | chi^2 lambert | fon | eon | cycles | best |", "|---|---|---|---|---|---|"]
    for c in res["cases"]:
        lines.append(f"| {c['case']} | " + " | ".join(f"{c['chi2'][k]:.3g}" for k in MODELS) + f" | {', '.join(c['best'])} |")
    return "\n".join(lines)


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--resolution", type=int, default=96, help="pixels per sphere (image height)")
    p.add_argument("--samples", type=int, default=64)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--out", type=Path, default=None)
    return p.parse_args(argv)


def run(args, progress=print):
    """The entry signature (validation/harness/entry.py): ``measure`` with the options of ``parse_args``; passed
    when the best model of every case includes Cycles' own."""
    result = measure(resolution=args.resolution, samples=args.samples, threads=args.threads, out_dir=args.out,
                     log=progress)
    result["passed"] = all("cycles" in c["best"] for c in result["cases"])
    return result


def to_markdown(result):
    """The chi^2 table of ``format_table``."""
    return format_table(result)
