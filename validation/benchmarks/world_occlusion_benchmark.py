"""World occlusion (``Features.occlusion``, issue 29 item 1) on the floor study, against the path-traced twin.

    python scripts/benchmark_world_occlusion.py [--out docs/benchmarks] [--quick]

The lookdev scene with its floor (``lookdev_twin.shadow_study``), lit by the world alone (the studio lights
removed) and then with them, once per occlusion model.  Per model: the floor's per-pixel error against the twin
(the validation's metric: median / p90), the RT Lit render's time, and the visibility RT Lit applies (its occluded
floor over its unoccluded one) against the twin's (shadowed over unshadowed), per pixel: how well ambient
occlusion stands for the world's real visibility, apart from the World term's own error.  Writes
``world_occlusion.md`` and ``.json`` in ``--out``.
"""
from __future__ import annotations

import argparse
import platform
from pathlib import Path

import numpy as np

from ...core.materials.rt_lit_interface import OCCLUSION_MODELS, Features
from ..checks import lookdev_twin
from ..harness import entry, outputs

REPO = Path(__file__).resolve().parents[2]


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


def _row(study):
    floor = study["floor_with_shadows"]
    return {"median": floor["median"], "p90": floor["p90"], "noise_median": floor["noise_median"],
            "rt_lit_seconds": study["seconds"]["rt_lit_cycles"], "rt_lit_samples": study["rt_lit_samples"]}


def run(args, progress=entry.flush_log):
    """Measure every occlusion model on the floor study; writes the report where ``args.out`` says."""
    resolution, samples = ((96, 60), 8) if args.quick else ((320, 200), 64)
    models = {False: ("none", "cones_clipped") if args.quick else OCCLUSION_MODELS,     # the world alone
              True: ("none", "cones_clipped") if args.quick else ("none", "cones_clipped", "lagarde")}
    result = {"machine": platform.processor() or platform.machine(), "resolution": list(resolution),
              "samples": samples, "quick": args.quick, "world": {}, "with_lights": {}}
    for lights in (False, True):
        studies = {}
        for model in models[lights]:
            study = lookdev_twin.shadow_study(args.lut_dir, resolution, samples, progress, Features(occlusion=model),
                                              lights=lights)
            studies[model] = study
            row = _row(study)
            if model != "none":
                row["visibility"] = _visibility(study, studies["none"])
            result["with_lights" if lights else "world"][model] = row
            progress(f"[world occlusion] {'lights and world' if lights else 'world alone'}, {model}: floor median "
                     f"{row['median']:.1%}, p90 {row['p90']:.1%}")
    outputs.write_results(args.out, "world_occlusion", result, to_markdown(result))
    return result


def to_markdown(result):
    lines = ["# World occlusion on the floor study", "",
             "Written by `python scripts/benchmark_world_occlusion.py` (validation/benchmarks/"
             "world_occlusion_benchmark.py; docs/shadows.md).  The lookdev scene with its floor against its path-"
             f"traced twin ({result['resolution'][0]} x {result['resolution'][1]}, the twin at {result['samples']} spp "
             "x 2 seeds, 0 bounces); the floor's per-pixel relative error, median / p90.  Visibility: RT Lit's "
             "occluded floor over its unoccluded one against the twin's shadowed floor over its unshadowed one, "
             "|ratio - 1| per pixel, and the two means over the floor.", ""]
    for key, title in (("world", "The world alone (the studio lights removed)"), ("with_lights", "World and lights")):
        lines += [f"## {title}", "", "| World Occlusion | floor vs twin | visibility error | mean visibility, RT Lit / "
                  "twin | RT Lit render |", "|---|---|---|---|---|"]
        for model, row in result[key].items():
            vis = row.get("visibility")
            vis_cells = (f"{vis['median']:.1%} / {vis['p90']:.1%} | {vis['rt_mean']:.2f} / {vis['twin_mean']:.2f}"
                         if vis else "- | -")
            lines.append(f"| {model} | {row['median']:.1%} / {row['p90']:.1%} | {vis_cells} | "
                         f"{row['rt_lit_seconds']:.1f} s ({row['rt_lit_samples']} spp) |")
        lines.append("")
    lines += ["The twin's own noise (median of its two seeds' half-difference) is "
              f"{next(iter(result['world'].values()))['noise_median']:.1%} on the floor.  The render times are one "
              "run each, as the study ran them (not a speed measurement: the time against error of shadows is the "
              "speed-vs-error benchmark's).", ""]
    return "\n".join(lines)


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--out", type=Path, default=REPO / "docs" / "benchmarks")
    p.add_argument("--lut-dir", type=Path, default=None, help="LUT folder (default: the extension's luts/)")
    p.add_argument("--quick", action="store_true", help="96 x 60, 8 spp, two models (smoke run)")
    return p.parse_args(argv)
