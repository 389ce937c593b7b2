"""Two runs of scripts/validate.py side by side: the (a) vs (c) relative errors of each technique, light kind
and roughness, pooled over the cases both runs rendered, from the images they saved.

    python scripts/compare_validation.py BEFORE_DIR AFTER_DIR [--techniques ggx turquin ...] [--out FILE.md]

Per case folder: node_a.exr (a), truth_c.exr (c; Cycles' two-seed mean or the brute force, 0 where not
computed) and cycles_passes.exr (Position and Normal, which give each pixel's sphere, ``suite_scene.sphere_index``).
Per sphere the values (pixel x channel) above ``floor`` x the sphere's maximum of c (the suite's floor) are
pooled; median, p90 and RMS of |a - c| / c, as validation.json's per-variant figures, which have no pooled RMS.
The two runs must share the case generator (same ``--seed``, cell and samples): their truths are then the same
renders and only (a) differs.
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from ..harness import exr_images
from . import suite_cases
from . import suite_scene

#: The techniques that use the GGX lobe under area lights (suite_cases.TECHNIQUES).
GGX_TECHNIQUES = ("ggx", "turquin", "fdez_aguera", "dielectric", "metal", "kulla_conty", "turquin_color")


def case_values(folder, case, floor):
    """{variant index: rel values} of one case folder."""
    ch = exr_images.read_channels(folder / "cycles_passes.exr")
    index = suite_scene.sphere_index(case, exr_images.find_pass(ch, "Position", "XYZ"),
                                     exr_images.find_pass(ch, "Normal", "XYZ"))
    a = exr_images.read_layer(folder / "node_a.exr").astype(np.float64)
    c = exr_images.read_layer(folder / "truth_c.exr").astype(np.float64)
    out = {}
    for i in range(len(case.variants)):
        cv, av = c[index == i].ravel(), a[index == i].ravel()
        if cv.size == 0 or cv.max() <= 0:
            continue
        sel = cv > floor * cv.max()
        out[i] = np.abs(av[sel] - cv[sel]) / cv[sel]
    return out


def pooled(run_dir, cases, techniques, floor):
    """{(technique, light, roughness): rel values} over the cases of ``run_dir``."""
    groups = {}
    for case in cases:
        folder = Path(run_dir) / case.name
        if not (folder / "node_a.exr").exists():
            continue
        for i, rel in case_values(folder, case, floor).items():
            v = case.variants[i]
            if v.technique in techniques:
                key = (v.technique, "+".join(case.light_kinds), round(v.roughness, 3))
                groups.setdefault(key, []).append(rel)
    return {k: np.concatenate(v) for k, v in groups.items()}


def _stats(rel):
    return {"values": int(rel.size), "median": float(np.median(rel)), "p90": float(np.percentile(rel, 90)),
            "rms": float(np.sqrt(np.mean(rel ** 2)))}


def compare(before_dir, after_dir, techniques=GGX_TECHNIQUES, floor=0.1, seed=0):
    """Rows per (technique, light, roughness) and per (light, roughness band), before and after."""
    cases = suite_cases.build_cases(seed)
    b, a = pooled(before_dir, cases, techniques, floor), pooled(after_dir, cases, techniques, floor)
    rows = [{"technique": t, "light": l, "roughness": r, "before": _stats(b[(t, l, r)]), "after": _stats(a[(t, l, r)])}
            for (t, l, r) in sorted(set(b) & set(a))]
    bands = {}
    for (t, l, r) in set(b) & set(a):
        band = "r <= 0.3" if r <= 0.3 else "0.3 < r < 0.7" if r < 0.7 else "r >= 0.7"
        bands.setdefault((l, band), ([], []))
        bands[(l, band)][0].append(b[(t, l, r)])
        bands[(l, band)][1].append(a[(t, l, r)])
    band_rows = [{"light": l, "band": band, "before": _stats(np.concatenate(x)), "after": _stats(np.concatenate(y))}
                 for (l, band), (x, y) in sorted(bands.items())]
    return {"floor": floor, "rows": rows, "bands": band_rows}


def markdown(res, intro=()):
    def cells(r):
        return " | ".join(f"{100 * r['before'][k]:.2f}% / **{100 * r['after'][k]:.2f}%**" for k in ("median", "p90", "rms"))

    lines = list(intro) + [f"Relative error over values above {res['floor']:g} x the sphere's maximum; before / after.", "",
             "| light | roughness | values | median | p90 | RMS |", "|---|---|---|---|---|---|"]
    lines += [f"| {r['light']} | {r['band']} | {r['before']['values']} | {cells(r)} |" for r in res["bands"]]
    lines += ["", "| technique | light | r | values | median | p90 | RMS |", "|---|---|---|---|---|---|---|"]
    lines += [f"| {r['technique']} | {r['light']} | {r['roughness']:g} | {r['before']['values']} | {cells(r)} |"
              for r in res["rows"]]
    return "\n".join(lines) + "\n"


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("before", type=Path)
    p.add_argument("after", type=Path)
    p.add_argument("--techniques", nargs="*", default=list(GGX_TECHNIQUES))
    p.add_argument("--floor", type=float, default=0.1)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", type=Path, default=None, help="write the markdown (and a .json beside it) here")
    p.add_argument("--intro", default=None, help="a file whose text opens the markdown (what the two runs were)")
    return p.parse_args(argv)


def run(args, log=print):
    res = compare(args.before, args.after, tuple(args.techniques), args.floor, args.seed)
    text = markdown(res, [Path(args.intro).read_text().rstrip("\n"), ""] if args.intro else ())
    if args.out:
        args.out.write_text(text)
        args.out.with_suffix(".json").write_text(json.dumps(res, indent=1))
    log(text)
    return res
