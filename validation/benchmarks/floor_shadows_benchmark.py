"""World occlusion and light shadows on the floor study (issue 29), against the path-traced twin.

    python scripts/benchmark_floor_shadows.py [--out docs/benchmarks] [--quick]

The lookdev scene with its floor (``lookdev_twin.shadow_study``): lit by the world alone (the studio lights
removed) once per occlusion model (``Features.occlusion``); then with the studio lights, unshadowed and with the
lights' shadows of the ratio estimator (addon/shadows.py) at a few probe settings.  Per row: the floor's
per-pixel error against the twin (the validation's metric, median / p90), the same over the floor pixels path
tracing darkens by more than 5%, and the RT Lit render's time (one run).  World-occlusion rows also give the
visibility RT Lit applies (its occluded floor over its unoccluded one) against the twin's (shadowed over
unshadowed), per pixel: how well ambient occlusion stands for the world's real visibility, apart from the World
term's own error.  Writes ``floor_shadows.md`` and ``.json`` in ``--out``.
"""
from __future__ import annotations

import platform
from pathlib import Path

import numpy as np

from ...core.materials.rt_lit_interface import OCCLUSION_MODELS, Features
from ..checks import lookdev_twin
from ..harness import entry, outputs

REPO = Path(__file__).resolve().parents[2]

#: The rows: (section, occlusion model, ``shadows.enable_shadows`` options or None).  "world": True shadows the World
#: term by its ratio too (the Cycles trees then leave the occlusion model out: addon/shadows.py).
LIGHTS_ONLY = {"samples": 4, "denoise": True, "world": False}
WORLD_ROWS = tuple(("world", model, None) for model in OCCLUSION_MODELS) + (
    ("world", "none", {"samples": 4, "denoise": True, "world": True}),
    ("world", "none", {"samples": 16, "denoise": True, "world": True}))
LIGHT_ROWS = (("lights", "none", None), ("lights", "cones_clipped", None),
              ("lights", "cones_clipped", LIGHTS_ONLY),
              ("lights", "none", {"samples": 4, "denoise": True, "world": True}),
              ("lights", "none", {"samples": 16, "denoise": True, "world": True}))
QUICK_ROWS = (("world", "none", None), ("world", "none", {"samples": 4, "denoise": True, "world": True}),
              ("lights", "none", None), ("lights", "cones_clipped", LIGHTS_ONLY))


def _stats(values):
    values = np.asarray(values, np.float64)
    return {"median": float(np.median(values)), "p90": float(np.percentile(values, 90))}


def _visibility(study, unoccluded):
    """|RT Lit's visibility / the twin's - 1| per floor pixel (the mean over RGB of each image first)."""
    mask = study["floor_mask"]
    images, plain = study["images"], unoccluded["images"]
    rt = images["rt_lit"][mask].mean(-1) / np.maximum(plain["rt_lit"][mask].mean(-1), 1e-9)
    true = images["path_traced"][mask].mean(-1) / np.maximum(images["path_traced_no_shadows"][mask].mean(-1), 1e-9)
    return dict(_stats(np.abs(rt / np.maximum(true, 1e-9) - 1.0)), rt_mean=float(rt.mean()), twin_mean=float(true.mean()))


def row_label(model, light_shadows, section="lights"):
    if light_shadows is None:
        shadows = "none"
    else:
        world = light_shadows.get("world", True)
        what = ("world" if section == "world" else "lights + world") if world else "lights"
        shadows = f"{what}, {light_shadows['samples']} spp{', OIDN' if light_shadows['denoise'] else ''}"
    return f"{model} | {shadows}"


def run(args, progress=entry.flush_log):
    """Measure every row on the floor study; writes the report where ``args.out`` says."""
    resolution, samples = ((96, 60), 8) if args.quick else ((320, 200), 64)
    rows = QUICK_ROWS if args.quick else WORLD_ROWS + LIGHT_ROWS
    result = {"machine": platform.processor() or platform.machine(), "resolution": list(resolution),
              "samples": samples, "quick": args.quick, "rows": []}
    plain = {}
    for section, model, light_shadows in rows:
        study = lookdev_twin.shadow_study(args.lut_dir, resolution, samples, progress, Features(occlusion=model),
                                          lights=section == "lights", light_shadows=light_shadows)
        floor, dark = study["floor_with_shadows"], study["floor_darkened"]
        row = {"section": section, "occlusion": model, "light_shadows": light_shadows,
               "median": floor["median"], "p90": floor["p90"], "noise_median": floor["noise_median"],
               "darkened_median": dark["median"], "darkened_p90": dark["p90"],
               "floor_unshadowed_twin_median": study["floor_without_shadows"]["median"],
               "rt_lit_seconds": study["seconds"]["rt_lit_cycles"], "rt_lit_samples": study["rt_lit_samples"],
               "spheres": study["spheres"]}
        if model == "none" and light_shadows is None:
            plain[section] = study
        elif light_shadows is None and section in plain:
            row["visibility"] = _visibility(study, plain[section])
        result["rows"].append(row)
        progress(f"[floor shadows] {section}, {row_label(model, light_shadows, section)}: floor median {row['median']:.1%}, "
                 f"p90 {row['p90']:.1%}; darkened pixels median {row['darkened_median']:.1%}; spheres median "
                 f"{row['spheres']['all']['median']:.1%}, glossy {row['spheres']['glossy']['median']:.1%}")
    outputs.write_results(args.out, "floor_shadows", result, to_markdown(result))
    return result


def to_markdown(result):
    lines = ["# World occlusion and light shadows on the floor study", "",
             "Written by `python scripts/benchmark_floor_shadows.py` (validation/benchmarks/floor_shadows_benchmark.py;"
             " docs/shadows.md).  The lookdev scene with its floor against its path-traced twin "
             f"({result['resolution'][0]} x {result['resolution'][1]}, the twin at {result['samples']} spp x 2 seeds, "
             "0 bounces): the floor's per-pixel relative error, median / p90, over all its pixels and over those path "
             "tracing darkens by more than 5%; the spheres' over all their pixels and over the glossy ones (roughness "
             "<= 0.25).  Shadows: the ratio estimator's probe layers (samples, denoiser) on the lights, or on the lights "
             "and the World term (addon/shadows.py); none: unshadowed.  Visibility (world occlusion without light shadows): RT Lit's occluded floor "
             "over its unoccluded one against the twin's shadowed floor over its unshadowed one, |ratio - 1| per "
             "pixel, and the two means over the floor.", ""]
    for section, title in (("world", "The world alone (the studio lights removed)"),
                           ("lights", "The world and the studio lights")):
        lines += [f"## {title}", "", "| World Occlusion | shadows | floor | darkened pixels | spheres | glossy spheres |"
                  " visibility error | mean visibility, RT Lit / twin | RT Lit render |",
                  "|---|---|---|---|---|---|---|---|---|"]
        for row in (r for r in result["rows"] if r["section"] == section):
            vis = row.get("visibility")
            vis_cells = (f"{vis['median']:.1%} / {vis['p90']:.1%} | {vis['rt_mean']:.2f} / {vis['twin_mean']:.2f}"
                         if vis else "- | -")
            lines.append(f"| {row_label(row['occlusion'], row['light_shadows'], row['section'])} | {row['median']:.1%} / "
                         f"{row['p90']:.1%} | {row['darkened_median']:.1%} / {row['darkened_p90']:.1%} | "
                         f"{outputs.median_p90(row['spheres']['all'])} | "
                         f"{outputs.median_p90(row['spheres']['glossy'])} | {vis_cells} | "
                         f"{row['rt_lit_seconds']:.1f} s ({row['rt_lit_samples']} spp) |")
        unshadowed = next((r["floor_unshadowed_twin_median"] for r in result["rows"]
                           if r["section"] == section and r["occlusion"] == "none" and r["light_shadows"] is None), None)
        if unshadowed is not None:
            lines += ["", f"Unshadowed RT Lit against the twin without the spheres' shadows (the residual the shadows "
                      f"cannot remove): {unshadowed:.1%} median."]
        lines.append("")
    lines += _per_sphere(result["rows"])
    lines += ["The twin's own noise (median of its two seeds' half-difference) is "
              f"{result['rows'][0]['noise_median']:.1%} on the floor.  The render times are one run each, as the study "
              "ran them (not a speed measurement).", ""]
    return "\n".join(lines)


def _per_sphere(rows):
    """A table of each sphere's median error per row (the spheres' names without the scene's)."""
    names = list(rows[0]["spheres"]["per_sphere"]) if rows else []
    if not names:
        return []
    short = [" ".join(n.split()[-2:]) for n in names]
    lines = ["## Each sphere (median error against the twin)", "",
             "| section | World Occlusion | shadows | " + " | ".join(short) + " |",
             "|---|---|---|" + "---|" * len(names)]
    for row in rows:
        per = row["spheres"]["per_sphere"]
        lines.append(f"| {row['section']} | {row_label(row['occlusion'], row['light_shadows'], row['section'])} | "
                     + " | ".join(f"{per[n]:.1%}" if n in per else "-" for n in names) + " |")
    return lines + [""]


def parse_args(argv):
    p = entry.benchmark_parser(__doc__, REPO / "docs" / "benchmarks", "96 x 60, 8 spp, four rows (smoke run)")
    return p.parse_args(argv)
