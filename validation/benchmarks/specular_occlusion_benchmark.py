"""Specular occlusion from ambient occlusion (issue 29, item 1), measured against the integral it stands for.

    python scripts/benchmark_specular_occlusion.py [--out docs/benchmarks] [--samples 16384] [--quick]

The model both estimates assume (core/occlusion.py): the directions a point sees form a cone about its normal whose
cosine-weighted share of the hemisphere is the ambient occlusion AO.  The reference is the share of the GGX
reflection of the view (F = 1, height-correlated Smith, Heitz 2018 VNDF samples on a Hammersley set) whose light
directions lie inside that cone.  The estimates: Lagarde & de Rousiers 2014 (a fit in N.V, AO and alpha); the
cone intersection of Jimenez et al. 2016 (GTSO) as engines ship it; and the same cones with the lobe cone first
clipped by the horizon (the intersection at AO over the intersection at AO = 1, so that AO = 1 occludes nothing),
a variant measured here.  A grid of N.V, roughness and AO; the error is the absolute error of the visible share.
Writes ``specular_occlusion.md`` and ``.json`` in ``--out``.
"""
from __future__ import annotations

import argparse
import platform
import time
from pathlib import Path

import numpy as np

from ...core import occlusion
from ..harness import entry, outputs

REPO = Path(__file__).resolve().parents[2]
#: The estimates measured: name -> function(N.V, N.R, AO, r).
ESTIMATES = {
    "lagarde": lambda mu, n_dot_r, ao, r: occlusion.specular_occlusion_lagarde(mu, ao, r),
    "cones": lambda mu, n_dot_r, ao, r: occlusion.specular_occlusion_cones(n_dot_r, ao, r),
    "cones, horizon-clipped": lambda mu, n_dot_r, ao, r: occlusion.specular_occlusion_cones_clipped(n_dot_r, ao, r),
}


def grid(quick):
    """(N.V values, roughness values, AO values) of the sweep."""
    if quick:
        return np.array([0.1, 0.5, 1.0]), np.array([0.2, 0.6, 1.0]), np.array([0.3, 0.7])
    return np.linspace(0.05, 1.0, 8), np.array([0.1, 0.25, 0.4, 0.55, 0.7, 0.85, 1.0]), \
        np.array([0.1, 0.3, 0.5, 0.7, 0.9])


def _stats(errors):
    errors = np.asarray(errors)
    return {"median": float(np.median(errors)), "p90": float(np.quantile(errors, 0.9)), "max": float(errors.max())}


def run(args, progress=entry.flush_log):
    """Measure every estimate over the grid; writes the report where ``args.out`` says."""
    mus, roughnesses, aos = grid(args.quick)
    rows = []
    t0 = time.perf_counter()
    for r in roughnesses:
        for mu in mus:
            n_dot_r = mu                                       # N.R of the mirror direction R = 2 (N.V) N - V
            for ao in aos:
                reference = occlusion.specular_occlusion_reference(mu, r, ao, args.samples)
                row = {"r": float(r), "mu": float(mu), "ao": float(ao), "reference": reference}
                row.update({name: float(fn(mu, n_dot_r, ao, r)) for name, fn in ESTIMATES.items()})
                rows.append(row)
        progress(f"[specular occlusion] r = {r:.2f} done")
    summary = {name: _stats([abs(row[name] - row["reference"]) for row in rows]) for name in ESTIMATES}
    by_roughness = {name: {f"{r:.2f}": _stats([abs(row[name] - row["reference"]) for row in rows if row["r"] == r])
                           for r in roughnesses} for name in ESTIMATES}
    result = {"machine": f"{platform.processor() or platform.machine()}", "samples": args.samples,
              "quick": args.quick, "points": len(rows), "seconds": time.perf_counter() - t0,
              "summary": summary, "by_roughness": by_roughness, "rows": rows,
              "best": min(summary, key=lambda name: (summary[name]["p90"], summary[name]["median"]))}
    outputs.write_results(args.out, "specular_occlusion", result, to_markdown(result))
    return result


def to_markdown(result):
    names = list(result["summary"])
    roughnesses = list(result["by_roughness"][names[0]])
    lines = ["# Specular occlusion from ambient occlusion", "",
             "Written by `python scripts/benchmark_specular_occlusion.py` "
             "(validation/benchmarks/specular_occlusion_benchmark.py, core/occlusion.py).  The visible directions are "
             "a cone about N whose cosine-weighted share of the hemisphere is AO; the reference is the share of the "
             f"GGX reflection (F = 1) whose light directions fall inside it ({result['samples']} VNDF samples per "
             f"point).  {result['points']} points: N.V, roughness and AO on a grid.  Error: |estimate - reference| "
             "of the visible share.", "",
             "| estimate | median | p90 | max |", "|---|---|---|---|"]
    for name, s in result["summary"].items():
        lines.append(f"| {name} | {s['median']:.3f} | {s['p90']:.3f} | {s['max']:.3f} |")
    lines += ["", "Per roughness (median / p90):", "",
              "| r | " + " | ".join(names) + " |", "|---|" + "---|" * len(names)]
    for r in roughnesses:
        cells = [f"{result['by_roughness'][n][r]['median']:.3f} / {result['by_roughness'][n][r]['p90']:.3f}"
                 for n in names]
        lines.append(f"| {r} | " + " | ".join(cells) + " |")
    lines += ["", f"Best by p90 (then median): **{result['best']}**.  The reference is the cone model the two cone "
              "estimates are built on, so this ranks how well each approximates that model; how well the model "
              "stands for real occluders is measured on the floor study and the concave scene (issue 29).", ""]
    return "\n".join(lines)


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--out", type=Path, default=REPO / "docs" / "benchmarks")
    p.add_argument("--samples", type=int, default=1 << 14, help="VNDF samples per reference point")
    p.add_argument("--quick", action="store_true", help="a 3 x 3 x 2 grid (smoke run)")
    return p.parse_args(argv)
