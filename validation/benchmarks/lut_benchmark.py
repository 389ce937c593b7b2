"""Benchmark the energy LUT bake: time, error against sample count, table axis, E_avg fits.

    python scripts/benchmark_luts.py [--out docs/benchmarks] [--repeats 3] [--quick] [--skip-bake]

Writes luts.json (all numbers) and luts.md (tables) to --out.  Measures:
1. bake time of the ggx_energy group (the three tables come from one pass), median of
   --repeats runs, at the shipped sample count;
2. error of E(mu, r) against a 2^20-point reference on a 16 x 16 subset of the table nodes,
   for 2^10 .. 2^18 points per cell, with the time per cell;
3. interpolation error of the 64 x 64 table at off-node points, for the shipped mu-linear
   v axis and for a sqrt(1 - mu) axis;
4. the talk's AverageEnergy(smoothness) polynomial against the table's E_avg, and what its
   0.999 clamp does to the Kulla-Conty white furnace.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

from ..harness import entry


from ...core import energy
from ...core import energy_checks as validation  # noqa: E402
from ...core import lut_bake as bake
from ...core.ir import semantics
from ...core.lut import catalog, exr_io, lookup  # noqa: E402

REPO = Path(__file__).resolve().parents[2]


def _time(fn, repeats):
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), times, result


def bake_time(repeats):
    params = catalog.GROUPS["ggx_energy"].params
    median, runs, tables = _time(lambda: bake.compute_energy_tables(params["size"], params["samples"]), repeats)
    with tempfile.TemporaryDirectory() as tmp:
        write_s = {name: _time(lambda: exr_io.write_table(Path(tmp) / f"{name}.exr", table, {"table": name}),
                               repeats)[0] for name, table in tables.items()}
    return {"group": "ggx_energy", "tables": list(tables), "samples_per_cell": params["samples"],
            "cells": params["size"] ** 2, "median_s": median, "runs_s": runs, "write_median_s": write_s}, tables


def error_vs_samples(exponents, reference_exponent, stride):
    nodes = np.arange(catalog.ENERGY_SIZE) / (catalog.ENERGY_SIZE - 1)
    r, mu = nodes[::stride], nodes[::stride]
    mu_eval = mu[mu >= 0.1]
    t0 = time.perf_counter()
    ref = energy.directional_albedo(mu_eval, r, 1 << reference_exponent)
    ref_time = time.perf_counter() - t0
    rows = []
    for k in exponents:
        t_med, _, e = _time(lambda: energy.directional_albedo(mu_eval, r, 1 << k), 1)
        err = np.abs(e - ref)
        rows.append({"samples": 1 << k, "max_abs_err": float(err.max()), "p99_abs_err": float(np.quantile(err, 0.99)),
                     "mean_abs_err": float(err.mean()), "ms_per_cell": 1e3 * t_med / err.size})
    return {"reference_samples": 1 << reference_exponent, "reference_s": ref_time,
            "cells": int(r.size * mu_eval.size), "mu_min": 0.1, "rows": rows}


def interpolation_error(shipped_tables, samples, stride=1):
    """The 64 x 64 table's error at cell centres (every ``stride``-th cell in r and mu), on the shipped mu-linear
    v axis and on a sqrt(1 - mu) axis (that table baked here, ``samples`` points per node; with a ``stride``, only
    the nodes around the cells measured)."""
    size = catalog.ENERGY_SIZE
    nodes = np.arange(size) / (size - 1)
    # off-node evaluation points: cell centres in (r, mu)
    r_mid = ((nodes[:-1] + nodes[1:]) / 2)[::stride]
    mu_mid = ((nodes[:-1] + nodes[1:]) / 2)[::stride]
    mu_mid = mu_mid[mu_mid >= 0.1]
    exact = energy.directional_albedo(mu_mid, r_mid, samples)                     # (r, mu)
    R, M = np.meshgrid(r_mid, mu_mid, indexing="ij")
    mu_linear = 1.0 - semantics.sample_bilinear(shipped_tables["ggx_one_minus_E"],
                                             *lookup.energy_lut_uv(M, R))[..., 0]
    # the same table on a sqrt(1 - mu) axis: the nodes a bilinear read at the points above touches
    v_of_points = lookup.lut_coordinate(np.sqrt(1.0 - mu_mid), size) * size - 0.5
    v_used = np.unique(np.clip(np.concatenate([np.floor(v_of_points), np.floor(v_of_points) + 1]), 0, size - 1))
    r_used = np.unique(np.clip(np.concatenate([np.arange(size)[::stride], np.arange(size)[::stride] + 1]), 0, size - 1))
    v_rows, r_cols = v_used.astype(int), r_used.astype(int)
    e_sqrt = np.zeros((size, size))
    e_sqrt[np.ix_(v_rows, r_cols)] = energy.directional_albedo(1.0 - nodes[v_rows] ** 2, nodes[r_cols], samples).T
    table_sqrt = np.repeat(e_sqrt[..., None], 4, axis=-1)
    sqrt_axis = semantics.sample_bilinear(table_sqrt, lookup.lut_coordinate(R, size),
                                       lookup.lut_coordinate(np.sqrt(1.0 - M), size))[..., 0]
    out = {}
    for name, approx in (("mu_linear (shipped)", mu_linear), ("sqrt_one_minus_mu", sqrt_axis)):
        err = np.abs(approx - exact)
        idx = np.unravel_index(err.argmax(), err.shape)
        out[name] = {"max_abs_err": float(err.max()), "p99_abs_err": float(np.quantile(err, 0.99)),
                     "median_abs_err": float(np.median(err)), "worst_at_r_mu": [float(R[idx]), float(M[idx])]}
    return {"points": int(R.size), "mu_min": 0.1, "samples": samples, "stride": stride, "axes": out}


def to_markdown(res):
    """The results as Markdown (luts.md)."""
    b = res["bake"]
    lines = [
        "# Energy LUT benchmark", "",
        f"Command: `python scripts/benchmark_luts.py` ({res['machine']}, {res['date']}).", "",
        "## Bake time", ""]
    if b is None:
        lines += ["Not timed (`--skip-bake`): the tables of the LUT folder.", ""]
    else:
        lines += [
            f"Group `ggx_energy` ({', '.join(b['tables'])}; one pass, {b['cells']} cells x "
            f"{b['samples_per_cell']} points): median **{b['median_s']:.1f} s** of {len(b['runs_s'])} runs "
            f"({', '.join(f'{t:.1f}' for t in b['runs_s'])} s). Writing each EXR file (median): "
            + ", ".join(f"{n} {1e3 * t:.1f} ms" for n, t in b["write_median_s"].items()) + ".", ""]
    lines += [
        "## Error of E(mu, r) against sample count", "",
        f"Reference: {res['samples']['reference_samples']} points per cell; {res['samples']['cells']} cells "
        f"(every 4th node, mu >= 0.1).", "",
        "| points per cell | max abs err | p99 | mean | ms per cell |", "|---|---|---|---|---|"]
    for row in res["samples"]["rows"]:
        mark = " (shipped)" if row["samples"] == catalog.ENERGY_SAMPLES else ""
        lines.append(f"| {row['samples']}{mark} | {row['max_abs_err']:.2e} | {row['p99_abs_err']:.2e} | "
                     f"{row['mean_abs_err']:.2e} | {row['ms_per_cell']:.2f} |")
    it = res["interpolation"]
    every = f", every {it['stride']}th cell" if it.get("stride", 1) > 1 else ""
    lines += ["", f"## Interpolation error of the 64 x 64 table (off-node points, mu >= 0.1{every})", "",
              "| v axis | max abs err | p99 | median | worst at (r, mu) |", "|---|---|---|---|---|"]
    for name, a in it["axes"].items():
        lines.append(f"| {name} | {a['max_abs_err']:.2e} | {a['p99_abs_err']:.2e} | {a['median_abs_err']:.2e} | "
                     f"({a['worst_at_r_mu'][0]:.3f}, {a['worst_at_r_mu'][1]:.3f}) |")
    tp = res["talk_polynomial"]
    lines += ["", "## The talk's AverageEnergy(smoothness) polynomial", "",
              f"Max |fit - E_avg| = {tp['max_abs_err_vs_table']:.4f} at r = {tp['at_r']:.3f}; "
              f"it is clamped to 0.999 for r <= {tp['clamped_below_r']:.3f}.", "",
              "White furnace E + E_ms with E from the table and E_avg from the fit (the identity needs 1):", "",
              f"| r | max abs err, mu >= 0.1 | err at mu = {tp['furnace_with_polynomial'][0]['grazing_mu']:.3f} |",
              "|---|---|---|"]
    for row in tp["furnace_with_polynomial"]:
        lines.append(f"| {row['r']:.3f} | {row['max_err_mu_ge_0.1']:.4f} | {row['err_at_grazing_mu']:+.4f} |")
    lines += ["", "With E_avg from the table itself the identity holds to rounding "
              "(tests/core/test_multiscatter.py::test_kulla_conty_white_furnace).", ""]
    return "\n".join(lines)


def parse_args(argv):
    """The options of scripts/benchmark_luts.py parsed from ``argv``."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", type=Path, default=REPO / "docs" / "benchmarks")
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--quick", action="store_true", help="fewer sample counts, smaller reference, the interpolation "
                   "error on every 4th cell (smoke run)")
    p.add_argument("--skip-bake", action="store_true", help="do not time the bake: the tables of the LUT folder")
    return p.parse_args(argv)


def run(args, progress=entry.flush_log):
    """Measure, write luts.json and luts.md to ``args.out``; returns the results."""
    args.out.mkdir(parents=True, exist_ok=True)
    res = {"machine": f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores",
           "date": time.strftime("%Y-%m-%d")}
    if args.skip_bake:
        res["bake"] = None
        tables = {name: exr_io.read_table(catalog.default_lut_dir() / spec.filename)[0]
                  for name, spec in catalog.TABLES.items() if spec.group == "ggx_energy"}
    else:
        progress("[bench] bake time ...")
        res["bake"], tables = bake_time(1 if args.quick else args.repeats)
        progress(f"[bench]   median {res['bake']['median_s']:.1f} s")
    progress("[bench] error vs samples ...")
    exps = [10, 12, 14] if args.quick else [10, 11, 12, 13, 14, 15, 16, 18]
    res["samples"] = error_vs_samples(exps, 16 if args.quick else 20, 8 if args.quick else 4)
    progress("[bench] interpolation error ...")
    res["interpolation"] = interpolation_error(tables, catalog.ENERGY_SAMPLES, 4 if args.quick else 1)
    res["talk_polynomial"] = validation.talk_polynomial_furnace(tables)
    (args.out / "luts.json").write_text(json.dumps(res, indent=2))
    markdown = to_markdown(res)
    (args.out / "luts.md").write_text(markdown)
    progress(markdown)
    return res
