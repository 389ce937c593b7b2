"""Report writers of scripts/validate.py: EXR images, PNG previews and error maps, CSV, HTML."""
from __future__ import annotations

import csv
import html
import json
from pathlib import Path

import numpy as np

from . import exr_images
from . import png as _png


def flush_log(line):
    """The default ``log`` of long runs: print at once (progress shows while a job runs)."""
    print(line, flush=True)


def json_default(o):
    """``json.dumps(default=...)`` for numpy scalars and arrays and paths."""
    if isinstance(o, (np.bool_, np.integer, np.floating)):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, Path):
        return str(o)
    raise TypeError(f"not JSON serialisable: {type(o)}")


def write_exr(path, rgb):
    """(H, W, 3) float image (row 0 = top) as a 32-bit float RGB EXR; NaN written as 0."""
    return exr_images.write_rgb(path, rgb)


def preview_png(path, rgb, scale_value):
    """Display-referred preview: x / scale_value, clipped, sRGB-ish gamma; NaN shown dark red."""
    rgb = np.asarray(rgb, np.float64)
    nan = ~np.isfinite(rgb).all(axis=-1)
    v = np.clip(np.nan_to_num(rgb) / max(scale_value, 1e-12), 0.0, 1.0) ** (1 / 2.2)
    v[nan] = (0.15, 0.0, 0.0)
    _png.write_rgb(path, v)
    return path


def error_png(path, err, vmax):
    """False-colour map of a per-pixel error (H, W) in [0, vmax] with a colour bar (top = vmax);
    pixels without a value (NaN) are white."""
    e = np.asarray(err, np.float64)
    _png.heatmap(path, np.flipud(np.nan_to_num(e)), vmax, scale=1, bar_width=10)
    return path


def write_results(folder, stem, result, markdown):
    """A benchmark's ``<stem>.md`` and ``<stem>.json`` in ``folder`` (made if needed); nothing when ``folder`` is
    None."""
    if folder is None:
        return
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    (folder / f"{stem}.md").write_text(markdown)
    (folder / f"{stem}.json").write_text(json.dumps(result, indent=1, default=json_default))


def write_csv(path, rows):
    keys = []
    for r in rows:
        for k in r:
            if k not in keys:
                keys.append(k)
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        for r in rows:
            w.writerow({k: _fmt_csv(r.get(k)) for k in keys})


def _fmt_csv(v):
    if isinstance(v, float):
        return f"{v:.6g}"
    return v


def _pct(x, digits=2):
    return "-" if x is None else f"{100 * x:.{digits}f}%"


def _sci(x):
    return "-" if x is None else f"{x:.2e}"


def _ok(flag):
    return "" if flag is None else ('<span class="ok">ok</span>' if flag else '<span class="fail">FAIL</span>')


_CSS = """
body{font-family:sans-serif;margin:1.5em;max-width:1400px}
table{border-collapse:collapse;margin:0.5em 0 1em 0;font-size:13px}
td,th{border:1px solid #bbb;padding:2px 6px;text-align:right}
th{background:#eee} td.l{text-align:left}
.ok{color:#070;font-weight:bold}.fail{color:#b00;font-weight:bold}
img{image-rendering:pixelated;border:1px solid #888;margin:2px;vertical-align:top}
figure{display:inline-block;margin:0 8px 8px 0}figcaption{font-size:12px}
"""


def write_html(path, result):
    from ..checks.suite_cases import CYCLES_ERROR_EXPONENTS

    s = result["settings"]
    out = [f"<!doctype html><html><head><meta charset='utf-8'><title>RT Lookdev validation</title>"
           f"<style>{_CSS}</style></head><body>",
           "<h1>RT Lookdev: headless validation</h1>",
           f"<p>Overall: {_ok(result['passed'])} &nbsp; suite time {result['timings_s']['total']:.1f} s "
           f"(Blender {html.escape(s['blender'])}, {s['threads']} threads).</p>",
           "<p>Per case: (a) node render: Cycles, RT Lit material (emission), 1 sample at pixel centres; "
           "(b) numpy evaluation of the same IR at (a)'s Position/Normal passes; (c) ground truth: Cycles path "
           f"tracing of the equivalent closure ({s['samples']} spp, seeds {s['seeds']}, c = mean of both, "
           "direct light only) or the brute-force integral of the true BRDF over the light "
           f"(at most {s['brute_pixels']} seeded pixels per sphere). "
           f"Relative errors (a) vs (c) are over values (pixel x channel) with c &gt; {s['floor']:g} x the sphere's "
           f"max (the gated figures); the same statistics with the floor at {s['floor_wide']:g} x max are in the "
           "JSON/CSV ('wide'). Noise: |c1 - c2| / 2 per value, the Monte Carlo error of c, reported with the "
           "same statistics; 'spp to match' = the Cycles samples whose noise equals the node render's own RMS "
           "error (noise scaling as spp^-k, k per family "
           f"{', '.join(f'{f} {k:g}' for f, k in CYCLES_ERROR_EXPONENTS.items())}, measured by the speed-vs-error benchmark, "
           "docs/benchmarks/speed_error.md; '&ge;' when the node error is below this comparison's noise).</p>"]
    # checks
    out.append("<h2>Acceptance checks</h2><table><tr><th>check</th><th>measured</th><th>threshold</th><th></th></tr>")
    for c in result["checks"]:
        out.append(f"<tr><td class='l'>{html.escape(c['name'])}</td><td>{html.escape(c['measured'])}</td>"
                   f"<td>{html.escape(c['threshold'])}</td><td>{_ok(c['ok'])}</td></tr>")
    out.append("</table>")
    # pooled
    out.append("<h2>Per technique and light kind (pooled over cases)</h2><table><tr><th>technique</th><th>light</th>"
               "<th>truth</th><th>values</th><th>mean</th><th>median</th><th>p90</th><th>max</th>"
               "<th>noise median</th><th>median (floor wide)</th><th>p90 (floor wide)</th></tr>")
    for g in result["pooled"]:
        out.append(f"<tr><td class='l'>{g['technique']}</td><td class='l'>{g['light']}</td><td class='l'>{g['truth']}</td>"
                   f"<td>{g['values']}</td><td>{_pct(g['mean'])}</td><td>{_pct(g['median'])}</td><td>{_pct(g['p90'])}</td>"
                   f"<td>{_pct(g['max'])}</td><td>{_pct(g.get('noise_median'), 3)}</td>"
                   f"<td>{_pct(g.get('wide_median'))}</td><td>{_pct(g.get('wide_p90'))}</td></tr>")
    out.append("</table>")
    # furnace
    fur = result.get("furnace")
    if fur:
        out.append("<h2>White furnace (uniform white world)</h2>")
        out.append(f"<p>Cycles Glossy Multiscatter GGX, F = 1 (scripts/validate_energy.py, {fur['settings']}): "
                   + ", ".join(f"r={k}: {v['mean']:.4f}" for k, v in fur["multi_ggx"].items())
                   + f" {_ok(fur['multi_ggx_ok'])}; validate_energy overall {_ok(fur['validate_energy_passed'])}.</p>")
        out.append("<p>Kulla-Conty with the shipped tables, E_ss (true integral) + E_ms (LUT lobe) - 1, max |.| over "
                   "mu in [0.1, 1]: " + ", ".join(f"r={k}: {v:.1e}" for k, v in fur["kc_lut_max_abs"].items())
                   + f" {_ok(fur['kc_lut_ok'])}</p>")
        kc = fur["kc_color"]
        out.append(f"<p>Kulla-Conty coloured albedo c E + F_ms(c)(1 - E) vs Cycles Glossy Multiscatter GGX with "
                   f"Color c = {kc['color']} (per-mu-bin means, mu &ge; 0.1), max relative difference per roughness: "
                   + ", ".join(f"r={k}: {_pct(v, 3)}" for k, v in kc["max_rel_bin"].items())
                   + f" {_ok(kc['ok'])}</p>")
    # cases
    out.append("<h2>Cases</h2>")
    for case in result["cases"]:
        out.append(f"<h3 id='{case['name']}'>{html.escape(case['name'])}</h3><p>{html.escape(case['description'])}. "
                   f"Image {case['image'][0]}x{case['image'][1]}, Cycles truth {case['samples']} spp per seed; times: (a) {case['time_a']:.2f} s, "
                   f"(b) {case['time_b']:.2f} s, (c) Cycles {', '.join(f'{t:.1f}' for t in case['time_c_cycles'])} s"
                   f", brute force {case['time_c_brute']:.1f} s. (a) vs (b): max rel {_sci(case['ab']['max_rel'])}, "
                   f"max abs near 0 {_sci(case['ab']['max_abs_near_zero'])} {_ok(case['ab_ok'])}</p>")
        out.append("<table><tr><th>#</th><th>variant</th><th>truth</th><th>(a)-(b) max rel</th><th>values</th>"
                   "<th>mean</th><th>median</th><th>p90</th><th>max</th><th>RMSE</th><th>noise median</th>"
                   "<th>noise p90</th><th>spp to match</th><th>quadrature err</th><th>brute vs Cycles median</th>"
                   "<th>time (c) s</th></tr>")
        for v in case["variants"]:
            t = v.get("truth_metrics") or {}
            spp = t.get("cycles_spp_to_match")
            spp_s = "-" if spp is None else (("&ge;" if t.get("cycles_spp_to_match_is_lower_bound") else "")
                                             + f"{spp:.3g}")
            chk = v.get("brute_check") or {}
            out.append(f"<tr><td>{v['index']}</td><td class='l'>{html.escape(v['label'])}</td><td class='l'>{v['truth']}</td>"
                       f"<td>{_sci(v['ab']['max_rel'])}</td><td>{t.get('values', '-')}</td><td>{_pct(t.get('mean'))}</td>"
                       f"<td>{_pct(t.get('median'))}</td><td>{_pct(t.get('p90'))}</td><td>{_pct(t.get('max'))}</td>"
                       f"<td>{_sci(t.get('rmse'))}</td><td>{_pct(t.get('noise_median'), 3)}</td>"
                       f"<td>{_pct(t.get('noise_p90'), 3)}</td><td>{spp_s}</td>"
                       f"<td>{_sci(t.get('quadrature_rel_max'))}</td><td>{_pct(chk.get('median'), 3)}</td>"
                       f"<td>{v.get('time_c', 0):.2f}</td></tr>")
        out.append("</table>")
        figs = case["png"]
        for key, cap in (("a", "(a) node render"), ("c", "(c) ground truth"), ("err_ac", "|a - c| / c (bar: 0 - "
                         f"{s['err_vmax']:g})"), ("err_ab", f"|a - b| / max(|b|, 0.01) (bar: 0 - {s['ab_tol']:g})")):
            if key in figs:
                out.append(f"<figure><img src='{figs[key]}'><figcaption>{cap}</figcaption></figure>")
    out.append("<h2>Settings</h2><pre>" + html.escape(json.dumps(result["settings"], indent=1)) + "</pre>")
    out.append("</body></html>")
    Path(path).write_text("\n".join(out))
    return path
