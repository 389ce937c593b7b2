"""Environment baking measured over Blender's 8 studio HDRIs; writes docs/benchmarks/environment.md.

    python scripts/benchmark_environment.py [--normals 500] [--dirs 128] [--out docs/benchmarks/environment.md]

Per HDRI (full 1024 x 512 source): SH irradiance vs brute-force irradiance (every texel summed) at
random normals (mean / max relative = the L2 truncation error), the SH and prefiltered bake times
(forced), the cached re-run time, and the prefiltered radiance looked up (bilinear, between levels
when needed) at random directions vs the brute-force split-sum integral.  For one HDRI, the
importance-sampling method (Colbert & Krivanek 2007) against the FFT quadrature at texel centres.
For large sources (a 4096 x 2048 and an 8192 x 4096 image made from forest.exr with an added sun),
the bake's time and peak memory with the default source cap (``PrefilterSettings.max_source_width``)
and without it (4096 only: 8K without the cap would need an estimated ~18 GB), and the levels' difference between the two.
Results: ``--out`` (Markdown) and the same numbers as JSON beside it.
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path


import numpy as np

from ..harness import entry

from ...core.environment import equirect, prefilter, sh  # noqa: E402

REPO = Path(__file__).resolve().parents[2]


def _rel(a, b):
    """Per-point relative difference of RGB values: sum |a - b| / sum b."""
    return np.abs(a - b).sum(axis=-1) / np.maximum(np.abs(b).sum(axis=-1), 1e-12)


def _unit(rng, n):
    v = rng.normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


SUN_DIRECTION = (0.5, -0.6, 0.35)        # about 20 deg above the horizon
SUN_RADIUS = np.radians(0.27)            # the real sun's angular radius
SUN_RADIANCE = 1.0e5


def large_source(width):
    """forest.exr bilinearly enlarged to width x width / 2, plus a sun disk (``SUN_*``) with its edge
    texels' coverage supersampled 4 x 4: detail that a 1024-wide source cannot hold."""
    small = equirect.read_equirect(equirect.resolve_hdri("forest"))
    h = width // 2
    image = np.empty((h, width, 3), np.float32)
    for s in range(0, h, 256):
        image[s:s + 256] = equirect.sample_equirect(small, equirect.texel_directions(h, width, slice(s, s + 256)))
    sun = np.asarray(SUN_DIRECTION) / np.linalg.norm(SUN_DIRECTION)
    u, v = equirect.direction_to_uv(sun)
    col, row = int(u * width), int((1.0 - v) * h)
    pad = int(np.ceil(2.0 * SUN_RADIUS / (np.pi / h))) + 2
    rows, cols = np.arange(row - pad, row + pad + 1), np.arange(col - pad, col + pad + 1)
    sub = (np.arange(4) + 0.5) / 4.0
    v_sub = 1.0 - (rows[:, None] + sub[None, :]) / h                                     # (R, 4)
    u_sub = (cols[:, None] + sub[None, :]) / width                                       # (C, 4)
    d = equirect.uv_to_direction(*np.broadcast_arrays(u_sub[None, :, None, :],
                                                      v_sub[:, None, :, None]))      # (R, C, 4, 4, 3)
    coverage = (d @ sun > np.cos(SUN_RADIUS)).mean(axis=(2, 3))
    block = image[np.ix_(rows, cols % width)]
    image[np.ix_(rows, cols % width)] = block * (1.0 - coverage[..., None]) + SUN_RADIANCE * coverage[..., None]
    return image


def _large_bake_child(width, cap, out_dir):
    """Run in a child process (peak memory is per process): bake ``large_source(width)`` with the cap
    ``cap``; prints one JSON line."""
    image = large_source(width)
    settings = prefilter.PrefilterSettings(max_source_width=cap)
    t0 = time.perf_counter()
    bake = prefilter.bake_environment_image(image, f"large{width}_cap{cap}", "benchmark", out_dir, settings,
                                            force=True)
    seconds = time.perf_counter() - t0
    print(json.dumps({"width": width, "cap": cap, "seconds": seconds, "sh": bake.seconds["sh"],
                      "prefiltered": bake.seconds["prefiltered"], "path": str(bake.prefiltered_path),
                      "max_rss_gb": _peak_memory_gb()}))


def _peak_memory_gb():
    """This process's peak resident memory: VmHWM (Linux; ru_maxrss would include the parent's peak,
    which Linux keeps across execve), else ru_maxrss."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 2 ** 20
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2 ** 20


def _large_bake(width, cap, out_dir):
    """``_large_bake_child`` in a fresh interpreter (its own peak memory); returns its JSON line."""
    code = (f"import sys; from {__name__} import _large_bake_child; "
            "_large_bake_child(int(sys.argv[1]), int(sys.argv[2]), sys.argv[3])")
    cmd = [sys.executable, "-c", code, str(width), str(cap), str(out_dir)]
    done = subprocess.run(cmd, check=True, capture_output=True, text=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def large_source_rows(tmp, default_cap, progress=print):
    """Bake times and peak memory of large sources with and without the cap, and per level the
    relative difference (sum over RGB) between the capped and the full-resolution levels."""
    runs = [_large_bake(4096, default_cap, tmp), _large_bake(4096, 4096, tmp), _large_bake(8192, default_cap, tmp)]
    capped, _, _ = prefilter.read_prefiltered(runs[0]["path"])
    full, levels, _ = prefilter.read_prefiltered(runs[1]["path"])
    diff = []
    for k, r in enumerate(levels):
        rel = _rel(capped[k].astype(np.float64), full[k].astype(np.float64))
        diff.append({"r": r, "mean": float(rel.mean()), "p99": float(np.percentile(rel, 99)), "max": float(rel.max())})
    for run in runs:
        progress(f"large source {run['width']} cap {run['cap']}: {run['seconds']:.1f} s "
            f"(SH {run['sh']:.1f} s), peak {run['max_rss_gb']:.2f} GB")
    return runs, diff


#: Roughness values of the prefiltered-lookup check.
CHECK_R = (0.125, 0.5, 1.0)


def hdri_rows(normals, dirs, settings, tmp, progress=entry.flush_log, names=None):
    """Per studio HDRI (``names``: a subset): (name, SH irradiance mean / p90 / max relative error, SH bake s,
    prefiltered bake s, cached re-run s), and (name, [relative errors of the prefiltered lookup per
    ``CHECK_R``])."""
    rows, pf_rows = [], []
    for name, path in equirect.studio_hdris().items():
        if names and name not in names:
            continue
        rng = np.random.default_rng(2024)
        image = equirect.read_equirect(path)
        normals_ = _unit(rng, normals)
        e_bf = sh.irradiance_brute_force(image, normals_)
        baked = prefilter.bake_environment(path, tmp, settings, force=True)
        e_sh = sh.sh_irradiance(baked.sh_image, normals_)
        rel = _rel(e_sh, e_bf)
        t0 = time.perf_counter()
        again = prefilter.bake_environment(path, tmp, settings)
        cached = time.perf_counter() - t0
        assert again.states == {"sh": "cached", "prefiltered": "cached"}, again.states
        rows.append((name, rel.mean(), np.percentile(rel, 90), rel.max(), baked.seconds["sh"],
                     baked.seconds["prefiltered"], cached))
        levels, rl, _ = prefilter.read_prefiltered(baked.prefiltered_path)
        dirs_ = _unit(rng, dirs)
        errs = []
        for r in CHECK_R:
            ref = prefilter.prefilter_reference(image, dirs_, r)
            errs.append(_rel(prefilter.sample_prefiltered(levels, rl, dirs_, r), ref))
        pf_rows.append((name, errs))
        progress(f"{name}: SH irradiance mean {rel.mean():.4f} max {rel.max():.4f}; bake SH "
            f"{baked.seconds['sh']:.2f} s, prefiltered {baked.seconds['prefiltered']:.2f} s; cached "
            f"re-run {cached:.3f} s; prefiltered lookup mean rel "
            + ", ".join(f"r={r}: {e.mean():.4f}" for r, e in zip(CHECK_R, errs)))
    return rows, pf_rows


def method_rows(progress=entry.flush_log):
    """Importance sampling vs the FFT quadrature (exact at texel centres) on one HDRI, per roughness:
    [r, FFT s, FFT max rel vs brute force, then per (samples, bias): samples, bias, s, mean, p90]."""
    image = equirect.read_equirect(equirect.resolve_hdri("sunset"))
    mips = equirect.mip_chain(image)
    sel = np.array([3, 12, 21, 30, 39, 48, 57])
    out = []
    for r in (0.25, 0.5, 1.0):
        t0 = time.perf_counter()
        exact = prefilter.prefilter_level_fft(image, r, 128, 64)
        t_fft = time.perf_counter() - t0
        ref = prefilter.prefilter_reference(image, equirect.texel_directions(64, 128)[sel].reshape(-1, 3), r)
        line = [r, t_fft, _rel(exact[sel].reshape(-1, 3), ref).max()]
        for samples, bias in ((256, 0.0), (256, 1.0), (1024, 0.0)):
            t0 = time.perf_counter()
            est = prefilter.prefilter_level(mips, r, 128, 64, samples, bias)
            t_is = time.perf_counter() - t0
            e = _rel(est, exact)
            line += [samples, bias, t_is, e.mean(), np.percentile(e, 90)]
        out.append(line)
        progress(" ".join(map(str, ["method", line])))
    return out


def _markdown_hdris(result, settings):
    md = ["# Environment baking (issue 6, part 1)", "",
          f"Generated by `python scripts/benchmark_environment.py` on {result['cpus']} CPU cores "
          f"({result['date']}).  Sources: Blender's 8 studio HDRIs (1024 x 512, CC0, read from the bpy "
          "wheel).  Code: `core/environment/` (equirect.py, sh.py, prefilter.py).", "",
          "## SH irradiance vs brute force, bake times, cache", "",
          f"Irradiance E(n) at {result['normals']} random normals (seed 2024): the 9-coefficient SH irradiance "
          "(Ramamoorthi & Hanrahan 2001, eq. 7-9) vs the sum over every texel of the full image (Fejer x "
          "midpoint weights).  Relative difference per normal = sum_RGB |E_SH - E_bf| / sum_RGB E_bf: the L2 "
          "truncation error (the clamped cosine's bands >= 4; A_3 = 0).  Bake times are forced bakes in one "
          f"process (SH projection of the 1024 x 512 image; {len(settings.roughness)} prefiltered levels r = "
          f"0, 0.125, ..., 1 of {settings.width} x {settings.height}, FFT quadrature); the cached re-run reads the "
          "source (to hash its pixels) and the two files' headers and pixels (content hash) and computes nothing.", "",
          "| HDRI | SH irradiance mean rel | p90 | max | SH bake (s) | prefiltered bake (s) | cached re-run (s) |",
          "|---|---|---|---|---|---|---|"]
    for h in result["hdris"]:
        md.append(f"| {h['name']} | {h['sh_irradiance_mean']:.4f} | {h['p90']:.4f} | {h['max']:.4f} | "
                  f"{h['sh_s']:.2f} | {h['prefiltered_s']:.2f} | {h['cached_s']:.3f} |")
    md += ["", "The max relative differences occur where the irradiance is small (normals facing dark ground "
           "or a dark sky side): nine coefficients cannot follow a sharp bright/dark horizon, and a small bright sun (sunrise, studio) makes the L2 irradiance ring (max > 1: the SH value overshoots, or goes below zero, opposite the sun).", ""]
    return md


def _markdown_prefiltered(result, settings):
    md = ["## Prefiltered radiance looked up vs the brute-force split sum", "",
          f"{result['dirs']} random directions per HDRI; the stored {settings.width} x {settings.height} level "
          "looked up bilinearly (Blender's Linear filtering, `prefilter.sample_prefiltered`) vs "
          "`prefilter_reference` (the normalised D(h) max(R.l, 0) convolution of Karis 2013 summed over every "
          "source texel).  At r = 0.125 the lobe (alpha = 0.0156) is narrower than an output texel (2.8 deg), "
          "so the error there is the output resolution's, not the method's: at texel centres the FFT "
          "quadrature equals the brute force to ~1e-7.", "",
          "| HDRI | " + " | ".join(f"r = {r}: mean / max rel" for r in CHECK_R) + " |",
          "|---|" + "---|" * len(CHECK_R)]
    for row in result["prefiltered_lookup"]:
        md.append(f"| {row['name']} | " + " | ".join(f"{row[f'r{r}']['mean']:.4f} / {row[f'r{r}']['max']:.4f}"
                                                   for r in CHECK_R) + " |")
    return md


def _markdown_method(method):
    t_fft_med = float(np.median([line[1] for line in method]))
    t_is_med = float(np.median([line[5] for line in method]))          # 256 samples, bias 0
    e_is_mean = float(np.median([line[6] for line in method]))
    t_is1024 = float(np.median([line[15] for line in method]))       # 1024 samples, bias 0
    e_is1024 = float(np.median([line[16] for line in method]))
    md = ["", "## Method: FFT quadrature vs importance sampling with filtered lookups", "",
          "sunset, one 128 x 64 level: the FFT quadrature's time and its max relative difference from the "
          "brute force at 7 rows of texel centres; importance sampling of the GGX NDF with trilinear mip "
          "lookups (Colbert & Krivanek 2007, lod = 1/2 log2(Omega_s / Omega_p) + bias) vs the FFT result at "
          f"every texel (mean and p90 relative).  Median over the three levels: FFT {t_fft_med:.2f} s, exact; "
          f"256 importance samples {t_is_med:.2f} s at {100 * e_is_mean:.2f}% mean error, 1024 samples "
          f"{t_is1024:.2f} s at {100 * e_is1024:.2f}%.  The FFT is the default: no noise and no mip bias; C&K's "
          "+1 level bias over-blurs here.", "",
          "| r | FFT (s) | FFT vs brute force (max rel) | IS 256, bias 0: s / mean / p90 | IS 256, bias 1 | IS 1024, bias 0 |",
          "|---|---|---|---|---|---|"]
    for line in method:
        r, t_fft, e_fft = line[:3]
        cells = []
        for i in range(3):
            _, _, t_is, m, p = line[3 + 5 * i: 8 + 5 * i]
            cells.append(f"{t_is:.2f} / {m:.4f} / {p:.4f}")
        md.append(f"| {r} | {t_fft:.2f} | {e_fft:.1e} | " + " | ".join(cells) + " |")
    return md


def _markdown_large(settings, large_runs, large_diff):
    md = ["", "## Large sources: the source cap", "",
          f"`PrefilterSettings.max_source_width` = {settings.max_source_width}: a wider source is area-averaged "
          "to that width before prefiltering (`prefilter.prefilter_source`); the SH projection always reads the "
          f"full image.  Sources: forest.exr enlarged bilinearly, plus a sun disk of radius 0.27 deg and radiance "
          f"{SUN_RADIANCE:g} about 20 deg above the horizon (edge texels supersampled), baked in a child process "
          "each (peak memory = its peak resident set, VmHWM, the image included).", "",
          "| source | cap | bake (s) | SH (s) | prefiltered (s) | peak memory (GB) |", "|---|---|---|---|---|---|"]
    for run in large_runs:
        md.append(f"| {run['width']} x {run['width'] // 2} | {run['cap']} | {run['seconds']:.1f} | {run['sh']:.1f} | "
                  f"{run['prefiltered']:.1f} | {run['max_rss_gb']:.2f} |")
    md += ["", f"Capped ({settings.max_source_width}) vs full-resolution (4096) levels of the 4096 x 2048 source, "
           "relative difference per output texel (sum over RGB): the error the cap adds.", "",
           "| r | mean | p99 | max |", "|---|---|---|---|"]
    for d in large_diff:
        md.append(f"| {d['r']:g} | {d['mean']:.1e} | {d['p99']:.1e} | {d['max']:.1e} |")
    return md


#: The result's keys that the JSON file leaves out: inputs of the Markdown only.
MARKDOWN_ONLY = ("normals", "dirs", "quick", "method")


def _results(rows, pf_rows, large_runs, large_diff):
    """The result as the JSON file holds it."""
    return {"cpus": os.cpu_count(), "date": time.strftime("%Y-%m-%d"),
            "hdris": [{"name": n, "sh_irradiance_mean": m, "p90": p, "max": x, "sh_s": a, "prefiltered_s": b,
                       "cached_s": c} for n, m, p, x, a, b, c in rows],
            "prefiltered_lookup": [{"name": n, **{f"r{r}": {"mean": float(e.mean()), "max": float(e.max())}
                                                  for r, e in zip(CHECK_R, errs)}} for n, errs in pf_rows],
            "large_sources": [{k: v for k, v in run.items() if k != "path"} for run in large_runs],
            "cap_difference": large_diff}


def parse_args(argv):
    """The options of scripts/benchmark_environment.py parsed from ``argv``."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--normals", type=int, default=500)
    p.add_argument("--dirs", type=int, default=128, help="random directions for the prefilter check")
    p.add_argument("--out", type=Path, default=REPO / "docs" / "benchmarks" / "environment.md")
    p.add_argument("--hdris", default="", help="comma-separated studio HDRIs (default: all 8)")
    p.add_argument("--quick", action="store_true",
                   help="smoke run: skip the large-source and sampling-method sections (most of the ~10 minutes)")
    return p.parse_args(argv)


def run(args, progress=entry.flush_log):
    """Measure, write ``args.out`` (Markdown) and the JSON beside it; returns the JSON's dict with the inputs of the
    Markdown that the JSON file leaves out (``MARKDOWN_ONLY``: the options, the sampling-method lines)."""
    settings = prefilter.PrefilterSettings()
    with tempfile.TemporaryDirectory() as tmp:
        names = [n for n in args.hdris.split(",") if n]
        rows, pf_rows = hdri_rows(args.normals, args.dirs, settings, tmp, progress, names)
        large_runs, large_diff = ([], []) if args.quick else large_source_rows(tmp, settings.max_source_width,
                                                                               progress)
    method = [] if args.quick else method_rows(progress)
    result = {**_results(rows, pf_rows, large_runs, large_diff), "normals": args.normals, "dirs": args.dirs,
              "quick": args.quick, "method": method}
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(to_markdown(result))
    saved = {k: v for k, v in result.items() if k not in MARKDOWN_ONLY}
    args.out.with_suffix(".json").write_text(json.dumps(saved, indent=1) + "\n")
    progress(f"wrote {args.out} and {args.out.with_suffix('.json')}")
    return result


def to_markdown(result):
    """The result as Markdown (environment.md; the prefilter settings are the defaults, as ``run`` bakes with)."""
    settings = prefilter.PrefilterSettings()
    md = _markdown_hdris(result, settings) + _markdown_prefiltered(result, settings)
    if not result["quick"]:
        md += _markdown_method(result["method"]) + _markdown_large(settings, result["large_sources"],
                                                                   result["cap_difference"])
    return "\n".join(md) + "\n"
