"""The multiscattering wrapped diffuse (issue 17, item 3), measured against brute force in numpy.

    python scripts/benchmark_wrapped_diffuse.py [--out docs/benchmarks] [--lights 120] [--quick]

The lobe (core/diffuse.py ``cod_wrapped_diffuse_cosine``): the CoD WWII diffuse evaluated at the wrapped light
direction, f_CoD(l_w, v) mu_w / (1 + w).  Three measurements:
- **punctual**: its directional albedo against the CoD lobe's (the wrap keeps it; sphere quadrature);
- **area**: over seeded random quads and disks (centres from w below the horizon to the zenith, 1.5-4 m, 0.3-2 m
  wide, views up to 80 deg), the shipped form (the CoD LTC over the light's image under the wrap,
  core/ltc/shading.py ``cod_wrapped_diffuse``) and the talk's construction (the CoD LTC about the normal tilted
  towards the light, ``cod_wrapped_diffuse_tilted``), each against the integral of the lobe over the light
  (core/ltc/reference.py, Gauss-Legendre panels, converged);
- **SH**: the wrapped lobe about the CoD SH-LTC axis (core/indirect.py ``sh_cod_wrapped_diffuse``, the World term)
  and about N (the "magnitude only" baseline), against the lobe integrated under the same L2 SH environment
  (``cod_wrapped_diffuse_reference``): a sky with a sun, and a white sky (the furnace).
Writes ``wrapped_diffuse.md`` and ``.json`` in ``--out``.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from ..harness import entry, outputs
from ...core import diffuse
from ...core import indirect
from ...core.conventions import alpha_from_roughness
from ...core.ltc import reference, shading
from ...core.lut import lookup
from ...core.lut.catalog import default_lut_dir

WRAPS = (0.0, 0.5, 1.0)
ROUGHNESS = (0.3, 0.8)


def _unit(x):
    return x / np.linalg.norm(x, axis=-1, keepdims=True)


def random_light(rng, kind, wrap):
    """(light for core.ltc.shading, the brute-force geometry, size, distance): one seeded light seen from the origin
    (normal +Z), its centre from -wrap (sine of the elevation) to the zenith, facing the origin."""
    el = np.arcsin(rng.uniform(-0.9 * wrap, 1.0) if wrap > 0 else rng.uniform(0.05, 1.0))
    az, dist, size = rng.uniform(0, 2 * np.pi), rng.uniform(1.5, 4.0), rng.uniform(0.3, 2.0)
    c = dist * np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
    axis = -c / dist
    u = _unit(np.cross(axis, [0.0, 0.0, 1.0] if abs(axis[2]) < 0.9 else [1.0, 0.0, 0.0])) * size / 2
    v = np.cross(axis, u)
    if kind == "quad":     # corners clockwise seen from the lit side (core/ltc/shading.py QuadLight)
        corners = np.array([c - u - v, c + u - v, c + u + v, c - u + v])
        if np.cross(corners[1] - corners[0], corners[3] - corners[0]) @ c < 0:
            corners = corners[::-1]
        return shading.QuadLight(list(corners), center_point=c), ("quad", corners), size, dist
    if np.cross(u, v) @ c < 0:
        v = -v
    return shading.DiskLight(c, u, v), ("disk", (c, u, v)), size, dist


def area_row(tables, kind, wrap, roughness, lights, seed):
    """Relative errors of the shipped area form and the talk's against the lobe's integral over ``lights`` lights."""
    rng = np.random.default_rng(seed)
    n, p = np.array([0.0, 0.0, 1.0]), np.zeros(3)
    alpha = alpha_from_roughness(roughness)
    image, tilted = [], []
    for _ in range(lights):
        light, (shape, geometry), size, dist = random_light(rng, kind, wrap)
        theta, phi = rng.uniform(0.0, 1.4), rng.uniform(0.0, 2 * np.pi)
        view = np.array([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)])

        def f_cos(l):
            return diffuse.cod_wrapped_diffuse_cosine(1.0, np.broadcast_to(n, l.shape), np.broadcast_to(view, l.shape),
                                                      l, alpha, wrap)

        if shape == "quad":
            truth = reference.integrate_polygon(f_cos, geometry, None, False, 16, 8).value
        else:
            truth = reference.integrate_disk(f_cos, *geometry, None, False, 16, 8).value
        if truth <= 1e-3 * size * size / dist ** 2:      # lights the lobe barely sees: relative error meaningless
            continue
        image.append(abs(float(shading.cod_wrapped_diffuse(tables, light, p, n, view, roughness, 1.0, wrap)) / truth - 1))
        tilted.append(abs(float(shading.cod_wrapped_diffuse_tilted(tables, light, p, n, view, roughness, 1.0, wrap))
                          / truth - 1))
    return {"kind": kind, "wrap": wrap, "roughness": roughness, "lights": len(image),
            "image": _stats(image), "tilted": _stats(tilted)}


def _stats(errors):
    e = np.asarray(errors, np.float64)
    return {"median": float(np.median(e)), "p90": float(np.percentile(e, 90)), "mean": float(e.mean())}


def _sky(d):
    sun = _unit(np.array([0.3, 0.2, 0.93]))
    return (np.exp(8 * (d @ sun - 1))[:, None] * np.array([6.0, 5.0, 4.0])
            + (0.4 + 0.3 * np.clip(d[:, 2], 0, 1))[:, None] * np.array([0.5, 0.7, 1.0]))


def sh_rows(tables, points, seed):
    """Mean / median relative error of the SH forms against the lobe under the same SH environment."""
    rng = np.random.default_rng(seed)
    n, v = _unit(rng.normal(size=(points, 3))), _unit(rng.normal(size=(points, 3)))
    v = np.where((np.sum(n * v, -1) < 0.05)[:, None], -v, v)
    keep = np.sum(n * v, -1) > 0.05
    n, v = n[keep], v[keep]
    rows = []
    for name, env in (("sky with a sun", _sky), ("white (furnace)", lambda d: np.ones((len(d), 3)))):
        coeffs = indirect.sh_project(env)
        cl = indirect.coefficient_list(coeffs)
        for wrap in WRAPS:
            for r in ROUGHNESS:
                rr = np.full(len(n), r)
                ref = indirect.cod_wrapped_diffuse_reference(coeffs, n, v, rr, wrap)
                ltc = indirect.sh_cod_wrapped_diffuse(tables, cl, n, v, rr, np.ones(3), wrap)
                mag = indirect.sh_cod_wrapped_diffuse_magnitude_only(tables, cl, n, v, rr, np.ones(3), wrap)
                rows.append({"environment": name, "wrap": wrap, "roughness": r, "points": int(len(n)),
                             "sh_ltc": _stats(np.abs(ltc / ref - 1).ravel()),
                             "magnitude_only": _stats(np.abs(mag / ref - 1).ravel())})
    return rows


def albedo_rows(views=6):
    """The punctual lobe's directional albedo at w = 0.5 and 1 against w = 0 (the CoD lobe's)."""
    rng = np.random.default_rng(1)
    n = np.tile([0.0, 0.0, 1.0], (views, 1))
    v = _unit(np.concatenate([rng.normal(size=(views, 2)), rng.uniform(0.1, 1.0, (views, 1))], -1))
    dirs, wts = indirect.sphere_quadrature(192, 384)
    rows = []
    for r in ROUGHNESS:
        alpha = alpha_from_roughness(r)
        alb = {w: diffuse.cod_wrapped_diffuse_cosine(1.0, n[:, None], v[:, None], dirs[None], alpha, w) @ wts
               for w in WRAPS}
        rows.append({"roughness": r, "albedo_w0": [float(x) for x in alb[0.0]],
                     "max_rel_change": {f"{w:g}": float(np.max(np.abs(alb[w] / alb[0.0] - 1))) for w in WRAPS[1:]}})
    return rows


def to_markdown(result):
    """The result as Markdown (wrapped_diffuse.md)."""
    L = ["# Multiscattering wrapped diffuse: measured", "",
         "`python scripts/benchmark_wrapped_diffuse.py` (validation/benchmarks/wrapped_diffuse_benchmark.py; numpy, "
         f"{result['seconds']:.0f} s on this machine). The lobe, f_CoD(l_w, v) mu_w / (1 + w) with l_w the wrapped "
         "light direction, is defined in core/diffuse.py; docs/multiscattering.md says why.", "",
         "## Punctual: the directional albedo is the CoD lobe's", "",
         "| r | CoD albedo at the 6 views | max relative change, w = 0.5 / 1 |", "|---|---|---|"]
    for row in result["albedo"]:
        ch = row["max_rel_change"]
        L.append(f"| {row['roughness']:g} | {min(row['albedo_w0']):.3f}-{max(row['albedo_w0']):.3f} | "
                 f"{ch['0.5']:.1e} / {ch['1']:.1e} |")
    L += ["", f"## Area lights: {result['lights']} seeded lights per row against the lobe's integral", "",
          "Relative error, median / p90. 'Image': the CoD LTC over the light's image under the wrap (shipped); "
          "'tilted': the talk's CoD LTC about the normal tilted towards the light's centre, / (1 + w).", "",
          "| light | w | r | lights | image: median / p90 | talk's tilted normal: median / p90 |",
          "|---|---|---|---|---|---|"]
    for row in result["area"]:
        i, t = row["image"], row["tilted"]
        L.append(f"| {row['kind']} | {row['wrap']:g} | {row['roughness']:g} | {row['lights']} | "
                 f"{i['median']:.2%} / {i['p90']:.2%} | {t['median']:.2%} / {t['p90']:.2%} |")
    L += ["", "## World (L2 SH): against the lobe under the same SH environment", "",
          "Relative error, mean / median, over seeded normals and views (N.V > 0.05).", "",
          "| environment | w | r | wrapped lobe about the CoD SH-LTC axis (shipped) | about N (magnitude only) |",
          "|---|---|---|---|---|"]
    for row in result["sh"]:
        a, b = row["sh_ltc"], row["magnitude_only"]
        L.append(f"| {row['environment']} | {row['wrap']:g} | {row['roughness']:g} | {a['mean']:.2%} / "
                 f"{a['median']:.2%} | {b['mean']:.2%} / {b['median']:.2%} |")
    return "\n".join(L) + "\n"


def run(args, progress=entry.flush_log):
    """Measure the three parts with ``args``' options; writes wrapped_diffuse.md and .json in ``args.out``."""
    t0 = time.perf_counter()
    tables = lookup.LutSet.from_folder(args.lut_dir or default_lut_dir())
    lights = min(args.lights, 12) if args.quick else args.lights
    area = [area_row(tables, kind, w, r, lights, seed=100 * i + j)
            for i, kind in enumerate(("quad", "disk")) for j, (w, r) in
            enumerate([(w, r) for w in (WRAPS[-1:] if args.quick else WRAPS) for r in ROUGHNESS])]
    result = {"lights": lights, "quick": args.quick, "area": area,
              "sh": sh_rows(tables, 60 if args.quick else 300, seed=1), "albedo": albedo_rows(2 if args.quick else 6)}
    result["seconds"] = time.perf_counter() - t0
    md = to_markdown(result)
    outputs.write_results(args.out, "wrapped_diffuse", result, md)
    progress(md)
    return result


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--out", default="docs/benchmarks", help="folder for wrapped_diffuse.md / .json")
    p.add_argument("--lights", type=int, default=120, help="seeded lights per area row")
    p.add_argument("--quick", action="store_true", help="w = 1 only, 12 lights per row, fewer SH points")
    p.add_argument("--lut-dir", default=None)
    return p.parse_args(argv)
