"""The validation suite's HTML report (validation/checks/suite.py writes it as <out>/report.html)."""
from __future__ import annotations

import html
import json
from pathlib import Path

from ..harness.outputs import CSS, html_verdict, percent, scientific
from .suite_metrics import CYCLES_ERROR_EXPONENTS


def write_html(path, result):
    """The suite's HTML report at ``path``: the checks, the pooled errors, the white furnace, every case with its
    images, the settings."""
    s = result["settings"]
    out = [f"<!doctype html><html><head><meta charset='utf-8'><title>RT Lookdev validation</title>"
           f"<style>{CSS}</style></head><body>",
           "<h1>RT Lookdev: headless validation</h1>",
           f"<p>Overall: {html_verdict(result['passed'])} &nbsp; suite time {result['timings_s']['total']:.1f} s "
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
                   f"<td>{html.escape(c['threshold'])}</td><td>{html_verdict(c['ok'])}</td></tr>")
    out.append("</table>")
    # pooled
    out.append("<h2>Per technique and light kind (pooled over cases)</h2><table><tr><th>technique</th><th>light</th>"
               "<th>truth</th><th>values</th><th>mean</th><th>median</th><th>p90</th><th>max</th>"
               "<th>noise median</th><th>median (floor wide)</th><th>p90 (floor wide)</th></tr>")
    for g in result["pooled"]:
        out.append(f"<tr><td class='l'>{g['technique']}</td><td class='l'>{g['light']}</td><td class='l'>{g['truth']}</td>"
                   f"<td>{g['values']}</td><td>{percent(g['mean'])}</td><td>{percent(g['median'])}</td><td>{percent(g['p90'])}</td>"
                   f"<td>{percent(g['max'])}</td><td>{percent(g.get('noise_median'), 3)}</td>"
                   f"<td>{percent(g.get('wide_median'))}</td><td>{percent(g.get('wide_p90'))}</td></tr>")
    out.append("</table>")
    # furnace
    fur = result.get("furnace")
    if fur:
        out.append("<h2>White furnace (uniform white world)</h2>")
        out.append(f"<p>Cycles Glossy Multiscatter GGX, F = 1 (scripts/validate_energy.py, {fur['settings']}): "
                   + ", ".join(f"r={k}: {v['mean']:.4f}" for k, v in fur["multi_ggx"].items())
                   + f" {html_verdict(fur['multi_ggx_ok'])}; validate_energy overall {html_verdict(fur['validate_energy_passed'])}.</p>")
        out.append("<p>Kulla-Conty with the shipped tables, E_ss (true integral) + E_ms (LUT lobe) - 1, max |.| over "
                   "mu in [0.1, 1]: " + ", ".join(f"r={k}: {v:.1e}" for k, v in fur["kc_lut_max_abs"].items())
                   + f" {html_verdict(fur['kc_lut_ok'])}</p>")
        kc = fur["kc_color"]
        out.append(f"<p>Kulla-Conty coloured albedo c E + F_ms(c)(1 - E) vs Cycles Glossy Multiscatter GGX with "
                   f"Color c = {kc['color']} (per-mu-bin means, mu &ge; 0.1), max relative difference per roughness: "
                   + ", ".join(f"r={k}: {percent(v, 3)}" for k, v in kc["max_rel_bin"].items())
                   + f" {html_verdict(kc['ok'])}</p>")
    # cases
    out.append("<h2>Cases</h2>")
    for case in result["cases"]:
        out.append(f"<h3 id='{case['name']}'>{html.escape(case['name'])}</h3><p>{html.escape(case['description'])}. "
                   f"Image {case['image'][0]}x{case['image'][1]}, Cycles truth {case['samples']} spp per seed; times: (a) {case['time_a']:.2f} s, "
                   f"(b) {case['time_b']:.2f} s, (c) Cycles {', '.join(f'{t:.1f}' for t in case['time_c_cycles'])} s"
                   f", brute force {case['time_c_brute']:.1f} s. (a) vs (b): max rel {scientific(case['ab']['max_rel'])}, "
                   f"max abs near 0 {scientific(case['ab']['max_abs_near_zero'])} {html_verdict(case['ab_ok'])}</p>")
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
                       f"<td>{scientific(v['ab']['max_rel'])}</td><td>{t.get('values', '-')}</td><td>{percent(t.get('mean'))}</td>"
                       f"<td>{percent(t.get('median'))}</td><td>{percent(t.get('p90'))}</td><td>{percent(t.get('max'))}</td>"
                       f"<td>{scientific(t.get('rmse'))}</td><td>{percent(t.get('noise_median'), 3)}</td>"
                       f"<td>{percent(t.get('noise_p90'), 3)}</td><td>{spp_s}</td>"
                       f"<td>{scientific(t.get('quadrature_rel_max'))}</td><td>{percent(chk.get('median'), 3)}</td>"
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
