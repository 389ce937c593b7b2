"""Metal and dielectric shaded apart (issue 17, item 5), measured against Cycles at Metallic 0.5.

    python scripts/benchmark_metal_split.py [--out docs/benchmarks] [--quick]

The validation suite's ``metallic_mix_*`` cases (validation/checks/suite_cases.py: Turquin, Fdez-Aguera and Kulla-Conty at
Metallic 0.5, copper base colour, IOR 1.5, r = 0.3 / 0.6 / 0.9, under a quad, a disk and a point light, against
Cycles' Mix Shader of the dielectric and the metal closures, each Multiscatter GGX) are run twice: with the shipped
shading (``light_shading.SPLIT_F0_MODELS``: the compensated specular computed with each F0, mixed by Metallic) and
with that tuple emptied, the one mixed F0 of the earlier releases.  Each run is a child process (the traced
materials are cached per process) of ``scripts/validate.py --cases ...``; its pooled and per-roughness errors are
the suite's own (relative, over the values above 0.1 x each sphere's maximum, against two Cycles seeds).
``--quick``: the point-light case only.  Writes ``metal_split.md`` and ``.json`` in ``--out``.
"""
from __future__ import annotations

import argparse
import csv
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from ..harness import entry, outputs
from ...core.materials import light_shading
from ..checks import suite

REPO = Path(__file__).resolve().parents[2]
#: How the specular of a partly metallic surface is shaded: the one mixed F0 (before) or each F0 apart (shipped).
SHADINGS = ("mixed_f0", "apart")
CASES, QUICK_CASES = ("metallic_mix_quad", "metallic_mix_disk", "metallic_mix_point"), ("metallic_mix_point",)


def measure(shading, cases, work):
    """Run in the child process: the suite's ``cases`` with ``shading``; its results land in ``work``.  The cases run
    in this process (``--workers 0``): the shading is set here, and a Dask worker's process would not see it."""
    if shading == "mixed_f0":
        light_shading.SPLIT_F0_MODELS = ()
    args = suite.parse_args(["--cases", *cases, "--out", str(work), "--skip-furnace", "--workers", "0"])
    return suite.run(args)


def _run_child(shading, cases, work, progress):
    cmd = [sys.executable, str(REPO / "scripts" / "benchmark_metal_split.py"), "--measure", shading,
           "--work", str(work), "--cases", *cases]
    progress(f"[metal_split] {shading}: {' '.join(cases)}")
    proc = subprocess.run(cmd, cwd=REPO, capture_output=True, text=True)
    if proc.returncode != 0:
        raise RuntimeError(f"the suite run ({shading}) failed:\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}")
    pooled = json.loads((Path(work) / "validation.json").read_text())["pooled"]
    with open(Path(work) / "validation.csv", newline="") as f:
        variants = [{"model": r["technique"][len("mix_"):], "light": r["light"], "roughness": float(r["roughness"]),
                     "median": float(r["ac_median"]), "p90": float(r["ac_p90"])} for r in csv.DictReader(f)]
    return {"pooled": [{"model": p["technique"][len("mix_"):], "light": p["light"], "values": p["values"],
                        "median": p["median"], "p90": p["p90"], "noise_median": p["noise_median"]} for p in pooled],
            "variants": variants}


def _pairs(result, part, key):
    """{key(row): {shading: row}} of one part ("pooled" or "variants") of both runs."""
    rows = {}
    for shading in SHADINGS:
        for row in result[shading][part]:
            rows.setdefault(key(row), {})[shading] = row
    return dict(sorted(rows.items()))


def to_markdown(result):
    """The result of the benchmark (not of a ``--measure`` child) as Markdown (metal_split.md)."""
    L = ["# Metal and dielectric apart: Metallic 0.5 against Cycles", "",
         f"`python scripts/benchmark_metal_split.py{' --quick' if result['quick'] else ''}` "
         f"(validation/benchmarks/metal_split_benchmark.py; {result['seconds']:.0f} s on 2 cores). The validation suite's "
         "`metallic_mix_*` cases (Metallic 0.5, copper base colour, IOR 1.5, r = 0.3 / 0.6 / 0.9) against Cycles' "
         "Mix Shader of the dielectric and the metal Multiscatter GGX closures, run with the specular shaded from "
         "one mixed F0 (before) and with the dielectric's and the metal's F0 apart, mixed by Metallic (shipped, "
         "`light_shading.SPLIT_F0_MODELS`). Relative error over the values above 0.1 x each sphere's maximum, as "
         "the suite measures it.", "",
         "## Pooled per model and light", "",
         "| model | light | values | one mixed F0: median / p90 | apart: median / p90 | reference noise (median) |",
         "|---|---|---|---|---|---|"]
    for (model, light), r in _pairs(result, "pooled", lambda p: (p["model"], p["light"])).items():
        b, a = r["mixed_f0"], r["apart"]
        L.append(f"| {model} | {light} | {a['values']} | {b['median']:.2%} / {b['p90']:.2%} | "
                 f"{a['median']:.2%} / {a['p90']:.2%} | {a['noise_median']:.3%} |")
    L += ["", "## Per roughness", "", "| model | light | r | one mixed F0: median / p90 | apart: median / p90 |",
          "|---|---|---|---|---|"]
    for (model, light, r), v in _pairs(result, "variants",
                                       lambda p: (p["model"], p["light"], p["roughness"])).items():
        b, a = v["mixed_f0"], v["apart"]
        L.append(f"| {model} | {light} | {r:g} | {b['median']:.2%} / {b['p90']:.2%} | "
                 f"{a['median']:.2%} / {a['p90']:.2%} |")
    return "\n".join(L) + "\n"


def run(args, progress=entry.flush_log):
    """Both shadings' suite runs, each a child process, compared; writes metal_split.md and .json in ``args.out``.
    With ``--measure`` (the child process's part): the suite's ``--cases`` with that shading, its files in
    ``--work``; returns what was run (no "passed": the child's exit code is 0 whatever the suite's gates say)."""
    if args.measure:
        measure(args.measure, args.cases, args.work)
        return {"measure": args.measure, "cases": list(args.cases), "work": args.work}
    t0 = time.perf_counter()
    cases = QUICK_CASES if args.quick else CASES
    result = {"quick": args.quick, "cases": list(cases)}
    with tempfile.TemporaryDirectory(prefix="rtl-metal-split-") as tmp:
        for shading in SHADINGS:
            result[shading] = _run_child(shading, cases, Path(tmp) / shading, progress)
    result["seconds"] = time.perf_counter() - t0
    md = to_markdown(result)
    outputs.write_results(args.out, "metal_split", result, md)
    progress(md)
    return result


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--out", default="docs/benchmarks", help="folder for metal_split.md / .json")
    p.add_argument("--quick", action="store_true", help="the point-light case only")
    p.add_argument("--measure", choices=SHADINGS, help=argparse.SUPPRESS)   # the child process's part
    p.add_argument("--work", help=argparse.SUPPRESS)
    p.add_argument("--cases", nargs="+", help=argparse.SUPPRESS)
    return p.parse_args(argv)
