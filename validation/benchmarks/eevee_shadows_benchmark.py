"""RT Lit shadows in EEVEE (its Shadow pass) against RT Lit shadows in Cycles (the ratio estimator), issue 29.

    python scripts/benchmark_eevee_shadows.py [--out docs/benchmarks] [--quick]

On each scene of ``shadow_studies.EEVEE_STUDY_SCENES`` (the floor study, the concave scene), ``Features()``, the
studio lights and world: EEVEE F12 with shadows against Cycles F12 with shadows (the lights' ratio estimator,
``world=False``, since EEVEE does not shadow the World term), and the same without shadows for reference; the
per-pixel relative error (the validation's metric), median / p90, over every RT Lit object and per region, and each
render's seconds (one run).  Writes ``eevee_shadows.md`` and ``.json`` in ``--out``.
"""
from __future__ import annotations

import platform
from pathlib import Path

from ..checks import shadow_studies
from ..harness import entry, outputs

REPO = Path(__file__).resolve().parents[2]

#: (resolution, EEVEE samples, scenes) of the full run and of ``--quick``.
FULL = ((160, 100), 16, shadow_studies.EEVEE_STUDY_SCENES)
QUICK = ((48, 30), 2, ("floor",))


def run(args, progress=entry.flush_log):
    """Measure every scene; writes the report where ``args.out`` says."""
    resolution, samples, scenes = QUICK if args.quick else FULL
    result = {"machine": platform.processor() or platform.machine(), "resolution": list(resolution),
              "eevee_samples": samples, "quick": args.quick, "scenes": []}
    for kind in scenes:
        study = shadow_studies.eevee_shadow_study(args.lut_dir, resolution, samples, log=progress, scene_kind=kind)
        study.pop("images")
        result["scenes"].append(study)
    outputs.write_results(args.out, "eevee_shadows", result, to_markdown(result))
    return result


def to_markdown(result):
    lines = ["# RT Lit shadows: EEVEE against Cycles", "",
             "Written by `python scripts/benchmark_eevee_shadows.py` (validation/benchmarks/eevee_shadows_benchmark.py;"
             " docs/shadows.md, \"Light shadows in EEVEE renders\").  EEVEE with RT Lit shadows (EEVEE's Shadow pass, one "
             "ratio for all lights) against Cycles with RT Lit shadows (the ratio estimator per light, 4 spp, OIDN, the "
             "world unshadowed as in EEVEE), and the two engines without shadows for reference: the per-pixel "
             f"relative error, median / p90, at {result['resolution'][0]} x {result['resolution'][1]}, EEVEE at "
             f"{result['eevee_samples']} samples (llvmpipe), `Features()`, the studio lights and world.", ""]
    for study in result["scenes"]:
        seconds = study["seconds"]
        lines += [f"## The {study['scene']} scene", "", "| region | with shadows | without shadows |", "|---|---|---|"]
        lines += [f"| {region} | {outputs.median_p90(cases['shadows'], 2)} | "
                  f"{outputs.median_p90(cases['no_shadows'], 2)} |" for region, cases in study["regions"].items()]
        change = outputs.median_p90(study["cycles_shadows_vs_cycles"], 2)
        lines += ["", f"The shadows change Cycles' render by {change} (all RT Lit "
                  "pixels: the size of what is compared).  F12 seconds, one run each on a shared machine: "
                  + ", ".join(f"{k} {v:.1f}" for k, v in seconds.items()) + ".", ""]
    return "\n".join(lines)


def parse_args(argv):
    p = entry.benchmark_parser(__doc__, REPO / "docs" / "benchmarks", "the floor study only, 48 x 30, 2 EEVEE samples (smoke run)")
    return p.parse_args(argv)
