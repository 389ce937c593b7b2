"""The exported ltc_code GGX pair (f32 and f16) against the published ltc_code table, over random quads per roughness.

    python scripts/benchmark_ltc_code_export.py [--quads 400] [--anchor ../shared/anchors/ltc_code_ggx_table.txt] [--out docs/benchmarks/ltc_code_export.md]

Issue 32: an engine that reads selfshadow/ltc_code's ``ltc_1`` / ``ltc_2`` (three.js' ``LTC_FLOAT_1/2``, its half
tables ``LTC_HALF_1/2``) swaps in the export's ``ltc_code`` layout unchanged (core/export/luts.py).  Measured here,
as such an engine uses the pair: the LTC integral of the quad (Heitz et al. 2016) with the matrix and the magnitude
read from the table by a bilinear lookup at texel centres (``core.lut.lookup.ltc_lut_uv``,
``core.ir.semantics.sample_bilinear``), against the brute-force integral of the GGX BRDF x cosine (F = 1,
height-correlated Smith G2; core/ltc/reference.py, ``ltc_random_lights.true_integral``).  Horizon: **exact
clipping** (ltc_code's clipped branch, ``polygon.ltc_polygon_integral(method="clipped")``), so that the tables are
compared and not an engine's horizon approximation (three.js' clipped-sphere form factor dominates its own p90,
issue 32).  Tables compared, per roughness column r = 0.1, 0.2, ..., 1.0 (table nodes are at i / 63: these r
fall between nodes, as a material's roughness does):
- ``published``: the published ltc_code GGX table (``validation/harness/published_ltc.py``, the anchor file);
- ``exported f32`` / ``exported f16``: the export's ``ltc_1`` / ``ltc_2`` as ``core.export.luts`` stores them
  (``ltc_ggx_single``; f16 plain half values, decoded as an engine reads them: no scale);
- ``band base alone``: what the ltc_code layout held before issue 32 for r >= 0.65, ``ltc_ggx``'s base LTC read
  without its band (its B channel ignored, as such an engine does).
The lights: ``ltc_random_lights.random_lights`` (seeded; view angle 0-80 deg, half of the quads aimed within 60 deg
of the mirror direction, half anywhere above -15 deg elevation, 1-4 away, sides 0.3-3, facing the point within
45 deg), the same geometry at every roughness.  Error: relative, on the lights that carry > 10% of the lobe's
albedo (``ltc_random_lights.error_stats``); median and p90 per roughness and pooled over all roughness values.
"""
from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np

from ...core.export import luts
from ...core.ir import semantics
from ...core.ltc import fit, matrix, polygon
from ...core.ltc import fit_lobes as lobes
from ...core.lut import catalog, lookup
from ..harness import entry, outputs, published_ltc
from . import ltc_random_lights

REPO = Path(__file__).resolve().parents[2]
ROUGHNESS = tuple(round(0.1 * k, 1) for k in range(1, 11))
SEED = 2032
#: Quadrature panels tried in turn for the brute-force truth (``ltc_random_lights.true_integral``): the light set's
#: (8, 32) left 9 of r = 0.1's 96 counted lights above 1e-4 relative (up to 1.5e-2); 128 panels converge them.
PANELS = (8, 32, 128)
TABLES = ("published", "exported f32", "exported f16", "band base alone")


def table_pairs(lut_dir, anchor=None):
    """{name: (ltc_1, ltc_2) as (64, 64, 4) float64 arrays indexed [t, a]} of the compared tables."""
    source = lookup.LutSet.from_folder(lut_dir)
    exported = {t.name: t for t in luts.layout_tables(source, "ltc_code")}
    pairs = {}
    try:
        pairs["published"] = published_ltc.load_anchor(anchor)
    except FileNotFoundError:          # not beside this checkout (CI): measured without it, and the report says so
        pass
    for precision in ("f32", "f16"):
        pairs[f"exported {precision}"] = tuple(luts.decode(*exported[n].encode(precision)).astype(np.float64)
                                               for n in ("ltc_1", "ltc_2"))
    pairs["band base alone"] = tuple(source.array(n).astype(np.float64) for n in ("ltc_ggx_inv", "ltc_ggx_mag"))
    return pairs


def ltc_quad_estimate(ltc1, ltc2, r, mu, corners):
    """The engine's estimate: Minv and magnitude by bilinear lookup at (r, sqrt(1 - mu)), the LTC integral of the
    quad with exact horizon clipping, times the magnitude (ltc_2's R)."""
    u, v = lookup.ltc_lut_uv(np.array(mu), np.array(r))
    c = semantics.sample_bilinear(ltc1, u, v)
    magnitude = semantics.sample_bilinear(ltc2, u, v)[0]
    minv = matrix.unpack_inverse(np.asarray(c, np.float64))
    value = polygon.ltc_polygon_integral(minv, np.asarray(corners, np.float64), method="clipped")
    return float(value) * float(magnitude)


def measure(pairs, quads, seed=SEED, roughness=ROUGHNESS, progress=entry.quiet):
    """Per roughness: {"truth", "albedo", "theta", "reference_error", table name: estimates} over the same lights."""
    lobe = lobes.LOBES["ggx"]
    lights = ltc_random_lights.random_lights("quad", quads, "ggx", seed)
    out = {}
    for r in roughness:
        rows = {"truth": [], "albedo": [], "theta": [], "reference_error": [], **{name: [] for name in pairs}}
        for _, theta, v, corners in lights:
            mu = float(v[2])
            truth, err = ltc_random_lights.true_integral(
                "quad", lambda l, vv, r=r: lobe.eval_cos(l, vv, np.array(r)), v, corners, PANELS)
            rows["truth"].append(truth)
            rows["reference_error"].append(err)
            rows["theta"].append(theta)
            rows["albedo"].append(float(fit.lobe_integrals(lobe, max(mu, fit.FIT_MU_MIN), np.array([r]), 1 << 12)[0][0]))
            for name, (ltc1, ltc2) in pairs.items():
                rows[name].append(ltc_quad_estimate(ltc1, ltc2, r, mu, corners))
        out[r] = rows
        progress(f"[ltc_code export] r = {r}: {quads} quads")
    return out


def summarise(rows_by_r, names):
    """Error statistics per table: per roughness and pooled (every roughness's lights together)."""
    return ltc_random_lights.stats_by_roughness(rows_by_r, names)


def paired_share(rows_by_r, ours="exported f32", theirs="published"):
    """Per roughness and pooled: the share of the counted lights (> 10% of the albedo) on which ``ours`` is closer to
    the truth than ``theirs`` (0.5: a tie; ties between the two count half)."""
    out, wins, count = {}, 0.0, 0
    for r, rows in rows_by_r.items():
        truth = np.asarray(rows["truth"])
        sel = truth > 0.1 * np.asarray(rows["albedo"])
        a, b = (np.abs(np.asarray(rows[k]) - truth)[sel] for k in (ours, theirs))
        w = float(np.sum(a < b) + 0.5 * np.sum(a == b))
        out[str(r)] = w / max(int(sel.sum()), 1)
        wins, count = wins + w, count + int(sel.sum())
    out["pooled"] = wins / max(count, 1)
    return out


def recheck(pairs, stats, args, progress=entry.quiet):
    """Each roughness where an exported table's median is above the published one's, measured again with
    ``args.recheck_seeds`` more seeds (the next seeds after ``args.seed``), all seeds' lights pooled: is it a
    difference or the light set's noise?"""
    out = {}
    for r in ROUGHNESS:
        key = str(r)
        if all(stats[f"exported {p}"]["per_roughness"][key]["rel_median"] <= stats["published"]["per_roughness"][key]
               ["rel_median"] for p in ("f32", "f16")) or not args.recheck_seeds:
            continue
        seeds = list(range(args.seed, args.seed + 1 + args.recheck_seeds))
        rows = {"truth": [], "albedo": [], "theta": [], "reference_error": [], **{name: [] for name in pairs}}
        for seed in seeds:
            one = measure(pairs, args.quads, seed, roughness=(r,))[r]
            for k in rows:
                rows[k] += list(one[k])
        progress(f"[ltc_code export] r = {r} again over seeds {seeds[0]}-{seeds[-1]}")
        pooled = summarise({r: rows}, list(pairs))
        # the columns the bilinear lookup reads at r, and how far apart the two tables' ltc_1 are there
        cols = sorted({int(np.floor(r * 63)), int(np.ceil(r * 63))})
        diff = np.abs(pairs["exported f32"][0][:, cols] - pairs["published"][0][:, cols]).max(axis=(1, 2))
        out[key] = {"seeds": seeds, "stats": {n: pooled[n]["per_roughness"][key] for n in pairs},
                    "exported_f32_closer_than_published": paired_share({r: rows})[key], "columns": cols,
                    "ltc_1_max_difference_rows_0_48": float(diff[:49].max()),
                    "ltc_1_max_difference_rows_49_63": float(diff[49:].max())}
    return out


def run(args, progress=entry.flush_log):
    """Measure the four tables; writes ``args.out`` (Markdown) and the JSON beside it."""
    t0 = time.perf_counter()
    lut_dir = args.lut_dir or catalog.default_lut_dir()
    pairs = table_pairs(lut_dir, args.anchor)
    rows = measure(pairs, args.quads, args.seed, progress=progress)
    stats = summarise(rows, list(pairs))
    per_r = stats["exported f32"]["per_roughness"]
    published = "published" in stats
    share = paired_share(rows) if published else None
    result = {"date": time.strftime("%Y-%m-%d"), "quads_per_roughness": args.quads, "seed": args.seed,
              "roughness": list(ROUGHNESS), "horizon": "exact clipping (ltc_code's clipped branch)",
              "stats": stats,
              "reference_max_error_estimate": float(max(np.max(r["reference_error"]) for r in rows.values())),
              "exported_f32_closer_than_published": share,
              "published_table": str(args.anchor or published_ltc.DEFAULT_PATH) if published else None,
              "acceptance": None if not published else {
                  precision: {"median_at_or_below_published_at_every_roughness": all(
                      stats[f"exported {precision}"]["per_roughness"][r]["rel_median"]
                      <= stats["published"]["per_roughness"][r]["rel_median"] for r in per_r),
                      "pooled_p90_below_published": stats[f"exported {precision}"]["pooled"]["rel_p90"]
                      < stats["published"]["pooled"]["rel_p90"]} for precision in ("f32", "f16")}}
    if published:
        result["recheck"] = recheck(pairs, stats, args, progress)
    result["seconds"] = time.perf_counter() - t0
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.with_suffix(".json").write_text(json.dumps(result, indent=1, default=outputs.json_default))
    out.write_text(to_markdown(result))
    progress(f"wrote {out} and {out.with_suffix('.json')}")
    return result


def to_markdown(result):
    """The result as Markdown (ltc_code_export.md)."""
    s = result["stats"]
    names = [n for n in TABLES if n in s]
    lines = ["# The exported ltc_code GGX pair against the published table", "",
             f"Measured {result['date']} with `python scripts/benchmark_ltc_code_export.py --quads "
             f"{result['quads_per_roughness']}` ({result['seconds']:.0f} s; "
             "`validation/benchmarks/ltc_code_export_benchmark.py`, whose docstring says what is compared and how). "
             f"{result['quads_per_roughness']} seeded quads (seed {result['seed']}) at every roughness, the LTC "
             f"integral with {result['horizon']}, against a brute-force integral of the GGX BRDF x cosine "
             f"(estimated quadrature error <= {result['reference_max_error_estimate']:.1e}). Relative error on "
             "the lights carrying > 10% of the lobe's albedo: median / p90.", "",
             "| r | lights | " + " | ".join(names) + " | exported f32 closer than published |",
             "|---|---|" + "---|" * len(names) + "---|"]
    share = result.get("exported_f32_closer_than_published") or {}
    ours = s["exported f32"]
    for r in ours["per_roughness"]:
        cells = [f"{100 * s[n]['per_roughness'][r]['rel_median']:.2f} / {100 * s[n]['per_roughness'][r]['rel_p90']:.2f}%"
                 for n in names]
        closer = f"{100 * share[r]:.0f}% of lights" if r in share else "-"
        lines.append(f"| {r} | {ours['per_roughness'][r]['lights_over_10pct']} | " + " | ".join(cells) + f" | {closer} |")
    cells = [f"**{100 * s[n]['pooled']['rel_median']:.2f} / {100 * s[n]['pooled']['rel_p90']:.2f}%**" for n in names]
    closer = f"{100 * share['pooled']:.0f}% of lights" if share else "-"
    lines.append(f"| pooled | {ours['pooled']['lights_over_10pct']} | " + " | ".join(cells) + f" | {closer} |")
    if result["acceptance"] is None:
        lines += ["", "The published table was not found (`--anchor`): no comparison with it, no acceptance."]
    else:
        lines += ["", "Acceptance (issue 32: median <= the published table's at every roughness, lower pooled p90):",
                  ""]
    for precision, a in (result["acceptance"] or {}).items():
        worse = [r for r in s["published"]["per_roughness"]
                 if s[f"exported {precision}"]["per_roughness"][r]["rel_median"]
                 > s["published"]["per_roughness"][r]["rel_median"]]
        lines.append(f"- exported {precision}: median <= published at every roughness: "
                     f"{'yes' if a['median_at_or_below_published_at_every_roughness'] else 'no (r = ' + ', '.join(worse) + ')'}; "
                     f"pooled p90 below published: {'yes' if a['pooled_p90_below_published'] else 'no'}")
    for r, again in (result.get("recheck") or {}).items():
        st = again["stats"]
        lines += ["", f"**r = {r} again**, {len(again['seeds'])} seeds ({again['seeds'][0]}-{again['seeds'][-1]}, "
                      f"{st['published']['lights_over_10pct']} counted lights pooled): median / p90 "
                  + ", ".join(f"{n} {100 * st[n]['rel_median']:.2f} / {100 * st[n]['rel_p90']:.2f}%" for n in names)
                  + f"; exported f32 closer than published on {100 * again['exported_f32_closer_than_published']:.0f}% "
                    f"of the lights. The lookup reads table column(s) {', '.join(map(str, again['columns']))} there, where "
                    "the exported and the published `ltc_1` differ by at most "
                    f"{again['ltc_1_max_difference_rows_0_48']:.1e} up to row 48 (view angles to 65 deg) and "
                    f"{again['ltc_1_max_difference_rows_49_63']:.1e} in rows 49-63."]
    lines += ["", "`band base alone` is what the ltc_code layout exported before issue 32 for r >= 0.65 (ltc_ggx's "
                  "base LTC, its band ignored); below r = 0.65 it is the same table as `exported f32`."]
    return "\n".join(lines) + "\n"


def parse_args(argv):
    p = entry.benchmark_parser(__doc__, REPO / "docs" / "benchmarks" / "ltc_code_export.md",
                               "40 quads per roughness instead of 400")
    p.add_argument("--quads", type=int, default=None, help="quads per roughness (default 400; 40 with --quick)")
    p.add_argument("--seed", type=int, default=SEED)
    p.add_argument("--recheck-seeds", type=int, default=4,
                   help="more seeds for a roughness where an exported median is above the published one (0: none)")
    p.add_argument("--anchor", type=Path, default=None,
                   help="the published ltc_code table (default: validation/harness/published_ltc.DEFAULT_PATH)")
    args = p.parse_args(argv)
    if args.quads is None:
        args.quads = 40 if args.quick else 400
    return args
