"""Light shadows on an asset-like concave scene (issue 29), against the path-traced twin, beside path tracing's own
time-vs-error curve.

    python scripts/benchmark_concave_shadows.py [--out docs/benchmarks] [--quick] [--runs N]

The concave scene (``lookdev_scene.new_concave_scene``: a torus resting on the floor of an open box, a copper
Suzanne beside it, the studio lights and HDRI world) measured by ``shadow_studies.concave_study``: one row per RT Lit
setting (unshadowed; world occlusion; the lights' shadows by the ratio estimator of addon/shadows.py at 1 ... 64
probe samples per pixel with Open Image Denoise, world occlusion on), each against ONE reference, the twin path
traced at ``--samples`` spp x 2 seeds.  Per row: the per-value relative error (the validation's metric) over every
RT Lit object's pixels, median / p90, and per object; the RT Lit render's seconds (the median of ``--runs``).  Path
tracing's curve: the twin at 1 ... 64 spp (another seed) against the same reference, its error and seconds, so that
each row's error reads against the time path tracing needs for it.  A row's shadow options are the keyword
arguments of ``shadows.enable_shadows`` and its switches those of ``Features``.  Writes ``concave_shadows.md``,
``.json`` and ``concave_shadows.png`` (RT Lit unshadowed, RT Lit with the default light shadows, path traced) in
``--out``.
"""
from __future__ import annotations

import math
import platform
from pathlib import Path

import numpy as np

from ..checks import lookdev_twin, shadow_studies
from ..harness import entry, outputs, png

REPO = Path(__file__).resolve().parents[2]

#: World occlusion's model in the rows that occlude the world by AO (the most accurate of
#: docs/benchmarks/specular_occlusion.md).
OCCLUSION = "cones_clipped"
#: The default of ``shadows.enable_shadows`` (4 probe samples, OIDN, the World term shadowed too): the acceptance row
#: of issue 29.
DEFAULT_SHADOWS = {"samples": 4, "denoise": True, "world": True}
SHADOW_SAMPLES = (1, 2, 4, 8, 16, 32, 64)
UNSHADOWED = {"features": {}, "light_shadows": None}
OCCLUDED = {"features": {"occlusion": OCCLUSION}, "light_shadows": None}
#: The lights' shadows with the world occluded by AO (the setup before the World term's shadows).
LIGHTS_AND_AO = {"features": {"occlusion": OCCLUSION}, "light_shadows": dict(DEFAULT_SHADOWS, world=False)}
ROWS = (UNSHADOWED, OCCLUDED, LIGHTS_AND_AO) + tuple(
    {"features": {}, "light_shadows": dict(DEFAULT_SHADOWS, samples=n)} for n in SHADOW_SAMPLES)
QUICK_ROWS = (UNSHADOWED, {"features": {}, "light_shadows": dict(DEFAULT_SHADOWS)})
#: The split (full run only): (key, title, ``concave_study`` options, rows): the lights alone and the world alone,
#: each against its own twin reference, one render per row, no curve.
SPLIT = (("lights_only", "The studio lights alone (no world)", {"world": False},
          (UNSHADOWED, {"features": {}, "light_shadows": dict(DEFAULT_SHADOWS)})),
         ("world_only", "The world alone (the studio lights removed)", {"lights": False},
          (UNSHADOWED, OCCLUDED, {"features": {}, "light_shadows": dict(DEFAULT_SHADOWS)})))
#: (resolution, reference spp, path tracing's curve) of the full run and of ``--quick``.
FULL = ((256, 192), 64, shadow_studies.PATH_TRACING_SPP)
QUICK = ((64, 48), 8, (1, 4))


def shadows_label(light_shadows):
    """A row's light-shadow options in words: "none", "4 spp, OIDN", other options as key=value."""
    if light_shadows is None:
        return "none"
    what = "lights + world" if light_shadows.get("world", True) else "lights"
    words = [what, f"{light_shadows.get('samples', 4)} spp"] + (["OIDN"] if light_shadows.get("denoise", True) else [])
    words += [f"{k}={v}" for k, v in light_shadows.items() if k not in ("samples", "denoise", "world")]
    return ", ".join(words)


def equal_error(curve, error):
    """Path tracing's (spp, seconds) at the median ``error``, log-log interpolated along ``curve``; (None, None) when
    ``error`` is outside the curve's range (the caller says which side)."""
    points = sorted((p["errors"]["all"]["median"], p["spp"], p["seconds"]) for p in curve)
    for (e0, s0, t0), (e1, s1, t1) in zip(points, points[1:]):
        if e0 <= error <= e1 and e1 > e0:
            w = (math.log(error) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp((1 - w) * math.log(s0) + w * math.log(s1)), (1 - w) * t0 + w * t1
    return None, None


def _equal_error_cell(curve, error):
    if not curve:
        return "-"
    spp, seconds = equal_error(curve, error)
    if spp is not None:
        return f"{spp:.0f} spp, {seconds:.1f} s"
    best = min(curve, key=lambda p: p["errors"]["all"]["median"])
    worst = max(curve, key=lambda p: p["errors"]["all"]["median"])
    return f"> {best['spp']} spp" if error < best["errors"]["all"]["median"] else f"< {worst['spp']} spp"


def _row_record(row, curve):
    """The JSON record of one measured row (its images left out)."""
    errors = row["errors"]
    spp, seconds = equal_error(curve, errors["all"]["median"]) if curve else (None, None)
    return {"features": row["features"], "light_shadows": row["light_shadows"], "label": row["label"],
            "rt_lit_samples": row["rt_lit_samples"], "errors": errors,
            "unshadowed_twin": row["errors_unshadowed_twin"], "seconds": row["seconds"], "runs": row["runs"],
            "path_tracing_equal_error": {"spp": spp, "seconds": seconds}}


def write_picture(path, rows):
    """RT Lit unshadowed | RT Lit with the default light shadows | path traced, side by side (x / (1 + x), gamma
    2.2)."""
    unshadowed = next(r for r in rows if r["light_shadows"] is None and not r["features"])
    shadowed = next((r for r in rows if r["light_shadows"] == DEFAULT_SHADOWS), rows[-1])
    images = [unshadowed["images"]["rt_lit"], shadowed["images"]["rt_lit"], unshadowed["images"]["path_traced"]]
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    gap = np.ones((images[0].shape[0], 4, 3))
    strip = np.concatenate([x for image in images for x in (lookdev_twin.display(image), gap)][:-1], axis=1)
    png.write_rgb(path, strip)
    return path


def run(args, progress=entry.flush_log):
    """Measure every row and path tracing's curve on the concave study; writes the report where ``args.out`` says."""
    resolution, samples, spps = QUICK if args.quick else FULL
    samples = args.samples or samples
    rows = QUICK_ROWS if args.quick else ROWS
    runs = args.runs if args.runs is not None else (1 if args.quick else 3)
    study = shadow_studies.concave_study(rows, args.lut_dir, resolution, samples, curve_spps=spps, runs=runs,
                                       log=progress)
    curve = study["path_tracing"]
    result = {"machine": platform.processor() or platform.machine(), "quick": args.quick, "runs": runs,
              "reference": study["reference"], "rows": [_row_record(r, curve) for r in study["rows"]],
              "path_tracing": curve}
    result["split"] = {} if args.quick else _split(args, resolution, samples, progress)
    if args.out is not None:
        result["picture"] = write_picture(Path(args.out) / "concave_shadows.png", study["rows"]).name
    outputs.write_results(args.out, "concave_shadows", result, to_markdown(result))
    return result


def _split(args, resolution, samples, progress):
    """{key: {"title", "reference", "rows"}} of the lights alone and the world alone (``SPLIT``)."""
    out = {}
    for key, title, options, rows in SPLIT:
        study = shadow_studies.concave_study(rows, args.lut_dir, resolution, samples, curve_spps=(), runs=1,
                                           log=progress, **options)
        out[key] = {"title": title, "reference": study["reference"],
                    "rows": [_row_record(r, []) for r in study["rows"]]}
    return out


def _split_markdown(split, names):
    lines = ["## The lights alone and the world alone", "",
             "The same measurement with the world left out, and with the studio lights removed, each against its own "
             "twin reference (same size and samples, one render per row): which part of the error the lights' shadows "
             "and World Occlusion each leave.  \"vs the unshadowed twin\": against the twin with its objects seen by "
             "camera rays only (the shading's own error, which no shadow removes).", "",
             "| lighting | World Occlusion | light shadows | all objects | " + " | ".join(_short(n) for n in names) +
             " | vs the unshadowed twin | reference noise | RT Lit render |",
             "|---|---|---|---|" + "---|" * len(names) + "---|---|---|"]
    for part in split.values():
        for row in part["rows"]:
            cells = [part["title"], row["features"].get("occlusion", "none"), shadows_label(row["light_shadows"]),
                     outputs.median_p90(row["errors"]["all"])]
            cells += [outputs.median_p90(row["errors"].get(n)) for n in names]
            cells += [outputs.median_p90(row["unshadowed_twin"]), f"{part['reference']['noise_median']:.1%}",
                      f"{row['seconds']:.1f} s ({row['rt_lit_samples']} spp)"]
            lines.append("| " + " | ".join(cells) + " |")
    return lines + [""]


def _short(name):
    """An object's name without the scene's ("Concave Study Box" -> "Box")."""
    return name.rsplit(" ", 1)[-1]


def _seconds_cell(record):
    """The median seconds of a row or curve point, with the fastest run when there were several (the machine is
    shared: the fastest is the nearest to the render's own cost)."""
    runs = record.get("runs") or []
    return f"{record['seconds']:.1f} s" + (f" (min {min(runs):.1f})" if len(runs) > 1 else "")


def to_markdown(result):
    ref = result["reference"]
    objects = ref["objects"]
    width, height = ref["resolution"]
    lines = ["# Light shadows on the concave scene", "",
             "Written by `python scripts/benchmark_concave_shadows.py` (validation/benchmarks/concave_shadows_benchmark.py;"
             " docs/shadows.md).  The concave scene (`lookdev_scene.new_concave_scene`: a torus resting on the floor of "
             "an open box, a copper Suzanne beside it, the studio lights and HDRI world) in Cycles against its path-traced "
             f"twin ({width} x {height}, the twin at {ref['samples']} spp x {len(ref['seeds'])} seeds, 0 bounces, rendered "
             "once for every row): the per-value relative error where the reference is above 1% of the object's maximum "
             "(the validation's metric), median / p90, over every RT Lit object's pixels and per object.  Light shadows: "
             "the ratio estimator's probe samples per pixel (`enable_shadows(samples=...)`, OIDN on).  RT Lit render: the "
             f"median of {result['runs']} F12 renders, wall clock, and the fastest of them (Cycles on "
             f"{result['machine'] or 'this machine'}, 2 threads, the machine shared with other jobs: the runs spread "
             "by tens of percent), the RT Lit samples in brackets (32 with world occlusion: its Ambient Occlusion node "
             "traces).  Path tracing at equal error: where path tracing's own curve (below) reaches the row's median "
             "error (log-log interpolated, median seconds).",
             ""]
    names = list(objects)
    lines += ["| World Occlusion | light shadows | all objects | " + " | ".join(_short(n) for n in names) +
              " | RT Lit render | path tracing at equal error |",
              "|---|---|---|" + "---|" * len(names) + "---|---|"]
    for row in result["rows"]:
        occlusion = row["features"].get("occlusion", "none")
        cells = [occlusion, shadows_label(row["light_shadows"]), outputs.median_p90(row["errors"]["all"])]
        cells += [outputs.median_p90(row["errors"].get(n)) for n in names]
        cells += [f"{_seconds_cell(row)}, {row['rt_lit_samples']} spp",
                  _equal_error_cell(result["path_tracing"], row["errors"]["all"]["median"])]
        lines.append("| " + " | ".join(cells) + " |")
    plain = next((r for r in result["rows"] if r["light_shadows"] is None and not r["features"]), None)
    lines.append("")
    if plain is not None and plain["unshadowed_twin"]:
        lines.append(f"Unshadowed RT Lit against the twin with its objects seen by camera rays only (no shadow, no "
                     f"occlusion of the world): {outputs.median_p90(plain['unshadowed_twin'])}, the error of the shading "
                     "itself, which shadows cannot remove.")
    lines += [f"The reference's own noise (median of its two seeds' half-difference): {ref['noise_median']:.1%}; "
              f"its renders took {', '.join(f'{s:.1f}' for s in ref['seconds'])} s.", ""]
    if result["path_tracing"]:
        lines += ["## Path tracing's own curve", "",
                  f"The twin at n spp (one seed, not the reference's) against the same reference, median of "
                  f"{result['runs']} renders' seconds.  Its error includes the reference's noise "
                  f"({ref['noise_median']:.1%}), so it flattens as n nears the reference's {ref['samples']} spp.", "",
                  "| spp | all objects | " + " | ".join(_short(n) for n in names) + " | path tracing render |",
                  "|---|---|" + "---|" * len(names) + "---|"]
        for point in result["path_tracing"]:
            cells = [str(point["spp"]), outputs.median_p90(point["errors"]["all"])]
            cells += [outputs.median_p90(point["errors"].get(n)) for n in names] + [_seconds_cell(point)]
            lines.append("| " + " | ".join(cells) + " |")
        lines.append("")
    if result.get("split"):
        lines += _split_markdown(result["split"], names)
    if result.get("picture"):
        lines += [f"![RT Lit unshadowed, RT Lit with light shadows at 4 spp + OIDN, path traced]({result['picture']})", ""]
    return "\n".join(lines)


def parse_args(argv):
    p = entry.benchmark_parser(__doc__, REPO / "docs" / "benchmarks", "64 x 48, the reference at 8 spp, two rows (smoke run)")
    p.add_argument("--samples", type=int, default=None, help="the reference's spp per seed (default 64; --quick 8)")
    p.add_argument("--runs", type=int, default=None, help="RT Lit and path tracing renders per row, the median "
                                                          "timed (default 3; --quick 1)")
    return p.parse_args(argv)
