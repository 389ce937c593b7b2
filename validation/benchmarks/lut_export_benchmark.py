"""Half-precision LUTs, measured: per table and end to end.

    python scripts/benchmark_lut_export.py [--quads 120 --disks 60] [--out docs/benchmarks/lut_export.md]

For the tables of the rtl layout (core/export/luts.py), three variants: float32 (as shipped), half as is
(every value rounded to the nearest float16, as an engine that squeezes the tables does: three.js issue
#20477 is that failure), and half as the exporter stores it (channels with values below half's smallest
normal multiplied by a power of two, decoded after the lookup).  Measured:
- per table: max absolute and relative error against float32, values that lose more than 2^-11;
- end to end: the LTC benchmark's seeded quads and disks per BRDF (validation/benchmarks/ltc_random_lights.end_to_end,
  the main job's light set by default) against brute force, for each variant;
- energy compensation: Kulla-Conty's furnace E_ss + E_ms - 1 over r in [0, 1], mu >= 0.1 (the lobe reads
  1 - E and 1 - E_avg), and how far Turquin's 1 + (1 - E)/E and Fdez-Aguera's E_ss + E_ms (F0 = 0.04) move
  from their float32 values over the table cells (their F0 = 1 furnaces hold by construction).
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from ...core import energy_checks, multiscatter
from ...core.export import luts
from ...core.ir.tables import Table
from ...core.lut import catalog
from ...core.lut.lookup import LutSet
from . import ltc_random_lights
from ..harness import entry

REPO = Path(__file__).resolve().parents[2]
VARIANTS = ("f32", "f16 plain", "f16 scaled")


def variant_tables(lut_dir):
    """{variant: {catalog table name: (H, W, 4) float64 array as the shader would read it}}."""
    source = LutSet.from_folder(lut_dir)
    out = {v: {} for v in VARIANTS}
    for name in catalog.TABLES:
        data = source.array(name).astype(np.float32)
        stored, scales = luts.encode(data, "f16")
        out["f32"][name] = data.astype(np.float64)
        out["f16 plain"][name] = data.astype(np.float16).astype(np.float64)
        out["f16 scaled"][name] = luts.decode(stored, scales).astype(np.float64)
    return out


def furnaces(arrays, reference):
    """Kulla-Conty's furnace with these tables, and how far Turquin's compensation 1 + (1 - E)/E (F0 = 1) and
    Fdez-Aguera's environment BRDF (F0 = 0.04) move from their values with the ``reference`` tables."""
    tables = LutSet({n: Table.from_array(n, a.astype(np.float32)) for n, a in arrays.items()})
    roughness = np.linspace(0.0, 1.0, 11)
    mu = np.linspace(0.1, 1.0, 10) + 0.013
    mu = mu[mu <= 1.0]
    kc = np.abs(energy_checks.kulla_conty_furnace(tables, roughness, mu))

    def compensations(a):
        e = 1.0 - a["ggx_one_minus_E"][..., 0]
        return (multiscatter.turquin_compensation(1.0, e),
                multiscatter.fdez_aguera_env_brdf(0.04, a["ggx_split_sum"][..., 0], a["ggx_split_sum"][..., 1]))

    (t, f), (t0, f0) = compensations(arrays), compensations(reference)
    return {"kulla_conty_furnace": float(kc.max()), "turquin_rel_change": float(np.max(np.abs(t - t0) / t0)),
            "fdez_aguera_rel_change": float(np.max(np.abs(f - f0) / np.abs(f0)))}


def run(args, progress=entry.flush_log):
    """Measure the three variants; writes ``args.out`` (Markdown) and the JSON beside it."""
    lut_dir = args.lut_dir or catalog.default_lut_dir()
    t0 = time.perf_counter()
    tables = luts.layout_tables(LutSet.from_folder(lut_dir), "rtl")
    per_table = {t.name: luts.precision_errors(t) for t in tables}
    variants = variant_tables(lut_dir)
    result = {"date": time.strftime("%Y-%m-%d"), "quads": args.quads, "disks": args.disks, "per_table": per_table,
              "end_to_end": {}, "furnaces": {}}
    for variant, arrays in variants.items():
        progress(f"[lut export] {variant}: LTC light set, furnaces")
        ltc = {n: a for n, a in arrays.items() if n.startswith("ltc_")}
        result["end_to_end"][variant] = ltc_random_lights.end_to_end(ltc, None, args.quads, args.disks)
        result["furnaces"][variant] = furnaces(arrays, variants["f32"])
    result["seconds"] = time.perf_counter() - t0
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.with_suffix(".json").write_text(json.dumps(result, indent=1))
    out.write_text(to_markdown(result))
    progress(f"wrote {out} and {out.with_suffix('.json')}")
    return result


def to_markdown(result):
    """The result as Markdown (lut_export.md)."""
    lines = ["# Half-precision LUTs: per table and end to end", "",
             f"Measured {result['date']} with `python scripts/benchmark_lut_export.py` "
             f"({result['seconds']:.0f} s). Half as is: every value rounded to float16; half scaled: as "
             "`core/export/luts.py` stores it (a channel with values below half's smallest normal, 6.1e-5, "
             "multiplied by a power of two, decoded after the lookup: the manifest's `decode_scale`).", "",
             "## Per table, against float32", "",
             "| table | half as is: max abs / max rel / values > 2^-11 off | half scaled: max abs / max rel / values > "
             "2^-11 off | decode scale (log2, RGBA) |", "|---|---|---|---|"]
    for name, p in result["per_table"].items():
        a, b = p["f16_plain"], p["f16_scaled"]
        lines.append(f"| {name} | {a['max_abs']:.1e} / {a['max_rel']:.1e} / {a['values_beyond_half_epsilon']} | "
                     f"{b['max_abs']:.1e} / {b['max_rel']:.1e} / {b['values_beyond_half_epsilon']} | "
                     f"{', '.join(str(int(np.log2(s))) for s in p['decode_scale'])} |")
    lines += ["", "Relative errors are over the non-zero values; the values that stay more than 2^-11 off when "
                  "scaled are below 2^-24 x the scale (e.g. 1 - E < 1e-11 at r = 0): their absolute error is below "
                  "1e-11.", "",
              f"## End to end: LTC area lights ({result['quads']} quads and {result['disks']} disks per BRDF, seeded)",
              "", "Relative error against brute force on lights carrying > 10% of the lobe's albedo "
                  "(validation/benchmarks/ltc_benchmark.py).", "",
              "| BRDF / light | " + " | ".join(f"{v}: median / p90 / max" for v in VARIANTS) + " |",
              "|---|" + "---|" * len(VARIANTS)]
    for key in result["end_to_end"]["f32"]:
        cells = []
        for v in VARIANTS:
            s = result["end_to_end"][v][key]["ours"]
            cells.append(f"{100 * s['rel_median']:.3f}% / {100 * s['rel_p90']:.2f}% / {100 * s['rel_max']:.1f}%")
        lines.append(f"| {key} | " + " | ".join(cells) + " |")
    lines += ["", "## Energy compensation", "", "| measure | " + " | ".join(VARIANTS) + " |",
              "|---|" + "---|" * len(VARIANTS)]
    rows = (("kulla_conty_furnace", "Kulla-Conty furnace: max abs(E_ss + E_ms - 1), r in [0, 1], mu >= 0.1"),
            ("turquin_rel_change", "Turquin 1 + (1 - E)/E (F0 = 1): max relative change from f32, every cell"),
            ("fdez_aguera_rel_change", "Fdez-Aguera E_ss + E_ms (F0 = 0.04): max relative change from f32, every cell"))
    for key, label in rows:
        lines.append(f"| {label} | " + " | ".join(f"{result['furnaces'][v][key]:.3e}" for v in VARIANTS) + " |")
    return "\n".join(lines) + "\n"


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--quads", type=int, default=120)
    p.add_argument("--disks", type=int, default=60)
    p.add_argument("--lut-dir", type=Path, default=None)
    p.add_argument("--out", type=Path, default=REPO / "docs" / "benchmarks" / "lut_export.md")
    return p.parse_args(argv)
